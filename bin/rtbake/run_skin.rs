//! `rtbake run skin`: heads from a mesh through the skin chain (library: `rtbake::runtime::skin_render`, meshes:
//! `rtbake::mesh`).

use crate::cli::{usage, usage_msg, Ctx};
use rtbake::facial::wrinkles::GreenConvention;
use rtbake::io::{self, atomic::write_atomic};
use rtbake::mesh::framing::{head_height_units, to_metres, MeshOrigin, MeshUnits, TapDistance};
use rtbake::mesh::{gltf::parse_gltf, head::default_head, obj::parse_obj, Mesh, UvOrigin};
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::mesh_skin_inputs::RigPose;
use rtbake::runtime::skin::lighting::{SceneLights, TransmittanceMode};
use rtbake::runtime::skin::surface_maps::SurfaceMaps;
use rtbake::runtime::skin_passes::{SkinPasses, Wrinkles};
use rtbake::runtime::skin_render::{self, SkinRenderSettings, SkinShader, StretchPreset};
use rtbake::runtime::texture_space::{TsSettings, DEFAULT_MAP_SIZE};
use rtbake::runtime::wrinkle_pass::{parse_wrinkle_weights, WrinkleMaps};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Largest mesh file read, bytes (a scanned head with 10⁶ triangles is ~100 MB of glTF).
pub const MAX_MESH_FILE_BYTES: u64 = 512 << 20;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ShaderArg {
    /// Diffuse lighting, no subsurface scattering (TAP 2009's "No SSS").
    None,
    /// Screen-space sum of Gaussians with the baked fit (TAP 2009's "SS Full", thesis ch. 4).
    SsFull,
    /// Separable SSS with the baked kernel (thesis ch. 6).
    Separable,
    /// Hable et al.'s 13 jittered taps in one disk pass (TAP 2009's "SS Jittered"), derived from d'Eon's 6 Gaussians.
    SsJittered,
    /// d'Eon et al.'s texture-space diffusion (TAP 2009's "TS"): irradiance map in UV space, stretch map, the 6
    /// Gaussians of the baked fit, with the thesis ch. 3 optimisations of --ts-opt.
    Ts,
}

