//! `rtbake maps`: facial appearance maps — hemoglobin appearance rig (thesis ch. 7) and wrinkle maps (ch. 8).
//!
//! Every subcommand reads and validates all inputs and computes every output in memory first; only then does it
//! create the output directory and write the files atomically. Bad input exits 2 and writes nothing.

use crate::cli::{prepare_out_dir, usage, usage_msg, Ctx};
use anyhow::Result;
use rtbake::bake::facial::{self as bf, RigDescription, RigSource};
use rtbake::bake::wrinkle_maps::{self, WrinkleConversion, WrinkleOutput};
use rtbake::bake::{BakedFile, FileFormat, FileKind, FileMeta};
use rtbake::error::InvalidInput;
use rtbake::facial::disk_stats::Border;
use rtbake::facial::hemoglobin_rig::{self, RigSettings};
use rtbake::facial::inputs::{self, ValueRange};
use rtbake::facial::wrinkles::WrinkleEncoding;
use rtbake::facial::{synthetic, wrinkles};
use rtbake::image_buf::Image;
use rtbake::io;
use serde_json::json;
use std::path::{Path, PathBuf};

#[derive(clap::Subcommand)]
pub enum MapsCommand {
    /// Bake a hemoglobin appearance rig (eq. 7.1-7.6): per-target scale/bias maps, H0 and rig.json.
    Hemoglobin(HemoglobinArgs),
    /// Evaluate a baked rig (eq. 7.6) for given weights at full resolution.
    RigEval(RigEvalArgs),
    /// Convert a normal map to a partial-derivative or difference wrinkle map (thesis ch. 8).
    Wrinkles(WrinklesArgs),
    /// Pack up to 8 wrinkle zone masks into two RGBA8 textures (thesis Table 8.1 zones).
    WrinkleMasks(WrinkleMasksArgs),
    /// Write the project's synthetic hemoglobin maps (16-bit PNG, concentration = sample/65535).
    Synthetic(SyntheticArgs),
}

/// `--out DIR` and `--zstd LEVEL`: where a map command writes its file set, and how its KTX2 files are compressed.
#[derive(clap::Args)]
struct MapSetOutput {
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    #[command(flatten)]
    zstd: crate::cli::ZstdArg,
}

#[derive(clap::Args)]
pub struct HemoglobinArgs {
    /// Neutral hemoglobin map Hn: EXR (f16/f32), 16-bit PNG, or 8-bit PNG with --value-range; single-channel, or
    /// multi-channel with --channel.
    #[arg(long, value_name = "FILE")]
    neutral: PathBuf,
    /// Target map as NAME=FILE (repeatable, or comma-separated), e.g. anger=anger.exr; names use [a-z0-9_-],
    /// 'neutral' is reserved.
    #[arg(long = "target", value_name = "NAME=FILE", required = true)]
    targets: Vec<String>,
    /// Disk radius r of the local statistics (eq. 7.1), in texels of the input maps; 1..=(min(w,h)-1)/2.
    #[arg(long, value_name = "TEXELS")]
    radius: u32,
    /// Border handling of the disk: clip (normalise by covered area) or wrap (tileable maps).
    #[arg(long, default_value = "clip", value_parser = ["clip", "wrap"])]
    border: String,
    /// Floor eps of sigma_neutral in scale = sigma_i / max(sigma_n, eps), in concentration units (> 0).
    #[arg(long, default_value_t = 1e-4, value_name = "EPS")]
    sigma_floor: f64,
    /// Storage size of the scale/bias maps (thesis: 256), clamped per axis to the input size; 1..=16384.
    #[arg(long, default_value_t = 256, value_name = "TEXELS")]
    rig_size: u32,
    /// Concentration range MIN,MAX that PNG samples 0..max map to (linearly). Required for 8-bit PNGs;
    /// 16-bit PNGs default to 0,1 (concentration = s/65535). Ignored for EXR (values used as stored).
    #[arg(long, value_name = "MIN,MAX")]
    value_range: Option<String>,
    /// Channel that holds the concentration in multi-channel maps (RGB/RGBA EXR or PNG, gray+alpha PNG): R, G, B,
    /// A, Y (gray), or luminance = 0.2126 R + 0.7152 G + 0.0722 B. Applies to every map; single-channel maps are
    /// read as they are.
    #[arg(long, value_name = "R|G|B|A|Y|luminance")]
    channel: Option<String>,
    #[command(flatten)]
    output: MapSetOutput,
}

