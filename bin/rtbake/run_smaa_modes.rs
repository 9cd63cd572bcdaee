//! `rtbake run smaa --mode 1x|s2x|t2x|4x`: SMAA over a frame sequence — the procedural moving scene
//! (`rtbake::runtime::moving_scene`) or a directory of user frames — on the GPU or its CPU twin.

use crate::cli::{usage, usage_msg, Ctx};
use rtbake::image_buf::Image;
use rtbake::io;
use rtbake::manifest::{BakedFile, ColorSpace, FileFormat, FileKind, FileMeta, SampleType};
use rtbake::runtime::chain::SmaaSequence;
use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
use rtbake::runtime::smaa_modes::{self, ModeFrame, SmaaMode, TemporalResolve};
use std::path::{Path, PathBuf};

/// `run smaa`: one PNG through SMAA 1x (`--input/--output`), or a frame sequence through a mode (`--mode`).
#[derive(clap::Args)]
#[command(after_long_help = INPUT_DIR_HELP)]
pub struct SmaaArgs {
    /// Input PNG (8-bit, gray/gray+alpha/RGB/RGBA, sRGB-encoded): one image through SMAA 1x. Not with --mode.
    #[arg(long, value_name = "PNG", required_unless_present = "mode", conflicts_with = "mode")]
    pub input: Option<PathBuf>,
    /// Output PNG (RGBA8) of --input.
    #[arg(long, value_name = "PNG", required_unless_present = "mode", conflicts_with = "mode")]
    pub output: Option<PathBuf>,
    /// SMAA mode over a frame sequence (the procedural moving scene, or --input-dir): 1x, s2x (2 spatial samples,
    /// D3D10.1 2x pattern), t2x (2 temporal samples, reprojection of eq. 10.6–10.7), 4x (s2x + t2x).
    #[arg(long, value_enum, requires = "out", conflicts_with_all = ["edges", "depth", "predication", "mask"])]
    pub mode: Option<ModeArg>,
    /// With --mode: a directory (written all-or-nothing) receiving frame_NNNN.png for every frame, or a path ending
    /// in .png receiving the last frame only.
    #[arg(long, value_name = "DIR|PNG", requires = "mode")]
    pub out: Option<PathBuf>,
    /// Frames of the procedural sequence, 1..=10000.
    #[arg(long, default_value_t = 8, value_name = "N", conflicts_with = "input_dir")]
    pub frames: u64,
    /// Frame width of the procedural sequence, pixels.
    #[arg(long, default_value_t = 640, value_name = "PIXELS", conflicts_with = "input_dir")]
    pub width: u32,
    /// Frame height of the procedural sequence, pixels.
    #[arg(long, default_value_t = 360, value_name = "PIXELS", conflicts_with = "input_dir")]
    pub height: u32,
    /// User frames instead of the procedural scene (file names below).
    #[arg(long, value_name = "DIR", requires = "mode")]
    pub input_dir: Option<PathBuf>,
    /// K of eq. 10.6 (velocity weighting of the temporal resolve), 0..=10000; 0 = reprojection without weighting.
    #[arg(long, default_value_t = smaa_modes::DEFAULT_K, allow_negative_numbers = true)]
    pub k: f32,
    /// Temporal modes: the plain 50/50 blend of the current and previous frame (no reprojection) instead of eq. 10.7.
    #[arg(long, conflicts_with = "k")]
    pub plain_blend: bool,
    /// Edge detection of the single-image path (--input); the modes use luma edges.
    #[command(flatten)]
    pub edges: crate::run_edges::EdgeArgs,
    #[command(flatten)]
    pub common: crate::run::Common,
}

const INPUT_DIR_HELP: &str = "\
--input-dir DIR holds, for frames N = 0000, 0001, … (consecutive, four digits, from 0000):
  frame_N.png            colour (8-bit RGB or RGBA, sRGB-encoded) for 1x and t2x;
  frame_N_s0.png, frame_N_s1.png
                         colour of the two samples for s2x and 4x (sample 0 at (+0.25, +0.25) px and sample 1 at
                         (-0.25, -0.25) px from the pixel centre, y down, for s2x; 4x: even frames (+0.375, +0.125),
                         (-0.125, -0.375), odd frames (+0.125, +0.375), (-0.375, -0.125); t2x: frame_N.png sampled at
                         (+0.25, +0.25) on even and (-0.25, -0.25) on odd frames);
  frame_N_velocity.exr   velocity, pixels per frame (R = x right, G = y down; v = p(t) - p(t-1)), 2 to 4 channels,
                         finite, the colour's size.
All frames must have the same size. Output: frame_N.png per frame in --out DIR (or the last frame in --out X.png).";

/// `--mode`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ModeArg {
    #[value(name = "1x")]
    X1,
    S2x,
    T2x,
    #[value(name = "4x")]
    X4,
}

impl From<ModeArg> for SmaaMode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::X1 => SmaaMode::X1,
            ModeArg::S2x => SmaaMode::S2x,
            ModeArg::T2x => SmaaMode::T2x,
            ModeArg::X4 => SmaaMode::X4,
        }
    }
}

