//! Burley's normalized diffusion for the profiles rtbake knows, in `baked/burley/` (asset `burley-profiles`:
//! what engine bakers — Unreal's Subsurface Profile, Unity HDRP's Diffusion Profile — use, measured against physics).
//!
//! For every case (the 11 Jensen 2001 materials as dipoles, η = 1.3; the physiological two-layer skins as layered
//! multipoles, the `diffusion-profiles` points):
//! - **fit**: A and d per channel minimising the L2 of r·R(r) ([`crate::fitting::burley_fit`]), with its errors
//!   against the target ([`crate::fitting::evaluate::compare_profiles`]: r·R(r) L2, max, totals);
//! - **artist** (materials only): the mapping an engine user makes from measured coefficients — A = the dipole's total
//!   diffuse reflectance, ℓ = the diffuse mean free path 1/σ_tr, d = ℓ / s(A) with Christensen & Burley's searchlight
//!   fit (§3.2) — with the same errors. A layer stack has no single σ_tr, so the skins have none.
//!
//! Files: `burley/fits.json` and `burley/fits.csv` (every case and channel), `burley/<case>.svg` (r·R(r) of the
//! target, solid, and of the fit, dashed; PNG too for the cases in `png_plots`), and for the cases in
//! `transmission` the Unreal-style transmission profile T(s) against thickness both from the Burley fit (closed-form
//! plane integral, [`crate::transmittance::TransmittanceModel::Burley`]) and from a sum of Gaussians fitted to the
//! same profile (plane-integral form exp(−s²/(2v))), as the tables of `rtbake transmittance --out`
//! (`burley/transmission/<case>_{burley,gaussians<k>}_physical.*`) and one plot comparing them with the target
//! profile's own plane integral 2π∫ₛ^∞ ρ R(ρ) dρ (`burley/transmission/<case>.{svg,png}`). Every fit also gets
//! importance-sampled screen-space kernels ([`crate::sss_sampling`], Burley's closed-form CDF) for the sample
//! budgets in `kernel_samples` (default 40), as `rtbake importance-kernel --out` writes them
//! (`burley/kernels/<case>_n<N>.{json,hlsl,glsl,wgsl}` and `_f32x8.bin`).

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile, FileMeta};
use crate::baked_layout::path::BURLEY_DIR;
use crate::diffusion::burley::{Burley, RgbBurley, ShapeFit};
use crate::diffusion::multipole::Series;
use crate::diffusion::source::{MaterialModel, ProfileSource};
use crate::diffusion::{materials, FdrForm};
use crate::error::InvalidInput;
use crate::fitting::burley_fit::fit_burley;
use crate::fitting::evaluate::{compare_profiles, ProfileErrors};
use crate::fitting::{fit_sum_of_gaussians, FitSettings};
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use crate::plot::profile::{overlay_plot, render, PlotFormat, CHANNEL_COLORS, PANEL_HEIGHT, PLOT_WIDTH};
use crate::plot::{Curve, LinePlot};
use crate::spectral::skin_layers::{physiological_skin_source, SkinPhysiology, SkinProjection};
use crate::sss_sampling::disk::{ImportanceKernel, SampledProfile};
use crate::transmittance::{TableSettings, TransmittanceForm, TransmittanceModel};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// One physiological two-layer skin point.
use super::SkinPoint;

/// The transmission-profile tables.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Transmission {
    /// Cases (`dipole/<material>`, `skin/two_layer_cm<Cm>_chd<Chd>`).
    cases: Vec<String>,
    /// Gaussians of the comparison fit (2..=8).
    gaussians: usize,
    /// Table settings; the form must be `physical` (the plane integral both models share).
    table: TableSettings,
}

/// Parameters of `burley-profiles`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    /// Jensen 2001 materials, as dipoles (η = 1.3, DJ05 Fdr).
    materials: Vec<String>,
    /// Physiological two-layer skins (default physiology and RGB reduction, symmetric adding).
    skin: Vec<SkinPoint>,
    /// Cases that also get a PNG of their plot.
    png_plots: Vec<String>,
    transmission: Transmission,
    /// Sample budgets of the importance-sampled kernels baked from every case's Burley fit (each 1..=1024).
    kernel_samples: Vec<usize>,
}

