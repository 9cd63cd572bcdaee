//! `rtbake fit burley`: Burley's normalized diffusion (albedo A and shape parameter d per channel) fitted to a
//! profile (`rtbake::fitting::burley_fit`).

use crate::cli::{usage, usage_msg, Ctx};
use rtbake::fitting::burley_fit::fit_burley;
use serde_json::json;

#[derive(clap::Args)]
pub struct FitBurleyArgs {
    #[command(flatten)]
    pub target: super::FitTarget,
}

pub fn run(a: FitBurleyArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let (profile, source, _) = a.target.resolve(ctx)?.ok_or_else(|| {
        usage_msg(
            "one of --material, --profile-preset, --layers, --skin-melanin/--skin-hemoglobin or --profile-csv is required",
        )
    })?;
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
