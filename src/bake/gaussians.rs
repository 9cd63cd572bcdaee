//! Screen-space SSS sum-of-Gaussians parameters in `baked/sss/gaussians/`: d'Eon et al.'s 6- and 4-Gaussian skin
//! presets (thesis Table 4.2) and a shared-variance 6-Gaussian fit of the Jensen 2001 skin1 dipole, each as JSON,
//! HLSL / GLSL / WGSL includes and a plot (PNG + SVG) of r·R(r).

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile, FileMeta};
use crate::baked_layout::path::GAUSSIANS_DIR;
use crate::diffusion::source::{with_reference, MaterialModel, ProfileSource};
use crate::diffusion::{FdrForm, RadialProfile};
use crate::fitting::screen_space::{ScreenSpaceParams, StretchParams};
use crate::fitting::{fit_sum_of_gaussians, FitSettings, NormalizedProfile, RgbGaussians};
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use crate::plot::profile::fit_overlay_plot;
use crate::plot::LinePlot;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// Plot size, pixels / SVG user units.
pub const PLOT_WIDTH: u32 = 720;
pub const PLOT_HEIGHT: u32 = 420;

const JSON_CONVENTION: &str = "variances in mm^2 ascending; weights per Gaussian; blend_weights = thesis eq. 4.8; \
incremental_variances v_i - v_(i-1) (v_0 = 0) and std_devs = their sqrt, for blur i applied on top of blur i-1; \
lod_thresholds: apply Gaussian i where depth < threshold_i";

/// The JSON object, shader includes and plots of one sum of Gaussians, under `{stem}.json`, `{stem}.hlsl`,
/// `{stem}.glsl`, `{stem}.wgsl`, `{stem}_plot.png`, `{stem}_plot.svg`. `extra` keys (e.g. `error_percent`,
/// `source`) are merged into the JSON.
pub fn gaussian_files(
    stem: &str,
    sum: &RgbGaussians,
    stretch: StretchParams,
    extra: serde_json::Map<String, Value>,
    plot: &LinePlot,
) -> Result<Vec<BakedFile>, BakeError> {
    let ss = ScreenSpaceParams::new(sum, stretch)?;
    let mut obj = ss.to_json();
    for (k, v) in extra {
        obj.insert(k, v);
    }
    let name = stem.rsplit('/').next().unwrap_or(stem);
    let mut files = vec![json_file(&format!("{stem}.json"), &Value::Object(obj), FileKind::Json, JSON_CONVENTION)];
    files.extend(super::shader_include_files(
        stem,
        "per-Gaussian constant arrays, index i = Gaussian i by ascending variance; float3 = (R, G, B)",
        |lang| ss.shader_include(lang, &format!("sum of Gaussians '{name}'")),
    ));
    let img = plot.to_image(PLOT_WIDTH, PLOT_HEIGHT);
    let mut png_meta =
        FileMeta::text(FileKind::Plot, FileFormat::Png, "r*R(r) per channel on a log10 r axis (mm); fit dashed");
    png_meta.width = img.width;
    png_meta.height = img.height;
    png_meta.channels = 3;
    png_meta.sample_type = SampleType::U8;
    png_meta.color_space = ColorSpace::Srgb;
    files.push(BakedFile {
        path: format!("{stem}_plot.png"),
        bytes: crate::io::png::encode_u8_as(&img, crate::io::png::PngColor::Srgb)?,
        meta: png_meta,
    });
    files.push(text_file(
        &format!("{stem}_plot.svg"),
        plot.to_svg(PLOT_WIDTH, PLOT_HEIGHT),
        FileKind::Plot,
        FileFormat::Svg,
        "r*R(r) per channel on a log10 r axis (mm); fit dashed",
    ));
    Ok(files)
}

/// Parameters of `sss-gaussians`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PresetParams {
    presets: Vec<String>,
    stretch: StretchParams,
}

fn bake_presets(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: PresetParams = parse_params("sss-gaussians", params)?;
    let mut files = Vec::new();
    for name in &p.presets {
        let sog = crate::diffusion::source::gaussian_preset("presets", name)?;
        let sum = RgbGaussians::from(&sog);
        let mut extra = serde_json::Map::new();
        extra.insert(
            "source".into(),
            with_reference(
                ProfileSource::Preset(name.clone()).provenance(),
                "d'Eon, Luebke, Enderton, EGSR 2007; thesis Table 4.2",
            ),
        );
        let plot = fit_overlay_plot(&sum, None, &format!("{name}: r R(r), sum of Gaussians"));
        files.extend(gaussian_files(&crate::baked_layout::path::gaussians_stem(name), &sum, p.stretch, extra, &plot)?);
    }
    Ok(files)
}

