//! Facial appearance maps in `baked/facial/`: an example hemoglobin appearance rig built from the project's
//! synthetic maps (thesis ch. 7), the Table 8.1 wrinkle weights preset and an example wrinkle map / mask set
//! (thesis ch. 8). Also the file encoders shared with `rtbake maps` (the CLI writes the same files).

use super::{json_file, parse_params, unorm8_texture_files, Asset, BakeError, BakedFile, FileMeta};
use crate::facial::disk_stats::Border;
use crate::facial::hemoglobin_rig::{self, HemoglobinRig, RigSettings};
use crate::facial::{synthetic, wrinkles};
use crate::image_buf::Image;
use crate::io::{self, exr::ExrPrecision, PixelFormat};
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

pub use crate::baked_layout::path::{RIG_EXAMPLE_DIR, WRINKLES_DIR};
pub use crate::baked_layout::schema::HEMOGLOBIN_RIG as RIG_SCHEMA;
pub use crate::baked_layout::{rig_from_description, RigDescription, RigH0Files, RigMapFiles, RigSource};

#[allow(clippy::too_many_arguments)]
fn float_meta(
    format: FileFormat,
    st: SampleType,
    w: u32,
    h: u32,
    ch: u32,
    pf: Option<PixelFormat>,
    conv: &str,
    tol: f64,
) -> FileMeta {
    FileMeta {
        kind: FileKind::Lut,
        format,
        pixel_format: pf,
        width: w,
        height: h,
        channels: ch,
        sample_type: st,
        color_space: ColorSpace::Linear,
        convention: conv.into(),
        verify_tolerance: Some(tol),
        supercompression: None,
    }
}

fn preview_file(
    path: String,
    w: u32,
    h: u32,
    values: &[f32],
    lo: f64,
    hi: f64,
    what: &str,
) -> Result<BakedFile, BakeError> {
    let data = values.iter().map(|&v| wrinkles::encode_unorm8((v as f64 - lo) / (hi - lo))).collect();
    let bytes = io::png::encode_u8(&Image::from_vec(w, h, 1, data))?;
    let meta = FileMeta {
        kind: FileKind::Preview,
        format: FileFormat::Png,
        pixel_format: None,
        width: w,
        height: h,
        channels: 1,
        sample_type: SampleType::U8,
        color_space: ColorSpace::Linear,
        convention: format!("viewing only: gray = ({what} - {lo}) / ({hi} - {lo}), clamped; not for sampling"),
        verify_tolerance: Some(1.0),
        supercompression: None,
    };
    Ok(BakedFile { path, bytes, meta })
}

/// Encodes the float map files of one single-channel map: `{stem}.exr` (f32, one `Y` channel, for engines that
/// read named channels), `{stem}_f16.exr`, and `{stem}_rgb.exr` (f32 `R`,`G`,`B` with the value in R and
/// G = B = 0): the layout the `image` crate's EXR decoder, and so Bevy's EXR loader, requires.
fn exr_pair(dir: &str, stem: &str, w: u32, h: u32, v: &[f32], conv: &str) -> Result<Vec<BakedFile>, BakeError> {
    let img = Image::from_vec(w, h, 1, v.to_vec());
    let rgb = Image::from_vec(w, h, 3, v.iter().flat_map(|&x| [x, 0.0, 0.0]).collect());
    let rgb_conv = format!("{conv}; value in R, G = B = 0 (RGB EXR for the image crate / Bevy)");
    Ok(vec![
        BakedFile {
            path: format!("{dir}{stem}_rgb.exr"),
            bytes: io::exr::encode(&rgb, ExrPrecision::F32)?,
            meta: float_meta(FileFormat::Exr, SampleType::F32, w, h, 3, None, &rgb_conv, 1e-6),
        },
        BakedFile {
            path: format!("{dir}{stem}.exr"),
            bytes: io::exr::encode(&img, ExrPrecision::F32)?,
            meta: float_meta(FileFormat::Exr, SampleType::F32, w, h, 1, None, conv, 1e-6),
        },
        BakedFile {
            path: format!("{dir}{stem}_f16.exr"),
            bytes: io::exr::encode(&img, ExrPrecision::F16)?,
            meta: float_meta(FileFormat::Exr, SampleType::F16, w, h, 1, None, conv, 1e-3),
        },
    ])
}

fn min_max(v: &[f32]) -> (f64, f64) {
    let lo = v.iter().fold(f64::INFINITY, |a, &b| a.min(b as f64));
    let hi = v.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b as f64));
    if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5, lo + 0.5)
    }
}

