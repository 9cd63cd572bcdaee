//! `rtbake report chi2`: the 2AFC χ² test of TAP 2009 Table II (library: `rtbake::study`).

use crate::cli::{usage_msg, Ctx};
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
    /// comments), or `tap2009` for the counts TAP 2009 Table II implies (32 participants per comparison).
    #[arg(long, value_name = "FILE|tap2009")]
    counts: String,
    /// Level of significance, in (0, 1).
    #[arg(long, default_value_t = 0.05, allow_hyphen_values = true)]
    alpha: f64,
    /// Also write the table as CSV (configuration,comparison,chosen,total,chi2,p_value,significant).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
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
    if let Some(path) = &a.out {
        rtbake::io::atomic::write_atomic(path, csv.as_bytes())
            .map_err(|e| anyhow::anyhow!("--out {}: {e}", path.display()))?;
    }
    if ctx.json {
        ctx.emit_json(&json!({ "alpha": a.alpha, "df": 1, "rows": rows }));
    } else {
        crate::cli::print_stdout(&text);
    }
    Ok(())
}
