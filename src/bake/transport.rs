//! `transport-report`: how far rtbake's diffusion models are from Monte Carlo transport (`crate::transport`,
//! MCML-style; Wang, Jacques & Zheng 1995), for the Jensen 2001 materials (semi-infinite, η = 1.3, against the
//! dipole) and for physiological two-layer skins, so users see where each approximation stands.
//!
//! **Skins.** The reference is the *spectral* Monte Carlo profile: per wavelength (380–780 nm every `step_nm`, the
//! skin-colour LUT's coefficients) with Henyey–Greenstein g (σs = σs′/(1 − g), σs′ kept), projected linearly onto
//! linear sRGB under D65 ([`crate::diffusion::projected`]). Against it, per channel, three diffusion models of the
//! same skin: `multipole-symmetric` (one RGB stack of band-averaged coefficients, DJ05 adding as printed — the
//! thesis' model), `multipole-directional` (the same stack, Kubelka's directional adding) and `spectral-multipole`
//! (the per-wavelength multipole projected like the Monte Carlo; the default of `--skin-*`). Cases: the skins of the
//! other bakes (`skin`), a melanin × hemoglobin grid (`grid`) and dermis-only slabs (`dermis_only`: the dermis of
//! the skin with that hemoglobin fraction, in air above, the physiology's index below), each for every g in `g`.
//! The multipole does not depend on g (it sees σs′ only); the Monte Carlo does.
//!
//! **Photons and seeds.** Skins: `skin_photons` per wavelength and channel, so a skin's channel sums
//! (780 − 380)/`step_nm` + 1 wavelengths' photons (41 × 2500 = 1.03·10⁵ by default; standard errors from 4 batches
//! per wavelength group, pooled over the 14 groups) and its total R carries the
//! standard error printed beside it; materials: `photons` per channel (10⁵ by default; g = 0 only: the high-albedo
//! materials scatter thousands of times per photon). The whole report takes ~25 CPU-s in the README's dev build
//! (the lane kernel is built at opt-level 3 there too, `crates/rtbake-lanes`). Every case and g has its own seed, derived from `seed` and the case's
//! name by FNV-1a ([`case_seed`]); a wavelength group j adds j·2³² as `--model mc` does. Both models are normalised
//! per unit flux entering the surface (Monte Carlo ÷ (1 − Rsp), [`crate::transport::profile`]).
//!
//! Files in `transport/`:
//! - `report.csv` / `report.json`: one row per case, g, channel and model (see `CSV_CONVENTION`);
//! - `summary.md`: per family, model and g, the range of total-R differences and the median and largest r·R(r)
//!   error over cases and channels (the README's accuracy table);
//! - `accuracy.svg`: total-R difference and r·R(r) error against the Monte Carlo total R, one line per model and g;
//! - `<case>.svg` for the cases in `plots`: Monte Carlo R(r) with ±1 SE bars over the models.
//!
//! The output is deterministic (the same bytes for any thread count), so `verify` recomputes it byte for byte.

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile, FileMeta};
use crate::baked_layout::path;
use crate::diffusion::layered::{Adding, LayerStack, LayeredProfile};
use crate::diffusion::materials;
use crate::diffusion::multipole::Series;
use crate::diffusion::projected::{ProjectedPart, ProjectedProfile};
use crate::diffusion::{FdrForm, RadialProfile};
use crate::error::InvalidInput;
use crate::manifest::{FileFormat, FileKind};
use crate::plot::profile::{render, PlotFormat, CHANNEL_COLORS};
use crate::plot::{Curve, LinePlot};
use crate::spectral::colorimetry::Illuminant;
use crate::spectral::skin_layers::{spectral_skin_stacks, two_layer_skin_rgb, RgbReduction, SkinPhysiology};
use crate::transport::compare::{bin_averaged, BinnedReference, ModelDifference};
use crate::transport::profile::{McProfile, DEFAULT_TISSUE_G};
use crate::transport::{McSettings, McStack};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// One physiological skin point.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SkinPoint {
    melanin_fraction: f64,
    hemoglobin_fraction: f64,
}

/// A melanin × hemoglobin grid of skins (every pair).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SkinGrid {
    melanin_fraction: Vec<f64>,
    hemoglobin_fraction: Vec<f64>,
}

