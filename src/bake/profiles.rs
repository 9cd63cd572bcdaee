//! Diffusion-profile tables and plots in `baked/profiles/`: R(r) (and T(r) for
//! layer stacks) per channel on a log radius grid, with the totals R̂(0), T̂(0) and the model options, as CSV and
//! JSON ([`ProfileTable`]), plus a two-panel plot ([`crate::plot::profile`]: r·R(r) over log r, R(r) log–log) as
//! SVG for every profile and as PNG for the few listed in `png_plots`.
//!
//! Default profiles:
//! - `profiles/dipole/<material>`: the 11 measured materials of Jensen, Marschner, Levoy, Hanrahan, "A Practical
//!   Model for Subsurface Light Transport", SIGGRAPH 2001, as semi-infinite dipoles (η = 1.3, DJ05 Fdr);
//! - `profiles/presets/deon6`, `deon4`: d'Eon, Luebke, Enderton, "Efficient Rendering of Human Skin", EGSR 2007
//!   (6 Gaussians) and thesis Table 4.2 (4 Gaussians);
//! - `profiles/skin/two_layer_cm<Cm>_chd<Chd>`: the physiological two-layer skin (Donner & Jensen 2006 coefficients
//!   as in `spectral::skin_layers`; epidermis 0.25 mm over dermis 20 mm, η = 1.4) at (Cm, Chd) = (0.02, 0.05),
//!   (0.1, 0.1), (0.3, 0.05), symmetric adding (DJ05): by default per wavelength (380–780 nm, 10 nm) and projected
//!   linearly to linear sRGB under D65 (`skin_projection`; `{"kind": "band-averaged", ...}` keeps the earlier
//!   per-channel coefficients), with the multipole (`skin_model`; `{"model": "mc", "g", "photons", "seed"}` for
//!   Monte Carlo transport);
//! - `profiles/layered/skin3_example`: an illustrative three-layer stack, **not a measured material** (DJ05's
//!   three-layer skin coefficients are not public): a thin, translucent skin fold (ear rim, nostril) with air on both
//!   sides — epidermis 0.25 mm, blood-rich upper dermis 0.5 mm, lower dermis 1.5 mm, η = 1.4 throughout. The
//!   coefficients are the physiological model's, rounded to 3 digits: epidermis at (Cm, Chd) = (0.1, 0.05), upper
//!   dermis at Chd = 0.3, lower dermis at Chd = 0.05. Being thin, it has a visible T(r).
//!
//! `profiles/totals.csv` lists every profile's R̂(0) and T̂(0). All tables use the default grid of
//! `rtbake profile` (200 radii log-spaced over [0.001, 100] mm), so `rtbake profile --material skin1 --json` prints
//! the same numbers as `profiles/dipole/skin1.json`.

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile, FileMeta};
use crate::diffusion::layered::{Adding, LayerStack};
use crate::diffusion::multipole::Series;
use crate::diffusion::source::{MaterialModel, ProfileSource, TransportModel};
use crate::diffusion::table::{self, ProfileTable};
use crate::diffusion::{materials, sum_of_gaussians, FdrForm};
use crate::error::InvalidInput;
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use crate::plot::profile::{profile_panels, render, PlotFormat, PANEL_HEIGHT, PLOT_WIDTH};
use crate::spectral::skin_layers::{physiological_skin_source, SkinPhysiology, SkinProjection};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::collections::BTreeSet;

/// The radius grid (log-spaced, inclusive).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Grid {
    r_min_mm: f64,
    r_max_mm: f64,
    count: usize,
}

/// One point of the physiological two-layer skin.
use super::SkinPoint;

/// The transport model of the skins' profiles: `{"model": "multipole"}` (default) or
/// `{"model": "mc", "g": 0.8, "photons": 100000, "seed": 1}` (Monte Carlo, `transport::profile`; each wavelength
/// group its own stream).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SkinModel {
    model: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    g: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    photons: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    seed: Option<u64>,
}

impl SkinModel {
    fn transport(&self) -> Result<TransportModel, InvalidInput> {
        match self.model.as_str() {
            "multipole" if self.g.is_none() && self.photons.is_none() && self.seed.is_none() => {
                Ok(TransportModel::Multipole)
            }
            "multipole" => Err(InvalidInput::new("skin_model", "g, photons and seed apply only to model mc")),
            "mc" => TransportModel::monte_carlo(
                self.g.unwrap_or(crate::transport::profile::DEFAULT_TISSUE_G),
                self.photons.unwrap_or(crate::transport::profile::DEFAULT_PROFILE_PHOTONS),
                self.seed.unwrap_or(1),
            )
            .map_err(|e| InvalidInput::new(format!("skin_model.{}", e.param), e.message)),
            other => Err(InvalidInput::new("skin_model.model", format!("must be multipole or mc, got '{other}'"))),
        }
    }
}

