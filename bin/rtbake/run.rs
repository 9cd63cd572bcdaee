//! `rtbake run`: the GPU runtime (or its CPU reference with --cpu) on image files, and a procedural demo.

use crate::cli::{usage, usage_msg, Ctx};
use rtbake::baked_layout::path;
use rtbake::image_buf::Image;
use rtbake::io::{self, atomic::write_atomic};
use rtbake::runtime::chain::Subsurface;
use rtbake::runtime::chain::{self, Antialiasing};
use rtbake::runtime::demo::{self, DemoAssets, SssMethod};
use rtbake::runtime::device::{create_headless, Gpu};
use rtbake::runtime::importance_sss::{ImportanceSamples, ImportanceSssParams};
use rtbake::runtime::loader;
use rtbake::runtime::mlaa::MlaaAreaMap;
use rtbake::runtime::separable_sss::SssParams;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Subcommand)]
pub enum RunCommand {
    /// Antialias a PNG with SMAA 1x (area/search textures from the bake directory), or a frame sequence with
    /// SMAA 1x/S2x/T2x/4x (--mode).
    Smaa(crate::run_smaa_modes::SmaaArgs),
    /// Antialias a PNG with Jimenez's MLAA (area map of --max-distance from the bake directory).
    Mlaa(MlaaArgs),
    /// Subsurface scattering on a linear EXR (RGBA, alpha = strength) with its linear-depth EXR: separable SSS
    /// with a baked kernel (default), or the screen-space sum of Gaussians with the baked fit.
    Sss(Box<SssArgs>),
    /// Render a procedural scene (skin spheres over hard-edged shapes) through the whole chain: skin inputs,
    /// separable SSS, transmittance, SMAA/MLAA; writes a PNG, needs no input files.
    Demo(DemoArgs),
    /// Render heads from a mesh (the procedural head, or --mesh glTF/OBJ) through the skin chain: shadow-map
    /// thickness, skin colour, no SSS / sum-of-Gaussians / separable SSS, transmittance; writes a PNG.
    Skin(Box<crate::run_skin::SkinArgs>),
    /// Render TAP 2009's stimulus grid (TS, SS Full, SS Jittered, No SSS × light azimuths 0/60/110/150° at 45° ×
    /// zoom/near/far) and the α/β sweep of its Fig. 4 into a folder: frames, differences against TS, RMSE table
    /// (CSV + JSON), contact sheets.
    TapGrid(Box<crate::run_tap_grid::TapGridArgs>),
}

#[derive(clap::Args)]
pub struct Common {
    /// Run the CPU reference implementation instead of the GPU (no adapter needed).
    #[arg(long)]
    pub(crate) cpu: bool,
    /// Bake directory holding manifest.json and the LUTs (every table is checked against the manifest).
    #[arg(long = "baked-dir", alias = "baked", value_name = "DIR", default_value = "baked")]
    pub(crate) baked: PathBuf,
}

#[derive(clap::Args)]
pub struct AaArgs {
    /// Input PNG (8-bit, gray/gray+alpha/RGB/RGBA, sRGB-encoded).
    #[arg(long, value_name = "PNG")]
    input: PathBuf,
    /// Output PNG (RGBA8).
    #[arg(long, value_name = "PNG")]
    output: PathBuf,
    #[command(flatten)]
    edges: crate::run_edges::EdgeArgs,
    #[command(flatten)]
    common: Common,
}

/// `run demo --aa`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum DemoAa {
    /// SMAA 1x with the baked area and search textures.
    Smaa,
    /// Jimenez MLAA with the baked v1.4 area map of the default maximum distance.
    Mlaa,
    /// No antialiasing.
    None,
}

#[derive(clap::Args)]
pub struct MlaaArgs {
    #[command(flatten)]
    aa: AaArgs,
    /// Maximum distance N of the area map (the bake holds aa/mlaa/AreaMap{N}_v1.4.bin).
    #[arg(long, default_value_t = rtbake::runtime::mlaa::DEFAULT_MAX_DISTANCE)]
    max_distance: u32,
}

