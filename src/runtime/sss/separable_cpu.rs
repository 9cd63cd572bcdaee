//! CPU reference of separable SSS — the twin of `sss/separable.wgsl` (algorithm in
//! [`crate::runtime::sss::separable`]). The colour is rounded to f16 where the GPU stores it (input and the
//! intermediate target); bilinear fetches are f32. Known difference: the hardware may filter f16 colour with
//! reduced weight precision, so results agree to a stated tolerance, not bit for bit.

use crate::runtime::sampler::{f16r, Img};
use crate::runtime::sss::separable::{SssKernel, SssParams};
use rayon::prelude::*;

fn pass(color: &Img, depth: &Img, kernel: &SssKernel, p: &SssParams, dir: [f32; 2]) -> Vec<f32> {
    let (w, h) = (color.w, color.h);
    let dist = p.dist_to_window();
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
            let u = (x as f32 + 0.5) / w as f32;
            let v = (y as f32 + 0.5) / h as f32;
            let depth_m = depth.load(xi, yi, 0);
            let scale = dist / depth_m;
            let step = [
                p.sss_width * scale * dir[0] * cm[3] * (1.0 / 3.0),
                p.sss_width * scale * dir[1] * cm[3] * (1.0 / 3.0),
            ];
            let t0 = kernel.taps[0];
            let mut acc = [cm[0] * t0[0], cm[1] * t0[1], cm[2] * t0[2]];
            for t in &kernel.taps[1..] {
                let (su, sv) = (u + t[3] * step[0], v + t[3] * step[1]);
                let mut c = [color.bilinear(su, sv, 0), color.bilinear(su, sv, 1), color.bilinear(su, sv, 2)];
                if p.follow_surface {
                    let d = depth.bilinear(su, sv, 0);
                    let s = (300.0 * dist * p.sss_width * (depth_m - d).abs()).clamp(0.0, 1.0);
                    for k in 0..3 {
                        c[k] += (cm[k] - c[k]) * s;
                    }
                }
                for k in 0..3 {
                    acc[k] += t[k] * c[k];
                }
            }
            o.copy_from_slice(&[f16r(acc[0]), f16r(acc[1]), f16r(acc[2]), cm[3]]);
        }
    });
    out
}

/// Both passes. `color`: RGBA f32 (linear; alpha = strength), `depth`: linear depth; returns RGBA f32 rounded to
/// f16 like the GPU's `Rgba16Float` target.
pub fn separable_sss(color: &[f32], depth: &[f32], w: u32, h: u32, kernel: &SssKernel, p: &SssParams) -> Vec<f32> {
    assert_eq!(color.len(), (w * h * 4) as usize);
    assert_eq!(depth.len(), (w * h) as usize);
    let c16: Vec<f32> = color.iter().map(|v| f16r(*v)).collect();
    let d = Img { w, h, ch: 1, data: depth };
    let tmp = pass(&Img { w, h, ch: 4, data: &c16 }, &d, kernel, p, [1.0, 0.0]);
    pass(&Img { w, h, ch: 4, data: &tmp }, &d, kernel, p, [0.0, 1.0])
}
