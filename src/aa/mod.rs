//! Antialiasing lookup textures (thesis ch. 9 and 10): pure computation, no I/O.
//!
//! * [`smaa_area`] — SMAA area texture (160 × 560 RG8): [`smaa_area_ortho`] orthogonal cells (7 subsample slices,
//!   U-shape smoothing since SMAA 2.8) and [`smaa_area_diag`] diagonal cells (5 slices, 30 × 30 supersampling);
//! * [`smaa_search`] — SMAA search texture (64 × 16 R8) and its v2.8 / logical 66 × 33 tables;
//! * [`mlaa_area`] — Jimenez MLAA area maps v1.3, v1.4+ (any N) and MLAA 2.0.
//!
//! Every texture is byte-identical to the published one with default parameters (tests/aa_golden.rs); all values
//! are computed in f64 in the reference generator's order and truncated with [`unorm8_trunc`].

pub mod mlaa_area;
pub mod smaa_area;
pub mod smaa_area_diag;
pub mod smaa_area_ortho;
pub mod smaa_search;

/// Stores a coverage in `[0, 1]` as 8-bit UNORM by truncation, `floor(255·v)` (not rounding), as the published
/// textures do. Values below 0 give 0.
#[inline]
pub fn unorm8_trunc(v: f64) -> u8 {
    (255.0 * v) as u8
}
