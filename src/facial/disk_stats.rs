//! Exact local mean and standard deviation over a disk (thesis eq. 7.1; Jimenez, Scully, Barbosa, Donner,
//! Alvarez, Vieira, Matts, Orvalho, Gutierrez, Weyrich, "A practical appearance model for dynamic facial color",
//! ACM TOG 29(6) / SIGGRAPH Asia 2010):
//!
//! ```text
//! μ(x) = (H * f)(x)        σ(x) = sqrt( (H² * f)(x) − μ(x)² )        f(u) = 1/(πr²) for |u| ≤ r
//! ```
//!
//! The disk is the set of integer texel offsets (dx, dy) with dx² + dy² ≤ r². It is the union of 2r + 1 horizontal
//! chords of half-width `hw(dy) = floor(sqrt(r² − dy²))`, so with per-row prefix sums each chord costs two look-ups
//! and a texel costs O(r) (not O(r²)).
//!
//! Layout of the work: the map is cut into bands of [`BAND_ROWS`] rows (the parallel tasks; each
//! reads its `BAND_ROWS + 2r` prefix rows into per-thread buffers reused across bands), a band into tiles of 256
//! columns (their prefix rows stay in L2), and a tile row into blocks of 8 texels whose sums stay in AVX2 registers
//! across all 2r + 1 chords; two consecutive output rows are summed together, so every prefix row is read once for
//! both. The inner loop is load-bound (two 32-byte loads, one subtraction and one addition per two texels and
//! chord). [`disk_stats_bands`] hands each band's rows to a caller (the rig downsamples them at once, so no
//! full-size map is stored); [`disk_stats`] collects them.
//!
//! Numerics: samples are shifted by the map's global mean `c` before summing (accumulation in f64), so the
//! variance `E[(H−c)²] − E[H−c]²` does not cancel catastrophically for maps with a large mean; it is clamped at 0
//! before the square root. Results do not depend on how the rows are split between threads (each texel's sums
//! are formed in a fixed order), so the bytes are identical for any `RAYON_NUM_THREADS`.
//!
//! Borders: [`Border::Clip`] clips the disk at the map border and normalises by the covered texel count (no zero
//! padding, no wrap); [`Border::Wrap`] treats the map as tileable.

use crate::error::InvalidInput;
use rayon::prelude::*;

/// How the disk is handled where it leaves the map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Border {
    /// Clip the disk at the border and normalise by the covered area.
    Clip,
    /// Wrap around (tileable maps).
    Wrap,
}

impl Border {
    pub fn as_str(self) -> &'static str {
        match self {
            Border::Clip => "clip",
            Border::Wrap => "wrap",
        }
    }
}

/// Local statistics of a single-channel map (row-major, top row first).
#[derive(Clone, Debug, PartialEq)]
pub struct LocalStats {
    pub width: u32,
    pub height: u32,
    /// μ(x) of eq. 7.1.
    pub mean: Vec<f64>,
    /// σ(x) of eq. 7.1 (variance clamped at 0 before the square root).
    pub sigma: Vec<f64>,
}

/// Largest radius accepted for a `width × height` map: the disk diameter 2r + 1 must fit in the map.
pub fn max_radius(width: u32, height: u32) -> u32 {
    (width.min(height).saturating_sub(1)) / 2
}

/// Checks `radius` against the map size (`param` names the flag in the error).
pub fn check_radius(param: &str, radius: u32, width: u32, height: u32) -> Result<u32, InvalidInput> {
    let max = max_radius(width, height);
    if max == 0 {
        return Err(InvalidInput::new(
            param,
            format!("cannot be used with a {width}x{height} map: the map must be at least 3x3 texels"),
        ));
    }
    if radius == 0 || radius > max {
        return Err(InvalidInput::new(
            param,
            format!(
                "must be in 1..={max} texels for a {width}x{height} map (the disk diameter 2r+1 must fit), got {radius}"
            ),
        ));
    }
    Ok(radius)
}

