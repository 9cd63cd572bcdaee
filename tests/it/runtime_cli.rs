//! `rtbake run …`: end-to-end on files, and refusal of bad input (exit 2, nothing written).

use crate::support::*;
use rtbake::bake::BakedFile;
use rtbake::baked_layout::path;
use rtbake::image_buf::Image;
use rtbake::manifest::{ColorSpace, Manifest};
use std::path::Path;
use std::process::Command;

/// Committed files of `baked/` with their committed manifest metadata.
fn committed(paths: &[&str]) -> Vec<BakedFile> {
    let m = Manifest::load(&baked_dir()).unwrap();
    paths
        .iter()
        .map(|p| BakedFile {
            path: p.to_string(),
            bytes: std::fs::read(baked_dir().join(p)).unwrap(),
            meta: m.entry(p).unwrap_or_else(|| panic!("{p} not in baked/manifest.json")).meta.clone(),
        })
        .collect()
}

fn write_bake(dir: &Path, files: &[BakedFile]) {
    let mut m = Manifest::new();
    m.set_asset("test", serde_json::json!({}), files);
    for f in files {
        let p = dir.join(&f.path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, &f.bytes).unwrap();
    }
    std::fs::write(dir.join("manifest.json"), m.to_text()).unwrap();
}

/// Every table the demo and the passes read, copied from the committed bake.
fn demo_tables() -> Vec<String> {
    vec![
        path::SMAA_AREA.into(),
        path::SMAA_SEARCH.into(),
        path::mlaa_area_v1_4(9),
        path::mlaa_area_v1_4(33),
        path::SEPARABLE_KERNEL_DEFAULT.into(),
        path::GAUSSIANS_DEFAULT.into(),
        path::TRANSMITTANCE_DEFAULT.into(),
        path::sidecar(path::TRANSMITTANCE_DEFAULT),
        path::SKIN_LUT.into(),
        path::sidecar(path::SKIN_LUT),
    ]
}

/// A bake directory holding copies of the committed tables, the SMAA area texture declared `area_color_space`.
fn copied_bake(dir: &Path, area_color_space: ColorSpace) {
    let paths = demo_tables();
    let mut files = committed(&paths.iter().map(String::as_str).collect::<Vec<_>>());
    files[0].meta.color_space = area_color_space;
    write_bake(dir, &files);
}

use crate::support::rtbake;

fn read_rgba(p: &Path) -> Vec<u8> {
    match rtbake::io::png::decode(&std::fs::read(p).unwrap(), "out").unwrap() {
        rtbake::io::png::DecodedPng::U8(img) => {
            assert_eq!(img.channels, 4);
            img.data
        }
        _ => panic!("8-bit expected"),
    }
}

#[test]
fn smaa_and_mlaa_on_a_png_gpu_and_cpu() {
    let t = tempfile::tempdir().unwrap();
    copied_bake(t.path(), ColorSpace::Linear);
    let (w, h) = (160, 120);
    let input = Image::from_vec(w, h, 4, rtbake::runtime::scene::render_shapes(w, h, 1));
    let inp = t.path().join("in.png");
    std::fs::write(&inp, rtbake::io::png::encode_u8(&input).unwrap()).unwrap();
    let baked = t.path().to_str().unwrap();
    for pass in ["smaa", "mlaa"] {
        let gpu_out = t.path().join(format!("{pass}-gpu.png"));
        let cpu_out = t.path().join(format!("{pass}-cpu.png"));
        let mut extra: Vec<&str> = vec![];
        if pass == "mlaa" {
            extra = vec!["--max-distance", "9"];
        }
        for (out, cpu) in [(&gpu_out, false), (&cpu_out, true)] {
            let mut args = vec!["run", pass, "--input", inp.to_str().unwrap(), "--output", out.to_str().unwrap()];
            args.extend(["--baked-dir", baked]);
            args.extend(&extra);
            if cpu {
                args.push("--cpu");
            }
            let o = rtbake(&args);
            assert!(o.status.success(), "{pass} cpu={cpu}: {}", String::from_utf8_lossy(&o.stderr));
        }
        for out in [&gpu_out, &cpu_out] {
            let chunks = rtbake::io::png::chunk_types(&std::fs::read(out).unwrap());
            assert!(chunks.contains(b"sRGB") && chunks.contains(b"cICP"), "{pass}: frame not tagged sRGB {chunks:?}");
        }
        let (g, c) = (read_rgba(&gpu_out), read_rgba(&cpu_out));
        assert_ne!(g, input.data, "{pass} changed nothing");
        let (frac, _) = within(&g, &c, 1);
        assert!(frac >= 0.999, "{pass}: GPU vs CPU {frac}");
    }
}

