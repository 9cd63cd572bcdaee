//! CPU reference of Jimenez's MLAA — the twin of `aa/mlaa.wgsl` (algorithm and source in
//! [`crate::runtime::aa::mlaa`]). Same pixel-unit arithmetic, same bilinear/point fetches through [`Tex8`].

use crate::error::InvalidInput;
use crate::runtime::aa::edges::AaInputs;
use crate::runtime::aa::mlaa::{MlaaAreaMap, MlaaOptions, MLAA_THRESHOLD};
use crate::runtime::sampler::{linear_to_srgb, srgb_to_linear, unorm8, wgsl_round as round, FilterPrecision, Tex8};
use rayon::prelude::*;

const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Intermediate and final images of one MLAA run.
pub struct MlaaCpuOutput {
    pub edges: Vec<u8>,
    pub weights: Vec<u8>,
    pub output: Vec<u8>,
}

/// Runs MLAA on `rgba` (`w·h·4` bytes, sRGB-encoded, top row first).
pub fn mlaa(rgba: &[u8], w: u32, h: u32, map: &MlaaAreaMap, prec: FilterPrecision) -> MlaaCpuOutput {
    assert_eq!(rgba.len(), (w * h * 4) as usize, "image size");
    let color = Tex8::new(w, h, 4, rgba);
    let edges = edge_detection(&color);
    let weights = blending_weights(&Tex8::new(w, h, 2, &edges), map, prec);
    let output = neighbourhood_blending(&color, &Tex8::new(w, h, 4, &weights));
    MlaaCpuOutput { edges, weights, output }
}

/// Runs MLAA with an edge detector and mask (the twin of [`crate::runtime::aa::mlaa::Mlaa::with_options`]).
pub fn mlaa_with_options(
    rgba: &[u8],
    (w, h): (u32, u32),
    map: &MlaaAreaMap,
    prec: FilterPrecision,
    options: &MlaaOptions,
    inputs: &AaInputs,
) -> Result<MlaaCpuOutput, InvalidInput> {
    options.edges.validate()?;
    inputs.validate(w, h, &options.edges, options.masked)?;
    assert_eq!(rgba.len(), (w * h * 4) as usize, "image size");
    let color = Tex8::new(w, h, 4, rgba);
    let edges = if options.edges.is_plain_luma() {
        edge_detection(&color)
    } else {
        crate::runtime::aa::edges_cpu::edge_detection(&color, inputs.depth, &options.edges, 0.0)
    };
    let weights = blending_weights(&Tex8::new(w, h, 2, &edges), map, prec);
    let mut output = neighbourhood_blending(&color, &Tex8::new(w, h, 4, &weights));
    if let Some(mask) = inputs.mask.filter(|_| options.masked) {
        output = crate::runtime::aa::edges_cpu::apply_mask(rgba, &output, mask);
    }
    Ok(MlaaCpuOutput { edges, weights, output })
}

/// Listing 9.1, luminance variant.
pub fn edge_detection(color: &Tex8) -> Vec<u8> {
    let w = color.w;
    let luma =
        |x: i32, y: i32| color.load(x, y, 0) * LUMA[0] + color.load(x, y, 1) * LUMA[1] + color.load(x, y, 2) * LUMA[2];
    let mut out = vec![0u8; (w * color.h * 2) as usize];
    out.par_chunks_mut((w * 2) as usize).enumerate().for_each(|(y, row)| {
        let y = y as i32;
        for x in 0..w as i32 {
            let l = luma(x, y);
            row[x as usize * 2] = if (l - luma(x - 1, y)).abs() >= MLAA_THRESHOLD { 255 } else { 0 };
            row[x as usize * 2 + 1] = if (l - luma(x, y - 1)).abs() >= MLAA_THRESHOLD { 255 } else { 0 };
        }
    });
    out
}

struct Ctx<'a> {
    edges: Tex8<'a>,
    area: Tex8<'a>,
    n: f32,
    steps: f32,
    rt: [f32; 2],
    prec: FilterPrecision,
}

