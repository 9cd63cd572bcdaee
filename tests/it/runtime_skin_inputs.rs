//! Skin shading inputs: GPU vs CPU reference, rig evaluation (eq. 7.6), E of eq. 5.13, node-inclusive lookups.

use crate::support::*;
use rtbake::baked_layout::path;
use rtbake::runtime::cpu::skin_inputs::skin_inputs;
use rtbake::runtime::skin_inputs::{RigScaleBiasMaps, SkinFrame, SkinInputs, SkinLuts};

fn luts() -> SkinLuts {
    let (w, h) = (16u32, 12u32);
    let albedo = (0..w * h)
        .map(|i| {
            let (u, v) = ((i % w) as f32 / (w - 1) as f32, (i / w) as f32 / (h - 1) as f32);
            [0.8 - 0.6 * u, 0.6 - 0.4 * u - 0.2 * v, 0.5 - 0.4 * u + 0.1 * v]
        })
        .collect();
    let transmittance = (0..64).map(|i| {
        let s = 8.0 * i as f32 / 63.0;
        [(-s * s / 4.0).exp(), (-s * s / 1.0).exp(), (-s * s / 0.5).exp()]
    });
    SkinLuts { albedo_size: (w, h), albedo, transmittance: transmittance.collect(), s_max_mm: 8.0 }
}

fn rig() -> RigScaleBiasMaps {
    let (w, h) = (8u32, 8u32);
    let neutral = vec![[1.0f32, 0.05]; 64];
    let blush = (0..w * h).map(|i| [1.5 + 0.1 * (i % w) as f32, 0.08 + 0.01 * (i / w) as f32]).collect();
    RigScaleBiasMaps { width: w, height: h, targets: vec![neutral, blush] }
}

fn frame(w: u32, h: u32) -> SkinFrame {
    let n = (w * h) as usize;
    let (mut melanin, mut h0, mut thick, mut normals) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![[0.0; 3]; n]);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            melanin[i] = 0.5 * x as f32 / w as f32;
            h0[i] = 0.02 * ((x as f32 * 0.3).sin() + (y as f32 * 0.2).cos()) * 0.5;
            thick[i] = 6.0 * y as f32 / h as f32;
            let a = x as f32 / w as f32 * std::f32::consts::PI;
            normals[i] = [a.cos(), 0.0, a.sin()];
        }
    }
    SkinFrame { width: w, height: h, melanin, h0, thickness_mm: thick, normals }
}

#[test]
fn skin_inputs_gpu_matches_cpu() {
    gpu_matches_cpu(&luts(), &rig(), &[0.4, 0.6]);
}

/// The committed skin colour LUT (256×256), T(s) and example hemoglobin rig, through the loader.
#[test]
fn skin_inputs_gpu_matches_cpu_with_the_baked_tables() {
    use rtbake::runtime::loader;
    let dir = baked_dir();
    let l = loader::load_skin_luts(&dir, path::SKIN_LUT, path::TRANSMITTANCE_DEFAULT).unwrap();
    let r = loader::load_hemoglobin_rig(&dir, path::RIG_EXAMPLE).unwrap();
    let mut weights = vec![0.0f32; r.rig.targets.len()];
    weights[0] = 0.5;
    weights[1] = 0.5;
    gpu_matches_cpu(&l, &r.rig, &weights);
}

fn gpu_matches_cpu(l: &SkinLuts, r: &RigScaleBiasMaps, weights: &[f32]) {
    let (w, h) = (128, 96);
    let g = gpu();
    let f = frame(w, h);
    let light = [0.0f32, 0.6, -0.8];
    let mut pass = SkinInputs::new(&g.device, &g.queue, w, h, l, r).unwrap();
    let (ga, gt) = pass.run(&g.device, &g.queue, &f, weights, light).unwrap();
    let (ca, ct) = skin_inputs(&f, l, r, weights, light);
    for (name, gv, cv) in [("albedo", &ga, &ca), ("transmitted", &gt, &ct)] {
        let bad = gv.iter().zip(cv).filter(|(a, b)| (*a - *b).abs() > 2e-3 + 2e-3 * b.abs()).count();
        let max = gv.iter().zip(cv).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        eprintln!("{name}: {bad} of {} outside tolerance, max abs diff {max:.2e}", gv.len());
        assert!(bad as f64 <= 0.001 * gv.len() as f64, "{name}");
    }
}

#[test]
fn neutral_weights_reproduce_neutral_hemoglobin_and_e_follows_eq_5_13() {
    let (w, h) = (32, 32);
    let g = gpu();
    let (l, r, f) = (luts(), rig(), frame(w, h));
    let mut pass = SkinInputs::new(&g.device, &g.queue, w, h, &l, &r).unwrap();
    let light = [0.0f32, 0.0, 1.0];
    let (a, t) = pass.run(&g.device, &g.queue, &f, &[1.0, 0.0], light).unwrap();
    for i in 0..(w * h) as usize {
        // w_n = 1: H = bias_0 + H0 · scale_0 = 0.05 + H0.
        let want = 0.05 + f.h0[i];
        assert!((a[4 * i + 3] - want).abs() < 1e-4, "H {} vs {want}", a[4 * i + 3]);
        let e = (0.3 - f.normals[i][2]).max(0.0);
        assert!((t[4 * i + 3] - e).abs() < 2e-3, "E {} vs {e}", t[4 * i + 3]);
    }
    // Node-inclusive lookup: Cm = 0 and H = 0 read the first LUT texel exactly.
    let mut f0 = frame(4, 4);
    f0.melanin.iter_mut().for_each(|m| *m = 0.0);
    f0.h0.iter_mut().for_each(|m| *m = 0.0);
    let zero = RigScaleBiasMaps { width: 1, height: 1, targets: vec![vec![[1.0, 0.0]]] };
    let mut p0 = SkinInputs::new(&g.device, &g.queue, 4, 4, &l, &zero).unwrap();
    let (a, _) = p0.run(&g.device, &g.queue, &f0, &[1.0], light).unwrap();
    for (got, want) in a[..3].iter().zip(l.albedo[0]) {
        // The first texel (a neighbour differs by > 0.03), within the filtering error of any backend.
        assert!((got - half::f16::from_f32(want).to_f32()).abs() < 2e-3, "{got} vs {want}");
    }
}

#[test]
fn wrong_rig_weight_count_is_refused() {
    let g = gpu();
    let mut pass = SkinInputs::new(&g.device, &g.queue, 8, 8, &luts(), &rig()).unwrap();
    let e = pass.run(&g.device, &g.queue, &frame(8, 8), &[1.0], [0.0, 0.0, 1.0]).unwrap_err();
    assert!(e.to_string().contains("rig_weights needs one weight per rig target"), "{e}");
}
