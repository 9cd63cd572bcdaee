//! `rtbake aa`: bad input exits 2 with a message naming the flag and writes nothing; good runs write the requested
//! files with the expected bytes.

use std::path::Path;

use crate::support::rtbake;

fn entries(dir: &Path) -> Vec<String> {
    match std::fs::read_dir(dir) {
        Ok(rd) => rd.flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect(),
        Err(_) => Vec::new(),
    }
}

/// Runs `rtbake aa ARGS --out <fresh dir>` and asserts exit 2, `flag` in stderr, nothing written.
fn refused(args: &[&str], flag: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let mut all = vec!["aa"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", out.to_str().unwrap()]);
    let o = rtbake(&all);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: expected exit 2, stderr: {err}");
    assert!(err.contains(flag), "{args:?}: stderr should name {flag}: {err}");
    assert!(entries(&out).is_empty() && entries(tmp.path()).is_empty(), "{args:?}: nothing may be written");
}

#[test]
fn bad_distances_are_refused() {
    refused(&["mlaa-v1.4", "--max-distance", "0"], "--max-distance");
    refused(&["mlaa-v1.4", "--max-distance", "16"], "odd");
    refused(&["mlaa-v1.3", "--max-distance", "1000000"], "--max-distance");
    refused(&["mlaa-v2", "--max-distance=-3"], "--max-distance");
    refused(&["mlaa-v1.4", "--max-distance", "abc"], "--max-distance");
    refused(&["smaa-area", "--ortho-max-distance", "0"], "--ortho-max-distance");
    refused(&["smaa-area", "--diag-max-distance", "1000000"], "--diag-max-distance");
}

#[test]
fn malformed_offsets_are_refused() {
    refused(&["smaa-area", "--ortho-offsets", "0.1,abc"], "--ortho-offsets");
    refused(&["smaa-area", "--ortho-offsets", "0.1,NaN"], "--ortho-offsets");
    refused(&["smaa-area", "--ortho-offsets", "0.1,0.75"], "--ortho-offsets");
    refused(&["smaa-area", "--ortho-offsets", ""], "--ortho-offsets");
    refused(&["smaa-area", "--diag-offsets", "0.1"], "--diag-offsets");
    refused(&["smaa-area", "--diag-offsets", "0.1:inf"], "--diag-offsets");
    refused(&["smaa-area", "--diag-offsets", "0:0,x:1"], "--diag-offsets");
}

#[test]
fn inapplicable_flags_are_refused() {
    refused(&["smaa-area", "--max-distance", "9"], "--max-distance");
    refused(&["mlaa-v1.4", "--ortho-offsets", "0"], "--ortho-offsets");
    refused(&["smaa-search", "--diag-max-distance", "20"], "--diag-max-distance");
    refused(&["smaa-area-v2.8", "--no-u-smoothing"], "--no-u-smoothing");
    refused(&["smaa-search", "--stem", "../x"], "--stem");
}

#[test]
fn unwritable_out_dir_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let out = file.join("sub");
    let o = rtbake(&["aa", "smaa-search", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--out"));
    assert_eq!(entries(tmp.path()), vec!["a-file".to_string()]);
}

#[test]
fn variant_run_writes_requested_formats_and_json() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("v");
    let o = rtbake(&[
        "--json",
        "aa",
        "smaa-area",
        "--ortho-max-distance",
        "4",
        "--diag-max-distance",
        "5",
        "--ortho-offsets=0,-0.3,0.3",
        "--diag-offsets=0:0,0.3:-0.3",
        "--format",
        "bin,png",
        "--stem",
        "Small",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names = entries(&out);
    names.sort();
    // The PNG holds linear data: Bevy's `.meta` (is_srgb: false) goes beside it, as `bake` writes it.
    assert_eq!(names, vec!["Small.bin", "Small.png", "Small.png.meta"]);
    let bin = std::fs::read(out.join("Small.bin")).unwrap();
    // (5·4 + 4·5) × max(5·4·3, 4·5·2) texels, two channels.
    assert_eq!(bin.len(), 40 * 60 * 2);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let files = json["files"].as_array().unwrap();
    assert_eq!(files.len(), 3);
    assert_eq!(files[0]["bytes"], bin.len());
    assert_eq!(files[2]["path"].as_str().map(|p| p.ends_with("Small.png.meta")), Some(true), "{}", files[2]);
    assert_eq!(files[0]["sha256"].as_str().unwrap().len(), 64);
}

#[test]
fn default_run_matches_the_library_and_writes_headers() {
    let tmp = tempfile::tempdir().unwrap();
    let o = rtbake(&["aa", "mlaa-v1.4", "--max-distance", "9", "--out", tmp.path().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let bin = std::fs::read(tmp.path().join("AreaMap9_v1.4.bin")).unwrap();
    let lib = rtbake::aa::mlaa_area::mlaa_area_map(rtbake::aa::mlaa_area::MlaaVersion::V1_4, 9).unwrap();
    assert_eq!(bin, lib.data);
    for ext in ["dds", "ktx2", "png", "h", "rs"] {
        assert!(tmp.path().join(format!("AreaMap9_v1.4.{ext}")).is_file(), "{ext}");
    }
    let o = rtbake(&["aa", "smaa-search", "--format", "h", "--out", tmp.path().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    let h = std::fs::read_to_string(tmp.path().join("SearchTex.h")).unwrap();
    assert!(h.contains("#define SEARCHTEX_WIDTH 64") && h.contains("searchTexBytes"));
    // Exactly the requested formats are written (and only they are encoded): --format bin,png → two files.
    let only = tmp.path().join("only");
    let o = rtbake(&["aa", "mlaa-v2", "--format", "bin,png", "--out", only.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<String> =
        std::fs::read_dir(&only).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, ["AreaTex_MLAAv2.bin", "AreaTex_MLAAv2.png", "AreaTex_MLAAv2.png.meta"]);
}

#[test]
fn no_u_smoothing_flag_gives_the_v2_8_texture() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    let o = rtbake(&["aa", "smaa-area", "--no-u-smoothing", "--format", "bin", "--out", a.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rtbake(&["aa", "smaa-area-v2.8", "--format", "bin", "--out", b.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let smoothed_off = std::fs::read(a.join("AreaTex.bin")).unwrap();
    assert_eq!(smoothed_off, std::fs::read(b.join("AreaTex_v2.8.bin")).unwrap());
    // And that is the published v2.8 payload when the reference folder is present.
    if let Some(reference) =
        crate::support::reference_file("smaa/AreaTex_v2.8_RG8_160x560.bin", "v2.8 area texture vs the published bytes")
    {
        assert!(smoothed_off == std::fs::read(&reference).unwrap(), "differs from {}", reference.display());
    }
}
