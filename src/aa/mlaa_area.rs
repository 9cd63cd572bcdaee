//! Jimenez MLAA precomputed area maps (thesis ch. 9, § 9.4.3, Listing 9.4; J. Jimenez, B. Masia, J. I. Echevarria,
//! F. Navarro, D. Gutierrez, *Practical Morphological Anti-Aliasing*, GPU Pro 2, AK Peters, 2011).
//!
//! Layout: a 5 × 5 grid of `N × N` cells (`N` = `NUM_DISTANCES`, the number in the upstream file name `AreaMap{N}`);
//! cell `(e1, e2)` at `(N·e1, N·e2)`, `e ∈ {0, 1, 3, 4}` the crossing edges fetched at the left/right ends (row and
//! column 2 never occur and stay zero); texel `(left, right)` of a cell, distances linear `0..N` (v1.x) or quadratic
//! `i²` (MLAA 2.0). R = area where the crossing edge is of type 3, G = type 1. The shader point-samples
//! `(N·round(4e) + distance)/(5N − 1)` (Listing 9.4).
//!
//! Coverage: `d = left + right + 1`, `m = d/2`; the left half of the revectorised line has
//! height `y(t) = 0.5·(m − t)/m`; its area over the pixel is the trapezoid `(y(left) + y(left+1))/2` if
//! `left < right`, the triangle `y(left)·0.5/2` if `left = right`, else 0. The right half mirrors it. Each half is
//! quantised separately (`floor(255·a)`) and the bytes are added per channel (a symmetric U gives 2·31 = 62, not 63).
//! "+" ends (4): v1.4+ — a "+" counts only when the other end has a single crossing edge, as the opposite type;
//! v1.3 — a "+" adds its half to both R and G.

use crate::error::{check_size, InvalidInput};
use crate::image_buf::Image;
use serde::{Deserialize, Serialize};

/// Which published generator to reproduce.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum MlaaVersion {
    /// MLAA v1.3: "+" ends add to both channels; published N = 9, 16, 32.
    #[serde(rename = "v1.3")]
    V1_3,
    /// MLAA v1.4+: "+" ends act as the opposite of a single crossing edge; published N = 9, 17, 33, 65, 129.
    #[serde(rename = "v1.4")]
    V1_4,
    /// MLAA 2.0: v1.4 rules with quadratic distances (texel `i` ↔ distance `i²`); published N = 15 (75 × 75).
    #[serde(rename = "v2")]
    V2,
}

impl MlaaVersion {
    /// Published cell sizes.
    pub fn published(self) -> &'static [u32] {
        match self {
            Self::V1_3 => &[9, 16, 32],
            Self::V1_4 => &[9, 17, 33, 65, 129],
            Self::V2 => &[15],
        }
    }

    /// Accepted cell sizes `(min, max, odd_only)`. v1.4 searches two pixels per bilinear fetch, so its maximum
    /// distance `2·MAX_SEARCH_STEPS` is even and `N = 2·steps + 1` is odd; v1.3 and 2.0 accept any `N ≥ 2`.
    pub fn accepted(self) -> (u32, u32, bool) {
        match self {
            Self::V1_3 => (2, MAX_CELL, false),
            Self::V1_4 => (3, MAX_CELL - 1, true),
            Self::V2 => (2, MAX_CELL, false),
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Self::V1_3 => "v1.3",
            Self::V1_4 => "v1.4",
            Self::V2 => "v2",
        }
    }
}

/// Largest accepted cell size (5·1024 = 5120 texels per edge).
pub const MAX_CELL: u32 = 1024;

/// Errors of [`mlaa_area_map`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MlaaAreaError {
    #[error("{0}")]
    Invalid(#[from] InvalidInput),
}

/// Checks the cell size `n` for `version` (CLI `--max-distance`) and returns the texture edge `5n`.
pub fn validate(version: MlaaVersion, n: u32) -> Result<u32, InvalidInput> {
    let (lo, hi, odd) = version.accepted();
    let flag = "max_distance";
    let kind = if odd { "an odd" } else { "an" };
    if n < lo || n > hi || (odd && n.is_multiple_of(2)) {
        return Err(InvalidInput::new(
            flag,
            format!(
                "for MLAA {} must be {kind} integer in {lo}..={hi} texels per cell (published: {:?}), got {n}",
                version.label(),
                version.published()
            ),
        ));
    }
    let (w, _) = check_size("MLAA area map", 5 * n as u64, 5 * n as u64)?;
    Ok(w)
}

/// Height of the left half of the revectorised line at `t` (eq. of § 9.4.3 as specified): `0.5·(m − t)/m`.
fn height(m: f64, t: f64) -> f64 {
    0.5 * (m - t) / m
}