#[derive(clap::Args)]
pub struct SssArgs {
    /// Linear HDR diffuse irradiance, EXR with RGB or RGBA (alpha = per-pixel strength, 0 = not skin; RGB: 1).
    #[arg(long, value_name = "EXR")]
    color: PathBuf,
    /// Linear view-space depth (distance along the view axis, > 0), EXR of --color's size: the channel read is
    /// the only one of a single-channel (Y) file, else R. Same world units as --sss-width (default 0.012, the
    /// published demo's value); only the ratio sss-width / depth enters the kernel's screen size.
    /// `rtbake run demo --sss-inputs DIR` writes a matching pair.
    #[arg(long, value_name = "EXR")]
    depth: PathBuf,
    /// Output EXR (RGBA f16).
    #[arg(long, value_name = "EXR")]
    output: PathBuf,
    /// Separable kernel (schema rtbake-separable-kernel/1): a path listed in the manifest of --baked-dir
    /// (checked against it), or a kernel file elsewhere (content checks only).
    #[arg(long, value_name = "JSON", default_value = path::SEPARABLE_KERNEL_DEFAULT)]
    kernel: String,
    /// SSS method: separable (--kernel), gaussians (--gaussians) or importance (--samples and a profile flag).
    #[arg(long, value_enum, default_value = "separable")]
    method: SssMethodArg,
    /// Sample budget of --method importance, 1..=1024 (default 40).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    samples: Option<i64>,
    /// The profile --method importance samples.
    #[command(flatten)]
    profile: crate::importance::ImportanceProfileArgs,
    /// A baked importance kernel for --method importance instead of --samples and a profile flag: a path listed in
    /// the manifest of --baked-dir, e.g. sss/importance/skin1_dipole_n40.json or burley/kernels/dipole_skin1_n40.json.
    #[arg(long, value_name = "JSON")]
    importance_kernel: Option<String>,
    /// mm per world unit of --depth for --method importance (default 125: a head 1 unit tall).
    #[arg(long, default_value_t = ImportanceSssParams::default().mm_per_world_unit, allow_negative_numbers = true)]
    mm_per_world_unit: f32,
    /// Sum-of-Gaussians fit for --method gaussians, a path listed in the manifest of --baked-dir.
    #[arg(long, value_name = "JSON", default_value = path::GAUSSIANS_DEFAULT)]
    gaussians: String,
    /// Kernel width in world units (default: the kernel file's sss_width, else 0.012).
    #[arg(long)]
    sss_width: Option<f32>,
    /// Vertical field of view, degrees.
    #[arg(long, default_value_t = 20.0)]
    fovy: f32,
    /// Disable the follow-surface depth test.
    #[arg(long)]
    no_follow_surface: bool,
    #[command(flatten)]
    common: Common,
}

/// `run sss --method`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SssMethodArg {
    /// Separable SSS (thesis ch. 6), two passes.
    Separable,
    /// Screen-space sum of Gaussians (thesis ch. 4), α scaled from its 720-pixel viewport to the image height.
    Gaussians,
    /// Importance-sampled disk kernel of a profile (Unity HDRP's sampling), one pass of --samples fetches.
    Importance,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Method {
    /// Separable SSS (thesis ch. 6), two passes.
    Separable,
    /// Screen-space sum of Gaussians (thesis ch. 4), α scaled from its 720-pixel viewport to the image height.
    Gaussians,
    /// Importance-sampled disk kernel of the skin1 dipole, 40 samples (the baked sss/importance/skin1_dipole_n40.json).
    Importance,
}