/// Half-widths of the disk's chords, indexed by `dy + r` for `dy` in `−r..=r`: the largest integer `h` with
/// `h² + dy² ≤ r²` (exact integer arithmetic).
pub fn chord_half_widths(radius: u32) -> Vec<u32> {
    let r = radius as i64;
    (-r..=r)
        .map(|dy| {
            let m = r * r - dy * dy;
            let mut h = (m as f64).sqrt() as i64;
            while h * h > m {
                h -= 1;
            }
            while (h + 1) * (h + 1) <= m {
                h += 1;
            }
            h as u32
        })
        .collect()
}

/// Number of texels in the full (unclipped) disk.
pub fn disk_texel_count(radius: u32) -> u64 {
    chord_half_widths(radius).iter().map(|&h| 2 * h as u64 + 1).sum()
}

/// Mean of a map in f64, summed row by row in a fixed order (deterministic).
pub fn global_mean(data: &[f32]) -> f64 {
    if data.is_empty() {
        return 0.0;
    }
    let mut s = 0.0f64;
    for chunk in data.chunks(4096) {
        s += chunk.iter().map(|&v| v as f64).sum::<f64>();
    }
    s / data.len() as f64
}

/// Rows per parallel task (a band). Any value gives the same bytes (each texel's sums are formed in the same
/// order); a band reads `BAND_ROWS + 2r` input rows, so taller bands recompute fewer prefix rows.
pub const BAND_ROWS: usize = 64;
/// Output columns per cache tile: the `BAND_ROWS + 2r` prefix rows of a tile stay in L2 while its rows are summed.
const TILE_COLS: usize = 256;
/// Output texels summed together in registers over all chords of the disk (8 texels = four AVX2 vectors of
/// (Σ, Σ²) pairs): the accumulators are loaded and stored once per texel, not once per chord.
const BLOCK: usize = 8;
/// Output rows summed together (see [`accumulate_pair`]).
const ROW_PAIR: usize = 2;

/// Exact disk statistics in O(r) per texel. `data` is `width × height` single-channel, top row first.
/// The radius must pass [`check_radius`].
pub fn disk_stats(
    data: &[f32],
    width: u32,
    height: u32,
    radius: u32,
    border: Border,
) -> Result<LocalStats, InvalidInput> {
    let (w, h) = (width as usize, height as usize);
    let mut mean = vec![0.0f64; w * h];
    let mut sigma = vec![0.0f64; w * h];
    let outputs = mean.par_chunks_mut(BAND_ROWS * w).zip(sigma.par_chunks_mut(BAND_ROWS * w));
    disk_stats_bands(data, width, height, radius, border, outputs, |(m, s), _, band_mean, band_sigma| {
        m.copy_from_slice(band_mean);
        s.copy_from_slice(band_sigma);
    })?;
    Ok(LocalStats { width, height, mean, sigma })
}

/// Per-thread working buffers of one band, reused for every band the thread computes (no allocation, and so no
/// page faults, per band).
#[derive(Default)]
struct BandScratch {
    /// Extended prefix rows (Σ, Σ²) of the band's input rows.
    pre: Vec<[f64; 2]>,
    valid: Vec<bool>,
    /// (offset of P(x0 + hw + 1), offset of P(x0 − hw)) in `pre` of every valid chord of one output row.
    chords: Vec<(usize, usize)>,
    /// Per chord (dy + r): its two prefix offsets within a row, for the current tile.
    offsets: Vec<(usize, usize)>,
    /// Sums of the current tile row (and of the next one when a pair of rows is summed together).
    acc: Vec<[f64; 2]>,
    /// Whether `acc` holds the sums of the current pair of rows.
    pair_ready: bool,
    mean: Vec<f64>,
    sigma: Vec<f64>,
}

