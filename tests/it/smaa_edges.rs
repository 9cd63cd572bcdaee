//! SMAA's colour and depth edge detectors, predicated thresholding, MLAA's depth edges
//! (Listing 9.1) and matte/stencil masking — GPU vs CPU twin, the mask's pass-through, the CLI's flags and bad
//! input, and a quality check where luma cannot see the edges.

use crate::support::*;
use rtbake::runtime::cpu;
use rtbake::runtime::mlaa::{Mlaa, MlaaAreaMap, MlaaOptions};
use rtbake::runtime::scene::{render_shapes, render_shapes_depth, render_shapes_recoloured};
use rtbake::runtime::smaa::{Smaa, SmaaOptions};
use rtbake::runtime::smaa_edges::{AaInputs, EdgeDetector, EdgeSettings, Predication};
use std::path::Path;

fn settings(detector: EdgeDetector, predication: Option<Predication>) -> EdgeSettings {
    EdgeSettings { detector, predication, ..Default::default() }
}

fn edge_count(edges: &[u8]) -> usize {
    edges.chunks(2).filter(|e| e[0] > 0 || e[1] > 0).count()
}

/// A matte: the left 60 % of the frame and a disc on the right.
fn matte(w: u32, h: u32) -> Vec<u8> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let disc = (x - 0.8 * w as f32).powi(2) + (y - 0.5 * h as f32).powi(2) < (0.15 * h as f32).powi(2);
            if x < 0.6 * w as f32 || disc {
                255
            } else {
                0
            }
        })
        .collect()
}

/// SMAA with `options` on the GPU and the CPU twin: edges exact on ≥ 99.99 % of texels, output within 1/255 on
/// ≥ 99.9 % of channels; returns (CPU edges, GPU output, CPU output).
fn smaa_gpu_vs_cpu(
    (w, h): (u32, u32),
    img: &[u8],
    options: &SmaaOptions,
    inputs: &AaInputs,
) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let g = gpu();
    let luts = baked_smaa();
    let pass = Smaa::with_options(&g.device, &g.queue, w, h, &luts, options).unwrap();
    let out = pass.run_with(&g.device, &g.queue, img, inputs).unwrap();
    let edges = pass.read_edges(&g.device, &g.queue).unwrap();
    let c = cpu::smaa::smaa_with_options(img, (w, h), &luts, precision(&g), options, inputs).unwrap();
    let (fe, me) = within(&edges, &c.edges, 0);
    let (fo, mo) = within(&out, &c.output, 1);
    eprintln!(
        "SMAA {:?} {w}x{h}: {} edge pixels; edges exact {fe:.5} (max {me}); output ±1 {fo:.5} (max {mo})",
        options.edges,
        edge_count(&c.edges)
    );
    assert!(edge_count(&c.edges) > 0, "the test scene must have edges");
    let name = format!("smaa_edges_{w}x{h}");
    assert_gpu_matches_cpu(&name, fe >= 0.9999, &format!("edges exact {fe}"), (w, h, 2), &edges, &c.edges);
    assert_gpu_matches_cpu(&name, fo >= 0.999, &format!("output within 1/255 {fo}"), (w, h, 4), &out, &c.output);
    (c.edges, out, c.output)
}

fn mlaa_gpu_vs_cpu((w, h): (u32, u32), img: &[u8], options: &MlaaOptions, inputs: &AaInputs) -> (Vec<u8>, Vec<u8>) {
    let g = gpu();
    let map = MlaaAreaMap::new(33, baked_mlaa(33)).unwrap();
    let pass = Mlaa::with_options(&g.device, &g.queue, w, h, &map, options).unwrap();
    let out = pass.run_with(&g.device, &g.queue, img, inputs).unwrap();
    let edges = pass.read_edges(&g.device, &g.queue).unwrap();
    let c = cpu::mlaa::mlaa_with_options(img, (w, h), &map, precision(&g), options, inputs).unwrap();
    let (fe, _) = within(&edges, &c.edges, 0);
    let (fo, mo) = within(&out, &c.output, 1);
    eprintln!("MLAA {:?} {w}x{h}: edges exact {fe:.5}; output ±1 {fo:.5} (max {mo})", options.edges);
    assert!(edge_count(&c.edges) > 0);
    let name = format!("mlaa_edges_{w}x{h}");
    assert_gpu_matches_cpu(&name, fe >= 0.9999, &format!("edges exact {fe}"), (w, h, 2), &edges, &c.edges);
    assert_gpu_matches_cpu(&name, fo >= 0.999, &format!("output within 1/255 {fo}"), (w, h, 4), &out, &c.output);
    (out, c.output)
}

