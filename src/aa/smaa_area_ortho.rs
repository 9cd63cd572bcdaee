//! SMAA orthogonal coverage areas: the left half (columns `0..5·n`) of the SMAA area texture.
//!
//! J. Jimenez, J. I. Echevarria, T. Sousa, D. Gutierrez, *SMAA: Enhanced Subpixel Morphological Antialiasing*,
//! Computer Graphics Forum (Proc. Eurographics) 31(2), 2012 — thesis ch. 10, § 10.4.2–10.4.3. The revectorisation
//! is Jimenez's MLAA (GPU Pro 2, 2011; thesis § 9.4.3) with two SMAA additions: subsample offsets (§ 10.4.3,
//! Fig. 10.11: the line ends are moved by the subsample's vertical offset so that the subsample groups average to the
//! pixel centre) and, since SMAA 2.8, smoothing of short U shapes.
//!
//! Frame (per edge): the edge lies on `y = 0` from `x = 0` to
//! `x = d = left + right + 1`, the current pixel spans `x ∈ [left, left + 1]`. A crossing edge of type 1 puts the line
//! end at height `o1 = 0.5 + offset`, type 3 at `o2 = offset − 0.5`. The revectorised line passes through `(d/2, 0)`.
//! The area of the line over the pixel is returned as `(R, G)` = (area on the negative side, area on the positive
//! side).
//!
//! Every expression below keeps the floating-point evaluation order that produced the published bytes (f64, no fused
//! multiply-add).

/// Distance (pixels) over which short U shapes are smoothed towards the plain revectorisation (SMAA 2.8+).
pub const SMOOTH_MAX_DISTANCE: f64 = 32.0;

/// Crossing-edge type at one end of an orthogonal line: 0 none, 1 (up), 3 (down), 4 both ("+").
pub type EdgeType = u8;

/// Orthogonal end types indexed by cell coordinate: `(e1, e2) ∈ {0, 1, 3, 4}²`.
pub const ORTHO_EDGE_TYPES: [EdgeType; 4] = [0, 1, 3, 4];

/// Cell coordinates `(e1, e2)` of orthogonal pattern `p` (four crossing-edge bits): `e1 = 3·bit0 + bit2`,
/// `e2 = 3·bit1 + bit3`.
pub fn ortho_cell(pattern: u8) -> (EdgeType, EdgeType) {
    let bit = |k: u8| (pattern >> k) & 1;
    (3 * bit(0) + bit(2), 3 * bit(1) + bit(3))
}

/// A point of the edge frame (pixels).
type Pt = (f64, f64);

/// `(R, G)` coverage pair.
pub type Area2 = (f64, f64);

fn add(a: Area2, b: Area2) -> Area2 {
    (a.0 + b.0, a.1 + b.1)
}

/// Area of the segment `p1 → p2` over the pixel `[x, x + 1]` as `(negative side, positive side)`.
pub fn segment_area(p1: Pt, p2: Pt, x: f64) -> Area2 {
    let dx = p2.0 - p1.0;
    let dy = p2.1 - p1.1;
    let x1 = x;
    let x2 = x + 1.0;
    // The unclipped line at both pixel borders.
    let y1 = p1.1 + dy * (x1 - p1.0) / dx;
    let y2 = p1.1 + dy * (x2 - p1.0) / dx;

    let inside = (x1 >= p1.0 && x1 < p2.0) || (x2 > p1.0 && x2 <= p2.0);
    if !inside {
        return (0.0, 0.0);
    }
    // Same sign (signed zeros count by their sign bit) or a border height near zero: one trapezoid.
    let trapezoid = y1.is_sign_negative() == y2.is_sign_negative() || y1.abs() < 1e-4 || y2.abs() < 1e-4;
    if trapezoid {
        let a = (y1 + y2) / 2.0;
        return if a < 0.0 { (a.abs(), 0.0) } else { (0.0, a.abs()) };
    }
    // The line crosses y = 0 inside the pixel: two triangles on opposite sides.
    let xc = -p1.1 * dx / dy + p1.0;
    let f = xc.fract();
    let a1 = if xc > p1.0 { y1 * f / 2.0 } else { 0.0 };
    let a2 = if xc < p2.0 { y2 * (1.0 - f) / 2.0 } else { 0.0 };
    let dominant = if a1.abs() > a2.abs() { a1 } else { -a2 };
    if dominant < 0.0 {
        (a1.abs(), a2.abs())
    } else {
        (a2.abs(), a1.abs())
    }
}

/// U-shape smoothing of one half (SMAA 2.8+): `b = sqrt(2a)/2`, `p = clamp(d/32, 0, 1)`, `b + (a − b)·p`.
pub fn smooth_u_half(d: f64, a: Area2) -> Area2 {
    let p = (d / SMOOTH_MAX_DISTANCE).clamp(0.0, 1.0);
    let one = |a: f64| {
        let b = (a * 2.0).sqrt() * 0.5;
        b + (a - b) * p
    };
    (one(a.0), one(a.1))
}

