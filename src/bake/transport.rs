//! `transport-report`: Monte Carlo transport (`crate::transport`, MCML-style) against rtbake's diffusion models for
//! the Jensen 2001 materials (semi-infinite, η = 1.3, against the dipole) and the physiological two-layer skins
//! (against the layered multipole), so users see where each approximation stands.
//!
//! Files in `transport/`:
//! - `report.csv` / `report.json`: per case and channel the reduced albedo σs′/(σa + σs′) of the top layer, Monte
//!   Carlo total diffuse R ± SE, the diffusion total, their difference in %, and the relative L2 error of r·R(r)
//!   over all bins and over the bins beyond `far_r_mm` ([`crate::transport::compare`]);
//! - `difference_vs_albedo.svg`: the total-R difference (%) against the reduced albedo, per family;
//! - `<case>.svg` for the cases in `plots`: Monte Carlo R(r) with ±1 SE bars over the diffusion profile.
//!
//! Photon counts are small (default 2000 per channel: `verify` recomputes the asset; the output is deterministic,
//! so it verifies byte for byte); standard errors are listed beside every number. For tighter figures bake with
//! more `photons`.

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile, FileMeta};
use crate::baked_layout::path;
use crate::diffusion::materials;
use crate::error::InvalidInput;
use crate::manifest::{FileFormat, FileKind};
use crate::plot::profile::{render, PlotFormat, CHANNEL_COLORS};
use crate::plot::{Curve, LinePlot};
use crate::spectral::skin_layers::{physiological_skin_source, RgbReduction, SkinPhysiology, SkinProjection};
use crate::transport::compare::{bin_averaged, compare, diffusion_counterpart};
use crate::transport::{simulate, McSettings, McStack};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// One physiological skin point.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SkinPoint {
    melanin_fraction: f64,
    hemoglobin_fraction: f64,
}

/// Parameters of `transport-report`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ReportParams {
    /// Photons per channel and case.
    photons: u64,
    seed: u64,
    batches: u32,
    bin_mm: f64,
    bins: usize,
    /// Henyey–Greenstein g of every layer (σs = σs′/(1 − g)).
    g: f64,
    /// The r·R(r) error is also reported over bins with r ≥ this, mm.
    far_r_mm: f64,
    /// Jensen 2001 materials (semi-infinite, vs the dipole).
    materials: Vec<String>,
    /// Physiological skins (vs the layered multipole).
    skin: Vec<SkinPoint>,
    /// Cases (`dipole/<material>`, `skin/two_layer_cm<Cm>_chd<Chd>`) that also get an R(r) plot.
    plots: Vec<String>,
}

fn default_params() -> ReportParams {
    ReportParams {
        photons: 2000,
        seed: 1,
        batches: 10,
        bin_mm: 0.1,
        bins: 100,
        g: 0.0,
        far_r_mm: 2.0,
        materials: materials::names().iter().map(|s| s.to_string()).collect(),
        skin: [(0.02, 0.05), (0.1, 0.1), (0.3, 0.05)]
            .map(|(cm, chd)| SkinPoint { melanin_fraction: cm, hemoglobin_fraction: chd })
            .to_vec(),
        plots: vec!["dipole/skin1".into(), "skin/two_layer_cm0.1_chd0.1".into()],
    }
}

const CSV_CONVENTION: &str = "one row per case and channel: reduced albedo of the top layer, Monte Carlo total \
diffuse R and its standard error, the diffusion model's total R, (diffusion - MC)/MC in %, relative L2 error of \
r R(r) in % over all bins and over r >= far_r_mm (empty: no Monte Carlo photon there); '#' lines: settings";
const PLOT_CONVENTION: &str = "r R(r) (1/mm) and R(r) (mm^-2, log y) over r (mm): Monte Carlo solid with +-1 SE \
bars, diffusion dashed (annulus means); SVG <desc>: settings (JSON)";