fn default_params() -> Params {
    Params {
        materials: materials::JENSEN_2001.iter().map(|m| m.name.to_string()).collect(),
        skin: [(0.02, 0.05), (0.1, 0.1), (0.3, 0.05)]
            .into_iter()
            .map(|(melanin_fraction, hemoglobin_fraction)| SkinPoint { melanin_fraction, hemoglobin_fraction })
            .collect(),
        png_plots: vec!["dipole/skin1".into(), "skin/two_layer_cm0.1_chd0.1".into()],
        transmission: Transmission {
            cases: vec!["dipole/skin1".into(), "skin/two_layer_cm0.1_chd0.1".into()],
            gaussians: 4,
            table: TableSettings { samples: 64, height: 1, s_max_mm: 8.0, form: TransmittanceForm::Physical },
        },
        kernel_samples: vec![40],
    }
}

/// A case: its name, source (provenance) and, for a material, the artist mapping.
struct Case {
    name: String,
    source: ProfileSource,
    artist: Option<RgbBurley>,
}

/// A = the dipole's total diffuse reflectance, ℓ = 1/σ_tr (σ_tr = √(3 σa σt′)), searchlight s(A).
fn artist_mapping(m: &materials::Material, totals: [f64; 3]) -> Result<RgbBurley, InvalidInput> {
    let mut ch = [Burley { albedo: 0.0, d_mm: 1.0 }; 3];
    for c in 0..3 {
        let (sa, ss) = (m.sigma_a_per_mm[c], m.sigma_s_prime_per_mm[c]);
        let sigma_tr = (3.0 * sa * (sa + ss)).sqrt();
        ch[c] = Burley::from_mean_free_path(totals[c], 1.0 / sigma_tr, ShapeFit::Searchlight)?;
    }
    Ok(RgbBurley(ch))
}

fn cases(p: &Params) -> Result<Vec<Case>, BakeError> {
    let mut v = Vec::new();
    for name in &p.materials {
        let m = super::jensen_material("materials", name)?;
        let source = ProfileSource::Material {
            name: m.name.into(),
            model: MaterialModel::Dipole,
            fdr: FdrForm::Dj05,
            series: Series::Exact,
        };
        let totals = source.build()?.total_reflectance();
        v.push(Case { name: format!("dipole/{}", m.name), source, artist: Some(artist_mapping(m, totals)?) });
    }
    for (i, s) in p.skin.iter().enumerate() {
        let (cm, chd) = (s.melanin_fraction, s.hemoglobin_fraction);
        let (source, _) = physiological_skin_source(
            &SkinPhysiology::default(),
            &SkinProjection::default(),
            cm,
            chd,
            Default::default(),
            Default::default(),
            FdrForm::Dj05,
            Default::default(),
        )
        .map_err(|e| InvalidInput::new(format!("skin[{i}].{}", e.param), e.message))?;
        v.push(Case { name: format!("skin/two_layer_cm{cm}_chd{chd}"), source, artist: None });
    }
    for (field, list) in [("png_plots", &p.png_plots), ("transmission.cases", &p.transmission.cases)] {
        for (i, name) in list.iter().enumerate() {
            if !v.iter().any(|c| &c.name == name) {
                return Err(
                    InvalidInput::new(format!("{field}[{i}]"), format!("'{name}' is not one of the cases")).into()
                );
            }
        }
    }
    Ok(v)
}

fn errors_json(e: &ProfileErrors) -> Value {
    json!({"relative_l2_percent": e.relative_l2_percent, "max_percent": e.max_percent,
           "total_difference": e.total_difference})
}

fn burley_json(b: &RgbBurley) -> Value {
    json!({"albedo": b.0.map(|c| c.albedo), "d_mm": b.0.map(|c| c.d_mm),
           "mean_free_path_mm_diffuse_transmission":
               b.0.map(|c| c.d_mm * ShapeFit::DiffuseTransmission.scale(c.albedo))})
}

/// What one case gives: its JSON record, CSV rows and plot.
struct CaseResult {
    record: Value,
    rows: String,
    plot: LinePlot,
    fit: RgbBurley,
}

