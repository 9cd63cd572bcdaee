//! CPU reference of the skin-inputs pass — the twin of `skin/inputs.wgsl` (see
//! [`crate::runtime::skin::inputs`]). LUTs and rig maps are rounded to f16 as on the GPU; fetches are bilinear
//! in f32; outputs are rounded to f16.

use crate::runtime::sampler::{bilinear, f16r};
use crate::runtime::skin::inputs::{RigScaleBiasMaps, SkinFrame, SkinLuts};
use rayon::prelude::*;

fn node(t: f32, n: f32) -> f32 {
    (t.clamp(0.0, 1.0) * (n - 1.0) + 0.5) / n
}

/// Returns (albedo rgb + H, T(s)·E rgb + E) per pixel as RGBA f32 (f16-rounded).
pub fn skin_inputs(
    frame: &SkinFrame,
    luts: &SkinLuts,
    rig: &RigScaleBiasMaps,
    rig_weights: &[f32],
    light_dir: [f32; 3],
) -> (Vec<f32>, Vec<f32>) {
    let (w, h) = (frame.width, frame.height);
    let lut: Vec<[f32; 3]> = luts.albedo.iter().map(|c| c.map(f16r)).collect();
    let tt: Vec<[f32; 3]> = luts.transmittance.iter().map(|c| c.map(f16r)).collect();
    let targets: Vec<Vec<[f32; 2]>> = rig.targets.iter().map(|t| t.iter().map(|v| v.map(f16r)).collect()).collect();
    let (lw, lh) = luts.albedo_size;
    let nt = tt.len() as u32;
    let n = (w * h) as usize;
    let mut albedo = vec![0.0f32; 4 * n];
    let mut trans = vec![0.0f32; 4 * n];
    albedo.par_chunks_mut(4).zip(trans.par_chunks_mut(4)).enumerate().for_each(|(i, (a, t))| {
        let (x, y) = ((i % w as usize) as f32, (i / w as usize) as f32);
        let (u, v) = ((x + 0.5) * (1.0 / w as f32), (y + 0.5) * (1.0 / h as f32));
        let (mut sum_bias, mut sum_scale) = (0.0f32, 0.0f32);
        for (k, map) in targets.iter().enumerate() {
            let sb = bilinear(map, rig.width, rig.height, u, v);
            sum_scale += rig_weights[k] * sb[0];
            sum_bias += rig_weights[k] * sb[1];
        }
        let hb = sum_bias + frame.h0[i] * sum_scale; // eq. 7.6
        let lu = (frame.melanin[i] / 0.5).clamp(0.0, 1.0).powf(1.0 / 3.0);
        let lv = (hb / 0.32).clamp(0.0, 1.0).powf(1.0 / 3.0);
        let c = bilinear(&lut, lw, lh, node(lu, lw as f32), node(lv, lh as f32));
        let nrm = frame.normals[i];
        let e = (0.3 - (nrm[0] * light_dir[0] + nrm[1] * light_dir[1] + nrm[2] * light_dir[2])).max(0.0); // eq. 5.13
        let ts = bilinear(&tt, nt, 1, node(frame.thickness_mm[i] / luts.s_max_mm, nt as f32), 0.5);
        a.copy_from_slice(&[f16r(c[0]), f16r(c[1]), f16r(c[2]), f16r(hb)]);
        t.copy_from_slice(&[f16r(ts[0] * e), f16r(ts[1] * e), f16r(ts[2] * e), f16r(e)]);
    });
    (albedo, trans)
}
