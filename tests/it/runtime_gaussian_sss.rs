//! Screen-space sum-of-Gaussians SSS: GPU vs CPU reference in both shapes (fragment passes, compute over line
//! tiles), the tiles' seams and aprons, eq. 4.8 blend weights, depth LOD skip, energy.

use crate::support::*;
use rtbake::diffusion::sum_of_gaussians::{deon4, deon6, SumOfGaussians};
use rtbake::runtime::cpu::gaussian_sss::gaussian_sss;
use rtbake::runtime::gaussian_sss::{GaussianBlurs, GaussianSss, GaussianSssParams};
use rtbake::runtime::sss::PassShape;

/// Two striped discs (skin, alpha 1): one near (depth ≈ 2), one far (depth ≈ 20, where the narrow Gaussians
/// are skipped by eq. 4.6), on a background (alpha 0).
fn scene(w: u32, h: u32) -> (Vec<f32>, Vec<f32>) {
    let discs = [
        (0.3 * w as f32, 0.5 * h as f32, 0.25 * w as f32, 2.0f32),
        (0.75 * w as f32, 0.5 * h as f32, 0.15 * w as f32, 20.0),
    ];
    let look = Stripes { period: (5, 7), dark: 0.1, alpha: |_| 1.0, depth: |d0, z| d0 - 0.2 * z };
    striped_discs(w, h, &discs, &look)
}

/// How [`striped_discs`] draws its discs: stripes of `period` texels (x, y), the dark stripes at `dark`, alpha and
/// depth from the disc's depth d0 and the sphere's height z (1 at the centre, 0 at the rim).
struct Stripes {
    period: (u32, u32),
    dark: f32,
    alpha: fn(f32) -> f32,
    depth: fn(f32, f32) -> f32,
}

