//! TAP 2009's stimuli as commands: the single light of `run skin --light-azimuth/--light-elevation` (direction,
//! mirror symmetry, default unchanged, bad input) and `run tap-grid` (the folder's files, RMSE recomputed from the
//! frames, the Fig. 4 sweep, bad input with nothing written).

use crate::support::{baked_dir, rtbake};
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::skin::lighting::SceneLights;
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, StretchPreset};

fn settings() -> SkinRenderSettings {
    SkinRenderSettings {
        shader: SkinShader::Separable,
        heads: 1,
        distance_m: 0.6,
        width: 160,
        height: 120,
        melanin: 0.02,
        stretch: StretchPreset::Thesis,
    }
}

/// Summed RGB of the head's pixels (not the background) left and right of the frame's centre.
fn halves(img: &[u8], w: usize) -> (u64, u64) {
    let (mut l, mut r) = (0u64, 0u64);
    for (i, p) in img.chunks(4).enumerate() {
        if p[..3] == [46, 48, 52] {
            continue;
        }
        let v = p[..3].iter().map(|&c| c as u64).sum::<u64>();
        if i % w < w / 2 {
            l += v
        } else {
            r += v
        }
    }
    (l, r)
}

#[test]
fn the_single_light_points_where_tap_puts_it_and_mirrors_with_the_azimuth() {
    let s = settings();
    let cam = s.camera();
    // ϕ = 0, θ = 45°: in front of the face, above: (0, sin 45°, cos 45°) in view space for a camera on +z.
    let l = SceneLights::single(0.0, 45.0, &cam).unwrap();
    let h = 0.5f32.sqrt();
    assert!((l.key_view[0]).abs() < 1e-6 && (l.key_view[1] - h).abs() < 1e-6 && (l.key_view[2] - h).abs() < 1e-6);
    assert_eq!(l.key_view, l.back_view, "one light for both");
    for (az, el, field) in [(180.5, 45.0, "light_azimuth_deg"), (0.0, -90.5, "light_elevation_deg")] {
        assert_eq!(SceneLights::single(az, el, &cam).unwrap_err().param, field);
    }
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let frame = |lights: SceneLights| {
        let mut a = assets.clone();
        a.lights = lights;
        render_with(None, &head, &s, &SkinPasses::none(), &a).unwrap().data
    };
    // The default lights are the frame without the flags.
    assert!(frame(SceneLights::default()) == render_with(None, &head, &s, &SkinPasses::none(), &assets).unwrap().data);
    // A light at +60° lights the head's +x side (the frame's right), at −60° its left, by the same margin.
    let (l60, r60) = halves(&frame(SceneLights::single(60.0, 45.0, &cam).unwrap()), 160);
    let (lm60, rm60) = halves(&frame(SceneLights::single(-60.0, 45.0, &cam).unwrap()), 160);
    assert!(r60 as f64 > 1.2 * l60 as f64, "{l60} {r60}");
    assert!(lm60 as f64 > 1.2 * rm60 as f64, "{lm60} {rm60}");
    let ratio = (r60 as f64 / l60 as f64) / (lm60 as f64 / rm60 as f64);
    assert!((ratio - 1.0).abs() < 0.1, "mirror: {ratio}");
    // From almost behind (150°) the face is darker than from the front.
    let front = halves(&frame(SceneLights::single(0.0, 45.0, &cam).unwrap()), 160);
    let back = halves(&frame(SceneLights::single(150.0, 45.0, &cam).unwrap()), 160);
    assert!(back.0 + back.1 < (front.0 + front.1) * 3 / 4, "{front:?} {back:?}");
}

#[test]
fn light_angles_out_of_range_exit_2_and_write_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("x.png");
    let o_s = out.to_str().unwrap();
    for (flag, v, range) in [
        ("--light-azimuth", "200", "-180..=180"),
        ("--light-elevation", "-95", "-90..=90"),
        ("--light-azimuth", "nan", ""),
    ] {
        let o = rtbake(&["run", "skin", "--cpu", "--width", "32", "--height", "24", "--output", o_s, flag, v]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {v}: {err}");
        assert!(err.contains(flag) && err.contains(range), "{flag} {v}: {err}");
        assert!(!out.exists());
    }
}

fn read_rgba(p: &std::path::Path) -> image::RgbaImage {
    image::open(p).unwrap().to_rgba8()
}

