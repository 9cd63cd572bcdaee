//! Bad input met the way a user meets it: every consumer of a profile refuses the same garbage CSV with the flag and
//! the file named, spreadsheet CSVs keep all three channels, numbers out of range are reported with the flag and its
//! range (negative values included), and values that used to be accepted but wrong are refused. Each case: exit 2,
//! the message, nothing written.

use crate::support::{crate_dir, rtbake};
use std::path::Path;
use std::process::Output;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit 2 with every needle in the message, and nothing new in `dir`.
fn refused(args: &[&str], needles: &[&str], dir: &Path) {
    let before: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().map(|e| e.file_name()).collect();
    let o = rtbake(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: {n:?} not in {err}");
    }
    assert!(!err.contains("NaN"), "{args:?}: {err}");
    let after: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().map(|e| e.file_name()).collect();
    assert_eq!(before.len(), after.len(), "{args:?} wrote something: {after:?}");
}

const PROFILE_ROWS: &str = "0.05,3.1,1.9,0.8\n0.2,1.2,0.7,0.3\n0.8,0.2,0.1,0.03\n3,0.004,0.002,0.0005\n";

#[test]
fn every_consumer_refuses_a_garbage_profile_naming_the_flag_and_file() {
    let t = tempfile::tempdir().unwrap();
    let zero = t.path().join("zero.csv");
    std::fs::write(&zero, "r_mm,R_r,R_g,R_b\n0.1,0,0,0\n1,0,0,0\n").unwrap();
    let huge = t.path().join("huge.csv");
    std::fs::write(&huge, "r_mm,R_r,R_g,R_b\n0.1,1e308,1e308,1e308\n1,1e308,1e308,1e308\n").unwrap();
    let out = t.path().join("out");
    for (csv, what) in [(&zero, "0 at every radius"), (&huge, "overflows")] {
        let file = csv.file_name().unwrap().to_str().unwrap();
        let out = ["--out", s(&out)];
        for cmd in [
            &["fit", "gaussians", out[0], out[1]][..],
            &["fit", "burley"],
            &["fit", "separable", out[0], out[1]],
            &["kernel", out[0], out[1]],
            &["importance-kernel", "--samples", "16", out[0], out[1]],
            &["transmittance", "--s", "1", out[0], out[1]],
        ] {
            let args = [cmd, &["--profile-csv", s(csv)]].concat();
            refused(&args, &["--profile-csv", file, "channel R (red)", what], t.path());
        }
        let deon6 = crate_dir().join("baked/sss/gaussians/deon6.json");
        refused(&["evaluate", "--gaussians", s(&deon6), "--against", s(csv)], &["--against", file, what], t.path());
    }
}

#[test]
fn spreadsheet_csvs_keep_all_three_channels() {
    let t = tempfile::tempdir().unwrap();
    let deon6 = crate_dir().join("baked/sss/gaussians/deon6.json");
    let report = |header: &str, bom: bool| {
        let p = t.path().join("p.csv");
        let bom = if bom { "\u{feff}" } else { "" };
        std::fs::write(&p, format!("{bom}{header}\n{PROFILE_ROWS}")).unwrap();
        let o = rtbake(&["evaluate", "--gaussians", s(&deon6), "--against", s(&p), "--json"]);
        assert!(o.status.success(), "{header}: {}", stderr(&o));
        String::from_utf8(o.stdout).unwrap()
    };
    let canonical = report("r_mm,R_r,R_g,R_b", false);
    for (header, bom) in [("r_mm,R_r,R_g,R_b", true), ("r_mm,R,G,B", false), ("r_mm,red,green,blue", true)] {
        assert_eq!(report(header, bom), canonical, "{header} (BOM {bom}) is not read as the same three channels");
    }
    // A single R column followed by more columns would lose them: refused, naming the headers accepted.
    let p = t.path().join("q.csv");
    std::fs::write(&p, format!("r_mm,R,X,Y\n{PROFILE_ROWS}")).unwrap();
    refused(&["fit", "gaussians", "--profile-csv", s(&p)], &["q.csv", "header must be r_mm,R_r,R_g,R_b"], t.path());
}