/// [`disk_stats`] band by band without full-size outputs: the rows `y0 .. y0 + rows` of every band of
/// [`BAND_ROWS`] rows (the last one may be shorter) are computed into per-thread buffers and handed to
/// `sink(item, y0, mean, sigma)` (`rows × width` each) together with the band's item of `outputs`, which must
/// yield exactly one item per band in order (e.g. `buf.par_chunks_mut(BAND_ROWS * width)`). Bands run in parallel;
/// the values do not depend on the thread count.
pub fn disk_stats_bands<I, F>(
    data: &[f32],
    width: u32,
    height: u32,
    radius: u32,
    border: Border,
    outputs: I,
    sink: F,
) -> Result<(), InvalidInput>
where
    I: IndexedParallelIterator,
    F: Fn(I::Item, usize, &[f64], &[f64]) + Sync + Send,
{
    check_radius("radius", radius, width, height)?;
    let (w, h, r) = (width as usize, height as usize, radius as usize);
    assert_eq!(data.len(), w * h, "map data length");
    assert_eq!(outputs.len(), h.div_ceil(BAND_ROWS), "one output item per band");
    let hws = chord_half_widths(radius);
    let ctx = Context {
        data,
        w,
        h,
        r,
        border,
        shift: global_mean(data),
        full_count: hws.iter().map(|&x| 2 * x as u64 + 1).sum(),
        full_edge: edge_counts(&hws, w, r, |_| true),
        hws,
        ext: w + 2 * r + 1, // extended prefix row: index j + r for j in −r..=w+r
    };
    outputs.enumerate().for_each_init(BandScratch::default, |s, (band, item)| {
        let y0 = band * BAND_ROWS;
        let rows = BAND_ROWS.min(h - y0);
        ctx.band(s, y0, rows);
        sink(item, y0, &s.mean[..rows * w], &s.sigma[..rows * w]);
    });
    Ok(())
}

/// Covered texel counts of the `r` columns at each border (clip), for the chord rows `valid(i)` (i = dy + r).
/// w ≥ 2r + 1, so the two border ranges do not overlap.
fn edge_counts(hws: &[u32], w: usize, r: usize, valid: impl Fn(usize) -> bool) -> Vec<u64> {
    let hws_valid: Vec<i64> = hws.iter().enumerate().filter(|&(i, _)| valid(i)).map(|(_, &hw)| hw as i64).collect();
    (0..r)
        .chain(w - r..w)
        .map(|x| hws_valid.iter().map(|&hw| ((x as i64 + hw + 1).min(w as i64) - (x as i64 - hw).max(0)) as u64).sum())
        .collect()
}

/// What every band of one map shares.
struct Context<'a> {
    data: &'a [f32],
    w: usize,
    h: usize,
    r: usize,
    border: Border,
    /// The map's global mean c (samples are summed as H − c).
    shift: f64,
    hws: Vec<u32>,
    /// Texels of the whole disk, and of the disk at the border columns, when every chord row is inside the map.
    full_count: u64,
    full_edge: Vec<u64>,
    ext: usize,
}

