//! `rtbake run`: the GPU runtime (or its CPU reference with --cpu) on image files, and a procedural demo.

use crate::cli::{usage, usage_msg, Ctx};
use rtbake::image_buf::Image;
use rtbake::io::{self, atomic::write_atomic};
use rtbake::runtime::chain::{self, Antialiasing};
use rtbake::runtime::device::{create_headless, Gpu};
use rtbake::runtime::mlaa::MlaaAreaMap;
use rtbake::runtime::{loader, scene};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Subcommand)]
pub enum RunCommand {
    /// Antialias a PNG with SMAA 1x (area/search textures from the bake directory).
    Smaa(AaArgs),
    /// Antialias a PNG with Jimenez's MLAA (area map of --max-distance from the bake directory).
    Mlaa(MlaaArgs),
    /// Render a procedural scene (hard-edged shapes) through the available passes and write a PNG.
    Demo(DemoArgs),
}

#[derive(clap::Args)]
pub struct Common {
    /// Run the CPU reference implementation instead of the GPU (no adapter needed).
    #[arg(long)]
    cpu: bool,
    /// Bake directory holding manifest.json and the LUTs.
    #[arg(long, value_name = "DIR", default_value = "baked")]
    baked: PathBuf,
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
    common: Common,
}

#[derive(clap::Args)]
pub struct MlaaArgs {
    #[command(flatten)]
    aa: AaArgs,
    /// Maximum distance N of the area map (the bake holds aa/mlaa/AreaMap{N}_v1.4.bin).
    #[arg(long, default_value_t = 33)]
    max_distance: u32,
}

#[derive(clap::Args)]
pub struct DemoArgs {
    /// Output PNG.
    #[arg(long, value_name = "PNG")]
    output: PathBuf,
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Antialiasing of the final frame: smaa, mlaa or none.
    #[arg(long, default_value = "smaa")]
    aa: String,
    #[command(flatten)]
    common: Common,
}

pub fn run(cmd: RunCommand, ctx: &Ctx) -> anyhow::Result<()> {
    match cmd {
        RunCommand::Smaa(a) => {
            check_output(&a.output)?;
            let img = read_png(&a.input)?;
            let aa = Antialiasing::Smaa(loader::load_smaa_textures(&a.common.baked).map_err(usage)?);
            antialias_file(ctx, &a, img, &aa, "smaa")
        }
        RunCommand::Mlaa(m) => {
            check_output(&m.aa.output)?;
            let map = load_mlaa(&m.aa.common.baked, m.max_distance)?;
            let img = read_png(&m.aa.input)?;
            antialias_file(ctx, &m.aa, img, &Antialiasing::Mlaa(map), "mlaa")
        }
        RunCommand::Demo(d) => demo(ctx, d),
    }
}

fn load_mlaa(baked: &Path, n: u32) -> anyhow::Result<MlaaAreaMap> {
    if n < 3 || n.is_multiple_of(2) {
        return Err(usage_msg(format!("--max-distance must be odd and >= 3 (e.g. 9, 17, 33, 65, 129), got {n}")));
    }
    let bytes = loader::load_mlaa_area(baked, n).map_err(usage)?;
    Ok(MlaaAreaMap::new(n, bytes)?)
}

/// The output's directory must exist and be writable before any work is done.
fn check_output(path: &Path) -> anyhow::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(usage_msg(format!("--output {}: directory {} does not exist", path.display(), dir.display())));
    }
    Ok(())
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

fn device(ctx: &Ctx, cpu: bool) -> anyhow::Result<Option<Gpu>> {
    if cpu {
        ctx.info("backend: CPU reference");
        return Ok(None);
    }
    let g = create_headless(&Default::default())?;
    ctx.info(format!("adapter: {}", g.describe()));
    Ok(Some(g))
}

fn antialias_file(ctx: &Ctx, a: &AaArgs, img: Image<u8>, aa: &Antialiasing, name: &str) -> anyhow::Result<()> {
    let gpu = device(ctx, a.common.cpu)?;
    let t = Instant::now();
    let out = chain::antialias(gpu.as_ref(), &img, aa)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    write_atomic(&a.output, &io::png::encode_u8(&out)?)?;
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

fn demo(ctx: &Ctx, d: DemoArgs) -> anyhow::Result<()> {
    check_output(&d.output)?;
    rtbake::error::check_size("--width/--height", d.width as u64, d.height as u64)?;
    let aa = match d.aa.as_str() {
        "smaa" => Some(Antialiasing::Smaa(loader::load_smaa_textures(&d.common.baked).map_err(usage)?)),
        "mlaa" => Some(Antialiasing::Mlaa(load_mlaa(&d.common.baked, 33)?)),
        "none" => None,
        other => return Err(usage_msg(format!("--aa must be smaa, mlaa or none, got {other:?}"))),
    };
    let gpu = device(ctx, d.common.cpu)?;
    let t = Instant::now();
    let frame = Image::from_vec(d.width, d.height, 4, scene::render_shapes(d.width, d.height, 1));
    let out = match &aa {
        Some(aa) => chain::antialias(gpu.as_ref(), &frame, aa)?,
        None => frame,
    };
    let ms = t.elapsed().as_secs_f64() * 1e3;
    write_atomic(&d.output, &io::png::encode_u8(&out)?)?;
    report(ctx, "demo", &d.output, &out, gpu.as_ref(), ms);
    Ok(())
}