#[test]
fn demo_writes_a_png() {
    let t = tempfile::tempdir().unwrap();
    copied_bake(t.path(), ColorSpace::Linear);
    let out = t.path().join("demo.png");
    let o = rtbake(&[
        "run",
        "demo",
        "--output",
        out.to_str().unwrap(),
        "--width",
        "320",
        "--height",
        "180",
        "--baked-dir",
        t.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(read_rgba(&out).len(), 320 * 180 * 4);
    // The frame is sRGB-encoded and says so (a colour-managed viewer would otherwise decode it as linear).
    let chunks = rtbake::io::png::chunk_types(&std::fs::read(&out).unwrap());
    assert!(chunks.contains(b"sRGB") && chunks.contains(b"cICP"), "{chunks:?}");
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let t = tempfile::tempdir().unwrap();
    copied_bake(t.path(), ColorSpace::Linear);
    let baked = t.path().to_str().unwrap();
    let out = t.path().join("out.png");
    let outs = out.to_str().unwrap();
    // Missing input file.
    let o = rtbake(&["run", "smaa", "--input", "/nonexistent.png", "--output", outs, "--baked-dir", baked]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--input"));
    // Even max distance.
    let inp = t.path().join("in.png");
    std::fs::write(&inp, rtbake::io::png::encode_u8(&Image::from_vec(4, 4, 4, vec![9u8; 64])).unwrap()).unwrap();
    let o = rtbake(&[
        "run",
        "mlaa",
        "--input",
        inp.to_str().unwrap(),
        "--output",
        outs,
        "--baked-dir",
        baked,
        "--max-distance",
        "8",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--max-distance"));
    // Output directory missing.
    let o = rtbake(&[
        "run",
        "smaa",
        "--input",
        inp.to_str().unwrap(),
        "--output",
        "/nonexistent/dir/o.png",
        "--baked-dir",
        baked,
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
}

#[test]
fn srgb_declared_lut_is_refused() {
    let t = tempfile::tempdir().unwrap();
    copied_bake(t.path(), ColorSpace::Srgb);
    let inp = t.path().join("in.png");
    std::fs::write(&inp, rtbake::io::png::encode_u8(&Image::from_vec(4, 4, 4, vec![9u8; 64])).unwrap()).unwrap();
    let out = t.path().join("out.png");
    let o = rtbake(&[
        "run",
        "smaa",
        "--input",
        inp.to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--cpu",
        "--baked",
        t.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("colour space") && err.contains("AreaTex.bin"), "{err}");
    assert!(!out.exists());
}

#[test]
fn demo_gpu_and_cpu_agree_and_sss_runs_on_exr() {
    let t = tempfile::tempdir().unwrap();
    copied_bake(t.path(), ColorSpace::Linear);
    let baked = t.path().to_str().unwrap();
    let (g, c) = (t.path().join("g.png"), t.path().join("c.png"));
    for (out, cpu) in [(&g, false), (&c, true)] {
        let mut args = vec!["run", "demo", "--output", out.to_str().unwrap(), "--width", "192", "--height", "108"];
        args.extend(["--baked-dir", baked]);
        if cpu {
            args.push("--cpu");
        }
        let o = rtbake(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (fg, fc) = (read_rgba(&g), read_rgba(&c));
    // GPU chain vs CPU chain (f16 SSS differences propagate through sRGB encoding and SMAA): within 2/255 on
    // 99 % of the samples.
    let (frac, _) = within(&fg, &fc, 2);
    assert!(frac >= 0.99, "demo GPU vs CPU: {frac}");

    // run sss on EXR input.
    let (w, h) = (48u32, 32u32);
    let color: Vec<f32> =
        (0..w * h).flat_map(|i| [if (i % w) / 4 % 2 == 0 { 1.0 } else { 0.1 }, 0.5, 0.25, 1.0]).collect();
    let depth = vec![0.2f32; (w * h) as usize];
    let cp = t.path().join("c.exr");
    let dp = t.path().join("d.exr");
    let enc = |img: &Image<f32>| rtbake::io::exr::encode(img, rtbake::io::exr::ExrPrecision::F32).unwrap();
    std::fs::write(&cp, enc(&Image::from_vec(w, h, 4, color.clone()))).unwrap();
    std::fs::write(&dp, enc(&Image::from_vec(w, h, 1, depth))).unwrap();
    let op = t.path().join("o.exr");
    let o = rtbake(&[
        "run",
        "sss",
        "--color",
        cp.to_str().unwrap(),
        "--depth",
        dp.to_str().unwrap(),
        "--output",
        op.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (out, _) = rtbake::io::exr::decode(&std::fs::read(&op).unwrap(), "o").unwrap();
    assert_eq!((out.width, out.height, out.channels), (w, h, 4));
    // Stripes are blurred: red range shrinks.
    let reds: Vec<f32> = out.data.chunks(4).map(|p| p[0]).collect();
    let (mn, mx) = reds.iter().fold((f32::MAX, f32::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    assert!(mx - mn < 0.85, "SSS must blur the stripes: {mn}..{mx}");
    // Depth of another size is refused with exit 2.
    std::fs::write(&dp, enc(&Image::from_vec(4, 4, 1, vec![1.0; 16]))).unwrap();
    let o = rtbake(&[
        "run",
        "sss",
        "--color",
        cp.to_str().unwrap(),
        "--depth",
        dp.to_str().unwrap(),
        "--output",
        op.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--depth"));
}

/// From a clean checkout: `rtbake run demo --output demo.png` in the crate root reads the committed `baked/`.
#[test]
fn demo_runs_from_the_crate_root_with_the_committed_bake() {
    let t = tempfile::tempdir().unwrap();
    for (name, extra) in [
        ("sep.png", vec![]),
        ("gauss.png", vec!["--sss", "gaussians", "--aa", "mlaa"]),
        ("importance.png", vec!["--sss", "importance", "--cpu"]),
    ] {
        let out = t.path().join(name);
        let mut args = vec!["run", "demo", "--output", out.to_str().unwrap(), "--width", "256", "--height", "144"];
        args.extend(extra);
        let o = Command::new(env!("CARGO_BIN_EXE_rtbake"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(&args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        let img = read_rgba(&out);
        assert_eq!(img.len(), 256 * 144 * 4);
        // The centre of the head sphere is lit skin: red > green > blue, not the background.
        let c = &img[(72 * 256 + 128) * 4..][..3];
        assert!(c[0] > c[1] && c[1] > c[2] && c[0] > 120, "{name}: centre pixel {c:?}");
    }
}

/// `run demo --sss importance` with the committed bake's skin1 kernel: GPU and CPU chains agree as for the separable
/// pass (2/255 on 99 % of the samples), and a bake without the kernel is refused naming `--sss importance`.
#[test]
fn demo_importance_gpu_and_cpu_agree() {
    let t = tempfile::tempdir().unwrap();
    let (g, c) = (t.path().join("g.png"), t.path().join("c.png"));
    for (out, cpu) in [(&g, false), (&c, true)] {
        let mut args = vec!["run", "demo", "--sss", "importance", "--output", out.to_str().unwrap()];
        args.extend(["--width", "160", "--height", "96"]);
        if cpu {
            args.push("--cpu");
        }
        let o = Command::new(env!("CARGO_BIN_EXE_rtbake"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(&args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (frac, _) = within(&read_rgba(&g), &read_rgba(&c), 2);
    assert!(frac >= 0.99, "importance demo GPU vs CPU: {frac}");
    copied_bake(t.path(), ColorSpace::Linear);
    let out = t.path().join("x.png");
    let o = rtbake(&[
        "run",
        "demo",
        "--sss",
        "importance",
        "--cpu",
        "--baked-dir",
        t.path().to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--sss importance") && err.contains("skin1_dipole_n40"), "{err}");
    assert!(!out.exists());
}

#[test]
fn demo_refuses_a_bake_without_the_skin_lut() {
    let t = tempfile::tempdir().unwrap();
    let paths: Vec<String> = demo_tables().into_iter().filter(|p| !p.starts_with("skin/")).collect();
    write_bake(t.path(), &committed(&paths.iter().map(String::as_str).collect::<Vec<_>>()));
    let out = t.path().join("demo.png");
    let o = rtbake(&[
        "run",
        "demo",
        "--output",
        out.to_str().unwrap(),
        "--width",
        "64",
        "--height",
        "64",
        "--cpu",
        "--baked-dir",
        t.path().to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("skin/skin_color_lut.exr") && err.contains("not listed"), "{err}");
    assert!(!out.exists());
}

/// `run sss`: baked kernel by default, another kernel of the bake, a kernel file elsewhere, the Gaussian fit;
/// a kernel declared sRGB or a missing kernel is refused with exit 2.
#[test]
fn sss_reads_baked_kernels_and_gaussians() {
    let t = tempfile::tempdir().unwrap();
    let mut files =
        committed(&[path::SEPARABLE_KERNEL_DEFAULT, "sss/separable/published_n11.json", path::GAUSSIANS_DEFAULT]);
    let mut srgb = files[1].clone();
    srgb.path = "sss/separable/srgb.json".into();
    srgb.meta.color_space = ColorSpace::Srgb;
    files.push(srgb);
    let bake = t.path().join("bake");
    write_bake(&bake, &files);
    let (w, h) = (48u32, 32u32);
    let color: Vec<f32> =
        (0..w * h).flat_map(|i| [if (i % w) / 4 % 2 == 0 { 1.0 } else { 0.1 }, 0.5, 0.25, 1.0]).collect();
    let enc = |img: &Image<f32>| rtbake::io::exr::encode(img, rtbake::io::exr::ExrPrecision::F32).unwrap();
    let (cp, dp) = (t.path().join("c.exr"), t.path().join("d.exr"));
    std::fs::write(&cp, enc(&Image::from_vec(w, h, 4, color))).unwrap();
    std::fs::write(&dp, enc(&Image::from_vec(w, h, 1, vec![0.2f32; (w * h) as usize]))).unwrap();
    let outside = t.path().join("kernel.json");
    std::fs::copy(bake.join("sss/separable/published_n11.json"), &outside).unwrap();
    let op = t.path().join("o.exr");
    let run = |extra: &[&str]| {
        let _ = std::fs::remove_file(&op);
        let mut args = vec!["run", "sss", "--color", cp.to_str().unwrap(), "--depth", dp.to_str().unwrap()];
        args.extend(["--output", op.to_str().unwrap(), "--cpu", "--baked-dir", bake.to_str().unwrap()]);
        args.extend(extra);
        rtbake(&args)
    };
    let red_range = || {
        let (out, _) = rtbake::io::exr::decode(&std::fs::read(&op).unwrap(), "o").unwrap();
        let reds: Vec<f32> = out.data.chunks(4).map(|p| p[0]).collect();
        reds.iter().fold(f32::MIN, |a, v| a.max(*v)) - reds.iter().fold(f32::MAX, |a, v| a.min(*v))
    };
    let mut ranges = Vec::new();
    for extra in [
        vec![],
        vec!["--kernel", "sss/separable/published_n11.json"],
        vec!["--kernel", outside.to_str().unwrap()],
        vec!["--method", "gaussians"],
    ] {
        let o = run(&extra);
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        let r = red_range();
        assert!(r < 0.85, "{extra:?}: SSS must blur the stripes (red range {r})");
        ranges.push(r);
    }
    // The same kernel from the bake and from a file outside it gives the same image.
    assert_eq!(ranges[1], ranges[2]);
    for (extra, needle) in [
        (vec!["--kernel", "sss/separable/srgb.json"], "colour space"),
        (vec!["--kernel", "sss/separable/none.json"], "--kernel sss/separable/none.json"),
    ] {
        let o = run(&extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!op.exists());
    }
}

/// `--rig-weights` blends the baked rig's targets; unknown names or weights not summing to 1 exit 2.
#[test]
fn demo_rig_weights_from_json() {
    let t = tempfile::tempdir().unwrap();
    let weights = t.path().join("w.json");
    let demo = |out: &Path, w: Option<&str>| {
        let mut args = vec!["run", "demo", "--output", out.to_str().unwrap(), "--width", "128", "--height", "72"];
        args.push("--cpu");
        if let Some(w) = w {
            std::fs::write(&weights, w).unwrap();
            args.extend(["--rig-weights", weights.to_str().unwrap()]);
        }
        Command::new(env!("CARGO_BIN_EXE_rtbake")).current_dir(env!("CARGO_MANIFEST_DIR")).args(&args).output().unwrap()
    };
    let (a, b) = (t.path().join("neutral.png"), t.path().join("anger.png"));
    assert!(demo(&a, Some(r#"{"neutral": 1.0}"#)).status.success());
    assert!(demo(&b, Some(r#"{"neutral": 0.2, "anger": 0.8}"#)).status.success());
    assert_ne!(read_rgba(&a), read_rgba(&b), "the rig weights must change the skin colour");
    for (w, needle) in [(r#"{"smile": 1.0}"#, "unknown target"), (r#"{"neutral": 0.5}"#, "sum to 1")] {
        let out = t.path().join("bad.png");
        let o = demo(&out, Some(w));
        assert_eq!(o.status.code(), Some(2), "{w}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--rig-weights") && err.contains(needle), "{w}: {err}");
        assert!(!out.exists());
    }
}

/// `run demo` checks the whole frame against the adapter's limits before any work: a frame over them exits 2 at
/// once (no geometry, no pass run), naming `--width/--height`, the largest frame that fits and `--cpu`, and writes
/// nothing.
#[test]
fn demo_over_the_adapter_limits_is_refused_before_any_work() {
    let g = crate::support::gpu();
    let limits = g.device.limits();
    let side = limits.max_texture_dimension_2d.min(16384);
    let Err(expected) = rtbake::runtime::skin::demo::check_frame_fits(&limits, side, side) else {
        // A GPU whose buffers hold a 16-byte read-back of its largest texture has no over-limit frame in range.
        eprintln!("SKIPPED: {} holds a {side}² demo frame: no over-limit frame to refuse", g.adapter_info.name);
        assert!(!matches!(g.adapter_info.device_type, wgpu::DeviceType::Cpu), "lavapipe must refuse {side}²");
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("demo.png");
    let size = side.to_string();
    let started = std::time::Instant::now();
    let o = rtbake(&[
        "run",
        "demo",
        "--output",
        out.to_str().unwrap(),
        "--width",
        &size,
        "--height",
        &size,
        "--max-memory",
        "1024T",
        "--max-seconds",
        "1000000",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    // The library names fields (`width`, `cpu`); the CLI prints their flags.
    let cli_message =
        expected.message.replace("`width`", "--width").replace("`height`", "--height").replace("`cpu`", "--cpu");
    assert!(stderr.contains(&cli_message) && stderr.contains("--width/--height"), "{stderr}");
    assert!(stderr.contains("--cpu") && stderr.contains("largest frame"), "{stderr}");
    // Refused before the geometry of a {side}² frame is built (seconds of work at this size).
    assert!(started.elapsed().as_secs_f64() < 20.0, "took {:?}", started.elapsed());
    assert!(!out.exists(), "a refused frame wrote {}", out.display());
}
