//! SMAA search texture (thesis ch. 10, § 10.4.2 "Accurate distances search", eqs. 10.4–10.5; Jimenez et al.,
//! *SMAA: Enhanced Subpixel Morphological Antialiasing*, Computer Graphics Forum 31(2), Eurographics 2012).
//!
//! In the last step of an orthogonal search the shader fetches the edges texture bilinearly at `(−0.25, −0.125)`
//! from the pixel, mixing four edge bits (e0 top-left, e1 top-right, e2 bottom-left, e3 bottom-right) into one value
//! `f_xy = (1·e0 + 3·e1 + 7·e2 + 21·e3)/32` (eq. 10.5 with `x = 0.75`, `y = 0.875`); the 16 combinations give distinct
//! multiples of 1/32, so one fetch of the R ("left"/crossing) and G ("top"/edge) channels identifies eight bits.
//! The table answers how many extra pixels (0, 1 or 2) the search must add.
//!
//! Logical table 66 × 33: `x = 32·R` (left search in columns 0..33, right search at `x + 33`), `y = 32·G`; only
//! texels whose coordinates both decode are set. The shipped texture (64 × 16, R8) keeps rows 17..=32 and columns
//! 0..64 of the table storing `127·d` and flips it vertically (output row `r` = logical row `32 − r`; the shader
//! compensates). The v2.8 texture is the logical table storing `d` itself, uncropped and unflipped.

use crate::image_buf::Image;

/// Width and height of the logical table.
pub const LOGICAL_WIDTH: u32 = 66;
pub const LOGICAL_HEIGHT: u32 = 33;
/// Size of the shipped (cropped) texture, `SEARCHTEX_WIDTH`/`SEARCHTEX_HEIGHT`.
pub const SEARCHTEX_WIDTH: u32 = 64;
pub const SEARCHTEX_HEIGHT: u32 = 16;
/// First logical row kept by the crop.
pub const CROP_FIRST_ROW: u32 = 17;

/// Four edge bits `[e0 top-left, e1 top-right, e2 bottom-left, e3 bottom-right]`.
pub type Edges = [bool; 4];

/// 32 × the bilinear fetch of four edge bits at offset `(−0.25, −0.125)` (eq. 10.5): `e0 + 3·e1 + 7·e2 + 21·e3`.
pub fn bilinear_x32(e: Edges) -> u32 {
    e[0] as u32 + 3 * e[1] as u32 + 7 * e[2] as u32 + 21 * e[3] as u32
}

/// The four edge bits whose fetch equals `k/32`, if any (`k ∈ 0..=32`).
pub fn decode(k: u32) -> Option<Edges> {
    (0..16u32).map(|b| [b & 1 != 0, b & 2 != 0, b & 4 != 0, b & 8 != 0]).find(|&e| bilinear_x32(e) == k)
}

/// Extra pixels for a search to the left: 1 if `top.e3`; 2 if also `top.e2` and neither `left.e1` nor `left.e3`.
pub fn delta_left(left: Edges, top: Edges) -> u8 {
    let mut d = 0;
    if top[3] {
        d = 1;
    }
    if d == 1 && top[2] && !left[1] && !left[3] {
        d = 2;
    }
    d
}

/// Extra pixels for a search to the right: 1 if `top.e3` and neither `left.e1` nor `left.e3`; 2 if also `top.e2`
/// and neither `left.e0` nor `left.e2`.
pub fn delta_right(left: Edges, top: Edges) -> u8 {
    let mut d = 0;
    if top[3] && !left[1] && !left[3] {
        d = 1;
    }
    if d == 1 && top[2] && !left[0] && !left[2] {
        d = 2;
    }
    d
}

/// The 66 × 33 logical table storing `scale·d` (`scale` 1: v2.8 texture; 127: before crop and flip).
pub fn logical_table(scale: u8) -> Image<u8> {
    let mut img = Image::<u8>::new(LOGICAL_WIDTH, LOGICAL_HEIGHT, 1);
    for x in 0..33 {
        for y in 0..33 {
            if let (Some(left), Some(top)) = (decode(x), decode(y)) {
                img.set(x, y, 0, scale * delta_left(left, top));
                img.set(x + 33, y, 0, scale * delta_right(left, top));
            }
        }
    }
    img
}

/// The shipped 64 × 16 R8 search texture (crop of the 127-scaled table, flipped top to bottom).
pub fn search_texture() -> Image<u8> {
    let logical = logical_table(127);
    let mut img = Image::<u8>::new(SEARCHTEX_WIDTH, SEARCHTEX_HEIGHT, 1);
    for r in 0..SEARCHTEX_HEIGHT {
        let src = LOGICAL_HEIGHT - 1 - r;
        debug_assert!(src >= CROP_FIRST_ROW);
        img.row_mut(r).copy_from_slice(&logical.row(src)[..SEARCHTEX_WIDTH as usize]);
    }
    img
}

/// The v2.8 search texture: the 66 × 33 logical table storing 0/1/2.
pub fn search_texture_v2_8() -> Image<u8> {
    logical_table(1)
}

/// The 66 × 33 logical table storing 0/127/254 (before crop and flip; for debugging).
pub fn search_texture_logical_precrop() -> Image<u8> {
    logical_table(127)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_decode_values_are_distinct_multiples_of_1_32() {
        let mut seen = std::collections::BTreeSet::new();
        for b in 0..16u32 {
            let e = [b & 1 != 0, b & 2 != 0, b & 4 != 0, b & 8 != 0];
            // eq. 10.5 evaluated as the hardware does: lerp(lerp(e0, e1, 0.75), lerp(e2, e3, 0.75), 0.875).
            let f = |v: bool| v as u8 as f64;
            let a = f(e[0]) + (f(e[1]) - f(e[0])) * 0.75;
            let c = f(e[2]) + (f(e[3]) - f(e[2])) * 0.75;
            let v = a + (c - a) * 0.875;
            assert_eq!(v * 32.0, bilinear_x32(e) as f64, "{e:?}");
            assert_eq!(decode(bilinear_x32(e)), Some(e));
            seen.insert(bilinear_x32(e));
        }
        assert_eq!(seen.len(), 16);
        assert_eq!((0..=32).filter(|&k| decode(k).is_some()).count(), 16);
    }

    #[test]
    fn crop_drops_only_zeros() {
        let t = logical_table(127);
        for y in 0..LOGICAL_HEIGHT {
            for x in 0..LOGICAL_WIDTH {
                if y < CROP_FIRST_ROW || x >= SEARCHTEX_WIDTH {
                    assert_eq!(t.get(x, y, 0), 0, "({x},{y}) dropped by the crop must be zero");
                }
            }
        }
        let s = search_texture();
        assert_eq!(s.get(0, 0, 0), t.get(0, 32, 0));
        assert_eq!(s.get(5, 15, 0), t.get(5, 17, 0));
        assert!(s.data.iter().all(|&v| v == 0 || v == 127 || v == 254));
    }

    #[test]
    fn deltas_follow_the_rules() {
        let none = [false; 4];
        let top_e3 = [false, false, false, true];
        let top_e23 = [false, false, true, true];
        assert_eq!(delta_left(none, none), 0);
        assert_eq!(delta_left(none, top_e3), 1);
        assert_eq!(delta_left(none, top_e23), 2);
        assert_eq!(delta_left([false, true, false, false], top_e23), 1);
        assert_eq!(delta_right([false, false, false, true], top_e3), 0);
        assert_eq!(delta_right([true, false, false, false], top_e23), 1);
        assert_eq!(delta_right(none, top_e23), 2);
    }
}
