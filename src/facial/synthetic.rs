//! Procedural test data for the facial maps. The captured maps of the thesis (ch. 7, Fig. 7.4) are not public,
//! so the project generates realistic stand-ins:
//!
//! - a **neutral hemoglobin map** Hn: low-frequency perfusion (value-noise fBm) plus capillary-like detail —
//!   fine value noise and thin vessel-like ridges (ridged noise `(1 − |2n − 1|)^k`), with more blood over the
//!   cheek bones and the nose, in dermal volume fractions (typ. 0.03–0.15, Table 7.1 range 0–0.32);
//! - **expression / global-state targets** `Hi = base·p_i(u, v) + detail·c_i(u, v)` that raise or lower perfusion
//!   in smooth regional masks (forehead, cheeks, nose, chin) and change the local contrast of the capillary
//!   detail, loosely following the thesis observations (§7.3.1: more blood over the cheek bones when smiling,
//!   pallor in fear, flush in anger, different spatial patterns after exercise and alcohol);
//! - a **wrinkle height field** (forehead lines, crow's feet, frown lines, nasolabial folds) turned into a normal
//!   map, and the 8 zone masks of thesis Table 8.1.
//!
//! Only `+ − × ÷`, `floor` and `sqrt` are used (no libm transcendental functions), so the outputs are
//! bit-identical on every platform; committed fixtures are regenerated and compared by a test.
//! Coordinates are in UV units (texel centres at `(x + 0.5)/width`), so a map looks the same at any resolution.

use crate::image_buf::Image;

fn hash(ix: i64, iy: i64, seed: u32) -> u32 {
    // lowbias32 (C. Wellons) over a combination of the lattice point and the seed.
    let mut x =
        (ix as u32).wrapping_mul(0x8da6_b343) ^ (iy as u32).wrapping_mul(0xd816_3841) ^ seed.wrapping_mul(0xcb1a_b31f);
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

fn lattice(ix: i64, iy: i64, seed: u32) -> f64 {
    (hash(ix, iy, seed) >> 8) as f64 / (1u32 << 24) as f64
}

fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Value noise in [0, 1) at lattice coordinates (px, py).
pub fn value_noise(px: f64, py: f64, seed: u32) -> f64 {
    let (x0, y0) = (px.floor(), py.floor());
    let (fx, fy) = (fade(px - x0), fade(py - y0));
    let (ix, iy) = (x0 as i64, y0 as i64);
    let a = lattice(ix, iy, seed);
    let b = lattice(ix + 1, iy, seed);
    let c = lattice(ix, iy + 1, seed);
    let d = lattice(ix + 1, iy + 1, seed);
    let top = a + (b - a) * fx;
    let bot = c + (d - c) * fx;
    top + (bot - top) * fy
}

/// Fractal sum of `octaves` value-noise octaves starting at `freq` cycles per UV unit, normalised to [0, 1).
pub fn fbm(u: f64, v: f64, freq: f64, octaves: u32, seed: u32) -> f64 {
    let (mut sum, mut amp, mut norm, mut f) = (0.0, 1.0, 0.0, freq);
    for o in 0..octaves {
        sum += amp * value_noise(u * f, v * f, seed.wrapping_add(o.wrapping_mul(1013)));
        norm += amp;
        amp *= 0.5;
        f *= 2.0;
    }
    sum / norm
}

fn pow_int(mut b: f64, mut e: u32) -> f64 {
    let mut r = 1.0;
    while e > 0 {
        if e & 1 == 1 {
            r *= b;
        }
        b *= b;
        e >>= 1;
    }
    r
}

/// Thin ridges where the noise crosses 0.5: `(1 − |2n − 1|)^sharpness`.
fn ridges(u: f64, v: f64, freq: f64, sharpness: u32, seed: u32) -> f64 {
    // Domain warp and a rotated lattice hide the axis-aligned structure of value noise.
    let wu = u + 0.6 / freq * (fbm(u, v, freq * 0.5, 2, seed ^ 0x2545_f491) - 0.5) * 4.0;
    let wv = v + 0.6 / freq * (fbm(u, v, freq * 0.5, 2, seed ^ 0x9e37_79b9) - 0.5) * 4.0;
    let (c, s) = (0.825_335_614_909_678_3, 0.564_642_473_395_035_4); // cos, sin of 0.6 rad
    let (ru, rv) = (c * wu - s * wv, s * wu + c * wv);
    let n = value_noise(ru * freq, rv * freq, seed);
    pow_int(1.0 - (2.0 * n - 1.0).abs(), sharpness)
}

/// Smooth elliptical mask: `(1 − d²)³` inside the ellipse, 0 outside (C² continuous).
pub fn ellipse_mask(u: f64, v: f64, cu: f64, cv: f64, ru: f64, rv: f64) -> f64 {
    let (du, dv) = ((u - cu) / ru, (v - cv) / rv);
    let d2 = du * du + dv * dv;
    if d2 >= 1.0 {
        0.0
    } else {
        let t = 1.0 - d2;
        t * t * t
    }
}

/// Facial regions of the synthetic UV layout (front view: u to the right, v down).
pub const REGIONS: [&str; 5] = ["forehead", "cheeks", "nose", "chin", "global"];

fn region_masks(u: f64, v: f64) -> [f64; 4] {
    let forehead = ellipse_mask(u, v, 0.5, 0.18, 0.32, 0.12);
    let cheeks = ellipse_mask(u, v, 0.27, 0.58, 0.14, 0.12) + ellipse_mask(u, v, 0.73, 0.58, 0.14, 0.12);
    let nose = ellipse_mask(u, v, 0.5, 0.5, 0.07, 0.17);
    let chin = ellipse_mask(u, v, 0.5, 0.88, 0.13, 0.08);
    [forehead, cheeks, nose, chin]
}

/// A target state: relative perfusion change and local-contrast change, globally and per region
/// (forehead, cheeks, nose, chin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Expression {
    pub name: &'static str,
    pub perfusion_global: f64,
    pub perfusion: [f64; 4],
    pub contrast_global: f64,
    pub contrast: [f64; 4],
}

