//! CPU reference of separable SSS — the twin of `sss/separable.wgsl` (algorithm in
//! [`crate::runtime::sss::separable`]). The colour is rounded to f16 where the GPU stores it (input and the
//! intermediate target); bilinear fetches are f32. Known difference: the hardware may filter f16 colour with
//! reduced weight precision, so results agree to a stated tolerance, not bit for bit.

use crate::runtime::sampler::{f16r, Img};
use crate::runtime::sss::blur_cpu::{add_tap, shade_frame};
use crate::runtime::sss::separable::{SssKernel, SssParams};

fn pass(color: &Img, depth: &Img, kernel: &SssKernel, p: &SssParams, dir: [f32; 2]) -> Vec<f32> {
    let (w, h) = (color.w, color.h);
    let dist = p.dist_to_window();
    let follow = p.follow_surface.then_some(300.0 * dist * p.sss_width);
    shade_frame(color, |x, y, cm| {
        let u = (x as f32 + 0.5) / w as f32;
        let v = (y as f32 + 0.5) / h as f32;
        let depth_m = depth.load(x as i32, y as i32, 0);
        let scale = dist / depth_m;
        let step =
            [p.sss_width * scale * dir[0] * cm[3] * (1.0 / 3.0), p.sss_width * scale * dir[1] * cm[3] * (1.0 / 3.0)];
        let t0 = kernel.taps[0];
        let mut acc = [cm[0] * t0[0], cm[1] * t0[1], cm[2] * t0[2]];
        for t in &kernel.taps[1..] {
            let uv = (u + t[3] * step[0], v + t[3] * step[1]);
            add_tap(&mut acc, (color, depth), uv, (&cm, depth_m), follow, t);
        }
        acc
    })
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