/// Coverage `(R, G)` of the current pixel for orthogonal pattern cell `(e1, e2)`, distances `left`/`right` (pixels)
/// and subsample `offset` (pixels, vertical). `u_smoothing` selects the SMAA 2.8+ U-shape smoothing.
pub fn ortho_area(e1: EdgeType, e2: EdgeType, left: u32, right: u32, offset: f64, u_smoothing: bool) -> Area2 {
    let d = (left + right + 1) as f64;
    let x = left as f64;
    let o1 = 0.5 + offset;
    let o2 = 0.5 + offset - 1.0;
    let mid: Pt = (d / 2.0, 0.0);
    let area = |p1: Pt, p2: Pt| segment_area(p1, p2, x);
    // Z with blending: mean of the full line and of its two halves through the midpoint (only for offset ≠ 0).
    let z_blend = |a: f64, b: f64| {
        if offset.abs() > 0.0 {
            let full = area((0.0, a), (d, b));
            let halves = add(area((0.0, a), mid), area(mid, (d, b)));
            ((full.0 + halves.0) / 2.0, (full.1 + halves.1) / 2.0)
        } else {
            area((0.0, a), (d, b))
        }
    };
    // U: both halves, each optionally smoothed, summed per channel.
    let u_shape = |o: f64| {
        let h1 = area((0.0, o), mid);
        let h2 = area(mid, (d, o));
        let (h1, h2) = if u_smoothing { (smooth_u_half(d, h1), smooth_u_half(d, h2)) } else { (h1, h2) };
        add(h1, h2)
    };
    match (e1, e2) {
        // L shapes: only the half nearer the crossing edge.
        (3, 0) if left <= right => area((0.0, o2), mid),
        (1, 0) if left <= right => area((0.0, o1), mid),
        (0, 3) if left >= right => area(mid, (d, o2)),
        (0, 1) if left >= right => area(mid, (d, o1)),
        // Z shapes; a "+" end acts as the complement of the other end.
        (4, 3) | (1, 4) => area((0.0, o1), (d, o2)),
        (3, 4) | (4, 1) => area((0.0, o2), (d, o1)),
        (1, 3) => z_blend(o1, o2),
        (3, 1) => z_blend(o2, o1),
        // U shapes.
        (3, 3) => u_shape(o2),
        (1, 1) => u_shape(o1),
        _ => (0.0, 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_bits_map_to_cells() {
        assert_eq!(ortho_cell(0), (0, 0));
        assert_eq!(ortho_cell(1), (3, 0));
        assert_eq!(ortho_cell(4), (1, 0));
        assert_eq!(ortho_cell(6), (1, 3));
        assert_eq!(ortho_cell(15), (4, 4));
        let mut cells: Vec<_> = (0..16).map(ortho_cell).collect();
        cells.sort();
        cells.dedup();
        assert_eq!(cells.len(), 16, "16 patterns, 16 distinct cells, none in row/column 2");
        assert!(cells.iter().all(|&(a, b)| a != 2 && b != 2));
    }

    #[test]
    fn full_pixel_under_flat_line_is_its_height() {
        // Horizontal line at height 0.3 over the whole pixel: positive area 0.3.
        let a = segment_area((0.0, 0.3), (4.0, 0.3), 1.0);
        assert!((a.1 - 0.3).abs() < 1e-15 && a.0 == 0.0);
        // Outside the segment: nothing.
        assert_eq!(segment_area((0.0, 0.3), (1.0, 0.3), 2.0), (0.0, 0.0));
    }

    #[test]
    fn zero_crossing_splits_into_two_triangles() {
        // Line from (0, -0.75) to (3, 0.75) over pixel [1, 2]: crosses at x = 1.5; triangles of 1/16 each side.
        let a = segment_area((0.0, -0.75), (3.0, 0.75), 1.0);
        assert!((a.0 - 0.0625).abs() < 1e-15 && (a.1 - 0.0625).abs() < 1e-15, "{a:?}");
    }

    #[test]
    fn symmetric_u_is_mirror_symmetric_and_smoothing_only_touches_short_u() {
        for left in 0..20u32 {
            for right in 0..20u32 {
                let a = ortho_area(1, 1, left, right, 0.0, false);
                let b = ortho_area(1, 1, right, left, 0.0, false);
                assert!((a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12, "U({left},{right})");
                let d = left + right + 1;
                let s = ortho_area(1, 1, left, right, 0.0, true);
                if d >= 32 {
                    // b + (a − b)·1 is a up to one rounding.
                    assert!((s.0 - a.0).abs() < 1e-15 && (s.1 - a.1).abs() < 1e-15, "no smoothing from d = 32 on");
                } else if a.1 > 0.0 && a.1 < 0.5 {
                    // sqrt(2a)/2 > a for 0 < a < 1/2: smoothing raises short-U coverage.
                    assert!(s.1 > a.1, "U({left},{right}): {s:?} vs {a:?}");
                }
            }
        }
    }

    #[test]
    fn l_shape_uses_only_the_near_half_and_plus_ends_complement() {
        assert_eq!(ortho_area(3, 0, 5, 2, 0.0, true), (0.0, 0.0));
        assert!(ortho_area(3, 0, 2, 5, 0.0, true).0 > 0.0);
        assert_eq!(ortho_area(4, 3, 3, 7, 0.25, true), ortho_area(1, 4, 3, 7, 0.25, true));
        for (e1, e2) in [(0, 0), (4, 0), (0, 4), (4, 4)] {
            assert_eq!(ortho_area(e1, e2, 1, 2, 0.0, true), (0.0, 0.0));
        }
    }
}