/// Eight illustrative targets: six basic emotions and two global states (thesis §7.3: exercise, alcohol).
/// Columns: name; perfusion change, global and per region (forehead, cheeks, nose, chin); local-contrast change,
/// global and per region.
#[rustfmt::skip]
pub const EXPRESSIONS: [Expression; 8] = [
    row("joy",       0.0,   [0.0, 0.35, 0.10, 0.0],     0.0,   [0.0, 0.2, 0.0, 0.0]),
    row("anger",     0.10,  [0.30, 0.25, 0.20, 0.10],   0.10,  [0.2, 0.0, 0.0, 0.0]),
    row("fear",      -0.20, [-0.10, -0.15, -0.10, 0.0], -0.25, [0.0; 4]),
    row("disgust",   0.0,   [-0.10, 0.0, 0.30, 0.05],   0.0,   [0.0, 0.0, 0.3, 0.0]),
    row("sadness",   -0.05, [0.0, -0.05, 0.15, 0.20],   -0.10, [0.0; 4]),
    row("surprise",  0.0,   [-0.20, 0.05, 0.0, 0.0],    0.0,   [0.3, 0.0, 0.0, 0.0]),
    row("exercise",  0.25,  [0.20, 0.40, 0.20, 0.20],   0.10,  [0.0; 4]),
    row("alcohol",   0.15,  [0.0, 0.50, 0.35, 0.0],     0.0,   [0.0, 0.2, 0.0, 0.0]),
];

/// One row of [`EXPRESSIONS`].
const fn row(
    name: &'static str,
    perfusion_global: f64,
    perfusion: [f64; 4],
    contrast_global: f64,
    contrast: [f64; 4],
) -> Expression {
    Expression { name, perfusion_global, perfusion, contrast_global, contrast }
}

