//! `rtbake evaluate` — given parameters against a target profile, with the fits' metrics. A fit's own
//! parameters evaluated back reproduce the error the fit reported; a profile against its own CSV is within the CSV's
//! interpolation error (over the CSV's range only); `--max-error` gates with exit 1 after printing the report; the
//! separable fit beats thesis Table 6.1 under the metric it minimises; bad input exits 2 naming the flag, writing
//! nothing.

use crate::support::rtbake;
use serde_json::Value;

fn json_ok(args: &[&str]) -> Value {
    let o = rtbake(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

/// `fit gaussians --out` then `evaluate --gaussians` of the written file against the same profile: the eq. 2.2 RMS
/// is the fit's `error_percent` (same grid, same weighting), for a dipole material and for a Burley profile.
#[test]
fn a_fitted_sum_of_gaussians_evaluates_back_to_its_fit_error() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("fit");
    let d = dir.to_str().unwrap();
    let fit = json_ok(&["--json", "fit", "gaussians", "--material", "skin1", "--count", "4", "--out", d]);
    let file = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .unwrap();
    let e = json_ok(&["--json", "evaluate", "--gaussians", file.to_str().unwrap(), "--against", "skin1"]);
    for (a, b) in nums(&fit["error_percent"]).iter().zip(nums(&e["eq_2_2_rms_percent"])) {
        assert!((a - b).abs() <= 1e-9 * a.max(1.0), "fit {a} % vs evaluate {b} %");
    }
    // skin1's 4-Gaussian fit is a good one in the plotted curve too.
    assert!(e["worst_relative_l2_percent"].as_f64().unwrap() < 10.0, "{e}");
    // Totals: the fit is not normalised, so the Gaussians carry the dipole's total diffuse reflectance (within 4 %
    // measured: eq. 2.2 does not constrain the total).
    for (a, b) in nums(&e["candidate_totals"]).iter().zip(nums(&e["target_totals"])) {
        assert!((a - b).abs() < 0.05 * b, "{a} vs {b}");
    }
}

/// Library level for Burley (the target `--against` cannot name): a 6-Gaussian fit of a Burley profile evaluated back
/// gives the fit's own error, and a better shape match in r·R(r) than in eq. 2.2's weighting (Burley's R ∝ 1/r at
/// the origin puts eq. 2.2's norm on the smallest radii, where Gaussians are flat: measured 69–74 % in eq. 2.2 and
/// 10–15 % in r·R(r)).
#[test]
fn gaussians_fitted_to_burley_evaluate_back() {
    use rtbake::diffusion::burley::{Burley, RgbBurley};
    use rtbake::fitting::evaluate::compare_profiles;
    use rtbake::fitting::{fit_sum_of_gaussians, FitSettings};
    let b = RgbBurley([Burley::new(0.8, 1.0).unwrap(), Burley::new(0.5, 0.5).unwrap(), Burley::new(0.3, 0.2).unwrap()]);
    let fit = fit_sum_of_gaussians(&b, &FitSettings { count: 6, ..FitSettings::default() }).unwrap();
    let e = compare_profiles(&fit.sum, &b, false).unwrap();
    for c in 0..3 {
        assert!((e.eq_2_2_rms_percent[c] - fit.error_percent[c]).abs() < 1e-9, "{e:?} vs {:?}", fit.error_percent);
        assert!(e.relative_l2_percent[c] < e.eq_2_2_rms_percent[c], "{e:?}");
        // Measured: 9 %, 2 %, 0.3 % low (R, G, B).
        assert!(e.total_difference[c].abs() < 0.1 * b.0[c].albedo, "{e:?}");
    }
}

/// A Burley profile against its own `profile --csv` output: compared over the CSV's rows only, the difference is the
/// CSV's linear-in-log-r interpolation (< 0.5 %), not its extrapolation below the first row (which held R constant,
/// where Burley's r·R(r) peaks). `--max-error` then passes at 1 % and fails at 0.001 % (exit 1, report on stdout).
#[test]
fn burley_against_its_own_csv_and_the_max_error_gate() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("b.csv");
    let c = csv.to_str().unwrap();
    let burley = ["--burley-albedo", "0.8,0.5,0.3", "--burley-mfp-mm", "2,1,0.5"];
    let mut a = vec!["profile", "--csv", c, "-q"];
    a.extend(burley);
    assert_eq!(rtbake(&a).status.code(), Some(0));
    let eval = |extra: &[&str]| {
        let mut a = vec!["--json", "evaluate", "--against", c];
        a.extend(burley);
        a.extend(extra);
        rtbake(&a)
    };
    let o = eval(&["--max-error", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["pass"], true);
    for key in ["relative_l2_percent", "max_percent"] {
        for e in nums(&v[key]) {
            assert!(e < 0.5, "{key}: {v}");
        }
    }
    let range = nums(&v["compared_range_mm"]);
    let rows = std::fs::read_to_string(&csv).unwrap();
    let first_r: f64 = rows
        .lines()
        .find(|l| l.starts_with(|c: char| c.is_ascii_digit()))
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(range[0] >= first_r * (1.0 - 1e-12), "{range:?} vs first row {first_r}");

    let o = eval(&["--max-error", "0.001"]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["pass"], false);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--max-error 0.001"));
}

/// `--separable`: the strength/falloff that `fit separable` returns has a lower relative L2 than thesis Table 6.1's
/// in every channel (the fit minimises that kernel distance), and a plot is written with both curves.
#[test]
fn the_separable_fit_beats_table_6_1_under_its_metric() {
    let t = tempfile::tempdir().unwrap();
    let fit = json_ok(&["--json", "fit", "separable", "--profile", "deon6"]);
    let (s, f) = (nums(&fit["strength"]), nums(&fit["falloff"]));
    let fitted = format!("{},{},{},{},{},{}", s[0], s[1], s[2], f[0], f[1], f[2]);
    let plot = t.path().join("sep.png");
    let a = json_ok(&[
        "--json",
        "evaluate",
        "--separable",
        &fitted,
        "--against",
        "deon6",
        "--plot",
        plot.to_str().unwrap(),
    ]);
    let b = json_ok(&["--json", "evaluate", "--separable", "0.78,0.70,0.75,0.57,0.13,0.08", "--against", "deon6"]);
    for (x, y) in nums(&a["relative_l2_percent"]).iter().zip(nums(&b["relative_l2_percent"])) {
        assert!(x < &y, "fit {x} % vs Table 6.1 {y} %");
    }
    let img = image::open(&plot).unwrap();
    assert!(img.width() >= 320 && img.height() >= 200);
}

#[test]
fn bad_evaluate_input_exits_2_naming_the_flag() {
    let t = tempfile::tempdir().unwrap();
    let plot = t.path().join("p.png");
    let p = plot.to_str().unwrap();
    let bad_json = t.path().join("bad.json");
    std::fs::write(&bad_json, r#"{"variances": [1, -2], "weights": [[1,1,1],[1,1,1]]}"#).unwrap();
    let bj = bad_json.to_str().unwrap();
    for (args, needle) in [
        (vec!["--separable", "0.5,1", "--against", "deon6", "--max-error", "-1"], "--max-error"),
        (vec!["--separable", "0.5,1", "--against", "nosuchthing"], "--against"),
        (vec!["--separable", "0.5,1,2", "--against", "deon6"], "--separable"),
        (vec!["--separable", "0.5,1", "--against", "deon6", "--normalize"], "--normalize"),
        (vec!["--gaussians", bj, "--against", "deon6"], "variances"),
        (vec!["--burley-albedo", "0.5,0.5,1.5", "--burley-d-mm", "1,1,1", "--against", "skin1"], "--burley-albedo"),
        (vec!["--burley-albedo", "0.5,0.5,0.5", "--against", "skin1"], "--burley-d-mm"),
    ] {
        let mut a = vec!["evaluate", "--plot", p];
        a.extend(&args);
        let o = rtbake(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!plot.exists(), "{args:?} wrote the plot");
    }
}
