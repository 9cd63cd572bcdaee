//! Importance-sampled SSS: GPU vs CPU reference (a power-of-two-free and an odd size), the matte (non-skin pixels
//! pass through), energy conservation on a constant image, the chain's GPU/CPU choice, and the compute and fragment
//! shapes writing the same bytes.

use crate::support::*;
use rtbake::diffusion::burley::{RgbBurley, ShapeFit};
use rtbake::runtime::chain::{self, Subsurface};
use rtbake::runtime::cpu::importance_sss::importance_sss;
use rtbake::runtime::importance_sss::{ImportanceSamples, ImportanceSss, ImportanceSssParams};
use rtbake::runtime::sss::PassShape;
use rtbake::sss_sampling::compare::{BURLEY_SKIN_ALBEDO, BURLEY_SKIN_MFP_MM};
use rtbake::sss_sampling::{ImportanceKernel, SampledProfile};

fn burley_samples(n: usize) -> ImportanceSamples {
    let b =
        RgbBurley::from_mean_free_path(BURLEY_SKIN_ALBEDO, BURLEY_SKIN_MFP_MM, ShapeFit::DiffuseTransmission).unwrap();
    ImportanceSamples::from_kernel(&ImportanceKernel::new(SampledProfile::Burley(&b), n).unwrap())
}

fn skin1_samples(n: usize) -> ImportanceSamples {
    let p = rtbake::diffusion::materials::find("skin1").unwrap().dipole(rtbake::diffusion::FdrForm::Dj05);
    ImportanceSamples::from_kernel(&ImportanceKernel::new(SampledProfile::Tabulated(&p), n).unwrap())
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

#[test]
fn importance_sss_gpu_matches_cpu() {
    let g = gpu();
    for (w, h, samples) in [(256, 192, burley_samples(40)), (131, 97, skin1_samples(80)), (64, 64, burley_samples(1))] {
        for follow_surface in [true, false] {
            let p = ImportanceSssParams { follow_surface, ..Default::default() };
            let (color, depth) = scene(w, h);
            let pass = ImportanceSss::new(&g.device, w, h, &samples, &p).unwrap();
            let out = pass.run(&g.device, &g.queue, &color, &depth).unwrap();
            let cpu = importance_sss(&color, &depth, w, h, &samples, &p);
            let bad = out.iter().zip(&cpu).filter(|(a, b)| (*a - *b).abs() > 1.0 / 255.0).count();
            let max = out.iter().zip(&cpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
            eprintln!(
                "{w}x{h}, N = {}, follow {follow_surface}: {bad} of {} channels beyond 1/255, max abs diff {max:.2e}",
                samples.offsets_mm.len(),
                out.len()
            );
            assert!(bad as f64 <= 0.001 * out.len() as f64, "{bad} of {}", out.len());
            if samples.offsets_mm.len() > 1 {
                let changed = out.iter().zip(&color).filter(|(a, b)| (*a - *b).abs() > 1e-2).count();
                assert!(changed > 1000, "SSS must blur the stripes ({changed} samples changed)");
            }
        }
    }
}

#[test]
fn importance_sss_passes_non_skin_through_and_keeps_energy() {
    let g = gpu();
    let (w, h) = (96, 96);
    let samples = skin1_samples(40);
    let p = ImportanceSssParams { follow_surface: false, ..Default::default() };
    let (mut color, depth) = scene(w, h);
    let pass = ImportanceSss::new(&g.device, w, h, &samples, &p).unwrap();
    let out = pass.run(&g.device, &g.queue, &color, &depth).unwrap();
    for i in 0..(w * h) as usize {
        if color[4 * i + 3] == 0.0 {
            for c in 0..4 {
                assert_eq!(out[4 * i + c], half::f16::from_f32(color[4 * i + c]).to_f32());
            }
        }
    }
    for px in color.chunks_mut(4) {
        px.copy_from_slice(&[0.5, 0.25, 0.125, 1.0]);
    }
    let out = pass.run(&g.device, &g.queue, &color, &vec![2.0; (w * h) as usize]).unwrap();
    for px in out.chunks(4) {
        for (c, want) in [0.5f32, 0.25, 0.125].iter().enumerate() {
            assert!((px[c] - want).abs() < 2e-3 * want, "{px:?}");
        }
    }
}

#[test]
fn importance_sss_through_the_chain_and_bad_input() {
    let g = gpu();
    let (w, h) = (80, 60);
    let (color, depth) = scene(w, h);
    let samples = burley_samples(20);
    let params = ImportanceSssParams::default();
    let method = Subsurface::Importance { samples: &samples, params: &params };
    let a = chain::subsurface(Some(&g), &color, &depth, (w, h), &method).unwrap();
    let b = chain::subsurface(None, &color, &depth, (w, h), &method).unwrap();
    let bad = a.iter().zip(&b).filter(|(x, y)| (*x - *y).abs() > 1.0 / 255.0).count();
    assert!(bad as f64 <= 0.001 * a.len() as f64);
    let bad_params = ImportanceSssParams { mm_per_world_unit: 0.0, ..Default::default() };
    let method = Subsurface::Importance { samples: &samples, params: &bad_params };
    for gpu in [Some(&g), None] {
        let e = chain::subsurface(gpu, &color, &depth, (w, h), &method).unwrap_err().to_string();
        assert!(e.contains("mm_per_world_unit"), "{e}");
    }
    let empty = ImportanceSamples { offsets_mm: vec![], weights: vec![], cutoff_mm: 1.0 };
    let e = ImportanceSss::new(&g.device, w, h, &empty, &params).err().unwrap().to_string();
    assert!(e.contains("samples") && e.contains("1..=1024"), "{e}");
}

/// The compute shape (8×8-pixel workgroups) and the fragment pass call one per-pixel function through the same
/// sampler: the same bytes, at a size no multiple of the workgroup, with follow-surface across the sphere's edge,
/// and TAP's 13 jittered taps (SS Jittered) as well as a Burley kernel.
#[test]
fn importance_sss_compute_and_fragment_write_the_same_bytes() {
    let g = gpu();
    let (w, h) = (131, 97);
    let (color, depth) = scene(w, h);
    let jittered = rtbake::runtime::skin::frame::jittered_samples().unwrap();
    for samples in [jittered, burley_samples(40)] {
        let p = ImportanceSssParams::default();
        let run = |shape| {
            let pass = ImportanceSss::with_shape(&g.device, (w, h), &samples, &p, shape).unwrap();
            pass.run(&g.device, &g.queue, &color, &depth).unwrap()
        };
        let (compute, fragment) = (run(PassShape::Compute), run(PassShape::Fragment));
        let differ = compute.iter().zip(&fragment).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        assert_eq!(differ, 0, "N = {}: {differ} samples differ", samples.offsets_mm.len());
        let changed = compute.iter().zip(&color).filter(|(a, b)| (*a - *b).abs() > 1e-2).count();
        assert!(changed > 1000, "SSS must blur the stripes ({changed} samples changed)");
    }
}
