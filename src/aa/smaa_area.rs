//! SMAA area texture assembly (thesis ch. 10; Jimenez et al., *SMAA: Enhanced Subpixel Morphological
//! Antialiasing*, Computer Graphics Forum 31(2), Eurographics 2012): orthogonal and diagonal coverage cells laid out
//! in one RG8 texture, one slice per subsample offset.
//!
//! Layout with orthogonal cell size `n` (`SMAA_AREATEX_MAX_DISTANCE`, 16) and diagonal cell size `m`
//! (`SMAA_AREATEX_MAX_DISTANCE_DIAG`, 20) — upstream: 160 × 560:
//!
//! * orthogonal half, columns `0..5n`: slice `k` (orthogonal offset `k`) at rows `5n·k..5n·(k+1)`, a 5 × 5 grid of
//!   `n × n` cells; cell `(e1, e2)`, `e ∈ {0, 1, 3, 4}`, starts at `(n·e1, 5n·k + n·e2)`; texel `(i, j)` of a cell
//!   holds left distance `i²`, right distance `j²` (quadratic compression);
//! * diagonal half, columns `5n..5n + 4m`: slice `k` (diagonal offset `k`) at rows `4m·k..`, a 4 × 4 grid of `m × m`
//!   cells, cell `(e1, e2)` at `(5n + m·e1, 4m·k + m·e2)`; texel `(i, j)` = left `i`, right `j` (linear);
//! * R = area on the negative side of the edge, G = positive side; `floor(255·v)`; everything else zero.
//!
//! The stock shader addresses the diagonal half at `texcoord.x + 0.5` and both halves' slices with
//! `SMAA_AREATEX_SUBTEX_SIZE = 1/7`, i.e. it assumes `5n = 4m` and `5n·7 = height`; variants that break this need
//! matching shader constants (recorded in the manifest convention).

use super::smaa_area_diag::{diag_areas_all_patterns, diag_cell};
use super::smaa_area_ortho::{ortho_area, Area2};
use super::unorm8_trunc;
use crate::error::{check_range, check_size, InvalidInput};
use crate::image_buf::Image;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Upstream orthogonal subsample offsets (pixels), slice order 0..6: 1x → 0; S2x/T2x → 1, 2; 4x → 3..6.
pub const DEFAULT_ORTHO_OFFSETS: [f64; 7] = [0.0, -0.25, 0.25, -0.125, 0.125, -0.375, 0.375];
/// Upstream diagonal subsample offsets `(x, y)` (pixels), slice order 0..4.
pub const DEFAULT_DIAG_OFFSETS: [[f64; 2]; 5] =
    [[0.0, 0.0], [0.25, -0.25], [-0.25, 0.25], [0.125, -0.125], [-0.125, 0.125]];
/// Upstream orthogonal cell size (`SMAA_AREATEX_MAX_DISTANCE`).
pub const DEFAULT_ORTHO_MAX_DISTANCE: u32 = 16;
/// Upstream diagonal cell size (`SMAA_AREATEX_MAX_DISTANCE_DIAG`).
pub const DEFAULT_DIAG_MAX_DISTANCE: u32 = 20;
/// Accepted cell sizes (texels per cell edge) for both halves.
pub const MAX_DISTANCE_RANGE: (u32, u32) = (1, 128);
/// Accepted number of subsample slices per half.
pub const MAX_SLICES: usize = 16;

/// Parameters of the SMAA area texture. Defaults reproduce the SMAA 2.8+ texture byte for byte; `u_smoothing: false`
/// the older v2.8 texture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SmaaAreaParams {
    /// Orthogonal cell size `n` (texels; distances `0, 1, 4, …, (n−1)²` pixels). CLI `--ortho-max-distance`.
    pub ortho_max_distance: u32,
    /// Diagonal cell size `m` (texels; distances `0..m` pixels). CLI `--diag-max-distance`.
    pub diag_max_distance: u32,
    /// Vertical subsample offsets (pixels, each in (−0.5, 0.5)), one orthogonal slice each. CLI `--ortho-offsets`.
    pub ortho_offsets: Vec<f64>,
    /// Subsample offsets `[x, y]` (pixels, each in (−0.5, 0.5)), one diagonal slice each. CLI `--diag-offsets`.
    pub diag_offsets: Vec<[f64; 2]>,
    /// SMAA 2.8+ smoothing of short U shapes (false: the older v2.8 texture). CLI `--no-u-smoothing`.
    pub u_smoothing: bool,
}

