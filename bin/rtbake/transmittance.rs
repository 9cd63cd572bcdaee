//! `rtbake transmittance`: evaluate T(s) (thesis eq. 5.12) at given distances, or bake the table files.

use crate::cli::{parse_f64_list, prepare_out_dir, usage, usage_msg, Ctx};
use crate::profile_source::{named, Named};
use rtbake::diffusion::sum_of_gaussians::preset;
use rtbake::diffusion::RadialProfile;
use rtbake::fitting::{fit_sum_of_gaussians, FitSettings, RgbGaussians};
use rtbake::transmittance::{TableSettings, TransmittanceForm, TransmittanceModel, DEFAULT_SAMPLES, DEFAULT_S_MAX_MM};
use serde_json::{json, Value};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct TransmittanceArgs {
    /// Sum-of-Gaussians preset: deon6 | deon4 (default deon6 unless --material is given).
    #[arg(long, value_name = "NAME", conflicts_with = "material")]
    pub profile_preset: Option<String>,
    /// Fit a Jensen 2001 material (dipole, η = 1.3) with --count Gaussians first and use that sum.
    #[arg(long, value_name = "NAME")]
    pub material: Option<String>,
    /// Gaussians of the fit for --material, --layers, --skin-* or --profile-csv (2..=8).
    #[arg(long, default_value_t = 6)]
    pub count: usize,
    /// With a fitted profile: divide each channel by its total first (T(0) = 1).
    #[arg(long)]
    pub normalize: bool,
    /// With a fitted profile: per-channel variances instead of shared ones.
    #[arg(long)]
    pub per_channel: bool,
    /// A profile to fit --count Gaussians to first, as for --material: your --profile-csv, a --layers stack or the
    /// physiological --skin-*.
    #[command(flatten)]
    pub layered: crate::profile_source::LayeredArgs,
    /// Burley's normalized diffusion: the closed-form plane integral T(s) = A (e^(-s/d) + 3 e^(-s/(3d)))/4 (the
    /// transmission profile engine bakers derive; implies --physical).
    #[command(flatten)]
    pub burley: crate::profile_source::BurleyArgs,
    /// Distances s in mm to evaluate, comma-separated (any order, each finite and >= 0).
    #[arg(long = "s", value_name = "MM,...", allow_hyphen_values = true)]
    pub s: Option<String>,
    /// Use exp(-s^2/(2v)) (plane integral of normalised Gaussians) instead of the published exp(-s^2/v).
    #[arg(long)]
    pub physical: bool,
    /// Write the table (EXR f32/f16, KTX2 RGBA16F, sRGB preview PNG, 16-bit linear PNG, JSON) into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Table texels along s (2..=16384).
    #[arg(long, default_value_t = DEFAULT_SAMPLES, allow_hyphen_values = true)]
    pub samples: u32,
    /// Table rows (1 = 1-D table; >1 repeats the row for APIs without 1-D textures).
    #[arg(long, default_value_t = 1)]
    pub height: u32,
    /// Table domain end s_max in mm (> 0); texel i holds s = s_max*i/(n-1).
    #[arg(long = "s-max", default_value_t = DEFAULT_S_MAX_MM, allow_hyphen_values = true)]
    pub s_max: f64,
    #[command(flatten)]
    pub zstd: crate::cli::ZstdArg,
}

