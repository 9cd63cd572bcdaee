//! The frame loop and the tap the CPU twins of the one-kernel screen-space passes share ([`super::separable_cpu`],
//! [`super::importance_cpu`]), in the shaders' arithmetic order: a pixel of zero strength (alpha) passes through;
//! any other sums bilinear taps of the colour, each pulled towards the centre colour in the proportion
//! s = saturate(k·|Δdepth|) when following the surface, and is stored rounded to f16 (the GPU's `Rgba16Float`
//! target) with the centre's alpha.

use crate::runtime::sampler::{f16r, Img};
use rayon::prelude::*;

/// Runs `shade(x, y, centre)` (the blurred rgb) over every pixel of non-zero strength of `color`, rows in parallel.
pub(crate) fn shade_frame(color: &Img, shade: impl Fn(usize, usize, [f32; 4]) -> [f32; 3] + Sync) -> Vec<f32> {
    let w = color.w as usize;
    let mut out = vec![0.0f32; w * color.h as usize * 4];
    out.par_chunks_mut(w * 4).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            let (xi, yi) = (x as i32, y as i32);
            let cm = [color.load(xi, yi, 0), color.load(xi, yi, 1), color.load(xi, yi, 2), color.load(xi, yi, 3)];
            let o = &mut row[x * 4..x * 4 + 4];
            if cm[3] == 0.0 {
                o.copy_from_slice(&cm);
                continue;
            }
            let acc = shade(x, y, cm);
            o.copy_from_slice(&[f16r(acc[0]), f16r(acc[1]), f16r(acc[2]), cm[3]]);
        }
    });
    out
}

/// Adds `weight` times the colour at normalised (u, v) to `acc`; with `follow = Some(k)` the colour is first pulled
/// towards the centre colour `centre` (at depth `depth_m`) in the proportion saturate(k·|depth_m − depth(u, v)|).
pub(crate) fn add_tap(
    acc: &mut [f32; 3],
    (color, depth): (&Img, &Img),
    (u, v): (f32, f32),
    (centre, depth_m): (&[f32; 4], f32),
    follow: Option<f32>,
    weight: &[f32],
) {
    let mut c = [color.bilinear(u, v, 0), color.bilinear(u, v, 1), color.bilinear(u, v, 2)];
    if let Some(k) = follow {
        let s = (k * (depth_m - depth.bilinear(u, v, 0)).abs()).clamp(0.0, 1.0);
        for i in 0..3 {
            c[i] += (centre[i] - c[i]) * s;
        }
    }
    for i in 0..3 {
        acc[i] += weight[i] * c[i];
    }
}