/// A named layer stack (`stack` in the `--layers` JSON schema).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct NamedStack {
    name: String,
    /// What the stack is, recorded with its outputs.
    description: String,
    adding: Adding,
    stack: Value,
}

/// Parameters of `diffusion-profiles`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfilesParams {
    grid: Grid,
    /// Fdr polynomial for the dipoles and stacks.
    fdr: FdrForm,
    /// Jensen 2001 materials, as dipoles.
    materials: Vec<String>,
    /// Sum-of-Gaussians presets.
    presets: Vec<String>,
    /// Physiological two-layer skin points (default physiology and RGB reduction).
    skin: Vec<SkinPoint>,
    /// How the skin layers are combined.
    skin_adding: Adding,
    /// How a skin's spectrum becomes RGB (spectral projection by default, or band-averaged coefficients).
    skin_projection: SkinProjection,
    /// The skins' transport model (multipole by default; Monte Carlo with `{"model": "mc", ...}`).
    skin_model: SkinModel,
    /// User layer stacks.
    stacks: Vec<NamedStack>,
    /// Profiles (stems below `profiles/`, e.g. `dipole/skin1`) that also get a PNG plot.
    png_plots: Vec<String>,
}

fn default_params() -> ProfilesParams {
    let layer = |thickness_mm: f64, sigma_a: [f64; 3], sigma_s_prime: [f64; 3]| json!({"thickness_mm": thickness_mm, "eta": 1.4, "sigma_a": sigma_a, "sigma_s_prime": sigma_s_prime});
    ProfilesParams {
        grid: Grid {
            r_min_mm: table::DEFAULT_R_MIN_MM,
            r_max_mm: table::DEFAULT_R_MAX_MM,
            count: table::DEFAULT_COUNT,
        },
        fdr: FdrForm::Dj05,
        materials: materials::names().iter().map(|s| s.to_string()).collect(),
        presets: sum_of_gaussians::PRESET_NAMES.iter().map(|s| s.to_string()).collect(),
        skin: [(0.02, 0.05), (0.1, 0.1), (0.3, 0.05)]
            .map(|(cm, chd)| SkinPoint { melanin_fraction: cm, hemoglobin_fraction: chd })
            .to_vec(),
        skin_adding: Adding::Symmetric,
        skin_projection: SkinProjection::default(),
        skin_model: SkinModel { model: "multipole".into(), g: None, photons: None, seed: None },
        stacks: vec![NamedStack {
            name: "skin3_example".into(),
            description: "illustrative thin skin fold in air (not a measured material): epidermis 0.25 mm, blood-rich \
                          upper dermis 0.5 mm, lower dermis 1.5 mm; physiological-model coefficients rounded to 3 \
                          digits (epidermis at Cm 0.1, Chd 0.05; upper dermis Chd 0.3; lower dermis Chd 0.05)"
                .into(),
            adding: Adding::Symmetric,
            stack: json!({
                "eta_above": 1.0,
                "eta_below": 1.0,
                "layers": [
                    layer(0.25, [3.41, 4.81, 9.59], [5.46, 6.37, 9.15]),
                    layer(0.5, [3.87, 5.89, 20.5], [2.73, 3.18, 4.58]),
                    layer(1.5, [0.678, 1.03, 3.52], [2.73, 3.18, 4.58]),
                ],
            }),
        }],
        png_plots: vec![
            "dipole/skin1".into(),
            "presets/deon6".into(),
            "skin/two_layer_cm0.1_chd0.1".into(),
            "layered/skin3_example".into(),
        ],
    }
}

const CSV_CONVENTION: &str =
    "'#' lines: provenance (JSON) and totals R^(0) = int 2 pi r R dr (and T^(0)) per channel; \
columns r_mm, R_r, R_g, R_b in mm^-2 (then T_r, T_g, T_b for layer stacks); radii log-spaced";
const JSON_CONVENTION: &str = "r_mm: radii (mm, log-spaced); R: [r, g, b] per radius, mm^-2; total_R = R^(0) = \
int 2 pi r R dr; T, total_T for layer stacks; remaining keys: model options (provenance)";
const PLOT_CONVENTION: &str = "two panels over a log10 r axis (mm): r R(r) (1/mm, linear y) above, R(r) (mm^-2, log10 \
y, 10 decades) below; solid R per channel, dashed lighter T; SVG <desc>: model options (JSON)";