#[derive(clap::Args)]
pub struct DemoArgs {
    /// Output PNG (RGBA8, sRGB-encoded).
    #[arg(long, value_name = "PNG")]
    output: PathBuf,
    /// Frame width in pixels, 1..=16384.
    #[arg(long, default_value_t = 1280, value_name = "PIXELS")]
    width: u32,
    /// Frame height in pixels, 1..=16384; the sum-of-Gaussians α is scaled from its 720-pixel viewport to it.
    #[arg(long, default_value_t = 720, value_name = "PIXELS")]
    height: u32,
    /// Antialiasing of the final frame.
    #[arg(long, value_enum, default_value = "smaa")]
    aa: DemoAa,
    /// SSS pass of the demo: separable (baked kernel), gaussians (baked sum-of-Gaussians fit) or importance (baked
    /// importance-sampled kernel).
    #[arg(long, value_enum, default_value = "separable")]
    sss: Method,
    /// Also write the scene's SSS inputs into DIR, as `rtbake run sss` reads them: irradiance.exr (linear RGBA
    /// f32, alpha = SSS strength) and depth.exr (linear view-space depth, one channel Y, f32).
    #[arg(long, value_name = "DIR")]
    sss_inputs: Option<PathBuf>,
    /// Hemoglobin rig weights (eq. 7.6): JSON file {"target name": weight, ...} summing to 1 (default: neutral 0.6,
    /// joy 0.4 with the baked example rig).
    #[arg(long, value_name = "JSON")]
    rig_weights: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

pub fn run(cmd: RunCommand, ctx: &Ctx) -> anyhow::Result<()> {
    match cmd {
        RunCommand::Smaa(s) if s.mode.is_some() => {
            let (cpu, baked) = (s.common.cpu, s.common.baked.clone());
            crate::run_smaa_modes::run(ctx, s, cpu, &baked)
        }
        RunCommand::Smaa(s) => {
            let (input, output) = (s.input.expect("clap: --input"), s.output.expect("clap: --output"));
            let a = AaArgs { input, output, edges: s.edges, common: s.common };
            check_output(&a.output, "png", &[&[a.input.as_path()][..], &a.edges.files()].concat())?;
            let img = read_png(&a.input)?;
            let aa = Antialiasing::Smaa(loader::load_smaa_textures(&a.common.baked).map_err(usage)?);
            antialias_file(ctx, &a, img, &aa, "smaa")
        }
        RunCommand::Mlaa(m) => {
            check_output(&m.aa.output, "png", &[&[m.aa.input.as_path()][..], &m.aa.edges.files()].concat())?;
            let map = load_mlaa(&m.aa.common.baked, m.max_distance)?;
            let img = read_png(&m.aa.input)?;
            antialias_file(ctx, &m.aa, img, &Antialiasing::Mlaa(map), "mlaa")
        }
        RunCommand::Sss(a) => sss(ctx, *a),
        RunCommand::Demo(d) => run_demo(ctx, d),
        RunCommand::TapGrid(s) => crate::run_tap_grid::run(ctx, *s),
        RunCommand::Skin(s) => crate::run_skin::run(ctx, *s),
    }
}

/// Mesa's Vulkan and GL drivers print "XDG_RUNTIME_DIR is invalid or not set" when the session has none (SSH,
/// containers, CI). Give this process a private one (`$TMPDIR/rtbake-runtime-UID`, mode 0700) in that case;
/// a valid directory set by the session is kept.
pub fn ensure_runtime_dir() {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
        let valid = |p: &Path| std::fs::metadata(p).is_ok_and(|m| m.is_dir() && m.mode() & 0o077 == 0);
        if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| valid(Path::new(&d))) {
            return;
        }
        // SAFETY: getuid has no preconditions and cannot fail.
        let uid = unsafe { libc::getuid() };
        let dir = std::env::temp_dir().join(format!("rtbake-runtime-{uid}"));
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        let owned = std::fs::metadata(&dir).is_ok_and(|m| m.uid() == uid);
        if owned {
            let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
        }
        if owned && valid(&dir) {
            // Single-threaded here: no device, no rayon pool has started yet.
            std::env::set_var("XDG_RUNTIME_DIR", &dir);
        }
    }
}