#[test]
fn smaa_color_edges_gpu_matches_cpu() {
    for (w, h) in [(256, 256), (301, 173)] {
        let img = render_shapes(w, h, 1);
        let o = SmaaOptions { edges: settings(EdgeDetector::Color, None), ..Default::default() };
        let (edges, out, _) = smaa_gpu_vs_cpu((w, h), &img, &o, &AaInputs::default());
        let luma = cpu::smaa::smaa(&img, w, h, &baked_smaa(), cpu::FilterPrecision::Exact).edges;
        assert!(edges != luma, "colour and luma edges of the shapes scene differ somewhere");
        assert!(out != img);
    }
}

#[test]
fn smaa_color_predicated_gpu_matches_cpu_1080p() {
    let (w, h) = (1920, 1080);
    let img = render_shapes(w, h, 1);
    let depth = render_shapes_depth(w, h);
    let o = SmaaOptions { edges: settings(EdgeDetector::Color, Some(Predication::SMAA)), ..Default::default() };
    smaa_gpu_vs_cpu((w, h), &img, &o, &AaInputs { depth: Some(&depth), mask: None });
}

/// Depth edges on the GPU and CPU; predicated luma on a scene of weak edges (luma contrast 0.149: above T = 0.1,
/// below scale·T = 0.2, above scale·T·(1 − strength) = 0.12): with the scene's depth every outline is a depth edge
/// and stays, with a flat depth the raised threshold drops them all.
#[test]
fn smaa_depth_and_predicated_luma_gpu_match_cpu() {
    let (w, h) = (320, 240);
    let grey = |v: f32| [cpu::srgb_to_linear(v) as f64; 3];
    let img = render_shapes_recoloured(w, h, 1, &[grey(166.0 / 255.0)], grey(128.0 / 255.0));
    let depth = render_shapes_depth(w, h);
    let flat = vec![1.0f32; (w * h) as usize];
    let inputs = AaInputs { depth: Some(&depth), mask: None };
    let o = SmaaOptions { edges: settings(EdgeDetector::Depth, None), ..Default::default() };
    let (depth_edges, _, _) = smaa_gpu_vs_cpu((w, h), &img, &o, &inputs);
    // Every outline is a depth edge; the 0.0004/px tilt is none.
    assert!(edge_count(&depth_edges) > 500, "{}", edge_count(&depth_edges));
    let o = SmaaOptions { edges: settings(EdgeDetector::Luma, Some(Predication::SMAA)), ..Default::default() };
    let (pred_edges, _, _) = smaa_gpu_vs_cpu((w, h), &img, &o, &inputs);
    let luma = cpu::smaa::smaa(&img, w, h, &baked_smaa(), cpu::FilterPrecision::Exact).edges;
    assert!(edge_count(&luma) > 500);
    assert!(pred_edges == luma, "on depth edges the predicated threshold 0.12 keeps every 0.149 edge");
    let flat_inputs = AaInputs { depth: Some(&flat), mask: None };
    let c = cpu::smaa::smaa_with_options(&img, (w, h), &baked_smaa(), cpu::FilterPrecision::Exact, &o, &flat_inputs);
    assert_eq!(edge_count(&c.unwrap().edges), 0, "off depth edges the threshold 0.2 drops the 0.149 edges");
}

