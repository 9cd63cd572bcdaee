//! `rtbake skin-color`: evaluate the spectral two-layer skin model at one (Cm, Chd) point, and/or bake the
//! melanin × hemoglobin lookup table into `--out DIR` (thesis §7.6, eq. 7.7). Glue only: flags → `SkinColorParams`
//! → library.

use crate::cli::AddingArg;
use crate::cli::{prepare_out_dir, usage, usage_msg, Ctx};
use rtbake::diffusion::FdrForm;
use rtbake::error::InvalidInput;
use rtbake::skin_color::lut::{IndexForm, LutEvaluation};
use rtbake::skin_color::monte_carlo::McColorParams;
use rtbake::skin_color::two_layer::{SkinColorError, ThinLayer};
use rtbake::skin_color::SkinColorParams;
use rtbake::spectral::colorimetry::Illuminant;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct SkinColorArgs {
    /// Melanin volume fraction Cm of the point to evaluate, 0..=0.5 (Table 7.1).
    #[arg(long, allow_negative_numbers = true, value_name = "CM")]
    pub melanin: Option<f64>,
    /// Dermal hemoglobin volume fraction Chd of the point to evaluate, 0..=0.32 (Table 7.1).
    #[arg(long, allow_negative_numbers = true, value_name = "CHD")]
    pub hemoglobin: Option<f64>,
    /// Also output the reflectance spectrum R(λ), 380–780 nm (with --json: "wavelength_nm" and "reflectance").
    #[arg(long)]
    pub spectrum: bool,
    /// Bake the lookup table with these parameters into DIR (files under DIR/skin/, written atomically).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Model and table parameters (boxed: keeps the subcommand enum small).
    #[command(flatten)]
    pub model: Box<ModelFlags>,
    #[command(flatten)]
    pub zstd: crate::cli::ZstdArg,
    /// Transport model: multipole (the published table: multipole slabs + adding) or mc (Monte Carlo transport on
    /// a coarse (Cm, Chd) grid, the ratio to the published colour interpolated bilinearly; with --out writes the
    /// difference map of the bake's skin-color-mc-difference asset instead of the table) [default: multipole].
    #[arg(long = "model", value_enum)]
    pub transport: Option<SkinModelArg>,
    #[command(flatten)]
    pub mc: Box<McFlags>,
}

#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
pub enum SkinModelArg {
    Multipole,
    Mc,
}

/// Monte Carlo flags of `--model mc`; each is the JSON field of `McColorParams` in kebab case.
#[derive(clap::Args)]
pub struct McFlags {
    /// Henyey-Greenstein anisotropy for --model mc, in the open interval (-1, 1); sigma_s = sigma_s' / (1 - g)
    /// [default: 0.8].
    #[arg(long, allow_negative_numbers = true)]
    pub g: Option<f64>,
    /// Photons per wavelength at the Cm = 0 grid nodes for --model mc, >= 1; darker nodes get up to 16 times as
    /// many, (1 + 3u)^2 with u = cbrt(Cm/0.5) [default: 120].
    #[arg(long)]
    pub photons: Option<u64>,
    /// Seed of the first grid node for --model mc (node k uses SEED + k) [default: 1].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Grid nodes per axis for --model mc, 2..=17, uniform in the table's cube-root axes [default: 4].
    #[arg(long)]
    pub mc_nodes: Option<u32>,
    /// Wavelength step of the Monte Carlo, nm; must divide 400 [default: 40].
    #[arg(long)]
    pub mc_step_nm: Option<u32>,
    /// Edge of the difference map for --model mc --out, 8..=256 texels [default: 32].
    #[arg(long)]
    pub map_size: Option<u32>,
}

impl McFlags {
    fn given(&self) -> Option<&'static str> {
        [
            (self.g.is_some(), "--g"),
            (self.photons.is_some(), "--photons"),
            (self.seed.is_some(), "--seed"),
            (self.mc_nodes.is_some(), "--mc-nodes"),
            (self.mc_step_nm.is_some(), "--mc-step-nm"),
            (self.map_size.is_some(), "--map-size"),
        ]
        .into_iter()
        .find_map(|(given, flag)| given.then_some(flag))
    }

    fn params(&self) -> McColorParams {
        let mut p = McColorParams::default();
        p.g = self.g.unwrap_or(p.g);
        p.photons = self.photons.unwrap_or(p.photons);
        p.seed = self.seed.unwrap_or(p.seed);
        p.mc_nodes = self.mc_nodes.unwrap_or(p.mc_nodes);
        p.mc_step_nm = self.mc_step_nm.unwrap_or(p.mc_step_nm);
        p.map_size = self.map_size.unwrap_or(p.map_size);
        p
    }
}