fn load_mlaa(baked: &Path, n: u32) -> anyhow::Result<MlaaAreaMap> {
    rtbake::aa::mlaa_area::validate(rtbake::aa::mlaa_area::MlaaVersion::V1_4, n).map_err(usage)?;
    let listed = rtbake::manifest::Manifest::load(baked)
        .ok()
        .is_some_and(|m| m.entry(&rtbake::baked_layout::path::mlaa_area_v1_4(n)).is_some());
    if !listed && baked.join(rtbake::manifest::MANIFEST_NAME).is_file() {
        // The default bake holds the published sizes only; say how to bake another one (not "re-run rtbake bake",
        // which would not produce it).
        return Err(usage_msg(format!(
            "--max-distance {n}: {dir} has no {path}. Bake it into a bake directory first: \
             echo '{{\"mlaa-v1.4\": {{\"max_distances\": [{n}]}}}}' > p.json && \
             rtbake bake mlaa-v1.4 --asset-params p.json --out {dir}",
            dir = baked.display(),
            path = rtbake::baked_layout::path::mlaa_area_v1_4(n),
        )));
    }
    let bytes = loader::load_mlaa_area(baked, n).map_err(usage)?;
    Ok(MlaaAreaMap::new(n, bytes)?)
}

/// The output's directory must exist and be writable before any work is done.
/// `--output` must be in an existing directory and must not be one of the command's `inputs` (exit 2, both named).
/// `--output` in an existing directory and not one of the inputs (exit 2 otherwise).
/// The file's extension must name the format written (`png` or `exr`, any case): `--output s.jpg` is refused
/// instead of writing PNG bytes under a JPEG name, and so is an existing directory.
pub(crate) fn check_output_of(path: &Path, inputs: &[&Path]) -> anyhow::Result<()> {
    check_output(path, "png", inputs)
}

fn check_output(path: &Path, ext: &str, inputs: &[&Path]) -> anyhow::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(usage_msg(format!("--output {}: directory {} does not exist", path.display(), dir.display())));
    }
    if path.is_dir() {
        return Err(usage_msg(format!(
            "--output {}: is a directory; give a file name ending in .{ext}",
            path.display()
        )));
    }
    if !path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case(ext)) {
        return Err(usage_msg(format!(
            "--output {}: this command writes {}; the file name must end in .{ext} (accepted: .{ext}, .{})",
            path.display(),
            ext.to_ascii_uppercase(),
            ext.to_ascii_uppercase()
        )));
    }
    rtbake::io::file_set::check_outputs_not_inputs(&[path.to_path_buf()], inputs)
        .map_err(|e| usage(anyhow::anyhow!("--output: {e}")))
}

fn read_png(path: &Path) -> anyhow::Result<Image<u8>> {
    let bytes = std::fs::read(path).map_err(|e| usage(anyhow::anyhow!("--input {}: {e}", path.display())))?;
    let img = match io::png::decode(&bytes, &path.display().to_string()).map_err(usage)? {
        io::png::DecodedPng::U8(img) => img,
        io::png::DecodedPng::U16(_) => {
            return Err(usage_msg(format!("--input {}: 16-bit PNG; expected 8-bit sRGB", path.display())))
        }
    };
    Ok(chain::to_rgba8(&img)?)
}

pub(crate) fn device(ctx: &Ctx, cpu: bool) -> anyhow::Result<Option<Gpu>> {
    if cpu {
        ctx.info("backend: CPU reference");
        return Ok(None);
    }
    let g = create_headless(&Default::default()).map_err(|e| {
        anyhow::Error::new(e)
            .context("could not open a GPU adapter; add --cpu to run the CPU reference of the same passes")
    })?;
    ctx.info(format!("adapter: {}", g.describe()));
    Ok(Some(g))
}