impl Default for SmaaAreaParams {
    fn default() -> Self {
        Self {
            ortho_max_distance: DEFAULT_ORTHO_MAX_DISTANCE,
            diag_max_distance: DEFAULT_DIAG_MAX_DISTANCE,
            ortho_offsets: DEFAULT_ORTHO_OFFSETS.to_vec(),
            diag_offsets: DEFAULT_DIAG_OFFSETS.to_vec(),
            u_smoothing: true,
        }
    }
}

/// Errors of [`smaa_area_texture`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SmaaAreaError {
    #[error("{0}")]
    Invalid(#[from] InvalidInput),
}

fn check_offset(param: &str, v: f64) -> Result<(), InvalidInput> {
    if !(v.is_finite() && v > -0.5 && v < 0.5) {
        return Err(InvalidInput::new(param, format!("must be a finite number in (-0.5, 0.5) pixels, got {v}")));
    }
    Ok(())
}

fn check_count(param: &str, n: usize) -> Result<(), InvalidInput> {
    if n == 0 || n > MAX_SLICES {
        return Err(InvalidInput::new(param, format!("must list 1..={MAX_SLICES} offsets, got {n}")));
    }
    Ok(())
}

impl SmaaAreaParams {
    /// The v2.8 texture (no U-shape smoothing), otherwise upstream defaults.
    pub fn v2_8() -> Self {
        Self { u_smoothing: false, ..Self::default() }
    }

    /// Checks every field (names as the CLI flags) and returns the texture size, before anything is allocated.
    pub fn validate(&self) -> Result<(u32, u32), InvalidInput> {
        let (lo, hi) = MAX_DISTANCE_RANGE;
        check_range("ortho_max_distance", self.ortho_max_distance, lo, hi, "texels per cell")?;
        check_range("diag_max_distance", self.diag_max_distance, lo, hi, "texels per cell")?;
        check_count("ortho_offsets", self.ortho_offsets.len())?;
        check_count("diag_offsets", self.diag_offsets.len())?;
        for (k, &o) in self.ortho_offsets.iter().enumerate() {
            check_offset(&format!("ortho_offsets[{k}]"), o)?;
        }
        for (k, o) in self.diag_offsets.iter().enumerate() {
            check_offset(&format!("diag_offsets[{k}].x"), o[0])?;
            check_offset(&format!("diag_offsets[{k}].y"), o[1])?;
        }
        let (w, h) = self.size();
        check_size("SMAA area texture", w, h)
    }

    /// Texture size `(5n + 4m, max(5n·slices_ortho, 4m·slices_diag))`.
    fn size(&self) -> (u64, u64) {
        let n = self.ortho_max_distance as u64;
        let m = self.diag_max_distance as u64;
        let h = (5 * n * self.ortho_offsets.len() as u64).max(4 * m * self.diag_offsets.len() as u64);
        (5 * n + 4 * m, h)
    }
}

/// Orthogonal texel `(x, y)` (with `x < 5n`): `(e1, e2, left, right, slice)`, or None for unused cells/slices.
fn ortho_texel(p: &SmaaAreaParams, x: u32, y: u32) -> Option<(u8, u8, u32, u32, usize)> {
    let n = p.ortho_max_distance;
    let slice = (y / (5 * n)) as usize;
    let (cx, cy) = (x / n, (y % (5 * n)) / n);
    if slice >= p.ortho_offsets.len() || cx == 2 || cy == 2 {
        return None;
    }
    let (i, j) = (x % n, y % n);
    Some((cx as u8, cy as u8, i * i, j * j, slice))
}