impl Ctx<'_> {
    fn edges_at(&self, px: f32, py: f32) -> [f32; 2] {
        self.edges.sample2(px * self.rt[0], py * self.rt[1], self.prec)
    }

    /// Listing 9.3 generalised: `axis` 0 searches along x (reads G), 1 along y (reads R); `sign` ±1.
    fn search(&self, px: f32, py: f32, axis: usize, sign: f32) -> f32 {
        let mut t = [px, py];
        t[axis] += 1.5 * sign;
        let mut e = 0.0f32;
        let mut i = 0.0f32;
        while i < self.steps {
            e = self.edges_at(t[0], t[1])[1 - axis];
            if e < 0.9 {
                break;
            }
            t[axis] += 2.0 * sign;
            i += 1.0;
        }
        if sign < 0.0 {
            (-2.0 * i - 2.0 * e).max(-2.0 * self.steps)
        } else {
            (2.0 * i + 2.0 * e).min(2.0 * self.steps)
        }
    }

    /// Listing 9.4.
    fn area(&self, d: [f32; 2], e1: f32, e2: f32) -> [f32; 2] {
        let px = self.n * round(4.0 * e1) + d[0];
        let py = self.n * round(4.0 * e2) + d[1];
        let s = 5.0 * self.n - 1.0;
        self.area.sample2_nearest(px / s, py / s)
    }

    /// Listing 9.2.
    fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
        let mut weights = [0.0f32; 4];
        let e = [self.edges.load(x as i32, y as i32, 0), self.edges.load(x as i32, y as i32, 1)];
        if e[1] > 0.0 {
            let d = [self.search(px, py, 0, -1.0), self.search(px, py, 0, 1.0)];
            let e1 = self.edges_at(px + d[0], py - 0.25)[0];
            let e2 = self.edges_at(px + (d[1] + 1.0), py - 0.25)[0];
            let a = self.area([d[0].abs(), d[1].abs()], e1, e2);
            weights[0] = a[0];
            weights[1] = a[1];
        }
        if e[0] > 0.0 {
            let d = [self.search(px, py, 1, -1.0), self.search(px, py, 1, 1.0)];
            let e1 = self.edges_at(px - 0.25, py + d[0])[1];
            let e2 = self.edges_at(px - 0.25, py + (d[1] + 1.0))[1];
            let a = self.area([d[0].abs(), d[1].abs()], e1, e2);
            weights[2] = a[0];
            weights[3] = a[1];
        }
        weights
    }
}

/// Listing 9.2 over the whole frame.
pub fn blending_weights(edges: &Tex8, map: &MlaaAreaMap, prec: FilterPrecision) -> Vec<u8> {
    let (w, h) = (edges.w, edges.h);
    let ctx = Ctx {
        edges: *edges,
        area: Tex8::new(5 * map.n, 5 * map.n, 2, &map.bytes),
        n: map.n as f32,
        steps: map.search_steps() as f32,
        rt: [1.0 / w as f32, 1.0 / h as f32],
        prec,
    };
    let mut out = vec![0u8; (w * h * 4) as usize];
    out.par_chunks_mut((w * 4) as usize).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            let wgt = ctx.pixel(x, y as u32);
            for c in 0..4 {
                row[x as usize * 4 + c] = unorm8(wgt[c]);
            }
        }
    });
    out
}

/// Listing 9.5, in linear light.
pub fn neighbourhood_blending(color: &Tex8, weights: &Tex8) -> Vec<u8> {
    let w = color.w;
    let color_lin = |x: i32, y: i32| {
        [
            srgb_to_linear(color.load(x, y, 0)),
            srgb_to_linear(color.load(x, y, 1)),
            srgb_to_linear(color.load(x, y, 2)),
            color.load(x, y, 3),
        ]
    };
    let mut out = vec![0u8; (w * color.h * 4) as usize];
    out.par_chunks_mut((w * 4) as usize).enumerate().for_each(|(y, row)| {
        let y = y as i32;
        for x in 0..w as i32 {
            let a =
                [weights.load(x, y, 0), weights.load(x, y + 1, 1), weights.load(x, y, 2), weights.load(x + 1, y, 3)];
            let sum = a[0] + a[1] + a[2] + a[3];
            let o = x as usize * 4;
            if sum <= 0.0 {
                let i = (y as usize * w as usize + x as usize) * 4;
                row[o..o + 4].copy_from_slice(&color.data[i..i + 4]);
                continue;
            }
            let c = color_lin(x, y);
            let nb = [color_lin(x, y - 1), color_lin(x, y + 1), color_lin(x - 1, y), color_lin(x + 1, y)];
            for k in 0..4 {
                let mut v = 0.0f32;
                for j in 0..4 {
                    v += a[j] * (c[k] + (nb[j][k] - c[k]) * a[j]);
                }
                v /= sum;
                row[o + k] = unorm8(if k < 3 { linear_to_srgb(v) } else { v });
            }
        }
    });
    out
}