fn antialias_file(ctx: &Ctx, a: &AaArgs, img: Image<u8>, aa: &Antialiasing, name: &str) -> anyhow::Result<()> {
    let extra = a.edges.load(img.width, img.height)?;
    let gpu = device(ctx, a.common.cpu)?;
    let t = Instant::now();
    let masked = extra.inputs().mask.is_some();
    let (bytes, seconds) =
        chain::antialias_estimate_with(img.width, img.height, aa, gpu.is_some(), &extra.settings, masked);
    ctx.check_budget(&format!("--input {} ({}x{})", a.input.display(), img.width, img.height), bytes, seconds)?;
    let out = chain::antialias_with(gpu.as_ref(), &img, aa, &extra.settings, &extra.inputs())?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    write_atomic(&a.output, &io::png::encode_u8_frame(&out)?)?;
    report(ctx, name, &a.output, &out, gpu.as_ref(), ms);
    Ok(())
}

fn report(ctx: &Ctx, pass: &str, output: &Path, img: &Image<u8>, gpu: Option<&Gpu>, ms: f64) {
    let adapter = gpu.map(|g| g.describe()).unwrap_or_else(|| "CPU reference".into());
    ctx.info(format!("{pass}: {}x{} in {ms:.1} ms -> {}", img.width, img.height, output.display()));
    if ctx.json {
        ctx.emit_json(&serde_json::json!({
            "pass": pass,
            "output": output.display().to_string(),
            "width": img.width,
            "height": img.height,
            "adapter": adapter,
            "wall_ms": ms,
        }));
    }
}

fn read_exr(flag: &str, path: &Path) -> anyhow::Result<Image<f32>> {
    let bytes = std::fs::read(path).map_err(|e| usage(anyhow::anyhow!("{flag} {}: {e}", path.display())))?;
    // OpenEXR files start with the magic number 76 2f 31 01; say what the file is instead of the decoder's
    // "file identifier missing".
    if !bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        let what = if bytes.starts_with(b"\x89PNG") { "a PNG image" } else { "not an OpenEXR file" };
        return Err(usage_msg(format!(
            "{flag} {}: is {what}; {flag} takes an OpenEXR image (linear, half or float; `rtbake run demo \
             --sss-inputs DIR` writes a matching colour/depth pair)",
            path.display()
        )));
    }
    Ok(io::exr::decode(&bytes, &path.display().to_string()).map_err(usage)?.0)
}

/// The kernel named by --kernel: through the manifest of the bake directory when it lists the path, else a
/// kernel file elsewhere (content checks only).
fn read_kernel(ctx: &Ctx, baked: &Path, kernel: &str) -> anyhow::Result<loader::BakedKernel> {
    let listed = rtbake::manifest::Manifest::load(baked).ok().is_some_and(|m| m.entry(kernel).is_some());
    if listed {
        return loader::load_separable_kernel(baked, kernel).map_err(usage);
    }
    let path = Path::new(kernel);
    if !path.is_file() {
        return Err(usage_msg(format!(
            "--kernel {kernel}: neither listed in {}/manifest.json nor an existing file",
            baked.display()
        )));
    }
    ctx.info(format!("kernel {kernel}: not in a bake directory, content checks only (no manifest, no sha256)"));
    let text = std::fs::read_to_string(path).map_err(|e| usage(anyhow::anyhow!("--kernel {kernel}: {e}")))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| usage(anyhow::anyhow!("--kernel {kernel}: not valid JSON: {e}")))?;
    loader::separable_kernel_from_json(&v, kernel).map_err(usage)
}

