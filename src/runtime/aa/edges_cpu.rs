//! CPU twin of `aa/edges.wgsl`: colour and depth edge detection, predicated thresholding and the
//! matte/stencil composite shared by SMAA and MLAA (models and sources in [`crate::runtime::aa::edges`]).
//! Same f32 expressions in the same order as the shader; loads clamp to the edge.

use crate::runtime::aa::edges::{EdgeDetector, EdgeSettings, COLOR_THRESHOLD};
use crate::runtime::sampler::Tex8;
use rayon::prelude::*;

const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

#[inline]
fn step(edge: f32, x: f32) -> f32 {
    if x >= edge {
        1.0
    } else {
        0.0
    }
}

/// Edges (RG8: R left, G top, 0 or 255) of `color` by the detector of `settings`; `depth` (`w·h` values) when
/// the settings need it, `lca` the local contrast adaptation factor (SMAA 2.0, MLAA 0 = none).
///
/// # Panics
/// When `settings` need a depth image and `depth` is `None` or of another size (callers validate first with
/// [`crate::runtime::aa::edges::AaInputs::validate`]).
pub fn edge_detection(color: &Tex8, depth: Option<&[f32]>, settings: &EdgeSettings, lca: f32) -> Vec<u8> {
    let (w, h) = (color.w as usize, color.h as usize);
    let depth = settings.needs_depth().then(|| {
        let d = depth.expect("these edge settings need a depth image");
        assert_eq!(d.len(), w * h, "depth size");
        d
    });
    let depth_at =
        |d: &[f32], x: i32, y: i32| d[y.clamp(0, h as i32 - 1) as usize * w + x.clamp(0, w as i32 - 1) as usize];
    // Every pixel's encoded colour (the value a load returns, `byte / 255`) or its luma once, as the luma pass does.
    let colour_metric = settings.detector == EdgeDetector::Color;
    let n = if settings.detector == EdgeDetector::Depth { 0 } else { w * h };
    let mut px = vec![[0.0f32; 3]; n];
    px.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, p) in row.iter_mut().enumerate() {
            let c = &color.data[(y * w + x) * color.ch as usize..][..3];
            let v = [c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0];
            *p = if colour_metric { v } else { [v[0] * LUMA[0] + v[1] * LUMA[1] + v[2] * LUMA[2], 0.0, 0.0] };
        }
    });
    let rgb = |x: i32, y: i32| px[y.clamp(0, h as i32 - 1) as usize * w + x.clamp(0, w as i32 - 1) as usize];
    let contrast = |a: [f32; 3], b: [f32; 3]| {
        if colour_metric {
            let t = [(a[0] - b[0]).abs(), (a[1] - b[1]).abs(), (a[2] - b[2]).abs()];
            t[0].max(t[1]).max(t[2])
        } else {
            (a[0] - b[0]).abs()
        }
    };
    let mut out = vec![0u8; w * h * 2];
    out.par_chunks_mut(w * 2).enumerate().for_each(|(y, row)| {
        let y = y as i32;
        for x in 0..w as i32 {
            let edges = match (settings.detector, depth) {
                (EdgeDetector::Depth, Some(d)) => {
                    // Listing 9.1.
                    let c = depth_at(d, x, y);
                    let delta = [(c - depth_at(d, x - 1, y)).abs(), (c - depth_at(d, x, y - 1)).abs()];
                    [step(settings.depth_threshold, delta[0]), step(settings.depth_threshold, delta[1])]
                }
                _ => {
                    let threshold = match (settings.predication, depth) {
                        (Some(p), Some(d)) => {
                            let c = depth_at(d, x, y);
                            let dd = [(c - depth_at(d, x - 1, y)).abs(), (c - depth_at(d, x, y - 1)).abs()];
                            let e = [step(p.threshold, dd[0]), step(p.threshold, dd[1])];
                            let s = p.scale * COLOR_THRESHOLD;
                            [s * (1.0 - p.strength * e[0]), s * (1.0 - p.strength * e[1])]
                        }
                        _ => [COLOR_THRESHOLD; 2],
                    };
                    color_edges(&rgb, &contrast, x, y, threshold, lca)
                }
            };
            row[x as usize * 2] = crate::runtime::sampler::unorm8(edges[0]);
            row[x as usize * 2 + 1] = crate::runtime::sampler::unorm8(edges[1]);
        }
    });
    out
}

/// `color_edges` of the shader: threshold, then eq. 10.1's local contrast adaptation when `lca > 0`.
fn color_edges(
    rgb: &impl Fn(i32, i32) -> [f32; 3],
    contrast: &impl Fn([f32; 3], [f32; 3]) -> f32,
    x: i32,
    y: i32,
    threshold: [f32; 2],
    lca: f32,
) -> [f32; 2] {
    let c = rgb(x, y);
    let (c_left, c_top) = (rgb(x - 1, y), rgb(x, y - 1));
    let delta = [contrast(c, c_left), contrast(c, c_top)];
    let mut edges = [step(threshold[0], delta[0]), step(threshold[1], delta[1])];
    if edges[0] + edges[1] == 0.0 || lca <= 0.0 {
        return edges;
    }
    let (c_right, c_bottom) = (rgb(x + 1, y), rgb(x, y + 1));
    let mut max_delta = [delta[0].max(contrast(c, c_right)), delta[1].max(contrast(c, c_bottom))];
    let (c_leftleft, c_toptop) = (rgb(x - 2, y), rgb(x, y - 2));
    max_delta = [max_delta[0].max(contrast(c_left, c_leftleft)), max_delta[1].max(contrast(c_top, c_toptop))];
    let final_delta = max_delta[0].max(max_delta[1]);
    edges[0] *= step(final_delta, lca * delta[0]);
    edges[1] *= step(final_delta, lca * delta[1]);
    edges
}

