//! Separable SSS: GPU vs CPU reference, the matte (non-skin pixels pass through), energy conservation.

use crate::support::*;
use rtbake::runtime::cpu::separable_sss::separable_sss;
use rtbake::runtime::separable_sss::{SeparableSss, SssKernel, SssParams};
use rtbake::runtime::sss::separable_tiled::SeparableSssTiled;

/// The fragment pass or the compute pass over workgroup tiles (same arithmetic, same CPU twin).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Variant {
    Fragment,
    Tiled,
}

fn run_variant(
    v: Variant,
    g: &rtbake::runtime::device::Gpu,
    (w, h): (u32, u32),
    k: &SssKernel,
    p: &SssParams,
    color: &[f32],
    depth: &[f32],
) -> Vec<f32> {
    match v {
        Variant::Fragment => SeparableSss::new(&g.device, w, h, k, p).unwrap().run(&g.device, &g.queue, color, depth),
        Variant::Tiled => SeparableSssTiled::new(&g.device, w, h, k, p).unwrap().run(&g.device, &g.queue, color, depth),
    }
    .unwrap()
}

/// A 17-tap kernel: per-channel Gaussians (sigma 1.0, 0.5, 0.3 kernel units) over offsets in [-3, 3],
/// normalised per channel, centre first.
fn kernel() -> SssKernel {
    let n = 17;
    let offsets: Vec<f32> = (0..n).map(|i| -3.0 + 6.0 * i as f32 / (n - 1) as f32).collect();
    let sig = [1.0f32, 0.5, 0.3];
    let mut taps: Vec<[f32; 4]> = offsets
        .iter()
        .map(|&o| {
            let mut t = [0.0f32, 0.0, 0.0, o];
            for c in 0..3 {
                t[c] = (-o * o / (2.0 * sig[c] * sig[c])).exp();
            }
            t
        })
        .collect();
    for c in 0..3 {
        let s: f32 = taps.iter().map(|t| t[c]).sum();
        taps.iter_mut().for_each(|t| t[c] /= s);
    }
    let centre = taps.remove(n / 2);
    taps.insert(0, centre);
    SssKernel::new(taps).unwrap()
}

/// A lit sphere (skin, alpha 1) with stripes of light, on a far background (alpha 0).
fn scene(w: u32, h: u32) -> (Vec<f32>, Vec<f32>) {
    let (mut color, mut depth) = (vec![0.0f32; (w * h * 4) as usize], vec![10.0f32; (w * h) as usize]);
    let r = 0.4 * w.min(h) as f32;
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = (x as f32 + 0.5 - w as f32 / 2.0, y as f32 + 0.5 - h as f32 / 2.0);
            let i = (y * w + x) as usize;
            let d2 = dx * dx + dy * dy;
            if d2 < r * r {
                let z = (r * r - d2).sqrt() / r;
                let stripe = if ((x / 6) + (y / 9)) % 2 == 0 { 1.0 } else { 0.15 };
                let lit = (0.3 + 0.7 * z) * stripe;
                color[4 * i..4 * i + 4].copy_from_slice(&[0.9 * lit, 0.6 * lit, 0.5 * lit, 1.0]);
                depth[i] = 2.0 - 0.3 * z;
            } else {
                color[4 * i..4 * i + 4].copy_from_slice(&[0.2, 0.3, 0.4, 0.0]);
            }
        }
    }
    (color, depth)
}

/// The published 17-tap kernel from the committed bake, through the manifest-checked loader.
fn baked_kernel() -> SssKernel {
    let dir = baked_dir();
    rtbake::runtime::loader::load_separable_kernel(&dir, rtbake::baked_layout::path::SEPARABLE_KERNEL_DEFAULT)
        .unwrap_or_else(|e| panic!("{e}"))
        .kernel
}

#[test]
fn sss_gpu_matches_cpu() {
    gpu_matches_cpu(&kernel(), Variant::Fragment, 1.0);
}

#[test]
fn sss_gpu_matches_cpu_with_the_baked_kernel() {
    gpu_matches_cpu(&baked_kernel(), Variant::Fragment, 1.0);
}

#[test]
fn tiled_sss_gpu_matches_cpu() {
    gpu_matches_cpu(&kernel(), Variant::Tiled, 1.0);
    gpu_matches_cpu(&baked_kernel(), Variant::Tiled, 1.0);
}

/// A head 20× closer: the widest taps reach ~140 texels, beyond the tile's 64-texel apron (read from the textures).
#[test]
fn tiled_sss_taps_beyond_the_apron_match_cpu() {
    gpu_matches_cpu(&baked_kernel(), Variant::Tiled, 0.05);
}