/// A thesis ch. 3 optimisation of the texture-space shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TsOptArg {
    /// None of them (d'Eon et al. 2007 as published).
    None,
    /// Culled irradiance map: texels more than 105° from the view vector are occluded, not blurred (§3.2).
    Cull,
    /// Depth-based irradiance map: edge scaled by min(d_ref/d, 1) per head (eq. 3.1–3.2).
    Depth,
    /// Clipped irradiance map: texels outside the view frustum are clipped (eq. 3.3–3.4).
    Clip,
    /// All three.
    All,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum StretchArg {
    Thesis,
    Tap2009,
    Physical,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MeshOriginArg {
    Bounds,
    Authored,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnOff {
    On,
    Off,
}

#[derive(clap::Args)]
pub struct SkinArgs {
    /// Output PNG (RGBA8, sRGB-encoded).
    #[arg(long, alias = "out", value_name = "PNG")]
    output: PathBuf,
    /// Skin shader.
    #[arg(long, value_enum, default_value = "separable")]
    shader: ShaderArg,
    /// Heads side by side, 0.25 m apart, 1..=16 (TAP 2009 Table III: 1, 3, 5).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    heads: u32,
    /// Camera distance from the heads' centre: metres (0.2..=100), or TAP 2009's zoom, near or far, which keep
    /// the paper's ratios to the head's height (28, 50 and 132 units for a 27-unit head; 30° vertical field of view).
    #[arg(long, default_value = "0.6", allow_hyphen_values = true, value_name = "M|zoom|near|far")]
    distance: String,
    /// Mesh: glTF 2.0 (.gltf with embedded or neighbouring buffers, .glb) or Wavefront OBJ, with vertex normals
    /// and texture coordinates (TEXCOORD_0 / vt); default: the procedural head (about 6 600 triangles).
    #[arg(long, value_name = "FILE")]
    mesh: Option<PathBuf>,
    /// What one unit of --mesh is: mm, cm, m, in, auto (the mesh is a y-up head or bust: its crown-to-neck height
    /// becomes an adult head's 230 mm, for scans in arbitrary units) or a number of mm per unit. Default: m (glTF's
    /// unit; OBJ has none).
    #[arg(long, value_name = "UNITS")]
    mesh_units: Option<String>,
    /// Millimetres per unit of --mesh (a number; the same as --mesh-units NUMBER).
    #[arg(long, allow_negative_numbers = true, conflicts_with = "mesh_units")]
    mesh_mm_per_unit: Option<f32>,
    /// Where --mesh's origin goes: bounds (its bounding-box centre is put where the camera looks, so any mesh is
    /// framed) or authored (the file's own origin).
    #[arg(long, value_enum, default_value = "bounds")]
    mesh_origin: MeshOriginArg,
    /// Stretch parameters of --shader ss-full: tap2009 (α = 11, β = 800, no clamp of the depth derivative, TAP
    /// 2009 §4; the default: TAP's SS Full ≈ TS was found with it), thesis (the bake's α, β, γ) — both stated for a
    /// 20° field of view and scaled to the camera's — or physical (α from the camera: each Gaussian at its width
    /// in mm, as TS and SS Jittered).
    #[arg(long, value_enum, default_value = "tap2009")]
    stretch: StretchArg,
    /// Irradiance map edge of --shader ts, texels, 32..=2048 (T_max with --ts-opt depth; default 1024).
    #[arg(long, allow_negative_numbers = true, value_name = "TEXELS")]
    ts_map_size: Option<u32>,
    /// Thesis ch. 3 optimisations of --shader ts, comma-separated: none, cull, depth, clip, all (default none).
    #[arg(long, value_enum, value_delimiter = ',')]
    ts_opt: Vec<TsOptArg>,
    /// Melanin volume fraction Cm of the skin, 0..=0.5.
    #[arg(long, default_value_t = 0.02, allow_negative_numbers = true)]
    melanin: f32,
    /// Frame width in pixels (TAP 2009 measured 1280×720).
    #[arg(long, default_value_t = 1280, value_name = "PIXELS")]
    width: u32,
    /// Frame height in pixels.
    #[arg(long, default_value_t = 720, value_name = "PIXELS")]
    height: u32,
    /// Hemoglobin rig pose (eq. 7.6) at the mesh's uv: a JSON object or a file holding one,
    /// {"target": weight, ..., "global": {"anger": a, "fear": f}}; target weights sum to 1, global weights in
    /// 0..=1 (g = 1 + a·(1.27 − 1) + f·(0.81 − 1), thesis §7.7). Default: {"neutral": 1}.
    #[arg(long, value_name = "FILE|JSON")]
    rig_weights: Option<String>,
    /// Wrinkle pass (thesis Listing 8.1) with the baked example PD map and zone masks: NAME=WEIGHT,... with NAME
    /// one of Table 8.1's expressions (joy, surprise, fear, anger, disgust, sad) and WEIGHT in 0..=1.
    #[arg(long, value_name = "WEIGHTS")]
    wrinkles: Option<String>,
    /// Bloom on the HDR frame before tone mapping (thesis ch. 4): threshold 1.0, weight 0.25, three Gaussians of
    /// 0.25 %, 0.6 % and 1.2 % of the frame height mixed 0.5/0.3/0.2 (`rtbake::runtime::bloom`).
    #[arg(long, value_enum, default_value = "on")]
    bloom: OnOff,
    /// Samples per pixel of the mesh G-buffer: 1 or 4 (MSAA, the standard 4× pattern; edges blended by coverage).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    msaa: u32,
    #[command(flatten)]
    maps: MapArgs,
    /// TAP 2009's single light (key light and transmitted light at once): azimuth around the head in degrees,
    /// -180..=180 (0 in front of the face on the camera's side, positive towards +x; TAP used 0, 60, 110, 150).
    /// Giving this or --light-elevation replaces the default key + back light pair.
    #[arg(long, allow_negative_numbers = true, value_name = "DEG")]
    light_azimuth: Option<f32>,
    /// Elevation of the single light above the horizontal, degrees, -90..=90 (TAP: 45; the default when only
    /// --light-azimuth is given).
    #[arg(long, allow_negative_numbers = true, value_name = "DEG")]
    light_elevation: Option<f32>,
    /// Light seen through thin parts, with the thickness from the back light's shadow map (Listing 5.1):
    /// shadow-map (the baked T(s) of eq. 5.12, the translucent-shadow-map path), green (Green's Beer-Lambert
    /// T(s) = exp(-s sigma_t) with Jensen 2001's skin1 sigma_t', thesis 5.3) or off.
    #[arg(long, value_enum, default_value = "shadow-map")]
    transmittance: TransmittanceArg,
    #[command(flatten)]
    common: crate::run::Common,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TransmittanceArg {
    Off,
    Green,
    ShadowMap,
}

/// A scanned head's maps (shared by `run skin` and `run tap-grid`).
#[derive(clap::Args)]
pub struct MapArgs {
    /// Albedo map (PNG or JPEG, sRGB, RGB or RGBA) read at the mesh's uv and applied after the diffusion
    /// (post-scatter texturing, thesis §7.6), replacing the skin LUT's albedo. Default: the glTF material's
    /// base-colour texture when --mesh has one.
    #[arg(long, value_name = "FILE")]
    pub(crate) albedo: Option<PathBuf>,
    /// Tangent-space normal map (PNG or JPEG, linear, RGB or RGBA, c = 0.5 + 0.5·n) in the mesh's MikkTSpace frame.
    /// Default: the glTF material's normal texture when --mesh has one.
    #[arg(long, value_name = "FILE")]
    pub(crate) normal_map: Option<PathBuf>,
    /// Green channel of the normal map: opengl (+y up the texture: glTF's convention and the three.js scan's) or
    /// directx (+y down the texture).
    #[arg(long, value_enum, default_value = "opengl")]
    normal_green: GreenArg,
    /// Where v = 0 of --mesh's texture coordinates lies in --albedo/--normal-map: format (the format's own
    /// convention: glTF top-left, OBJ bottom-left), top-left or bottom-left. The three.js distribution of the
    /// Lee Perry-Smith scan is a glTF with bottom-left texture coordinates (three.js loads its maps with flipY):
    /// read as glTF, its lips land on the chin and its eyebrows on the neck.
    #[arg(long, value_enum, default_value = "format")]
    pub(crate) uv_origin: UvOriginArg,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum UvOriginArg {
    Format,
    TopLeft,
    BottomLeft,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum GreenArg {
    Opengl,
    Directx,
}

/// A map file of `flag` decoded with its own channel count (exit 2 naming the flag and the file).
fn read_picture(param: &str, path: &Path) -> anyhow::Result<rtbake::image_buf::ImageU8> {
    let name = format!("{} {}", crate::flags::render_param(param), path.display());
    let len = std::fs::metadata(path).map_err(|e| usage_msg(format!("{name}: {e}")))?.len();
    if len > MAX_MESH_FILE_BYTES {
        return Err(usage_msg(format!("{name}: {len} bytes; accepted at most {MAX_MESH_FILE_BYTES}")));
    }
    let bytes = std::fs::read(path).map_err(|e| usage_msg(format!("{name}: {e}")))?;
    io::picture::decode_u8(param, &path.display().to_string(), &bytes).map_err(usage)
}

/// The surface maps of --albedo / --normal-map, or the glTF material's own textures where a flag is absent
/// (exit 2 naming the flag or the mesh); None when there are none.
pub fn surface_maps(a: &MapArgs, mesh: Option<&Path>) -> anyhow::Result<Option<SurfaceMaps>> {
    use rtbake::runtime::skin::surface_maps::{ALBEDO_PARAM, NORMAL_MAP_PARAM};
    let mut albedo = a.albedo.as_deref().map(|p| read_picture(ALBEDO_PARAM, p)).transpose()?;
    let mut normal = a.normal_map.as_deref().map(|p| read_picture(NORMAL_MAP_PARAM, p)).transpose()?;
    let gltf = mesh.filter(|p| {
        matches!(p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(), Some("gltf" | "glb"))
    });
    if let (Some(path), true) = (gltf, albedo.is_none() || normal.is_none()) {
        let name = format!("--mesh {}", path.display());
        let bytes = std::fs::read(path).map_err(|e| usage_msg(format!("{name}: {e}")))?;
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let images = rtbake::mesh::gltf::material_images(&name, &bytes, &|uri: &str| {
            std::fs::read(dir.join(uri)).map_err(|e| format!("{uri}: {e}"))
        })
        .map_err(usage)?;
        let decode = |param: &str, img: &rtbake::mesh::gltf::EncodedImage| {
            io::picture::decode_u8(param, &format!("{name}: {}", img.origin), &img.bytes).map_err(usage)
        };
        if albedo.is_none() {
            albedo = images.base_color.as_ref().map(|i| decode(ALBEDO_PARAM, i)).transpose()?;
        }
        if normal.is_none() {
            normal = images.normal.as_ref().map(|i| decode(NORMAL_MAP_PARAM, i)).transpose()?;
        }
    }
    if albedo.is_none() && normal.is_none() {
        return Ok(None);
    }
    let green = match a.normal_green {
        GreenArg::Opengl => GreenConvention::OpenGl,
        GreenArg::Directx => GreenConvention::DirectX,
    };
    Ok(Some(SurfaceMaps::from_pictures(albedo.as_ref(), normal.as_ref(), green).map_err(usage)?))
}

/// A JSON argument given inline (starting with `{`) or as a file name (exit 2 naming `flag`).
fn json_arg(flag: &str, v: &str) -> anyhow::Result<serde_json::Value> {
    let text = if v.trim_start().starts_with('{') {
        v.to_string()
    } else {
        std::fs::read_to_string(v).map_err(|e| usage_msg(format!("{flag} {v}: {e}")))?
    };
    serde_json::from_str(&text).map_err(|e| usage_msg(format!("{flag}: not valid JSON: {e}")))
}

/// The passes around the SSS shader from the flags (exit 2 naming the flag).
fn passes(a: &SkinArgs, assets: &DemoAssets) -> anyhow::Result<SkinPasses> {
    let mut p = SkinPasses::default();
    if let Some(v) = &a.rig_weights {
        let json = json_arg("--rig-weights", v)?;
        rtbake::facial::hemoglobin_rig::check_pose_json("--rig-weights", &json).map_err(usage)?;
        let rig = assets.baked_rig.as_ref().ok_or_else(|| {
            usage_msg("--rig-weights needs the hemoglobin rig in the bake directory (facial/hemoglobin/example)")
        })?;
        p.rig_pose = Some(RigPose::for_baked_rig(&json, rig).map_err(usage)?);
    }
    rtbake::runtime::mesh_raster::check_samples(a.msaa).map_err(usage)?;
    p.msaa = a.msaa;
    if a.bloom == OnOff::Off {
        p.bloom = None;
    }
    if let Some(v) = &a.wrinkles {
        let zone_weights = parse_wrinkle_weights(v).map_err(usage)?;
        let maps = WrinkleMaps::load(&a.common.baked).map_err(|e| usage_msg(format!("--wrinkles: {e}")))?;
        p.wrinkles = Some(Wrinkles { maps: maps.into(), zone_weights });
    }
    Ok(p)
}

/// Reads and validates `--mesh` (exit 2 naming the file and the defect), re-reads its texture coordinates with
/// `uv_origin` (`--uv-origin`), then puts it in metres (`units`) with its bounding-box centre at the origin unless
/// `origin` is authored.
pub fn load_mesh(path: &Path, units: MeshUnits, origin: MeshOriginArg, uv_origin: UvOriginArg) -> anyhow::Result<Mesh> {
    let name = format!("--mesh {}", path.display());
    let meta = std::fs::metadata(path).map_err(|e| usage_msg(format!("{name}: {e}")))?;
    if meta.len() > MAX_MESH_FILE_BYTES {
        return Err(usage_msg(format!("{name}: {} bytes; accepted at most {MAX_MESH_FILE_BYTES}", meta.len())));
    }
    let bytes = std::fs::read(path).map_err(|e| usage_msg(format!("{name}: {e}")))?;
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mesh = match ext.as_deref() {
        Some("gltf") | Some("glb") => parse_gltf(&name, &bytes, &|uri: &str| {
            let p = dir.join(uri);
            let len = std::fs::metadata(&p).map_err(|e| format!("{}: {e}", p.display()))?.len();
            if len > MAX_MESH_FILE_BYTES {
                return Err(format!("{}: {len} bytes; accepted at most {MAX_MESH_FILE_BYTES}", p.display()));
            }
            std::fs::read(&p).map_err(|e| format!("{}: {e}", p.display()))
        }),
        Some("obj") => parse_obj(&name, &bytes, 1000.0),
        _ => return Err(usage_msg(format!("{name}: unknown extension; accepted .gltf, .glb, .obj"))),
    };
    // The parsers read each format's own convention into this crate's top-left one.
    let parsed_as = UvOrigin::of_format(ext.as_deref() != Some("obj"));
    let file_origin = match uv_origin {
        UvOriginArg::Format => parsed_as,
        UvOriginArg::TopLeft => UvOrigin::TopLeft,
        UvOriginArg::BottomLeft => UvOrigin::BottomLeft,
    };
    let mesh = mesh.map_err(usage)?.with_uv_origin(parsed_as, file_origin);
    let origin = match origin {
        MeshOriginArg::Bounds => MeshOrigin::Head,
        MeshOriginArg::Authored => MeshOrigin::Authored,
    };
    let framed = to_metres(&mesh, units, origin, "--mesh-units");
    framed.map_err(usage)
}

/// The units of --mesh from --mesh-units / --mesh-mm-per-unit (default metres).
pub fn mesh_units_of(mesh_units: &Option<String>, mesh_mm_per_unit: Option<f32>) -> anyhow::Result<MeshUnits> {
    match (mesh_units, mesh_mm_per_unit) {
        (Some(u), _) => MeshUnits::parse("--mesh-units", u).map_err(usage),
        (None, Some(v)) => {
            if !(v.is_finite() && v > 0.0) {
                return Err(usage_msg(format!("--mesh-mm-per-unit must be a finite number > 0, got {v}")));
            }
            MeshUnits::parse("--mesh-mm-per-unit", &v.to_string()).map_err(usage)
        }
        (None, None) => Ok(MeshUnits::Metres),
    }
}

/// --distance: metres, or TAP 2009's named distance for a head `height_m` tall.
fn camera_distance(v: &str, height_m: f32) -> anyhow::Result<(f32, Option<TapDistance>)> {
    if let Some(d) = TapDistance::parse(v.trim()) {
        return Ok((d.camera_distance_m(height_m), Some(d)));
    }
    let m: f32 = v.trim().parse().map_err(|_| {
        usage_msg(format!("--distance {v:?}: accepted a number of metres in 0.2..=100, or zoom, near, far (TAP 2009)"))
    })?;
    Ok((m, None))
}

/// The texture-space settings of `a` (validated: --ts-map-size in range).
fn ts_settings(a: &SkinArgs) -> anyhow::Result<TsSettings> {
    let has = |o| a.ts_opt.contains(&o) || a.ts_opt.contains(&TsOptArg::All);
    if a.ts_opt.contains(&TsOptArg::None) && a.ts_opt.len() > 1 {
        return Err(usage_msg("--ts-opt none cannot be combined with other optimisations".to_string()));
    }
    let ts = TsSettings {
        map_size: a.ts_map_size.unwrap_or(DEFAULT_MAP_SIZE),
        cull: has(TsOptArg::Cull),
        depth_sized: has(TsOptArg::Depth),
        clip: has(TsOptArg::Clip),
    };
    ts.validate().map_err(usage)?;
    Ok(ts)
}

pub fn run(ctx: &Ctx, a: SkinArgs) -> anyhow::Result<()> {
    let units = mesh_units_of(&a.mesh_units, a.mesh_mm_per_unit)?;
    if a.mesh.is_none() && (a.mesh_units.is_some() || a.mesh_mm_per_unit.is_some()) {
        return Err(usage_msg("--mesh-units and --mesh-mm-per-unit apply to --mesh only".to_string()));
    }
    // Named distances need the head's height: the procedural head's is known without reading a file.
    let provisional = camera_distance(&a.distance, 0.23)?;
    let mut settings = SkinRenderSettings {
        shader: match a.shader {
            ShaderArg::None => SkinShader::None,
            ShaderArg::SsFull => SkinShader::SsFull,
            ShaderArg::Separable => SkinShader::Separable,
            ShaderArg::SsJittered => SkinShader::SsJittered,
            ShaderArg::Ts => SkinShader::Ts(ts_settings(&a)?),
        },
        heads: a.heads,
        distance_m: provisional.0,
        width: a.width,
        height: a.height,
        melanin: a.melanin,
        stretch: match a.stretch {
            StretchArg::Thesis => StretchPreset::Thesis,
            StretchArg::Tap2009 => StretchPreset::Tap2009,
            StretchArg::Physical => StretchPreset::Physical,
        },
    };
    if !matches!(a.shader, ShaderArg::Ts) && (a.ts_map_size.is_some() || !a.ts_opt.is_empty()) {
        return Err(usage_msg("--ts-map-size and --ts-opt apply to --shader ts only".to_string()));
    }
    settings.validate().map_err(usage)?;
    let single_light = (a.light_azimuth.is_some() || a.light_elevation.is_some()).then(|| {
        let az = a.light_azimuth.unwrap_or(rtbake::mesh::framing::TAP_LIGHT_AZIMUTHS_DEG[0]);
        (az, a.light_elevation.unwrap_or(rtbake::mesh::framing::TAP_LIGHT_ELEVATION_DEG))
    });
    if let Some((az, el)) = single_light {
        SceneLights::single(az, el, &settings.camera()).map_err(usage)?;
    }
    let inputs: Vec<&Path> =
        a.mesh.iter().chain(&a.maps.albedo).chain(&a.maps.normal_map).map(|p| p.as_path()).collect();
    crate::run::check_output_of(&a.output, &inputs)?;
    ctx.check_budget(
        &format!("--width {} --height {}", a.width, a.height),
        rtbake::runtime::demo::memory_estimate_bytes(a.width, a.height)
            + (96 << 20)
            + match settings.shader {
                SkinShader::Ts(ts) => rtbake::runtime::texture_space::memory_estimate_bytes(ts.map_size),
                _ => 0,
            },
        rtbake::runtime::demo::time_estimate_seconds(a.width, a.height, a.common.cpu) + 0.5,
    )?;
    let mesh = match &a.mesh {
        Some(p) => load_mesh(p, units, a.mesh_origin, a.maps.uv_origin)?,
        None => default_head(),
    };
    let head_height_m = head_height_units(&mesh) * mesh.mm_per_unit / 1000.0;
    if a.mesh.is_some() && !(0.1..=0.5).contains(&head_height_m) {
        ctx.info(format!(
            "note: --mesh is {:.0} mm tall read as {units:?}; a head is about 230 mm (give --mesh-units: {})",
            head_height_m * 1000.0,
            MeshUnits::ACCEPTED
        ));
    }
    let (distance_m, named) = camera_distance(&a.distance, head_height_m)?;
    settings.distance_m = distance_m;
    settings.validate().map_err(usage)?;
    let mut assets = DemoAssets::load(&a.common.baked).map_err(usage)?;
    assets.set_transmittance(match a.transmittance {
        TransmittanceArg::Off => TransmittanceMode::Off,
        TransmittanceArg::Green => TransmittanceMode::green_skin1(),
        TransmittanceArg::ShadowMap => TransmittanceMode::ShadowMap,
    });
    if let Some((az, el)) = single_light {
        assets.lights = SceneLights::single(az, el, &settings.camera()).map_err(usage)?;
    }
    let mut passes = passes(&a, &assets)?;
    passes.surface_maps = surface_maps(&a.maps, a.mesh.as_deref())?;
    let gpu = crate::run::device(ctx, a.common.cpu)?;
    if let Some(g) = &gpu {
        // Every pass against the adapter's limits before any work (the CPU twins have none).
        skin_render::check_frame_fits(&g.device.limits(), &settings, &passes).map_err(usage)?;
        if g.is_software() {
            ctx.check_time(
                &format!("--width {} --height {} on a software adapter ({})", a.width, a.height, g.adapter_info.name),
                skin_render::software_adapter_time_estimate_seconds(&settings),
            )?;
        }
    }
    let t = Instant::now();
    let out = skin_render::render_with(gpu.as_ref(), &mesh, &settings, &passes, &assets)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    write_atomic(&a.output, &io::png::encode_u8_frame(&out)?)?;
    ctx.info(format!(
        "skin ({:?}, {} head(s), {} triangles each): {}x{} in {ms:.1} ms -> {}",
        a.shader,
        a.heads,
        mesh.triangle_count(),
        out.width,
        out.height,
        a.output.display()
    ));
    if ctx.json {
        ctx.emit_json(&serde_json::json!({
            "pass": "skin",
            "shader": format!("{:?}", a.shader),
            "heads": a.heads,
            "triangles_per_head": mesh.triangle_count(),
            "output": a.output.display().to_string(),
            "width": out.width,
            "height": out.height,
            "adapter": gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU reference".into()),
            "camera": {
                "distance_m": distance_m,
                "tap_distance": named.map(|d| d.name()),
                "fov_y_deg": settings.camera().fov_y_deg,
                "viewport": [out.width, out.height],
                "head_height_mm": head_height_m * 1000.0,
            },
            "light": match single_light {
                Some((az, el)) => serde_json::json!({
                    "kind": "single (TAP 2009)", "azimuth_deg": az, "elevation_deg": el,
                    "direction_view": assets.lights.key_view,
                }),
                None => serde_json::json!({
                    "kind": "key + back (default)", "key_view": assets.lights.key_view,
                    "back_view": assets.lights.back_view,
                }),
            },
            "ss_full_stretch": matches!(a.shader, ShaderArg::SsFull).then(|| {
                let p = settings.stretch.apply(assets.gaussian_params, settings.camera().fov_y_deg);
                let v = p.for_viewport_height(out.height);
                serde_json::json!({
                    "preset": format!("{:?}", a.stretch).to_lowercase(),
                    "alpha_stated_for": {"fov_y_deg": rtbake::runtime::skin_render::ALPHA_FOV_DEG, "viewport_height": 720},
                    "alpha_at_720px": p.alpha, "alpha_at_viewport": v.alpha, "beta": p.beta,
                    "gamma": if p.gamma == f32::MAX { None } else { Some(p.gamma) },
                })
            }),
            "surface_maps": passes.surface_maps.as_ref().map(|m| serde_json::json!({
                "albedo": m.albedo.as_ref().map(|t| [t.width, t.height]),
                "normal_map": m.normal.as_ref().map(|t| [t.width, t.height]),
                "tangents": "mikktspace",
                "texturing": "post-scatter (thesis 7.6)",
            })),
            "transmittance": format!("{:?}", a.transmittance).to_lowercase(),
            "wall_ms": ms,
        }));
    }
    Ok(())
}
