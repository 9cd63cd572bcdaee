//! Procedural test scenes (no input files): flat-shaded rotated polygons and discs with hard edges, rendered
//! either aliased (one sample at each pixel centre) or supersampled (n×n samples averaged in linear light) as a
//! ground truth for antialiasing quality checks.

use rayon::prelude::*;

/// A filled convex polygon or disc with a linear RGB colour.
#[derive(Clone, Debug)]
enum Shape {
    /// Convex polygon, counter-clockwise vertices in pixel units.
    Polygon(Vec<[f64; 2]>),
    /// Centre and radius in pixel units.
    Disc([f64; 2], f64),
}

impl Shape {
    fn contains(&self, x: f64, y: f64) -> bool {
        match self {
            Shape::Polygon(v) => (0..v.len()).all(|i| {
                let (a, b) = (v[i], v[(i + 1) % v.len()]);
                (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]) >= 0.0
            }),
            Shape::Disc(c, r) => (x - c[0]).powi(2) + (y - c[1]).powi(2) <= r * r,
        }
    }
}

fn regular_polygon(cx: f64, cy: f64, r: f64, n: usize, rot: f64) -> Shape {
    // Counter-clockwise in a y-down frame means decreasing angle; the orientation test above expects the
    // vertices ordered so that the interior is on the left in (x right, y down) coordinates.
    Shape::Polygon(
        (0..n)
            .map(|i| {
                let a = rot + i as f64 * std::f64::consts::TAU / n as f64;
                [cx + r * a.cos(), cy + r * a.sin()]
            })
            .collect(),
    )
}

/// The "shapes" test scene for a `w × h` frame: background, rotated square, triangle, hexagon, discs, thin bar.
fn shapes(w: u32, h: u32) -> Vec<(Shape, [f64; 3])> {
    let s = w.min(h) as f64;
    let (fw, fh) = (w as f64, h as f64);
    vec![
        (regular_polygon(0.30 * fw, 0.35 * fh, 0.22 * s, 4, 0.31), [0.85, 0.25, 0.10]),
        (regular_polygon(0.70 * fw, 0.30 * fh, 0.20 * s, 3, 0.12), [0.10, 0.60, 0.90]),
        (regular_polygon(0.68 * fw, 0.72 * fh, 0.18 * s, 6, 0.05), [0.95, 0.90, 0.20]),
        (Shape::Disc([0.30 * fw, 0.75 * fh], 0.16 * s), [0.90, 0.90, 0.90]),
        (Shape::Disc([0.50 * fw, 0.50 * fh], 0.07 * s), [0.05, 0.05, 0.05]),
        (
            Shape::Polygon(vec![
                [0.05 * fw, 0.92 * fh],
                [0.95 * fw, 0.86 * fh],
                [0.95 * fw, 0.86 * fh + 0.02 * s],
                [0.05 * fw, 0.92 * fh + 0.02 * s],
            ]),
            [0.20, 0.80, 0.30],
        ),
    ]
}

const BACKGROUND: [f64; 3] = [0.04, 0.05, 0.08];

fn shade(scene: &[(Shape, [f64; 3])], x: f64, y: f64) -> [f64; 3] {
    let mut c = BACKGROUND;
    for (shape, col) in scene {
        if shape.contains(x, y) {
            c = *col;
        }
    }
    c
}

/// Renders the shapes scene as RGBA8 (sRGB-encoded, alpha 255) with `n × n` samples per pixel (n = 1: aliased,
/// one sample at the pixel centre; n > 1: regular grid, averaged in linear light).
pub fn render_shapes(w: u32, h: u32, n: u32) -> Vec<u8> {
    let scene = shapes(w, h);
    encode_rows(w, h, |x, y| {
        let acc = grid_sum(x, y, n, |sx, sy| shade(&scene, sx, sy));
        let inv = 1.0 / (n * n) as f64;
        acc.map(|a| a * inv)
    })
}

/// RGBA8 (sRGB-encoded, alpha 255) of the linear colour `pixel(x, y)` of every pixel, rows in parallel.
fn encode_rows(w: u32, h: u32, pixel: impl Fn(usize, usize) -> [f64; 3] + Sync) -> Vec<u8> {
    use crate::runtime::sampler::{linear_to_srgb, unorm8};
    let mut out = vec![0u8; (w * h * 4) as usize];
    out.par_chunks_mut((w * 4) as usize).enumerate().for_each(|(y, row)| {
        for x in 0..w as usize {
            let c = pixel(x, y);
            for k in 0..3 {
                row[x * 4 + k] = unorm8(linear_to_srgb(c[k] as f32));
            }
            row[x * 4 + 3] = 255;
        }
    });
    out
}

/// The sum of `shade(sx, sy)` over the regular `n × n` grid of sample positions of pixel (x, y).
fn grid_sum(x: usize, y: usize, n: u32, shade: impl Fn(f64, f64) -> [f64; 3]) -> [f64; 3] {
    let mut acc = [0.0f64; 3];
    for j in 0..n {
        for i in 0..n {
            let sx = x as f64 + (i as f64 + 0.5) / n as f64;
            let sy = y as f64 + (j as f64 + 0.5) / n as f64;
            let c = shade(sx, sy);
            for k in 0..3 {
                acc[k] += c[k];
            }
        }
    }
    acc
}

/// The shapes scene with one sample per pixel at `offset` (pixel units from its top-left corner, each in 0..1):
/// one sample image of an MSAA render (e.g. the standard 4× pattern), RGBA8 sRGB-encoded.
pub fn render_shapes_at(w: u32, h: u32, offset: [f64; 2]) -> Vec<u8> {
    let scene = shapes(w, h);
    encode_rows(w, h, |x, y| shade(&scene, x as f64 + offset[0], y as f64 + offset[1]))
}

/// The shapes scene with other colours: shape `i` gets `colours[i % colours.len()]`, the background `background`
/// (linear RGB); `n` as in [`render_shapes`]. For scenes whose edges luma cannot see (equal-luma colours).
pub fn render_shapes_recoloured(w: u32, h: u32, n: u32, colours: &[[f64; 3]], background: [f64; 3]) -> Vec<u8> {
    assert!(!colours.is_empty(), "at least one colour");
    let scene: Vec<_> =
        shapes(w, h).into_iter().enumerate().map(|(i, (s, _))| (s, colours[i % colours.len()])).collect();
    encode_rows(w, h, |x, y| {
        let acc = grid_sum(x, y, n, |sx, sy| {
            let mut c = background;
            for (shape, col) in &scene {
                if shape.contains(sx, sy) {
                    c = *col;
                }
            }
            c
        });
        acc.map(|a| a / (n * n) as f64)
    })
}

/// Linear depth of the shapes scene at each pixel centre (what an aliased depth buffer holds): shape `i` (drawn
/// later = nearer) at 10 − i units, tilted by 0.0004 units per pixel in x (below any depth threshold between
/// neighbours), the background at 100.
pub fn render_shapes_depth(w: u32, h: u32) -> Vec<f32> {
    let scene = shapes(w, h);
    let mut out = vec![0.0f32; (w * h) as usize];
    out.par_chunks_mut(w as usize).enumerate().for_each(|(y, row)| {
        for (x, d) in row.iter_mut().enumerate() {
            let (sx, sy) = (x as f64 + 0.5, y as f64 + 0.5);
            let mut depth = 100.0;
            for (i, (shape, _)) in scene.iter().enumerate() {
                if shape.contains(sx, sy) {
                    depth = 10.0 - i as f64 + 0.0004 * sx;
                }
            }
            *d = depth as f32;
        }
    });
    out
}