/// Every model/table parameter; each flag is the JSON field of `SkinColorParams` in kebab case.
#[derive(clap::Args)]
pub struct ModelFlags {
    /// βm: eumelanin share of the melanin, 0..=1 [default: 0.61].
    #[arg(long, allow_negative_numbers = true)]
    pub melanin_blend: Option<f64>,
    /// Che / Chd: epidermal hemoglobin as a fraction of dermal hemoglobin, 0..=1 [default: 0.25].
    #[arg(long, allow_negative_numbers = true)]
    pub epidermal_hemoglobin_ratio: Option<f64>,
    /// γ: blood oxygenation, 0..=1 [default: 0.75].
    #[arg(long, allow_negative_numbers = true)]
    pub oxygenation: Option<f64>,
    /// Hemoglobin concentration of whole blood, g/L, > 0 [default: 150].
    #[arg(long, allow_negative_numbers = true)]
    pub hemoglobin_g_per_l: Option<f64>,
    /// Molar mass of hemoglobin, g/mol, > 0 [default: 64500].
    #[arg(long, allow_negative_numbers = true)]
    pub hemoglobin_molar_mass_g_per_mol: Option<f64>,
    /// Epidermis thickness, mm, > 1/σt′ at every wavelength [default: 0.25].
    #[arg(long, allow_negative_numbers = true)]
    pub epidermis_thickness_mm: Option<f64>,
    /// Dermis thickness, mm, > 0 [default: 20].
    #[arg(long, allow_negative_numbers = true)]
    pub dermis_thickness_mm: Option<f64>,
    /// Refractive index of the epidermis (air above), 0.1..=10 [default: 1.4].
    #[arg(long, allow_negative_numbers = true)]
    pub eta_epidermis: Option<f64>,
    /// Refractive index of the dermis (equal to the epidermis = index-matched interface) [default: 1.4].
    #[arg(long, allow_negative_numbers = true)]
    pub eta_dermis: Option<f64>,
    /// Refractive index below the dermis (equal to the dermis = semi-infinite, matched bottom) [default: 1.4].
    #[arg(long, allow_negative_numbers = true)]
    pub eta_below_dermis: Option<f64>,
    /// Illuminant of the colorimetry [default: d65].
    #[arg(long, value_enum)]
    pub illuminant: Option<IlluminantArg>,
    /// Layer adding at k = 0: symmetric R1 + T1²R2/(1 − R1R2) (published) or directional [default: symmetric].
    #[arg(long, value_enum)]
    pub adding: Option<AddingArg>,
    /// Wavelength step of the 380–780 nm integration, nm; must divide 400 [default: 1].
    #[arg(long)]
    pub spectral_step_nm: Option<u32>,
    /// Fdr polynomial of the boundary conditions [default: dj05].
    #[arg(long, value_enum)]
    pub fdr_form: Option<FdrArg>,
    /// Epidermis thinner than 1/σt′: reject (error) or clamp-transmittance [default: reject].
    #[arg(long, value_enum)]
    pub thin_layer: Option<ThinLayerArg>,
    /// Accept Cm, Chd anywhere in [0, 1] (volume fractions) instead of Table 7.1's ranges.
    #[arg(long)]
    pub allow_unphysiological: bool,
    /// Table index: normalized-cbrt u = ∛(Cm/0.5), v = ∛(Chd/0.32), or literal-cbrt u = ∛Cm, v = ∛Chd
    /// [default: normalized-cbrt].
    #[arg(long, value_enum)]
    pub index_form: Option<IndexFormArg>,
    /// Table size: N (square) or WxH, each edge 2..=2048 texels [default: 256].
    #[arg(long, value_name = "N|WxH")]
    pub resolution: Option<String>,
    /// Epidermis totals in the table: tabulated exact series (default) or direct per texel.
    #[arg(long, value_enum)]
    pub lut_evaluation: Option<LutEvaluationArg>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum IlluminantArg {
    D65,
    EqualEnergy,
}
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum FdrArg {
    Dj05,
    Jensen01,
}
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ThinLayerArg {
    Reject,
    ClampTransmittance,
}
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum IndexFormArg {
    NormalizedCbrt,
    LiteralCbrt,
}
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum LutEvaluationArg {
    Tabulated,
    Direct,
}

/// Parses `N` or `WxH` (as u64, so absurd sizes are reported rather than overflowing).
fn parse_resolution(s: &str) -> anyhow::Result<(u64, u64)> {
    let bad = || usage_msg(format!("--resolution must be N or WxH (e.g. 256 or 256x128), got '{s}'"));
    let parse = |t: &str| t.trim().parse::<u64>().map_err(|_| bad());
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((parse(w)?, parse(h)?)),
        None => {
            let n = parse(s)?;
            Ok((n, n))
        }
    }
}