fn sss(ctx: &Ctx, a: SssArgs) -> anyhow::Result<()> {
    check_output(&a.output, "exr", &[&a.color, &a.depth])?;
    let baked = &a.common.baked;
    if a.method != SssMethodArg::Importance
        && (a.samples.is_some() || a.profile.is_set() || a.importance_kernel.is_some())
    {
        return Err(usage_msg(
            "--samples, --importance-kernel and the profile flags (--material, --profile-preset, …) need --method \
             importance",
        ));
    }
    let importance_params = ImportanceSssParams {
        mm_per_world_unit: a.mm_per_world_unit,
        fovy_deg: a.fovy,
        follow_surface: !a.no_follow_surface,
    };
    let importance = match (a.method, &a.importance_kernel) {
        (SssMethodArg::Importance, Some(path)) => {
            if a.samples.is_some() || a.profile.is_set() {
                return Err(usage_msg(
                    "--importance-kernel is a baked kernel: give it alone, or --samples with a profile flag",
                ));
            }
            importance_params.validate()?;
            let k = loader::load_importance_kernel(baked, path).map_err(usage)?;
            ctx.info(format!(
                "importance kernel {path}: {} samples (cut-off {:.4} mm)",
                k.offsets_mm.len(),
                k.cutoff_mm
            ));
            Some((k, importance_params))
        }
        (SssMethodArg::Importance, None) => {
            let n = crate::importance::parse_samples(a.samples.unwrap_or(40))?;
            let resolved = a.profile.resolve(ctx)?;
            let k = resolved.kernel(n)?;
            ctx.info(format!("importance kernel: {} samples of {} (cut-off {:.4} mm)", n, resolved.stem, k.cutoff_mm));
            importance_params.validate()?;
            Some((ImportanceSamples::from_kernel(&k), importance_params))
        }
        _ => None,
    };
    let (kernel, gaussians) = match a.method {
        SssMethodArg::Separable => (Some(read_kernel(ctx, baked, &a.kernel)?), None),
        SssMethodArg::Gaussians => (None, Some(loader::load_gaussians(baked, &a.gaussians).map_err(usage)?)),
        SssMethodArg::Importance => (None, None),
    };
    let default_width = kernel.as_ref().and_then(|k| k.sss_width).unwrap_or(SssParams::default().sss_width);
    let params = SssParams {
        sss_width: a.sss_width.unwrap_or(default_width),
        fovy_deg: a.fovy,
        follow_surface: !a.no_follow_surface,
    };
    params.validate()?;
    let color = read_exr("--color", &a.color)?;
    let depth = read_exr("--depth", &a.depth)?;
    if (color.width, color.height) != (depth.width, depth.height) {
        return Err(usage_msg(format!(
            "--depth must match --color's size {}x{}, got {}x{}",
            color.width, color.height, depth.width, depth.height
        )));
    }
    let rgba = match color.channels {
        4 => color.data.clone(),
        3 => color.data.chunks(3).flat_map(|p| [p[0], p[1], p[2], 1.0]).collect(),
        n => return Err(usage_msg(format!("--color must have 3 or 4 channels (RGB/RGBA), got {n}"))),
    };
    let d: Vec<f32> = depth.data.chunks(depth.channels as usize).map(|p| p[0]).collect();
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(usage_msg("--depth must hold finite linear depths > 0"));
    }
    let gpu = device(ctx, a.common.cpu)?;
    let (w, h) = (color.width, color.height);
    let t = Instant::now();
    let method = match (&kernel, &gaussians, &importance) {
        (Some(k), _, _) => Subsurface::Separable { kernel: &k.kernel, params: &params },
        (None, Some(f), _) => Subsurface::Gaussians { blurs: &f.blurs, params: f.params },
        (None, None, Some((samples, p))) => Subsurface::Importance { samples, params: p },
        (None, None, None) => unreachable!("one SSS method is selected"),
    };
    let (bytes, seconds) = rtbake::runtime::chain::subsurface_estimate(w, h, &method, gpu.is_some());
    ctx.check_budget(&format!("--color {} ({w}x{h})", a.color.display()), bytes, seconds)?;
    let out = rtbake::runtime::chain::subsurface(gpu.as_ref(), &rgba, &d, (w, h), &method)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let img = Image::from_vec(w, h, 4, out);
    write_atomic(&a.output, &io::exr::encode(&img, io::exr::ExrPrecision::F16)?)?;
    let adapter = gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU reference".into());
    ctx.info(format!("sss: {w}x{h} in {ms:.1} ms -> {}", a.output.display()));
    if ctx.json {
        ctx.emit_json(&serde_json::json!({"pass": "sss", "output": a.output.display().to_string(), "width": w,
            "height": h, "adapter": adapter, "wall_ms": ms}));
    }
    Ok(())
}

