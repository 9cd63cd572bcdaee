//! `rtbake profile --burley-albedo … --burley-mfp-mm …` (issue 11, part): Burley's normalized diffusion as a
//! profile source — the values are the library's closed form, the totals are the albedos, the provenance rebuilds
//! the same profile, and bad input exits 2 naming the flag and the channel.

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