#[test]
fn mlaa_depth_edges_gpu_match_cpu_and_listing_9_1() {
    let (w, h) = (256, 200);
    let img = render_shapes(w, h, 1);
    let depth = render_shapes_depth(w, h);
    let inputs = AaInputs { depth: Some(&depth), mask: None };
    let o = MlaaOptions { edges: settings(EdgeDetector::Depth, None), masked: false };
    mlaa_gpu_vs_cpu((w, h), &img, &o, &inputs);
    // Listing 9.1 by hand: an edge bit exactly where |D - D_left| (|D - D_top|) reaches the threshold.
    let map = MlaaAreaMap::new(33, baked_mlaa(33)).unwrap();
    let c = cpu::mlaa::mlaa_with_options(&img, (w, h), &map, cpu::FilterPrecision::Exact, &o, &inputs).unwrap();
    for y in 0..h as usize {
        for x in 0..w as usize {
            let d = depth[y * w as usize + x];
            let left = depth[y * w as usize + x.saturating_sub(1)];
            let top = depth[y.saturating_sub(1) * w as usize + x];
            let want = [(d - left).abs() >= 0.01, (d - top).abs() >= 0.01];
            let i = (y * w as usize + x) * 2;
            assert_eq!([c.edges[i] == 255, c.edges[i + 1] == 255], want, "({x}, {y})");
        }
    }
}

/// Pixels outside the matte leave SMAA and MLAA byte for byte; inside, the output is the unmasked pass's.
#[test]
fn mask_passes_outside_pixels_through_smaa_and_mlaa() {
    let (w, h) = (240, 180);
    let img = render_shapes(w, h, 1);
    let mask = matte(w, h);
    let inputs = AaInputs { depth: None, mask: Some(&mask) };
    let check = |out: &[u8], unmasked: &[u8], what: &str| {
        let mut changed_inside = 0;
        for (i, m) in mask.iter().enumerate() {
            let (o, a, u) = (&out[i * 4..i * 4 + 4], &img[i * 4..i * 4 + 4], &unmasked[i * 4..i * 4 + 4]);
            if *m < 128 {
                assert_eq!(o, a, "{what}: pixel {i} outside the mask changed");
            } else {
                assert_eq!(o, u, "{what}: pixel {i} inside the mask differs from the unmasked pass");
                changed_inside += usize::from(o != a);
            }
        }
        let changed_outside = mask
            .iter()
            .enumerate()
            .filter(|(i, m)| **m < 128 && unmasked[i * 4..i * 4 + 4] != img[i * 4..i * 4 + 4])
            .count();
        eprintln!("{what}: {changed_inside} pixels antialiased inside, {changed_outside} left as they were outside");
        assert!(changed_inside > 100 && changed_outside > 100, "{what}: the matte must split the edges");
    };
    let o = SmaaOptions { masked: true, ..Default::default() };
    let (_, gpu_out, cpu_out) = smaa_gpu_vs_cpu((w, h), &img, &o, &inputs);
    let unmasked = cpu::smaa::smaa(&img, w, h, &baked_smaa(), precision(&gpu())).output;
    check(&cpu_out, &unmasked, "SMAA CPU");
    check(
        &gpu_out,
        &{
            let g = gpu();
            Smaa::new(&g.device, &g.queue, w, h, &baked_smaa()).unwrap().run(&g.device, &g.queue, &img).unwrap()
        },
        "SMAA GPU",
    );
    let o = MlaaOptions { edges: EdgeSettings::default(), masked: true };
    let (gpu_out, cpu_out) = mlaa_gpu_vs_cpu((w, h), &img, &o, &inputs);
    let map = MlaaAreaMap::new(33, baked_mlaa(33)).unwrap();
    check(&cpu_out, &cpu::mlaa::mlaa(&img, w, h, &map, precision(&gpu())).output, "MLAA CPU");
    let g = gpu();
    let unmasked_gpu = Mlaa::new(&g.device, &g.queue, w, h, &map).unwrap().run(&g.device, &g.queue, &img).unwrap();
    check(&gpu_out, &unmasked_gpu, "MLAA GPU");
}