#[derive(clap::Args)]
pub struct RigEvalArgs {
    /// rig.json written by `rtbake maps hemoglobin`.
    #[arg(long, value_name = "FILE")]
    rig: PathBuf,
    /// Weights as NAME=W,... over 'neutral' and the rig's targets; unnamed maps get 0; must sum to 1.
    #[arg(long, value_name = "NAME=W,...")]
    weights: String,
    /// Divide the weights by their sum instead of requiring a sum of 1.
    #[arg(long)]
    normalize_weights: bool,
    /// Global hemoglobin factor g (thesis: 1.27 anger, 0.81 fear); H is multiplied by it. 0..=10.
    #[arg(long, default_value_t = 1.0, value_name = "G")]
    global_scale: f64,
    /// Output precision of the EXR.
    #[arg(long, default_value = "f32", value_parser = ["f32", "f16"])]
    precision: String,
    /// Appearance transfer (thesis §7.4.2): another character's neutral hemoglobin map (PNG or EXR, read as `maps
    /// hemoglobin --neutral` reads it, at the rig's full size). The rig's relative changes (each target's local
    /// mean shift and spread ratio, eq. 7.3–7.5) are applied to it instead of to the subject's own map.
    #[arg(long, value_name = "FILE")]
    neutral: Option<PathBuf>,
    /// Output EXR file (single channel Y, concentration units).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

#[derive(clap::Args)]
pub struct WrinklesArgs {
    /// Wrinkle normal map (RGB/RGBA 8/16-bit PNG or EXR, encoded n = 2v - 1).
    #[arg(long, value_name = "FILE")]
    normal: PathBuf,
    /// Base normal map of the same size: required for --encoding difference; with pd, the wrinkle map is
    /// stored relative to it (pd(normal) - pd(base)) and the base PD map is written too.
    #[arg(long, value_name = "FILE")]
    base: Option<PathBuf>,
    /// Green-channel convention of the inputs; outputs are always DirectX (+y down the texture).
    #[arg(long, default_value = "directx", value_parser = ["directx", "opengl"])]
    green: String,
    /// Output encoding: pd (partial derivatives, RG8) or difference (0.5 + 0.5(w - b), RGBA8).
    #[arg(long, default_value = "pd", value_parser = ["pd", "difference"])]
    encoding: String,
    /// Normals outside the 45-degree cone of PD maps: clamp (and count) or reject (exit 2).
    #[arg(long, default_value = "clamp", value_parser = ["clamp", "reject"])]
    cone: String,
    /// Stored wrinkle map size (thesis: 256), area-downsampled, clamped per axis to the input; 1..=16384.
    #[arg(long, default_value_t = 256, value_name = "TEXELS")]
    size: u32,
    #[command(flatten)]
    output: MapSetOutput,
}

#[derive(clap::Args)]
pub struct WrinkleMasksArgs {
    /// Zone mask as ZONE=FILE (repeatable); zones: red, green, blue, brown, cyan, magenta, orange, gray
    /// (Table 8.1). Single-channel PNG (8/16-bit) or EXR, values 0..1; missing zones are 0.
    #[arg(long = "zone", value_name = "ZONE=FILE", required = true)]
    zones: Vec<String>,
    /// Stored mask size (thesis: 64), area-downsampled, clamped per axis to the input; 1..=16384.
    #[arg(long, default_value_t = 64, value_name = "TEXELS")]
    size: u32,
    #[command(flatten)]
    output: MapSetOutput,
}

#[derive(clap::Args)]
pub struct SyntheticArgs {
    /// Map edge in texels, 3..=8192.
    #[arg(long, default_value_t = 128)]
    size: u32,
    /// Noise seed.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Targets to generate, comma-separated (joy, anger, fear, disgust, sadness, surprise, exercise, alcohol).
    #[arg(long, default_value = "joy,anger,fear,disgust")]
    targets: String,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(cmd: MapsCommand, ctx: &Ctx) -> Result<()> {
    match cmd {
        MapsCommand::Hemoglobin(a) => run_hemoglobin(a, ctx),
        MapsCommand::RigEval(a) => run_rig_eval(a, ctx),
        MapsCommand::Wrinkles(a) => run_wrinkles(a, ctx),
        MapsCommand::WrinkleMasks(a) => run_masks(a, ctx),
        MapsCommand::Synthetic(a) => run_synthetic(a, ctx),
    }
}

fn read_input(flag: &str, path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| usage(anyhow::anyhow!("{flag} {}: cannot read: {e}", path.display())))
}

fn split_pair<'a>(flag: &str, s: &'a str) -> Result<(&'a str, &'a str)> {
    s.split_once('=')
        .filter(|(a, b)| !a.is_empty() && !b.is_empty())
        .ok_or_else(|| usage_msg(format!("{flag}: expected NAME=VALUE, got '{s}'")))
}

