//! What a first use of the CLI meets: map channels, pure CSV on stdout, output folders and lists, how to bake a
//! missing table, binary formats for large tables, `--help` texts, a quiet GPU start — one contract per test.

use crate::support::{crate_dir, rtbake};
use rtbake::image_buf::Image;
use rtbake::io::exr::{encode, ExrPrecision};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Point 4: RGB(A) EXR hemoglobin maps are refused without `--channel` (exit 2, nothing written), read with it,
/// and the choice is recorded in rig.json.
#[test]
fn hemoglobin_rgb_exr_maps_need_and_accept_a_channel() {
    let t = tempfile::tempdir().unwrap();
    let (w, h) = (32u32, 32u32);
    let map = |k: f32, channels: u32| {
        let mut data = Vec::new();
        for i in 0..w * h {
            let v = 0.01 + 0.001 * ((i * 7 + k as u32) % 13) as f32 * k;
            data.extend_from_slice(&[9.0, v, 9.0, 1.0][..channels as usize]);
        }
        encode(&Image::from_vec(w, h, channels, data), ExrPrecision::F32).unwrap()
    };
    let (n, a) = (t.path().join("n.exr"), t.path().join("a.exr"));
    std::fs::write(&n, map(1.0, 3)).unwrap();
    std::fs::write(&a, map(2.0, 4)).unwrap();
    let out = t.path().join("rig");
    let base = ["maps", "hemoglobin", "--neutral", s(&n), "--target", &format!("anger={}", s(&a)), "--radius", "4"];
    let mut args: Vec<&str> = base.to_vec();
    args.extend(["--out", s(&out)]);
    let o = rtbake(&args);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("--neutral") && err.contains("3 channels") && err.contains("--channel R|G|B|A|Y|luminance"));
    assert!(!out.exists(), "a refused command wrote {}", out.display());
    let mut bad = args.clone();
    bad.extend(["--channel", "Q"]);
    let o = rtbake(&bad);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("--channel"), "{}", text(&o.stderr));
    let mut good = args.clone();
    good.extend(["--channel", "G"]);
    let o = rtbake(&good);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let rig = std::fs::read_to_string(out.join("rig.json")).unwrap();
    assert!(rig.contains("(channel G)"), "rig.json does not record the channel: {rig}");
}

