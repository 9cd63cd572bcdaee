//! `--zstd LEVEL` on every command that writes KTX2: each KTX2 file becomes Zstandard-supercompressed
//! (scheme 2) and decodes, the way Bevy loads KTX2 (`ktx2` crate + zstd), to the level data of the uncompressed
//! file the same command writes without the flag; every other file is byte-identical. The bake records the level
//! as the `ktx2_zstd` asset parameter, so `verify` recomputes the compressed bytes and catches an edited level.

use crate::support::rtbake;
use std::path::{Path, PathBuf};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn run_ok(args: &[&str]) {
    let o = rtbake(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
}

fn files_below(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            let sub = p.strip_prefix(dir).unwrap().to_path_buf();
            out.extend(files_below(&p).into_iter().map(|f| sub.join(f)));
        } else {
            out.push(p.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    out.sort();
    out
}

/// Compares an output directory written with `--zstd` against the same command's output without it; returns the
/// number of KTX2 files checked.
fn compare(plain: &Path, zstd: &Path) -> usize {
    let names = files_below(plain);
    assert_eq!(names, files_below(zstd), "the same files with and without --zstd");
    let mut ktx2_files = 0;
    for name in names {
        let (a, b) = (std::fs::read(plain.join(&name)).unwrap(), std::fs::read(zstd.join(&name)).unwrap());
        if name.extension().and_then(|e| e.to_str()) != Some("ktx2") {
            if name.file_name().unwrap() != "manifest.json" {
                assert_eq!(a, b, "{}: non-KTX2 files are unchanged by --zstd", name.display());
            }
            continue;
        }
        let (ra, rb) = (ktx2::Reader::new(&a[..]).unwrap(), ktx2::Reader::new(&b[..]).unwrap());
        if ra.header().supercompression_scheme.is_some() {
            // Already supercompressed without the flag (the Bevy-named SMAA LUTs): left as they are.
            assert_eq!(a, b, "{}", name.display());
            continue;
        }
        ktx2_files += 1;
        assert_eq!(rb.header().supercompression_scheme, Some(ktx2::SupercompressionScheme::Zstandard), "{name:?}");
        assert_eq!(ra.header().format, rb.header().format, "{name:?}: format");
        let dims = |h: ktx2::Header| (h.type_size, h.pixel_width, h.pixel_height, h.level_count);
        assert_eq!(dims(ra.header()), dims(rb.header()), "{name:?}: dimensions");
        let (la, lb) = (ra.levels().next().unwrap(), rb.levels().next().unwrap());
        assert!(lb.data.len() < la.data.len(), "{name:?}: supercompressed level is smaller");
        let raw = zstd::bulk::decompress(lb.data, lb.uncompressed_byte_length as usize).unwrap();
        assert_eq!(raw, la.data, "{}: decoded level data", name.display());
    }
    ktx2_files
}

#[test]
fn bake_zstd_supercompresses_every_ktx2_and_verify_recomputes_it() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, z) = (dir.path().join("plain"), dir.path().join("z"));
    let assets = ["smaa-search", "transmittance", "wrinkle-maps-example"];
    let mut args = vec!["bake", "--quiet", "--out", s(&plain)];
    args.extend(assets);
    run_ok(&args);
    let mut args = vec!["bake", "--quiet", "--zstd", "15", "--out", s(&z)];
    args.extend(assets);
    run_ok(&args);
    assert!(compare(&plain, &z) >= 4);
    run_ok(&["verify", "--dir", s(&z)]);
    let manifest: serde_json::Value = serde_json::from_slice(&std::fs::read(z.join("manifest.json")).unwrap()).unwrap();
    for a in manifest["assets"].as_array().unwrap() {
        assert_eq!(a["params"][rtbake::bake::KTX2_ZSTD_PARAM], 15, "{}", a["name"]);
    }
    for f in manifest["files"].as_array().unwrap() {
        let is_ktx2 = f["path"].as_str().unwrap().ends_with(".ktx2");
        assert_eq!(f["supercompression"].as_str().is_some(), is_ktx2, "{}", f["path"]);
    }
    // An edited level is recomputed by verify, which then finds every KTX2 file of the asset different.
    let text = std::fs::read_to_string(z.join("manifest.json")).unwrap();
    let edited = text.replacen("\"ktx2_zstd\": 15", "\"ktx2_zstd\": 3", 1);
    assert_ne!(edited, text);
    std::fs::write(z.join("manifest.json"), edited).unwrap();
    let o = rtbake(&["verify", "--dir", s(&z)]);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stdout));
}