/// The SMAA area texture (RG8, top row first). Deterministic for any rayon thread count: every texel is computed
/// independently (orthogonal half in parallel over rows, diagonal half over (slice, right distance) groups whose
/// results are then placed sequentially).
pub fn smaa_area_texture(params: &SmaaAreaParams) -> Result<Image<u8>, SmaaAreaError> {
    let (w, h) = params.validate()?;
    let mut img = Image::<u8>::new(w, h, 2);
    let n = params.ortho_max_distance;
    let m = params.diag_max_distance;

    img.data.par_chunks_mut(2 * w as usize).enumerate().for_each(|(y, row)| {
        for x in 0..5 * n {
            if let Some((e1, e2, left, right, slice)) = ortho_texel(params, x, y as u32) {
                let (r, g) = ortho_area(e1, e2, left, right, params.ortho_offsets[slice], params.u_smoothing);
                row[2 * x as usize] = unorm8_trunc(r);
                row[2 * x as usize + 1] = unorm8_trunc(g);
            }
        }
    });

    // Diagonal half: one group per (slice, right), all left distances and all 16 patterns.
    let groups = params.diag_offsets.len() * m as usize;
    let blocks: Vec<Vec<[Area2; 16]>> = (0..groups)
        .into_par_iter()
        .map(|g| {
            let (slice, right) = (g / m as usize, (g % m as usize) as u32);
            let o = params.diag_offsets[slice];
            (0..m).map(|left| diag_areas_all_patterns(left, right, (o[0], o[1]))).collect()
        })
        .collect();
    for (g, block) in blocks.iter().enumerate() {
        let (slice, right) = ((g / m as usize) as u32, (g % m as usize) as u32);
        for (left, areas) in block.iter().enumerate() {
            for (pattern, &(r, gr)) in areas.iter().enumerate() {
                let (e1, e2) = diag_cell(pattern as u8);
                let x = 5 * n + m * e1 as u32 + left as u32;
                let y = 4 * m * slice + m * e2 as u32 + right;
                img.set(x, y, 0, unorm8_trunc(r));
                img.set(x, y, 1, unorm8_trunc(gr));
            }
        }
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_have_upstream_size_and_round_trip_json() {
        let p = SmaaAreaParams::default();
        assert_eq!(p.validate().unwrap(), (160, 560));
        let v = serde_json::to_value(&p).unwrap();
        assert_eq!(serde_json::from_value::<SmaaAreaParams>(v).unwrap(), p);
    }

    #[test]
    fn bad_params_are_refused_naming_the_flag() {
        let bad = |f: &dyn Fn(&mut SmaaAreaParams)| {
            let mut p = SmaaAreaParams::default();
            f(&mut p);
            p.validate().unwrap_err()
        };
        assert_eq!(bad(&|p| p.ortho_max_distance = 0).param, "ortho_max_distance");
        assert_eq!(bad(&|p| p.diag_max_distance = 1_000_000).param, "diag_max_distance");
        assert_eq!(bad(&|p| p.ortho_offsets = vec![]).param, "ortho_offsets");
        assert_eq!(bad(&|p| p.ortho_offsets[3] = f64::NAN).param, "ortho_offsets[3]");
        assert_eq!(bad(&|p| p.diag_offsets[1][1] = 0.5).param, "diag_offsets[1].y");
        let e = bad(&|p| p.ortho_offsets = vec![0.0; 17]);
        assert!(e.message.contains("1..=16"), "{e}");
    }

    #[test]
    fn unused_rows_and_columns_are_zero() {
        let p = SmaaAreaParams { ortho_max_distance: 4, diag_max_distance: 5, ..SmaaAreaParams::default() };
        let img = smaa_area_texture(&p).unwrap();
        assert_eq!((img.width, img.height), (40, 140));
        for y in 0..img.height {
            for x in 0..20 {
                let cell = (x / 4, (y % 20) / 4);
                if cell.0 == 2 || cell.1 == 2 {
                    assert_eq!((img.get(x, y, 0), img.get(x, y, 1)), (0, 0), "({x},{y})");
                }
            }
        }
        // Diagonal half below the 5 diagonal slices (rows 100..140) is empty.
        assert!((100..140).all(|y| (20..40).all(|x| img.get(x, y, 0) == 0 && img.get(x, y, 1) == 0)));
    }
}
