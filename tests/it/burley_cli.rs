//! User-facing profile inputs. `rtbake profile --burley-albedo … --burley-mfp-mm …`: Burley's
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

/// `--profile-csv`: rtbake's own `profile --csv` output fed back reproduces the fit of the built-in
/// profile (variances within 0.5 %, every weight above 1 % of the largest within 1 %, error within 0.05 points), for a
/// dipole (skin1) and for the layered multipole of the physiological two-layer skin (Cm 0.1, Chd 0.1).
#[test]
fn profile_csv_of_a_built_in_profile_reproduces_its_gaussian_fit() {
    let t = tempfile::tempdir().unwrap();
    for (name, source, count) in [
        ("skin1", &["--material", "skin1"][..], "6"),
        // The band-averaged skin: its 4-Gaussian fit is well conditioned enough for these tolerances (the spectral
        // default's smallest weights move by a few % with the CSV's interpolation).
        ("skin", &["--skin-melanin", "0.1", "--skin-hemoglobin", "0.1", "--skin-projection", "band-averaged"][..], "4"),
    ] {
        let csv = t.path().join(format!("{name}.csv"));
        let mut a = vec!["profile", "--csv", csv.to_str().unwrap(), "-q"];
        a.extend(source);
        let o = rtbake(&a);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let fit = |args: &[&str]| -> serde_json::Value {
            let mut a = vec!["--json", "fit", "gaussians", "--count", count];
            a.extend(args);
            let o = rtbake(&a);
            assert_eq!(o.status.code(), Some(0), "{a:?}: {}", String::from_utf8_lossy(&o.stderr));
            serde_json::from_slice(&o.stdout).unwrap()
        };
        let (built_in, from_csv) = (fit(source), fit(&["--profile-csv", csv.to_str().unwrap()]));
        fn nums(v: &serde_json::Value) -> Vec<f64> {
            match v {
                serde_json::Value::Array(a) => a.iter().flat_map(nums).collect(),
                x => vec![x.as_f64().unwrap()],
            }
        }
        for (a, b) in nums(&built_in["variances"]).iter().zip(nums(&from_csv["variances"])) {
            assert!((a - b).abs() <= 5e-3 * a, "{name}: variance {a} vs {b}");
        }
        let (wa, wb) = (nums(&built_in["weights"]), nums(&from_csv["weights"]));
        let wmax = wa.iter().cloned().fold(0.0, f64::max);
        for (a, b) in wa.iter().zip(&wb) {
            if *a > 0.01 * wmax {
                assert!((a - b).abs() <= 1e-2 * a, "{name}: weight {a} vs {b}");
            }
        }
        for (a, b) in nums(&built_in["error_percent"]).iter().zip(nums(&from_csv["error_percent"])) {
            assert!((a - b).abs() <= 0.05, "{name}: error {a} vs {b}");
        }
        assert_eq!(from_csv["source"]["model"], "tabulated", "{}", from_csv["source"]);
    }
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

/// `rtbake kernel --profile-csv` fits strength and falloff to the user's profile exactly as
/// `rtbake fit separable --profile-csv` does, then builds the same taps as `kernel --strength S --falloff F`; given
/// together with --strength the two sources are refused (exit 2, both named) and nothing is written.
#[test]
fn kernel_from_a_profile_csv_is_the_fit_separable_kernel() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("skin1.csv");
    let c = csv.to_str().unwrap();
    let o = rtbake(&["profile", "--material", "skin1", "--csv", c, "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let json = |args: &[&str]| -> serde_json::Value {
        let o = rtbake(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let fit = json(&["--json", "fit", "separable", "--profile-csv", c]);
    let kernel = json(&["--json", "kernel", "--samples", "9", "--profile-csv", c]);
    assert_eq!(kernel["strength"], fit["strength"]);
    assert_eq!(kernel["falloff"], fit["falloff"]);
    assert_eq!(kernel["fitted_to"].as_str(), Some(c));
    let rgb = |v: &serde_json::Value| -> String {
        (0..3).map(|i| format!("{:?}", v[i].as_f64().unwrap())).collect::<Vec<_>>().join(",")
    };
    let by_hand = json(&[
        "--json",
        "kernel",
        "--samples",
        "9",
        "--strength",
        &rgb(&fit["strength"]),
        "--falloff",
        &rgb(&fit["falloff"]),
    ]);
    assert_eq!(kernel["kernel"], by_hand["kernel"]);
    // The fitted falloff is not the published default: the profile was used.
    assert_ne!(kernel["falloff"][0].as_f64().unwrap(), 1.0);

    let out = t.path().join("k");
    let o = rtbake(&["kernel", "--profile-csv", c, "--strength", "0.5", "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--strength") && err.contains("--profile-csv"), "{err}");
    assert!(!out.exists());
}

/// `rtbake transmittance --burley-*` (the transmission profile engine bakers derive from Burley): T(s) is
/// the closed-form plane integral A (e^(−s/d) + 3e^(−s/(3d)))/4 at every texel of the baked table, T(0) = A, the
/// sidecar records A and d instead of Gaussians, and the form is the plane integral whatever --physical says.
#[test]
fn transmittance_from_burley_is_the_plane_integral() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("t");
    let args = ["--burley-albedo", "0.8,0.5,0.3", "--burley-mfp-mm", "1,0.5,0.25", "--burley-fit", "searchlight"];
    let mut a = vec!["--json", "transmittance", "--s", "0,0.5,2", "--samples", "64", "--s-max", "4"];
    a.extend(args);
    a.extend(["--out", out.to_str().unwrap()]);
    let o = rtbake(&a);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["form"], "physical");
    let want = |c: usize, s: f64| {
        Burley::from_mean_free_path([0.8, 0.5, 0.3][c], [1.0, 0.5, 0.25][c], ShapeFit::Searchlight)
            .unwrap()
            .plane_transmittance(s)
    };
    for (i, s) in [0.0, 0.5, 2.0].iter().enumerate() {
        for c in 0..3 {
            let got = v["T"][i][c].as_f64().unwrap();
            assert!((got - want(c, *s)).abs() <= 1e-15, "s = {s}, channel {c}: {got}");
        }
    }
    assert_eq!(v["T"][0][2].as_f64().unwrap(), 0.3);
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("burley_physical.json")).unwrap()).unwrap();
    assert!(side.get("variances_mm2").is_none(), "{side}");
    assert_eq!(side["burley"]["albedo"][0].as_f64(), Some(0.8));
    assert!(side["formula"].as_str().unwrap().contains("Burley"));
    // The f32 EXR texels, read as the `image` crate reads them: texel i holds s = 4·i/63.
    let img = image::open(out.join("burley_physical.exr")).unwrap().to_rgb32f();
    assert_eq!(img.dimensions(), (64, 1));
    for i in [0u32, 1, 20, 63] {
        let s = 4.0 * i as f64 / 63.0;
        for c in 0..3 {
            let got = img.get_pixel(i, 0)[c] as f64;
            assert!((got - want(c, s)).abs() <= 1e-7, "texel {i}, channel {c}: {got} vs {}", want(c, s));
        }
    }
}

