//! `rtbake evaluate`: the error of given parameters (a sum of Gaussians, separable strength/falloff, Burley A and d)
//! against a target profile, with the fits' metrics (library: `rtbake::fitting::evaluate`,
//! `rtbake::separable::fit::kernel_errors`); `--max-error` turns it into a pipeline gate (exit 1 above it).

use crate::cli::{parse_f64_list, parse_rgb, usage, usage_msg, Ctx};
use crate::profile_source::{named, physiological_skin, BurleyFitArg, Named};
use rtbake::diffusion::burley::{Burley, RgbBurley, ShapeFit};
use rtbake::diffusion::layered::{Adding, LayerStack};
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::source::{ProfileSource, TransportModel};
use rtbake::diffusion::{FdrForm, RadialProfile};
use rtbake::fitting::evaluate::compare_profiles;
use rtbake::plot::profile::{overlay_plot, render, PlotFormat};
use rtbake::plot::separable::separable_kernel_plot;
use rtbake::separable::fit::{kernel_errors, ObjectiveSpec, TargetKernel};
use rtbake::separable::SeparableParams;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("candidate").required(true).args(["gaussians", "separable", "burley_albedo"])))]
pub struct EvaluateArgs {
    /// Candidate: a sum-of-Gaussians file (the JSON `rtbake fit gaussians --out` and the bake write, e.g.
    /// baked/sss/gaussians/deon6.json: variances in mm^2, weights per Gaussian).
    #[arg(long, value_name = "JSON")]
    gaussians: Option<PathBuf>,
    /// Candidate: separable-SSS strength and falloff, "S,F" (all channels) or "Sr,Sg,Sb,Fr,Fg,Fb"; compared on the
    /// pixel-filtered 2-D kernel grid of `rtbake fit separable` (--width, --mm-per-world-unit, --pixel-mm).
    #[arg(long, value_name = "S,F", allow_hyphen_values = true)]
    separable: Option<String>,
    /// Candidate: Burley normalized diffusion with this surface albedo per channel R,G,B in 0..=1, with
    /// --burley-d-mm (shape parameter) or --burley-mfp-mm (mean free path, d = mfp / s(A)).
    #[arg(long, value_name = "R,G,B", allow_hyphen_values = true)]
    burley_albedo: Option<String>,
    /// Burley shape parameter d per channel, mm (> 0).
    #[arg(long, value_name = "R,G,B", requires = "burley_albedo", conflicts_with = "burley_mfp_mm")]
    burley_d_mm: Option<String>,
    /// Burley mean free path per channel, mm (> 0), with --burley-fit.
    #[arg(long, value_name = "R,G,B", requires = "burley_albedo")]
    burley_mfp_mm: Option<String>,
    /// Which of Christensen & Burley's s(A) fits maps --burley-mfp-mm to d.
    #[arg(long, value_enum, default_value = "diffuse-transmission")]
    burley_fit: BurleyFitArg,
    /// Target: a Jensen 2001 material name (dipole, eta 1.3), a preset (deon6, deon4), skin:CM,CHD (the
    /// physiological two-layer skin), a profile CSV (r_mm,R_r,R_g,R_b as `rtbake profile --csv` writes) or a
    /// layer-stack JSON file.
    #[arg(long, value_name = "TARGET")]
    against: String,
    /// Model of a skin:CM,CHD or layer-stack target: multipole (diffusion) or mc (Monte Carlo transport).
    #[arg(long, value_enum, default_value = "multipole")]
    model: crate::profile_source::TransportArg,
    #[command(flatten)]
    mc: crate::profile_source::McArgs,
    /// Compare shapes only: divide both profiles by their own totals first (Gaussians and Burley).
    #[arg(long)]
    normalize: bool,
    /// Exit 1 when the worst channel's relative L2 error (percent) exceeds this (the report is printed first).
    #[arg(long, value_name = "PERCENT", allow_hyphen_values = true)]
    max_error: Option<f64>,
    /// Write a plot of both (PNG or SVG by the extension): r·R(r) over log r; for --separable the pixel-filtered
    /// kernel along the x axis.
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// --separable: the fixed width (the shader's sssWidth, world units).
    #[arg(long, default_value_t = ObjectiveSpec::default().width, allow_hyphen_values = true)]
    width: f64,
    /// --separable: mm per world unit.
    #[arg(long, default_value_t = ObjectiveSpec::default().mm_per_world_unit, allow_hyphen_values = true)]
    mm_per_world_unit: f64,
    /// --separable: pixel footprint, mm.
    #[arg(long, default_value_t = ObjectiveSpec::default().pixel_mm, allow_hyphen_values = true)]
    pixel_mm: f64,
}