/// Parameters of `transport-report`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ReportParams {
    /// Photons per channel of each Jensen material (g = 0).
    photons: u64,
    /// Photons per wavelength and channel of each skin case and g.
    skin_photons: u64,
    /// Base seed; each case's own seed is derived from it and the case name ([`case_seed`]).
    seed: u64,
    batches: u32,
    bin_mm: f64,
    bins: usize,
    /// Henyey–Greenstein g of the skin rows (σs = σs′/(1 − g)); the materials use g = 0.
    g: Vec<f64>,
    /// Wavelength step of the spectral skins, nm (380–780 nm).
    step_nm: u32,
    /// The r·R(r) error is also reported over bins with r ≥ this, mm.
    far_r_mm: f64,
    /// Jensen 2001 materials (semi-infinite, vs the dipole).
    materials: Vec<String>,
    /// Physiological skins (the skins the other bakes use).
    skin: Vec<SkinPoint>,
    /// A melanin × hemoglobin grid of skins.
    grid: SkinGrid,
    /// Dermis-only slabs, by dermal hemoglobin fraction.
    dermis_only: Vec<f64>,
    /// Cases (`dipole/<material>`, `skin/two_layer_cm<Cm>_chd<Chd>`, `skin/dermis_only_chd<Chd>`) that also get
    /// an R(r) plot (skins at the last g of `g`).
    plots: Vec<String>,
}

fn default_params() -> ReportParams {
    ReportParams {
        photons: 100_000,
        skin_photons: 2500,
        seed: 1,
        batches: 4,
        bin_mm: 0.1,
        bins: 100,
        g: vec![0.0, DEFAULT_TISSUE_G],
        step_nm: crate::spectral::skin_layers::DEFAULT_SPECTRAL_STEP_NM,
        far_r_mm: 2.0,
        materials: materials::names().iter().map(|s| s.to_string()).collect(),
        skin: [(0.02, 0.05), (0.1, 0.1), (0.3, 0.05)]
            .map(|(cm, chd)| SkinPoint { melanin_fraction: cm, hemoglobin_fraction: chd })
            .to_vec(),
        grid: SkinGrid {
            melanin_fraction: vec![0.01, 0.05, 0.2, 0.45],
            hemoglobin_fraction: vec![0.01, 0.03, 0.1, 0.3],
        },
        dermis_only: vec![0.1],
        plots: vec!["dipole/skin1".into(), "skin/two_layer_cm0.1_chd0.1".into()],
    }
}

pub fn assets() -> Vec<Asset> {
    vec![Asset {
        name: "transport-report",
        summary: "Monte Carlo transport vs the dipole (Jensen 2001 materials) and vs the multipole models of \
                  physiological skins (spectral Monte Carlo reference, g = 0 and tissue-like g): total R and \
                  r R(r) differences, table, summary and figures",
        default_params: || serde_json::to_value(default_params()).expect("params serialise"),
        bake,
        time_estimate: Some(time_estimate),
    }]
}

/// The seed of one case: FNV-1a (64-bit) of the case label, XOR the base seed. Deterministic, and different for
/// every skin and g, so no two rows share a random stream.
pub fn case_seed(base: u64, label: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in label.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h ^ base
}

const CSV_CONVENTION: &str = "one row per case, g, channel and model: case, melanin and dermal hemoglobin \
fractions (empty for materials), Henyey-Greenstein g of the Monte Carlo, channel, reduced albedo of the top layer \
(band-averaged for skins), the reference (Monte Carlo; spectral for skins) total diffuse R and its standard error, \
the reference's own r R(r) noise in %, the model, its total R, (model - MC)/MC in %, relative L2 error of r R(r) \
in % over all bins and over r >= far_r_mm (empty: no light there); both per unit flux entering the surface";
const PLOT_CONVENTION: &str = "r R(r) (1/mm) and R(r) (mm^-2, log y) over r (mm): Monte Carlo solid with +-1 SE \
bars, models dashed (annulus means); SVG <desc>: settings (JSON)";
const SUMMARY_CONVENTION: &str = "Markdown table: per family (Jensen materials vs the dipole; skins vs the spectral \
Monte Carlo), model and g, the range of (model - MC)/MC total R in % over every case and channel, and the median \
and largest relative L2 error of r R(r) in %; the Monte Carlo standard errors are in report.csv";