fn fit_case(case: &Case) -> Result<CaseResult, BakeError> {
    let target = case.source.build()?;
    let fit = fit_burley(target.as_ref())?;
    let burley = RgbBurley(fit.channels);
    let fit_err = compare_profiles(&burley, target.as_ref(), false)?;
    let artist_err = match &case.artist {
        Some(a) => Some(compare_profiles(a, target.as_ref(), false)?),
        None => None,
    };
    let totals = target.total_reflectance();
    let mut rows = String::new();
    for (c, ch) in ["R", "G", "B"].iter().enumerate() {
        let artist = match (&case.artist, &artist_err) {
            (Some(a), Some(e)) => {
                format!("{:?},{:?},{:?},{:?}", a.0[c].albedo, a.0[c].d_mm, e.relative_l2_percent[c], e.max_percent[c])
            }
            _ => ",,,".into(),
        };
        rows.push_str(&format!(
            "{},{ch},{:?},{:?},{:?},{:?},{:?},{:?},{artist}\n",
            case.name,
            totals[c],
            burley.0[c].albedo,
            burley.0[c].d_mm,
            fit_err.relative_l2_percent[c],
            fit_err.max_percent[c],
            fit_err.total_difference[c],
        ));
    }
    let record = json!({
        "case": case.name,
        "target": case.source.provenance(),
        "target_totals": totals,
        "fit": {"burley": burley_json(&burley), "errors": errors_json(&fit_err)},
        "artist": match (&case.artist, &artist_err) {
            (Some(a), Some(e)) => json!({"burley": burley_json(a), "errors": errors_json(e),
                "mapping": "A = dipole total diffuse reflectance, mfp = 1/sigma_tr, d = mfp / s(A), searchlight s(A)"}),
            _ => Value::Null,
        },
    });
    let mut plot = overlay_plot(
        target.as_ref(),
        "target",
        Some((&burley, "Burley fit")),
        &format!("Burley fit vs {} (r R(r))", case.name),
    );
    if let Some(a) = &case.artist {
        let artist_plot = overlay_plot(target.as_ref(), "target", Some((a, "Burley artist")), "");
        // The artist curves (the overlay half), dotted-looking: lighter colour, dashed.
        for mut curve in artist_plot.series.into_iter().skip(3) {
            curve.color = curve.color.map(|v| v / 2 + 110);
            plot.series.push(curve);
        }
    }
    Ok(CaseResult { record, rows, plot, fit: burley })
}

/// A one-panel plot as an sRGB PNG with its image metadata.
fn png_plot_file(path: &str, plot: &LinePlot, convention: &str) -> Result<BakedFile, BakeError> {
    let img = plot.to_image(PLOT_WIDTH, PANEL_HEIGHT);
    let mut meta = FileMeta::text(FileKind::Plot, FileFormat::Png, convention);
    (meta.width, meta.height, meta.channels) = (img.width, img.height, img.channels);
    meta.sample_type = SampleType::U8;
    meta.color_space = ColorSpace::Srgb;
    Ok(BakedFile {
        path: path.into(),
        bytes: crate::io::png::encode_u8_as(&img, crate::io::png::PngColor::Srgb)?,
        meta,
    })
}

const PLOT_CONVENTION: &str = "plot for people: r R(r) (1/mm) over log r (mm) of the target profile (solid) and \
    Burley's normalized diffusion (dashed); sRGB PNG / SVG";