/// A `w`×`h` frame (colour RGBA, depth) of striped, sphere-lit skin discs (cx, cy, r, d0) on a background of alpha
/// 0 at depth 100.
fn striped_discs(w: u32, h: u32, discs: &[(f32, f32, f32, f32)], look: &Stripes) -> (Vec<f32>, Vec<f32>) {
    let (mut color, mut depth) = (vec![0.0f32; (w * h * 4) as usize], vec![100.0f32; (w * h) as usize]);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            color[4 * i..4 * i + 4].copy_from_slice(&[0.1, 0.2, 0.3, 0.0]);
            for &(cx, cy, r, d0) in discs {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
                let d2 = dx * dx + dy * dy;
                if d2 < r * r {
                    let z = (r * r - d2).sqrt() / r;
                    let stripe =
                        if (x / look.period.0 + y / look.period.1).is_multiple_of(2) { 1.0 } else { look.dark };
                    let lit = (0.3 + 0.7 * z) * stripe;
                    color[4 * i..4 * i + 4].copy_from_slice(&[0.9 * lit, 0.6 * lit, 0.5 * lit, (look.alpha)(z)]);
                    depth[i] = (look.depth)(d0, z);
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

/// Samples of `out` farther from `cpu` than 2e-3 + 4e-3·|cpu| (f16 storage and the hardware's filter weights).
fn outside_tolerance(out: &[f32], cpu: &[f32]) -> usize {
    out.iter().zip(cpu).filter(|(a, b)| (*a - *b).abs() > 2e-3 + 4e-3 * b.abs()).count()
}

#[test]
fn gaussian_sss_gpu_matches_cpu() {
    let (w, h) = (240, 128);
    let g = gpu();
    let (color, depth) = scene(w, h);
    let blurs = GaussianBlurs::from_sum_of_gaussians(&deon6()).unwrap();
    let p = GaussianSssParams::default();
    let cpu = gaussian_sss(&color, &depth, w, h, &blurs, &p);
    for shape in [PassShape::Fragment, PassShape::Compute] {
        let pass = GaussianSss::with_shape(&g.device, (w, h), &blurs, &p, shape).unwrap();
        assert_eq!((pass.shape(), pass.passes()), (shape, 10));
        let out = pass.run(&g.device, &g.queue, &color, &depth).unwrap();
        let bad = outside_tolerance(&out, &cpu);
        let max = out.iter().zip(&cpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        eprintln!("{} {w}x{h}: {bad} of {} samples outside tolerance, max abs diff {max:.2e}", shape.name(), out.len());
        assert!(bad as f64 <= 0.001 * out.len() as f64);
        let changed = out.iter().zip(&color).filter(|(a, b)| (*a - *b).abs() > 1e-2).count();
        assert!(changed > 1000, "the blur must act on skin ({changed})");
    }
}

/// Striped discs at four depths on a frame that is no multiple of the 128-texel segment either way (301×187): a
/// close one in the middle whose widest Gaussians reach well over 100 texels (beyond the 64-texel apron, on both
/// sides) and which crosses the seam between the first and second segment of its rows and columns, one at the
/// thesis' distance (within the apron) crossing the second seam of its rows, one farther (its narrow Gaussians
/// skipped by eq. 4.6) and one far away (all skipped), each a depth discontinuity and a matte edge. The compute chain
/// lerps in f32 as the CPU twin does, so every sample must be within the twins' tolerance (the sampler-filtered
/// fragment chain may miss it on 0.1 %): a tap read one texel off (a wrong apron or segment origin), or a tap beyond
/// the apron read from the wrong place, fails.
#[test]
fn compute_chain_matches_cpu_across_tile_seams_and_beyond_the_apron() {
    let (w, h) = (301u32, 187u32);
    let discs = [
        (150.0f32, 93.0f32, 60.0f32, 0.4f32),
        (250.0, 60.0, 40.0, 2.0),
        (40.0, 140.0, 35.0, 20.0),
        (35.0, 30.0, 15.0, 200.0),
    ];
    let look = Stripes { period: (3, 4), dark: 0.05, alpha: |z| 0.5 + 0.5 * z, depth: |d0, z| d0 - 0.1 * d0 * z };
    let (color, depth) = striped_discs(w, h, &discs, &look);
    let g = gpu();
    let p = GaussianSssParams::default();
    // d'Eon's six (five blurs: the running sum ping-pongs an odd number of times) and a sharp pair whose one wide
    // blur (σ 2 mm, ~175 texels on the close disc) acts on the unblurred stripes, where a wrong far tap shows.
    let pair = SumOfGaussians { variances_mm2: vec![0.0064, 4.0], weights: vec![[0.5; 3], [0.5; 3]] };
    let mut outputs = Vec::new();
    for fit in [deon6(), pair] {
        let blurs = GaussianBlurs::from_sum_of_gaussians(&fit).unwrap();
        let cpu = gaussian_sss(&color, &depth, w, h, &blurs, &p);
        let run = |shape| {
            let pass = GaussianSss::with_shape(&g.device, (w, h), &blurs, &p, shape).unwrap();
            pass.run(&g.device, &g.queue, &color, &depth).unwrap()
        };
        let (compute, fragment) = (run(PassShape::Compute), run(PassShape::Fragment));
        let diff = |out: &[f32]| out.iter().zip(&cpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        let (dc, df) = (diff(&compute), diff(&fragment));
        let n = fit.variances_mm2.len();
        eprintln!("{w}x{h}, {n} Gaussians: max abs diff to the CPU twin: compute {dc:.2e}, fragment {df:.2e}");
        // The twins' tolerance with no exception (the fragment chain is allowed 0.1 % of the samples beyond it).
        let bad = outside_tolerance(&compute, &cpu);
        assert_eq!(bad, 0, "{n} Gaussians, compute vs CPU twin: {bad} samples beyond 2e-3 + 4e-3·|x| (max {dc:.2e})");
        assert!(outside_tolerance(&fragment, &cpu) as f64 <= 0.001 * cpu.len() as f64);
        outputs.push(compute);
    }
    let compute = &outputs[0];
    // The scene exercises what it claims: the close disc is blurred, the far one left as it was (f16).
    let at = |x: u32, y: u32| 4 * (y * w + x) as usize;
    let blurred =
        (110..190).filter(|&x| (compute[at(x, 93)] - half::f16::from_f32(color[at(x, 93)]).to_f32()).abs() > 0.05);
    assert!(blurred.count() > 40, "the close disc must be blurred");
    for i in [at(35, 30), at(0, 0)] {
        assert_eq!(
            compute[i..i + 4],
            color[i..i + 4].iter().map(|&c| half::f16::from_f32(c).to_f32()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn lod_skip_and_matte_leave_pixels_untouched_and_energy_is_kept() {
    let (w, h) = (64, 64);
    let g = gpu();
    let (color, _) = scene(w, h);
    let blurs = GaussianBlurs::from_sum_of_gaussians(&deon6()).unwrap();
    let p = GaussianSssParams::default();
    for shape in [PassShape::Fragment, PassShape::Compute] {
        lod_skip_and_matte(&g, shape, &color, (w, h), &blurs, &p);
    }
}

fn lod_skip_and_matte(
    g: &rtbake::runtime::device::Gpu,
    shape: PassShape,
    color: &[f32],
    (w, h): (u32, u32),
    blurs: &GaussianBlurs,
    p: &GaussianSssParams,
) {
    let pass = GaussianSss::with_shape(&g.device, (w, h), blurs, p, shape).unwrap();
    // Far away (d ≥ 2·sqrt(v_max)·α for every Gaussian): everything is skipped, output = input (f16).
    let far = 2.0 * 7.41f32.sqrt() * p.alpha + 1.0;
    let out = pass.run(&g.device, &g.queue, color, &vec![far; (w * h) as usize]).unwrap();
    for (o, c) in out.iter().zip(color) {
        assert_eq!(*o, half::f16::from_f32(*c).to_f32());
    }
    // Constant skin colour at a near depth: the normalised blurs keep it.
    let flat: Vec<f32> = (0..w * h).flat_map(|_| [0.5f32, 0.25, 0.125, 1.0]).collect();
    let out = pass.run(&g.device, &g.queue, &flat, &vec![2.0; (w * h) as usize]).unwrap();
    for px in out.chunks(4) {
        for (c, want) in [0.5f32, 0.25, 0.125].iter().enumerate() {
            assert!((px[c] - want).abs() < 3e-3 * want, "{}: {px:?}", shape.name());
        }
    }
}