/// A skin case: a two-layer skin or a dermis-only slab.
#[derive(Clone, Copy, Debug)]
enum SkinCase {
    TwoLayer { cm: f64, chd: f64 },
    DermisOnly { chd: f64 },
}

impl SkinCase {
    fn name(self) -> String {
        match self {
            Self::TwoLayer { cm, chd } => format!("skin/two_layer_cm{cm}_chd{chd}"),
            Self::DermisOnly { chd } => format!("skin/dermis_only_chd{chd}"),
        }
    }
    fn fractions(self) -> (f64, f64) {
        match self {
            Self::TwoLayer { cm, chd } => (cm, chd),
            Self::DermisOnly { chd } => (0.0, chd),
        }
    }
    /// The stack as the case uses it (a dermis-only case keeps the dermis, in air above).
    fn restrict(self, stack: LayerStack) -> Result<LayerStack, InvalidInput> {
        match self {
            Self::TwoLayer { .. } => Ok(stack),
            Self::DermisOnly { .. } => LayerStack::new(1.0, stack.eta_below(), vec![stack.layers()[1].clone()]),
        }
    }
}

/// A skin case's inputs: the band-averaged RGB stack and the per-wavelength stacks with their projection weights.
struct SkinInputs {
    case: SkinCase,
    band: LayerStack,
    spectral: Vec<(LayerStack, [[f64; 3]; 3])>,
}

fn skin_inputs(case: SkinCase, param: &str, step_nm: u32) -> Result<SkinInputs, InvalidInput> {
    let physiology = SkinPhysiology::default();
    let (cm, chd) = case.fractions();
    let named = |e: InvalidInput| InvalidInput::new(format!("{param}.{}", e.param), e.message);
    let band = two_layer_skin_rgb(&physiology, cm, chd, false, &RgbReduction::default()).map_err(named)?;
    let band = case.restrict(band.layer_stack()?)?;
    let stacks = spectral_skin_stacks(&physiology, cm, chd, Illuminant::D65, step_nm)
        .map_err(|e| InvalidInput::new("step_nm", e.message))?;
    let spectral = stacks
        .stacks
        .into_iter()
        .zip(stacks.weights)
        .map(|(s, w)| Ok((case.restrict(s)?, w)))
        .collect::<Result<_, InvalidInput>>()?;
    Ok(SkinInputs { case, band, spectral })
}

/// The projection of one profile per wavelength group (unclipped: the exact linear functional).
fn projected(parts: Vec<Box<dyn RadialProfile + Send>>, spectral: &[(LayerStack, [[f64; 3]; 3])]) -> ProjectedProfile {
    let parts = parts.into_iter().zip(spectral).map(|(profile, (_, w))| ProjectedPart { profile, weights: *w });
    ProjectedProfile::new(parts.collect(), false)
}

