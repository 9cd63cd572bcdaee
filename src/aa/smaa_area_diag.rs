//! SMAA diagonal coverage areas: the right half (columns `5·n_ortho..`) of the SMAA area texture.
//!
//! J. Jimenez, J. I. Echevarria, T. Sousa, D. Gutierrez, *SMAA: Enhanced Subpixel Morphological Antialiasing*,
//! Computer Graphics Forum (Proc. Eurographics) 31(2), 2012 — thesis ch. 10, § 10.4.2 "Diagonal patterns",
//! Fig. 10.8. Coverage is estimated by brute-force supersampling, as in the reference generator:
//!
//! * a line runs from `S` to `E + (d, d)`, `d = left + right + 1`; the subsample offset is added to `S` only if
//!   `e1 > 0` and to the end only if `e2 > 0`;
//! * the pixel with corner `P` is sampled at `P + (i/29, j/29)`, `i, j ∈ 0..30` (closed unit square); a sample is
//!   inside when `(p2.y − p1.y)·(x − xm) + (p1.x − p2.x)·(y − ym) > 0`, `m` the segment midpoint;
//! * texel `(R, G) = (1 − A, B)` with `A` the coverage at `P = (1 + left, left)` and `B` at `P = (1 + left, 1 + left)`;
//!   patterns with two candidate lines average them.
//!
//! **Exact fast counting.** The half-plane value of sample `(i, j)` is `ax[i] + by[j]` with
//! `ax[i] = a·((P.x + i/29) − xm)` and `by[j] = b·((P.y + j/29) − ym)`, each product computed exactly as the
//! reference computes it. The rounded sum of two doubles is positive iff the exact sum is (round-to-nearest keeps the
//! sign and a non-zero sum of doubles is never below the smallest subnormal), so `ax[i] + by[j] > 0` iff
//! `by[j] > −ax[i]`. Both lists are monotone in their index (every rounded operation is monotone), so one merge
//! over the two sorted lists gives the same count as the 900 tests, bit for bit, in about 60 comparisons
//! (`tests::fast_count_equals_brute_force`). [`diag_areas_all_patterns`] also evaluates each distinct line once per
//! texel instead of once per pattern.

use super::smaa_area_ortho::Area2;

/// Samples per axis of the brute-force coverage estimate (30 × 30 per pixel).
pub const SAMPLES_DIAG: usize = 30;

/// Crossing-edge type at one end of a diagonal line, `0..=3`.
pub type DiagEdge = u8;

/// Cell coordinates `(e1, e2)` of diagonal pattern `p`: `e1 = bit0 + 2·bit2`, `e2 = 2·bit1 + bit3`.
pub fn diag_cell(pattern: u8) -> (DiagEdge, DiagEdge) {
    let bit = |k: u8| (pattern >> k) & 1;
    (bit(0) + 2 * bit(2), 2 * bit(1) + bit(3))
}

/// Inverse of [`diag_cell`].
pub fn diag_pattern(e1: DiagEdge, e2: DiagEdge) -> u8 {
    (e1 & 1) | ((e2 >> 1) & 1) << 1 | ((e1 >> 1) & 1) << 2 | (e2 & 1) << 3
}

type Pt = (f64, f64);

/// Start/end points of the candidate lines (before the end gets `+ (d, d)`): `A = (1, 1)`, `B = (1, 0)`, `O = (0, 0)`.
const POINTS: [Pt; 3] = [(1.0, 1.0), (1.0, 0.0), (0.0, 0.0)];
const A: u8 = 0;
const B: u8 = 1;
const O: u8 = 2;

/// Candidate lines `(S, E)` of each diagonal pattern (indexed by pattern number; Fig. 10.8, four patterns a row) as
/// indices into [`POINTS`]; one line, or two that are averaged.
#[rustfmt::skip]
const CANDIDATES: [&[(u8, u8)]; 16] = [
    /*  0 */ &[(A, A), (B, B)], /*  1 */ &[(B, O), (B, B)], /*  2 */ &[(O, B), (B, B)], /*  3 */ &[(B, B)],
    /*  4 */ &[(A, O), (A, B)], /*  5 */ &[(A, O), (B, B)], /*  6 */ &[(A, B)],         /*  7 */ &[(A, B), (B, B)],
    /*  8 */ &[(O, A), (B, A)], /*  9 */ &[(B, A)],         /* 10 */ &[(O, A), (B, B)], /* 11 */ &[(B, A), (B, B)],
    /* 12 */ &[(A, A)],         /* 13 */ &[(A, A), (B, A)], /* 14 */ &[(A, A), (A, B)], /* 15 */ &[(A, A), (B, B)],
];

/// The candidate lines of diagonal pattern `pattern` (`0..16`).
fn candidates(pattern: u8) -> &'static [(u8, u8)] {
    CANDIDATES[pattern as usize]
}

