//! `rtbake report chi2`: the 2AFC χ² test of TAP 2009 Table II (library: `rtbake::study`).

use crate::cli::{usage_msg, Ctx};
use rtbake::plot::preference::{fig8_image, fig8_svg};
use rtbake::study::proportions::preference_proportions;
use rtbake::study::{chi_square_2afc, parse_counts_csv, tap2009, PreferenceCount};
use serde_json::json;
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub enum ReportCommand {
    /// One-sample χ² (df = 1, no continuity correction) of a two-alternative forced-choice study against the
    /// 50/50 expectation, with p-values and significance (TAP 2009 §6, Table II).
    Chi2(Chi2Args),
}

#[derive(clap::Args)]
pub struct Chi2Args {
    /// Preference counts: a CSV with the header `configuration,comparison,chosen,total` (chosen = how many of
    /// total participants picked the first alternative; non-negative integers, chosen ≤ total; `#` lines are
    /// comments), or `tap2009` for the counts TAP 2009 Table II implies (32 responses per comparison: 16
    /// participants, each pair shown twice).
    #[arg(long, value_name = "FILE|tap2009")]
    counts: String,
    /// Level of significance, in (0, 1).
    #[arg(long, default_value_t = 0.05, allow_hyphen_values = true)]
    alpha: f64,
    /// Also write the table as CSV (configuration,comparison,chosen,total,chi2,p_value,significant).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Also plot the proportion of trials the first alternative (TS) was chosen, per light angle and per camera
    /// distance (TAP 2009 Fig. 8, thesis Fig. 4.9), PNG or SVG by the extension; the conditions are read from the
    /// configuration names ("TS - Far - 110°": zoom/near/far and an angle in degrees).
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    plot: Option<PathBuf>,
}

pub fn run(cmd: ReportCommand, ctx: &Ctx) -> anyhow::Result<()> {
    match cmd {
        ReportCommand::Chi2(a) => chi2(a, ctx),
    }
}

fn chi2(a: Chi2Args, ctx: &Ctx) -> anyhow::Result<()> {
    if !(a.alpha > 0.0 && a.alpha < 1.0) {
        return Err(usage_msg(format!("--alpha must be in the open interval (0, 1), got {}", a.alpha)));
    }
    let plot_svg = match &a.plot {
        None => None,
        Some(p) => match p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("svg") => Some(true),
            Some("png") => Some(false),
            _ => return Err(usage_msg(format!("--plot {}: unknown extension; accepted .png, .svg", p.display()))),
        },
    };
    if let (Some(o), Some(p)) = (&a.out, &a.plot) {
        if o == p {
            return Err(usage_msg(format!("--out and --plot are the same file {}; give two names", o.display())));
        }
    }
    let builtin = a.counts == "tap2009";
    let counts: Vec<PreferenceCount> = if builtin {
        tap2009::implied_counts()
    } else {
        let body = std::fs::read_to_string(&a.counts)
            .map_err(|e| usage_msg(format!("--counts {}: cannot read: {e}", a.counts)))?;
        parse_counts_csv(&body).map_err(|e| usage_msg(format!("--counts {}: {e}", a.counts)))?
    };
    let tests = counts
        .iter()
        .map(|c| chi_square_2afc(c.chosen, c.total, a.alpha))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| usage_msg(format!("--counts {}: {e}", a.counts)))?;
    let mut csv = String::from("configuration,comparison,chosen,total,chi2,p_value,significant\n");
    let mut text = format!(
        "2AFC chi-square, df = 1, alpha = {}{}\n{:<22} {:<22} {:>11} {:>9} {:>7}  {}\n",
        a.alpha,
        if builtin { " (counts implied by TAP 2009 Table II)" } else { "" },
        "configuration",
        "comparison",
        "chosen",
        "chi2",
        "p",
        "significant"
    );
    let mut rows = Vec::new();
    for (c, t) in counts.iter().zip(&tests) {
        csv.push_str(&format!(
            "{},{},{},{},{},{:.6},{}\n",
            c.configuration, c.comparison, c.chosen, c.total, t.chi2, t.p_value, t.significant
        ));
        text.push_str(&format!(
            "{:<22} {:<22} {:>11} {:>9.3} {:>7.3}  {}\n",
            c.configuration,
            c.comparison,
            format!("{}/{}", c.chosen, c.total),
            t.chi2,
            t.p_value,
            if t.significant { "yes" } else { "no" }
        ));
        rows.push(json!({
            "configuration": c.configuration, "comparison": c.comparison, "chosen": c.chosen, "total": c.total,
            "chi2": t.chi2, "p_value": t.p_value, "significant": t.significant,
        }));
    }
    let proportions = preference_proportions(&counts);
    let plot_bytes = match plot_svg {
        None => None,
        Some(_) if proportions.by_light_azimuth_deg.is_empty() && proportions.by_distance.is_empty() => {
            return Err(usage_msg(format!(
                "--plot: no configuration of --counts {} names a camera distance (zoom, near, far) or a light angle \
                 (e.g. \"TS - Far - 110°\"); nothing to plot",
                a.counts
            )))
        }
        Some(true) => Some(fig8_svg(&proportions).into_bytes()),
        Some(false) => Some(rtbake::io::png::encode_u8_as(&fig8_image(&proportions), rtbake::io::png::PngColor::Srgb)?),
    };
    for (label, groups) in [
        (
            "light azimuth (deg)",
            proportions.by_light_azimuth_deg.iter().map(|(a, g)| (format!("{a}"), g)).collect::<Vec<_>>(),
        ),
        ("camera distance", proportions.by_distance.iter().map(|(d, g)| (d.name().to_string(), g)).collect()),
    ] {
        if groups.is_empty() {
            continue;
        }
        text.push_str(&format!("\nproportion of trials the first alternative was chosen, per {label}:\n"));
        for (k, g) in groups {
            let cells: Vec<String> =
                g.iter().map(|p| format!("{} {}/{} = {:.3}", p.comparison, p.chosen, p.total, p.proportion)).collect();
            text.push_str(&format!("  {k:<6} {}\n", cells.join("; ")));
        }
    }
    if let Some(path) = &a.out {
        rtbake::io::atomic::write_atomic(path, csv.as_bytes())
            .map_err(|e| anyhow::anyhow!("--out {}: {e}", path.display()))?;
    }
    if let (Some(path), Some(bytes)) = (&a.plot, &plot_bytes) {
        rtbake::io::atomic::write_atomic(path, bytes).map_err(|e| anyhow::anyhow!("--plot {}: {e}", path.display()))?;
    }
    if ctx.json {
        ctx.emit_json(&json!({ "alpha": a.alpha, "df": 1, "rows": rows, "proportions": proportions }));
    } else {
        crate::cli::print_stdout(&text);
    }
    Ok(())
}