fn parse_border(s: &str) -> Border {
    if s == "wrap" {
        Border::Wrap
    } else {
        Border::Clip
    }
}

/// Writes files below `dir` (paths relative to it) as one set: locked, all or nothing, never over an input.
/// `--zstd` supercompresses the set's KTX2 files first.
fn write_files(
    ctx: &Ctx,
    flag: &str,
    dir: &Path,
    mut files: Vec<BakedFile>,
    inputs: &[&Path],
    zstd: &crate::cli::ZstdArg,
) -> Result<Vec<BakedFile>> {
    zstd.apply(&mut files)?;
    rtbake::bake::add_bevy_meta_files(&mut files);
    prepare_out_dir(flag, dir)?;
    crate::cli::write_set(ctx, flag, dir, &files, inputs)?;
    Ok(files)
}

fn run_hemoglobin(a: HemoglobinArgs, ctx: &Ctx) -> Result<()> {
    a.output.zstd.level()?;
    let range = match &a.value_range {
        None => None,
        Some(s) => {
            let v = crate::cli::parse_f64_list("--value-range", s)?;
            if v.len() != 2 {
                return Err(usage_msg(format!("--value-range: expected MIN,MAX, got '{s}'")));
            }
            Some(ValueRange::new("--value-range", v[0], v[1])?)
        }
    };
    let channel = a.channel.as_deref().map(|c| inputs::ChannelSelect::parse("--channel", c)).transpose()?;
    let border = parse_border(&a.border);
    // Parse target names first (cheap errors before reading files).
    let mut pairs = Vec::new();
    // Each --target may also hold comma-separated pairs (as --params FILE expands arrays).
    for t in a.targets.iter().flat_map(|t| t.split(',')) {
        let (name, file) = split_pair("--target", t)?;
        hemoglobin_rig::check_target_name("--target", name)?;
        if pairs.iter().any(|(n, _): &(String, PathBuf)| n == name) {
            return Err(usage_msg(format!("--target: target '{name}' is given twice")));
        }
        pairs.push((name.to_string(), PathBuf::from(file)));
    }
    let neutral_path = a.neutral.display().to_string();
    let neutral = inputs::decode_concentration_channel(
        "--neutral",
        &neutral_path,
        &read_input("--neutral", &a.neutral)?,
        range,
        channel,
    )?;
    let (w, h) = (neutral.image.width, neutral.image.height);
    let settings = RigSettings { radius_texels: a.radius, border, sigma_floor: a.sigma_floor, rig_size: a.rig_size };
    hemoglobin_rig::check_settings(&settings, w, h)?;
    let n_maps = pairs.len() + 1;
    ctx.check_budget(
        &format!("--radius {} on {n_maps} maps of {w}x{h}", a.radius),
        hemoglobin_rig::memory_estimate_bytes(w, h, n_maps),
        hemoglobin_rig::time_estimate_seconds(w, h, n_maps, a.radius, rayon::current_num_threads()),
    )?;
    let mut sources = vec![RigSource {
        name: "neutral".into(),
        source: file_name(&a.neutral),
        format: neutral.source_format.into(),
        mapping: neutral.mapping.clone(),
    }];
    let mut maps = Vec::new();
    for (name, path) in &pairs {
        let flag = format!("--target {name}");
        let p = path.display().to_string();
        let m = inputs::decode_concentration_channel(&flag, &p, &read_input(&flag, path)?, range, channel)?;
        if (m.image.width, m.image.height) != (w, h) {
            return Err(usage(InvalidInput::new(
                flag,
                format!(
                    "{p}: map is {}x{}, but the neutral map is {w}x{h}; all maps must have the same size",
                    m.image.width, m.image.height
                ),
            )));
        }
        sources.push(RigSource {
            name: name.clone(),
            source: file_name(path),
            format: m.source_format.into(),
            mapping: m.mapping.clone(),
        });
        maps.push((name.clone(), m.image.data));
    }
    ctx.info(format!("hemoglobin rig: {w}x{h}, {} targets, r = {} texels", maps.len(), a.radius));
    let refs: Vec<(String, &[f32])> = maps.iter().map(|(n, v)| (n.clone(), v.as_slice())).collect();
    let bar = ctx.progress(1 + refs.len() as u64, "local statistics");
    let rig = hemoglobin_rig::build_rig_with_progress(&neutral.image.data, w, h, &refs, &settings, &|k| {
        bar.set_position(k as u64)
    })?;
    bar.finish_and_clear();
    let (files, desc) = bf::hemoglobin_rig_files(
        &rig,
        "`rtbake maps hemoglobin`",
        "",
        &sources,
        "as given by the input value mapping (see maps[].source)",
    )?;
    let mut input_paths: Vec<&Path> = vec![a.neutral.as_path()];
    input_paths.extend(pairs.iter().map(|(_, p)| p.as_path()));
    let files = write_files(ctx, "--out", &a.output.out, files, &input_paths, &a.output.zstd)?;
    let pct = 100.0 * rig.sigma_floored_texels as f64 / (w as f64 * h as f64);
    ctx.info(format!(
        "wrote {} files to {} (rig {}x{}); sigma_neutral floored at {} in {} texels ({pct:.3} %)",
        files.len(),
        a.output.out.display(),
        rig.rig_width,
        rig.rig_height,
        a.sigma_floor,
        rig.sigma_floored_texels
    ));
    if ctx.json {
        ctx.emit_json(&json!({
            "rig": a.output.out.join("rig.json").display().to_string(),
            "full_size": desc.full_size,
            "rig_size": desc.rig_size,
            "sigma_floored_texels": rig.sigma_floored_texels,
            "files": files.iter().map(|f| f.path.clone()).collect::<Vec<_>>(),
        }));
    }
    Ok(())
}