fn transmission_files(
    case: &Case,
    burley: &RgbBurley,
    t: &Transmission,
    reference: &Value,
) -> Result<Vec<BakedFile>, BakeError> {
    if t.table.form != TransmittanceForm::Physical {
        return Err(InvalidInput::new(
            "transmission.table.form",
            "must be 'physical': the Burley and Gaussian transmission profiles are both plane integrals",
        )
        .into());
    }
    let target = case.source.build()?;
    let settings = FitSettings { count: t.gaussians, ..FitSettings::default() };
    settings.validate().map_err(|e| InvalidInput::new("transmission.gaussians", e.message))?;
    let gauss = fit_sum_of_gaussians(target.as_ref(), &settings)
        .map_err(|e| InvalidInput::new("transmission", e.to_string()))?;
    let stem = format!("{BURLEY_DIR}/transmission/{}", case.name.replace('/', "_"));
    let models = [
        (
            "burley",
            TransmittanceModel::Burley(*burley),
            json!({"kind": "burley-fit", "profile": case.source.provenance(),
            "burley": burley_json(burley), "reference": reference}),
        ),
        (
            &*format!("gaussians{}", t.gaussians),
            TransmittanceModel::Gaussians(gauss.sum.clone()),
            json!({"kind": "fit", "profile": case.source.provenance(), "count": t.gaussians,
                   "error_percent": gauss.error_percent}),
        ),
    ];
    let mut files = Vec::new();
    let mut series = Vec::new();
    // The target's own plane integral T(s) = 2π ∫ₛ^∞ ρ R(ρ) dρ: trapezoid in ln ρ over 481 nodes 1e-4..1e2 mm,
    // accumulated from the far end, interpolated linearly at the plotted thicknesses.
    let (lo, hi, m) = (1e-4f64, 1e2f64, 480);
    let rho: Vec<f64> = (0..=m).map(|i| lo * (hi / lo).powf(i as f64 / m as f64)).collect();
    let mut r_values = target.reflectance_many(&rho);
    crate::fitting::quadrature::checked_samples("profile", &rho, &mut r_values)?;
    let h = (hi / lo).ln() / m as f64;
    let mut tail = vec![[0.0f64; 3]; m + 1];
    for i in (0..m).rev() {
        for c in 0..3 {
            let f = |k: usize| 2.0 * std::f64::consts::PI * rho[k] * rho[k] * r_values[k][c];
            tail[i][c] = tail[i + 1][c] + 0.5 * h * (f(i) + f(i + 1));
        }
    }
    let direct = |s: f64, c: usize| -> f64 {
        if s <= lo {
            return target.total_reflectance()[c];
        }
        let x = (s / lo).ln() / h;
        let k = (x.floor() as usize).min(m - 1);
        let t = x - k as f64;
        tail[k][c] + (tail[k + 1][c] - tail[k][c]) * t
    };
    // Plot the thicknesses that carry the curves: up to 1.2× the last s where any exceeds 0.2 % of the largest T(0).
    let t0 =
        (0..3).map(|c| direct(0.0, c).max(models[0].1.at(0.0, TransmittanceForm::Physical)[c])).fold(0.0, f64::max);
    let s_plot = (0..=400)
        .map(|i| t.table.s_max_mm * i as f64 / 400.0)
        .filter(|&s| {
            (0..3).any(|c| {
                models.iter().any(|m| m.1.at(s, TransmittanceForm::Physical)[c] >= 2e-3 * t0)
                    || direct(s, c) >= 2e-3 * t0
            })
        })
        .fold(0.0, |a: f64, s| a.max(1.2 * s))
        .clamp(0.05 * t.table.s_max_mm, t.table.s_max_mm);
    let n = 160;
    for (k, (name, model, source)) in models.iter().enumerate() {
        files.extend(super::transmittance::table_files(
            &format!("{stem}_{name}_physical"),
            model,
            &t.table,
            source.clone(),
        )?);
        for c in 0..3 {
            series.push(Curve {
                label: format!("{} {}", if k == 0 { "Burley" } else { "Gaussians" }, ["R", "G", "B"][c]),
                color: if k == 0 { CHANNEL_COLORS[c] } else { CHANNEL_COLORS[c].map(|v| v / 2) },
                dashed: k == 1,
                points: (0..n)
                    .map(|i| {
                        let s = s_plot * i as f64 / (n - 1) as f64;
                        (s, model.at(s, TransmittanceForm::Physical)[c])
                    })
                    .collect(),
            });
        }
    }
    for c in 0..3 {
        series.push(Curve {
            label: format!("profile {}", ["R", "G", "B"][c]),
            color: CHANNEL_COLORS[c].map(|v| v / 2 + 110),
            dashed: false,
            points: (0..n)
                .map(|i| {
                    let s = s_plot * i as f64 / (n - 1) as f64;
                    (s, direct(s, c))
                })
                .collect(),
        });
    }
    let plot = LinePlot {
        title: format!("transmission profile of {} (plane integral)", case.name),
        x_label: "thickness s (mm)".into(),
        y_label: "T(s)".into(),
        log_x: false,
        log_y: false,
        series,
    };
    const CONVENTION: &str = "plot for people: T(s) against thickness s (mm) from the Burley fit (solid), the \
        Gaussian fit (dashed) and the target profile's own plane integral (light); sRGB PNG / SVG";
    files.push(BakedFile {
        path: format!("{stem}.svg"),
        bytes: render(std::slice::from_ref(&plot), PlotFormat::Svg, reference)?,
        meta: FileMeta::text(FileKind::Plot, FileFormat::Svg, CONVENTION),
    });
    files.push(png_plot_file(&format!("{stem}.png"), &plot, CONVENTION)?);
    Ok(files)
}