/// Flags → validated-later library parameters.
fn params(a: &ModelFlags) -> anyhow::Result<SkinColorParams> {
    let mut p = SkinColorParams::default();
    macro_rules! set {
        ($($f:ident),*) => { $( if let Some(v) = a.$f { p.$f = v; } )* };
    }
    set!(
        melanin_blend,
        epidermal_hemoglobin_ratio,
        oxygenation,
        hemoglobin_g_per_l,
        hemoglobin_molar_mass_g_per_mol,
        epidermis_thickness_mm,
        dermis_thickness_mm,
        eta_epidermis,
        eta_dermis,
        eta_below_dermis,
        spectral_step_nm
    );
    if let Some(v) = a.illuminant {
        p.illuminant = match v {
            IlluminantArg::D65 => Illuminant::D65,
            IlluminantArg::EqualEnergy => Illuminant::EqualEnergy,
        };
    }
    if let Some(v) = a.adding {
        p.adding = v.into();
    }
    if let Some(v) = a.fdr_form {
        p.fdr_form = match v {
            FdrArg::Dj05 => FdrForm::Dj05,
            FdrArg::Jensen01 => FdrForm::Jensen01,
        };
    }
    if let Some(v) = a.thin_layer {
        p.thin_layer = match v {
            ThinLayerArg::Reject => ThinLayer::Reject,
            ThinLayerArg::ClampTransmittance => ThinLayer::ClampTransmittance,
        };
    }
    if let Some(v) = a.index_form {
        p.index_form = match v {
            IndexFormArg::NormalizedCbrt => IndexForm::NormalizedCbrt,
            IndexFormArg::LiteralCbrt => IndexForm::LiteralCbrt,
        };
    }
    if let Some(v) = a.lut_evaluation {
        p.lut_evaluation = match v {
            LutEvaluationArg::Tabulated => LutEvaluation::Tabulated,
            LutEvaluationArg::Direct => LutEvaluation::Direct,
        };
    }
    p.allow_unphysiological = a.allow_unphysiological;
    if let Some(r) = &a.resolution {
        let (w, h) = parse_resolution(r)?;
        let max = rtbake::skin_color::lut::MAX_EDGE as u64;
        let min = rtbake::skin_color::lut::MIN_EDGE as u64;
        if !(min..=max).contains(&w) || !(min..=max).contains(&h) {
            return Err(usage_msg(format!("--resolution must be {min}..={max} texels per edge, got {w}x{h}")));
        }
        (p.width, p.height) = (w as u32, h as u32);
    }
    Ok(p)
}

/// A library error as bad usage (exit 2): `cli::exit_with` names its field by the flag `flags`' table maps it to. The
/// table's size, the library's `width` and `height`, is the one flag `--resolution WxH` here.
fn flag_error(e: SkinColorError) -> anyhow::Error {
    let SkinColorError::Invalid(e) = e;
    match e.param.as_str() {
        "width" | "height" => usage(InvalidInput::new("--resolution", e.message)),
        _ => usage(e),
    }
}

