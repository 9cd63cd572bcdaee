//! CPU reference of SMAA 1x — the twin of `aa/smaa.wgsl` (see that file and [`crate::runtime::aa::smaa`] for
//! the algorithm and its source, Jimenez et al., Eurographics 2012). Positions are in pixel units, exactly as in the
//! shader; texture fetches go through [`Tex8`] so the bilinear tricks of SMAA (two edges per search fetch, four
//! edge bits decoded through the search texture, interpolated area lookups) are reproduced.
//!
//! Known differences from a GPU: `pow` (sRGB) and `sqrt` may differ in the last ulp, and the GPU may fuse
//! multiply-adds; both can flip an output byte by one. The bilinear precision of the adapter is modelled by
//! [`FilterPrecision`].

use crate::error::InvalidInput;
use crate::runtime::aa::edges::{AaInputs, SMAA_LOCAL_CONTRAST_ADAPTATION};
use crate::runtime::aa::smaa::preset::*;
use crate::runtime::aa::smaa::{SmaaOptions, SmaaTextures, SubsampleIndices, AREA_TEX_SIZE, SEARCH_TEX_SIZE};
use crate::runtime::sampler::{
    linear_to_srgb, srgb_to_linear, unorm8, wgsl_round as round, FilterPrecision, Tex8, UNORM8_F32,
};
use rayon::prelude::*;

const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Intermediate and final images of one SMAA run.
pub struct SmaaCpuOutput {
    /// RG8 edges (R left, G top).
    pub edges: Vec<u8>,
    /// RGBA8 blending weights.
    pub weights: Vec<u8>,
    /// RGBA8 output (sRGB-encoded).
    pub output: Vec<u8>,
}

/// Runs SMAA 1x on `rgba` (`w·h·4` bytes, sRGB-encoded, top row first).
pub fn smaa(rgba: &[u8], w: u32, h: u32, luts: &SmaaTextures, prec: FilterPrecision) -> SmaaCpuOutput {
    smaa_with_subsample(rgba, w, h, luts, prec, SubsampleIndices::SMAA_1X)
}

/// Runs SMAA with explicit area-texture slices (one sample of S2x/T2x/4x).
pub fn smaa_with_subsample(
    rgba: &[u8],
    w: u32,
    h: u32,
    luts: &SmaaTextures,
    prec: FilterPrecision,
    subsample: SubsampleIndices,
) -> SmaaCpuOutput {
    let mut out = SmaaCpuOutput { edges: Vec::new(), weights: Vec::new(), output: Vec::new() };
    smaa_into(rgba, w, h, luts, prec, subsample, &mut out);
    out
}

/// Runs SMAA with every option of [`SmaaOptions`] (the twin of [`crate::runtime::aa::smaa::Smaa::with_options`]);
/// `inputs` as for the GPU pass, validated the same way.
pub fn smaa_with_options(
    rgba: &[u8],
    (w, h): (u32, u32),
    luts: &SmaaTextures,
    prec: FilterPrecision,
    options: &SmaaOptions,
    inputs: &AaInputs,
) -> Result<SmaaCpuOutput, InvalidInput> {
    options.edges.validate()?;
    inputs.validate(w, h, &options.edges, options.masked)?;
    if options.edges.is_plain_luma() && !options.masked {
        return Ok(smaa_with_subsample(rgba, w, h, luts, prec, options.subsample));
    }
    assert_eq!(rgba.len(), (w * h * 4) as usize, "image size");
    let color = Tex8::new(w, h, 4, rgba);
    let edges = if options.edges.is_plain_luma() {
        edge_detection(&color)
    } else {
        crate::runtime::aa::edges_cpu::edge_detection(
            &color,
            inputs.depth,
            &options.edges,
            SMAA_LOCAL_CONTRAST_ADAPTATION,
        )
    };
    let weights = blending_weights_with_subsample(&Tex8::new(w, h, 2, &edges), luts, prec, options.subsample);
    let mut output = neighbourhood_blending(&color, &Tex8::new(w, h, 4, &weights));
    if let Some(mask) = inputs.mask.filter(|_| options.masked) {
        output = crate::runtime::aa::edges_cpu::apply_mask(rgba, &output, mask);
    }
    Ok(SmaaCpuOutput { edges, weights, output })
}

