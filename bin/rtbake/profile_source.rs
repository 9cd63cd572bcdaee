//! Profile inputs shared by `fit gaussians` and `fit separable` beyond the named materials and presets:
//! a user layer stack (`--layers FILE`) or the physiological two-layer skin (`--skin-melanin`, `--skin-hemoglobin`).

use crate::cli::{parse_f64_list, usage, usage_msg, AddingArg, Ctx};
use rtbake::diffusion::burley::{RgbBurley, ShapeFit};
use rtbake::diffusion::layered::{Adding, LayerStack};
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::source::{MaterialModel, ProfileSource, TransportModel};
use rtbake::diffusion::{FdrForm, RadialProfile};
use rtbake::error::InvalidInput;
use rtbake::spectral::skin_layers::{physiological_skin_source, RgbReduction, SkinPhysiology, SkinProjection};
use rtbake::transport::profile::{DEFAULT_PROFILE_PHOTONS, DEFAULT_TISSUE_G};
use serde_json::{json, Value};
use std::path::PathBuf;

/// `--model` for layer stacks and skins: the transport model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TransportArg {
    /// Diffusion: multipole slabs combined by adding (Donner & Jensen 2005; the thesis' model).
    #[default]
    Multipole,
    /// Monte Carlo photon transport (MCML-style; --g, --photons, --seed).
    Mc,
}

/// `--skin-projection`: how a physiological skin's spectrum becomes RGB.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum SkinProjectionArg {
    /// Profiles per wavelength (380-780 nm, 10 nm), projected linearly to linear sRGB under D65 (the skin-colour
    /// LUT's colour is the profile's integral).
    #[default]
    Spectral,
    /// One RGB stack with band-averaged coefficients (D65 x sRGB-sensitivity weighted means; the earlier reduction).
    BandAveraged,
}

impl From<SkinProjectionArg> for SkinProjection {
    fn from(a: SkinProjectionArg) -> Self {
        match a {
            SkinProjectionArg::Spectral => SkinProjection::default(),
            SkinProjectionArg::BandAveraged => SkinProjection::BandAveraged { reduction: RgbReduction::default() },
        }
    }
}

/// Monte Carlo flags of `--model mc` (shared by every profile command).
#[derive(clap::Args, Debug, Default, Clone)]
pub struct McArgs {
    /// Henyey-Greenstein anisotropy for --model mc, in the open interval (-1, 1); sigma_s = sigma_s' / (1 - g) keeps
    /// the layers' reduced scattering. Default 0.8 (tissue-like: van Gemert et al. 1989, "Skin optics").
    #[arg(long, value_name = "G", allow_hyphen_values = true)]
    pub g: Option<f64>,
    /// Photons per channel (per wavelength for spectral skins) for --model mc, 1..=1e10 (default 100000).
    #[arg(long, value_name = "N")]
    pub photons: Option<u64>,
    /// Seed of the Monte Carlo random numbers for --model mc (the same seed gives the same bytes on any thread
    /// count; default 1).
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
}

impl McArgs {
    /// The transport model for `--model`; --g/--photons/--seed without `--model mc` are refused (exit 2).
    pub fn transport(&self, model: TransportArg) -> anyhow::Result<TransportModel> {
        if model != TransportArg::Mc {
            if self.g.is_some() || self.photons.is_some() || self.seed.is_some() {
                return Err(usage_msg("--g, --photons and --seed apply only to --model mc"));
            }
            return Ok(TransportModel::Multipole);
        }
        TransportModel::monte_carlo(
            self.g.unwrap_or(DEFAULT_TISSUE_G),
            self.photons.unwrap_or(DEFAULT_PROFILE_PHOTONS),
            self.seed.unwrap_or(1),
        )
        .map_err(|e| {
            let flag = crate::flags::flag_among(&e.param, &["--g", "--photons"]).unwrap_or("--model mc");
            usage(anyhow::anyhow!("{flag}: {}", e.message))
        })
    }
}