fn file_name(p: &Path) -> String {
    p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| p.display().to_string())
}

fn parse_weights(s: &str) -> Result<Vec<(String, f64)>> {
    s.split(',')
        .map(|t| {
            let (n, v) = split_pair("--weights", t.trim())?;
            let v: f64 = v.parse().map_err(|_| usage_msg(format!("--weights: '{v}' is not a number (in '{t}')")))?;
            Ok((n.to_string(), v))
        })
        .collect()
}

fn run_rig_eval(a: RigEvalArgs, ctx: &Ctx) -> Result<()> {
    let pairs = parse_weights(&a.weights)?;
    rtbake::error::check_range("--global-scale", a.global_scale, 0.0, 10.0, "")?;
    // A `maps hemoglobin` killed while renaming its set left a committed journal: finish it, so the rig read
    // below is the whole new set, never a mix of new and old maps.
    let rig_dir = a.rig.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if let Some(note) = ctx.with_wait(|w| io::file_set::settle(rig_dir, w)).map_err(crate::cli::file_set_err)? {
        ctx.info(note);
    }
    let text = std::fs::read_to_string(&a.rig)
        .map_err(|e| usage(anyhow::anyhow!("--rig {}: cannot read: {e}", a.rig.display())))?;
    let desc: RigDescription = serde_json::from_str(&text)
        .map_err(|e| usage(anyhow::anyhow!("--rig {}: not a valid rig description: {e}", a.rig.display())))?;
    let names: Vec<String> = desc.maps.iter().map(|m| m.name.clone()).collect();
    let weights = hemoglobin_rig::rig_weights(&names, &pairs, a.normalize_weights)?;
    // The output is full size: estimate before the maps are read or anything is allocated.
    let ([fw, fh], [rw, rh]) = (desc.full_size, desc.rig_size);
    ctx.check_budget(
        &format!("--rig {} (full size {fw}x{fh})", a.rig.display()),
        hemoglobin_rig::evaluate_memory_estimate_bytes(fw, fh, rw, rh, names.len()),
        hemoglobin_rig::evaluate_time_estimate_seconds(fw, fh),
    )?;
    let dir = a.rig.parent().unwrap_or(Path::new(".")).to_path_buf();
    let param = format!("--rig {}", a.rig.display());
    let rig = bf::rig_from_description(&param, &desc, &mut |file| {
        let p = dir.join(file);
        std::fs::read(&p).map_err(|e| InvalidInput::new(param.clone(), format!("{}: cannot read: {e}", p.display())))
    })?;
    let rig = match &a.neutral {
        None => rig,
        Some(path) => {
            let other = inputs::decode_concentration(
                "--neutral",
                &path.display().to_string(),
                &read_input("--neutral", path)?,
                None,
            )?;
            if (other.image.width, other.image.height) != (rig.width, rig.height) {
                return Err(usage_msg(format!(
                    "--neutral {}: {}x{} texels; the rig was built from {}x{} maps, so the other character's neutral \
                     map must be {}x{}",
                    path.display(),
                    other.image.width,
                    other.image.height,
                    rig.width,
                    rig.height,
                    rig.width,
                    rig.height
                )));
            }
            rtbake::facial::appearance_transfer::transfer_rig(&rig, &other.image.data, "--neutral")?
        }
    };
    let (w, h) = (rig.width, rig.height);
    let out = hemoglobin_rig::evaluate(&rig, &weights, a.global_scale);
    let precision = if a.precision == "f16" { io::exr::ExrPrecision::F16 } else { io::exr::ExrPrecision::F32 };
    let bytes = io::exr::encode(&Image::from_vec(w, h, 1, out), precision)?;
    if let Some(parent) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(usage_msg(format!("--out {}: directory {} does not exist", a.out.display(), parent.display())));
        }
    }
    let out_name = a.out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let out_dir = a.out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut read: Vec<PathBuf> = vec![a.rig.clone(), dir.join(&desc.h0.exr)];
    read.extend(a.neutral.iter().cloned());
    for m in &desc.maps {
        read.push(dir.join(&m.scale_exr));
        read.push(dir.join(&m.bias_exr));
    }
    let read_refs: Vec<&Path> = read.iter().map(PathBuf::as_path).collect();
    let file =
        BakedFile { path: out_name, bytes, meta: rtbake::manifest::FileMeta::text(FileKind::Map, FileFormat::Exr, "") };
    crate::cli::write_set(ctx, "--out", out_dir, &[file], &read_refs)?;
    let used: Vec<String> = names.iter().zip(&weights).map(|(n, w)| format!("{n}={w}")).collect();
    ctx.info(format!("wrote {} ({w}x{h}) with weights {}", a.out.display(), used.join(",")));
    if ctx.json {
        ctx.emit_json(&json!({"out": a.out.display().to_string(), "size": [w, h], "weights": names.iter().zip(&weights).map(|(n, w)| (n.clone(), json!(w))).collect::<serde_json::Map<_, _>>()}));
    }
    Ok(())
}