const TARGET_FORMS: &str =
    "a Jensen 2001 material (e.g. skin1), a preset (deon6, deon4), skin:CM,CHD, a profile .csv or a layer-stack .json";

/// Resolves `--against`: (profile, provenance, label).
fn target(text: &str, transport: TransportModel, ctx: &Ctx) -> anyhow::Result<(Box<dyn RadialProfile>, Value, String)> {
    let path = Path::new(text);
    let takes_model = text.starts_with("skin:") || text.to_ascii_lowercase().ends_with(".json");
    if transport != TransportModel::Multipole && !takes_model {
        return Err(usage_msg(format!(
            "--model mc applies to --against skin:CM,CHD and layer-stack .json targets, got '{text}'"
        )));
    }
    // The time budget of a Monte Carlo target (profiles evaluated at up to 4096 radii).
    let checked_build = |src: &ProfileSource| -> anyhow::Result<Box<dyn RadialProfile + Send>> {
        crate::profile_source::check_source_time(ctx, src, 4096)?;
        src.build().map_err(|e| usage(anyhow::anyhow!("--against {text}: {e}")))
    };
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if matches!(ext.as_deref(), Some("csv") | Some("json")) {
        let body =
            std::fs::read_to_string(path).map_err(|e| usage(anyhow::anyhow!("--against {text}: cannot read: {e}")))?;
        if ext.as_deref() == Some("csv") {
            let p = rtbake::diffusion::tabulated::TabulatedProfile::from_csv_str(&body, text)
                .map_err(|e| usage(anyhow::anyhow!("--against {e}")))?;
            crate::profile_source::checked("--against", path, &p)?;
            return Ok((Box::new(p), json!({"model": "tabulated", "file": text}), text.to_string()));
        }
        let stack = LayerStack::from_json_str(&body).map_err(|e| usage(anyhow::anyhow!("--against {text}: {e}")))?;
        let src = ProfileSource::Layers {
            stack,
            adding: Adding::Symmetric,
            series: Series::Exact,
            fdr: FdrForm::Dj05,
            transport,
        };
        let p = checked_build(&src)?;
        let mut provenance = src.provenance();
        crate::profile_source::add_standard_errors(&mut provenance, p.as_ref());
        return Ok((p, provenance, text.to_string()));
    }
    if let Some(rest) = text.strip_prefix("skin:") {
        let v = parse_f64_list("--against skin:CM,CHD", rest)?;
        if v.len() != 2 {
            return Err(usage_msg(format!("--against skin:CM,CHD needs two numbers, got '{rest}'")));
        }
        let (src, _) = physiological_skin(
            v[0],
            v[1],
            Adding::Symmetric,
            Series::Exact,
            FdrForm::Dj05,
            transport,
            Default::default(),
        )?;
        let p = checked_build(&src)?;
        let mut provenance = src.provenance();
        crate::profile_source::add_standard_errors(&mut provenance, p.as_ref());
        return Ok((p, provenance, format!("skin Cm {} Chd {}", v[0], v[1])));
    }
    // Names resolve only through the library's `ProfileSource`: a preset, else a Jensen material.
    let (src, p, _) = named(Named::Preset { flag: "--against", name: text })
        .or_else(|_| named(Named::Material { flag: "--against", name: text }))
        .map_err(|_| usage_msg(format!("--against must be {TARGET_FORMS}; got '{text}'")))?;
    let label = match src {
        ProfileSource::Material { ref name, .. } => format!("{name} (dipole)"),
        _ => text.to_string(),
    };
    Ok((p, src.provenance(), label))
}