/// A stem component: lower-case letters, digits, `_`, `-`, `.`, not starting with `.`.
fn check_name(param: &str, name: &str) -> Result<(), InvalidInput> {
    let ok = !name.is_empty()
        && !name.starts_with('.')
        && name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || matches!(c, '_' | '-' | '.'));
    if ok {
        Ok(())
    } else {
        Err(InvalidInput::new(param, format!("must be a file name of [a-z0-9_.-] not starting with '.', got '{name}'")))
    }
}

/// The profiles to bake: (stem below `profiles/`, title, source, extra provenance keys).
fn sources(p: &ProfilesParams) -> Result<Vec<(String, String, ProfileSource, Value)>, InvalidInput> {
    let mut out = Vec::new();
    for name in &p.materials {
        let m = super::jensen_material("materials", name)?;
        let src = ProfileSource::Material {
            name: m.name.into(),
            model: MaterialModel::Dipole,
            fdr: p.fdr,
            series: Series::Exact,
        };
        out.push((
            format!("dipole/{}", m.name),
            format!("{} (dipole, Jensen 2001)", m.name),
            src,
            json!({"reference": "Jensen, Marschner, Levoy, Hanrahan, SIGGRAPH 2001"}),
        ));
    }
    for name in &p.presets {
        let lower = name.to_ascii_lowercase();
        crate::diffusion::source::gaussian_preset("presets", name)?;
        out.push((
            format!("presets/{lower}"),
            format!("{lower} (sum of Gaussians)"),
            ProfileSource::Preset(lower),
            json!({"reference": "d'Eon, Luebke, Enderton, EGSR 2007; thesis Table 4.2"}),
        ));
    }
    let physiology = SkinPhysiology::default();
    for (i, s) in p.skin.iter().enumerate() {
        let (cm, chd) = (s.melanin_fraction, s.hemoglobin_fraction);
        let (source, provenance) = physiological_skin_source(
            &physiology,
            &p.skin_projection,
            cm,
            chd,
            p.skin_adding,
            Series::Exact,
            p.fdr,
            p.skin_model.transport()?,
        )
        .map_err(|e| InvalidInput::new(format!("skin[{i}].{}", e.param), e.message))?;
        out.push((
            format!("skin/two_layer_cm{cm}_chd{chd}"),
            format!("two-layer skin, Cm {cm}, Chd {chd}"),
            source,
            provenance,
        ));
    }
    for (i, s) in p.stacks.iter().enumerate() {
        check_name(&format!("stacks[{i}].name"), &s.name)?;
        let stack = LayerStack::from_json_str(&s.stack.to_string())
            .map_err(|e| InvalidInput::new(format!("stacks[{i}].stack: {}", e.param), e.message))?;
        out.push((
            format!("layered/{}", s.name),
            format!("{} ({}-layer stack)", s.name, stack.layers().len()),
            ProfileSource::Layers {
                stack,
                adding: s.adding,
                series: Series::Exact,
                fdr: p.fdr,
                transport: TransportModel::Multipole,
            },
            json!({"name": s.name, "description": s.description}),
        ));
    }
    Ok(out)
}