/// The passes refuse what they cannot use, naming the flag: depth missing, of another size, non-finite;
/// predication with depth edges; a mask of another size.
#[test]
fn passes_refuse_bad_depth_and_mask() {
    let (w, h) = (16, 8);
    let img = render_shapes(w, h, 1);
    let luts = baked_smaa();
    let depth_opts = SmaaOptions { edges: settings(EdgeDetector::Depth, None), ..Default::default() };
    let err = |o: &SmaaOptions, i: &AaInputs| {
        cpu::smaa::smaa_with_options(&img, (w, h), &luts, cpu::FilterPrecision::Exact, o, i).err().expect("refused")
    };
    assert_eq!(err(&depth_opts, &AaInputs::default()).param, "depth");
    assert_eq!(err(&depth_opts, &AaInputs { depth: Some(&[1.0; 7]), mask: None }).param, "depth");
    let mut nan = vec![1.0f32; (w * h) as usize];
    nan[17] = f32::NAN;
    let e = err(&depth_opts, &AaInputs { depth: Some(&nan), mask: None });
    assert!(e.param == "depth" && e.message.contains("(1, 1)"), "{e}");
    let both = SmaaOptions { edges: settings(EdgeDetector::Depth, Some(Predication::SMAA)), ..Default::default() };
    assert_eq!(err(&both, &AaInputs { depth: Some(&nan), mask: None }).param, "predication");
    let bad_scale = Predication { scale: 6.0, ..Predication::SMAA };
    let o = SmaaOptions { edges: settings(EdgeDetector::Luma, Some(bad_scale)), ..Default::default() };
    assert_eq!(err(&o, &AaInputs::default()).param, "predication_scale");
    let masked = SmaaOptions { masked: true, ..Default::default() };
    assert_eq!(err(&masked, &AaInputs { depth: None, mask: Some(&[255; 3]) }).param, "mask");
    // The GPU pass checks the same way before it draws.
    let g = gpu();
    let pass = Smaa::with_options(&g.device, &g.queue, w, h, &luts, &depth_opts).unwrap();
    let e = pass.run_with(&g.device, &g.queue, &img, &AaInputs { depth: Some(&nan), mask: None }).err().unwrap();
    assert!(e.to_string().contains("depth must be finite"), "{e}");
}

// ------------------------------------------------------------------------------------------------------------
// Quality where a threshold can fail: shapes whose colours all have the luma of the background.

/// sRGB-encoded colours with the luma (eq. 9.2 on encoded values) of grey 0.5, as linear RGB for the scene.
fn isoluminant_palette() -> (Vec<[f64; 3]>, [f64; 3]) {
    let lin = |c: [f64; 3]| c.map(|v| cpu::srgb_to_linear(v as f32) as f64);
    let g = |r: f64, b: f64| (0.5 - 0.2126 * r - 0.0722 * b) / 0.7152;
    let colours = [[0.9, g(0.9, 0.2), 0.2], [0.3, g(0.3, 0.95), 0.95], [0.75, g(0.75, 0.9), 0.9]];
    (colours.iter().map(|c| lin(*c)).collect(), lin([0.5, 0.5, 0.5]))
}

/// Mean absolute error (0..255, RGB) over `mask`.
fn edge_error(img: &[u8], truth: &[u8], mask: &[bool]) -> f64 {
    crate::support::edge_error_and_psnr(img, truth, mask).0
}