/// All files of a rig, paths prefixed by `dir` (e.g. `facial/hemoglobin/example/` or empty), plus the
/// description written to `{dir}rig.json`. `made_by` names the command that made them (recorded as `generated_by`).
pub fn hemoglobin_rig_files(
    rig: &HemoglobinRig,
    made_by: &str,
    dir: &str,
    sources: &[RigSource],
    value_unit: &str,
) -> Result<(Vec<BakedFile>, RigDescription), BakeError> {
    assert_eq!(sources.len(), rig.maps.len(), "one source per rig map");
    let (w, h, rw, rh) = (rig.width, rig.height, rig.rig_width, rig.rig_height);
    let mut files = Vec::new();

    // H0 at full resolution.
    let h0_conv = "H0 = Hn - bilinear(neutral bias), full resolution, top row first, concentration units (eq. 7.4)";
    files.extend(exr_pair(dir, "h0", w, h, &rig.h0, h0_conv)?);
    let h0_img = Image::from_vec(w, h, 1, rig.h0.clone());
    files.push(BakedFile {
        path: format!("{dir}h0.ktx2"),
        bytes: io::ktx2::encode_f16(&h0_img)?,
        meta: float_meta(FileFormat::Ktx2, SampleType::F16, w, h, 1, Some(PixelFormat::R16Sfloat), h0_conv, 1e-3),
    });
    let amp = rig.h0.iter().fold(0.0f64, |a, &b| a.max((b as f64).abs())).max(1e-12);
    files.push(preview_file(format!("{dir}h0_preview.png"), w, h, &rig.h0, -amp, amp, "H0")?);

    // Shared preview range of all biases.
    let (mut blo, mut bhi) = (f64::INFINITY, f64::NEG_INFINITY);
    for m in &rig.maps {
        let (a, b) = min_max(&m.bias);
        blo = blo.min(a);
        bhi = bhi.max(b);
    }
    let mut maps = Vec::new();
    for (i, (m, src)) in rig.maps.iter().zip(sources).enumerate() {
        let n = &m.name;
        let sc = format!("scale_{i} ({n}) = sigma_{n} / max(sigma_neutral, eps), {rw}x{rh} area-downsampled (eq. 7.5)");
        let bc = format!("bias_{i} ({n}) = mu_{n}, {rw}x{rh} area-downsampled, concentration units (eq. 7.5)");
        files.extend(exr_pair(dir, &format!("{n}_scale"), rw, rh, &m.scale, &sc)?);
        files.extend(exr_pair(dir, &format!("{n}_bias"), rw, rh, &m.bias, &bc)?);
        let packed: Vec<f32> = m.scale.iter().zip(&m.bias).flat_map(|(&s, &b)| [s, b]).collect();
        files.push(BakedFile {
            path: format!("{dir}{n}_scale_bias.ktx2"),
            bytes: io::ktx2::encode_f16(&Image::from_vec(rw, rh, 2, packed))?,
            meta: float_meta(
                FileFormat::Ktx2,
                SampleType::F16,
                rw,
                rh,
                2,
                Some(PixelFormat::R16G16Sfloat),
                &format!("R = scale_{i}, G = bias_{i} ({n}); {rw}x{rh}, sample bilinearly with clamp-to-edge"),
                1e-3,
            ),
        });
        files.push(preview_file(format!("{dir}{n}_scale_preview.png"), rw, rh, &m.scale, 0.0, 2.0, "scale")?);
        files.push(preview_file(format!("{dir}{n}_bias_preview.png"), rw, rh, &m.bias, blo, bhi, "bias")?);
        maps.push(RigMapFiles {
            index: i,
            name: n.clone(),
            scale_exr: format!("{n}_scale.exr"),
            scale_exr_f16: format!("{n}_scale_f16.exr"),
            bias_exr: format!("{n}_bias.exr"),
            bias_exr_f16: format!("{n}_bias_f16.exr"),
            scale_bias_ktx2: format!("{n}_scale_bias.ktx2"),
            scale_preview: format!("{n}_scale_preview.png"),
            bias_preview: format!("{n}_bias_preview.png"),
            source: src.clone(),
        });
    }
    let mut global = serde_json::Map::new();
    for (k, v) in hemoglobin_rig::THESIS_GLOBAL_SCALES {
        global.insert(k.into(), json!(v));
    }
    let desc = RigDescription {
        schema: RIG_SCHEMA.into(),
        generated_by: format!("rtbake {} from {made_by}; do not edit", env!("CARGO_PKG_VERSION")),
        model: "Jimenez et al. 2010, 'A practical appearance model for dynamic facial color' (thesis ch. 7, eq. 7.1-7.6)".into(),
        evaluation: "H = g * (sum_i w_i * bias_i + H0 * sum_i w_i * scale_i), weights w_i over maps[] summing to 1 (eq. 7.6); \
                     g = 1 or a global state factor (global_scales); maps[0] is the neutral map (scale = 1, bias = mu_neutral)"
            .into(),
        sampling: format!(
            "scale/bias maps are {rw}x{rh}, H0 is {w}x{h}; all cover UV [0,1]^2 with texel centres at (i+0.5)/size, top row first; \
             read scale/bias with bilinear filtering and clamp-to-edge addressing"
        ),
        radius_texels: rig.settings.radius_texels,
        border: rig.settings.border,
        sigma_floor: rig.settings.sigma_floor,
        sigma_floored_texels: rig.sigma_floored_texels,
        full_size: [w, h],
        rig_size: [rw, rh],
        value_unit: value_unit.into(),
        h0: RigH0Files {
            definition: "H0 = Hn - bilinear(bias_0 as stored in f32), so w_neutral = 1 reproduces Hn (eq. 7.4 with the stored mu_n)".into(),
            exr: "h0.exr".into(),
            exr_f16: "h0_f16.exr".into(),
            ktx2: "h0.ktx2".into(),
            preview: "h0_preview.png".into(),
            preview_range: [-amp, amp],
        },
        maps,
        global_scales: global,
        previews: "8-bit gray, linear, for viewing only: scale previews map [0, 2]; bias previews share one range (see each file's manifest convention)".into(),
    };
    let value = serde_json::to_value(&desc).map_err(|e| BakeError::Other(e.to_string()))?;
    files.push(json_file(
        &crate::baked_layout::path::rig_description(dir),
        &value,
        FileKind::Json,
        &format!("hemoglobin rig description (schema {RIG_SCHEMA})"),
    ));
    Ok((files, desc))
}

