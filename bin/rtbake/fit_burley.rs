//! `rtbake fit burley`: Burley's normalized diffusion (albedo A and shape parameter d per channel) fitted to a
//! profile (`rtbake::fitting::burley_fit`).

use crate::cli::{usage, usage_msg, Ctx};
use crate::profile_source::Named;
use rtbake::diffusion::RadialProfile;
use rtbake::fitting::burley_fit::fit_burley;
use serde_json::{json, Value};

#[derive(clap::Args)]
pub struct FitBurleyArgs {
    /// Jensen 2001 material as a dipole (η = 1.3, DJ05 Fdr): apple, chicken1, …, wholemilk.
    #[arg(long, value_name = "NAME", conflicts_with = "profile_preset")]
    pub material: Option<String>,
    /// A sum-of-Gaussians preset: deon6 | deon4.
    #[arg(long, value_name = "NAME")]
    pub profile_preset: Option<String>,
    /// Layered targets (--layers, --skin-melanin/--skin-hemoglobin) or your own profile (--profile-csv).
    #[command(flatten)]
    pub layered: crate::profile_source::LayeredArgs,
}

fn target(a: &FitBurleyArgs, ctx: &Ctx) -> anyhow::Result<(Box<dyn RadialProfile>, Value)> {
    if a.layered.is_set() && (a.material.is_some() || a.profile_preset.is_some()) {
        return Err(usage_msg(
            "give one target: --material, --profile-preset, --layers, --skin-melanin or --profile-csv",
        ));
    }
    if let Some((p, provenance, _)) = a.layered.resolve(ctx)? {
        return Ok((p, provenance));
    }
    let named = match (&a.material, &a.profile_preset) {
        (Some(name), _) => Named::Material { flag: "--material", name },
        (None, Some(name)) => Named::Preset { flag: "--profile-preset", name },
        (None, None) => {
            return Err(usage_msg(
                "one of --material, --profile-preset, --layers, --skin-melanin/--skin-hemoglobin or --profile-csv is required",
            ))
        }
    };
    let (src, profile, _) = crate::profile_source::named(named)?;
    Ok((profile, src.provenance()))
}

pub fn run(a: FitBurleyArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let (profile, source) = target(&a, ctx)?;
    let fit = fit_burley(profile.as_ref()).map_err(usage)?;
    let albedo = fit.channels.map(|b| b.albedo);
    let d_mm = fit.channels.map(|b| b.d_mm);
    if ctx.json {
        ctx.emit_json(&json!({
            "model": "burley",
            "albedo": albedo,
            "d_mm": d_mm,
            "s_per_mm": d_mm.map(|d| 1.0 / d),
            "error_percent": fit.error_percent,
            "metric": "relative L2 of r*R(r): sqrt(int (r (R - R_B))^2 dr / int (r R)^2 dr), percent",
            "profile_totals": fit.profile_totals,
            "source": source,
        }));
    } else {
        println!("channel   albedo A     d (mm)   error %   (Burley normalized diffusion, L2 of r*R(r))");
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            println!("{name:<7} {:>10.6} {:>10.6} {:>9.3}", albedo[c], d_mm[c], fit.error_percent[c]);
        }
    }
    Ok(())
}