fn gpu_matches_cpu(k: &SssKernel, variant: Variant, depth_scale: f32) {
    let (w, h) = (200, 160);
    let g = gpu();
    let (color, mut depth) = scene(w, h);
    depth.iter_mut().for_each(|d| *d *= depth_scale);
    let (k, p) = (k.clone(), SssParams::default());
    let out = run_variant(variant, &g, (w, h), &k, &p, &color, &depth);
    let cpu = separable_sss(&color, &depth, w, h, &k, &p);
    // Tolerance in linear space: 2e-3 absolute + 2e-3 relative (f16 storage is ~1e-3 relative).
    let bad = out.iter().zip(&cpu).filter(|(a, b)| (*a - *b).abs() > 2e-3 + 2e-3 * b.abs()).count();
    let max = out.iter().zip(&cpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    eprintln!("{w}x{h}: {bad} of {} samples outside tolerance, max abs diff {max:.2e}", out.len());
    let ok = bad as f64 <= 0.001 * out.len() as f64;
    let what = format!("{variant:?}: {bad} samples outside 2e-3 + 2e-3 relative");
    assert_gpu_matches_cpu("separable_sss", ok, &what, (w, h, 4), &unorm8_of(&out), &unorm8_of(&cpu));
    // The blur did something on skin.
    let changed = out.iter().zip(&color).filter(|(a, b)| (*a - *b).abs() > 1e-2).count();
    assert!(changed > 1000, "SSS must blur the stripes ({changed} samples changed)");
}

#[test]
fn non_skin_pixels_pass_through_and_energy_is_kept() {
    for k in [kernel(), baked_kernel()] {
        for v in [Variant::Fragment, Variant::Tiled] {
            pass_through_and_energy(k.clone(), v);
        }
    }
}

fn pass_through_and_energy(k: SssKernel, variant: Variant) {
    let (w, h) = (96, 96);
    let g = gpu();
    let (mut color, depth) = scene(w, h);
    let p = SssParams { follow_surface: false, ..Default::default() };
    // Background must come back bit-exact (f16 of the input).
    let out = run_variant(variant, &g, (w, h), &k, &p, &color, &depth);
    for i in 0..(w * h) as usize {
        if color[4 * i + 3] == 0.0 {
            for c in 0..4 {
                assert_eq!(out[4 * i + c], half::f16::from_f32(color[4 * i + c]).to_f32());
            }
        }
    }
    // A constant skin image keeps its value (kernel weights sum to 1 per channel).
    for px in color.chunks_mut(4) {
        px.copy_from_slice(&[0.5, 0.25, 0.125, 1.0]);
    }
    let out = run_variant(variant, &g, (w, h), &k, &p, &color, &vec![2.0; (w * h) as usize]);
    for px in out.chunks(4) {
        for (c, want) in [0.5f32, 0.25, 0.125].iter().enumerate() {
            assert!((px[c] - want).abs() < 2e-3 * want, "{px:?}");
        }
    }
}

#[test]
fn the_sss_pass_shape_comes_from_rtbake_sss_passes() {
    use rtbake::runtime::sss::{shape_for_adapter, PassShape, SHAPE_ENV};
    assert_eq!(SHAPE_ENV, "RTBAKE_SSS_PASSES");
    // Without the variable: the fragment passes on a software rasteriser, compute on a GPU. (The variable is read,
    // never set here: tests share one process.)
    match std::env::var(SHAPE_ENV).ok().as_deref() {
        None => {
            assert_eq!(shape_for_adapter(true).unwrap(), PassShape::Fragment);
            assert_eq!(shape_for_adapter(false).unwrap(), PassShape::Compute);
        }
        Some(v) => match PassShape::parse(v) {
            Ok(shape) => assert_eq!(shape_for_adapter(true).unwrap(), shape),
            Err(_) => {
                let e = shape_for_adapter(false).unwrap_err().to_string();
                assert!(e.contains("RTBAKE_SSS_PASSES") && e.contains("must be compute or fragment"), "{e}");
            }
        },
    }
}

/// `run sss` on the adapter with `RTBAKE_SSS_PASSES` naming no shape: exit 2 naming the variable and its values,
/// nothing written; `compute` and `fragment` both run (the sum of Gaussians, whose two shapes differ most).
#[test]
fn run_sss_refuses_an_unknown_pass_shape() {
    use rtbake::image_buf::Image;
    let t = tempfile::tempdir().unwrap();
    let (w, h) = (40u32, 24u32);
    let (color, depth) = scene(w, h);
    let enc = |img: &Image<f32>| rtbake::io::exr::encode(img, rtbake::io::exr::ExrPrecision::F32).unwrap();
    let (cp, dp, op) = (t.path().join("c.exr"), t.path().join("d.exr"), t.path().join("o.exr"));
    std::fs::write(&cp, enc(&Image::from_vec(w, h, 4, color))).unwrap();
    std::fs::write(&dp, enc(&Image::from_vec(w, h, 1, depth))).unwrap();
    let baked = baked_dir();
    let run = |shape: &str| {
        let _ = std::fs::remove_file(&op);
        let mut args = vec!["run", "sss", "--method", "gaussians", "--color", cp.to_str().unwrap()];
        args.extend(["--depth", dp.to_str().unwrap(), "--output", op.to_str().unwrap()]);
        args.extend(["--baked-dir", baked.to_str().unwrap()]);
        std::process::Command::new(env!("CARGO_BIN_EXE_rtbake"))
            .args(&args)
            .env("RTBAKE_SSS_PASSES", shape)
            .output()
            .unwrap()
    };
    let o = run("tiled");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("RTBAKE_SSS_PASSES") && err.contains("must be compute or fragment, got \"tiled\""), "{err}");
    assert!(!op.exists(), "nothing may be written");
    for shape in ["compute", "fragment"] {
        let o = run(shape);
        assert!(o.status.success(), "{shape}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(op.exists());
    }
}