#[test]
fn negative_and_huge_numbers_are_reported_with_the_flag_and_range() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    refused(&["transport", "--material", "skin1", "--photons", "-5"], &["--photons", "1..=1e10", "-5"], dir);
    refused(&["transport", "--material", "skin1", "--seed", "-1"], &["--seed", "0..=18446744073709551615"], dir);
    // A u32 flag: the range its help states, not the type's.
    refused(&["run", "demo", "--cpu", "--width", "-5", "--output", "x.png"], &["--width", "1..=16384", "-5"], dir);
    refused(
        &["evaluate", "--burley-albedo", "0.5,0.5,0.5", "--burley-d-mm", "-1,1,1", "--against", "skin1"],
        &["--burley-d-mm", "> 0", "-1"],
        dir,
    );
    for size in ["-1G", "99999999999999999999999G"] {
        refused(&["--max-memory", size, "assets"], &["--max-memory", "1..=1024T", size], dir);
    }
}

#[test]
fn accepted_but_wrong_inputs_are_refused() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    let baked = crate_dir().join("baked");
    // A pose whose weights overflow f32 (their sum is NaN) is not rendered.
    let pose = dir.join("pose.json");
    std::fs::write(&pose, r#"{"neutral": 1e308, "anger": -1e308}"#).unwrap();
    let png = dir.join("d.png");
    let demo = ["run", "demo", "--cpu", "--width", "64", "--height", "36", "--baked-dir", s(&baked)];
    refused(
        &[&demo[..], &["--rig-weights", s(&pose), "--output", s(&png)]].concat(),
        &["--rig-weights", "-1000..=1000", "1e308"],
        dir,
    );
    // PNG bytes under a JPEG name.
    refused(&[&demo[..], &["--output", s(&dir.join("s.jpg"))]].concat(), &["--output", "s.jpg", ".png"], dir);
    // A frame sequence with a gap: the missing frame is named, nothing is processed.
    let frames = dir.join("frames");
    std::fs::create_dir(&frames).unwrap();
    for n in ["0000", "0002", "0003"] {
        std::fs::write(frames.join(format!("frame_{n}.png")), b"x").unwrap();
    }
    refused(
        &["run", "smaa", "--cpu", "--mode", "t2x", "--input-dir", s(&frames), "--out", s(&dir.join("o"))],
        &["--input-dir", "frame_0001.png", "is missing", "frame_0003"],
        dir,
    );
    // Burley's R(r) diverges at r = 0: the radius is blamed, not the skin flags.
    refused(
        &["profile", "--burley-albedo", "0.5,0.5,0.5", "--burley-mfp-mm", "1,1,1", "--radii", "0,1"],
        &["--radii", "r = 0"],
        dir,
    );
}

#[test]
fn the_rig_reader_refuses_a_rig_without_the_neutral_map_first() {
    let t = tempfile::tempdir().unwrap();
    let fixture = |n: &str| crate_dir().join(format!("tests/fixtures/facial/hemoglobin_{n}.png"));
    let rig = t.path().join("rig");
    let anger = format!("anger={}", s(&fixture("anger")));
    let o = rtbake(&[
        "maps",
        "hemoglobin",
        "--neutral",
        s(&fixture("neutral")),
        "--target",
        &anger,
        "--radius",
        "4",
        "--rig-size",
        "16",
        "--out",
        s(&rig),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = rig.join("rig.json");
    let mut desc: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    desc["maps"].as_array_mut().unwrap().reverse();
    std::fs::write(&json, serde_json::to_string_pretty(&desc).unwrap()).unwrap();
    let out = t.path().join("h.exr");
    let o = rtbake(&["maps", "rig-eval", "--rig", s(&json), "--weights", "neutral=1", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--rig") && stderr(&o).contains("neutral map first"), "{}", stderr(&o));
    assert!(!out.exists());
}
