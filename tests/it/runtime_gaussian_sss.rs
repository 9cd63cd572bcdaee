//! Screen-space sum-of-Gaussians SSS: GPU vs CPU reference, eq. 4.8 blend weights, depth LOD skip, energy.

use crate::support::*;
use rtbake::diffusion::sum_of_gaussians::{deon4, deon6};
use rtbake::runtime::cpu::gaussian_sss::gaussian_sss;
use rtbake::runtime::gaussian_sss::{GaussianBlurs, GaussianSss, GaussianSssParams};

/// Two striped discs (skin, alpha 1): one near (depth ≈ 2), one far (depth ≈ 20, where the narrow Gaussians
/// are skipped by eq. 4.6), on a background (alpha 0).
fn scene(w: u32, h: u32) -> (Vec<f32>, Vec<f32>) {
    let (mut color, mut depth) = (vec![0.0f32; (w * h * 4) as usize], vec![100.0f32; (w * h) as usize]);
    let discs = [
        (0.3 * w as f32, 0.5 * h as f32, 0.25 * w as f32, 2.0f32),
        (0.75 * w as f32, 0.5 * h as f32, 0.15 * w as f32, 20.0),
    ];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            color[4 * i..4 * i + 4].copy_from_slice(&[0.1, 0.2, 0.3, 0.0]);
            for &(cx, cy, r, d0) in &discs {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
                let d2 = dx * dx + dy * dy;
                if d2 < r * r {
                    let z = (r * r - d2).sqrt() / r;
                    let stripe = if (x / 5 + y / 7) % 2 == 0 { 1.0 } else { 0.1 };
                    let lit = (0.3 + 0.7 * z) * stripe;
                    color[4 * i..4 * i + 4].copy_from_slice(&[0.9 * lit, 0.6 * lit, 0.5 * lit, 1.0]);
                    depth[i] = d0 - 0.2 * z;
                }
            }
        }
    }
    (color, depth)
}

#[test]
fn blend_weights_follow_eq_4_8() {
    // Thesis Table 4.2, 4-Gaussian skin: w' = 1; 0.3251, 0.4501, 0.3583; 0.3400, 0.1870, 0.0; 0.4600, 0.0, 0.0402
    let b = GaussianBlurs::from_sum_of_gaussians(&deon4()).unwrap();
    let want = [[1.0, 1.0, 1.0], [0.3251, 0.4501, 0.3583], [0.3400, 0.1870, 0.0], [0.4600, 0.0, 0.0402]];
    for (got, want) in b.blend.iter().zip(want) {
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() < 6e-4, "{got:?} vs {want:?}");
        }
    }
    // Incremental variance example of §4.2.1: 2.0062 − 0.2719 = 1.7343.
    assert!((b.incremental_sigma_mm[3] - 1.7343f32.sqrt()).abs() < 1e-5);
}

#[test]
fn gaussian_sss_gpu_matches_cpu() {
    let (w, h) = (240, 128);
    let g = gpu();
    let (color, depth) = scene(w, h);
    let blurs = GaussianBlurs::from_sum_of_gaussians(&deon6()).unwrap();
    let p = GaussianSssParams::default();
    let pass = GaussianSss::new(&g.device, w, h, &blurs, &p).unwrap();
    let out = pass.run(&g.device, &g.queue, &color, &depth).unwrap();
    let cpu = gaussian_sss(&color, &depth, w, h, &blurs, &p);
    let bad = out.iter().zip(&cpu).filter(|(a, b)| (*a - *b).abs() > 2e-3 + 4e-3 * b.abs()).count();
    let max = out.iter().zip(&cpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    eprintln!("{w}x{h}: {bad} of {} samples outside tolerance, max abs diff {max:.2e}", out.len());
    assert!(bad as f64 <= 0.001 * out.len() as f64);
    let changed = out.iter().zip(&color).filter(|(a, b)| (*a - *b).abs() > 1e-2).count();
    assert!(changed > 1000, "the blur must act on skin ({changed})");
}

#[test]
fn lod_skip_and_matte_leave_pixels_untouched_and_energy_is_kept() {
    let (w, h) = (64, 64);
    let g = gpu();
    let (color, _) = scene(w, h);
    let blurs = GaussianBlurs::from_sum_of_gaussians(&deon6()).unwrap();
    let p = GaussianSssParams::default();
    let pass = GaussianSss::new(&g.device, w, h, &blurs, &p).unwrap();
    // Far away (d ≥ 2·sqrt(v_max)·α for every Gaussian): everything is skipped, output = input (f16).
    let far = 2.0 * 7.41f32.sqrt() * p.alpha + 1.0;
    let out = pass.run(&g.device, &g.queue, &color, &vec![far; (w * h) as usize]).unwrap();
    for (o, c) in out.iter().zip(&color) {
        assert_eq!(*o, half::f16::from_f32(*c).to_f32());
    }
    // Constant skin colour at a near depth: the normalised blurs keep it.
    let flat: Vec<f32> = (0..w * h).flat_map(|_| [0.5f32, 0.25, 0.125, 1.0]).collect();
    let out = pass.run(&g.device, &g.queue, &flat, &vec![2.0; (w * h) as usize]).unwrap();
    for px in out.chunks(4) {
        for (c, want) in [0.5f32, 0.25, 0.125].iter().enumerate() {
            assert!((px[c] - want).abs() < 3e-3 * want, "{px:?}");
        }
    }
}