/// Refuses (exit 2) a source whose time estimate exceeds `--max-seconds`; the message names the flags that set it.
pub fn check_source_time(ctx: &Ctx, source: &ProfileSource, radii: usize) -> anyhow::Result<()> {
    let estimate = source.time_estimate_seconds(radii, rayon::current_num_threads());
    let flags = match source.transport() {
        Some(TransportModel::MonteCarlo { g, photons, .. }) => format!("--model mc --photons {photons} --g {g}"),
        _ => format!("{radii} radii of a layered profile"),
    };
    ctx.check_time(&flags, estimate)
}

/// Adds what only the built profile knows to its provenance: the Monte Carlo standard errors of the totals
/// (`total_R_se`) and the negative mass a spectral projection clipped (`clipped_negative_mass`).
pub fn add_standard_errors(provenance: &mut Value, profile: &dyn RadialProfile) {
    rtbake::diffusion::source::add_built_provenance(provenance, profile);
}

/// Checks the `--csv`, `--out` and `--plot` files of a profile-table command before any work (distinct, writable,
/// none of them one of the `--layers` inputs) and returns the plot's format.
pub fn check_table_outputs(
    csv: &Option<PathBuf>,
    out: &Option<PathBuf>,
    plot: &Option<PathBuf>,
    layers: &[PathBuf],
) -> anyhow::Result<Option<rtbake::plot::profile::PlotFormat>> {
    let outputs = [("--csv", csv), ("--out", out), ("--plot", plot)];
    check_distinct_outputs(&outputs)?;
    for (flag, path) in outputs {
        if let Some(p) = path {
            crate::profile::check_output_file(flag, p)?;
            let inputs: Vec<&std::path::Path> = layers.iter().map(PathBuf::as_path).collect();
            rtbake::io::file_set::check_outputs_not_inputs(std::slice::from_ref(p), &inputs)
                .map_err(|e| usage(anyhow::anyhow!("{flag}: {e}")))?;
        }
    }
    match plot {
        Some(path) => Ok(Some(rtbake::plot::profile::PlotFormat::from_path("--plot", path).map_err(usage)?)),
        None => Ok(None),
    }
}

/// Refuses (exit 2) two output flags naming the same file (`--csv X --out X` would leave only the last write).
/// Paths are compared after resolving their directories, so `./x` and `x` collide.
pub fn check_distinct_outputs(outputs: &[(&str, &Option<PathBuf>)]) -> anyhow::Result<()> {
    let key = |p: &PathBuf| {
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
        let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
        dir.join(p.file_name().unwrap_or_default())
    };
    for (i, (flag_a, a)) in outputs.iter().enumerate() {
        for (flag_b, b) in &outputs[i + 1..] {
            if let (Some(a), Some(b)) = (a, b) {
                if key(a) == key(b) {
                    return Err(usage_msg(format!(
                        "{flag_a} and {flag_b} name the same file {}: give each output its own path",
                        a.display()
                    )));
                }
            }
        }
    }
    Ok(())
}

/// A resolved target: the profile, its provenance JSON and a file stem.
pub type ResolvedProfile = (Box<dyn RadialProfile>, Value, String);