/// Sample positions `base + i/29` of one pixel axis.
fn axis(base: f64) -> [f64; SAMPLES_DIAG] {
    std::array::from_fn(|i| base + i as f64 / (SAMPLES_DIAG - 1) as f64)
}

/// `k·(v − mid)` for the 30 sample positions of one axis, in ascending order. Each rounded operation is monotone
/// in its argument, so the sequence is monotone in the sample index: increasing for `k ≥ 0`, else reversed.
fn terms(k: f64, base: f64, mid: f64) -> [f64; SAMPLES_DIAG] {
    let v = axis(base);
    let mut t: [f64; SAMPLES_DIAG] = std::array::from_fn(|i| k * (v[i] - mid));
    if k < 0.0 {
        t.reverse();
    }
    debug_assert!(t.windows(2).all(|w| w[0] <= w[1]));
    t
}

/// The half-plane test of line `p1 → p2` as the reference generator writes it: a point is inside when
/// `a·(x − xm) + b·(y − ym) > 0` with `a = p2.y − p1.y`, `b = p1.x − p2.x` and `m` the segment midpoint. Returns
/// `(m, a, b)`, each rounded as the reference rounds it.
fn half_plane(p1: Pt, p2: Pt) -> (Pt, f64, f64) {
    let xm = (p1.0 + p2.0) / 2.0;
    let ym = (p1.1 + p2.1) / 2.0;
    ((xm, ym), p2.1 - p1.1, p1.0 - p2.0)
}

/// Fraction of the 30×30 samples of the pixel with corner `p` strictly on the positive side of `p1 → p2`
/// (1 when the points coincide). Counts `ax[i] + by[j] > 0` ⟺ `by[j] > −ax[i]` with a merge over the two sorted
/// term lists (see the module docs): identical to [`pixel_coverage_brute_force`].
pub fn pixel_coverage(p1: Pt, p2: Pt, p: Pt) -> f64 {
    if p1 == p2 {
        return 1.0;
    }
    let ((xm, ym), a, b) = half_plane(p1, p2);
    let ax = terms(a, p.0, xm);
    let by = terms(b, p.1, ym);
    // For ascending ax the threshold −ax falls, so k = #{j : by[j] ≤ −ax[i]} only decreases.
    let mut k = SAMPLES_DIAG;
    let mut count = 0usize;
    for &x in &ax {
        let t = -x;
        while k > 0 && by[k - 1] > t {
            k -= 1;
        }
        count += SAMPLES_DIAG - k;
    }
    count as f64 / (SAMPLES_DIAG * SAMPLES_DIAG) as f64
}

/// Reference implementation: the 900 half-plane tests one by one.
pub fn pixel_coverage_brute_force(p1: Pt, p2: Pt, p: Pt) -> f64 {
    if p1 == p2 {
        return 1.0;
    }
    let ((xm, ym), a, b) = half_plane(p1, p2);
    let mut count = 0usize;
    for i in 0..SAMPLES_DIAG {
        for j in 0..SAMPLES_DIAG {
            let x = p.0 + i as f64 / (SAMPLES_DIAG - 1) as f64;
            let y = p.1 + j as f64 / (SAMPLES_DIAG - 1) as f64;
            if a * (x - xm) + b * (y - ym) > 0.0 {
                count += 1;
            }
        }
    }
    count as f64 / (SAMPLES_DIAG * SAMPLES_DIAG) as f64
}

/// End points of candidate line `(s, e)`: `S`, `E + (d, d)`, each moved by `offset` if its flag is set.
fn line_points(s: u8, e: u8, offset_start: bool, offset_end: bool, d: f64, offset: Pt) -> (Pt, Pt) {
    let mut p1 = POINTS[s as usize];
    let e = POINTS[e as usize];
    let mut p2 = (e.0 + d, e.1 + d);
    if offset_start {
        p1 = (p1.0 + offset.0, p1.1 + offset.1);
    }
    if offset_end {
        p2 = (p2.0 + offset.0, p2.1 + offset.1);
    }
    (p1, p2)
}

/// `(1 − A, B)` of one line: `A` coverage at `(1 + left, left)`, `B` at `(1 + left, 1 + left)`.
fn line_area((p1, p2): (Pt, Pt), left: u32) -> Area2 {
    let l = left as f64;
    let a1 = pixel_coverage(p1, p2, (1.0 + l, 0.0 + l));
    let a2 = pixel_coverage(p1, p2, (1.0 + l, 1.0 + l));
    (1.0 - a1, a2)
}

fn average(lines: &[Area2]) -> Area2 {
    match *lines {
        [one] => one,
        [a, b] => ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0),
        _ => unreachable!("one or two candidate lines per pattern"),
    }
}