/// [`smaa_with_subsample`] into the buffers of a previous run (resized as needed), the CPU counterpart of the GPU
/// pass creating its textures once and reusing them every frame: a frame then allocates nothing and touches no
/// fresh pages (at 1080p the three buffers are 20 MB; first-touch page faults cost more than the passes).
/// Same bytes as [`smaa_with_subsample`].
pub fn smaa_into(
    rgba: &[u8],
    w: u32,
    h: u32,
    luts: &SmaaTextures,
    prec: FilterPrecision,
    subsample: SubsampleIndices,
    out: &mut SmaaCpuOutput,
) {
    assert_eq!(rgba.len(), (w * h * 4) as usize, "image size");
    let n = (w * h) as usize;
    out.edges.resize(2 * n, 0);
    out.weights.resize(4 * n, 0);
    out.output.resize(4 * n, 0);
    let color = Tex8::new(w, h, 4, rgba);
    edge_detection_into(&color, &mut out.edges);
    let edges = Tex8::new(w, h, 2, &out.edges);
    blending_weights_into(&edges, luts, prec, subsample, &mut out.weights);
    neighbourhood_blending_into(&color, &Tex8::new(w, h, 4, &out.weights), &mut out.output);
}

/// `(v as f32 / 255.0) * LUMA[k]` for every byte `v`: the shader's per-channel luma products, looked up.
const LUMA_TABLES: [[f32; 256]; 3] = {
    let mut t = [[0.0f32; 256]; 3];
    let mut i = 0;
    while i < 256 {
        let v = i as f32 / 255.0;
        t[0][i] = v * LUMA[0];
        t[1][i] = v * LUMA[1];
        t[2][i] = v * LUMA[2];
        i += 1;
    }
    t
};

/// Rows per parallel band of the edge pass: the band's luma rows (plus two above, one below) stay in cache.
const EDGE_BAND_ROWS: usize = 32;

/// Pass 1: luma edge detection with local contrast adaptation.
///
/// Row bands in parallel (disjoint outputs, so the bytes do not depend on the thread count). Each band tabulates
/// the luma of its rows and of the two rows above and one below (clamped), each row padded with two clamped
/// texels on the left and one on the right, so the per-texel test reads without clamping. The luma is the
/// shader's dot product, evaluated in the same order.
pub fn edge_detection(color: &Tex8) -> Vec<u8> {
    let mut out = vec![0u8; color.w as usize * color.h as usize * 2];
    edge_detection_into(color, &mut out);
    out
}