use rtbake::io::frame_sequence::{frame_name, read_frame_sequence, SequenceFrame};

/// `--input-dir`: the library's reader (`rtbake::io::frame_sequence`), its errors prefixed with the flag.
fn read_user_frames(dir: &Path, mode: SmaaMode) -> anyhow::Result<(u32, u32, Vec<SequenceFrame>)> {
    let seq = read_frame_sequence(dir, mode.samples_per_frame(), mode.name())
        .map_err(|e| usage(anyhow::anyhow!("--input-dir {e}")))?;
    Ok((seq.width, seq.height, seq.frames))
}

fn frame_file(n: u64, w: u32, h: u32, rgba: Vec<u8>) -> anyhow::Result<BakedFile> {
    let bytes = io::png::encode_u8_frame(&Image::from_vec(w, h, 4, rgba))?;
    let meta = FileMeta {
        kind: FileKind::Frame,
        format: FileFormat::Png,
        pixel_format: None,
        width: w,
        height: h,
        channels: 4,
        sample_type: SampleType::U8,
        color_space: ColorSpace::Srgb,
        convention: "RGBA8 sRGB-encoded, top row first".into(),
        verify_tolerance: None,
        supercompression: None,
    };
    Ok(BakedFile { path: format!("{}.png", frame_name(n)), bytes, meta })
}

/// Runs `--mode` (the caller has checked `a.mode` is set).
pub fn run(ctx: &Ctx, a: SmaaArgs, cpu: bool, baked: &Path) -> anyhow::Result<()> {
    let mode: SmaaMode = a.mode.expect("--mode").into();
    let out = a.out.clone().expect("clap: --mode requires --out");
    let last_only = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let resolve = if a.plain_blend { TemporalResolve::Plain } else { TemporalResolve::Reprojected { k: a.k } };
    resolve.validate()?;
    let inputs: Vec<&Path> = a.input_dir.iter().map(|p| p.as_path()).collect();
    if last_only {
        let dir = out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        if !dir.is_dir() {
            return Err(usage_msg(format!("--out {}: directory {} does not exist", out.display(), dir.display())));
        }
    }
    rtbake::io::file_set::check_outputs_not_inputs(std::slice::from_ref(&out), &inputs)
        .map_err(|e| usage(anyhow::anyhow!("--out: {e}")))?;
    // The sequence: user frames (all read and checked first) or the procedural scene.
    let (w, h, user, scene) = match &a.input_dir {
        Some(dir) => {
            let (w, h, frames) = read_user_frames(dir, mode)?;
            (w, h, Some(frames), None)
        }
        None => {
            if !(1..=10_000).contains(&a.frames) {
                return Err(usage_msg(format!("--frames must be in 1..=10000, got {}", a.frames)));
            }
            let scene = MovingScene::new(a.width, a.height, SceneMotion::DEFAULT)?;
            (a.width, a.height, None, Some(scene))
        }
    };
    let frames = user.as_ref().map_or(a.frames, |f| f.len() as u64);
    let kept = if last_only { 1 } else { frames };
    let (bytes, seconds) = smaa_modes::estimate(w, h, mode, frames, kept, !cpu);
    ctx.check_budget(&format!("--mode {} ({frames} frames of {w}x{h})", mode.name()), bytes, seconds)?;
    let luts = rtbake::runtime::loader::load_smaa_textures(baked).map_err(usage)?;
    let gpu = crate::run::device(ctx, cpu)?;
    let mut seq = SmaaSequence::new(gpu.as_ref(), (w, h), &luts, mode, resolve)?;
    let t = std::time::Instant::now();
    let mut files = Vec::new();
    for n in 0..frames {
        let rgba = match (&user, &scene) {
            (Some(f), _) => {
                let f = &f[n as usize];
                seq.run_frame(&ModeFrame { samples: &f.samples, velocity_px: &f.velocity_px })?
            }
            (None, Some(scene)) => {
                let (samples, velocity) = smaa_modes::scene_frame(scene, mode, n);
                seq.run_frame(&ModeFrame { samples: &samples, velocity_px: &velocity })?
            }
            (None, None) => unreachable!("a sequence"),
        };
        if !last_only || n + 1 == frames {
            files.push(frame_file(n, w, h, rgba)?);
        }
    }
    let ms = t.elapsed().as_secs_f64() * 1e3;
    if last_only {
        let f = files.pop().expect("the last frame");
        io::atomic::write_atomic(&out, &f.bytes)?;
    } else {
        crate::cli::prepare_out_dir("--out", &out)?;
        crate::cli::write_set(ctx, "--out", &out, &files, &inputs)?;
    }
    let adapter = gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU reference".into());
    ctx.info(format!(
        "smaa {}: {frames} frames of {w}x{h} in {ms:.1} ms ({adapter}) -> {}",
        mode.name(),
        out.display()
    ));
    if ctx.json {
        ctx.emit_json(
            &serde_json::json!({"pass": format!("smaa-{}", mode.name()), "output": out.display().to_string(),
            "frames": frames, "width": w, "height": h, "adapter": adapter, "wall_ms": ms}),
        );
    }
    Ok(())
}
