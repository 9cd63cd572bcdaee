//! `rtbake report chi2` — TAP 2009 Table II's χ² and significance from the counts the paper implies, the
//! same from a user's counts file, and bad counts files refused (exit 2, the line and column named, nothing written).

use crate::support::rtbake;
use rtbake::study::tap2009::published;
use serde_json::Value;

/// The built-in implied counts reproduce every printed χ² exactly and every printed p to its 3 decimals; the
/// significance column is the paper's reading (only SS Full at Zoom 110° of the SS Full column differs from TS).
#[test]
fn reproduces_tap2009_table_ii_from_the_implied_counts() {
    let o = rtbake(&["--json", "report", "chi2", "--counts", "tap2009"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 36);
    let mut not_significant = 0;
    for (r, p) in rows.iter().zip(published().iter()) {
        assert_eq!(r["chi2"].as_f64().unwrap(), p.chi2, "{r}");
        assert!((r["p_value"].as_f64().unwrap() - p.p_value).abs() <= 5e-4, "{r} vs printed p {}", p.p_value);
        not_significant += usize::from(!r["significant"].as_bool().unwrap());
    }
    assert_eq!(not_significant, 11, "the paper: SS Full not significantly different from TS in 11 of 12");
}

/// A counts file gives the same table as the built-in counts, and `--out` writes it as CSV.
#[test]
fn a_counts_file_and_the_csv_output() {
    let t = tempfile::tempdir().unwrap();
    let counts = t.path().join("counts.csv");
    std::fs::write(&counts, format!("# TAP 2009, implied\n{}", rtbake::study::tap2009::implied_counts_csv())).unwrap();
    let out = t.path().join("table.csv");
    let o = rtbake(&["report", "chi2", "--counts", counts.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("TS - Zoom - 110°") && text.contains("22/32"), "{text}");
    let csv = std::fs::read_to_string(&out).unwrap();
    let line = csv.lines().find(|l| l.starts_with("TS - Zoom - 110°,TS vs SS Full,")).unwrap();
    assert!(line.starts_with("TS - Zoom - 110°,TS vs SS Full,22,32,4.5,0.0338"), "{line}");
    assert!(line.ends_with(",true"), "{line}");
}

#[test]
fn bad_counts_exit_2_naming_line_and_column_and_write_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("table.csv");
    let h = "configuration,comparison,chosen,total\n";
    for (body, needle) in [
        (format!("{h}a,b,-1,32\n"), "line 2 column chosen"),
        (format!("{h}a,b,3.5,32\n"), "line 2 column chosen"),
        (format!("{h}a,b,12,ten\n"), "line 2 column total"),
        (format!("{h}a,b,33,32\n"), "line 2 column chosen"),
        (format!("{h}a,b,0,0\n"), "line 2 column total"),
        ("chosen,total\n1,2\n".to_string(), "line 1"),
        (String::new(), "empty"),
    ] {
        let f = t.path().join("c.csv");
        std::fs::write(&f, &body).unwrap();
        let o = rtbake(&["report", "chi2", "--counts", f.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{body:?}: {err}");
        assert!(err.contains("--counts") && err.contains(needle), "{body:?}: {err}");
        assert!(!out.exists());
    }
    let o = rtbake(&["report", "chi2", "--counts", "tap2009", "--alpha", "1.5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--alpha"));
    let o = rtbake(&["report", "chi2", "--counts", t.path().join("missing.csv").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

/// The `--out` table read the way an analysis script reads it: Python's `csv` module (UTF-8, header row), every
/// number parsed with `float`, the booleans as `true`/`false`; TAP's Zoom 110° SS Full row is χ² 4.5, significant.
#[test]
fn the_csv_table_loads_in_python_csv() {
    if !crate::support::tool_available(
        "Python csv read of report chi2",
        "python3",
        &["--version"],
        "apt-get install python3",
    ) {
        return;
    }
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("table.csv");
    let o = rtbake(&["report", "chi2", "--counts", "tap2009", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let script = r#"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], encoding="utf-8", newline="")))
assert len(rows) == 36, len(rows)
for r in rows:
    float(r["chi2"]); float(r["p_value"]); int(r["chosen"]); int(r["total"])
    assert r["significant"] in ("true", "false"), r
z = [r for r in rows if r["configuration"] == "TS - Zoom - 110\u00b0" and r["comparison"] == "TS vs SS Full"]
assert len(z) == 1 and float(z[0]["chi2"]) == 4.5 and z[0]["significant"] == "true", z
print("ok")
"#;
    let py = std::process::Command::new("python3").args(["-c", script, out.to_str().unwrap()]).output().unwrap();
    assert!(py.status.success(), "{}", String::from_utf8_lossy(&py.stderr));
    assert_eq!(String::from_utf8_lossy(&py.stdout).trim(), "ok");
}

/// `--plot` draws TAP 2009 Fig. 8 as a PNG a person can read (two labelled panels) and the JSON carries the
/// proportions behind it; a counts file without distances or angles, or a plot with an unknown extension, exits 2
/// with nothing written.
#[test]
fn the_fig_8_proportions_and_their_plot() {
    let t = tempfile::tempdir().unwrap();
    let png = t.path().join("fig8.png");
    let o = rtbake(&["--json", "report", "chi2", "--counts", "tap2009", "--plot", png.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let by_angle = v["proportions"]["by_light_azimuth_deg"].as_array().unwrap();
    assert_eq!(by_angle.len(), 4);
    // 110°: SS Full chosen 17 + 19 + 22 = 58 of 96.
    let full_110 = by_angle[2][1].as_array().unwrap().iter().find(|p| p["comparison"] == "TS vs SS Full").unwrap();
    assert_eq!(
        (by_angle[2][0].as_f64(), full_110["chosen"].as_u64(), full_110["total"].as_u64()),
        (Some(110.0), Some(58), Some(96))
    );
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (760, 720));
    let svg = t.path().join("fig8.svg");
    let o = rtbake(&["report", "chi2", "--counts", "tap2009", "--plot", svg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("per camera distance") && text.contains("chance (0.5)"));
    assert!(String::from_utf8_lossy(&o.stdout).contains("TS vs SS Full 58/96"));

    let counts = t.path().join("c.csv");
    std::fs::write(&counts, "configuration,comparison,chosen,total\nsession 1,A vs B,10,20\n").unwrap();
    let none = t.path().join("none.png");
    let o = rtbake(&["report", "chi2", "--counts", counts.to_str().unwrap(), "--plot", none.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--plot"), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rtbake(&["report", "chi2", "--counts", "tap2009", "--plot", t.path().join("f.jpg").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("accepted .png, .svg"));
    assert!(!none.exists() && !t.path().join("f.jpg").exists());
}