impl Context<'_> {
    /// Extended prefix sums of (H − c) and (H − c)², interleaved, of input row `y`.
    fn prefix_row(&self, y: usize, p: &mut [[f64; 2]]) {
        let (w, r) = (self.w, self.r);
        let row = &self.data[y * w..(y + 1) * w];
        p[r] = [0.0, 0.0];
        let (mut s, mut q) = (0.0f64, 0.0f64);
        for (x, &v) in row.iter().enumerate() {
            let d = v as f64 - self.shift;
            s += d;
            q += d * d;
            p[r + x + 1] = [s, q];
        }
        match self.border {
            Border::Clip => {
                for j in 0..r {
                    p[j] = [0.0, 0.0];
                    p[r + w + 1 + j] = [s, q];
                }
            }
            Border::Wrap => {
                // P(j) = P(j mod w) + floor(j / w)·total, with |j| < w here.
                for j in 0..r {
                    // left: index j ↔ position j − r (negative), equal to P(j − r + w) − total
                    let m = j + w - r;
                    p[j] = [p[r + m][0] - s, p[r + m][1] - q];
                }
                for j in 0..r {
                    // right: position w + 1 + j, equal to P(1 + j) + total
                    let m = 1 + j;
                    p[r + w + 1 + j] = [p[r + m][0] + s, p[r + m][1] + q];
                }
            }
        }
    }

    /// Mean and σ of output rows `y0 .. y0 + rows` into `s.mean`, `s.sigma`.
    fn band(&self, s: &mut BandScratch, y0: usize, rows: usize) {
        let (w, h, r, ext) = (self.w, self.h, self.r, self.ext);
        // Input rows needed, as positions y0 − r .. y0 + rows + r (wrapped or clipped).
        let lo = y0 as i64 - r as i64;
        let n_in = rows + 2 * r;
        s.pre.resize(n_in * ext, [0.0; 2]);
        s.valid.clear();
        s.valid.resize(n_in, false);
        s.mean.resize(rows * w, 0.0);
        s.sigma.resize(rows * w, 0.0);
        s.acc.resize(ROW_PAIR * TILE_COLS.min(w), [0.0; 2]);
        for k in 0..n_in {
            let pos = lo + k as i64;
            let y = match self.border {
                Border::Clip if pos < 0 || pos >= h as i64 => continue,
                Border::Clip => pos as usize,
                Border::Wrap => pos.rem_euclid(h as i64) as usize,
            };
            s.valid[k] = true;
            self.prefix_row(y, &mut s.pre[k * ext..(k + 1) * ext]);
        }
        // Covered texel counts per output row: `interior` away from the left/right borders, explicit for the r
        // columns at each border (the whole-disk values unless chord rows fall outside the map).
        let counts: Vec<(u64, Option<Vec<u64>>)> = (0..rows)
            .map(|oy| {
                let rows_valid = |i: usize| s.valid[oy + i];
                if (0..self.hws.len()).all(rows_valid) {
                    return (self.full_count, None);
                }
                let interior =
                    self.hws.iter().enumerate().filter(|&(i, _)| rows_valid(i)).map(|(_, &hw)| 2 * hw as u64 + 1).sum();
                debug_assert!(self.border == Border::Clip, "wrapped bands have every chord row");
                (interior, Some(edge_counts(&self.hws, w, r, rows_valid)))
            })
            .collect();
        // Tile columns so the prefix rows of a tile stay in cache across consecutive output rows.
        for x0 in (0..w).step_by(TILE_COLS) {
            let tw = TILE_COLS.min(w - x0);
            // Chord offsets within a prefix row (of the tile's first column): P(x + hw + 1), P(x − hw).
            s.offsets.clear();
            s.offsets.extend(self.hws.iter().map(|&hw| (x0 + r + hw as usize + 1, x0 + r - hw as usize)));
            for (oy, (interior, edge)) in counts.iter().enumerate() {
                if oy % ROW_PAIR == 0 {
                    // Two output rows share 2r of their 2r + 1 chord rows: summed together where both have them
                    // all (each prefix row is then read from L2 once for two rows).
                    let all = oy + ROW_PAIR <= rows && s.valid[oy..oy + ROW_PAIR + 2 * r].iter().all(|&v| v);
                    s.pair_ready = all;
                    if all {
                        let (acc, acc_next) = s.acc.split_at_mut(TILE_COLS.min(w));
                        accumulate_pair(&s.pre[oy * ext..], ext, &s.offsets, &mut acc[..tw], &mut acc_next[..tw]);
                    }
                }
                let pair_slot = oy % ROW_PAIR;
                let acc_len = TILE_COLS.min(w);
                if !s.pair_ready {
                    s.chords.clear();
                    for (i, &(hi, lo)) in s.offsets.iter().enumerate() {
                        let k = oy + i; // input position y0 + oy + i − r
                        if s.valid[k] {
                            s.chords.push((k * ext + hi, k * ext + lo));
                        }
                    }
                    accumulate(&s.pre, &s.chords, &mut s.acc[..tw]);
                }
                let acc =
                    if s.pair_ready { &s.acc[pair_slot * acc_len..pair_slot * acc_len + tw] } else { &s.acc[..tw] };
                let edge = match (self.border, edge) {
                    (Border::Wrap, _) => None,
                    (Border::Clip, Some(e)) => Some(e.as_slice()),
                    (Border::Clip, None) => Some(self.full_edge.as_slice()),
                };
                let out_m = &mut s.mean[oy * w + x0..oy * w + x0 + tw];
                let out_s = &mut s.sigma[oy * w + x0..oy * w + x0 + tw];
                // Interior columns share one count (a branch-free loop); the border columns take theirs.
                let (a, b) = match edge {
                    None => (x0, x0 + tw),
                    Some(_) => (x0.max(r).min(x0 + tw), (w - r).min(x0 + tw).max(x0.max(r).min(x0 + tw))),
                };
                finish(
                    &acc[a - x0..b - x0],
                    *interior as f64,
                    self.shift,
                    &mut out_m[a - x0..b - x0],
                    &mut out_s[a - x0..b - x0],
                );
                if let Some(edge) = edge {
                    for gx in (x0..a).chain(b..x0 + tw) {
                        let n = if gx < r { edge[gx] } else { edge[r + gx - (w - r)] } as f64;
                        let x = gx - x0;
                        finish(&acc[x..x + 1], n, self.shift, &mut out_m[x..x + 1], &mut out_s[x..x + 1]);
                    }
                }
            }
        }
    }
}