fn burley(a: &EvaluateArgs, albedo: &str) -> anyhow::Result<(RgbBurley, Value)> {
    let albedo = parse_rgb("--burley-albedo", albedo)?;
    let named_err = |e: rtbake::error::InvalidInput| {
        let flag =
            crate::flags::flag_among(&e.param, &["--burley-albedo", "--burley-d-mm"]).unwrap_or("--burley-mfp-mm");
        usage(anyhow::anyhow!("{flag}: {e}"))
    };
    if let Some(d) = &a.burley_d_mm {
        let d = parse_rgb("--burley-d-mm", d)?;
        let mut ch = [Burley { albedo: 0.0, d_mm: 1.0 }; 3];
        for c in 0..3 {
            ch[c] = Burley::new(albedo[c], d[c]).map_err(named_err)?;
        }
        return Ok((RgbBurley(ch), json!({"model": "burley", "albedo": albedo, "d_mm": d})));
    }
    let Some(mfp) = &a.burley_mfp_mm else {
        return Err(usage_msg("--burley-albedo needs --burley-d-mm or --burley-mfp-mm"));
    };
    let mfp = parse_rgb("--burley-mfp-mm", mfp)?;
    let fit = ShapeFit::from(a.burley_fit);
    let b = RgbBurley::from_mean_free_path(albedo, mfp, fit).map_err(named_err)?;
    Ok((
        b,
        json!({"model": "burley", "albedo": albedo, "mean_free_path_mm": mfp, "shape_fit": fit.name(),
                  "d_mm": b.0.map(|x| x.d_mm)}),
    ))
}

fn separable_params(text: &str) -> anyhow::Result<SeparableParams> {
    let v = parse_f64_list("--separable", text)?;
    let p = match v.len() {
        2 => SeparableParams { strength: [v[0]; 3], falloff: [v[1]; 3] },
        6 => SeparableParams { strength: [v[0], v[1], v[2]], falloff: [v[3], v[4], v[5]] },
        n => return Err(usage_msg(format!("--separable: expected S,F or Sr,Sg,Sb,Fr,Fg,Fb, got {n} numbers"))),
    };
    rtbake::separable::kernel::validate_params(&p)
        .map_err(|e| usage(anyhow::anyhow!("--separable: {}", crate::flags::render(&e))))?;
    Ok(p)
}

