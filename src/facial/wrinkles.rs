//! Wrinkle maps (thesis ch. 8; Jimenez, Echevarria, Oat, Gutierrez, "Practical and Realistic Facial Wrinkles
//! Animation", GPU Pro 2, 2011).
//!
//! **Partial-derivative (PD) normal maps** (Acton 2008, without the customary minus sign — thesis §8.2 drops it
//! in both directions): a tangent-space normal `n = (nx, ny, nz)` is stored as `(nx/nz, ny/nz)` and rebuilt as
//! `normalize(x, y, 1)`. Wrinkles compose by addition: `n = normalize(base.xy + Σ_z mask_z·weight_z·wrinkle.xy, 1)`
//! (Listing 8.1), where each zone weight is the sum of the active expressions' Table 8.1 weights clamped to
//! [0, 1]. A PD map stored as UNORM `0.5 + 0.5·pd` represents slopes up to 1, i.e. normals inside the **45° cone**
//! around +z (`x² + y² ≤ 1`); normals outside are clamped to the cone (direction kept, tilt set to 45°) and
//! counted, or rejected.
//!
//! **Difference maps** (§8.2.1) for engines that keep standard normal maps: `d = 0.5 + 0.5·(w − b)` with `w`, `b`
//! the unit wrinkle and base normals; components of `w − b` outside [−1, 1] cannot be stored and are clamped
//! (counted).
//!
//! Conventions: input maps are encoded `n = 2·v − 1`. Outputs use the **DirectX** green convention (+y points
//! down the texture, towards increasing row index / texcoord v, matching the project's top-row-first storage);
//! OpenGL-convention inputs (+y up) have y negated on input. Output channels: R = x, G = y (Listing 8.1 reads
//! `.gr` from its own textures; with rtbake's textures read `.rg`). Zone masks: 8 zones in two RGBA8 textures,
//! `masks_0.rgba = (red, green, blue, brown)`, `masks_1.rgba = (cyan, magenta, orange, gray)` — the column order of
//! Table 8.1 and the `weights[0]`, `weights[1]` float4s of Listing 8.1.

use super::resample::resample_area;
use crate::error::InvalidInput;
use crate::image_buf::Image;

/// Green-channel (y) convention of a tangent-space normal map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GreenConvention {
    /// +y towards increasing v (down the texture), "Y−" in some tools; rtbake's output convention.
    DirectX,
    /// +y towards decreasing v (up the texture), "Y+".
    OpenGl,
}

/// Storage of the wrinkle map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WrinkleEncoding {
    /// Partial-derivative normal map, two channels.
    Pd,
    /// Difference map `0.5 + 0.5·(w − b)`, three channels (stored RGBA8 with A = 1).
    Difference,
}

/// What to do with normals outside the 45° cone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ConeMode {
    Clamp,
    Reject,
}

/// Zone names in storage order (Table 8.1 columns).
pub const ZONES: [&str; 8] = ["red", "green", "blue", "brown", "cyan", "magenta", "orange", "gray"];

/// Thesis Table 8.1: weights used for each expression and zone (columns in [`ZONES`] order).
pub const TABLE_8_1: [(&str, [f64; 8]); 6] = [
    ("joy", [1.0, 1.0, 0.2, 0.2, 0.0, 0.0, 0.0, 0.0]),
    ("surprise", [0.8, 0.8, 0.8, 0.8, 0.0, 0.0, 0.0, 0.0]),
    ("fear", [0.2, 0.2, 0.75, 0.75, 0.3, 0.3, 0.0, 0.6]),
    ("anger", [-0.6, -0.6, -0.8, -0.8, 0.8, 0.8, 1.0, 0.0]),
    ("disgust", [0.0, 0.0, -0.1, -0.1, 1.0, 1.0, 1.0, 0.5]),
    ("sad", [0.2, 0.2, 0.75, 0.75, 0.0, 0.0, 0.1, 1.0]),
];

/// Tolerance on the cone test so normals exactly at 45° count as inside.
const CONE_EPS: f64 = 1e-9;