/// One reference (a Monte Carlo case at one g) with its models' differences.
struct Row {
    case: String,
    fractions: Option<(f64, f64)>,
    g: f64,
    albedo: [f64; 3],
    reference: BinnedReference,
    noise: [Option<f64>; 3],
    models: Vec<(&'static str, [ModelDifference; 3], [ModelDifference; 3])>,
}

fn top_albedo(stack: &LayerStack) -> [f64; 3] {
    let l = &stack.layers()[0];
    [0, 1, 2].map(|c| l.sigma_s_prime[c] / (l.sigma_s_prime[c] + l.sigma_a[c]))
}

fn check_photons(name: &str, photons: u64) -> Result<(), InvalidInput> {
    if photons == 0 || photons > 100_000 {
        return Err(InvalidInput::new(name, format!("must be in 1..=100000 in a bake, got {photons}")));
    }
    Ok(())
}

/// A Jensen material's case: name, Monte Carlo stack and single-scattering albedo per channel.
type MaterialCase = (String, McStack, [f64; 3]);

/// The report's validated cases: the materials and the skins (every parameter checked, errors naming it).
fn cases(p: &ReportParams) -> Result<(Vec<MaterialCase>, Vec<SkinInputs>), BakeError> {
    check_photons("photons", p.photons)?;
    check_photons("skin_photons", p.skin_photons)?;
    McSettings::new(p.photons, p.seed, p.batches, p.bin_mm, p.bins)?;
    crate::error::check_non_negative("far_r_mm", p.far_r_mm, "mm")?;
    for (i, &g) in p.g.iter().enumerate() {
        if !(g.is_finite() && g > -1.0 && g < 1.0) {
            return Err(
                InvalidInput::new(format!("g[{i}]"), format!("must be in the open interval (-1, 1), got {g}")).into()
            );
        }
    }
    let mut material_stacks = Vec::new();
    for name in &p.materials {
        let m = super::jensen_material("materials", name)?;
        let stack = McStack::semi_infinite(m.sigma_a_per_mm, m.sigma_s_prime_per_mm, 0.0, materials::JENSEN_2001_ETA)?;
        material_stacks.push((
            format!("dipole/{}", m.name),
            stack,
            [0, 1, 2].map(|c| m.sigma_s_prime_per_mm[c] / (m.sigma_s_prime_per_mm[c] + m.sigma_a_per_mm[c])),
        ));
    }
    let mut skins = Vec::new();
    for (i, s) in p.skin.iter().enumerate() {
        let case = SkinCase::TwoLayer { cm: s.melanin_fraction, chd: s.hemoglobin_fraction };
        skins.push(skin_inputs(case, &format!("skin[{i}]"), p.step_nm)?);
    }
    for (i, &cm) in p.grid.melanin_fraction.iter().enumerate() {
        for (j, &chd) in p.grid.hemoglobin_fraction.iter().enumerate() {
            let case = SkinCase::TwoLayer { cm, chd };
            skins.push(skin_inputs(case, &format!("grid[{i}][{j}]"), p.step_nm)?);
        }
    }
    for (i, &chd) in p.dermis_only.iter().enumerate() {
        skins.push(skin_inputs(SkinCase::DermisOnly { chd }, &format!("dermis_only[{i}]"), p.step_nm)?);
    }
    Ok((material_stacks, skins))
}

/// [`Asset::time_estimate`] of the report: every Monte Carlo run's own estimate
/// ([`McSettings::time_estimate_for_stack`]) summed — the materials at `photons`, each skin at `skin_photons` per
/// wavelength group and g (the diffusion models' share is small beside them).
fn time_estimate(params: &Value, threads: usize) -> Result<f64, BakeError> {
    let p: ReportParams = parse_params("transport-report", params)?;
    let (material_stacks, skins) = cases(&p)?;
    let mut seconds = 0.0;
    for (_, stack, _) in &material_stacks {
        seconds +=
            McSettings::new(p.photons, p.seed, p.batches, p.bin_mm, p.bins)?.time_estimate_for_stack(stack, threads);
    }
    let skin_settings = McSettings::new(p.skin_photons, p.seed, p.batches, p.bin_mm, p.bins)?;
    for skin in &skins {
        for &g in &p.g {
            for (stack, _) in &skin.spectral {
                seconds += skin_settings.time_estimate_for_stack(&McStack::from_layer_stack(stack, g)?, threads);
            }
        }
    }
    Ok(seconds)
}

fn bake(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: ReportParams = parse_params("transport-report", params)?;
    let (material_stacks, skins) = cases(&p)?;
    let names: Vec<String> =
        material_stacks.iter().map(|m| m.0.clone()).chain(skins.iter().map(|s| s.case.name())).collect();
    for (i, plot) in p.plots.iter().enumerate() {
        if !names.contains(plot) {
            return Err(
                InvalidInput::new(format!("plots[{i}]"), format!("'{plot}' is not one of the report's cases")).into()
            );
        }
    }
    let window_all = [0.0, f64::INFINITY];
    let window_far = [p.far_r_mm, f64::INFINITY];

    // Monte Carlo runs, one job per (material) or (skin, g, wavelength group), traced side by side; collected in
    // order, so the bytes do not depend on the thread count.
    let mat_settings: Vec<McSettings> = material_stacks
        .iter()
        .map(|(name, _, _)| McSettings::new(p.photons, case_seed(p.seed, name), p.batches, p.bin_mm, p.bins))
        .collect::<Result<_, _>>()?;
    let mut jobs = Vec::new();
    for (s, skin) in skins.iter().enumerate() {
        for (gi, &g) in p.g.iter().enumerate() {
            let seed = case_seed(p.seed, &format!("{} g={g}", skin.case.name()));
            for (j, (stack, _)) in skin.spectral.iter().enumerate() {
                let settings =
                    McSettings::new(p.skin_photons, seed.wrapping_add((j as u64) << 32), p.batches, p.bin_mm, p.bins)?;
                jobs.push((s, gi, McStack::from_layer_stack(stack, g)?, settings));
            }
        }
    }
    // Materials and skins side by side (the high-albedo materials' long histories would otherwise leave a core idle).
    let (material_refs, mut skin_mc): (Vec<McProfile>, Vec<Option<McProfile>>) = rayon::join(
        || {
            material_stacks
                .par_iter()
                .zip(&mat_settings)
                .map(|((_, stack, _), settings)| McProfile::simulate(stack, settings))
                .collect()
        },
        || jobs.par_iter().map(|(_, _, stack, settings)| Some(McProfile::simulate(stack, settings))).collect(),
    );
    // The diffusion models of each skin (independent of g).
    // Each model averaged over the Monte Carlo annuli once, with its totals: (name, per-bin values, totals).
    type Binned = (&'static str, Vec<[f64; 3]>, [f64; 3]);
    let skin_models: Vec<Vec<Binned>> = skins
        .par_iter()
        .map(|skin| -> Result<_, InvalidInput> {
            let layered = |s: &LayerStack, a: Adding| LayeredProfile::new(s, a, Series::Exact, FdrForm::Dj05);
            let spectral_parts = skin
                .spectral
                .iter()
                .map(|(s, _)| Ok(Box::new(layered(s, Adding::Symmetric)?) as Box<dyn RadialProfile + Send>))
                .collect::<Result<Vec<_>, InvalidInput>>()?;
            let binned = |name, m: &dyn RadialProfile| (name, bin_averaged(m, p.bin_mm, p.bins), m.total_reflectance());
            Ok(vec![
                binned("multipole-symmetric", &layered(&skin.band, Adding::Symmetric)?),
                binned("multipole-directional", &layered(&skin.band, Adding::Directional)?),
                binned("spectral-multipole", &projected(spectral_parts, &skin.spectral)),
            ])
        })
        .collect::<Result<_, _>>()?;

    let mut rows = Vec::new();
    for (((name, stack, albedo), mc), settings) in material_stacks.iter().zip(&material_refs).zip(&mat_settings) {
        let reference = BinnedReference::from_profile(mc, settings.bin_mm, settings.bins);
        let (dipole, model) = crate::transport::compare::diffusion_counterpart(stack)?;
        let all = reference.compare(dipole.as_ref(), window_all);
        let far = reference.compare(dipole.as_ref(), window_far);
        let noise = reference.rr_noise_percent(window_all);
        rows.push(Row {
            case: name.clone(),
            fractions: None,
            g: 0.0,
            albedo: *albedo,
            reference,
            noise,
            models: vec![(model, all, far)],
        });
    }
    let mut next = 0;
    for (s, skin) in skins.iter().enumerate() {
        for &g in &p.g {
            let groups = skin.spectral.len();
            let parts: Vec<Box<dyn RadialProfile + Send>> = (next..next + groups)
                .map(|k| Box::new(skin_mc[k].take().expect("each run is used once")) as Box<dyn RadialProfile + Send>)
                .collect();
            debug_assert!(jobs[next].0 == s);
            next += groups;
            let mc = projected(parts, &skin.spectral);
            let reference = BinnedReference::from_profile(&mc, p.bin_mm, p.bins);
            let noise = reference.rr_noise_percent(window_all);
            let models = skin_models[s]
                .iter()
                .map(|(name, avg, totals)| {
                    let all = reference.compare_binned(avg, *totals, window_all);
                    (*name, all, reference.compare_binned(avg, *totals, window_far))
                })
                .collect();
            rows.push(Row {
                case: skin.case.name(),
                fractions: Some(skin.case.fractions()),
                g,
                albedo: top_albedo(&skin.band),
                reference,
                noise,
                models,
            });
        }
    }
    for row in &rows {
        for (_, all, far) in &row.models {
            for c in 0..3 {
                let vals =
                    [all[c].total_r, all[c].rr_error_percent.unwrap_or(0.0), far[c].rr_error_percent.unwrap_or(0.0)];
                if !(vals.iter().all(|v| v.is_finite()) && row.reference.total_r[c].mean.is_finite()) {
                    return Err(InvalidInput::new(row.case.clone(), "gave a non-finite comparison").into());
                }
            }
        }
    }

    let provenance = json!({"settings": params, "reference": "Monte Carlo after Wang, Jacques & Zheng 1995 (MCML), \
        per unit flux entering the surface; skins spectral (D65, CIE 1931 2 degree, linear sRGB); dipole: Jensen et \
        al. 2001; layered multipole: Donner & Jensen 2005; directional adding: Kubelka 1954"});
    let mut files = Vec::new();
    files.push(text_file(
        path::TRANSPORT_REPORT_CSV,
        report_csv(&rows),
        FileKind::Csv,
        FileFormat::Csv,
        CSV_CONVENTION,
    ));
    files.push(json_file(
        &format!("{}/report.json", path::TRANSPORT_DIR),
        &json!({"provenance": provenance, "rows": report_json(&rows)}),
        FileKind::Json,
        CSV_CONVENTION,
    ));
    files.push(text_file(
        &format!("{}/summary.md", path::TRANSPORT_DIR),
        summary_markdown(&rows, &p),
        FileKind::Table,
        FileFormat::Md,
        SUMMARY_CONVENTION,
    ));
    files.push(BakedFile {
        path: format!("{}/accuracy.svg", path::TRANSPORT_DIR),
        bytes: render(&accuracy_panels(&rows), PlotFormat::Svg, &provenance)?,
        meta: FileMeta::text(
            FileKind::Plot,
            FileFormat::Svg,
            "(model - Monte Carlo)/Monte Carlo total diffuse R in % (top) and the relative L2 error of r R(r) in % \
             (bottom) over the Monte Carlo total R, every case and channel, one line per model and g",
        ),
    });
    for plot in &p.plots {
        let row = rows.iter().rev().find(|r| &r.case == plot).expect("plots are checked to name a case");
        let profiles: Vec<(Vec<[f64; 3]>, &str)> = if let Some(k) = material_stacks.iter().position(|m| &m.0 == plot) {
            let (dipole, model) = crate::transport::compare::diffusion_counterpart(&material_stacks[k].1)?;
            vec![(bin_averaged(dipole.as_ref(), p.bin_mm, p.bins), model)]
        } else {
            let s = skins.iter().position(|s| &s.case.name() == plot).expect("a skin case");
            skin_models[s].iter().map(|(n, avg, _)| (avg.clone(), *n)).collect()
        };
        let models: Vec<(&[[f64; 3]], &str)> = profiles.iter().map(|(v, n)| (v.as_slice(), *n)).collect();
        let title = format!("{plot}, g = {}: Monte Carlo vs diffusion", row.g);
        let panels = crate::plot::transport::reference_panels(&row.reference, &models, &title);
        files.push(BakedFile {
            path: format!("{}/{plot}.svg", path::TRANSPORT_DIR),
            bytes: render(&panels, PlotFormat::Svg, &provenance)?,
            meta: FileMeta::text(FileKind::Plot, FileFormat::Svg, PLOT_CONVENTION),
        });
    }
    Ok(files)
}

const CHANNELS: [&str; 3] = ["r", "g", "b"];

fn report_csv(rows: &[Row]) -> String {
    // Header row and data rows only (pandas/spreadsheet defaults); the provenance is in report.json.
    let mut csv = String::from(
        "case,melanin_fraction,hemoglobin_fraction,g,channel,albedo_prime,total_R_mc,total_R_mc_se,\
         rR_noise_mc_percent,model,total_R_model,total_R_difference_percent,rR_error_percent,rR_error_far_percent\n",
    );
    let opt = |v: Option<f64>| v.map(|x| format!("{x:.3}")).unwrap_or_default();
    for row in rows {
        let (cm, chd) = row.fractions.map(|(a, b)| (a.to_string(), b.to_string())).unwrap_or_default();
        for (model, all, far) in &row.models {
            for c in 0..3 {
                let e = row.reference.total_r[c];
                csv.push_str(&format!(
                    "{},{cm},{chd},{},{},{:.6},{:.6},{:.6},{},{model},{:.6},{:.3},{},{}\n",
                    row.case,
                    row.g,
                    CHANNELS[c],
                    row.albedo[c],
                    e.mean,
                    e.se,
                    opt(row.noise[c]),
                    all[c].total_r,
                    all[c].total_r_difference_percent,
                    opt(all[c].rr_error_percent),
                    opt(far[c].rr_error_percent),
                ));
            }
        }
    }
    csv
}

fn report_json(rows: &[Row]) -> Vec<Value> {
    let mut out = Vec::new();
    for row in rows {
        for (model, all, far) in &row.models {
            for c in 0..3 {
                out.push(json!({
                    "case": row.case,
                    "melanin_fraction": row.fractions.map(|f| f.0),
                    "hemoglobin_fraction": row.fractions.map(|f| f.1),
                    "g": row.g,
                    "channel": CHANNELS[c],
                    "albedo_prime": row.albedo[c],
                    "total_R_mc": row.reference.total_r[c],
                    "rR_noise_mc_percent": row.noise[c],
                    "model": model,
                    "total_R_model": all[c].total_r,
                    "total_R_difference_percent": all[c].total_r_difference_percent,
                    "rR_error_percent": all[c].rr_error_percent,
                    "rR_error_far_percent": far[c].rr_error_percent,
                }));
            }
        }
    }
    out
}

/// (family, model, g) groups in the order they first appear.
fn groups(rows: &[Row]) -> Vec<(&'static str, &'static str, f64)> {
    let mut keys: Vec<(&'static str, &'static str, f64)> = Vec::new();
    for row in rows {
        let family = if row.fractions.is_some() { "skin" } else { "Jensen materials" };
        for (model, _, _) in &row.models {
            if !keys.iter().any(|k| k.0 == family && k.1 == *model && k.2 == row.g) {
                keys.push((family, model, row.g));
            }
        }
    }
    keys
}

fn group_values(rows: &[Row], key: (&str, &str, f64)) -> (Vec<f64>, Vec<f64>, f64) {
    let (mut diff, mut rr, mut max_se) = (Vec::new(), Vec::new(), 0.0f64);
    for row in rows {
        let family = if row.fractions.is_some() { "skin" } else { "Jensen materials" };
        if family != key.0 || row.g != key.2 {
            continue;
        }
        for (model, all, _) in row.models.iter().filter(|m| m.0 == key.1) {
            debug_assert_eq!(*model, key.1);
            for (d, e) in all.iter().zip(&row.reference.total_r) {
                diff.push(d.total_r_difference_percent);
                rr.extend(d.rr_error_percent);
                max_se = max_se.max(100.0 * e.se / e.mean);
            }
        }
    }
    (diff, rr, max_se)
}

fn summary_markdown(rows: &[Row], p: &ReportParams) -> String {
    let mut s = String::from(
        "| family | model | g | total R vs Monte Carlo (min .. max, %) | r R(r) error (median / max, %) | MC SE (max, %) |\n\
         | --- | --- | --- | --- | --- | --- |\n",
    );
    for key in groups(rows) {
        let (mut diff, mut rr, max_se) = group_values(rows, key);
        diff.sort_by(f64::total_cmp);
        rr.sort_by(f64::total_cmp);
        let median = if rr.is_empty() { f64::NAN } else { rr[rr.len() / 2] };
        s.push_str(&format!(
            "| {} | {} | {} | {:+.0} .. {:+.0} | {:.0} / {:.0} | {:.1} |\n",
            key.0,
            key.1,
            key.2,
            diff.first().copied().unwrap_or(f64::NAN),
            diff.last().copied().unwrap_or(f64::NAN),
            median,
            rr.last().copied().unwrap_or(f64::NAN),
            max_se
        ));
    }
    s.push_str(&format!(
        "\nMonte Carlo: {} photons per channel (materials, g = 0); skins {} photons per wavelength and channel, \
         {} nm steps ({} wavelengths: {} photons per channel); every case its own seed. Skins: {} two-layer skins \
         and {} dermis-only slab(s).\n",
        p.photons,
        p.skin_photons,
        p.step_nm,
        400 / p.step_nm + 1,
        u64::from(400 / p.step_nm + 1) * p.skin_photons,
        p.skin.len() + p.grid.melanin_fraction.len() * p.grid.hemoglobin_fraction.len(),
        p.dermis_only.len()
    ));
    s
}

fn accuracy_panels(rows: &[Row]) -> [LinePlot; 2] {
    let colors = [CHANNEL_COLORS[0], CHANNEL_COLORS[1], CHANNEL_COLORS[2], [0, 0, 0]];
    let model_color = |m: &str| match m {
        "multipole-symmetric" => colors[0],
        "multipole-directional" => colors[1],
        "spectral-multipole" => colors[2],
        _ => colors[3],
    };
    let panel = |rr: bool| {
        let mut series = Vec::new();
        let keys = groups(rows);
        let first_g = keys.iter().map(|k| k.2).next().unwrap_or(0.0);
        for key in keys {
            let mut pts = Vec::new();
            for row in rows.iter().filter(|r| r.g == key.2 && (r.fractions.is_some() == (key.0 == "skin"))) {
                for (_, all, _) in row.models.iter().filter(|m| m.0 == key.1) {
                    for (d, e) in all.iter().zip(&row.reference.total_r) {
                        let y = if rr { d.rr_error_percent } else { Some(d.total_r_difference_percent) };
                        if let Some(y) = y {
                            pts.push((e.mean, y));
                        }
                    }
                }
            }
            pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
            series.push(Curve {
                label: format!("{}, g = {}", key.1, key.2),
                color: model_color(key.1),
                dashed: key.2 != first_g,
                points: pts,
            });
        }
        LinePlot {
            title: if rr {
                "r R(r) error of diffusion vs Monte Carlo transport".into()
            } else {
                "Total diffuse R: diffusion vs Monte Carlo transport".into()
            },
            x_label: "Monte Carlo total diffuse R (per channel, dimensionless)".into(),
            y_label: if rr { "relative L2 error of r R(r) (%)".into() } else { "(model - MC) / MC (%)".into() },
            log_x: true,
            log_y: false,
            series,
        }
    };
    [panel(false), panel(true)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_params_round_trip_and_bad_params_name_the_field() {
        let (v, _): (_, ReportParams) = crate::bake::tests::default_params_round_trip(&assets()[0]);
        let expect = |field: &str, value: Value, name: &str| {
            let mut bad = v.clone();
            bad[field] = value;
            let e = bake(&bad).unwrap_err().to_string();
            assert!(e.contains(name), "{field}: {e}");
        };
        expect("plots", json!(["dipole/unobtainium"]), "plots[0]");
        expect("photons", json!(0), "photons");
        expect("skin_photons", json!(0), "skin_photons");
        expect("skin_photons", json!(200_000), "skin_photons");
        expect("g", json!([0.0, 1.0]), "g[1]");
        expect("grid", json!({"melanin_fraction": [0.9], "hemoglobin_fraction": [0.1]}), "grid[0][0].melanin_fraction");
        expect("dermis_only", json!([0.5]), "dermis_only[0].hemoglobin_fraction");
    }

    #[test]
    fn every_case_and_g_has_its_own_seed() {
        let p = default_params();
        let mut seeds = Vec::new();
        for cm in &p.grid.melanin_fraction {
            for chd in &p.grid.hemoglobin_fraction {
                for g in &p.g {
                    seeds.push(case_seed(
                        p.seed,
                        &format!("{} g={g}", SkinCase::TwoLayer { cm: *cm, chd: *chd }.name()),
                    ));
                }
            }
        }
        let n = seeds.len();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), n);
        // FNV-1a of the empty label is its offset basis (the published constant).
        assert_eq!(case_seed(0, ""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(case_seed(1, "a"), 0xaf63_dc4c_8601_ec8c ^ 1);
    }
}