/// Layered-profile flags (flattened into the fit commands).
#[derive(clap::Args, Debug, Default)]
pub struct LayeredArgs {
    /// Target: a layer-stack JSON, top layer first (mm, mm^-1): {"eta_above": 1.0, "eta_below": 1.0, "layers":
    /// [{"thickness_mm": .., "eta": .., "sigma_a": [r,g,b], "sigma_s_prime": [r,g,b]}, ...]}
    #[arg(long, value_name = "FILE")]
    pub layers: Option<PathBuf>,
    /// Target: physiological two-layer skin (Donner & Jensen 2006; epidermis 0.25 mm over dermis 20 mm, eta 1.4)
    /// with this melanin volume fraction Cm in 0..=0.5; coefficients are D65 / sRGB-sensitivity-weighted spectral
    /// averages per channel (see `rtbake::spectral::skin_layers`)
    #[arg(long, value_name = "CM", requires = "skin_hemoglobin")]
    pub skin_melanin: Option<f64>,
    /// Dermal hemoglobin volume fraction Chd in 0..=0.32 for --skin-melanin
    #[arg(long, value_name = "CHD", requires = "skin_melanin")]
    pub skin_hemoglobin: Option<f64>,
    /// Layer adding for --layers / --skin-*: symmetric (DJ05 as printed, default) or directional (Kubelka)
    #[arg(long, value_enum, default_value = "symmetric")]
    pub adding: AddingArg,
    /// Truncate the multipole image series to i = -N..N (default: exact infinite series)
    #[arg(long, value_name = "N")]
    pub dipole_pairs: Option<u32>,
    /// Model for --layers / --skin-*: multipole (diffusion, default) or mc (Monte Carlo transport)
    #[arg(long, value_enum, default_value = "multipole")]
    pub model: TransportArg,
    #[command(flatten)]
    pub mc: McArgs,
    /// How --skin-* spectra become RGB: spectral (per-wavelength profiles projected to linear sRGB, default) or
    /// band-averaged (one RGB stack of averaged coefficients)
    #[arg(long, value_enum, default_value = "spectral")]
    pub skin_projection: SkinProjectionArg,
    /// Target: your own profile as CSV, the layout `rtbake profile --csv` and `rtbake transport --csv` write (`#`
    /// comments, header r_mm,R_r,R_g,R_b (or r_mm,R,G,B) or r_mm,R, rows of r in mm strictly increasing and R in mm^-2 >= 0, any
    /// spacing, >= 2 rows); interpolated linearly in log r, 0 beyond the last radius
    #[arg(long, value_name = "FILE")]
    pub profile_csv: Option<PathBuf>,
}

impl LayeredArgs {
    pub fn is_set(&self) -> bool {
        self.layers.is_some() || self.skin_melanin.is_some() || self.profile_csv.is_some()
    }

    /// Resolves the layered source, if one was given: (profile, provenance, file stem).
    pub fn resolve(&self, ctx: &Ctx) -> anyhow::Result<Option<ResolvedProfile>> {
        if !self.is_set() {
            if self.model == TransportArg::Mc {
                return Err(usage_msg("--model mc applies to --layers and --skin-melanin/--skin-hemoglobin"));
            }
            return Ok(None);
        }
        let given = [self.layers.is_some(), self.skin_melanin.is_some(), self.profile_csv.is_some()];
        if given.iter().filter(|&&g| g).count() > 1 {
            return Err(usage_msg("--layers, --skin-melanin/--skin-hemoglobin and --profile-csv are exclusive"));
        }
        let transport = self.mc.transport(self.model)?;
        if let Some(path) = &self.profile_csv {
            if self.model == TransportArg::Mc {
                return Err(usage_msg(
                    "--model mc applies to --layers and --skin-melanin/--skin-hemoglobin, not --profile-csv",
                ));
            }
            let text = std::fs::read_to_string(path)
                .map_err(|e| usage(anyhow::anyhow!("--profile-csv {}: cannot read: {e}", path.display())))?;
            let profile =
                rtbake::diffusion::tabulated::TabulatedProfile::from_csv_str(&text, &path.display().to_string())
                    .map_err(|e| usage(anyhow::anyhow!("--profile-csv {e}")))?;
            checked("--profile-csv", path, &profile)?;
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "profile".into());
            let provenance = json!({
                "model": "tabulated",
                "file": path.display().to_string(),
                "rows": profile.r_mm.len(),
                "interpolation": "linear in log r; held below the first radius, 0 above the last",
            });
            return Ok(Some((Box::new(profile), provenance, stem)));
        }
        let adding = Adding::from(self.adding);
        if let Some(n) = self.dipole_pairs {
            if n > 10_000 {
                return Err(usage_msg(format!("--dipole-pairs must be in 0..=10000, got {n}")));
            }
        }
        let series = self.dipole_pairs.map(|pairs| Series::Truncated { pairs }).unwrap_or_default();
        let (src, extra, stem) = if let Some(path) = &self.layers {
            let text = std::fs::read_to_string(path)
                .map_err(|e| usage(anyhow::anyhow!("--layers {}: cannot read: {e}", path.display())))?;
            let stack = LayerStack::from_json_str(&text)
                .map_err(|e| usage(anyhow::anyhow!("--layers {}: {e}", path.display())))?;
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "layers".into());
            let src = ProfileSource::Layers { stack, adding, series, fdr: FdrForm::Dj05, transport };
            (src, json!({"file": path.display().to_string()}), stem)
        } else {
            let cm = self.skin_melanin.expect("checked");
            let chd = self.skin_hemoglobin.expect("required by clap");
            let (src, extra) =
                physiological_skin(cm, chd, adding, series, FdrForm::Dj05, transport, self.skin_projection.into())?;
            (src, extra, format!("skin_cm{cm}_chd{chd}"))
        };
        check_source_time(ctx, &src, rtbake::diffusion::table::DEFAULT_COUNT)?;
        let profile = src.build().map_err(usage)?;
        let mut provenance = src.provenance();
        if let (Value::Object(p), Value::Object(e)) = (&mut provenance, extra) {
            p.extend(e);
        }
        add_standard_errors(&mut provenance, profile.as_ref());
        Ok(Some((profile, provenance, stem)))
    }
}