/// Point 5: plain `profile` prints a CSV table (header first, totals on stderr); with `--csv FILE` stdout stays
/// empty.
#[test]
fn profile_stdout_is_pure_csv_and_empty_when_writing_a_file() {
    let o = rtbake(&["profile", "--profile-preset", "deon6", "--radii", "0.1,1,2"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 4, "{out}");
    assert!(lines[0].starts_with("r_mm"), "first stdout line is not the CSV header: {:?}", lines[0]);
    let cols = lines[0].split(',').count();
    assert!(lines.iter().all(|l| l.split(',').count() == cols), "{out}");
    assert!(text(&o.stderr).contains("total R"));
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("p.csv");
    let o = rtbake(&["profile", "--profile-preset", "deon6", "--radii", "0.1,1,2", "--csv", s(&csv)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(o.stdout.is_empty(), "profile --csv FILE also printed: {}", text(&o.stdout));
    assert!(std::fs::read_to_string(&csv).unwrap().contains("r_mm"));
}

/// Point 5: `skin-color --out DIR` writes into DIR like the other commands, and the sidecar names its siblings.
#[test]
fn skin_color_out_dir_receives_the_files() {
    let t = tempfile::tempdir().unwrap();
    let o = rtbake(&["skin-color", "--out", s(t.path()), "--resolution", "4", "--spectral-step-nm", "20"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(t.path().join("skin_color_lut.exr").is_file() && !t.path().join("skin").exists());
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(t.path().join("skin_color_lut.json")).unwrap()).unwrap();
    for (_, f) in side["files"].as_object().unwrap() {
        assert!(t.path().join(f.as_str().unwrap()).is_file(), "sidecar names {f}, which is not beside it");
    }
}

/// Point 5: `maps synthetic --json` reports what it wrote.
#[test]
fn maps_synthetic_json_lists_the_files() {
    let t = tempfile::tempdir().unwrap();
    let o = rtbake(&["maps", "synthetic", "--size", "16", "--targets", "joy", "--out", s(t.path()), "--json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON on stdout");
    assert_eq!(v["files"], serde_json::json!(["neutral.png", "joy.png"]));
    assert_eq!(v["width"], 16);
    assert!(t.path().join("joy.png").is_file());
}

/// Point 5: an MLAA size the bake does not hold gets a recipe that produces it, not "re-run rtbake bake".
#[test]
fn run_mlaa_with_an_unbaked_distance_says_how_to_bake_it() {
    let t = tempfile::tempdir().unwrap();
    let baked = crate_dir().join("baked");
    let (i, o) = (t.path().join("in.png"), t.path().join("out.png"));
    let r = rtbake(
        &["run", "mlaa", "--cpu", "--input", s(&i), "--output", s(&o), "--max-distance", "257"]
            .into_iter()
            .chain(["--baked-dir", s(&baked)])
            .collect::<Vec<_>>(),
    );
    assert_eq!(r.status.code(), Some(2));
    let err = text(&r.stderr);
    assert!(err.contains("--max-distance 257") && err.contains("rtbake bake mlaa-v1.4 --asset-params"), "{err}");
    assert!(err.contains("\"max_distances\": [257]") && !err.contains("re-run"), "{err}");
}

/// Point 6: large AA tables default to the binary formats; sources only when named.
#[test]
fn large_aa_tables_default_to_binary_formats() {
    let t = tempfile::tempdir().unwrap();
    let o = rtbake(&["aa", "mlaa-v1.4", "--max-distance", "257", "--out", s(t.path())]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mut names: Vec<String> =
        std::fs::read_dir(t.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    // `dds` is the DX10 file and its legacy-header copy; each texture has Bevy's `.meta` beside it.
    assert_eq!(
        names,
        [
            "AreaMap257_v1.4.bin",
            "AreaMap257_v1.4.dds",
            "AreaMap257_v1.4.dds.meta",
            "AreaMap257_v1.4.ktx2",
            "AreaMap257_v1.4.ktx2.meta",
            "AreaMap257_v1.4.png",
            "AreaMap257_v1.4.png.meta",
            "AreaMap257_v1.4_dx9.dds",
            "AreaMap257_v1.4_dx9.dds.meta"
        ]
    );
    assert!(text(&o.stderr).contains("--format h,rs"), "{}", text(&o.stderr));
    let o = rtbake(&["aa", "mlaa-v1.4", "--max-distance", "257", "--format", "h", "--out", s(t.path())]);
    assert!(o.status.success());
    assert!(t.path().join("AreaMap257_v1.4.h").is_file());
    // Small tables keep every format by default.
    let small = t.path().join("small");
    assert!(rtbake(&["aa", "smaa-search", "--out", s(&small)]).status.success());
    assert!(small.join("SearchTex.h").is_file() && small.join("SearchTex.rs").is_file());
}

/// Point 8: the flags the issue found undocumented have descriptions with units or ranges.
#[test]
fn help_describes_demo_size_and_stretch_parameters() {
    let demo = text(&rtbake(&["run", "demo", "--help"]).stdout);
    assert!(demo.contains("Frame width in pixels, 1..=16384") && demo.contains("Frame height in pixels"), "{demo}");
    assert!(demo.contains("--sss-inputs"));
    let fit = text(&rtbake(&["fit", "gaussians", "--help"]).stdout);
    for needle in ["thesis: 31.5", "thesis: 800", "thesis: 0.001"] {
        assert!(fit.contains(needle), "fit gaussians --help lacks {needle:?}");
    }
    let sss = text(&rtbake(&["run", "sss", "--help"]).stdout);
    assert!(sss.contains("view-space depth") && sss.contains("single-channel (Y) file, else R"), "{sss}");
}

/// Point 7: every command that opens an adapter (`run …`, `transport --gpu`) gives the drivers a private runtime
/// directory when the session has none or an invalid one, so their "XDG_RUNTIME_DIR is invalid" line never prints.
#[test]
fn gpu_commands_do_not_print_the_xdg_runtime_dir_warning() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("demo.png");
    let demo: Vec<std::ffi::OsString> =
        ["run", "demo", "--width", "32", "--height", "32", "--output", s(&out), "--baked-dir"]
            .iter()
            .map(Into::into)
            .chain([crate_dir().join("baked").into_os_string()])
            .collect();
    let transport: Vec<std::ffi::OsString> =
        ["transport", "--gpu", "--material", "skin1", "--photons", "2000", "--json"].iter().map(Into::into).collect();
    for args in [&demo, &transport] {
        for xdg in [None, Some("/nonexistent-runtime-dir")] {
            let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_rtbake"));
            c.args(args);
            match xdg {
                None => c.env_remove("XDG_RUNTIME_DIR"),
                Some(d) => c.env("XDG_RUNTIME_DIR", d),
            };
            let o = c.output().unwrap();
            assert!(o.status.success(), "{args:?} {xdg:?}: {}", text(&o.stderr));
            assert!(!text(&o.stderr).contains("XDG_RUNTIME_DIR"), "{args:?} {xdg:?}: {}", text(&o.stderr));
        }
    }
}