#[test]
fn color_and_depth_edges_find_what_luma_misses_and_lower_the_edge_error() {
    let (w, h) = (384, 384);
    let (palette, background) = isoluminant_palette();
    let aliased = render_shapes_recoloured(w, h, 1, &palette, background);
    let truth = render_shapes_recoloured(w, h, 4, &palette, background); // 16 samples per pixel
    let depth = render_shapes_depth(w, h);
    let inputs = AaInputs { depth: Some(&depth), mask: None };
    let mask: Vec<bool> =
        aliased.chunks(4).zip(truth.chunks(4)).map(|(a, t)| (0..3).any(|k| a[k].abs_diff(t[k]) > 8)).collect();
    let edge_px = mask.iter().filter(|m| **m).count();
    let luts = baked_smaa();
    let prec = cpu::FilterPrecision::Exact;
    let run = |d: EdgeDetector| {
        let o = SmaaOptions { edges: settings(d, None), ..Default::default() };
        cpu::smaa::smaa_with_options(&aliased, (w, h), &luts, prec, &o, &inputs).unwrap()
    };
    let (luma, colour, depth_run) = (run(EdgeDetector::Luma), run(EdgeDetector::Color), run(EdgeDetector::Depth));
    let map = MlaaAreaMap::new(33, baked_mlaa(33)).unwrap();
    let mlaa = |d: EdgeDetector| {
        let o = MlaaOptions { edges: settings(d, None), masked: false };
        cpu::mlaa::mlaa_with_options(&aliased, (w, h), &map, prec, &o, &inputs).unwrap()
    };
    let (mlaa_luma, mlaa_depth) = (mlaa(EdgeDetector::Luma), mlaa(EdgeDetector::Depth));
    let e_none = edge_error(&aliased, &truth, &mask);
    let rows = [
        ("SMAA luma", &luma.edges, &luma.output),
        ("SMAA colour", &colour.edges, &colour.output),
        ("SMAA depth", &depth_run.edges, &depth_run.output),
        ("MLAA luma", &mlaa_luma.edges, &mlaa_luma.output),
        ("MLAA depth", &mlaa_depth.edges, &mlaa_depth.output),
    ];
    eprintln!("{edge_px} edge pixels; no AA: mean abs edge error {e_none:.2}/255");
    for (name, edges, out) in rows {
        eprintln!("{name}: {} edge pixels, edge error {:.2}/255", edge_count(edges), edge_error(out, &truth, &mask));
    }
    assert!(edge_px > 1000);
    // Luma sees (almost) nothing: every colour has the background's luma up to 8-bit rounding.
    assert!(edge_count(&luma.edges) * 50 < edge_count(&colour.edges), "luma must miss the isoluminant edges");
    assert!(edge_count(&mlaa_luma.edges) * 50 < edge_count(&mlaa_depth.edges));
    assert!(edge_count(&depth_run.edges) > 1000);
    let e_luma = edge_error(&luma.output, &truth, &mask);
    for (name, out) in [("SMAA colour", &colour.output), ("SMAA depth", &depth_run.output)] {
        let e = edge_error(out, &truth, &mask);
        assert!(e < 0.75 * e_luma, "{name} must lower the edge error clearly: {e} vs luma {e_luma}");
    }
    let (e_ml, e_md) = (edge_error(&mlaa_luma.output, &truth, &mask), edge_error(&mlaa_depth.output, &truth, &mask));
    assert!(e_md < 0.75 * e_ml, "MLAA depth must lower the edge error clearly: {e_md} vs luma {e_ml}");
}

// ------------------------------------------------------------------------------------------------------------
// CLI

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn write_png(path: &Path, w: u32, h: u32, ch: u32, data: Vec<u8>) {
    let img = rtbake::image_buf::Image::from_vec(w, h, ch, data);
    std::fs::write(path, rtbake::io::png::encode_u8(&img).unwrap()).unwrap();
}

fn write_exr(path: &Path, w: u32, h: u32, ch: u32, data: Vec<f32>) {
    let img = rtbake::image_buf::Image::from_vec(w, h, ch, data);
    std::fs::write(path, rtbake::io::exr::encode(&img, rtbake::io::exr::ExrPrecision::F32).unwrap()).unwrap();
}

/// `run smaa --edges depth --depth D --mask M` on the CPU writes what the library computes; `run mlaa` likewise.
#[test]
fn cli_edges_depth_predication_and_mask_match_the_library() {
    let t = tempfile::tempdir().unwrap();
    let (w, h) = (96, 64);
    let img = render_shapes(w, h, 1);
    let depth = render_shapes_depth(w, h);
    let mask = matte(w, h);
    let (input, d, m) = (t.path().join("in.png"), t.path().join("depth.exr"), t.path().join("mask.png"));
    write_png(&input, w, h, 4, img.clone());
    write_exr(&d, w, h, 1, depth.clone());
    write_png(&m, w, h, 1, mask.clone());
    let baked = baked_dir();
    let inputs = AaInputs { depth: Some(&depth), mask: Some(&mask) };
    let read = |p: &Path| match rtbake::io::png::decode(&std::fs::read(p).unwrap(), "out").unwrap() {
        rtbake::io::png::DecodedPng::U8(i) => i.data,
        _ => panic!("8-bit output"),
    };
    let out = t.path().join("smaa.png");
    let r = rtbake(&[
        "run",
        "smaa",
        "--cpu",
        "--input",
        s(&input),
        "--output",
        s(&out),
        "--baked-dir",
        s(&baked),
        "--edges",
        "color",
        "--predication",
        "--depth",
        s(&d),
        "--mask",
        s(&m),
    ]);
    assert!(r.status.success(), "{}", text(&r.stderr));
    let o = SmaaOptions {
        edges: settings(EdgeDetector::Color, Some(Predication::SMAA)),
        masked: true,
        ..Default::default()
    };
    let want = cpu::smaa::smaa_with_options(&img, (w, h), &baked_smaa(), cpu::FilterPrecision::Exact, &o, &inputs);
    assert_eq!(read(&out), want.unwrap().output);
    let out = t.path().join("mlaa.png");
    let r = rtbake(&[
        "run",
        "mlaa",
        "--cpu",
        "--input",
        s(&input),
        "--output",
        s(&out),
        "--baked-dir",
        s(&baked),
        "--edges",
        "depth",
        "--depth",
        s(&d),
        "--depth-threshold",
        "0.5",
        "--mask",
        s(&m),
    ]);
    assert!(r.status.success(), "{}", text(&r.stderr));
    let edges = EdgeSettings { detector: EdgeDetector::Depth, depth_threshold: 0.5, predication: None };
    let map = MlaaAreaMap::new(33, baked_mlaa(33)).unwrap();
    let o = MlaaOptions { edges, masked: true };
    let want = cpu::mlaa::mlaa_with_options(&img, (w, h), &map, cpu::FilterPrecision::Exact, &o, &inputs).unwrap();
    assert_eq!(read(&out), want.output);
}

