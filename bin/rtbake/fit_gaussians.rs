//! `rtbake fit gaussians`: sum-of-Gaussians fit (thesis eq. 2.2) with screen-space parameters, or the Jensen 2001
//! error table.

use crate::cli::{prepare_out_dir, usage, usage_msg, Ctx};
use rtbake::diffusion::RadialProfile;
use rtbake::fitting::screen_space::{ScreenSpaceParams, StretchParams, DEFAULT_ALPHA, DEFAULT_BETA, DEFAULT_GAMMA};
use rtbake::fitting::{error_table, fit_sum_of_gaussians, FitSettings, GaussianFitError};
use rtbake::plot::profile::fit_overlay_plot;
use serde_json::{json, Value};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct FitGaussiansArgs {
    #[command(flatten)]
    pub target: super::FitTarget,
    /// Number of Gaussians (2..=8).
    #[arg(long, default_value_t = 4, allow_hyphen_values = true)]
    pub count: i64,
    /// Independent variances per channel (default: variances shared across R, G, B).
    #[arg(long)]
    pub per_channel: bool,
    /// Divide each channel by its total reflectance first (weights then sum to ~1).
    #[arg(long)]
    pub normalize: bool,
    /// Deterministic optimiser starts (1..=64).
    #[arg(long, default_value_t = 8)]
    pub starts: usize,
    /// Global SSS level α of the stretch factor s = α / (d + β·min(|∇d|, γ)) (thesis eq. 4.1–4.2) and of the
    /// depth-LOD thresholds (eq. 4.6), for a 720-pixel-high viewport; any finite value > 0 (thesis: 31.5).
    #[arg(long, default_value_t = DEFAULT_ALPHA, value_name = "ALPHA")]
    pub alpha: f64,
    /// β of the stretch factor above: how strongly the depth gradient |∇d| shrinks the kernel (eq. 4.1–4.2);
    /// any finite value >= 0 (thesis: 800).
    #[arg(long, default_value_t = DEFAULT_BETA, value_name = "BETA")]
    pub beta: f64,
    /// γ of the stretch factor above: the clamp of |∇d| (depth units per pixel) (eq. 4.1–4.2); any finite value
    /// >= 0 (thesis: 0.001).
    #[arg(long, default_value_t = DEFAULT_GAMMA, value_name = "GAMMA")]
    pub gamma: f64,
    /// Print the 33-entry error table of per-channel 4-Gaussian fits of the Jensen 2001 materials instead.
    #[arg(long, conflicts_with_all = ["material", "profile_preset", "out"])]
    pub error_table: bool,
    /// Also write JSON, HLSL/GLSL/WGSL includes and the plot (PNG, SVG) into DIR.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

/// Library input errors are bad usage (exit 2); optimiser failures are runtime errors (exit 1).
pub fn fit_error(e: GaussianFitError) -> anyhow::Error {
    match e {
        GaussianFitError::Invalid(i) => usage(i),
        other => anyhow::anyhow!(other),
    }
}

fn run_error_table(ctx: &Ctx) -> anyhow::Result<()> {
    let rows = error_table().map_err(fit_error)?;
    if ctx.json {
        ctx.emit_json(&json!({
            "count": 4,
            "per_channel": true,
            "profile": "dipole, eta 1.3, DJ05 Fdr (Jensen et al. 2001 coefficients)",
            "metric": "relative RMS sqrt(int r (R - fit)^2 dr / int r R^2 dr), percent",
            "rows": rows,
        }));
    } else {
        println!("{:<10} {:>9} {:>9} {:>9}   (per-channel 4-Gaussian fit error, %)", "material", "R", "G", "B");
        for r in &rows {
            println!(
                "{:<10} {:>9.4} {:>9.4} {:>9.4}",
                r.material, r.error_percent[0], r.error_percent[1], r.error_percent[2]
            );
        }
    }
    Ok(())
}

pub fn run(a: FitGaussiansArgs, ctx: &Ctx) -> anyhow::Result<()> {
    if a.error_table {
        return run_error_table(ctx);
    }
    let count = usize::try_from(a.count)
        .map_err(|_| usage_msg(format!("--count must be in 2..=8 Gaussians, got {}", a.count)))?;
    let settings = FitSettings { count, shared_variances: !a.per_channel, normalize: a.normalize, starts: a.starts };
    settings.validate().map_err(usage)?;
    let stretch = StretchParams { alpha: a.alpha, beta: a.beta, gamma: a.gamma };
    stretch.validate().map_err(usage)?;
    let (profile, source, stem) = a.target.resolve(ctx)?.ok_or_else(|| {
        usage_msg(
            "one of --material NAME, --profile-preset NAME, --layers FILE, --skin-melanin CM --skin-hemoglobin CHD, \
             --profile-csv FILE or --error-table is required",
        )
    })?;
    let fit = fit_sum_of_gaussians(profile.as_ref(), &settings).map_err(fit_error)?;
    let ss = ScreenSpaceParams::new(&fit.sum, stretch)?;
    let mut obj = ss.to_json();
    obj.insert("error_percent".into(), json!(fit.error_percent));
    obj.insert("profile_totals".into(), json!(fit.profile_totals));
    let prov = rtbake::bake::gaussians::fit_provenance(source, &settings);
    for (k, v) in prov.as_object().expect("object") {
        obj.insert(k.clone(), v.clone());
    }
    if let Some(dir) = &a.out {
        let mode = if settings.shared_variances { "shared" } else { "per_channel" };
        let file_stem = format!("fit_{stem}_k{count}_{mode}");
        let plotted: Box<dyn RadialProfile> = if settings.normalize {
            Box::new(rtbake::fitting::NormalizedProfile { inner: profile.as_ref(), totals: fit.profile_totals })
        } else {
            profile
        };
        let mut plot = fit_overlay_plot(plotted.as_ref(), Some(&fit.sum), &format!("{stem}: {count}-Gaussian fit"));
        if settings.normalize {
            plot = rtbake::plot::profile::normalized(plot);
        }
        let mut extra = obj.clone();
        for k in ScreenSpaceParams::new(&fit.sum, stretch)?.to_json().keys() {
            extra.remove(k);
        }
        let files = rtbake::bake::gaussians::gaussian_files(&file_stem, &fit.sum, stretch, extra, &plot)
            .map_err(|e| anyhow::anyhow!(e))?;
        prepare_out_dir("--out", dir)?;
        let inputs: Vec<&std::path::Path> =
            a.target.layered.layers.iter().chain(&a.target.layered.profile_csv).map(|p| p.as_path()).collect();
        crate::cli::write_set(ctx, "--out", dir, &files, &inputs)?;
        obj.insert(
            "files".into(),
            json!(files.iter().map(|f| dir.join(&f.path).display().to_string()).collect::<Vec<_>>()),
        );
        ctx.info(format!("wrote {} files to {}", files.len(), dir.display()));
    }
    if ctx.json {
        ctx.emit_json(&Value::Object(obj));
    } else {
        let names = ["R", "G", "B"];
        for (c, name) in names.iter().enumerate() {
            println!("{name} error {:.4} %", fit.error_percent[c]);
            for (v, w) in fit.sum.variances_mm2[c].iter().zip(&fit.sum.weights[c]) {
                println!("  v = {v:>12.6} mm^2   w = {w:.6}");
            }
        }
    }
    Ok(())
}
