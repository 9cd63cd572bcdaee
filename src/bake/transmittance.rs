//! Transmittance table T(s) (thesis eq. 5.12) in `baked/transmittance/`, from d'Eon's 6-Gaussian skin preset.

use super::{json_file, parse_params, Asset, BakeError, BakedFile, FileMeta};
use crate::baked_layout::{self, TransmittanceSidecar};
use crate::fitting::RgbGaussians;
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use crate::transmittance::{TableSettings, TransmittanceForm, TransmittanceModel};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Absolute tolerance `verify` allows on the f32 payloads.
pub const VERIFY_TOLERANCE: f64 = 1e-6;

/// Every file of one table: EXR f32/f16, KTX2 RGBA16F, sRGB preview PNG, 16-bit linear PNG and a JSON sidecar with
/// the provenance (`source`, `form`, convention, lookup formula). Paths `{stem}.*`.
pub fn table_files(
    stem: &str,
    model: &TransmittanceModel,
    settings: &TableSettings,
    source: Value,
) -> Result<Vec<BakedFile>, BakeError> {
    let img = model.table(settings).map_err(|e| match e {
        crate::transmittance::TransmittanceError::Invalid(i) => BakeError::Invalid(i),
    })?;
    let formula = model.formula(settings.form);
    let convention = settings.convention_for(formula);
    let s_max = settings.s_max_mm;
    let ticks: Vec<f64> = (0..=4).map(|k| (s_max * k as f64 / 4.0 * 1e4).round() / 1e4).collect();
    let axes = crate::plot::preview::PreviewAxes {
        title: format!("{}: transmittance T(s) per channel (RGB, sRGB-encoded for viewing)", sibling_name(stem)),
        x_label: "thickness s (mm)".into(),
        x_ticks: crate::plot::preview::PreviewAxes::node_ticks(0.0, s_max, settings.samples, &ticks, ""),
        y_label: if img.height > 1 { "identical rows".into() } else { String::new() },
        y_ticks: Vec::new(),
    };
    let mut files =
        super::float_texture_files_with_preview(stem, &img, FileKind::Lut, &convention, VERIFY_TOLERANCE, &axes)?;
    let mut meta =
        FileMeta::text(FileKind::Lut, FileFormat::Png, &format!("{convention}; 16-bit linear: value = sample/65535"));
    meta.width = img.width;
    meta.height = img.height;
    meta.channels = img.channels;
    meta.sample_type = SampleType::U16;
    meta.color_space = ColorSpace::Linear;
    meta.verify_tolerance = None;
    files.push(BakedFile { path: format!("{stem}_linear16.png"), bytes: crate::io::png::encode_linear16(&img)?, meta });
    let form = match settings.form {
        TransmittanceForm::Published => "published",
        TransmittanceForm::Physical => "physical",
    };
    let sidecar = TransmittanceSidecar {
        source,
        form: form.into(),
        formula: formula.into(),
        samples: settings.samples,
        height: settings.height,
        s_max_mm: settings.s_max_mm,
        texel_convention: TransmittanceSidecar::TEXEL_CONVENTION.into(),
        shader_lookup: TransmittanceSidecar::SHADER_LOOKUP.into(),
        variances_mm2: match model {
            TransmittanceModel::Gaussians(sum) => sum.variances_mm2.clone(),
            TransmittanceModel::Burley(_) => Default::default(),
        },
        weights: match model {
            TransmittanceModel::Gaussians(sum) => sum.weights.clone(),
            TransmittanceModel::Burley(_) => Default::default(),
        },
        burley: match model {
            TransmittanceModel::Gaussians(_) => None,
            TransmittanceModel::Burley(b) => Some(b.into()),
        },
    };
    files.push(json_file(
        &baked_layout::path::sidecar(&format!("{stem}.exr")),
        &serde_json::to_value(&sidecar).expect("sidecar serialises"),
        FileKind::Json,
        "provenance of the transmittance table next to it",
    ));
    Ok(files)
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    preset: String,
    table: TableSettings,
}

fn bake(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: Params = parse_params("transmittance", params)?;
    let sog = crate::diffusion::source::gaussian_preset("preset", &p.preset)?;
    let form = match p.table.form {
        TransmittanceForm::Published => "published",
        TransmittanceForm::Physical => "physical",
    };
    let source = crate::diffusion::source::with_reference(
        crate::diffusion::source::ProfileSource::Preset(p.preset.clone()).provenance(),
        "d'Eon, Luebke, Enderton, EGSR 2007",
    );
    table_files(
        &baked_layout::path::transmittance_stem(&p.preset, form),
        &TransmittanceModel::Gaussians(RgbGaussians::from(&sog)),
        &p.table,
        source,
    )
}

pub fn assets() -> Vec<Asset> {
    vec![Asset {
        name: "transmittance",
        summary: "transmittance table T(s) (thesis eq. 5.12) of d'Eon's 6-Gaussian skin, 256x1 over 0..8 mm",
        default_params: || {
            serde_json::to_value(Params { preset: "deon6".into(), table: TableSettings::default() })
                .expect("params serialise")
        },
        bake,
        time_estimate: Some(|v, _threads| {
            let p: Params = parse_params("transmittance", v)?;
            Ok(p.table.time_estimate_seconds())
        }),
    }]
}

/// The file name part of a stem (`burley/transmission/x` → `x`).
fn sibling_name(stem: &str) -> &str {
    stem.rsplit('/').next().unwrap_or(stem)
}