/// [`edge_detection`] into `out` (`w·h·2` bytes; every byte is written).
pub fn edge_detection_into(color: &Tex8, out: &mut [u8]) {
    let (w, h) = (color.w as usize, color.h as usize);
    assert_eq!(out.len(), w * h * 2, "edge buffer size");
    if out.is_empty() {
        return;
    }
    let stride = w + 3;
    out.par_chunks_mut(w * 2 * EDGE_BAND_ROWS).enumerate().for_each(|(b, band)| {
        let y0 = b * EDGE_BAND_ROWS;
        let rows = band.len() / (2 * w);
        let mut lum = vec![0.0f32; stride * (rows + 3)];
        let mut planes = [vec![0u8; w], vec![0u8; w]];
        for (k, lrow) in lum.chunks_exact_mut(stride).enumerate() {
            let y = (y0 + k).saturating_sub(2).min(h - 1);
            let src = &color.data[y * w * 4..(y + 1) * w * 4];
            for (l, c) in lrow[2..2 + w].iter_mut().zip(src.chunks_exact(4)) {
                *l = LUMA_TABLES[0][c[0] as usize] + LUMA_TABLES[1][c[1] as usize] + LUMA_TABLES[2][c[2] as usize];
            }
            (lrow[0], lrow[1], lrow[w + 2]) = (lrow[2], lrow[2], lrow[w + 1]);
        }
        for (r, orow) in band.chunks_exact_mut(2 * w).enumerate() {
            // Rows y − 2, y − 1, y, y + 1 of the band's table; texel x is at index x + 2.
            let tt = &lum[r * stride..(r + 1) * stride];
            let t = &lum[(r + 1) * stride..(r + 2) * stride];
            let c = &lum[(r + 2) * stride..(r + 3) * stride];
            let bo = &lum[(r + 3) * stride..(r + 4) * stride];
            // Branch-free over the row into one plane per edge (the compiler vectorises it), then interleaved; the
            // shader's early exit only skips work. max is exact, so its grouping does not change the result.
            let (cl, cc, cr, cll) = (&c[1..w + 1], &c[2..w + 2], &c[3..w + 3], &c[0..w]);
            let (tc, ttc, bc) = (&t[2..w + 2], &tt[2..w + 2], &bo[2..w + 2]);
            for x in 0..w {
                let l = cc[x];
                let (d0, d1) = ((l - cl[x]).abs(), (l - tc[x]).abs());
                let m0 = d0.max((l - cr[x]).abs()).max((cl[x] - cll[x]).abs());
                let m1 = d1.max((l - bc[x]).abs()).max((tc[x] - ttc[x]).abs());
                let final_delta = m0.max(m1);
                // step(THRESHOLD, delta) · step(final_delta, 2·delta); a set edge is stored as unorm8(1.0) = 255.
                let e0 = (d0 >= THRESHOLD) & (LOCAL_CONTRAST_ADAPTATION * d0 >= final_delta);
                let e1 = (d1 >= THRESHOLD) & (LOCAL_CONTRAST_ADAPTATION * d1 >= final_delta);
                planes[0][x] = 0u8.wrapping_sub(e0 as u8);
                planes[1][x] = 0u8.wrapping_sub(e1 as u8);
            }
            for ((o, &e0), &e1) in orow.chunks_exact_mut(2).zip(&planes[0][..w]).zip(&planes[1][..w]) {
                o[0] = e0;
                o[1] = e1;
            }
        }
    });
}

struct Ctx<'a> {
    edges: Tex8<'a>,
    area: Tex8<'a>,
    search: Tex8<'a>,
    rt: [f32; 2],
    prec: FilterPrecision,
    subsample: [f32; 4],
}