fn rmse(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let mut s = 0.0f64;
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            s += ((p.0[c] as f64 - q.0[c] as f64) / 255.0).powi(2);
        }
    }
    (s / (3.0 * (a.width() * a.height()) as f64)).sqrt()
}

#[test]
fn tap_grid_writes_frames_differences_rmse_and_sheets_for_the_procedural_head() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("grid");
    let o = rtbake(&[
        "--json",
        "run",
        "tap-grid",
        "--cpu",
        "--width",
        "128",
        "--height",
        "72",
        "--ts-map-size",
        "128",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let count = |d: &str| std::fs::read_dir(out.join(d)).unwrap().count();
    assert_eq!((count("frames"), count("differences"), count("fig4")), (48, 36, 6));
    for f in ["rmse.csv", "rmse.json", "contact_sheet.png", "fig4_sweep.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(out.join("rmse.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], "shader,distance,azimuth_deg,elevation_deg,rmse_vs_ts");
    assert_eq!(rows.len(), 1 + 36 + 6);
    // Every grid row's RMSE is the one recomputed from the frames it names.
    for row in &rows[1..37] {
        let f: Vec<&str> = row.split(',').collect();
        let stem = |sh: &str| format!("{sh}_{}_az{:03}.png", f[1], f[2].parse::<i32>().unwrap());
        let a = read_rgba(&out.join("frames").join(stem(f[0])));
        let b = read_rgba(&out.join("frames").join(stem("ts")));
        let want = rmse(&a, &b);
        let got: f64 = f[4].parse().unwrap();
        assert!((got - want).abs() < 1e-6, "{row}: recomputed {want}");
        assert_eq!(f[3], "45");
    }
    // No SSS differs from TS under every condition; the camera distances keep TAP's 28 : 50 : 132.
    let no_sss: Vec<f64> = rows[1..37]
        .iter()
        .filter(|r| r.starts_with("no-sss"))
        .map(|r| r.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(no_sss.len(), 12);
    assert!(no_sss.iter().all(|&r| r > 0.0), "{no_sss:?}");
    let d = &v["distances_m"];
    let (zoom, near, far) = (d["zoom"].as_f64().unwrap(), d["near"].as_f64().unwrap(), d["far"].as_f64().unwrap());
    assert!((near / zoom - 50.0 / 28.0).abs() < 1e-4 && (far / zoom - 132.0 / 28.0).abs() < 1e-4, "{d}");
    for sh in ["ss-full", "ss-jittered", "no-sss"] {
        assert!(v["mean_rmse"][sh].as_f64().unwrap() > 0.0, "{v}");
    }
    // Fig. 4: α = 0 is the unblurred frame, so its RMSE is No SSS's at near, 0°.
    let sweep = &v["fig4_sweep"];
    assert_eq!(sweep.as_array().unwrap().len(), 6);
    let near0 = rows.iter().find(|r| r.starts_with("no-sss,near,0,")).unwrap();
    let near0: f64 = near0.rsplit(',').next().unwrap().parse().unwrap();
    assert!((sweep[0]["rmse"].as_f64().unwrap() - near0).abs() < 1e-6, "{sweep} vs {near0}");
    assert_eq!((sweep[0]["alpha"].as_f64(), sweep[3]["beta"].as_f64()), (Some(0.0), Some(0.0)));
    // The contact sheet holds 7 rows × 12 columns of 128×72 cells with labels.
    let sheet = read_rgba(&out.join("contact_sheet.png"));
    assert!(sheet.width() > 12 * 128 && sheet.height() > 7 * 72, "{}x{}", sheet.width(), sheet.height());
    // The difference images are |Δ|×8 on the ramp: where a frame equals TS the difference is black.
    let diff = read_rgba(&out.join("differences/no-sss_far_az150.png"));
    let (a, b) = (read_rgba(&out.join("frames/no-sss_far_az150.png")), read_rgba(&out.join("frames/ts_far_az150.png")));
    let same = (0..72 * 128 - 128 * 14).filter(|&i| a.as_raw()[4 * i..4 * i + 3] == b.as_raw()[4 * i..4 * i + 3]);
    for i in same {
        assert_eq!(diff.as_raw()[4 * i..4 * i + 3], [0, 0, 0], "pixel {i}");
    }
}

/// `--separable` adds the fifth shader of `run skin` under every condition: its frames, its differences against
/// TS and its rows of the RMSE table (recomputed from the frames); it blurs, so it is nearer TS than No SSS on average
/// and differs from both.
#[test]
fn tap_grid_with_separable_adds_a_fifth_row_recomputable_from_its_frames() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("grid5");
    let o = rtbake(&[
        "--json",
        "run",
        "tap-grid",
        "--cpu",
        "--separable",
        "--width",
        "96",
        "--height",
        "54",
        "--ts-map-size",
        "64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let count = |d: &str| std::fs::read_dir(out.join(d)).unwrap().count();
    assert_eq!((count("frames"), count("differences"), count("fig4")), (60, 48, 6));
    let csv = std::fs::read_to_string(out.join("rmse.csv")).unwrap();
    let sep: Vec<&str> = csv.lines().filter(|r| r.starts_with("separable,")).collect();
    assert_eq!(sep.len(), 12, "{csv}");
    for row in &sep {
        let f: Vec<&str> = row.split(',').collect();
        let stem = |sh: &str| format!("{sh}_{}_az{:03}.png", f[1], f[2].parse::<i32>().unwrap());
        let a = read_rgba(&out.join("frames").join(stem("separable")));
        let ts = read_rgba(&out.join("frames").join(stem("ts")));
        let none = read_rgba(&out.join("frames").join(stem("no-sss")));
        let got: f64 = f[4].parse().unwrap();
        assert!((got - rmse(&a, &ts)).abs() < 1e-6, "{row}");
        assert!(rmse(&a, &none) > 0.0, "{row}: separable equals No SSS");
    }
    let mean = |sh: &str| v["mean_rmse"][sh].as_f64().unwrap();
    assert!(mean("separable") > 0.0 && mean("separable") < mean("no-sss"), "{}", v["mean_rmse"]);
    let sheet = read_rgba(&out.join("contact_sheet.png"));
    assert!(sheet.height() > 9 * 54, "5 frame rows + 4 difference rows: {}", sheet.height());
}

#[test]
fn tap_grid_bad_input_exits_2_and_writes_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("grid");
    let o_s = out.to_str().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["--width", "0"], "--width"),
        (&["--ts-map-size", "16"], "--ts-map-size"),
        (&["--albedo", "/nonexistent.png"], "--albedo"),
        (&["--mesh-units", "furlong"], "--mesh-units"),
    ];
    for (extra, flag) in cases {
        let mut a = vec!["run", "tap-grid", "--cpu", "--width", "64", "--height", "36", "--out", o_s];
        a.extend_from_slice(extra);
        let o = rtbake(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(flag), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} created the folder");
    }
    // The 54 frames' estimated time is checked against the budget before any work.
    let o =
        rtbake(&["--max-seconds", "1", "run", "tap-grid", "--cpu", "--width", "1280", "--height", "720", "--out", o_s]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("54 frames") && err.contains("--max-seconds"), "{err}");
    assert!(!out.exists());
}