/// Matte / stencil composite (`fs_mask`): RGBA8 `aa` where `mask ≥ 128`, else `color` unchanged.
pub fn apply_mask(color: &[u8], aa: &[u8], mask: &[u8]) -> Vec<u8> {
    assert!(color.len() == aa.len() && color.len() == mask.len() * 4, "mask composite sizes");
    let mut out = aa.to_vec();
    for ((o, c), m) in out.chunks_mut(4).zip(color.chunks(4)).zip(mask) {
        if *m < 128 {
            o.copy_from_slice(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::aa::edges::Predication;

    fn settings(detector: EdgeDetector, predication: Option<Predication>) -> EdgeSettings {
        EdgeSettings { detector, predication, ..Default::default() }
    }

    /// Two colours of equal luma side by side: luma sees no edge, colour does, at the boundary only.
    #[test]
    fn colour_finds_the_isoluminant_edge_luma_misses() {
        // (230, 105, 51) and (128, 128, 128): luma of the encoded values 0.497 vs 0.502, max channel delta 0.4.
        let (w, h) = (8u32, 4u32);
        let mut img = vec![0u8; (w * h * 4) as usize];
        for (i, p) in img.chunks_mut(4).enumerate() {
            let left = (i as u32 % w) < 4;
            p.copy_from_slice(if left { &[230, 105, 51, 255] } else { &[128, 128, 128, 255] });
        }
        let t = Tex8::new(w, h, 4, &img);
        let luma = edge_detection(&t, None, &settings(EdgeDetector::Luma, None), 2.0);
        let colour = edge_detection(&t, None, &settings(EdgeDetector::Color, None), 2.0);
        assert!(luma.iter().all(|e| *e == 0));
        for y in 0..h as usize {
            for x in 0..w as usize {
                let i = (y * w as usize + x) * 2;
                assert_eq!(colour[i], if x == 4 { 255 } else { 0 }, "left edge at ({x}, {y})");
                assert_eq!(colour[i + 1], 0, "top edge at ({x}, {y})");
            }
        }
    }

    /// Predication: a luma step of 0.15 (above T = 0.1, below 2·T = 0.2) is an edge only where the depth also
    /// steps (threshold 2·0.1·(1 − 0.4) = 0.12 there).
    #[test]
    fn predication_keeps_a_weak_edge_only_on_a_depth_edge() {
        let (w, h) = (4u32, 2u32);
        let mut img = vec![255u8; (w * h * 4) as usize];
        for (i, p) in img.chunks_mut(4).enumerate() {
            let v = if (i as u32 % w) < 2 { 100 } else { 138 }; // 38/255 = 0.149 of luma
            p[..3].copy_from_slice(&[v, v, v]);
        }
        // Depth steps at x = 2 in the top row only.
        let depth: Vec<f32> = (0..w * h).map(|i| if i < w && i % w >= 2 { 2.0 } else { 1.0 }).collect();
        let t = Tex8::new(w, h, 4, &img);
        let e = edge_detection(&t, Some(&depth), &settings(EdgeDetector::Luma, Some(Predication::SMAA)), 2.0);
        assert_eq!(e[2 * 2], 255, "top row: luma and depth edge");
        assert_eq!(e[(w as usize + 2) * 2], 0, "bottom row: luma edge only, threshold raised to 0.2");
        let plain = edge_detection(&t, None, &settings(EdgeDetector::Luma, None), 2.0);
        assert_eq!(plain[(w as usize + 2) * 2], 255, "without predication T = 0.1 finds it");
    }

    /// Listing 9.1: depth steps above the threshold are edges whatever the colour.
    #[test]
    fn depth_edges_ignore_colour() {
        let (w, h) = (3u32, 3u32);
        let img = vec![128u8; (w * h * 4) as usize];
        let depth: Vec<f32> = (0..w * h).map(|i| if i / w == 2 { 5.0 } else { 5.02 }).collect();
        let s = EdgeSettings { detector: EdgeDetector::Depth, depth_threshold: 0.01, predication: None };
        let e = edge_detection(&Tex8::new(w, h, 4, &img), Some(&depth), &s, 0.0);
        for i in 0..(w * h) as usize {
            assert_eq!(e[2 * i], 0);
            assert_eq!(e[2 * i + 1], if i / w as usize == 2 { 255 } else { 0 }, "pixel {i}");
        }
    }

    #[test]
    fn mask_passes_outside_pixels_through() {
        let color = [1u8, 2, 3, 4, 5, 6, 7, 8];
        let aa = [9u8, 9, 9, 9, 9, 9, 9, 9];
        assert_eq!(apply_mask(&color, &aa, &[127, 128]), [1, 2, 3, 4, 9, 9, 9, 9]);
    }
}