/// PD encoding of one normal (any length, y already in DirectX convention). Returns `(x, y)` and whether it
/// had to be clamped to the 45° cone (also when `nz ≤ 0`).
pub fn to_pd(n: [f64; 3]) -> ([f64; 2], bool) {
    let [nx, ny, nz] = n;
    if nz <= 0.0 {
        // Horizon or back-facing: no finite slope; keep the direction at 45°.
        let l = (nx * nx + ny * ny).sqrt();
        return (if l > 0.0 { [nx / l, ny / l] } else { [0.0, 0.0] }, true);
    }
    let (x, y) = (nx / nz, ny / nz); // thesis §8.2: n'x = nx/nz, n'y = ny/nz
    let r2 = x * x + y * y;
    if r2 > 1.0 + CONE_EPS {
        let l = r2.sqrt();
        return ([x / l, y / l], true);
    }
    ([x, y], false)
}

/// Reconstruction `normalize(x, y, 1)` (thesis §8.2).
pub fn from_pd(pd: [f64; 2]) -> [f64; 3] {
    let l = (pd[0] * pd[0] + pd[1] * pd[1] + 1.0).sqrt();
    [pd[0] / l, pd[1] / l, 1.0 / l]
}

/// UNORM8 storage of a value in [−1, 1]: `round(255·(0.5 + 0.5·v))` (read back as `2·s/255 − 1`).
pub fn encode_snorm_in_unorm8(v: f64) -> u8 {
    ((0.5 + 0.5 * v.clamp(-1.0, 1.0)) * 255.0).round() as u8
}

/// UNORM8 of a value in [0, 1].
pub fn encode_unorm8(v: f64) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// A PD map (two interleaved channels, f64) with its conversion report.
#[derive(Clone, Debug, PartialEq)]
pub struct PdMap {
    pub width: u32,
    pub height: u32,
    pub pd: Vec<f64>,
    /// Texels clamped to the 45° cone.
    pub cone_clamped: u64,
}

fn y_sign(green: GreenConvention) -> f64 {
    match green {
        GreenConvention::DirectX => 1.0,
        GreenConvention::OpenGl => -1.0,
    }
}

/// Converts a decoded normal map (3 channels, `n = 2v − 1`) to a PD map in the DirectX convention.
pub fn normals_to_pd(
    param: &str,
    normals: &Image<f32>,
    green: GreenConvention,
    cone: ConeMode,
) -> Result<PdMap, InvalidInput> {
    assert_eq!(normals.channels, 3);
    let s = y_sign(green);
    let mut pd = Vec::with_capacity(normals.data.len() / 3 * 2);
    let mut clamped = 0u64;
    for px in normals.data.chunks_exact(3) {
        let (v, c) = to_pd([px[0] as f64, s * px[1] as f64, px[2] as f64]);
        clamped += c as u64;
        pd.extend_from_slice(&v);
    }
    if cone == ConeMode::Reject && clamped > 0 {
        return Err(InvalidInput::new(
            param,
            format!(
                "{clamped} texels lie outside the 45° cone that partial-derivative maps can represent; \
                 use `cone` clamp to clamp them"
            ),
        ));
    }
    Ok(PdMap { width: normals.width, height: normals.height, pd, cone_clamped: clamped })
}

/// `wrinkle − base` in PD space, clamped per component to [−1, 1] (storable); returns the count of clamped texels.
pub fn pd_delta(wrinkle: &PdMap, base: &PdMap) -> (Vec<f64>, u64) {
    let mut clamped = 0u64;
    let mut out = Vec::with_capacity(wrinkle.pd.len());
    for (w, b) in wrinkle.pd.chunks_exact(2).zip(base.pd.chunks_exact(2)) {
        let d = [w[0] - b[0], w[1] - b[1]];
        if d.iter().any(|v| v.abs() > 1.0) {
            clamped += 1;
        }
        out.extend(d.iter().map(|v| v.clamp(-1.0, 1.0)));
    }
    (out, clamped)
}