/// Parameters of the example rig asset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigExampleParams {
    /// Edge of the synthetic maps in texels.
    pub size: u32,
    pub seed: u32,
    /// Synthetic expressions used as targets (see `facial::synthetic::EXPRESSIONS`).
    pub targets: Vec<String>,
    pub radius_texels: u32,
    pub border: Border,
    pub sigma_floor: f64,
    pub rig_size: u32,
}

impl Default for RigExampleParams {
    fn default() -> Self {
        Self {
            size: 128,
            seed: 1,
            targets: ["joy", "anger", "fear", "disgust"].iter().map(|s| s.to_string()).collect(),
            radius_texels: 8,
            border: Border::Clip,
            sigma_floor: 1e-4,
            rig_size: 32,
        }
    }
}

fn bake_rig_example(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: RigExampleParams = parse_params("hemoglobin-rig-example", params)?;
    crate::error::check_range("size", p.size, 3, 1024, "texels")?;
    let set = synthetic::hemoglobin_set("targets", p.size, p.seed, &p.targets)?;
    let dir = format!("{RIG_EXAMPLE_DIR}/");
    let mut files = Vec::new();
    let mut sources = Vec::new();
    let conc: Vec<(String, Vec<f32>)> =
        set.iter().map(|(n, img)| (n.clone(), synthetic::u16_to_concentration(img))).collect();
    for (name, img) in &set {
        let path = format!("{dir}input/{name}.png");
        files.push(BakedFile {
            path: path.clone(),
            bytes: io::png::encode_u16(img)?,
            meta: FileMeta {
                kind: FileKind::Input,
                format: FileFormat::Png,
                pixel_format: None,
                width: img.width,
                height: img.height,
                channels: 1,
                sample_type: SampleType::U16,
                color_space: ColorSpace::Linear,
                convention: "synthetic hemoglobin map: dermal volume fraction = sample / 65535".into(),
                verify_tolerance: None,
                supercompression: None,
            },
        });
        sources.push(RigSource {
            name: name.clone(),
            source: format!("input/{name}.png (synthetic, seed {})", p.seed),
            format: "png16".into(),
            mapping: "concentration = 0 + (1 - 0) * s / 65535".into(),
        });
    }
    let settings = RigSettings {
        radius_texels: p.radius_texels,
        border: p.border,
        sigma_floor: p.sigma_floor,
        rig_size: p.rig_size,
    };
    let targets: Vec<(String, &[f32])> = conc[1..].iter().map(|(n, v)| (n.clone(), v.as_slice())).collect();
    let rig = hemoglobin_rig::build_rig(&conc[0].1, p.size, p.size, &targets, &settings)?;
    let (rig_files, _) = hemoglobin_rig_files(
        &rig,
        "`rtbake bake hemoglobin-rig-example`",
        &dir,
        &sources,
        "dermal hemoglobin volume fraction",
    )?;
    files.extend(rig_files);
    Ok(files)
}