impl Ctx<'_> {
    #[inline]
    fn edges_at(&self, px: f32, py: f32) -> [f32; 2] {
        self.edges.sample2(px * self.rt[0], py * self.rt[1], self.prec)
    }

    #[inline]
    fn area_at(&self, tx: f32, ty: f32) -> [f32; 2] {
        self.area.sample2(tx / AREA_TEX_SIZE.0 as f32, ty / AREA_TEX_SIZE.1 as f32, self.prec)
    }

    fn search_diag(&self, px: f32, py: f32, dir: [f32; 2], decode: bool) -> ([f32; 2], [f32; 2]) {
        let mut c = [if decode { px + 0.25 } else { px }, py, -1.0f32, 1.0f32];
        let mut e = [0.0f32; 2];
        while c[2] < MAX_SEARCH_STEPS_DIAG - 1.0 && c[3] > 0.9 {
            c[0] += dir[0];
            c[1] += dir[1];
            c[2] += 1.0;
            e = self.edges_at(c[0], c[1]);
            if decode {
                e = decode_diag(e);
            }
            c[3] = e[0] * 0.5 + e[1] * 0.5;
        }
        ([c[2], c[3]], e)
    }

    /// The area of a diagonal line of lengths `d[0]`, `d[1]` with crossing edges `e`, an end's crossing dropped where
    /// its search stopped on one (`d[2]`, `d[3]` ≥ 0.9).
    fn area_diag(&self, d: [f32; 4], mut e: [f32; 2], offset: f32) -> [f32; 2] {
        for k in 0..2 {
            if d[2 + k] >= 0.9 {
                e[k] = 0.0;
            }
        }
        let tx = AREATEX_MAX_DISTANCE_DIAG * e[0] + d[0] + 0.5 + 80.0;
        let ty = AREATEX_MAX_DISTANCE_DIAG * e[1] + d[1] + 0.5 + AREATEX_SUBTEX_ROWS * offset;
        self.area_at(tx, ty)
    }

    fn diag_weights(&self, px: f32, py: f32, e: [f32; 2]) -> [f32; 2] {
        let mut weights = [0.0f32; 2];
        let mut d = [0.0f32; 4];
        if e[0] > 0.0 {
            let (r, end) = self.search_diag(px, py, [-1.0, 1.0], false);
            d[0] = r[0] + if end[1] > 0.9 { 1.0 } else { 0.0 };
            d[2] = r[1];
        }
        let (r1, _) = self.search_diag(px, py, [1.0, -1.0], false);
        d[1] = r1[0];
        d[3] = r1[1];
        if d[0] + d[1] > 2.0 {
            let c0 = decode_diag(self.edges_at(px - d[0] + 0.25 - 1.0, py + d[0]));
            let c1 = decode_diag(self.edges_at(px + d[1] + 1.0, py - d[1] - 0.25));
            let c = [c0[1], c0[0], c1[1], c1[0]];
            let cc = [2.0 * c[0] + c[1], 2.0 * c[2] + c[3]];
            let a = self.area_diag(d, cc, self.subsample[2]);
            weights = [weights[0] + a[0], weights[1] + a[1]];
        }
        let (r2, _) = self.search_diag(px, py, [-1.0, -1.0], true);
        d[0] = r2[0];
        d[2] = r2[1];
        if self.edges_at(px + 1.0, py)[0] > 0.0 {
            let (r3, end) = self.search_diag(px, py, [1.0, 1.0], true);
            d[1] = r3[0] + if end[1] > 0.9 { 1.0 } else { 0.0 };
            d[3] = r3[1];
        } else {
            d[1] = 0.0;
            d[3] = 0.0;
        }
        if d[0] + d[1] > 2.0 {
            let (q0x, q0y) = (px - d[0], py - d[0]);
            let (q1x, q1y) = (px + d[1], py + d[1]);
            let cx = self.edges_at(q0x - 1.0, q0y)[1];
            let cy = self.edges_at(q0x, q0y - 1.0)[0];
            let c1 = self.edges_at(q1x + 1.0, q1y);
            let (cz, cw) = (c1[1], c1[0]);
            let cc = [2.0 * cx + cy, 2.0 * cz + cw];
            let a = self.area_diag(d, cc, self.subsample[3]);
            weights = [weights[0] + a[1], weights[1] + a[0]];
        }
        weights
    }

    fn search_length(&self, e: [f32; 2], offset: f32) -> f32 {
        let ix = round(32.0 * e[0]) as i32 + if offset > 0.0 { 33 } else { 0 };
        let iy = 32 - round(32.0 * e[1]) as i32;
        self.search.load(ix.clamp(0, SEARCH_TEX_SIZE.0 as i32 - 1), iy.clamp(0, SEARCH_TEX_SIZE.1 as i32 - 1), 0)
    }

    /// Horizontal search; `sign` −1 left, +1 right. Returns the end coordinate.
    fn search_x(&self, sx: f32, sy: f32, end: f32, sign: f32) -> f32 {
        let mut t = sx;
        let mut e = [0.0f32, 1.0];
        while (if sign < 0.0 { t > end } else { t < end }) && e[1] > 0.8281 && e[0] == 0.0 {
            e = self.edges_at(t, sy);
            t += 2.0 * sign;
        }
        let offset = -(255.0f32 / 127.0) * self.search_length(e, if sign < 0.0 { 0.0 } else { 0.5 }) + 3.25;
        t - sign * offset
    }

    /// Vertical search; `sign` −1 up, +1 down.
    fn search_y(&self, sx: f32, sy: f32, end: f32, sign: f32) -> f32 {
        let mut t = sy;
        let mut e = [1.0f32, 0.0];
        while (if sign < 0.0 { t > end } else { t < end }) && e[0] > 0.8281 && e[1] == 0.0 {
            e = self.edges_at(sx, t);
            t += 2.0 * sign;
        }
        let offset = -(255.0f32 / 127.0) * self.search_length([e[1], e[0]], if sign < 0.0 { 0.0 } else { 0.5 }) + 3.25;
        t - sign * offset
    }

    fn area_ortho(&self, d: [f32; 2], e1: f32, e2: f32, offset: f32) -> [f32; 2] {
        let tx = AREATEX_MAX_DISTANCE * round(4.0 * e1) + d[0].sqrt() + 0.5;
        let ty = AREATEX_MAX_DISTANCE * round(4.0 * e2) + d[1].sqrt() + 0.5 + AREATEX_SUBTEX_ROWS * offset;
        self.area_at(tx, ty)
    }

    fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
        let mut weights = [0.0f32; 4];
        let mut e = [self.edges.load(x as i32, y as i32, 0), self.edges.load(x as i32, y as i32, 1)];
        let span = 2.0 * MAX_SEARCH_STEPS;
        if e[1] > 0.0 {
            let dw = self.diag_weights(px, py, e);
            weights[0] = dw[0];
            weights[1] = dw[1];
            if dw[0] == -dw[1] {
                let left = self.search_x(px - 0.25, py - 0.125, px - 0.25 - span, -1.0);
                let y1 = py - 0.25;
                let e1 = self.edges_at(left, y1)[0];
                let right = self.search_x(px + 1.25, py - 0.125, px + 1.25 + span, 1.0);
                let d = [round(left - px).abs(), round(right - px).abs()];
                let e2 = self.edges_at(right + 1.0, y1)[0];
                let mut w = self.area_ortho(d, e1, e2, self.subsample[1]);
                let r = corner_factor(d);
                let mut f = [1.0f32, 1.0];
                f[0] -= r[0] * self.edges_at(left, py + 1.0)[0];
                f[0] -= r[1] * self.edges_at(right + 1.0, py + 1.0)[0];
                f[1] -= r[0] * self.edges_at(left, py - 2.0)[0];
                f[1] -= r[1] * self.edges_at(right + 1.0, py - 2.0)[0];
                w = [w[0] * f[0].clamp(0.0, 1.0), w[1] * f[1].clamp(0.0, 1.0)];
                weights[0] = w[0];
                weights[1] = w[1];
            } else {
                e[0] = 0.0;
            }
        }
        if e[0] > 0.0 {
            let up = self.search_y(px - 0.125, py - 0.25, py - 0.25 - span, -1.0);
            let x1 = px - 0.25;
            let e1 = self.edges_at(x1, up)[1];
            let down = self.search_y(px - 0.125, py + 1.25, py + 1.25 + span, 1.0);
            let d = [round(up - py).abs(), round(down - py).abs()];
            let e2 = self.edges_at(x1, down + 1.0)[1];
            let mut w = self.area_ortho(d, e1, e2, self.subsample[0]);
            let r = corner_factor(d);
            let mut f = [1.0f32, 1.0];
            f[0] -= r[0] * self.edges_at(px + 1.0, up)[1];
            f[0] -= r[1] * self.edges_at(px + 1.0, down + 1.0)[1];
            f[1] -= r[0] * self.edges_at(px - 2.0, up)[1];
            f[1] -= r[1] * self.edges_at(px - 2.0, down + 1.0)[1];
            w = [w[0] * f[0].clamp(0.0, 1.0), w[1] * f[1].clamp(0.0, 1.0)];
            weights[2] = w[0];
            weights[3] = w[1];
        }
        weights
    }
}