/// `fn $name(args)`: `$body(args)` compiled for AVX2 (the twin `$avx2`) where the CPU has it (detected at run time)
/// and the optional condition holds, else the baseline build. The bodies use only correctly rounded IEEE operations
/// in a fixed order (no FMA contraction), so both builds give the same bits; only the vector width differs.
macro_rules! avx2_dispatch {
    ($name:ident, $avx2:ident, $body:ident($($arg:ident: $ty:ty),* $(,)?) $(, if $when:expr)? $(,)?) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) {
            $body($($arg),*)
        }

        fn $name($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            if $($when &&)? std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU supports AVX2 (checked at run time).
                return unsafe { $avx2($($arg),*) };
            }
            $body($($arg),*)
        }
    };
}

/// μ = c + Σ/n, σ = sqrt(max(Σ²/n − (Σ/n)², 0)) of texels sharing the count `n`.
#[inline(always)]
fn finish_body(acc: &[[f64; 2]], n: f64, shift: f64, out_m: &mut [f64], out_s: &mut [f64]) {
    for ((a, m_out), s_out) in acc.iter().zip(out_m).zip(out_s) {
        let m = a[0] / n;
        let var = (a[1] / n - m * m).max(0.0);
        *m_out = shift + m;
        *s_out = var.sqrt();
    }
}

// [`finish_body`] compiled for AVX2 (correctly rounded division and square root: the same bits, four lanes), for
// rows of more than one texel.
avx2_dispatch!(
    finish,
    finish_avx2,
    finish_body(acc: &[[f64; 2]], n: f64, shift: f64, out_m: &mut [f64], out_s: &mut [f64]),
    if acc.len() > 1
);

/// `acc[x] = Σ_chords P(x + hw + 1) − P(x − hw)` for the tile's columns, chords in disk order: the O(r) inner
/// loop. `chords` holds each chord's two prefix offsets (of the tile's first column) in `pre`. Blocks of
/// [`BLOCK`] texels keep their sums in registers across all chords.
#[inline(always)]
fn accumulate_body(pre: &[[f64; 2]], chords: &[(usize, usize)], acc: &mut [[f64; 2]]) {
    let tw = acc.len();
    let mut x = 0;
    while x + BLOCK <= tw {
        let mut a = [[0.0f64; 2]; BLOCK];
        for &(hi, lo) in chords {
            add_chord(&mut a, pre, hi + x, lo + x);
        }
        acc[x..x + BLOCK].copy_from_slice(&a);
        x += BLOCK;
    }
    for (j, a) in acc.iter_mut().enumerate().skip(x) {
        *a = [0.0, 0.0];
        for &(hi, lo) in chords {
            a[0] += pre[hi + j][0] - pre[lo + j][0];
            a[1] += pre[hi + j][1] - pre[lo + j][1];
        }
    }
}