/// Coverage `(R, G)` of diagonal pattern cell `(e1, e2)` (each `0..=3`) at distances `left`/`right` (pixels) for the
/// subsample `offset = (x, y)` (pixels).
pub fn diag_area(e1: DiagEdge, e2: DiagEdge, left: u32, right: u32, offset: (f64, f64)) -> Area2 {
    let d = (left + right + 1) as f64;
    let areas: Vec<Area2> = candidates(diag_pattern(e1, e2))
        .iter()
        .map(|&(s, e)| line_area(line_points(s, e, e1 > 0, e2 > 0, d, offset), left))
        .collect();
    average(&areas)
}

/// [`diag_area`] for all 16 patterns at once (indexed by pattern number), evaluating each distinct line once:
/// the 28 candidate lines of the 16 patterns are only 14 distinct ones (8 for a zero offset).
pub fn diag_areas_all_patterns(left: u32, right: u32, offset: (f64, f64)) -> [Area2; 16] {
    let d = (left + right + 1) as f64;
    // Key: (start point, start offset flag, end point, end offset flag).
    let mut cache: [[Option<Area2>; 6]; 6] = [[None; 6]; 6];
    std::array::from_fn(|p| {
        let (e1, e2) = diag_cell(p as u8);
        let lines = candidates(p as u8);
        let mut areas = [(0.0, 0.0); 2];
        for (slot, &(s, e)) in areas.iter_mut().zip(lines) {
            let (fs, fe) = (e1 > 0, e2 > 0);
            let entry = &mut cache[2 * s as usize + fs as usize][2 * e as usize + fe as usize];
            *slot = *entry.get_or_insert_with(|| line_area(line_points(s, e, fs, fe, d, offset), left));
        }
        average(&areas[..lines.len()])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_round_trip_and_are_distinct() {
        for p in 0..16u8 {
            let (e1, e2) = diag_cell(p);
            assert!(e1 < 4 && e2 < 4);
            assert_eq!(diag_pattern(e1, e2), p);
        }
        assert_eq!(diag_cell(1), (1, 0));
        assert_eq!(diag_cell(2), (0, 2));
        assert_eq!(diag_cell(4), (2, 0));
        assert_eq!(diag_cell(8), (0, 1));
    }

    #[test]
    fn fast_count_equals_brute_force() {
        // Every line and pixel the default texture evaluates for small distances, plus offsets putting many
        // samples exactly on the line (45° lines through sample points).
        let offsets = [(0.0, 0.0), (0.25, -0.25), (-0.25, 0.25), (0.125, -0.125), (-0.125, 0.125), (0.5, 0.5)];
        let mut n = 0;
        for p in 0..16u8 {
            let (e1, e2) = diag_cell(p);
            for &(s, e) in candidates(p) {
                for left in 0..6u32 {
                    for right in 0..6u32 {
                        let d = (left + right + 1) as f64;
                        for &o in &offsets {
                            let (p1, p2) = line_points(s, e, e1 > 0, e2 > 0, d, o);
                            for py in [left as f64, left as f64 + 1.0] {
                                let px = (1.0 + left as f64, py);
                                let fast = pixel_coverage(p1, p2, px);
                                let slow = pixel_coverage_brute_force(p1, p2, px);
                                assert_eq!(fast.to_bits(), slow.to_bits(), "{p1:?}->{p2:?} at {px:?}");
                                n += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(n > 10_000);
    }

    #[test]
    fn all_patterns_at_once_equals_one_by_one() {
        for (left, right) in [(0, 0), (3, 7), (19, 19), (12, 2)] {
            for o in [(0.0, 0.0), (0.25, -0.25), (-0.125, 0.125)] {
                let all = diag_areas_all_patterns(left, right, o);
                for p in 0..16u8 {
                    let (e1, e2) = diag_cell(p);
                    assert_eq!(all[p as usize], diag_area(e1, e2, left, right, o), "p {p} ({left},{right}) {o:?}");
                }
            }
        }
    }

    #[test]
    fn coverage_of_exact_diagonal_counts_strict_side_only() {
        // The 45° line through the pixel corner (0,0)-(1,1): samples with x > y... the positive side of
        // (0,0)->(2,2) is a·(x − xm) + b·(y − ym) = 2(x − 1) − 2(y − 1) > 0, i.e. x > y: 435 of 900 samples.
        let c = pixel_coverage_brute_force((0.0, 0.0), (2.0, 2.0), (0.0, 0.0));
        assert_eq!(c, 435.0 / 900.0);
        assert_eq!(pixel_coverage((0.0, 0.0), (2.0, 2.0), (0.0, 0.0)), c);
        assert_eq!(pixel_coverage((1.0, 1.0), (1.0, 1.0), (3.0, 0.0)), 1.0);
    }
}