fn decode_diag(e: [f32; 2]) -> [f32; 2] {
    [round(e[0] * (5.0 * e[0] - 5.0 * 0.75).abs()), round(e[1])]
}

fn corner_factor(d: [f32; 2]) -> [f32; 2] {
    let lr = [if d[1] >= d[0] { 1.0f32 } else { 0.0 }, if d[0] >= d[1] { 1.0f32 } else { 0.0 }];
    let s = lr[0] + lr[1];
    [(1.0 - CORNER_ROUNDING_NORM) * lr[0] / s, (1.0 - CORNER_ROUNDING_NORM) * lr[1] / s]
}

/// Pass 2: blending weights (RGBA8) from the edges (RG8), SMAA 1x.
pub fn blending_weights(edges: &Tex8, luts: &SmaaTextures, prec: FilterPrecision) -> Vec<u8> {
    blending_weights_with_subsample(edges, luts, prec, SubsampleIndices::SMAA_1X)
}

/// Pass 2 with explicit area-texture slices.
pub fn blending_weights_with_subsample(
    edges: &Tex8,
    luts: &SmaaTextures,
    prec: FilterPrecision,
    subsample: SubsampleIndices,
) -> Vec<u8> {
    let mut out = vec![0u8; (edges.w * edges.h * 4) as usize];
    blending_weights_into(edges, luts, prec, subsample, &mut out);
    out
}