/// The one validation of a profile read from a user's file, before any consumer sees it
/// (`rtbake::fitting::profile_check`): every channel finite, non-negative, with a positive, finite total. The error
/// names the flag and the file.
pub fn checked(flag: &str, path: &std::path::Path, profile: &dyn RadialProfile) -> anyhow::Result<()> {
    rtbake::fitting::profile_check::check_profile(profile)
        .map_err(|e| usage(anyhow::anyhow!("{flag} {}: {}", path.display(), e.message)))
}

/// `--skin-melanin CM --skin-hemoglobin CHD` with the default physiology and RGB reduction, through the library's
/// one resolver; errors name the flags.
pub fn physiological_skin(
    cm: f64,
    chd: f64,
    adding: Adding,
    series: Series,
    fdr: FdrForm,
    transport: TransportModel,
    projection: SkinProjection,
) -> anyhow::Result<(ProfileSource, Value)> {
    physiological_skin_source(&SkinPhysiology::default(), &projection, cm, chd, adding, series, fdr, transport).map_err(
        |e| {
            let flag = crate::flags::flag_among(&e.param, &["--skin-melanin", "--skin-hemoglobin"])
                .unwrap_or("--skin-melanin/--skin-hemoglobin");
            usage(anyhow::anyhow!("{flag}: {e}"))
        },
    )
}

/// A Jensen 2001 material as a dipole (η = 1.3, DJ05 Fdr) or a sum-of-Gaussians preset, through
/// [`ProfileSource`] (the library's one resolver and provenance shape); `flag` names the option the user typed.
pub fn named(kind: Named<'_>) -> anyhow::Result<(ProfileSource, Box<dyn RadialProfile + Send>, String)> {
    let (src, flag, stem) = match kind {
        Named::Material { flag, name } => (
            ProfileSource::Material {
                name: name.to_string(),
                model: MaterialModel::Dipole,
                fdr: FdrForm::Dj05,
                series: Series::Exact,
            },
            flag,
            format!("{}_dipole", name.to_ascii_lowercase()),
        ),
        Named::Preset { flag, name } => (ProfileSource::Preset(name.to_string()), flag, name.to_ascii_lowercase()),
    };
    let profile = src.build().map_err(|e| usage(anyhow::anyhow!("{flag}: {}", e.message)))?;
    Ok((src, profile, stem))
}

