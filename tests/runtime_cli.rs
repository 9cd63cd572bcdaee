//! `rtbake run …`: end-to-end on files, and refusal of bad input (exit 2, nothing written).

mod runtime_support;

use rtbake::bake::{BakedFile, FileMeta};
use rtbake::image_buf::Image;
use rtbake::io::PixelFormat;
use rtbake::manifest::Manifest;
use rtbake::runtime::loader;
use runtime_support::*;
use std::path::Path;
use std::process::Command;

fn lut(path: &str, bytes: Vec<u8>, pf: PixelFormat, w: u32, h: u32, color_space: &str) -> BakedFile {
    BakedFile {
        path: path.into(),
        bytes,
        meta: FileMeta {
            kind: "lut".into(),
            format: "raw".into(),
            pixel_format: Some(pf),
            width: w,
            height: h,
            channels: pf.channels(),
            sample_type: "u8".into(),
            color_space: color_space.into(),
            convention: "test".into(),
            verify_tolerance: None,
        },
    }
}

/// A bake directory holding the golden SMAA textures and the N = 9 MLAA map, with a manifest.
fn golden_bake(dir: &Path, area_color_space: &str) {
    let s = golden_smaa();
    let files = vec![
        lut(loader::SMAA_AREA_PATH, s.area, PixelFormat::R8G8Unorm, 160, 560, area_color_space),
        lut(loader::SMAA_SEARCH_PATH, s.search, PixelFormat::R8Unorm, 64, 16, "linear"),
        lut(&loader::mlaa_area_path(9), golden_mlaa(9), PixelFormat::R8G8Unorm, 45, 45, "linear"),
    ];
    let mut m = Manifest::new("test".into());
    m.set_asset("aa", serde_json::json!({}), &files);
    for f in &files {
        let p = dir.join(&f.path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, &f.bytes).unwrap();
    }
    std::fs::write(dir.join("manifest.json"), m.to_text()).unwrap();
}

fn rtbake(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rtbake")).args(args).output().unwrap()
}

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
    golden_bake(t.path(), "linear");
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
            args.extend(["--baked", baked]);
            args.extend(&extra);
            if cpu {
                args.push("--cpu");
            }
            let o = rtbake(&args);
            assert!(o.status.success(), "{pass} cpu={cpu}: {}", String::from_utf8_lossy(&o.stderr));
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
    golden_bake(t.path(), "linear");
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
        "--baked",
        t.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(read_rgba(&out).len(), 320 * 180 * 4);
}

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let t = tempfile::tempdir().unwrap();
    golden_bake(t.path(), "linear");
    let baked = t.path().to_str().unwrap();
    let out = t.path().join("out.png");
    let outs = out.to_str().unwrap();
    // Missing input file.
    let o = rtbake(&["run", "smaa", "--input", "/nonexistent.png", "--output", outs, "--baked", baked]);
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
        "--baked",
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
        "--baked",
        baked,
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
}

#[test]
fn srgb_declared_lut_is_refused() {
    let t = tempfile::tempdir().unwrap();
    golden_bake(t.path(), "srgb");
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
    golden_bake(t.path(), "linear");
    let baked = t.path().to_str().unwrap();
    let (g, c) = (t.path().join("g.png"), t.path().join("c.png"));
    for (out, cpu) in [(&g, false), (&c, true)] {
        let mut args = vec!["run", "demo", "--output", out.to_str().unwrap(), "--width", "192", "--height", "108"];
        args.extend(["--baked", baked]);
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