/// [`blending_weights_with_subsample`] into `out` (`w·h·4` bytes; every byte is written).
pub fn blending_weights_into(
    edges: &Tex8,
    luts: &SmaaTextures,
    prec: FilterPrecision,
    subsample: SubsampleIndices,
    out: &mut [u8],
) {
    let (w, h) = (edges.w, edges.h);
    assert_eq!(out.len(), (w * h * 4) as usize, "weight buffer size");
    if out.is_empty() {
        return;
    }
    let ctx = Ctx {
        edges: *edges,
        area: Tex8::new(AREA_TEX_SIZE.0, AREA_TEX_SIZE.1, 2, &luts.area),
        search: Tex8::new(SEARCH_TEX_SIZE.0, SEARCH_TEX_SIZE.1, 1, &luts.search),
        rt: [1.0 / w as f32, 1.0 / h as f32],
        prec,
        subsample: subsample.as_f32(),
    };
    out.par_chunks_mut((w * 4) as usize).enumerate().for_each(|(y, row)| {
        row.fill(0);
        let erow = &edges.data[y * w as usize * 2..(y + 1) * w as usize * 2];
        // No edge, no weights: skip the (mostly zero) edge row eight bytes, four texels, at a time.
        let mut words = erow.chunks_exact(8);
        let mut x0 = 0usize;
        for word in words.by_ref() {
            if u64::from_ne_bytes(word.try_into().unwrap()) != 0 {
                blend_weights_of(&ctx, erow, row, x0..x0 + 4, y as u32);
            }
            x0 += 4;
        }
        blend_weights_of(&ctx, erow, row, x0..w as usize, y as u32);
    });
}

/// Weights of the texels `xs` of row `y` that have an edge, stored in that row of the output.
#[inline]
fn blend_weights_of(ctx: &Ctx, erow: &[u8], row: &mut [u8], xs: std::ops::Range<usize>, y: u32) {
    for x in xs {
        if erow[x * 2] == 0 && erow[x * 2 + 1] == 0 {
            continue; // no edge: all weights are zero
        }
        let wgt = ctx.pixel(x as u32, y);
        for c in 0..4 {
            row[x * 4 + c] = unorm8(wgt[c]);
        }
    }
}

/// Pass 3: neighbourhood blending in linear light; output RGBA8 sRGB-encoded.
///
/// A texel whose four blending weights (its own R and B, the right neighbour's A, the lower neighbour's G) are
/// all zero keeps its input bytes (their sum is below the shader's 1e-5 exactly when every byte is 0), so the
/// output starts as a copy of the input and only texels next to an edge are blended, found eight at a time.
pub fn neighbourhood_blending(color: &Tex8, weights: &Tex8) -> Vec<u8> {
    let mut out = vec![0u8; color.w as usize * color.h as usize * 4];
    neighbourhood_blending_into(color, weights, &mut out);
    out
}

