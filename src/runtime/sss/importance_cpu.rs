//! CPU reference of importance-sampled SSS — the twin of `sss/importance.wgsl` (algorithm in
//! [`crate::runtime::sss::importance`]). The colour is rounded to f16 where the GPU stores it (input and output);
//! bilinear fetches are f32. Known difference: the hardware may filter f16 colour with reduced weight precision, so
//! results agree to a stated tolerance, not bit for bit.

use crate::runtime::sampler::{f16r, Img};
use crate::runtime::sss::blur_cpu::{add_tap, shade_frame};
use crate::runtime::sss::importance::{ImportanceSamples, ImportanceSssParams};

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
    let follow = p.follow_surface.then_some(inv_cutoff);
    shade_frame(&color, |x, y, cm| {
        let depth_m = depth.load(x as i32, y as i32, 0);
        let px_per_mm = px_scale * cm[3] / depth_m;
        let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
        let mut acc = [0.0f32; 3];
        for (off, wt) in samples.offsets_mm.iter().zip(&samples.weights) {
            let su = (px + off[0] * px_per_mm) * (1.0 / w as f32);
            let sv = (py + off[1] * px_per_mm) * (1.0 / h as f32);
            add_tap(&mut acc, (&color, &depth), (su, sv), (&cm, depth_m), follow, wt);
        }
        acc
    })
}