/// `rtbake transmittance --profile-csv` fits --count Gaussians to the user's profile as --material does
/// to the built-in one: rtbake's own skin1 CSV gives T(s) within 1 % (of T(0)) of `--material skin1`. Two profile
/// sources, or fit flags without a fitted profile, exit 2 and write nothing.
#[test]
fn transmittance_from_a_profile_csv_matches_the_built_in_material() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("skin1.csv");
    let c = csv.to_str().unwrap();
    let o = rtbake(&["profile", "--material", "skin1", "--csv", c, "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let run = |src: &[&str]| -> serde_json::Value {
        let mut a = vec!["--json", "transmittance", "--s", "0,0.25,1,3", "--count", "4"];
        a.extend(src);
        let o = rtbake(&a);
        assert_eq!(o.status.code(), Some(0), "{a:?}: {}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let (built_in, from_csv) = (run(&["--material", "skin1"]), run(&["--profile-csv", c]));
    assert_eq!(from_csv["source"]["profile"]["model"], "tabulated");
    for i in 0..4 {
        for ch in 0..3 {
            let (a, b) = (built_in["T"][i][ch].as_f64().unwrap(), from_csv["T"][i][ch].as_f64().unwrap());
            let t0 = built_in["T"][0][ch].as_f64().unwrap();
            assert!((a - b).abs() <= 0.01 * t0, "s index {i}, channel {ch}: {a} vs {b}");
        }
    }
    let out = t.path().join("t");
    let o_ = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["--profile-csv", c, "--material", "skin1"], "give one profile"),
        (vec!["--profile-csv", c, "--burley-albedo", "0.5,0.5,0.5", "--burley-mfp-mm", "1,1,1"], "give one profile"),
        (vec!["--profile-preset", "deon4", "--count", "3"], "--count"),
        (vec!["--burley-albedo", "0.5,0.5,0.5", "--burley-mfp-mm", "1,0,1"], "--burley-mfp-mm"),
    ] {
        let mut a = vec!["transmittance", "--out", o_];
        a.extend(&args);
        let o = rtbake(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists());
    }
}