/// SS Full's default stretch is TAP's (α = 11, β = 800, no clamp, stated for a 20° camera at 720 px), and `--json`
/// prints what was used: α at 720 px and at the viewport, β, γ, the field of view and the viewport.
#[test]
fn ss_full_defaults_to_taps_stretch_and_json_states_the_camera() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("f.png");
    let o = rtbake(&[
        "--json",
        "run",
        "skin",
        "--cpu",
        "--shader",
        "ss-full",
        "--width",
        "64",
        "--height",
        "36",
        "--output",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let st = &v["ss_full_stretch"];
    assert_eq!(st["preset"], "tap2009", "{v}");
    assert_eq!((st["beta"].as_f64(), st["gamma"].is_null()), (Some(800.0), true), "{st}");
    assert_eq!(st["alpha_stated_for"]["fov_y_deg"], 20.0);
    let fov = v["camera"]["fov_y_deg"].as_f64().unwrap();
    assert_eq!(fov, 30.0);
    let want = 11.0 * (10f64.to_radians().tan() / (fov / 2.0).to_radians().tan());
    let a720 = st["alpha_at_720px"].as_f64().unwrap();
    assert!((a720 - want).abs() < 1e-4, "{a720} vs {want}");
    assert!((st["alpha_at_viewport"].as_f64().unwrap() - a720 * 36.0 / 720.0).abs() < 1e-4, "{st}");
    assert_eq!(v["camera"]["viewport"], serde_json::json!([64, 36]));
}