/// Looks an expression up by name.
pub fn expression(name: &str) -> Option<&'static Expression> {
    EXPRESSIONS.iter().find(|e| e.name == name)
}

/// Low-frequency perfusion and capillary detail of the neutral map at (u, v).
fn neutral_parts(u: f64, v: f64, seed: u32) -> (f64, f64) {
    let [_, cheeks, nose, _] = region_masks(u, v);
    let low = fbm(u, v, 3.0, 3, seed);
    let base = 0.045 + 0.02 * low + 0.015 * cheeks + 0.01 * nose;
    let fine = fbm(u, v, 24.0, 3, seed ^ 0x5bd1_e995);
    let vessels = ridges(u, v, 9.0, 12, seed ^ 0x1b87_3593) + 0.6 * ridges(u, v, 21.0, 16, seed ^ 0x68e3_1da4);
    let detail = 0.008 * (fine - 0.5) + 0.035 * vessels;
    (base, detail)
}

/// Hemoglobin concentration (dermal volume fraction) of the neutral map, or of `expr` when given.
pub fn hemoglobin_at(u: f64, v: f64, seed: u32, expr: Option<&Expression>) -> f64 {
    let (base, detail) = neutral_parts(u, v, seed);
    let h = match expr {
        None => base + detail,
        Some(e) => {
            let m = region_masks(u, v);
            let mut p = 1.0 + e.perfusion_global;
            let mut c = 1.0 + e.contrast_global;
            for ((mk, pk), ck) in m.iter().zip(&e.perfusion).zip(&e.contrast) {
                p += pk * mk;
                c += ck * mk;
            }
            base * p + detail * c
        }
    };
    h.clamp(0.0, 0.32)
}

/// A `size × size` concentration map in f64.
pub fn hemoglobin_map(size: u32, seed: u32, expr: Option<&Expression>) -> Vec<f64> {
    let n = size as f64;
    let mut out = Vec::with_capacity((size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            out.push(hemoglobin_at((x as f64 + 0.5) / n, (y as f64 + 0.5) / n, seed, expr));
        }
    }
    out
}

/// Quantises a concentration map to 16-bit samples with the default PNG value mapping
/// `concentration = sample / 65535`.
pub fn quantize_u16(size: u32, values: &[f64]) -> Image<u16> {
    let data = values.iter().map(|&c| (c.clamp(0.0, 1.0) * 65535.0).round() as u16).collect();
    Image::from_vec(size, size, 1, data)
}

/// The fixture / demo set: `neutral` then one map per named expression, as 16-bit single-channel images.
/// Unknown expression names are an error naming `param`.
/// Wall time (s) and peak memory (bytes) of [`hemoglobin_set`] of `maps` maps (neutral + expressions) at
/// `size`² with their 16-bit PNG encoding (`maps synthetic`; the budget check). Measured with the release
/// build on the project's 2-core machine: 5 maps at 4096² took 40.8 s and 300 MB (0.49 µs and 3.6 bytes per texel
/// and map); the estimate takes 0.6 µs and 8 bytes, plus 0.3 s and 32 MiB.
pub fn hemoglobin_set_estimate(size: u32, maps: usize) -> (u64, f64) {
    let texel_maps = size as f64 * size as f64 * maps as f64;
    ((8.0 * texel_maps) as u64 + (32 << 20), 0.3 + 0.6e-6 * texel_maps)
}

pub fn hemoglobin_set(
    param: &str,
    size: u32,
    seed: u32,
    expressions: &[String],
) -> Result<Vec<(String, Image<u16>)>, crate::error::InvalidInput> {
    let mut out = vec![("neutral".to_string(), quantize_u16(size, &hemoglobin_map(size, seed, None)))];
    for name in expressions {
        let e = expression(name).ok_or_else(|| {
            let known: Vec<&str> = EXPRESSIONS.iter().map(|e| e.name).collect();
            crate::error::InvalidInput::new(
                param,
                format!("unknown synthetic expression '{name}'; known: {}", known.join(", ")),
            )
        })?;
        out.push((name.clone(), quantize_u16(size, &hemoglobin_map(size, seed, Some(e)))));
    }
    Ok(out)
}