/// Parameters of `sss-gaussians-fit`: a Jensen 2001 material as a dipole (η = 1.3, DJ05 Fdr) and the fit settings.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FitParams {
    material: String,
    fit: FitSettings,
    stretch: StretchParams,
}

/// Provenance of a fit: source profile, settings and quadrature.
pub fn fit_provenance(source: Value, settings: &FitSettings) -> Value {
    json!({
        "source": source,
        "fit": {
            "method": "thesis eq. 2.2; exact NNLS weights (Lawson-Hanson) inside argmin Nelder-Mead on log-variances, \
                       deterministic multi-start",
            "count": settings.count,
            "shared_variances": settings.shared_variances,
            "normalize": settings.normalize,
            "starts": settings.starts,
            "quadrature": "trapezoid in ln r, r = 1e-5..1e3 mm, 16 nodes per decade (129 nodes), trapezoid continued to r -> 0",
            "error_metric": "relative RMS sqrt(int r (R - fit)^2 dr / int r R^2 dr), percent",
        }
    })
}

fn bake_fit(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: FitParams = parse_params("sss-gaussians-fit", params)?;
    let m = super::jensen_material("material", &p.material)?;
    let profile = m.dipole(FdrForm::Dj05);
    let fit = fit_sum_of_gaussians(&profile, &p.fit).map_err(|e| match e {
        crate::fitting::GaussianFitError::Invalid(i) => BakeError::Invalid(i),
        other => BakeError::Other(other.to_string()),
    })?;
    let source = with_reference(
        ProfileSource::Material {
            name: m.name.into(),
            model: MaterialModel::Dipole,
            fdr: FdrForm::Dj05,
            series: crate::diffusion::multipole::Series::Exact,
        }
        .provenance(),
        "Jensen et al. 2001",
    );
    let prov = fit_provenance(source, &p.fit);
    let mut extra = serde_json::Map::new();
    extra.insert("error_percent".into(), json!(fit.error_percent));
    extra.insert("profile_totals".into(), json!(fit.profile_totals));
    for (k, v) in prov.as_object().expect("object") {
        extra.insert(k.clone(), v.clone());
    }
    let mode = if p.fit.shared_variances { "shared" } else { "per_channel" };
    let stem = format!("{GAUSSIANS_DIR}/fit_{}_dipole_k{}_{mode}", m.name, p.fit.count);
    // Plot the profile in the units that were fitted.
    let plotted: Box<dyn RadialProfile> = if p.fit.normalize {
        Box::new(NormalizedProfile { inner: &profile, totals: profile.total_reflectance() })
    } else {
        Box::new(profile)
    };
    let mut plot = fit_overlay_plot(
        plotted.as_ref(),
        Some(&fit.sum),
        &format!("{}: dipole vs {}-Gaussian fit", m.name, p.fit.count),
    );
    if p.fit.normalize {
        plot = crate::plot::profile::normalized(plot);
    }
    gaussian_files(&stem, &fit.sum, p.stretch, extra, &plot)
}

pub fn assets() -> Vec<Asset> {
    vec![
        Asset {
            time_estimate: None,
            name: "sss-gaussians",
            summary:
                "screen-space SSS parameters of d'Eon's 6- and 4-Gaussian skin presets (JSON, HLSL/GLSL/WGSL, plot)",
            default_params: || {
                serde_json::to_value(PresetParams {
                    presets: vec!["deon6".into(), "deon4".into()],
                    stretch: StretchParams::default(),
                })
                .expect("params serialise")
            },
            bake: bake_presets,
        },
        Asset {
            time_estimate: None,
            name: "sss-gaussians-fit",
            summary: "shared 6-Gaussian fit of the Jensen 2001 skin1 dipole with its screen-space parameters",
            default_params: || {
                serde_json::to_value(FitParams {
                    material: "skin1".into(),
                    fit: FitSettings { count: 6, shared_variances: true, normalize: true, starts: 8 },
                    stretch: StretchParams::default(),
                })
                .expect("params serialise")
            },
            bake: bake_fit,
        },
    ]
}
