//! The published skin-colour LUT against Monte Carlo transport: `skin-color --model mc` and the baked
//! `skin-color-mc-difference` asset (PNG for people, per-texel CSV, node CSV), read as a consumer would.

use crate::support::rtbake;
use std::process::Output;

fn assert_usage(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "expected exit 2: {err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks '{n}': {err}");
    }
}

/// The asset bakes, `verify` recomputes it bit for bit, the PNG decodes as an sRGB picture with the map inside a
/// labelled frame, and the CSVs hold one row per texel / node. Physically the diffusion table is too bright for
/// every skin (multipole over-estimates low-albedo layers), so the transport's luminance is lower everywhere and
/// the colour difference is far above the Monte Carlo noise.
#[test]
fn difference_map_bakes_verifies_and_reads() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("b");
    let d = dir.to_str().unwrap();
    let o = rtbake(&["bake", "skin-color-mc-difference", "--out", d]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rtbake(&["verify", "--dir", d]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let png = std::fs::read(dir.join("skin/skin_color_mc_difference.png")).unwrap();
    assert!(rtbake::io::png::chunk_types(&png).contains(b"sRGB"), "plot tagged sRGB");
    let img = image::load_from_memory(&png).unwrap().to_rgb8();
    assert!(img.width() >= 512 && img.height() >= 512, "{}x{}", img.width(), img.height());

    let csv = std::fs::read_to_string(dir.join("skin/skin_color_mc_difference.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}"));
    let (de, rl) = (col("delta_e_ab"), col("relative_luminance"));
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 32 * 32);
    let max_de = rows.iter().map(|r| r[de]).fold(0.0, f64::max);
    for r in &rows {
        assert!(r[rl] < 0.0, "transport brighter than the multipole at {r:?}");
        assert!(r[de] > 1.0, "difference within the noise at {r:?}");
    }
    assert!(max_de > 5.0 && max_de < 60.0, "max dE*ab {max_de}");

    let nodes = std::fs::read_to_string(dir.join("skin/skin_color_mc_nodes.csv")).unwrap();
    assert_eq!(nodes.lines().count(), 1 + 16);
    for l in nodes.lines().skip(1) {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        for c in 0..3 {
            assert!(v[2 + c] > 0.0 && v[5 + c] > 0.0 && v[5 + c] < 0.25 * v[2 + c], "node {l}");
        }
    }
}

/// `skin-color --model mc` at a point: the transport colour is darker than the published one in every channel,
/// with the published colour and their dE*ab beside it; the same seed gives the same numbers.
#[test]
fn model_mc_point_is_darker_than_the_published_table() {
    let args = [
        "skin-color",
        "--melanin",
        "0.1",
        "--hemoglobin",
        "0.1",
        "--model",
        "mc",
        "--mc-nodes",
        "2",
        "--photons",
        "100",
        "--json",
    ];
    let o = rtbake(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["model"], "mc");
    assert_eq!(v["g"], 0.8);
    for c in 0..3 {
        let (m, p) = (v["linear_rgb"][c].as_f64().unwrap(), v["published_linear_rgb"][c].as_f64().unwrap());
        assert!(m > 0.0 && m < p, "channel {c}: Monte Carlo {m}, published {p}");
    }
    assert!(v["delta_e_ab"].as_f64().unwrap() > 1.0);
    let again: serde_json::Value = serde_json::from_slice(&rtbake(&args).stdout).unwrap();
    assert_eq!(v["linear_rgb"], again["linear_rgb"]);
}

/// Bad Monte Carlo settings exit 2 naming the flag and its range, before any work and with nothing written.
#[test]
fn model_mc_bad_input_names_the_flag() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("o");
    let o = out.to_str().unwrap();
    let mc = |extra: &[&str]| {
        let mut a = vec!["skin-color", "--model", "mc", "--out", o];
        a.extend_from_slice(extra);
        rtbake(&a)
    };
    assert_usage(&mc(&["--g", "1"]), &["--g", "(-1, 1)"]);
    assert_usage(&mc(&["--photons", "0"]), &["--photons"]);
    assert_usage(&mc(&["--mc-nodes", "1"]), &["--mc-nodes", "2..=17"]);
    assert_usage(&mc(&["--mc-step-nm", "7"]), &["--mc-step-nm"]);
    assert_usage(&mc(&["--map-size", "4"]), &["--map-size", "8..=256"]);
    assert_usage(&mc(&["--photons", "10000000", "--max-seconds", "5"]), &["--max-seconds", "estimated"]);
    assert_usage(&rtbake(&["skin-color", "--out", o, "--g", "0.5"]), &["--g", "--model mc"]);
    assert!(!out.exists(), "nothing may be written on bad input");
}
