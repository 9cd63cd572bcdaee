//! Issue 11 (part), user-facing profile inputs. `rtbake profile --burley-albedo … --burley-mfp-mm …`: Burley's
//! normalized diffusion as a profile source (the values are the library's closed form, the totals are the albedos,
//! the provenance rebuilds the same profile, bad input exits 2 naming the flag and the channel). `--profile-csv`:
//! a tabulated profile in the `rtbake profile --csv` layout for the fits (rtbake's own output reproduces the
//! built-in fit; bad CSVs exit 2 naming the file and the row).

use crate::support::rtbake;
use rtbake::diffusion::burley::{Burley, ShapeFit};
use rtbake::diffusion::source::ProfileSource;

#[test]
fn profile_values_are_the_closed_form_and_totals_the_albedo() {
    let o = rtbake(&[
        "--json",
        "profile",
        "--burley-albedo",
        "0.8,0.5,0.2",
        "--burley-mfp-mm",
        "3,1.5,0.8",
        "--burley-fit",
        "searchlight",
        "--radii",
        "0.05,0.5,2,10",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (albedo, mfp) = ([0.8, 0.5, 0.2], [3.0, 1.5, 0.8]);
    for (i, r) in [0.05, 0.5, 2.0, 10.0].iter().enumerate() {
        for c in 0..3 {
            let want =
                Burley::from_mean_free_path(albedo[c], mfp[c], ShapeFit::Searchlight).unwrap().reflectance_mm2(*r);
            let got = v["R"][i][c].as_f64().unwrap();
            assert!((got - want).abs() <= 1e-12 * want, "r = {r}, channel {c}: {got} vs {want}");
        }
    }
    for c in 0..3 {
        assert_eq!(v["total_R"][c].as_f64().unwrap(), albedo[c]);
    }
    // The recorded provenance rebuilds the same profile.
    let src = ProfileSource::from_json(&v).unwrap();
    assert!(matches!(src, ProfileSource::Burley { fit: ShapeFit::Searchlight, .. }), "{src:?}");
    let p = src.build().unwrap();
    assert_eq!(p.reflectance_mm2(0.5)[1], v["R"][1][1].as_f64().unwrap());
}

#[test]
fn bad_burley_input_exits_2_naming_the_flag() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("b.csv");
    let c = csv.to_str().unwrap();
    for (albedo, mfp, flag, needle) in [
        ("0.8,0.5,1.2", "1,1,1", "--burley-albedo", "albedo[2]"),
        ("0.8,-0.1,0.2", "1,1,1", "--burley-albedo", "0..=1"),
        ("0.8,0.5", "1,1,1", "--burley-albedo", "three values"),
        ("0.8,0.5,0.2", "1,0,1", "--burley-mfp-mm", "mean_free_path_mm"),
        ("0.8,0.5,0.2", "1,1,nan", "--burley-mfp-mm", ""),
    ] {
        let o = rtbake(&["profile", "--burley-albedo", albedo, "--burley-mfp-mm", mfp, "--csv", c]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{albedo} {mfp}: {err}");
        assert!(err.contains(flag) && err.contains(needle), "{albedo} {mfp}: {err}");
        assert!(!csv.exists());
    }
    let o = rtbake(&["profile", "--burley-albedo", "0.5,0.5,0.5", "--csv", c]);
    assert_eq!(o.status.code(), Some(2), "--burley-albedo needs --burley-mfp-mm");
}

/// `--profile-csv` (issue 11): rtbake's own `profile --csv` output fed back reproduces the fit of the built-in
/// profile (variances within 0.5 %, every weight above 1 % of the largest within 1 %, error within 0.05 points).
#[test]
fn profile_csv_of_a_built_in_profile_reproduces_its_gaussian_fit() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("skin1.csv");
    let o = rtbake(&["profile", "--material", "skin1", "--csv", csv.to_str().unwrap(), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let fit = |args: &[&str]| -> serde_json::Value {
        let mut a = vec!["--json", "fit", "gaussians"];
        a.extend(args);
        let o = rtbake(&a);
        assert_eq!(o.status.code(), Some(0), "{a:?}: {}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let (built_in, from_csv) = (fit(&["--material", "skin1"]), fit(&["--profile-csv", csv.to_str().unwrap()]));
    fn nums(v: &serde_json::Value) -> Vec<f64> {
        match v {
            serde_json::Value::Array(a) => a.iter().flat_map(nums).collect(),
            x => vec![x.as_f64().unwrap()],
        }
    }
    for (a, b) in nums(&built_in["variances"]).iter().zip(nums(&from_csv["variances"])) {
        assert!((a - b).abs() <= 5e-3 * a, "variance {a} vs {b}");
    }
    let (wa, wb) = (nums(&built_in["weights"]), nums(&from_csv["weights"]));
    let wmax = wa.iter().cloned().fold(0.0, f64::max);
    for (a, b) in wa.iter().zip(&wb) {
        if *a > 0.01 * wmax {
            assert!((a - b).abs() <= 1e-2 * a, "weight {a} vs {b}");
        }
    }
    for (a, b) in nums(&built_in["error_percent"]).iter().zip(nums(&from_csv["error_percent"])) {
        assert!((a - b).abs() <= 0.05, "error {a} vs {b}");
    }
    assert_eq!(from_csv["source"]["model"], "tabulated", "{}", from_csv["source"]);
}

#[test]
fn bad_profile_csvs_exit_2_naming_the_row() {
    let t = tempfile::tempdir().unwrap();
    for (name, text, needle) in [
        ("empty.csv", "", "is empty"),
        ("nan.csv", "r_mm,R\n0.1,1\n0.2,NaN\n", "row 3"),
        ("decreasing.csv", "r_mm,R\n0.2,1\n0.1,1\n", "row 3"),
        ("negative.csv", "r_mm,R_r,R_g,R_b\n0.1,1,1,1\n0.2,1,-1,1\n", "row 3"),
        ("one_row.csv", "r_mm,R\n0.1,1\n", "at least 2 rows"),
    ] {
        let path = t.path().join(name);
        std::fs::write(&path, text).unwrap();
        let out = t.path().join("out");
        let o = rtbake(&["fit", "separable", "--profile-csv", path.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains("--profile-csv") && err.contains(name) && err.contains(needle), "{name}: {err}");
        assert!(!out.exists());
    }
}

/// `rtbake fit burley` recovers the parameters of a Burley profile written by `rtbake profile --csv` (through the
/// CSV's interpolation: within 1 %), and names what is missing.
#[test]
fn fit_burley_recovers_a_burley_profile_from_its_csv() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("b.csv");
    let c = csv.to_str().unwrap();
    let o = rtbake(&["profile", "--burley-albedo", "0.8,0.5,0.2", "--burley-mfp-mm", "3,1.5,0.8", "--csv", c, "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rtbake(&["--json", "fit", "burley", "--profile-csv", c]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for (ch, (a, mfp)) in [(0.8, 3.0), (0.5, 1.5), (0.2, 0.8)].iter().enumerate() {
        let want = Burley::from_mean_free_path(*a, *mfp, ShapeFit::DiffuseTransmission).unwrap();
        let (ga, gd) = (v["albedo"][ch].as_f64().unwrap(), v["d_mm"][ch].as_f64().unwrap());
        assert!((ga - want.albedo).abs() < 0.01 * want.albedo, "channel {ch}: A {ga} vs {}", want.albedo);
        assert!((gd - want.d_mm).abs() < 0.01 * want.d_mm, "channel {ch}: d {gd} vs {}", want.d_mm);
    }
    let o = rtbake(&["fit", "burley"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--profile-csv"));
}
