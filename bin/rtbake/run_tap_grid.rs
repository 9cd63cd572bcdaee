//! `rtbake run tap-grid`: TAP 2009's stimulus grid on a head (library: `rtbake::runtime::skin::tap_grid`).

use crate::cli::{usage, usage_msg, Ctx};
use crate::run_skin::{load_mesh, mesh_units_of, surface_maps, MapArgs, MeshOriginArg, StretchArg};
use rtbake::manifest::{BakedFile, FileMeta};
use rtbake::mesh::framing::head_height_units;
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::skin::tap_grid::{display_name, render_grid, TapGridSettings};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{self, StretchPreset};
use rtbake::runtime::texture_space::DEFAULT_MAP_SIZE;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub struct TapGridArgs {
    /// Output folder: frames/, differences/, fig4/, rmse.csv, rmse.json, contact_sheet.png, fig4_sweep.png.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Mesh (glTF 2.0 or OBJ with normals and texture coordinates); default: the procedural head.
    #[arg(long, value_name = "FILE")]
    mesh: Option<PathBuf>,
    /// What one unit of --mesh is: mm, cm, m, in, auto or a number of mm per unit (as `run skin`).
    #[arg(long, value_name = "UNITS")]
    mesh_units: Option<String>,
    /// Where --mesh's origin goes: bounds or authored (as `run skin`).
    #[arg(long, value_enum, default_value = "bounds")]
    mesh_origin: MeshOriginArg,
    #[command(flatten)]
    maps: MapArgs,
    /// SS Full's stretch preset (as `run skin --stretch`).
    #[arg(long, value_enum, default_value = "tap2009")]
    stretch: StretchArg,
    /// TS's irradiance map edge, texels, 32..=2048 (TAP: 1024).
    #[arg(long, default_value_t = DEFAULT_MAP_SIZE, allow_negative_numbers = true, value_name = "TEXELS")]
    ts_map_size: u32,
    /// Melanin volume fraction Cm, 0..=0.5.
    #[arg(long, default_value_t = 0.02, allow_negative_numbers = true)]
    melanin: f32,
    /// Frame width in pixels (TAP's stimuli: 1280×720 renders shown at 1650×988).
    #[arg(long, default_value_t = 640, value_name = "PIXELS")]
    width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 360, value_name = "PIXELS")]
    height: u32,
    /// Also render separable SSS (thesis ch. 6; not one of TAP's stimuli) under every condition: a fifth row of
    /// frames and differences and a fifth column of the RMSE table.
    #[arg(long)]
    separable: bool,
    #[command(flatten)]
    common: crate::run::Common,
}