/// Bad depth or mask files: exit 2 naming the file (or the missing flag), nothing written.
#[test]
fn cli_refuses_bad_depth_and_mask_files() {
    let t = tempfile::tempdir().unwrap();
    let (w, h) = (32, 24);
    let input = t.path().join("in.png");
    write_png(&input, w, h, 4, render_shapes(w, h, 1));
    let p = |n: &str| t.path().join(n);
    write_exr(&p("small.exr"), w - 1, h, 1, vec![1.0; ((w - 1) * h) as usize]);
    write_exr(&p("rgb.exr"), w, h, 3, vec![1.0; (w * h * 3) as usize]);
    let mut nan = vec![1.0f32; (w * h) as usize];
    nan[5] = f32::INFINITY;
    write_exr(&p("inf.exr"), w, h, 1, nan);
    write_exr(&p("good.exr"), w, h, 1, vec![1.0; (w * h) as usize]);
    write_png(&p("small_mask.png"), w, h - 1, 1, vec![255; (w * (h - 1)) as usize]);
    write_png(&p("rgb_mask.png"), w, h, 3, vec![255; (w * h * 3) as usize]);
    let baked = baked_dir();
    let out = p("out.png");
    let f = |n: &str| p(n).to_str().unwrap().to_string();
    let (small, rgb, inf, good) = (f("small.exr"), f("rgb.exr"), f("inf.exr"), f("good.exr"));
    let (small_mask, rgb_mask, missing) = (f("small_mask.png"), f("rgb_mask.png"), f("missing.exr"));
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--edges", "depth", "--depth", &small], &small),
        (vec!["--edges", "depth", "--depth", &rgb], &rgb),
        (vec!["--predication", "--depth", &inf], &inf),
        (vec!["--mask", &small_mask], &small_mask),
        (vec!["--mask", &rgb_mask], &rgb_mask),
        (vec!["--edges", "depth"], "--depth"),
        (vec!["--edges", "depth", "--depth", &missing], &missing),
        (vec!["--edges", "color", "--depth", &good], "--depth"),
        (vec!["--predication", "--predication-strength", "1.5", "--depth", &good], "--predication-strength"),
        (vec!["--edges", "depth", "--depth-threshold", "nan", "--depth", &good], "--depth-threshold"),
    ];
    for pass in ["smaa", "mlaa"] {
        for (extra, named) in &cases {
            let mut args =
                vec!["run", pass, "--cpu", "--input", s(&input), "--output", s(&out), "--baked-dir", s(&baked)];
            args.extend(extra.iter().copied());
            let r = rtbake(&args);
            let err = text(&r.stderr);
            assert_eq!(r.status.code(), Some(2), "{pass} {extra:?}: {err}");
            assert!(err.contains(named), "{pass} {extra:?} must name {named}: {err}");
            assert!(!out.exists(), "{pass} {extra:?} wrote an output");
        }
    }
}