fn bake(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: ReportParams = parse_params("transport-report", params)?;
    let settings = McSettings::new(p.photons, p.seed, p.batches, p.bin_mm, p.bins)?;
    if p.photons > 100_000 {
        return Err(InvalidInput::new("photons", format!("must be at most 100000 in a bake, got {}", p.photons)).into());
    }
    crate::error::check_non_negative("far_r_mm", p.far_r_mm, "mm")?;
    let mut cases: Vec<(String, McStack)> = Vec::new();
    for name in &p.materials {
        let m = super::jensen_material("materials", name)?;
        let stack = McStack::semi_infinite(m.sigma_a_per_mm, m.sigma_s_prime_per_mm, p.g, materials::JENSEN_2001_ETA)?;
        cases.push((format!("dipole/{}", m.name), stack));
    }
    for (i, s) in p.skin.iter().enumerate() {
        let (cm, chd) = (s.melanin_fraction, s.hemoglobin_fraction);
        let (src, _) = physiological_skin_source(
            &SkinPhysiology::default(),
            &SkinProjection::BandAveraged { reduction: RgbReduction::default() },
            cm,
            chd,
            Default::default(),
            Default::default(),
            Default::default(),
            Default::default(),
        )
        .map_err(|e| InvalidInput::new(format!("skin[{i}].{}", e.param), e.message))?;
        let crate::diffusion::source::ProfileSource::Layers { stack, .. } = &src else {
            unreachable!("physiological skin is a layer stack")
        };
        cases.push((format!("skin/two_layer_cm{cm}_chd{chd}"), McStack::from_layer_stack(stack, p.g)?));
    }
    for (i, plot) in p.plots.iter().enumerate() {
        if !cases.iter().any(|c| &c.0 == plot) {
            return Err(
                InvalidInput::new(format!("plots[{i}]"), format!("'{plot}' is not one of the report's cases")).into()
            );
        }
    }
    let provenance = json!({"settings": params, "reference": "Monte Carlo after Wang, Jacques & Zheng 1995 (MCML); \
        dipole: Jensen et al. 2001; layered multipole: Donner & Jensen 2005"});
    // Header row and data rows only (pandas/spreadsheet defaults); the provenance is in report.json.
    let mut csv = String::from(
        "case,channel,albedo_prime,total_R_mc,total_R_mc_se,model,total_R_diffusion,total_R_difference_percent,\
         rR_error_percent,rR_error_far_percent\n",
    );
    let mut rows = Vec::new();
    let mut files = Vec::new();
    let mut by_family: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    for (name, stack) in &cases {
        let result = simulate(stack, &settings);
        let (profile, model) = diffusion_counterpart(stack)?;
        let all = compare(&result, profile.as_ref(), [0.0, f64::INFINITY]);
        let far = compare(&result, profile.as_ref(), [p.far_r_mm, f64::INFINITY]);
        let top = &stack.layers()[0];
        for c in 0..3 {
            let sp = top.sigma_s_per_mm[c] * (1.0 - top.g[c]);
            let albedo = sp / (sp + top.sigma_a_per_mm[c]);
            let (a, f) = (&all.channels[c], &far.channels[c]);
            let pct = |v: Option<f64>| v.map(|x| format!("{x:.3}")).unwrap_or_default();
            for v in [
                a.total_r_mc.mean,
                a.total_r_diffusion,
                a.rr_error_percent.unwrap_or(0.0),
                f.rr_error_percent.unwrap_or(0.0),
            ] {
                if !v.is_finite() {
                    return Err(InvalidInput::new(name.clone(), "gave a non-finite comparison").into());
                }
            }
            csv.push_str(&format!(
                "{name},{},{albedo:.6},{:.6},{:.6},{model},{:.6},{:.3},{},{}\n",
                ["r", "g", "b"][c],
                a.total_r_mc.mean,
                a.total_r_mc.se,
                a.total_r_diffusion,
                a.total_r_difference_percent,
                pct(a.rr_error_percent),
                pct(f.rr_error_percent)
            ));
            let channel = ["r", "g", "b"][c];
            rows.push(json!({"case": name, "channel": channel, "albedo_prime": albedo, "model": model,
                "total_R_mc": a.total_r_mc, "total_R_diffusion": a.total_r_diffusion,
                "total_R_difference_percent": a.total_r_difference_percent, "rR_error_percent": a.rr_error_percent,
                "rR_error_far_percent": f.rr_error_percent}));
            by_family[usize::from(name.starts_with("skin/"))].push((albedo, a.total_r_difference_percent));
        }
        if p.plots.contains(name) {
            let avg = bin_averaged(profile.as_ref(), p.bin_mm, p.bins);
            let panels = crate::plot::transport::transport_panels(
                &result,
                Some((&avg, model)),
                &format!("{name}, Monte Carlo vs {model}"),
            );
            files.push(BakedFile {
                path: format!("{}/{name}.svg", path::TRANSPORT_DIR),
                bytes: render(&panels, PlotFormat::Svg, &provenance)?,
                meta: FileMeta::text(FileKind::Plot, FileFormat::Svg, PLOT_CONVENTION),
            });
        }
    }
    files.push(text_file(path::TRANSPORT_REPORT_CSV, csv, FileKind::Csv, FileFormat::Csv, CSV_CONVENTION));
    files.push(json_file(
        &format!("{}/report.json", path::TRANSPORT_DIR),
        &json!({"provenance": provenance, "rows": rows}),
        FileKind::Json,
        CSV_CONVENTION,
    ));
    let series = by_family
        .iter()
        .zip(["Jensen 2001 materials vs dipole", "two-layer skin vs layered multipole"])
        .enumerate()
        .map(|(k, (pts, label))| {
            let mut pts = pts.clone();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            Curve { label: label.into(), color: CHANNEL_COLORS[2 * k], dashed: k == 1, points: pts }
        })
        .collect();
    let plot = LinePlot {
        title: "Total diffuse R: diffusion vs Monte Carlo".into(),
        x_label: "reduced albedo of the top layer".into(),
        y_label: "(diffusion - MC) / MC (%)".into(),
        log_x: false,
        log_y: false,
        series,
    };
    files.push(BakedFile {
        path: format!("{}/difference_vs_albedo.svg", path::TRANSPORT_DIR),
        bytes: render(std::slice::from_ref(&plot), PlotFormat::Svg, &provenance)?,
        meta: FileMeta::text(
            FileKind::Plot,
            FileFormat::Svg,
            "(diffusion - Monte Carlo)/Monte Carlo total diffuse R in % over the reduced albedo of the top layer, \
             every case and channel, sorted by albedo, one line per family",
        ),
    });
    Ok(files)
}

pub fn assets() -> Vec<Asset> {
    vec![Asset {
        name: "transport-report",
        summary: "Monte Carlo transport vs the dipole (Jensen 2001 materials) and the layered multipole \
                  (physiological skins): total R and r R(r) differences, table and figures",
        default_params: || serde_json::to_value(default_params()).expect("params serialise"),
        bake,
    }]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_params_round_trip_and_bad_params_name_the_field() {
        let v = (assets()[0].default_params)();
        let p: ReportParams = serde_json::from_value(v.clone()).unwrap();
        assert_eq!(serde_json::to_value(&p).unwrap(), v);
        let mut bad = v.clone();
        bad["plots"] = json!(["dipole/unobtainium"]);
        assert!(bake(&bad).unwrap_err().to_string().contains("plots[0]"));
        let mut bad = v.clone();
        bad["photons"] = json!(0);
        assert!(bake(&bad).unwrap_err().to_string().contains("photons"));
        let mut bad = v;
        bad["g"] = json!(1.0);
        assert!(bake(&bad).unwrap_err().to_string().contains("g"));
    }
}