/// What [`named`] resolves.
pub enum Named<'a> {
    Material { flag: &'a str, name: &'a str },
    Preset { flag: &'a str, name: &'a str },
}

/// Burley normalized diffusion from the artist's parameters (Christensen & Burley 2015): flattened into every
/// command that takes a Burley profile; `rtbake::diffusion::burley` does the maths.
#[derive(clap::Args, Debug, Default)]
pub struct BurleyArgs {
    /// Burley's normalized diffusion (Christensen & Burley 2015) with this surface albedo per channel, each in
    /// 0..=1 (needs --burley-mfp-mm).
    #[arg(long, value_name = "R,G,B", requires = "burley_mfp_mm", allow_hyphen_values = true)]
    pub burley_albedo: Option<String>,
    /// Mean free path per channel for --burley-albedo, mm (> 0); the shape parameter is d = mfp / s(A).
    #[arg(long, value_name = "R,G,B", requires = "burley_albedo", allow_hyphen_values = true)]
    pub burley_mfp_mm: Option<String>,
    /// Which of the paper's fits s(A) relates d to the mean free path (--burley-albedo only).
    #[arg(long, value_enum, default_value = "diffuse-transmission")]
    pub burley_fit: BurleyFitArg,
}

/// `--burley-fit`: Christensen & Burley's s(A) fits.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum)]
pub enum BurleyFitArg {
    /// Searchlight illumination, diffuse mean free path: s = 1.85 - A + 7|A - 0.8|^3.
    Searchlight,
    /// Diffuse surface transmission, diffuse mean free path: s = 1.9 - A + 3.5(A - 0.8)^2.
    #[default]
    DiffuseTransmission,
    /// Searchlight illumination, volume mean free path 1/sigma_t: s = 3.5 + 100(A - 0.33)^4.
    MeanFreePath,
}

impl From<BurleyFitArg> for ShapeFit {
    fn from(a: BurleyFitArg) -> Self {
        match a {
            BurleyFitArg::Searchlight => ShapeFit::Searchlight,
            BurleyFitArg::DiffuseTransmission => ShapeFit::DiffuseTransmission,
            BurleyFitArg::MeanFreePath => ShapeFit::MeanFreePath,
        }
    }
}

/// Three comma-separated numbers R,G,B for `flag`.
pub fn three(flag: &str, text: &str) -> anyhow::Result<[f64; 3]> {
    let v = parse_f64_list(flag, text)?;
    <[f64; 3]>::try_from(v.as_slice())
        .map_err(|_| usage_msg(format!("{flag}: expected three values R,G,B, got '{text}'")))
}

impl BurleyArgs {
    pub fn is_set(&self) -> bool {
        self.burley_albedo.is_some()
    }

    /// The validated profile and its [`ProfileSource`] (provenance), if --burley-albedo was given; errors name
    /// the flag and the channel.
    pub fn resolve(&self) -> anyhow::Result<Option<(RgbBurley, ProfileSource)>> {
        let (Some(albedo), Some(mfp)) = (&self.burley_albedo, &self.burley_mfp_mm) else {
            return Ok(None);
        };
        let (albedo, mean_free_path_mm) = (three("--burley-albedo", albedo)?, three("--burley-mfp-mm", mfp)?);
        let fit = ShapeFit::from(self.burley_fit);
        let profile = RgbBurley::from_mean_free_path(albedo, mean_free_path_mm, fit).map_err(|e| {
            let flag = crate::flags::flag_among(&e.param, &["--burley-albedo"]).unwrap_or("--burley-mfp-mm");
            usage(InvalidInput::new(flag, format!("{}: {}", e.param, e.message)))
        })?;
        Ok(Some((profile, ProfileSource::Burley { albedo, mean_free_path_mm, fit })))
    }
}