pub fn run(a: SkinColorArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let p = params(&a.model)?;
    let point = match (a.melanin, a.hemoglobin) {
        (Some(cm), Some(chd)) => Some((cm, chd)),
        (None, None) => None,
        (Some(_), None) => return Err(usage_msg("--melanin needs --hemoglobin (the point is (Cm, Chd))")),
        (None, Some(_)) => return Err(usage_msg("--hemoglobin needs --melanin (the point is (Cm, Chd))")),
    };
    if point.is_none() && a.out.is_none() {
        return Err(usage_msg("give a point (--melanin CM --hemoglobin CHD) and/or --out DIR to bake the table"));
    }
    if a.transport == Some(SkinModelArg::Mc) {
        return run_mc(&a, ctx, &p, point);
    }
    if let Some(flag) = a.mc.given() {
        return Err(usage_msg(format!("{flag} needs --model mc (it is a Monte Carlo setting)")));
    }
    if a.spectrum && point.is_none() {
        return Err(usage_msg("--spectrum needs a point (--melanin CM --hemoglobin CHD)"));
    }
    // Everything is validated and computed before anything is written.
    p.layout().map_err(flag_error)?;
    a.zstd.level()?;
    let model = p.model().map_err(flag_error)?;
    if a.out.is_some() {
        use rtbake::skin_color::lut;
        let layout = p.layout().map_err(flag_error)?;
        let evaluation = match p.lut_evaluation {
            lut::LutEvaluation::Tabulated => "tabulated",
            lut::LutEvaluation::Direct => "direct",
        };
        ctx.check_budget(
            &format!("--resolution {}x{} --lut-evaluation {evaluation}", layout.width, layout.height),
            lut::memory_estimate_bytes(&layout),
            lut::time_estimate_seconds(
                &layout,
                p.lut_evaluation,
                model.wavelengths_nm().len(),
                rayon::current_num_threads(),
            ),
        )?;
    }
    let sample = match point {
        Some((cm, chd)) => Some(model.evaluate(cm, chd, p.allow_unphysiological).map_err(flag_error)?),
        None => None,
    };
    let files = match &a.out {
        Some(_) => {
            let pb = ctx.progress(p.layout().map_err(flag_error)?.height as u64, "skin LUT rows");
            pb.set_style(
                indicatif::ProgressStyle::with_template("{msg} {bar:30} {pos}/{len} rows [{elapsed}]")
                    .expect("valid template"),
            );
            let files =
                rtbake::bake::skin::skin_color_lut_files_with_progress(&p, &|done, _| pb.set_position(done as u64))
                    .map_err(|e| match e {
                        rtbake::bake::BakeError::Invalid(i) => flag_error(SkinColorError::Invalid(i)),
                        other => anyhow::Error::new(other),
                    })?;
            pb.finish_and_clear();
            let mut files = files;
            a.zstd.apply(&mut files)?;
            Some(files)
        }
        None => None,
    };
    // `--out DIR` receives the files themselves, like `transmittance`, `fit` and `kernel` (the bake's `skin/`
    // subdirectory is the bake layout, not this command's).
    let files = files.map(|fs| {
        fs.into_iter()
            .map(|mut f| {
                f.path = f.path.strip_prefix("skin/").map(str::to_string).unwrap_or(f.path);
                f
            })
            .collect::<Vec<_>>()
    });
    let mut written = Vec::new();
    if let (Some(dir), Some(files)) = (&a.out, &files) {
        prepare_out_dir("--out", dir)?;
        written = crate::cli::write_set(ctx, "--out", dir, files, &[])?
            .iter()
            .map(|p| p.strip_prefix(dir).unwrap_or(p).to_string_lossy().into_owned())
            .collect();
        ctx.info(format!("wrote {} files of the skin-colour table to {}", written.len(), dir.display()));
    }
    if let Some(s) = &sample {
        if ctx.json {
            let mut v = serde_json::json!({ "linear_rgb": s.linear_rgb, "srgb8": s.srgb8 });
            if a.spectrum {
                v["wavelength_nm"] = serde_json::json!(model.wavelengths_nm());
                v["reflectance"] = serde_json::json!(s.reflectance);
            }
            if a.out.is_some() {
                v["written"] = serde_json::json!(written);
            }
            ctx.emit_json(&v);
        } else {
            let [r, g, b] = s.linear_rgb;
            let [r8, g8, b8] = s.srgb8;
            println!("Cm {} Chd {}: linear sRGB {r:.6} {g:.6} {b:.6}  sRGB8 {r8} {g8} {b8}", s.melanin, s.hemoglobin);
            if a.spectrum {
                println!("wavelength_nm,reflectance");
                for (l, r) in model.wavelengths_nm().iter().zip(&s.reflectance) {
                    println!("{l},{r:.8}");
                }
            }
        }
    } else if ctx.json {
        ctx.emit_json(&serde_json::json!({ "written": written }));
    }
    Ok(())
}

