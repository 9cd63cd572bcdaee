//! CPU reference of the screen-space sum-of-Gaussians SSS — the twin of `sss/gaussian.wgsl` (algorithm
//! and source in [`crate::runtime::sss::gaussian`]). Values are rounded to f16 wherever the GPU stores them
//! (input, RT1, RT2, RTF); the alpha blend of eq. 4.9 is computed in f32 and then rounded.

use crate::runtime::sampler::f16r;
use crate::runtime::sss::gaussian::{GaussianBlurs, GaussianSssParams};
use rayon::prelude::*;

const W: [f32; 7] = [0.006, 0.061, 0.242, 0.382, 0.242, 0.061, 0.006];

struct Frame<'a> {
    w: u32,
    h: u32,
    depth: &'a [f32],
    matte: &'a [f32],
    p: &'a GaussianSssParams,
}

impl Frame<'_> {
    fn depth_load(&self, x: i32, y: i32) -> f32 {
        let x = x.clamp(0, self.w as i32 - 1) as usize;
        let y = y.clamp(0, self.h as i32 - 1) as usize;
        self.depth[y * self.w as usize + x]
    }

    /// The uv step per tap, or None when skipped (matte / eq. 4.6).
    fn stretch_step(&self, x: i32, y: i32, dir: [i32; 2], incr_sigma: f32, sigma: f32) -> Option<[f32; 2]> {
        let d = self.depth_load(x, y);
        let a = self.matte[(y as usize * self.w as usize + x as usize) * 4 + 3];
        if a == 0.0 || d >= self.p.lod_factor * sigma * self.p.alpha {
            return None;
        }
        let parity = (x * dir[0] + y * dir[1]) & 1;
        let (bx, by) = (x - dir[0] * parity, y - dir[1] * parity);
        let dd = self.depth_load(bx + dir[0], by + dir[1]) - self.depth_load(bx, by);
        let s = self.p.alpha / (d + self.p.beta * dd.abs().min(self.p.gamma)); // eq. 4.1/4.2
        let s_local = s * a; // eq. 4.3/4.4
        Some([
            s_local * incr_sigma * (1.0 / self.w as f32) * dir[0] as f32,
            s_local * incr_sigma * (1.0 / self.h as f32) * dir[1] as f32,
        ])
    }
}

fn load4(img: &[f32], w: u32, h: u32, x: i32, y: i32) -> [f32; 4] {
    let x = x.clamp(0, w as i32 - 1) as usize;
    let y = y.clamp(0, h as i32 - 1) as usize;
    let i = (y * w as usize + x) * 4;
    [img[i], img[i + 1], img[i + 2], img[i + 3]]
}

fn bilinear3(img: &[f32], w: u32, h: u32, u: f32, v: f32) -> [f32; 3] {
    let x = u * w as f32 - 0.5;
    let y = v * h as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i32, y0 as i32);
    let (a, b) = (load4(img, w, h, x0, y0), load4(img, w, h, x0 + 1, y0));
    let (c, d) = (load4(img, w, h, x0, y0 + 1), load4(img, w, h, x0 + 1, y0 + 1));
    let mut out = [0.0f32; 3];
    for k in 0..3 {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        out[k] = top + (bottom - top) * fy;
    }
    out
}

fn blur(src: &[f32], w: u32, h: u32, x: i32, y: i32, fw: [f32; 2]) -> [f32; 4] {
    let mut off = [(x as f32 + 0.5) / w as f32 - fw[0], (y as f32 + 0.5) / h as f32 - fw[1]];
    let mut c = [0.0f32; 3];
    for wi in W {
        let t = bilinear3(src, w, h, off[0], off[1]);
        for k in 0..3 {
            c[k] += wi * t[k];
        }
        off = [off[0] + fw[0] / 3.0, off[1] + fw[1] / 3.0];
    }
    [c[0], c[1], c[2], load4(src, w, h, x, y)[3]]
}

/// Runs the chain; `color` RGBA f32 (alpha = SSS level), `depth` linear; returns RTF (RGBA, f16-rounded).
pub fn gaussian_sss(
    color: &[f32],
    depth: &[f32],
    w: u32,
    h: u32,
    blurs: &GaussianBlurs,
    p: &GaussianSssParams,
) -> Vec<f32> {
    assert_eq!(color.len(), (w * h * 4) as usize);
    assert_eq!(depth.len(), (w * h) as usize);
    let input: Vec<f32> = color.iter().map(|v| f16r(*v)).collect();
    let f = Frame { w, h, depth, matte: &input, p };
    let mut rt1 = input.clone();
    let mut rtf = input.clone();
    for i in 1..blurs.sigma_mm.len() {
        let (incr, sigma, wb) = (blurs.incremental_sigma_mm[i], blurs.sigma_mm[i], blurs.blend[i]);
        let mut rt2 = vec![0.0f32; rt1.len()];
        rt2.par_chunks_mut(w as usize * 4).enumerate().for_each(|(y, row)| {
            for x in 0..w as usize {
                let (xi, yi) = (x as i32, y as i32);
                let v = match f.stretch_step(xi, yi, [1, 0], incr, sigma) {
                    None => load4(&rt1, w, h, xi, yi),
                    Some(fw) => blur(&rt1, w, h, xi, yi, fw).map(f16r),
                };
                row[x * 4..x * 4 + 4].copy_from_slice(&v);
            }
        });
        let rt1_prev = std::mem::take(&mut rt1);
        let mut next1 = rt1_prev.clone();
        next1.par_chunks_mut(w as usize * 4).zip(rtf.par_chunks_mut(w as usize * 4)).enumerate().for_each(
            |(y, (r1, rf))| {
                for x in 0..w as usize {
                    let (xi, yi) = (x as i32, y as i32);
                    if let Some(fw) = f.stretch_step(xi, yi, [0, 1], incr, sigma) {
                        let c = blur(&rt2, w, h, xi, yi, fw);
                        let o = x * 4;
                        for k in 0..3 {
                            r1[o + k] = f16r(c[k]);
                            rf[o + k] = f16r(c[k] * wb[k] + rf[o + k] * (1.0 - wb[k]));
                            // eq. 4.9
                        }
                        r1[o + 3] = f16r(c[3]);
                    }
                }
            },
        );
        rt1 = next1;
    }
    rtf
}
