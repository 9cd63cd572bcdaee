//! A Monte Carlo result as text: CSV in the layout of `rtbake profile --csv`
//! ([`crate::diffusion::table::ProfileTable::to_csv`]: header `r_mm,R_r,R_g,R_b[,T_r,T_g,T_b]`, one row per bin
//! centre, R and T in mm⁻², no comment lines) so every consumer of profile tables (the fits' `--profile-csv`,
//! pandas, spreadsheets) reads it unchanged; provenance, totals and standard errors are in the JSON ([`to_json`]:
//! `R_se`, `T_se`), not in the CSV.

use super::compare::Comparison;
use super::mc::McResult;
use serde_json::{json, Value};

fn has_transmittance(r: &McResult) -> bool {
    r.channels.iter().any(|c| c.transmittance.mean > 0.0)
}

/// CSV, see the module docs (header row and data rows only; `provenance` and the totals go to [`to_json`]).
pub fn to_csv(r: &McResult, _provenance: &Value) -> String {
    let mut s = String::new();
    let t3 = |f: &dyn Fn(usize) -> f64| format!("{:e},{:e},{:e}", f(0), f(1), f(2));
    let transmits = has_transmittance(r);
    s.push_str(if transmits { "r_mm,R_r,R_g,R_b,T_r,T_g,T_b\n" } else { "r_mm,R_r,R_g,R_b\n" });
    for (i, radius) in r.settings.radii_mm().iter().enumerate() {
        s.push_str(&format!("{radius:e},{}", t3(&|c| r.channels[c].reflectance_mm2[i].mean)));
        if transmits {
            s.push_str(&format!(",{}", t3(&|c| r.channels[c].transmittance_mm2[i].mean)));
        }
        s.push('\n');
    }
    s
}

/// JSON: provenance, settings, per-bin R, T and their standard errors (rows of [r, g, b]), totals with standard
/// errors, specular reflectance, absorbed fraction per layer, and the comparison with diffusion when given.
pub fn to_json(r: &McResult, provenance: &Value, comparison: Option<&Comparison>) -> Value {
    let rows = |f: &dyn Fn(usize, usize) -> f64| -> Vec<[f64; 3]> {
        (0..r.settings.bins).map(|i| [f(0, i), f(1, i), f(2, i)]).collect()
    };
    let rgb = |f: &dyn Fn(usize) -> Value| -> Vec<Value> { (0..3).map(f).collect() };
    let mut v = json!({
        "provenance": provenance,
        "units": "r in mm, R and T in mm^-2 (annulus means at the bin centres), totals dimensionless",
        "photons_per_channel": r.photons,
        "seed": r.settings.seed,
        "batches": r.settings.batches,
        "bin_mm": r.settings.bin_mm,
        "r_mm": r.settings.radii_mm(),
        "R": rows(&|c, i| r.channels[c].reflectance_mm2[i].mean),
        "R_se": rows(&|c, i| r.channels[c].reflectance_mm2[i].se),
        "total_R": rgb(&|c| json!(r.channels[c].diffuse_reflectance)),
        "specular_R": rgb(&|c| json!(r.channels[c].specular_reflectance)),
        "total_T": rgb(&|c| json!(r.channels[c].transmittance)),
        "absorbed_per_layer": rgb(&|c| json!(r.channels[c].absorbed)),
        "interactions": rgb(&|c| json!(r.channels[c].interactions)),
    });
    if has_transmittance(r) {
        v["T"] = json!(rows(&|c, i| r.channels[c].transmittance_mm2[i].mean));
        v["T_se"] = json!(rows(&|c, i| r.channels[c].transmittance_mm2[i].se));
    }
    if let Some(cmp) = comparison {
        v["diffusion_comparison"] = json!(cmp);
    }
    v
}