/// Area of the left half of the line over the current pixel (pixels², `0..=0.25`).
pub fn left_half_area(left: u32, right: u32) -> f64 {
    let m = (left + right + 1) as f64 / 2.0;
    let l = left as f64;
    if left < right {
        (height(m, l) + height(m, l + 1.0)) / 2.0
    } else if left == right {
        height(m, l) * 0.5 / 2.0
    } else {
        0.0
    }
}

fn q(a: f64) -> u8 {
    super::unorm8_trunc(a)
}

/// `(R, G)` bytes of cell `(e1, e2)` at distances `(left, right)` (pixels).
pub fn texel(version: MlaaVersion, e1: u8, e2: u8, left: u32, right: u32) -> (u8, u8) {
    texel_from_halves(version, e1, e2, half_bytes(left, right))
}

/// The two stored halves `(floor(255·left half), floor(255·right half))` at distances `(left, right)`: they do not
/// depend on the crossing edges, so a map computes them once per distance pair, not once per cell.
fn half_bytes(left: u32, right: u32) -> (u8, u8) {
    (q(left_half_area(left, right)), q(left_half_area(right, left)))
}

/// [`texel`] from the halves of [`half_bytes`].
fn texel_from_halves(version: MlaaVersion, e1: u8, e2: u8, (lh, rh): (u8, u8)) -> (u8, u8) {
    let (mut r, mut g) = (0u8, 0u8);
    let mut put = |kind: u8, h: u8| match kind {
        1 => g += h,
        3 => r += h,
        _ => {}
    };
    // Effective type of each end: a "+" (4) depends on the version and the other end.
    let eff = |own: u8, other: u8| -> u8 {
        match (own, version) {
            (4, MlaaVersion::V1_3) => 4,
            (4, _) => match other {
                1 => 3,
                3 => 1,
                _ => 0,
            },
            (e, _) => e,
        }
    };
    for (kind, h) in [(eff(e1, e2), lh), (eff(e2, e1), rh)] {
        if kind == 4 {
            put(1, h);
            put(3, h);
        } else {
            put(kind, h);
        }
    }
    (r, g)
}

/// The `5N × 5N` RG8 area map with cell size `n` (CLI `--max-distance`).
pub fn mlaa_area_map(version: MlaaVersion, n: u32) -> Result<Image<u8>, MlaaAreaError> {
    mlaa_area_map_with_progress(version, n, &|_, _| {})
}

/// [`mlaa_area_map`], calling `progress(rows_done, rows)` from the calling thread after each band of image rows
/// (`rows` = 5·N; large N take seconds). Rows are computed in parallel (rayon), each texel by [`texel`] alone, so
/// the map is the same bytes for any thread count and does not depend on the callback.
pub fn mlaa_area_map_with_progress(
    version: MlaaVersion,
    n: u32,
    progress: &dyn Fn(u32, u32),
) -> Result<Image<u8>, MlaaAreaError> {
    let row_bytes = 2 * 5 * n as usize;
    area_map_in_bands(version, n, BAND_BYTES.div_ceil(row_bytes.max(1)), progress)
}

/// Bytes of image rows filled per parallel band: several 2 MiB huge pages ([`advise_huge_pages`]), so the threads
/// of a band first-touch (and the kernel zeroes) different pages instead of queueing on the same one, as they did
/// with 64-row bands (650 KB at N = 1023: both threads of a band inside one huge page, the fresh-process generator
/// no faster on 2 threads than on 1).
const BAND_BYTES: usize = 4 << 20;

/// [`mlaa_area_map_with_progress`] with `band_rows` rows per band (progress is reported after each band).
fn area_map_in_bands(
    version: MlaaVersion,
    n: u32,
    band_rows: usize,
    progress: &dyn Fn(u32, u32),
) -> Result<Image<u8>, MlaaAreaError> {
    use rayon::prelude::*;
    let band_rows = band_rows.max(1);
    let edge = validate(version, n)?;
    let mut img = Image::<u8>::new(edge, edge, 2);
    advise_huge_pages(&img.data);
    let dist = |i: u32| if version == MlaaVersion::V2 { i * i } else { i };
    // The halves of every distance pair (i, j), row j = right distance: N² area evaluations instead of 16 N².
    let halves: Vec<(u8, u8)> = (0..n * n).into_par_iter().map(|k| half_bytes(dist(k % n), dist(k / n))).collect();
    // Image row y holds the cells (e1, e2 = y / N) at right distance j = y % N; cell row and column 2 stay zero.
    let fill_row = |y: u32, row: &mut [u8]| {
        let (e2, j) = ((y / n) as u8, y % n);
        if e2 == 2 {
            return;
        }
        let halves_j = &halves[(j * n) as usize..((j + 1) * n) as usize];
        for e1 in [0u8, 1, 3, 4] {
            for (i, &h) in halves_j.iter().enumerate() {
                let i = i as u32;
                let (r, g) = texel_from_halves(version, e1, e2, h);
                let x = (n * e1 as u32 + i) as usize;
                row[2 * x] = r;
                row[2 * x + 1] = g;
            }
        }
    };
    let row_bytes = 2 * edge as usize;
    for (b, band) in img.data.chunks_mut(row_bytes * band_rows).enumerate() {
        let y0 = b * band_rows;
        band.par_chunks_mut(row_bytes).enumerate().for_each(|(r, row)| fill_row((y0 + r) as u32, row));
        progress(((y0 + band_rows) as u32).min(edge), edge);
    }
    Ok(img)
}

