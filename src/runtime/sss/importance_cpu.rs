//! CPU reference of importance-sampled SSS — the twin of `sss/importance.wgsl` (algorithm in
//! [`crate::runtime::sss::importance`]). The colour is rounded to f16 where the GPU stores it (input and output);
//! bilinear fetches are f32. Known difference: the hardware may filter f16 colour with reduced weight precision, so
//! results agree to a stated tolerance, not bit for bit.

use crate::runtime::sampler::{f16r, Img};
use crate::runtime::sss::importance::{ImportanceSamples, ImportanceSssParams};
use rayon::prelude::*;

/// The pass. `color`: RGBA f32 (linear; alpha = strength), `depth`: linear depth (world units); returns RGBA f32
/// rounded to f16 like the GPU's `Rgba16Float` target.
pub fn importance_sss(
    color: &[f32],
    depth: &[f32],
    w: u32,
    h: u32,
    samples: &ImportanceSamples,
    p: &ImportanceSssParams,
) -> Vec<f32> {
    assert_eq!(color.len(), (w * h * 4) as usize);
    assert_eq!(depth.len(), (w * h) as usize);
    let c16: Vec<f32> = color.iter().map(|v| f16r(*v)).collect();
    let color = Img { w, h, ch: 4, data: &c16 };
    let depth = Img { w, h, ch: 1, data: depth };
    let px_scale = 0.5 * h as f32 * p.dist_to_window() / p.mm_per_world_unit;
    let inv_cutoff = p.mm_per_world_unit / samples.cutoff_mm;
    let mut out = vec![0.0f32; (w * h * 4) as usize];
    out.par_chunks_mut(w as usize * 4).enumerate().for_each(|(y, row)| {
        for x in 0..w as usize {
            let (xi, yi) = (x as i32, y as i32);
            let cm = [color.load(xi, yi, 0), color.load(xi, yi, 1), color.load(xi, yi, 2), color.load(xi, yi, 3)];
            let o = &mut row[x * 4..x * 4 + 4];
            if cm[3] == 0.0 {
                o.copy_from_slice(&cm);
                continue;
            }
            let depth_m = depth.load(xi, yi, 0);
            let px_per_mm = px_scale * cm[3] / depth_m;
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let mut acc = [0.0f32; 3];
            for (off, wt) in samples.offsets_mm.iter().zip(&samples.weights) {
                let su = (px + off[0] * px_per_mm) * (1.0 / w as f32);
                let sv = (py + off[1] * px_per_mm) * (1.0 / h as f32);
                let mut c = [color.bilinear(su, sv, 0), color.bilinear(su, sv, 1), color.bilinear(su, sv, 2)];
                if p.follow_surface {
                    let d = depth.bilinear(su, sv, 0);
                    let s = ((depth_m - d).abs() * inv_cutoff).clamp(0.0, 1.0);
                    for k in 0..3 {
                        c[k] += (cm[k] - c[k]) * s;
                    }
                }
                for k in 0..3 {
                    acc[k] += wt[k] * c[k];
                }
            }
            o.copy_from_slice(&[f16r(acc[0]), f16r(acc[1]), f16r(acc[2]), cm[3]]);
        }
    });
    out
}