pub fn run(ctx: &Ctx, a: TapGridArgs) -> anyhow::Result<()> {
    let units = mesh_units_of(&a.mesh_units, None)?;
    if a.mesh.is_none() && a.mesh_units.is_some() {
        return Err(usage_msg("--mesh-units applies to --mesh only".to_string()));
    }
    let stretch = match a.stretch {
        StretchArg::Thesis => StretchPreset::Thesis,
        StretchArg::Tap2009 => StretchPreset::Tap2009,
        StretchArg::Physical => StretchPreset::Physical,
    };
    // The procedural head's height stands in until the mesh is read: every check on sizes comes first.
    let mut settings = TapGridSettings {
        width: a.width,
        height: a.height,
        head_height_m: 0.23,
        stretch,
        ts_map_size: a.ts_map_size,
        melanin: a.melanin,
        separable: a.separable,
    };
    settings.validate().map_err(usage)?;
    let inputs: Vec<&Path> =
        a.mesh.iter().chain(&a.maps.albedo).chain(&a.maps.normal_map).map(|p| p.as_path()).collect();
    crate::cli::check_dir_name("--out", &a.out)?;
    let frames = settings.frames();
    let ts_frames =
        frames.iter().filter(|f| matches!(f.shader, rtbake::runtime::skin_render::SkinShader::Ts(_))).count();
    let time: f64 = frames
        .iter()
        .map(|f| rtbake::runtime::demo::time_estimate_seconds(f.width, f.height, a.common.cpu))
        .sum::<f64>()
        + ts_frames as f64 * 2.5e-6 * (a.ts_map_size as f64).powi(2);
    ctx.check_budget(
        &format!("--width {} --height {} --ts-map-size {} ({} frames)", a.width, a.height, a.ts_map_size, frames.len()),
        rtbake::runtime::demo::memory_estimate_bytes(a.width, a.height) * 2
            + (96 << 20)
            + rtbake::runtime::texture_space::memory_estimate_bytes(a.ts_map_size)
            + frames.len() as u64 * 8 * a.width as u64 * a.height as u64,
        time,
    )?;
    let mesh = match &a.mesh {
        Some(p) => load_mesh(p, units, a.mesh_origin, a.maps.uv_origin)?,
        None => default_head(),
    };
    settings.head_height_m = head_height_units(&mesh) * mesh.mm_per_unit / 1000.0;
    settings.validate().map_err(usage)?;
    let assets = DemoAssets::load(&a.common.baked).map_err(usage)?;
    let passes = SkinPasses { surface_maps: surface_maps(&a.maps, a.mesh.as_deref())?, ..SkinPasses::none() };
    let gpu = crate::run::device(ctx, a.common.cpu)?;
    if let Some(g) = &gpu {
        for f in &frames {
            skin_render::check_frame_fits(&g.device.limits(), f, &passes).map_err(usage)?;
        }
        if g.is_software() {
            let t: f64 = frames.iter().map(skin_render::software_adapter_time_estimate_seconds).sum();
            ctx.check_time(&format!("{} frames on a software adapter ({})", frames.len(), g.adapter_info.name), t)?;
        }
    }
    let t = Instant::now();
    let pb = ctx.progress(frames.len() as u64 + 3, "tap-grid");
    let grid = render_grid(gpu.as_ref(), &mesh, &settings, &passes, &assets, &|n| pb.set_position(n as u64))?;
    pb.finish_and_clear();
    let describe = serde_json::json!({
        "mesh": a.mesh.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "procedural head".into()),
        "triangles": mesh.triangle_count(),
        "adapter": gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU reference".into()),
        "surface_maps": passes.surface_maps.as_ref().map(|m| serde_json::json!({
            "albedo": m.albedo.as_ref().map(|t| [t.width, t.height]),
            "normal_map": m.normal.as_ref().map(|t| [t.width, t.height]),
        })),
        "fov_y_deg": settings.frame("ts", rtbake::mesh::framing::TapDistance::Near).camera().fov_y_deg,
    });
    let files: Vec<BakedFile> = grid
        .files(describe.clone())?
        .into_iter()
        .map(|(path, bytes)| {
            use rtbake::manifest::{FileFormat, FileKind};
            let (kind, format) = if path.ends_with(".png") {
                (FileKind::Frame, FileFormat::Png)
            } else if path.ends_with(".csv") {
                (FileKind::Csv, FileFormat::Csv)
            } else {
                (FileKind::Json, FileFormat::Json)
            };
            BakedFile { path, bytes, meta: FileMeta::text(kind, format, "") }
        })
        .collect();
    crate::cli::write_set(ctx, "--out", &a.out, &files, &inputs)?;
    let secs = t.elapsed().as_secs_f64();
    let means: Vec<String> =
        settings.shaders()[1..].iter().map(|sh| format!("{} {:.4}", display_name(sh), grid.mean_rmse(sh))).collect();
    ctx.info(format!(
        "tap-grid: {} frames + {} sweep frames at {}x{} in {secs:.1} s -> {}; mean RMSE vs TS: {}",
        grid.frames.len(),
        grid.sweep.len(),
        a.width,
        a.height,
        a.out.display(),
        means.join(", "),
    ));
    if ctx.json {
        ctx.emit_json(&grid.rmse_json(describe));
    }
    Ok(())
}