/// Asks the kernel to back a large, not yet touched buffer with transparent huge pages (Linux `madvise`
/// `MADV_HUGEPAGE`, honoured where THP is in `madvise` mode): the rows' first writes then fault in 2 MiB pages
/// instead of 4 KiB ones (AreaMap513's 13 MB map: about 7 faults instead of 3200, which took most of the generator's
/// time in a fresh process). A hint only: the bytes are the same whether or not it is taken.
fn advise_huge_pages(buf: &[u8]) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = buf.as_ptr() as usize;
        let (lo, hi) = (start.next_multiple_of(HUGE), (start + buf.len()) / HUGE * HUGE);
        if hi > lo {
            // SAFETY: [lo, hi) lies inside `buf`'s allocation; MADV_HUGEPAGE only changes how the kernel backs
            // those pages (their contents stay), and a failure is ignored.
            unsafe { libc::madvise(lo as *mut libc::c_void, hi - lo, libc::MADV_HUGEPAGE) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = buf;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_reaches_every_row_and_the_map_is_the_serial_definition_for_any_thread_count() {
        let n = 65; // 325 rows: with 64-row bands several bands, the last one partial
        let last = std::cell::Cell::new(0);
        let with = area_map_in_bands(MlaaVersion::V1_4, n, 64, &|done, rows| {
            assert!(done > last.get(), "progress only grows");
            assert_eq!(rows, 5 * n);
            last.set(done);
        })
        .unwrap();
        assert_eq!(last.get(), 5 * n);
        // The definition, texel by texel in cell order.
        let mut serial = Image::<u8>::new(5 * n, 5 * n, 2);
        for e1 in [0u8, 1, 3, 4] {
            for e2 in [0u8, 1, 3, 4] {
                for i in 0..n {
                    for j in 0..n {
                        let (r, g) = texel(MlaaVersion::V1_4, e1, e2, i, j);
                        serial.set(n * e1 as u32 + i, n * e2 as u32 + j, 0, r);
                        serial.set(n * e1 as u32 + i, n * e2 as u32 + j, 1, g);
                    }
                }
            }
        }
        assert!(with == serial, "parallel rows differ from the serial definition");
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            assert!(pool.install(|| mlaa_area_map(MlaaVersion::V1_4, n).unwrap()) == serial, "{threads} threads");
        }
    }

    #[test]
    fn halves_sum_to_the_triangle_of_the_line() {
        // The two halves of a U are mirror images; the full left-half triangle has area m·0.5/2 = d/8.
        for d in 1..40u32 {
            let total: f64 = (0..d).map(|l| left_half_area(l, d - 1 - l)).sum();
            assert!((total - d as f64 / 8.0).abs() < 1e-12, "d = {d}: {total}");
        }
    }

    #[test]
    fn symmetric_u_is_twice_the_truncated_half() {
        assert_eq!(texel(MlaaVersion::V1_4, 1, 1, 0, 0), (0, 62));
        assert_eq!(texel(MlaaVersion::V1_4, 3, 3, 0, 0), (62, 0));
        // v1.4: "+" is the opposite of a single crossing edge; zero against none or another "+".
        assert_eq!(texel(MlaaVersion::V1_4, 4, 1, 0, 0), (31, 31));
        assert_eq!(texel(MlaaVersion::V1_4, 4, 0, 0, 3), (0, 0));
        assert_eq!(texel(MlaaVersion::V1_4, 4, 4, 0, 0), (0, 0));
        // v1.3: "+" adds to both channels.
        // left = 0, right = 3: d = 4, m = 2, trapezoid (0.5 + 0.25)/2 = 0.375 → 95.
        assert_eq!(texel(MlaaVersion::V1_3, 4, 0, 0, 3), (95, 95));
    }

    #[test]
    fn validation_names_flag_and_parity() {
        assert!(validate(MlaaVersion::V1_4, 0).unwrap_err().to_string().contains("max_distance"));
        assert!(validate(MlaaVersion::V1_4, 16).unwrap_err().to_string().contains("odd"));
        assert!(validate(MlaaVersion::V1_3, 16).is_ok());
        assert!(validate(MlaaVersion::V2, 1_000_000).is_err());
        for v in [MlaaVersion::V1_3, MlaaVersion::V1_4, MlaaVersion::V2] {
            for &n in v.published() {
                assert_eq!(validate(v, n).unwrap(), 5 * n);
            }
        }
    }
}