/// [`neighbourhood_blending`] into `out` (`w·h·4` bytes; every byte is written).
pub fn neighbourhood_blending_into(color: &Tex8, weights: &Tex8, out: &mut [u8]) {
    let (w, h) = (color.w as usize, color.h as usize);
    assert_eq!(out.len(), w * h * 4, "output buffer size");
    assert_eq!((weights.w as usize, weights.h as usize, weights.ch, color.ch), (w, h, 4, 4), "texture sizes");
    // srgb_to_linear of every 8-bit value, once per pass (the same function of the same texel values).
    let to_linear: [f32; 256] = std::array::from_fn(|v| srgb_to_linear(UNORM8_F32[v]));
    let color_lin = |x: i32, y: i32| {
        let x = x.clamp(0, w as i32 - 1) as usize;
        let y = y.clamp(0, h as i32 - 1) as usize;
        let c = &color.data[(y * w + x) * 4..(y * w + x) * 4 + 4];
        [to_linear[c[0] as usize], to_linear[c[1] as usize], to_linear[c[2] as usize], UNORM8_F32[c[3] as usize]]
    };
    if out.is_empty() {
        return;
    }
    out.par_chunks_mut(w * 4).enumerate().for_each(|(y, row)| {
        row.copy_from_slice(&color.data[y * w * 4..(y + 1) * w * 4]);
        let wrow = &weights.data[y * w * 4..(y + 1) * w * 4];
        let yb = (y + 1).min(h - 1);
        let wbelow = &weights.data[yb * w * 4..(yb + 1) * w * 4];
        let zero = |s: &[u8]| s.iter().fold(0u8, |a, &b| a | b) == 0;
        let zero32 = |s: &[u8]| <&[u8; 32]>::try_from(s).unwrap().iter().fold(0u8, |a, &b| a | b) == 0;
        for x0 in (0..w).step_by(8) {
            let x1 = (x0 + 8).min(w);
            // Bytes any texel of x0..x1 reads: this row's up to texel x1 (its A), the row below's.
            let quiet = if x1 == x0 + 8 {
                zero32(&wrow[x0 * 4..x1 * 4]) && zero32(&wbelow[x0 * 4..x1 * 4]) && (x1 == w || wrow[x1 * 4 + 3] == 0)
            } else {
                zero(&wrow[x0 * 4..w * 4]) && zero(&wbelow[x0 * 4..w * 4])
            };
            if quiet {
                continue;
            }
            for x in x0..x1 {
                let wx = x * 4;
                let right = (x + 1).min(w - 1) * 4 + 3;
                if wrow[right] == 0 && wbelow[wx + 1] == 0 && wrow[wx + 2] == 0 && wrow[wx] == 0 {
                    continue;
                }
                let (xi, yi) = (x as i32, y as i32);
                let a = [
                    weights.load(xi + 1, yi, 3),
                    weights.load(xi, yi + 1, 1),
                    weights.load(xi, yi, 2),
                    weights.load(xi, yi, 0),
                ];
                let c = color_lin(xi, yi);
                let horizontal = a[0].max(a[2]) > a[1].max(a[3]);
                let (wt, n0, n1) = if horizontal {
                    ([a[0], a[2]], color_lin(xi + 1, yi), color_lin(xi - 1, yi))
                } else {
                    ([a[1], a[3]], color_lin(xi, yi + 1), color_lin(xi, yi - 1))
                };
                let s = wt[0] + wt[1];
                let wn = [wt[0] / s, wt[1] / s];
                for k in 0..4 {
                    let m0 = c[k] + (n0[k] - c[k]) * wt[0];
                    let m1 = c[k] + (n1[k] - c[k]) * wt[1];
                    let v = wn[0] * m0 + wn[1] * m1;
                    row[wx + k] = unorm8(if k < 3 { linear_to_srgb(v) } else { v });
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifest::sha256_hex;
    use crate::runtime::aa::scene::render_shapes;

    fn luts() -> SmaaTextures {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("baked");
        crate::runtime::loader::load_smaa_textures(&dir).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Blocks of pseudo-random colour (sizes 1–5 px) with sparse single-pixel noise: edges of every
    /// orientation, diagonal staircases, edges at the image border and isolated texels.
    fn blocks(w: u32, h: u32, seed: u64) -> Vec<u8> {
        let mut s = seed;
        let mut next = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 33) as u32
        };
        let palette: Vec<[u8; 3]> = (0..6).map(|_| [next() as u8, next() as u8, next() as u8]).collect();
        let (bw, bh) = (1 + next() % 5, 1 + next() % 5);
        let cells: Vec<usize> = (0..(w / bw + 1) * (h / bh + 1)).map(|_| (next() % 6) as usize).collect();
        let mut out = vec![255u8; (w * h * 4) as usize];
        for y in 0..h {
            for x in 0..w {
                let mut c = palette[cells[((y / bh) * (w / bw + 1) + x / bw) as usize]];
                if next() % 17 == 0 {
                    c = [next() as u8, next() as u8, next() as u8];
                }
                let i = ((y * w + x) * 4) as usize;
                out[i..i + 3].copy_from_slice(&c);
            }
        }
        out
    }

    fn digest(o: &SmaaCpuOutput) -> String {
        format!("{} {} {}", &sha256_hex(&o.edges)[..16], &sha256_hex(&o.weights)[..16], &sha256_hex(&o.output)[..16])
    }

    /// The CPU twin is the GPU pass' reference: its bytes are pinned (edges, weights, output) on the procedural
    /// scene at 1080p (both filter-precision models, 1x and one 4x slice set) and on random block images of odd
    /// sizes, so a faster implementation cannot change a byte. Digests computed with the straightforward
    /// per-texel implementation (rtbake 8582a9a).
    #[test]
    fn smaa_cpu_bytes_are_pinned() {
        let luts = luts();
        let mut got = Vec::new();
        let img = render_shapes(1920, 1080, 1);
        got.push(digest(&smaa(&img, 1920, 1080, &luts, FilterPrecision::Exact)));
        got.push(digest(&smaa(&img, 1920, 1080, &luts, FilterPrecision::Unorm8)));
        let s = SubsampleIndices::SMAA_4X[1];
        got.push(digest(&smaa_with_subsample(&img, 1920, 1080, &luts, FilterPrecision::Exact, s)));
        for (w, h, seed) in [(131u32, 77u32, 1u64), (64, 1, 2), (1, 50, 3), (257, 129, 4), (300, 200, 5)] {
            let img = blocks(w, h, seed);
            got.push(digest(&smaa(&img, w, h, &luts, FilterPrecision::Exact)));
            got.push(digest(&smaa(&img, w, h, &luts, FilterPrecision::Unorm8)));
        }
        // The reusing entry point gives the same bytes, also into buffers of another size and content.
        let mut reused = smaa(&blocks(300, 200, 9), 300, 200, &luts, FilterPrecision::Exact);
        for (w, h, seed) in [(131u32, 77u32, 1u64), (300, 200, 5)] {
            let img = blocks(w, h, seed);
            smaa_into(&img, w, h, &luts, FilterPrecision::Unorm8, SubsampleIndices::SMAA_1X, &mut reused);
            assert_eq!(digest(&reused), digest(&smaa(&img, w, h, &luts, FilterPrecision::Unorm8)), "{w}x{h}");
        }
        let want = [
            "9c60cb7d5f0b648a 9c2269e7d6522968 9c85caf4f6f2dd1c",
            "9c60cb7d5f0b648a 45e800a8a42441f9 9ceb3e987dac90ca",
            "9c60cb7d5f0b648a b39f37d76131e0af daf083e9dd5930de",
            "f1ce57e563bac39f 98404b72142a8bf3 e3ec6c9cbe8cbe3a",
            "f1ce57e563bac39f ecd91d891171d995 caf1e9790aa64c89",
            "464293f4d76270ee 5341e6b2646979a7 b317eb6f91cea9af",
            "464293f4d76270ee 5341e6b2646979a7 b317eb6f91cea9af",
            "f5d6c615338bc967 6d9c54dee5660c46 c89a862cd48d6651",
            "f5d6c615338bc967 6d9c54dee5660c46 c89a862cd48d6651",
            "e17ecef60f12243a 9d631b98f6b45308 63c3b0da32742251",
            "e17ecef60f12243a 16219f835b547026 6bf7d3d8a711872b",
            "58515544228b9611 9fecddf279cc44df c32f924a55ad1083",
            "58515544228b9611 f559fc10f825a238 f6f8b9ad91ecae85",
        ];
        assert_eq!(got, want);
    }
}