fn bake(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: Params = parse_params("burley-profiles", params)?;
    let cases = cases(&p)?;
    let results: Vec<CaseResult> = cases.par_iter().map(fit_case).collect::<Result<_, _>>()?;
    let reference = json!({"settings": params,
        "reference": "Christensen & Burley 2015 (Pixar TM 15-04); dipole: Jensen et al. 2001; layered multipole: \
                      Donner & Jensen 2005"});
    let mut files = Vec::new();
    // Header row and data rows only (pandas/spreadsheet defaults); the provenance is in fits.json.
    let mut csv = String::from(
        "case,channel,target_total,fit_albedo,fit_d_mm,fit_rR_error_percent,fit_max_percent,fit_total_difference,\
         artist_albedo,artist_d_mm,artist_rR_error_percent,artist_max_percent\n",
    );
    for (case, r) in cases.iter().zip(&results) {
        csv.push_str(&r.rows);
        files.push(BakedFile {
            path: format!("{BURLEY_DIR}/{}.svg", case.name),
            bytes: render(std::slice::from_ref(&r.plot), PlotFormat::Svg, &r.record)?,
            meta: FileMeta::text(FileKind::Plot, FileFormat::Svg, PLOT_CONVENTION),
        });
        if p.png_plots.contains(&case.name) {
            files.push(png_plot_file(&format!("{BURLEY_DIR}/{}.png", case.name), &r.plot, PLOT_CONVENTION)?);
        }
        if p.transmission.cases.contains(&case.name) {
            files.extend(transmission_files(case, &r.fit, &p.transmission, &reference)?);
        }
        for (i, &n) in p.kernel_samples.iter().enumerate() {
            let k = ImportanceKernel::new(SampledProfile::Burley(&r.fit), n).map_err(|e| {
                InvalidInput::new(format!("kernel_samples[{i}]"), format!("{}: {}", e.param, e.message))
            })?;
            let provenance = json!({"kind": "burley-fit", "profile": case.source.provenance(),
                                    "burley": burley_json(&r.fit)});
            files.extend(super::importance::kernel_files(
                &format!("{BURLEY_DIR}/kernels"),
                &format!("{}_n{n}", case.name.replace('/', "_")),
                &k,
                &provenance,
                &format!("rtbake bake burley-profiles (Burley fit of {})", case.name),
            ));
        }
    }
    files.push(text_file(
        &format!("{BURLEY_DIR}/fits.csv"),
        csv,
        FileKind::Table,
        FileFormat::Csv,
        "Burley fit (and artist mapping for materials) per case and channel: A, d (mm), errors in percent",
    ));
    files.push(json_file(
        &format!("{BURLEY_DIR}/fits.json"),
        &json!({"provenance": reference, "cases": results.iter().map(|r| r.record.clone()).collect::<Vec<_>>()}),
        FileKind::Table,
        "Burley fits per case: fit and artist parameters with their errors against the target profile",
    ));
    Ok(files)
}

pub fn assets() -> Vec<Asset> {
    vec![Asset {
        time_estimate: None,
        name: "burley-profiles",
        summary: "Burley normalized diffusion fitted to the Jensen 2001 dipoles and the physiological skins (and the \
                  artist mapping A, 1/sigma_tr), with plots and transmission profiles T(s) from Burley and from Gaussians",
        default_params: || serde_json::to_value(default_params()).expect("params serialise"),
        bake,
    }]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_params_name_the_field() {
        let mut bad = serde_json::to_value(default_params()).unwrap();
        bad["png_plots"] = json!(["dipole/unobtainium"]);
        assert!(bake(&bad).unwrap_err().to_string().contains("png_plots[0]"));
        let mut bad = serde_json::to_value(default_params()).unwrap();
        bad["materials"] = json!(["skin1"]);
        bad["skin"] = json!([]);
        bad["png_plots"] = json!([]);
        bad["transmission"]["cases"] = json!(["dipole/skin1"]);
        bad["transmission"]["table"]["form"] = json!("published");
        assert!(bake(&bad).unwrap_err().to_string().contains("transmission.table.form"));
    }
}