fn source_model(a: &TransmittanceArgs, ctx: &Ctx) -> anyhow::Result<(TransmittanceModel, Value, String)> {
    let sources = [a.profile_preset.is_some(), a.material.is_some(), a.layered.is_set(), a.burley.is_set()];
    if sources.iter().filter(|&&s| s).count() > 1 {
        return Err(usage_msg(
            "give one profile: --profile-preset, --material, --layers, --skin-*, --profile-csv or --burley-albedo",
        ));
    }
    let fitted = a.material.is_some() || a.layered.is_set();
    if !fitted && (a.count != 6 || a.normalize || a.per_channel) {
        return Err(usage_msg(
            "--count, --normalize and --per-channel apply to a fitted profile (--material, --layers, --skin-*, \
             --profile-csv)",
        ));
    }
    if let Some((burley, src)) = a.burley.resolve()? {
        let stem = "burley".to_string();
        return Ok((TransmittanceModel::Burley(burley), src.provenance(), stem));
    }
    let target = match &a.material {
        Some(name) => {
            let (src, profile, _) = named(Named::Material { flag: "--material", name })?;
            Some((profile as Box<dyn RadialProfile>, src.provenance(), name.to_ascii_lowercase()))
        }
        None => a.layered.resolve(ctx)?,
    };
    if let Some((profile, provenance, stem)) = target {
        let settings = FitSettings {
            count: a.count,
            shared_variances: !a.per_channel,
            normalize: a.normalize,
            ..FitSettings::default()
        };
        settings.validate().map_err(usage)?;
        let fit = fit_sum_of_gaussians(profile.as_ref(), &settings).map_err(crate::fit::fit_error)?;
        let provenance = json!({"kind": "fit", "profile": provenance, "count": a.count,
                         "shared_variances": !a.per_channel, "normalize": a.normalize,
                         "error_percent": fit.error_percent});
        return Ok((TransmittanceModel::Gaussians(fit.sum), provenance, format!("{stem}_k{}", a.count)));
    }
    let name = a.profile_preset.clone().unwrap_or_else(|| "deon6".into());
    let (src, _, stem) = named(Named::Preset { flag: "--profile-preset", name: &name })?;
    let sog = preset(&name).expect("resolved by ProfileSource");
    Ok((TransmittanceModel::Gaussians(RgbGaussians::from(&sog)), src.provenance(), stem))
}

pub fn run(a: TransmittanceArgs, ctx: &Ctx) -> anyhow::Result<()> {
    // Burley has only the plane integral.
    let form = if a.physical || a.burley.is_set() { TransmittanceForm::Physical } else { TransmittanceForm::Published };
    // Validate every input before any work or output.
    let s_mm = match &a.s {
        Some(text) => {
            let v = parse_f64_list("--s", text)?;
            rtbake::transmittance::check_distances(&v).map_err(usage)?;
            Some(v)
        }
        None => None,
    };
    let table = TableSettings { samples: a.samples, height: a.height, s_max_mm: a.s_max, form };
    table.validate().map_err(usage)?;
    a.zstd.level()?;
    if a.out.is_some() {
        ctx.check_budget(
            &format!("--samples {} --height {}", a.samples, a.height),
            table.memory_estimate_bytes(),
            table.time_estimate_seconds(),
        )?;
    }
    if s_mm.is_none() && a.out.is_none() {
        return Err(usage_msg("nothing to do: give --s MM,... to evaluate and/or --out DIR to write the table"));
    }
    let (model, source, stem) = source_model(&a, ctx)?;
    let form_name = if form == TransmittanceForm::Physical { "physical" } else { "published" };
    let formula = model.formula(form);
    let mut result = json!({"form": form_name, "formula": formula, "source": source});
    if let Some(s) = &s_mm {
        let t = model.evaluate(s, form).map_err(usage)?;
        result["s_mm"] = json!(s);
        result["T"] = json!(t);
        if !ctx.json {
            ctx.info(formula);
            for (s, t) in s.iter().zip(&t) {
                println!("s = {s:>8.4} mm   T = {:.6} {:.6} {:.6}", t[0], t[1], t[2]);
            }
        }
    }
    if let Some(dir) = &a.out {
        let mut files =
            rtbake::bake::transmittance::table_files(&format!("{stem}_{form_name}"), &model, &table, source)
                .map_err(|e| anyhow::anyhow!(e))?;
        a.zstd.apply(&mut files)?;
        prepare_out_dir("--out", dir)?;
        crate::cli::write_set(ctx, "--out", dir, &files, &[])?;
        result["files"] = json!(files.iter().map(|f| dir.join(&f.path).display().to_string()).collect::<Vec<_>>());
        result["convention"] = json!(table.convention_for(formula));
        ctx.info(format!("wrote {} files to {}", files.len(), dir.display()));
    }
    if ctx.json {
        ctx.emit_json(&result);
    }
    Ok(())
}