fn run_wrinkles(a: WrinklesArgs, ctx: &Ctx) -> Result<()> {
    a.output.zstd.level()?;
    rtbake::error::check_range("--size", a.size, 1, rtbake::error::MAX_TEXTURE_EDGE, "texels")?;
    let green =
        if a.green == "opengl" { wrinkles::GreenConvention::OpenGl } else { wrinkles::GreenConvention::DirectX };
    let cone = if a.cone == "reject" { wrinkles::ConeMode::Reject } else { wrinkles::ConeMode::Clamp };
    let np = a.normal.display().to_string();
    let normal = inputs::decode_normal_map("--normal", &np, &read_input("--normal", &a.normal)?)?;
    let (bytes, seconds) = wrinkles::wrinkle_estimate(normal.width, normal.height, a.base.is_some());
    ctx.check_budget(&format!("--normal {np} ({}x{})", normal.width, normal.height), bytes, seconds)?;
    let base = match &a.base {
        None => None,
        Some(b) => {
            let bp = b.display().to_string();
            let img = inputs::decode_normal_map("--base", &bp, &read_input("--base", b)?)?;
            if (img.width, img.height) != (normal.width, normal.height) {
                return Err(usage_msg(format!(
                    "--base {bp}: map is {}x{}, but --normal is {}x{}; both must have the same size",
                    img.width, img.height, normal.width, normal.height
                )));
            }
            Some(img)
        }
    };
    let encoding = if a.encoding == "difference" { WrinkleEncoding::Difference } else { WrinkleEncoding::Pd };
    if encoding == WrinkleEncoding::Difference && base.is_none() {
        return Err(usage_msg("--base is required with --encoding difference (d = 0.5 + 0.5 (w - b))"));
    }
    let conversion = WrinkleConversion { input_name: file_name(&a.normal), green, cone, encoding, size: a.size };
    let WrinkleOutput { files, report, summary } = wrinkle_maps::wrinkle_files(&normal, base.as_ref(), &conversion)?;
    ctx.info(summary);
    let inputs_read: Vec<&Path> = std::iter::once(a.normal.as_path()).chain(a.base.as_deref()).collect();
    write_files(ctx, "--out", &a.output.out, files, &inputs_read, &a.output.zstd)?;
    if ctx.json {
        ctx.emit_json(&report);
    }
    Ok(())
}