/// Decoded concentration of a 16-bit sample with the default mapping (`sample / 65535`), as f32.
pub fn u16_to_concentration(img: &Image<u16>) -> Vec<f32> {
    img.data.iter().map(|&s| (s as f64 / 65535.0) as f32).collect()
}

// ---------------------------------------------------------------------------------------------------------
// Wrinkles

/// Height (in texel-independent UV units) of the synthetic wrinkle field: horizontal forehead lines, crow's
/// feet fanning out from the eye corners, frown lines between the brows and the nasolabial folds.
/// Returns (h, ∂h/∂u, ∂h/∂v).
fn wrinkle_height(u: f64, v: f64) -> (f64, f64, f64) {
    // Each wrinkle is a groove with profile −a·(1 − t²)² (|t| < 1) across a line, faded along it by a mask.
    let mut h = 0.0;
    let (mut hu, mut hv) = (0.0, 0.0);
    let mut groove = |dist: f64, ddist_du: f64, ddist_dv: f64, width: f64, depth: f64, fade: f64, fu: f64, fv: f64| {
        let t = dist / width;
        if t.abs() >= 1.0 || fade == 0.0 {
            return;
        }
        let s = 1.0 - t * t;
        let prof = -depth * s * s;
        let dprof_dt = -depth * 2.0 * s * (-2.0 * t);
        let dt_du = ddist_du / width;
        let dt_dv = ddist_dv / width;
        h += prof * fade;
        hu += dprof_dt * dt_du * fade + prof * fu;
        hv += dprof_dt * dt_dv * fade + prof * fv;
    };
    // Forehead: four horizontal lines, gently curved (v = c + k·(u − 0.5)²).
    for (i, c) in [0.10, 0.14, 0.18, 0.22].iter().enumerate() {
        let k = 0.25 + 0.05 * i as f64;
        let line_v = c + k * (u - 0.5) * (u - 0.5);
        let dist = v - line_v;
        let (fade, fu) = {
            let x = (u - 0.5) / 0.3;
            if x.abs() >= 1.0 {
                (0.0, 0.0)
            } else {
                let s = 1.0 - x * x;
                (s * s, 2.0 * s * (-2.0 * x) / 0.3)
            }
        };
        groove(dist, -2.0 * k * (u - 0.5), 1.0, 0.012, 0.004, fade, fu, 0.0);
    }
    // Crow's feet: three rays from each outer eye corner.
    for (cu, sign) in [(0.18, -1.0), (0.82, 1.0)] {
        for slope in [-0.5, 0.0, 0.5] {
            let (du, dv) = (u - cu, v - 0.38);
            let along = du * sign;
            if !(0.0..0.08).contains(&along) {
                continue;
            }
            let dist = dv - slope * du * sign;
            let x = along / 0.08;
            let s = 1.0 - x * x;
            let fade = s * s;
            let fu = 2.0 * s * (-2.0 * x) / 0.08 * sign;
            groove(dist, -slope * sign, 1.0, 0.008, 0.003, fade, fu, 0.0);
        }
    }
    // Glabella: two short vertical frown lines between the brows.
    for cu in [0.47, 0.53] {
        let x = (v - 0.30) / 0.05;
        if x.abs() < 1.0 {
            let s = 1.0 - x * x;
            groove(u - cu, 1.0, 0.0, 0.006, 0.002, s * s, 0.0, 2.0 * s * (-2.0 * x) / 0.05);
        }
    }
    // Nasolabial folds: lines from beside the nose to the mouth corners.
    for sign in [-1.0, 1.0] {
        let (u0, v0, u1, v1): (f64, f64, f64, f64) = (0.5 + sign * 0.08, 0.58, 0.5 + sign * 0.15, 0.78);
        let (lu, lv) = (u1 - u0, v1 - v0);
        let len = (lu * lu + lv * lv).sqrt();
        let (nu, nv) = (-lv / len, lu / len);
        let (pu, pv) = (u - u0, v - v0);
        let along = (pu * lu + pv * lv) / (len * len);
        if !(0.0..1.0).contains(&along) {
            continue;
        }
        let dist = pu * nu + pv * nv;
        let x = 2.0 * along - 1.0;
        let s = 1.0 - x * x;
        let fade = s * s;
        let dfade_dalong = 2.0 * s * (-2.0 * x) * 2.0;
        let (fu, fv) = (dfade_dalong * lu / (len * len), dfade_dalong * lv / (len * len));
        groove(dist, nu, nv, 0.02, 0.006, fade, fu, fv);
    }
    (h, hu, hv)
}