/// `a[j] += P(hi + j) − P(lo + j)` for the block's texels.
#[inline(always)]
fn add_chord(a: &mut [[f64; 2]; BLOCK], pre: &[[f64; 2]], hi: usize, lo: usize) {
    let p_hi: &[[f64; 2]; BLOCK] = pre[hi..hi + BLOCK].try_into().expect("block");
    let p_lo: &[[f64; 2]; BLOCK] = pre[lo..lo + BLOCK].try_into().expect("block");
    for j in 0..BLOCK {
        a[j][0] += p_hi[j][0] - p_lo[j][0];
        a[j][1] += p_hi[j][1] - p_lo[j][1];
    }
}

/// The sums of two consecutive output rows at once: `pre` starts at the first row's first chord row, every chord
/// row is valid, `offsets[i]` are the offsets of chord i (dy = i − r) within a row. Prefix row j carries chord j of
/// the first row and chord j − 1 of the second, so each is loaded once for both; each texel still adds its chords
/// in disk order (the same sums, bit for bit, as [`accumulate_body`]).
#[inline(always)]
fn accumulate_pair_body(
    pre: &[[f64; 2]],
    ext: usize,
    offsets: &[(usize, usize)],
    acc_a: &mut [[f64; 2]],
    acc_b: &mut [[f64; 2]],
) {
    let tw = acc_a.len();
    let n = offsets.len(); // 2r + 1
    let chord = |a: &mut [[f64; 2]; BLOCK], row: usize, (hi, lo): (usize, usize), x: usize| {
        add_chord(a, pre, row + hi + x, row + lo + x)
    };
    let mut x = 0;
    while x + BLOCK <= tw {
        let (mut a, mut b) = ([[0.0f64; 2]; BLOCK], [[0.0f64; 2]; BLOCK]);
        chord(&mut a, 0, offsets[0], x);
        for j in 1..n {
            chord(&mut a, j * ext, offsets[j], x);
            chord(&mut b, j * ext, offsets[j - 1], x);
        }
        chord(&mut b, n * ext, offsets[n - 1], x);
        acc_a[x..x + BLOCK].copy_from_slice(&a);
        acc_b[x..x + BLOCK].copy_from_slice(&b);
        x += BLOCK;
    }
    for (q, acc) in [acc_a, acc_b].into_iter().enumerate() {
        for (j, a) in acc.iter_mut().enumerate().skip(x) {
            *a = [0.0, 0.0];
            for (i, &(hi, lo)) in offsets.iter().enumerate() {
                let row = (q + i) * ext;
                a[0] += pre[row + hi + j][0] - pre[row + lo + j][0];
                a[1] += pre[row + hi + j][1] - pre[row + lo + j][1];
            }
        }
    }
}

// [`accumulate_pair_body`], AVX2 where the CPU has it.
avx2_dispatch!(
    accumulate_pair,
    accumulate_pair_avx2,
    accumulate_pair_body(
        pre: &[[f64; 2]],
        ext: usize,
        offsets: &[(usize, usize)],
        acc_a: &mut [[f64; 2]],
        acc_b: &mut [[f64; 2]],
    )
);

