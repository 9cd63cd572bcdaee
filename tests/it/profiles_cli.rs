//! `rtbake profile --plot FILE [--overlay-fit K]`: the files it writes and its bad-input handling.

use rtbake::io::png::{decode, DecodedPng};
use rtbake::plot::profile::CHANNEL_COLORS;
use std::path::Path;

use crate::support::rtbake;

fn ok(args: &[&str]) {
    let out = rtbake(args);
    assert!(out.status.success(), "{args:?}: stderr {}", String::from_utf8_lossy(&out.stderr));
}

fn path_str(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// `stroke` colours of the SVG's polylines, in document order.
fn polyline_strokes(svg: &str) -> Vec<String> {
    svg.lines()
        .filter(|l| l.starts_with("<polyline"))
        .map(|l| l.split("stroke=\"").nth(1).unwrap().split('"').next().unwrap().to_string())
        .collect()
}

#[test]
fn png_plot_decodes_with_both_panels_and_every_channel() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("skin1.png");
    ok(&["profile", "--material", "skin1", "--plot", &path_str(&png), "--json"]);
    let bytes = std::fs::read(&png).unwrap();
    let DecodedPng::U8(img) = decode(&bytes, "skin1.png").unwrap() else { panic!("8-bit PNG expected") };
    assert_eq!((img.width, img.height, img.channels), (720, 800, 3));
    // Each channel's colour is drawn in both panels (upper and lower half).
    for color in CHANNEL_COLORS {
        let rows: Vec<u32> = (0..img.height)
            .filter(|&y| (0..img.width).any(|x| (0..3).all(|c| img.get(x, y, c as u32) == color[c])))
            .collect();
        assert!(rows.iter().any(|&y| y < 400) && rows.iter().any(|&y| y >= 400), "colour {color:?}");
    }
}

#[test]
fn svg_plot_has_one_polyline_per_channel_and_panel() {
    let dir = tempfile::tempdir().unwrap();
    // Dipole: R only.
    let svg_path = dir.path().join("deon6.svg");
    ok(&["profile", "--profile-preset", "deon6", "--plot", &path_str(&svg_path), "--json"]);
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    let strokes = polyline_strokes(&svg);
    let rgb: Vec<String> = CHANNEL_COLORS.iter().map(|&c| hex(c)).collect();
    assert_eq!(strokes, [rgb.clone(), rgb.clone()].concat(), "R, G, B in each of the two panels");
    assert!(svg.contains("r R(r), log r axis") && svg.contains("R(r), log-log"));

    // Layer stack: R and T per channel and panel.
    let svg_path = dir.path().join("skin.SVG");
    ok(&["profile", "--skin-melanin", "0.1", "--skin-hemoglobin", "0.1", "--plot", &path_str(&svg_path), "--json"]);
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    // R in both panels and T in the linear one; T lies below the log panel's decade window there, so it has only
    // its legend entry (no empty polyline, which ImageMagick refuses).
    assert_eq!(polyline_strokes(&svg).len(), 9);
    assert!(!svg.contains(r#"points="""#));
    assert!(svg.contains(">T G</text>"));
}

#[test]
fn overlay_fit_adds_one_dashed_series_per_channel() {
    let dir = tempfile::tempdir().unwrap();
    let svg_path = dir.path().join("fit.svg");
    ok(&["profile", "--material", "marble", "--plot", &path_str(&svg_path), "--overlay-fit", "3", "--json"]);
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let lines: Vec<&str> = svg.lines().filter(|l| l.starts_with("<polyline")).collect();
    assert_eq!(lines.len(), 12);
    assert_eq!(lines.iter().filter(|l| l.contains("stroke-dasharray")).count(), 6);
    assert!(svg.contains(">3-Gaussian fit B</text>"));
    // The SVG records the model options and the fit.
    let desc = svg.split("<desc>rtbake profile: ").nth(1).unwrap().split("</desc>").next().unwrap();
    let v: serde_json::Value = serde_json::from_str(desc).unwrap();
    assert_eq!((v["material"].as_str(), v["model"].as_str()), (Some("marble"), Some("dipole")));
    assert_eq!(v["overlay_fit"]["count"], 3);
    assert_eq!(v["overlay_fit"]["variances_mm2"].as_array().unwrap().len(), 3);
}

/// Exit 2, the flag named on stderr, nothing in `dir`.
fn rejected(dir: &Path, args: &[&str], needle: &str) {
    let out = rtbake(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: stderr {err}");
    assert!(err.contains(needle), "{args:?}: stderr should name {needle:?}: {err}");
    let left: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty() || left == [dir.join("sub")], "{args:?} wrote {left:?}");
}

#[test]
fn bad_plot_paths_and_fit_counts_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let csv = path_str(&d.join("t.csv"));
    let out = path_str(&d.join("t.json"));
    for bad in ["p.jpg", "p", "p.png.txt"] {
        let plot = path_str(&d.join(bad));
        rejected(d, &["profile", "--material", "skin1", "--csv", &csv, "--out", &out, "--plot", &plot], "--plot");
    }
    let missing = path_str(&d.join("no/such/dir/p.png"));
    rejected(d, &["profile", "--material", "skin1", "--csv", &csv, "--plot", &missing], "--plot");
    std::fs::create_dir(d.join("sub")).unwrap();
    let is_dir = path_str(&d.join("sub"));
    rejected(d, &["profile", "--material", "skin1", "--csv", &csv, "--plot", &is_dir], "--plot");
    let plot = path_str(&d.join("p.png"));
    for k in ["1", "9"] {
        rejected(
            d,
            &["profile", "--material", "skin1", "--csv", &csv, "--plot", &plot, "--overlay-fit", k],
            "--overlay-fit",
        );
    }
    // --overlay-fit without --plot is a usage error too.
    rejected(d, &["profile", "--material", "skin1", "--csv", &csv, "--overlay-fit", "3"], "--plot");
}