/// A `size × size` tangent-space wrinkle normal map, 8-bit RGB encoded `0.5 + 0.5·n` (DirectX convention:
/// +y towards increasing v, i.e. down the texture). `strength` scales the slopes.
pub fn wrinkle_normal_map(size: u32, strength: f64) -> Image<u8> {
    let n = size as f64;
    let mut data = Vec::with_capacity((size * size * 3) as usize);
    for y in 0..size {
        for x in 0..size {
            let (_, hu, hv) = wrinkle_height((x as f64 + 0.5) / n, (y as f64 + 0.5) / n);
            // Normal of the surface z = s·h(u, v): (−s·∂h/∂u, −s·∂h/∂v, 1), normalised.
            let (nx, ny) = (-strength * hu, -strength * hv);
            let len = (nx * nx + ny * ny + 1.0).sqrt();
            for c in [nx / len, ny / len, 1.0 / len] {
                data.push(((0.5 + 0.5 * c) * 255.0).round().clamp(0.0, 255.0) as u8);
            }
        }
    }
    Image::from_vec(size, size, 3, data)
}

/// The 8 zone masks of Table 8.1 (red, green, blue, brown, cyan, magenta, orange, gray) on the synthetic
/// layout, `size × size`, values in [0, 1]. The thesis shows the zones only as colours in Fig. 8.3; this layout
/// is our reading of the Table 8.1 weights: red/green = outer forehead (left/right), blue/brown = inner forehead
/// (inner-brow raiser: surprise, fear, sadness), cyan/magenta = between the brows (brow lowerer: anger, disgust),
/// orange = nose and nasolabial folds, gray = chin (sadness).
pub fn wrinkle_zone_masks(size: u32) -> Vec<Vec<f64>> {
    let zones: [(f64, f64, f64, f64); 8] = [
        (0.30, 0.16, 0.14, 0.09), // red: outer forehead left
        (0.70, 0.16, 0.14, 0.09), // green: outer forehead right
        (0.42, 0.17, 0.08, 0.09), // blue: inner forehead left
        (0.58, 0.17, 0.08, 0.09), // brown: inner forehead right
        (0.46, 0.30, 0.04, 0.06), // cyan: between the brows, left
        (0.54, 0.30, 0.04, 0.06), // magenta: between the brows, right
        (0.50, 0.62, 0.20, 0.20), // orange: nose and nasolabial folds
        (0.50, 0.88, 0.12, 0.07), // gray: chin
    ];
    let n = size as f64;
    zones
        .iter()
        .map(|&(cu, cv, ru, rv)| {
            let mut m = Vec::with_capacity((size * size) as usize);
            for y in 0..size {
                for x in 0..size {
                    m.push(ellipse_mask((x as f64 + 0.5) / n, (y as f64 + 0.5) / n, cu, cv, ru, rv));
                }
            }
            m
        })
        .collect()
}