// [`accumulate_body`], AVX2 where the CPU has it.
avx2_dispatch!(
    accumulate,
    accumulate_avx2,
    accumulate_body(pre: &[[f64; 2]], chords: &[(usize, usize)], acc: &mut [[f64; 2]])
);

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference: visits every texel of the disk (O(r²) per texel) and uses the two-pass variance.
    fn brute_force(data: &[f32], (width, height): (u32, u32), radius: u32, border: Border) -> LocalStats {
        let (w, h, r) = (width as i64, height as i64, radius as i64);
        let mut mean = vec![0.0; (w * h) as usize];
        let mut sigma = vec![0.0; (w * h) as usize];
        let mut texels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                texels.clear();
                for dy in -r..=r {
                    for dx in -r..=r {
                        if dx * dx + dy * dy > r * r {
                            continue;
                        }
                        let (sx, sy) = (x + dx, y + dy);
                        let v = match border {
                            Border::Clip if sx < 0 || sy < 0 || sx >= w || sy >= h => continue,
                            Border::Clip => data[(sy * w + sx) as usize],
                            Border::Wrap => data[(sy.rem_euclid(h) * w + sx.rem_euclid(w)) as usize],
                        };
                        texels.push(v as f64);
                    }
                }
                let n = texels.len() as f64;
                let m = texels.iter().sum::<f64>() / n;
                let var = texels.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n;
                mean[(y * w + x) as usize] = m;
                sigma[(y * w + x) as usize] = var.sqrt();
            }
        }
        LocalStats { width, height, mean, sigma }
    }

    fn noise_map(w: u32, h: u32, seed: u32, offset: f32) -> Vec<f32> {
        let mut s = seed.wrapping_mul(2654435761).wrapping_add(1);
        (0..w * h)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                offset + (s % 10000) as f32 / 10000.0
            })
            .collect()
    }

    #[test]
    fn chord_half_widths_are_exact() {
        assert_eq!(chord_half_widths(1), vec![0, 1, 0]);
        assert_eq!(chord_half_widths(2), vec![0, 1, 2, 1, 0]);
        // r = 5: 3² + 4² = 5² is on the disk.
        let hw = chord_half_widths(5);
        assert_eq!(hw[5 + 3], 4);
        assert_eq!(hw[5 + 4], 3);
        assert_eq!(disk_texel_count(1), 5);
        assert_eq!(disk_texel_count(2), 13);
    }

    #[test]
    fn fast_matches_brute_force_clip_and_wrap() {
        // Includes maps wider than one cache tile (256 columns) and taller than one band (32 rows).
        for &(w, h, r) in
            &[(23u32, 17u32, 3u32), (16, 16, 7), (40, 9, 4), (5, 31, 2), (64, 64, 1), (300, 70, 6), (520, 13, 6)]
        {
            let data = noise_map(w, h, w * 31 + h, 0.0);
            for border in [Border::Clip, Border::Wrap] {
                let fast = disk_stats(&data, w, h, r, border).unwrap();
                let slow = brute_force(&data, (w, h), r, border);
                for i in 0..(w * h) as usize {
                    assert!((fast.mean[i] - slow.mean[i]).abs() < 1e-9, "{w}x{h} r={r} {border:?} mean at {i}");
                    assert!((fast.sigma[i] - slow.sigma[i]).abs() < 1e-9, "{w}x{h} r={r} {border:?} sigma at {i}");
                }
            }
        }
    }

    #[test]
    fn large_mean_does_not_cancel() {
        // Values 1e6 + [0, 1e-3): a naive E[H²] − E[H]² in f64 would lose every digit of the variance.
        let (w, h, r) = (24u32, 20u32, 4u32);
        let data: Vec<f32> = noise_map(w, h, 7, 0.0).iter().map(|v| 1.0e4 + v * 0.01).collect();
        let fast = disk_stats(&data, w, h, r, Border::Clip).unwrap();
        let slow = brute_force(&data, (w, h), r, Border::Clip);
        for i in 0..(w * h) as usize {
            assert!(slow.sigma[i] > 1e-3);
            assert!((fast.sigma[i] - slow.sigma[i]).abs() <= 1e-6 * slow.sigma[i], "sigma at {i}");
            assert!((fast.mean[i] - slow.mean[i]).abs() <= 1e-9 * slow.mean[i]);
        }
    }

    #[test]
    fn flat_map_has_zero_sigma_and_its_mean() {
        let data = vec![0.125f32; 30 * 20];
        for border in [Border::Clip, Border::Wrap] {
            let s = disk_stats(&data, 30, 20, 5, border).unwrap();
            assert!(s.mean.iter().all(|&m| m == 0.125));
            assert!(s.sigma.iter().all(|&v| v == 0.0));
        }
    }

    #[test]
    fn radius_is_validated() {
        let data = vec![0.0f32; 10 * 8];
        assert!(disk_stats(&data, 10, 8, 0, Border::Clip).is_err());
        assert!(disk_stats(&data, 10, 8, 4, Border::Clip).is_err());
        assert!(disk_stats(&data, 10, 8, 3, Border::Clip).is_ok());
        let e = check_radius("radius_texels", 9, 10, 8).unwrap_err();
        assert!(e.to_string().contains("radius_texels must be in 1..=3"), "{e}");
    }

    #[test]
    fn simd_dispatch_is_bit_identical_to_the_baseline_loop() {
        let (r, ext, rows) = (5usize, 40 + 11, 3usize);
        let n_in = rows + 2 * r;
        let vals = noise_map(ext as u32, n_in as u32 * 2, 9, -0.5);
        let pre: Vec<[f64; 2]> = vals.chunks(2).map(|p| [p[0] as f64 * 1e3, p[1] as f64]).collect();
        let hws = chord_half_widths(r as u32);
        for oy in 0..rows {
            // Every fourth chord row missing (clipped), tile widths with and without a scalar tail.
            let chords: Vec<(usize, usize)> = hws
                .iter()
                .enumerate()
                .filter(|&(i, _)| (oy + i) % 4 != 1)
                .map(|(i, &hw)| ((oy + i) * ext + r + hw as usize + 1, (oy + i) * ext + r - hw as usize))
                .collect();
            for tw in [40, 37, 5] {
                let (mut a, mut b) = (vec![[0.0; 2]; tw], vec![[0.0; 2]; tw]);
                accumulate(&pre, &chords, &mut a);
                accumulate_body(&pre, &chords, &mut b);
                assert!(a
                    .iter()
                    .zip(&b)
                    .all(|(x, y)| x[0].to_bits() == y[0].to_bits() && x[1].to_bits() == y[1].to_bits()));
                // The blocked sums are the plain per-texel sums in chord order.
                for (x, v) in b.iter().enumerate() {
                    let mut s = [0.0f64; 2];
                    for &(hi, lo) in &chords {
                        s[0] += pre[hi + x][0] - pre[lo + x][0];
                        s[1] += pre[hi + x][1] - pre[lo + x][1];
                    }
                    assert_eq!((s[0].to_bits(), s[1].to_bits()), (v[0].to_bits(), v[1].to_bits()));
                }
            }
        }
    }

    #[test]
    fn pair_of_rows_equals_each_row_alone_bit_for_bit() {
        let (r, ext) = (4usize, 37 + 9);
        let vals = noise_map(ext as u32, (2 * r + 2) as u32 * 2, 5, -0.25);
        let pre: Vec<[f64; 2]> = vals.chunks(2).map(|p| [p[0] as f64 * 1e2, p[1] as f64]).collect();
        let offsets: Vec<(usize, usize)> =
            chord_half_widths(r as u32).iter().map(|&hw| (r + hw as usize + 1, r - hw as usize)).collect();
        for tw in [37usize, 16, 3] {
            let (mut a, mut b) = (vec![[0.0; 2]; tw], vec![[0.0; 2]; tw]);
            accumulate_pair(&pre, ext, &offsets, &mut a, &mut b);
            for (q, got) in [a, b].iter().enumerate() {
                let chords: Vec<(usize, usize)> =
                    offsets.iter().enumerate().map(|(i, &(hi, lo))| ((q + i) * ext + hi, (q + i) * ext + lo)).collect();
                let mut want = vec![[0.0; 2]; tw];
                accumulate_body(&pre, &chords, &mut want);
                assert!(got
                    .iter()
                    .zip(&want)
                    .all(|(x, y)| x[0].to_bits() == y[0].to_bits() && x[1].to_bits() == y[1].to_bits()));
            }
        }
    }

    #[test]
    fn same_bytes_for_any_thread_count() {
        let (w, h) = (70u32, 150u32);
        let data = noise_map(w, h, 3, 0.5);
        let a = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let b = rayon::ThreadPoolBuilder::new().num_threads(4).build().unwrap();
        let sa = a.install(|| disk_stats(&data, w, h, 6, Border::Clip).unwrap());
        let sb = b.install(|| disk_stats(&data, w, h, 6, Border::Clip).unwrap());
        assert_eq!(sa, sb);
    }
}