#[test]
fn zstd_levels_outside_1_to_22_are_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for level in ["0", "23", "-1"] {
        for cmd in [
            vec!["bake", "transmittance"],
            vec!["transmittance"],
            vec!["skin-color", "--resolution", "4"],
            vec!["aa", "smaa-search"],
        ] {
            let mut args = cmd.clone();
            args.extend(["--zstd", level, "--out", s(&out)]);
            let o = rtbake(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert!(err.contains("--zstd") && err.contains("1..=22"), "{args:?}: {err}");
            assert!(!out.exists(), "{args:?} wrote {}", out.display());
        }
    }
    let params = dir.path().join("p.json");
    std::fs::write(&params, r#"{"transmittance": {"ktx2_zstd": "high"}}"#).unwrap();
    let o = rtbake(&["bake", "transmittance", "--asset-params", s(&params), "--out", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("transmittance parameter ktx2_zstd") && err.contains("1..=22"), "{err}");
    assert!(!out.exists());
}

#[test]
fn table_and_map_commands_take_zstd() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n);
    let mut checked = 0;
    for (name, cmd) in [
        ("transmittance", vec!["transmittance", "--samples", "32"]),
        ("skin-color", vec!["skin-color", "--resolution", "8"]),
    ] {
        let (plain, z) = (d(&format!("{name}_plain")), d(&format!("{name}_z")));
        let mut args = cmd.clone();
        args.extend(["--out", s(&plain)]);
        run_ok(&args);
        let mut args = cmd.clone();
        args.extend(["--zstd", "9", "--out", s(&z)]);
        run_ok(&args);
        checked += compare(&plain, &z);
    }
    let fx = d("fixtures");
    run_ok(&["maps", "synthetic", "--size", "32", "--targets", "anger", "--out", s(&fx)]);
    let neutral = fx.join("neutral.png");
    let anger = format!("anger={}", s(&fx.join("anger.png")));
    let normal = d("n.png");
    let px: Vec<u8> = (0..16 * 16).flat_map(|i| [128 + (i % 7) as u8, 120, 250]).collect();
    std::fs::write(&normal, rtbake::io::png::encode_u8(&rtbake::Image::from_vec(16, 16, 3, px)).unwrap()).unwrap();
    let zone = d("zone.png");
    let mask: Vec<u8> = (0..16 * 16).map(|i| (i % 255) as u8).collect();
    std::fs::write(&zone, rtbake::io::png::encode_u8(&rtbake::Image::from_vec(16, 16, 1, mask)).unwrap()).unwrap();
    let zone_arg = format!("red={}", s(&zone));
    for (name, cmd) in [
        (
            "rig",
            vec![
                "maps",
                "hemoglobin",
                "--neutral",
                s(&neutral),
                "--target",
                &anger,
                "--radius",
                "3",
                "--rig-size",
                "8",
            ],
        ),
        ("wrinkles", vec!["maps", "wrinkles", "--normal", s(&normal), "--size", "8"]),
        ("masks", vec!["maps", "wrinkle-masks", "--zone", &zone_arg, "--size", "8"]),
    ] {
        let (plain, z) = (d(&format!("{name}_plain")), d(&format!("{name}_z")));
        let mut args = cmd.clone();
        args.extend(["--out", s(&plain)]);
        run_ok(&args);
        let mut args = cmd.clone();
        args.extend(["--zstd", "19", "--out", s(&z)]);
        run_ok(&args);
        checked += compare(&plain, &z);
    }
    assert!(checked >= 7, "{checked} KTX2 files checked");
}