/// `--model mc`: the Monte Carlo grid of the same skin, validated and budgeted before any photon; the point's
/// colour (published colour times the interpolated node ratio) beside the published one, and/or the difference
/// map's files in `--out`.
fn run_mc(a: &SkinColorArgs, ctx: &Ctx, p: &SkinColorParams, point: Option<(f64, f64)>) -> anyhow::Result<()> {
    use rtbake::skin_color::monte_carlo::{delta_e_ab, McColorGrid};
    if a.spectrum {
        return Err(usage_msg("--spectrum is not available with --model mc (the grid holds colours, not spectra)"));
    }
    if p.allow_unphysiological {
        return Err(usage_msg("--allow-unphysiological is not available with --model mc (the grid spans Table 7.1)"));
    }
    a.zstd.level()?;
    let mc = a.mc.params();
    mc.validate().map_err(|e| flag_error(SkinColorError::Invalid(e)))?;
    let model = p.model().map_err(flag_error)?;
    let sample = match point {
        Some((cm, chd)) => Some(model.evaluate(cm, chd, false).map_err(flag_error)?),
        None => None,
    };
    let physiology = p.physiology();
    let estimate = mc
        .time_estimate_seconds(&physiology, rayon::current_num_threads())
        .map_err(|e| flag_error(SkinColorError::Invalid(e)))?;
    ctx.check_time(
        &format!(
            "--model mc --photons {} --mc-nodes {} --mc-step-nm {} --g {}",
            mc.photons, mc.mc_nodes, mc.mc_step_nm, mc.g
        ),
        estimate,
    )?;
    let grid = McColorGrid::simulate(&mc, &physiology).map_err(|e| flag_error(SkinColorError::Invalid(e)))?;
    let mut written = Vec::new();
    if let Some(dir) = &a.out {
        let mut files = rtbake::bake::skin::skin_color_mc_difference_files_for(p, &mc).map_err(|e| match e {
            rtbake::bake::BakeError::Invalid(i) => flag_error(SkinColorError::Invalid(i)),
            other => anyhow::Error::new(other),
        })?;
        a.zstd.apply(&mut files)?;
        for f in &mut files {
            f.path = f.path.strip_prefix("skin/").map(str::to_string).unwrap_or(f.path.clone());
        }
        prepare_out_dir("--out", dir)?;
        written = crate::cli::write_set(ctx, "--out", dir, &files, &[])?
            .iter()
            .map(|p| p.strip_prefix(dir).unwrap_or(p).to_string_lossy().into_owned())
            .collect();
        ctx.info(format!("wrote {} files of the Monte Carlo difference map to {}", written.len(), dir.display()));
    }
    let mut v = serde_json::json!({
        "model": "mc",
        "g": mc.g,
        "photons": mc.photons,
        "seed": mc.seed,
        "mc_nodes": mc.mc_nodes,
        "mc_step_nm": mc.mc_step_nm,
        "nodes_linear_rgb_se_max": grid.linear_rgb_se.iter().flatten().fold(0.0f64, |m, &x| m.max(x)),
    });
    if let Some(s) = &sample {
        // The point's Monte Carlo colour: the published colour times the bilinear ratio at the nodes, as in the map.
        let ratio = grid
            .ratio_to(&model)
            .map_err(|e| flag_error(SkinColorError::Invalid(e)))?
            .colour_at(s.melanin, s.hemoglobin);
        let m = [0, 1, 2].map(|c| s.linear_rgb[c] * ratio[c]);
        let de = delta_e_ab(s.linear_rgb, m);
        v["melanin"] = serde_json::json!(s.melanin);
        v["hemoglobin"] = serde_json::json!(s.hemoglobin);
        v["linear_rgb"] = serde_json::json!(m);
        v["published_linear_rgb"] = serde_json::json!(s.linear_rgb);
        v["delta_e_ab"] = serde_json::json!(de);
        if !ctx.json {
            println!(
                "Cm {} Chd {}: Monte Carlo (g {}) linear sRGB {:.6} {:.6} {:.6}; published {:.6} {:.6} {:.6}; dE*ab {de:.2}",
                s.melanin, s.hemoglobin, mc.g, m[0], m[1], m[2], s.linear_rgb[0], s.linear_rgb[1], s.linear_rgb[2]
            );
        }
    }
    if a.out.is_some() {
        v["written"] = serde_json::json!(written);
    }
    if ctx.json {
        ctx.emit_json(&v);
    }
    Ok(())
}