pub fn run(a: EvaluateArgs, ctx: &Ctx) -> anyhow::Result<()> {
    // Validate everything before any work or output.
    if let Some(m) = a.max_error {
        if !(m.is_finite() && m >= 0.0) {
            return Err(usage_msg(format!("--max-error must be a finite percentage >= 0, got {m}")));
        }
    }
    let plot_format = match &a.plot {
        Some(p) => {
            crate::profile::check_output_file("--plot", p)?;
            Some(PlotFormat::from_path("--plot", p).map_err(usage)?)
        }
        None => None,
    };
    if a.separable.is_some() && a.normalize {
        return Err(usage_msg(
            "--normalize applies to --gaussians and --burley-albedo (the separable kernel has unit total)",
        ));
    }
    let transport = a.mc.transport(a.model)?;
    let (target_profile, target_provenance, target_label) = target(&a.against, transport, ctx)?;

    let (report, plot, worst) = if let Some(text) = &a.separable {
        let params = separable_params(text)?;
        let spec = ObjectiveSpec {
            width: a.width,
            mm_per_world_unit: a.mm_per_world_unit,
            pixel_mm: a.pixel_mm,
            ..ObjectiveSpec::default()
        };
        spec.validate().map_err(usage)?;
        let tk = TargetKernel::from_profile(target_profile.as_ref(), &spec, &target_label).map_err(usage)?;
        let (l2, max) = kernel_errors(&tk, &params);
        let worst = l2.iter().copied().fold(0.0, f64::max);
        let report = json!({
            "candidate": {"model": "separable", "strength": params.strength, "falloff": params.falloff,
                          "width": a.width, "mm_per_world_unit": a.mm_per_world_unit, "pixel_mm": a.pixel_mm},
            "target": target_provenance,
            "relative_l2_percent": l2,
            "max_percent": max,
            "metric": "pixel-filtered 2-D kernel on the fit grid of `rtbake fit separable`: sqrt(sum (S - s x s)^2 / sum S^2) and max |S - s x s| / max S, percent; both kernels have unit total",
            "total_difference": [0.0, 0.0, 0.0],
        });
        let plot = plot_format.map(|_| separable_kernel_plot(&tk, &params, &target_label));
        (report, plot, worst)
    } else {
        let (candidate, provenance): (Box<dyn RadialProfile>, Value) = if let Some(path) = &a.gaussians {
            let text = std::fs::read_to_string(path)
                .map_err(|e| usage(anyhow::anyhow!("--gaussians {}: cannot read: {e}", path.display())))?;
            let file: rtbake::baked_layout::GaussiansFile = serde_json::from_str(&text).map_err(|e| {
                usage(anyhow::anyhow!("--gaussians {}: not a sum-of-Gaussians file: {e}", path.display()))
            })?;
            let sum = file.sum().map_err(|e| usage(anyhow::anyhow!("--gaussians {}: {e}", path.display())))?;
            (Box::new(sum), json!({"model": "sum-of-gaussians", "file": path.display().to_string()}))
        } else {
            let (b, prov) = burley(&a, a.burley_albedo.as_deref().expect("clap group"))?;
            (Box::new(b), prov)
        };
        let e = compare_profiles(candidate.as_ref(), target_profile.as_ref(), a.normalize).map_err(usage)?;
        let plot = plot_format.map(|_| {
            let name = if a.normalize { "target (normalised)" } else { "target" };
            let title = format!("{} vs {target_label}", provenance["model"].as_str().unwrap_or("candidate"));
            if a.normalize {
                let t = rtbake::fitting::NormalizedProfile {
                    inner: target_profile.as_ref(),
                    totals: target_profile.total_reflectance(),
                };
                let c = rtbake::fitting::NormalizedProfile {
                    inner: candidate.as_ref(),
                    totals: candidate.total_reflectance(),
                };
                rtbake::plot::profile::normalized(overlay_plot(&t, name, Some((&c, "candidate")), &title))
            } else {
                overlay_plot(target_profile.as_ref(), name, Some((candidate.as_ref(), "candidate")), &title)
            }
        });
        let report = json!({
            "candidate": provenance,
            "target": target_provenance,
            "relative_l2_percent": e.relative_l2_percent,
            "max_percent": e.max_percent,
            "eq_2_2_rms_percent": e.eq_2_2_rms_percent,
            "compared_range_mm": e.compared_range_mm,
            "candidate_totals": e.candidate_totals,
            "target_totals": e.target_totals,
            "total_difference": e.total_difference,
            "normalized": e.normalized,
            "metric": "relative L2 of r*R(r): sqrt(int (r (R_c - R_t))^2 dr / int (r R_t)^2 dr); max |r dR| / max |r R_t|; eq. 2.2 RMS (the Gaussian fit's error_percent): sqrt(int r (R_c - R_t)^2 dr / int r R_t^2 dr); percent, on the fits' radial grid 1e-5..1e3 mm within compared_range_mm",
        });
        (report, plot, e.worst_relative_l2_percent())
    };

    if let (Some(path), Some(fmt), Some(plot)) = (&a.plot, plot_format, &plot) {
        let bytes = render(std::slice::from_ref(plot), fmt, &report)?;
        rtbake::io::atomic::write_atomic(path, &bytes)?;
    }
    let pass = a.max_error.map(|m| worst <= m);
    if ctx.json {
        let mut r = report.clone();
        r["worst_relative_l2_percent"] = json!(worst);
        r["max_error"] = json!(a.max_error);
        r["pass"] = json!(pass);
        ctx.emit_json(&r);
    } else {
        println!("candidate: {}", report["candidate"]);
        println!("target:    {target_label}");
        println!("channel   rel. L2 %     max %   eq2.2 RMS %   total difference");
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            let num = |key: &str| report[key][c].as_f64().unwrap_or(f64::NAN);
            println!(
                "{name:<7} {:>9.3} {:>9.3} {:>13} {:>+18.6}",
                num("relative_l2_percent"),
                num("max_percent"),
                report.get("eq_2_2_rms_percent").map_or("-".into(), |_| format!("{:.3}", num("eq_2_2_rms_percent"))),
                num("total_difference")
            );
        }
        if worst > 100.0 {
            // Errors of several hundred percent alarm without saying why: they mean two different profiles.
            let totals: Vec<f64> =
                (0..3).filter_map(|c| report["total_difference"][c].as_f64()).map(f64::abs).collect();
            let biggest_total = totals.iter().cloned().fold(0.0, f64::max);
            let why = if !a.normalize && biggest_total > 0.05 {
                format!(
                    "the totals differ by up to {biggest_total:.3} (e.g. a kernel normalised to total 1 against a \
                     material's reflectance), and the shapes differ; --normalize compares shapes only"
                )
            } else {
                "their shapes differ (the candidate's radii are not the target's)".to_string()
            };
            println!(
                "note: errors above 100 % mean the candidate is a different profile from the target, not a \
                 numerical problem: {why}. A fit of this target (rtbake fit gaussians / fit burley with the same \
                 target) evaluated back gives its fit error, typically a few percent."
            );
        }
    }
    match (pass, a.max_error) {
        (Some(false), Some(m)) => {
            Err(anyhow::anyhow!("worst relative L2 error {worst:.3} % exceeds --max-error {m} %"))
        }
        _ => Ok(()),
    }
}