fn run_masks(a: WrinkleMasksArgs, ctx: &Ctx) -> Result<()> {
    a.output.zstd.level()?;
    rtbake::error::check_range("--size", a.size, 1, rtbake::error::MAX_TEXTURE_EDGE, "texels")?;
    let mut masks: [Option<Vec<f64>>; 8] = Default::default();
    let mut dims: Option<(u32, u32, String)> = None;
    for z in a.zones.iter().flat_map(|z| z.split(',')) {
        let (zone, file) = split_pair("--zone", z)?;
        let Some(i) = wrinkles::ZONES.iter().position(|n| *n == zone) else {
            return Err(usage_msg(format!("--zone: unknown zone '{zone}'; zones: {}", wrinkles::ZONES.join(", "))));
        };
        if masks[i].is_some() {
            return Err(usage_msg(format!("--zone: zone '{zone}' is given twice")));
        }
        let img = inputs::decode_mask("--zone", file, &read_input("--zone", Path::new(file))?)?;
        match &dims {
            Some((w, h, first)) if (*w, *h) != (img.width, img.height) => {
                return Err(usage_msg(format!(
                    "--zone {zone}={file}: mask is {}x{}, but {first} is {w}x{h}; all masks must have the same size",
                    img.width, img.height
                )));
            }
            None => {
                let zones = a.zones.iter().flat_map(|z| z.split(',')).count();
                let (bytes, seconds) = wrinkles::mask_estimate(img.width, img.height, zones);
                ctx.check_budget(
                    &format!("--zone x{zones} ({}x{} from {file})", img.width, img.height),
                    bytes,
                    seconds,
                )?;
                dims = Some((img.width, img.height, file.to_string()))
            }
            _ => {}
        }
        masks[i] = Some(img.data.iter().map(|&v| v as f64).collect());
    }
    let (w, h, _) = dims.expect("clap requires at least one --zone");
    let (files, report, packed) = wrinkle_maps::mask_files(&masks, w, h, a.size)?;
    let given = report["zones_given"].as_array().map_or(0, Vec::len);
    let inputs_read: Vec<&Path> = a
        .zones
        .iter()
        .flat_map(|z| z.split(','))
        .filter_map(|z| z.split_once('=').map(|(_, f)| Path::new(f)))
        .collect();
    write_files(ctx, "--out", &a.output.out, files, &inputs_read, &a.output.zstd)?;
    ctx.info(format!("packed {given} zone masks into 2 RGBA8 textures {}x{}", packed[0], packed[1]));
    if ctx.json {
        ctx.emit_json(&report);
    }
    Ok(())
}

fn run_synthetic(a: SyntheticArgs, ctx: &Ctx) -> Result<()> {
    rtbake::error::check_range("--size", a.size, 3, 8192, "texels")?;
    let names: Vec<String> = a.targets.split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
    let (bytes, seconds) = synthetic::hemoglobin_set_estimate(a.size, names.len() + 1);
    ctx.check_budget(&format!("--size {} with {} maps (--targets)", a.size, names.len() + 1), bytes, seconds)?;
    let set = synthetic::hemoglobin_set("--targets", a.size, a.seed, &names)?;
    let mut files = Vec::new();
    for (name, img) in &set {
        let bytes = io::png::encode_u16(img)?;
        files.push(BakedFile {
            path: format!("{name}.png"),
            bytes,
            meta: FileMeta::text(FileKind::Input, FileFormat::Png, ""),
        });
    }
    let files = write_files(ctx, "--out", &a.out, files, &[], &Default::default())?;
    ctx.info(format!(
        "wrote {} synthetic maps ({}x{}, concentration = sample/65535) to {}",
        set.len(),
        a.size,
        a.size,
        a.out.display()
    ));
    if ctx.json {
        ctx.emit_json(&json!({
            "out": a.out.display().to_string(),
            "width": a.size,
            "height": a.size,
            "format": "png16",
            "mapping": "concentration = sample / 65535",
            "files": files.iter().map(|f| f.path.clone()).collect::<Vec<_>>(),
        }));
    }
    Ok(())
}