fn bake(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: ProfilesParams = parse_params("diffusion-profiles", params)?;
    let radii = table::log_radii(p.grid.r_min_mm, p.grid.r_max_mm, p.grid.count)
        .map_err(|e| InvalidInput::new(format!("grid.{}", e.param), e.message))?;
    let list = sources(&p)?;
    let stems: BTreeSet<&str> = list.iter().map(|s| s.0.as_str()).collect();
    if stems.len() != list.len() {
        return Err(InvalidInput::new("materials/presets/skin/stacks", "list the same profile twice").into());
    }
    for (i, png) in p.png_plots.iter().enumerate() {
        if !stems.contains(png.as_str()) {
            return Err(InvalidInput::new(
                format!("png_plots[{i}]"),
                format!(
                    "'{png}' is not one of the baked profiles ({})",
                    stems.iter().copied().collect::<Vec<_>>().join(", ")
                ),
            )
            .into());
        }
    }
    // Every profile is independent: built side by side (the Hankel tables, the plots and their PNG compression),
    // then concatenated in list order, so the files and totals.csv are the same bytes for any thread count and
    // the first failing profile in list order is the error reported.
    let per_profile: Vec<Result<(Vec<BakedFile>, String), BakeError>> = list
        .par_iter()
        .map(|(stem, title, source, extra)| -> Result<(Vec<BakedFile>, String), BakeError> {
            let profile = source.build()?;
            let mut provenance = source.provenance();
            crate::diffusion::source::add_built_provenance(&mut provenance, profile.as_ref());
            if let (Value::Object(dst), Value::Object(src)) = (&mut provenance, extra) {
                for (k, v) in src {
                    dst.insert(k.clone(), v.clone());
                }
            }
            let t = ProfileTable::compute(profile.as_ref(), &radii, provenance)?;
            let path = format!("profiles/{stem}");
            let mut files = vec![
                text_file(&format!("{path}.csv"), t.to_csv(), FileKind::Csv, FileFormat::Csv, CSV_CONVENTION),
                json_file(&format!("{path}.json"), &t.to_json(), FileKind::Json, JSON_CONVENTION),
            ];
            let panels = profile_panels(&t, None, title);
            let svg = render(&panels, PlotFormat::Svg, &t.provenance)?;
            files.push(BakedFile {
                path: format!("{path}.svg"),
                bytes: svg,
                meta: FileMeta::text(FileKind::Plot, FileFormat::Svg, PLOT_CONVENTION),
            });
            if p.png_plots.iter().any(|s| s == stem) {
                let mut meta = FileMeta::text(FileKind::Plot, FileFormat::Png, PLOT_CONVENTION);
                meta.width = PLOT_WIDTH;
                meta.height = 2 * PANEL_HEIGHT;
                meta.channels = 3;
                meta.sample_type = SampleType::U8;
                meta.color_space = ColorSpace::Srgb;
                files.push(BakedFile {
                    path: format!("{path}.png"),
                    bytes: render(&panels, PlotFormat::Png, &t.provenance)?,
                    meta,
                });
            }
            let r = t.total_reflectance;
            let tt = t.total_transmittance.map(|v| format!("{:e},{:e},{:e}", v[0], v[1], v[2])).unwrap_or(",,".into());
            Ok((files, format!("{stem},{:e},{:e},{:e},{tt}\n", r[0], r[1], r[2])))
        })
        .collect();
    let mut files = Vec::new();
    let mut totals = String::from("profile,total_R_r,total_R_g,total_R_b,total_T_r,total_T_g,total_T_b\n");
    for result in per_profile {
        let (profile_files, row) = result?;
        files.extend(profile_files);
        totals.push_str(&row);
    }
    files.push(text_file(
        "profiles/totals.csv",
        totals,
        FileKind::Csv,
        FileFormat::Csv,
        "one row per baked profile (stem below profiles/): total_R = R^(0) = int 2 pi r R(r) dr, total_T = T^(0) per \
         channel (empty where the model has no T)",
    ));
    Ok(files)
}

/// [`Asset::time_estimate`]: every profile's own estimate ([`ProfileSource::time_estimate_seconds`] at the grid's
/// radii: the layered multipole's tabulation, or the Monte Carlo photons of `skin_model` mc), summed.
fn time_estimate(params: &Value, threads: usize) -> Result<f64, BakeError> {
    let p: ProfilesParams = parse_params("diffusion-profiles", params)?;
    Ok(sources(&p)?.iter().map(|(_, _, source, _)| source.time_estimate_seconds(p.grid.count, threads)).sum())
}

pub fn assets() -> Vec<Asset> {
    vec![Asset {
        name: "diffusion-profiles",
        summary: "R(r) (and T(r)) tables (CSV, JSON) and plots of the Jensen 2001 dipoles, d'Eon's presets, the \
                  physiological two-layer skin and an example 3-layer stack",
        default_params: || serde_json::to_value(default_params()).expect("params serialise"),
        bake,
        time_estimate: Some(time_estimate),
    }]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_params_round_trip_and_name_every_profile() {
        let (_, p): (_, ProfilesParams) = crate::bake::tests::default_params_round_trip(&assets()[0]);
        let list = sources(&p).unwrap();
        assert_eq!(list.len(), 11 + 2 + 3 + 1);
        let three = list.iter().find(|s| s.0 == "layered/skin3_example").unwrap();
        assert!(matches!(&three.2, ProfileSource::Layers { stack, .. } if stack.layers().len() == 3));
    }

    #[test]
    fn bad_params_name_the_field() {
        let mut v = (assets()[0].default_params)();
        v["png_plots"] = json!(["dipole/unobtainium"]);
        assert!(bake(&v).unwrap_err().to_string().contains("png_plots[0]"));
        let mut v = (assets()[0].default_params)();
        v["stacks"][0]["name"] = json!("../x");
        assert!(bake(&v).unwrap_err().to_string().contains("stacks[0].name"));
        let mut v = (assets()[0].default_params)();
        v["skin"][0]["melanin_fraction"] = json!(0.9);
        assert!(bake(&v).unwrap_err().to_string().contains("skin[0]"));
    }
}