fn normalize3(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 {
        [v[0] / l, v[1] / l, v[2] / l]
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Difference encoding `d = 0.5 + 0.5·(w − b)` (thesis §8.2.1) of unit normals in the DirectX convention:
/// three interleaved channels in [0, 1] and the count of texels with a component clamped.
pub fn difference_map(wrinkle: &Image<f32>, base: &Image<f32>, green: GreenConvention) -> (Vec<f64>, u64) {
    let s = y_sign(green);
    let mut clamped = 0u64;
    let mut out = Vec::with_capacity(wrinkle.data.len());
    for (w, b) in wrinkle.data.chunks_exact(3).zip(base.data.chunks_exact(3)) {
        let w = normalize3([w[0] as f64, s * w[1] as f64, w[2] as f64]);
        let b = normalize3([b[0] as f64, s * b[1] as f64, b[2] as f64]);
        let mut any = false;
        for c in 0..3 {
            let d = 0.5 + 0.5 * (w[c] - b[c]);
            any |= !(0.0..=1.0).contains(&d);
            out.push(d.clamp(0.0, 1.0));
        }
        clamped += any as u64;
    }
    (out, clamped)
}

/// Area-downsamples an interleaved map to at most `size × size` (per axis clamped to the input size).
pub fn downsample(values: &[f64], width: u32, height: u32, channels: u32, size: u32) -> (u32, u32, Vec<f64>) {
    let (ow, oh) = (size.min(width), size.min(height));
    (ow, oh, resample_area(values, width, height, channels, ow, oh))
}

/// Stores a PD map (values in [−1, 1]) as RG8 UNORM `0.5 + 0.5·pd`.
pub fn pd_to_rg8(width: u32, height: u32, pd: &[f64]) -> Image<u8> {
    Image::from_vec(width, height, 2, pd.iter().map(|&v| encode_snorm_in_unorm8(v)).collect())
}

/// Stores a difference map (3 channels in [0, 1]) as RGBA8 with A = 255.
pub fn difference_to_rgba8(width: u32, height: u32, d: &[f64]) -> Image<u8> {
    let mut data = Vec::with_capacity(d.len() / 3 * 4);
    for px in d.chunks_exact(3) {
        data.extend(px.iter().map(|&v| encode_unorm8(v)));
        data.push(255);
    }
    Image::from_vec(width, height, 4, data)
}

/// Packs up to 8 zone masks (same size, values in [0, 1], `None` = zero) into two RGBA8 textures after
/// area-downsampling to at most `size × size`.
pub fn pack_zone_masks(masks: &[Option<Vec<f64>>; 8], width: u32, height: u32, size: u32) -> [Image<u8>; 2] {
    let (ow, oh) = (size.min(width), size.min(height));
    let down: Vec<Option<Vec<f64>>> =
        masks.iter().map(|m| m.as_ref().map(|m| resample_area(m, width, height, 1, ow, oh))).collect();
    let n = (ow * oh) as usize;
    let tex = |first: usize| {
        let mut data = vec![0u8; n * 4];
        for c in 0..4 {
            if let Some(m) = &down[first + c] {
                for (i, &v) in m.iter().enumerate() {
                    data[i * 4 + c] = encode_unorm8(v);
                }
            }
        }
        Image::from_vec(ow, oh, 4, data)
    };
    [tex(0), tex(4)]
}

/// Per-zone weights for a mix of expressions (names from Table 8.1): `clamp(Σ_e w_e·W[e][z], 0, 1)` (§8.2: the
/// summed contribution of several blend shapes is clamped to [0, 1]; negative entries cancel others).
pub fn zone_weights(expressions: &[(&str, f64)]) -> Result<[f64; 8], InvalidInput> {
    let mut z = [0.0f64; 8];
    for (name, w) in expressions {
        let Some((_, row)) = TABLE_8_1.iter().find(|(n, _)| n == name) else {
            let known: Vec<&str> = TABLE_8_1.iter().map(|(n, _)| *n).collect();
            return Err(InvalidInput::new(
                "expression",
                format!("unknown expression '{name}'; known: {}", known.join(", ")),
            ));
        };
        for k in 0..8 {
            z[k] += w * row[k];
        }
    }
    Ok(z.map(|v| v.clamp(0.0, 1.0)))
}

/// Listing 8.1 on the CPU: `normalize(base.xy + Σ_z mask_z·weight_z·wrinkle.xy, 1)`.
pub fn wrinkled_normal(base_pd: [f64; 2], wrinkle_pd: [f64; 2], masks: [f64; 8], weights: [f64; 8]) -> [f64; 3] {
    let mut xy = base_pd;
    for z in 0..8 {
        let k = masks[z] * weights[z];
        xy[0] += k * wrinkle_pd[0];
        xy[1] += k * wrinkle_pd[1];
    }
    from_pd(xy)
}

/// The Table 8.1 preset as JSON under the schema id `schema` (the contract's
/// `crate::baked_layout::schema::WRINKLE_WEIGHTS`).
pub fn table_8_1_json(schema: &str) -> serde_json::Value {
    let mut expr = serde_json::Map::new();
    let mut f4 = serde_json::Map::new();
    for (name, row) in TABLE_8_1 {
        expr.insert(name.into(), serde_json::json!(row));
        f4.insert(name.into(), serde_json::json!([&row[..4], &row[4..]]));
    }
    serde_json::json!({
        "schema": schema,
        "source": "J. Jimenez, PhD thesis (2012), Table 8.1; Jimenez, Echevarria, Oat, Gutierrez, \"Practical and Realistic Facial Wrinkles Animation\", GPU Pro 2 (2011)",
        "zones": ZONES,
        "mask_packing": {
            "wrinkle_masks_0": {"r": "red", "g": "green", "b": "blue", "a": "brown"},
            "wrinkle_masks_1": {"r": "cyan", "g": "magenta", "b": "orange", "a": "gray"}
        },
        "composition": "zone_weight[z] = clamp(sum over active expressions e of w_e * expressions[e][z], 0, 1); n = normalize(base.xy + sum_z mask_z * zone_weight[z] * wrinkle.xy, 1) with base.xy, wrinkle.xy = 2*texel.rg - 1 (partial-derivative maps, thesis Listing 8.1)",
        "negative_weights": "allowed: they cancel other expressions' wrinkles in the same zone (thesis Fig. 8.5)",
        "expressions": expr,
        "weights_float4": f4,
    })
}

/// Peak memory (bytes) and wall time (s) of converting a `w`×`h` normal map (with a base map of the same size when
/// `with_base`) into the wrinkle files (the budget check, after decoding the input, before the work): 86 MB
/// and 0.2 s at 1024² measured on the project's 2-core machine, doubled, plus 48 bytes per texel for the base.
pub fn wrinkle_estimate(w: u32, h: u32, with_base: bool) -> (u64, f64) {
    let px = w as u64 * h as u64;
    ((160 + if with_base { 48 } else { 0 }) * px + (32 << 20), 0.5 + 0.4e-6 * px as f64)
}

/// Peak memory (bytes) and wall time (s) of packing `zones` zone masks of `w`×`h` (50 MB and 0.17 s for one
/// 1024² zone on the project's 2-core machine, scaled per zone and rounded up).
pub fn mask_estimate(w: u32, h: u32, zones: usize) -> (u64, f64) {
    let px = w as u64 * h as u64;
    ((32 + 32 * zones as u64) * px + (32 << 20), 0.5 + 0.3e-6 * px as f64 * zones.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_8_1_rows_are_the_published_ones() {
        // Spot checks against the thesis text, including the negative anger/disgust entries.
        let row = |n: &str| TABLE_8_1.iter().find(|(m, _)| *m == n).unwrap().1;
        assert_eq!(row("anger"), [-0.6, -0.6, -0.8, -0.8, 0.8, 0.8, 1.0, 0.0]);
        assert_eq!(row("disgust")[2], -0.1);
        assert_eq!(row("sad")[7], 1.0);
        assert_eq!(row("fear")[7], 0.6);
        // Fig. 8.5: surprise + anger cancel the forehead (red, green) wrinkles down to 0.2 and clamp below 0.
        let z = zone_weights(&[("surprise", 1.0), ("anger", 1.0)]).unwrap();
        assert!((z[0] - 0.2).abs() < 1e-12 && (z[2] - 0.0).abs() < 1e-12);
    }

    #[test]
    fn pd_round_trip_inside_the_cone_is_exact_in_f64() {
        for &(x, y) in &[(0.0, 0.0), (0.3, -0.5), (0.7, 0.7), (-1.0, 0.0)] {
            let n = from_pd([x, y]);
            let (pd, c) = to_pd(n);
            assert!(!c);
            assert!((pd[0] - x).abs() < 1e-12 && (pd[1] - y).abs() < 1e-12);
        }
    }

    #[test]
    fn outside_the_cone_is_clamped_to_45_degrees() {
        let (pd, c) = to_pd([0.9, 0.0, 0.3]);
        assert!(c);
        assert!((pd[0] - 1.0).abs() < 1e-12 && pd[1] == 0.0);
        let (pd, c) = to_pd([0.0, -1.0, 0.0]);
        assert!(c && pd == [0.0, -1.0]);
    }
}