/// Parameters of the example wrinkle asset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WrinkleExampleParams {
    /// Edge of the synthetic normal map and masks.
    pub size: u32,
    /// Slope multiplier of the synthetic wrinkles.
    pub strength: f64,
    /// Stored wrinkle map edge (thesis: 256).
    pub wrinkle_size: u32,
    /// Stored mask edge (thesis: 64).
    pub mask_size: u32,
}

impl Default for WrinkleExampleParams {
    fn default() -> Self {
        Self { size: 256, strength: 1.0, wrinkle_size: 128, mask_size: 64 }
    }
}

/// Manifest convention of a PD map.
pub const PD_CONVENTION: &str =
    "partial-derivative normal map (thesis ch. 8): R = nx/nz, G = ny/nz stored as 0.5 + 0.5*pd; \
     reconstruct n = normalize(2*rg - 1, 1); DirectX green convention (+y towards increasing v)";

/// Manifest convention of mask textures.
pub fn mask_convention(index: usize) -> String {
    let zones = &wrinkles::ZONES[index * 4..index * 4 + 4];
    format!(
        "wrinkle zone masks (thesis Table 8.1): R = {}, G = {}, B = {}, A = {}; values 0..1",
        zones[0], zones[1], zones[2], zones[3]
    )
}

fn bake_wrinkle_example(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: WrinkleExampleParams = parse_params("wrinkle-maps-example", params)?;
    crate::error::check_range("size", p.size, 1, 2048, "texels")?;
    crate::error::check_range("wrinkle_size", p.wrinkle_size, 1, 4096, "texels")?;
    crate::error::check_range("mask_size", p.mask_size, 1, 4096, "texels")?;
    crate::error::check_range("strength", p.strength, 0.0, 10.0, "")?;
    let dir = format!("{}/", crate::baked_layout::path::WRINKLE_EXAMPLE_DIR);
    let normal = synthetic::wrinkle_normal_map(p.size, p.strength);
    let mut files = vec![BakedFile {
        path: format!("{dir}input/wrinkle_normal.png"),
        bytes: io::png::encode_u8(&normal)?,
        meta: FileMeta {
            kind: FileKind::Input,
            format: FileFormat::Png,
            pixel_format: None,
            width: p.size,
            height: p.size,
            channels: 3,
            sample_type: SampleType::U8,
            color_space: ColorSpace::Linear,
            convention: "synthetic tangent-space normal map, n = 2*rgb/255 - 1, DirectX green convention".into(),
            verify_tolerance: None,
            supercompression: None,
        },
    }];
    let decoded = Image::from_vec(
        p.size,
        p.size,
        3,
        normal.data.iter().map(|&s| (2.0 * s as f64 / 255.0 - 1.0) as f32).collect(),
    );
    let (pd_files, wrinkle_report, _) = pd_wrinkle_files(
        &dir,
        &decoded,
        None,
        wrinkles::GreenConvention::DirectX,
        wrinkles::ConeMode::Clamp,
        p.wrinkle_size,
    )?;
    files.extend(pd_files);
    let masks = synthetic::wrinkle_zone_masks(p.size);
    let masks: [Option<Vec<f64>>; 8] = std::array::from_fn(|i| Some(masks[i].clone()));
    let packed = wrinkles::pack_zone_masks(&masks, p.size, p.size, p.mask_size);
    for (i, img) in packed.iter().enumerate() {
        files.extend(unorm8_texture_files(
            &crate::baked_layout::path::wrinkle_masks_stem(&dir, i),
            img,
            FileKind::Lut,
            &mask_convention(i),
        )?);
    }
    let report = json!({
        "schema": crate::baked_layout::schema::WRINKLES,
        "encoding": "pd",
        "input": "input/wrinkle_normal.png (synthetic)",
        "input_green": "directx",
        "output_green": "directx",
        "wrinkle": wrinkle_report,
        "masks": {"files": ["wrinkle_masks_0.{bin,dds,ktx2,png}", "wrinkle_masks_1.{bin,dds,ktx2,png}"], "size": [p.mask_size.min(p.size), p.mask_size.min(p.size)], "format": "R8G8B8A8_UNORM", "zones": wrinkles::ZONES},
        "weights": "../expression_weights.json",
    });
    files.push(json_file(&format!("{dir}wrinkles.json"), &report, FileKind::Json, "wrinkle example description"));
    Ok(files)
}