fn run_demo(ctx: &Ctx, d: DemoArgs) -> anyhow::Result<()> {
    check_output(&d.output, "png", &[])?;
    rtbake::error::check_size("--width/--height", d.width as u64, d.height as u64)?;
    ctx.check_budget(
        &format!("--width {} --height {}", d.width, d.height),
        demo::memory_estimate_bytes(d.width, d.height),
        demo::time_estimate_seconds(d.width, d.height, d.common.cpu),
    )?;
    let aa = match d.aa {
        DemoAa::Smaa => Some(Antialiasing::Smaa(loader::load_smaa_textures(&d.common.baked).map_err(usage)?)),
        DemoAa::Mlaa => {
            Some(Antialiasing::Mlaa(load_mlaa(&d.common.baked, rtbake::runtime::mlaa::DEFAULT_MAX_DISTANCE)?))
        }
        DemoAa::None => None,
    };
    let mut assets = DemoAssets::load(&d.common.baked).map_err(usage)?;
    if let Some(p) = &d.rig_weights {
        let text =
            std::fs::read_to_string(p).map_err(|e| usage(anyhow::anyhow!("--rig-weights {}: {e}", p.display())))?;
        let v: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| usage(anyhow::anyhow!("--rig-weights {}: not valid JSON: {e}", p.display())))?;
        rtbake::facial::hemoglobin_rig::check_pose_json("--rig-weights", &v).map_err(usage)?;
        assets.set_rig_weights(&v)?;
    }
    ctx.info(format!("hemoglobin rig: {}", assets.rig_source));
    let method = match d.sss {
        Method::Separable => SssMethod::Separable,
        Method::Gaussians => SssMethod::Gaussians,
        Method::Importance => SssMethod::Importance,
    };
    let gpu = device(ctx, d.common.cpu)?;
    if let Some(g) = gpu.as_ref() {
        demo::check_frame_fits(&g.device.limits(), d.width, d.height).map_err(usage)?;
    }
    if let Some(g) = gpu.as_ref().filter(|g| g.is_software()) {
        ctx.check_time(
            &format!("--width {} --height {} on a software adapter ({})", d.width, d.height, g.adapter_info.name),
            demo::software_adapter_time_estimate_seconds(d.width, d.height),
        )?;
    }
    let t = Instant::now();
    let out = demo::render(gpu.as_ref(), d.width, d.height, &assets, method, aa.as_ref())?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let inputs = match &d.sss_inputs {
        Some(dir) => Some((dir, demo::sss_inputs(gpu.as_ref(), d.width, d.height, &assets)?)),
        None => None,
    };
    write_atomic(&d.output, &io::png::encode_u8_frame(&out)?)?;
    if let Some((dir, i)) = inputs {
        crate::cli::prepare_out_dir("--sss-inputs", dir)?;
        let color = Image::from_vec(i.width, i.height, 4, i.irradiance_rgba);
        let depth = Image::from_vec(i.width, i.height, 1, i.depth);
        write_atomic(&dir.join("irradiance.exr"), &io::exr::encode(&color, io::exr::ExrPrecision::F32)?)?;
        write_atomic(&dir.join("depth.exr"), &io::exr::encode(&depth, io::exr::ExrPrecision::F32)?)?;
        ctx.info(format!("wrote the SSS inputs irradiance.exr and depth.exr to {}", dir.display()));
    }
    report(ctx, "demo", &d.output, &out, gpu.as_ref(), ms);
    Ok(())
}