fn bake_weights(_params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    Ok(vec![json_file(
        &format!("{WRINKLES_DIR}/expression_weights.json"),
        &wrinkles::table_8_1_json(crate::baked_layout::schema::WRINKLE_WEIGHTS),
        FileKind::Json,
        "thesis Table 8.1 wrinkle weights per expression and zone (negative values cancel)",
    )])
}

pub fn assets() -> Vec<Asset> {
    vec![
        Asset {
            time_estimate: None,
            name: "hemoglobin-rig-example",
            summary: "Example hemoglobin appearance rig (eq. 7.1-7.6) on the synthetic neutral + expression maps",
            default_params: || serde_json::to_value(RigExampleParams::default()).expect("params serialise"),
            bake: bake_rig_example,
        },
        Asset {
            time_estimate: None,
            name: "wrinkle-expression-weights",
            summary: "Thesis Table 8.1 wrinkle zone weights per expression (preset JSON)",
            default_params: || json!({}),
            bake: bake_weights,
        },
        Asset {
            time_estimate: None,
            name: "wrinkle-maps-example",
            summary: "Example partial-derivative wrinkle map and packed zone masks from a synthetic normal map",
            default_params: || serde_json::to_value(WrinkleExampleParams::default()).expect("params serialise"),
            bake: bake_wrinkle_example,
        },
    ]
}

/// A partial-derivative wrinkle map (thesis ch. 8) from decoded unit normals: PD conversion (cone handling
/// `cone`), optional difference against a base map's PD, area downsampling to `size` and the 8-bit texture
/// files `{prefix}wrinkle_pd.*` (and `{prefix}base_pd.*` with a base). Returns the files, the `"wrinkle"` report
/// object (sizes, clamp counts) and, with a base, the `"base"` one. Shared by `rtbake maps wrinkles` and the
/// `wrinkle-maps-example` bake.
pub fn pd_wrinkle_files(
    prefix: &str,
    normal: &Image<f32>,
    base: Option<&Image<f32>>,
    green: wrinkles::GreenConvention,
    cone: wrinkles::ConeMode,
    size: u32,
) -> Result<(Vec<BakedFile>, Value, Option<Value>), BakeError> {
    let (w, h) = (normal.width, normal.height);
    let pd = wrinkles::normals_to_pd("normal", normal, green, cone)?;
    let mut files = Vec::new();
    let (values, range_clamped, base_report) = match base {
        Some(b) => {
            let bpd = wrinkles::normals_to_pd("base", b, green, cone)?;
            files.extend(unorm8_texture_files(
                &format!("{prefix}base_pd"),
                &wrinkles::pd_to_rg8(w, h, &bpd.pd),
                FileKind::Lut,
                PD_CONVENTION,
            )?);
            let report = json!({"files": "base_pd.{bin,dds,ktx2,png}", "size": [w, h], "format": "R8G8_UNORM",
                                "cone_clamped_texels": bpd.cone_clamped});
            let (values, clamped) = wrinkles::pd_delta(&pd, &bpd);
            (values, clamped, Some(report))
        }
        None => (pd.pd.clone(), 0, None),
    };
    let (ow, oh, small) = wrinkles::downsample(&values, w, h, 2, size);
    files.extend(unorm8_texture_files(
        &crate::baked_layout::path::wrinkle_pd_stem(prefix),
        &wrinkles::pd_to_rg8(ow, oh, &small),
        FileKind::Lut,
        PD_CONVENTION,
    )?);
    let mut report = json!({"files": "wrinkle_pd.{bin,dds,ktx2,png}", "size": [ow, oh], "format": "R8G8_UNORM"});
    if base.is_some() {
        report["relative_to_base"] = json!(true);
        report["range_clamped_texels"] = json!(range_clamped);
    }
    report["cone_clamped_texels"] = json!(pd.cone_clamped);
    Ok((files, report, base_report))
}
