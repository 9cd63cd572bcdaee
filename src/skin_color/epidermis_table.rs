//! The epidermis' multipole totals tabulated against √σa, and the vectorised row loop of the skin-colour table.
//!
//! Donner & Jensen, "Light Diffusion in Multi-Layered Translucent Materials", SIGGRAPH 2005 (exact-series totals
//! R̂(0), T̂(0) of a slab) and their adding at k = 0 (symmetric, as printed):
//!
//! ```text
//! R = R1 + T1² R2 / (1 − R1 R2)
//! ```
//!
//! tabulated as in the thesis' skin-colour table (Jimenez 2012, §7.6, Fig. 7.9): every node value of an
//! [`EpidermisTable`] is `Slab::totals(Series::Exact)` at σa = y², y on a uniform grid of [`TABLE_INTERVALS`]
//! intervals; between nodes the 4-point Lagrange cubic through the nodes k − 1 … k + 2 around y is evaluated, stored
//! per interval in the power basis of the local coordinate t ∈ `[0, 1)`:
//!
//! ```text
//! p(t) = c0 + t (c1 + t (c2 + t c3))
//! c0 = f0,  c1 = f1 − f₋₁/3 − f0/2 − f2/6,  c2 = (f₋₁ + f1)/2 − f0,  c3 = (f2 − f₋₁)/6 + (f0 − f1)/2
//! ```
//!
//! (the same polynomial as the Lagrange form, three multiply-adds per value, no division). √σa is the natural
//! variable: the totals depend on σa through σtr = √(3σaσt′), smoothly down to σa = 0, and a square root is far
//! cheaper than a logarithm. Interpolation error ≈ 0.023 h⁴ max|f⁗| with h ≈ 0.025 mm^−½ (≈ 1e−8 in R); over the
//! whole default 256² table the tabulated and direct results differ by at most 6e−8 in linear RGB, i.e. f32 rounding
//! (`examples/bench_skin.rs` prints it; `tests/it/skin_color.rs` bounds it).
//!
//! The table's inner loop (`accumulate_symmetric_row`) evaluates one band for a row of texels: σa of the
//! epidermis, the table look-up, the adding above and the band's colour weights. On x86-64 with AVX2 (checked at
//! run time) it runs four texels per instruction: the four intervals' coefficients are loaded as one 256-bit vector
//! each and transposed, so the look-up needs no gather; with AVX-512F the square root and the division (which bound
//! the loop) run eight texels per instruction. The vector loops perform the same IEEE operations in the same
//! order as the scalar loop (no FMA contraction, correctly rounded `sqrt` and division), so both give the same
//! bits; the results do not depend on the CPU path or on the thread count.

/// Intervals of each band's [`EpidermisTable`] over the table's √σa range (a power of two: the look-up masks the
/// interval index, which lets the compiler drop the bounds check).
pub const TABLE_INTERVALS: usize = 512;
const _: () = assert!(TABLE_INTERVALS.is_power_of_two());

/// The cubics of one interval for the pair (R, T), one 64-byte cache line.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct IntervalCubic {
    /// c0..c3 of R (power basis in t).
    r: [f64; 4],
    /// c0..c3 of T.
    t: [f64; 4],
}

/// Power-basis coefficients of the Lagrange cubic through (−1, f₋₁), (0, f0), (1, f1), (2, f2).
fn power_basis(f: [f64; 4]) -> [f64; 4] {
    let [fm, f0, f1, f2] = f;
    [f0, f1 - fm / 3.0 - 0.5 * f0 - f2 / 6.0, 0.5 * (fm + f1) - f0, (f2 - fm) / 6.0 + 0.5 * (f0 - f1)]
}

/// c0 + t (c1 + t (c2 + t c3)).
#[inline(always)]
fn horner(c: &[f64; 4], t: f64) -> f64 {
    c[0] + t * (c[1] + t * (c[2] + t * c[3]))
}

/// The epidermis' exact multipole totals at one band, tabulated against y = √σa on a uniform grid spanning the σa
/// range a lookup table needs (see the module docs). It replaces ~65 000 series evaluations per wavelength of a
/// 256² table by 515, which is what makes the 1 nm bake fast.
#[derive(Clone, Debug)]
pub struct EpidermisTable {
    y_lo: f64,
    inv_h: f64,
    /// (R1↓, T1↓) cubics per interval.
    down: Vec<IntervalCubic>,
    /// (R1↑, T1↑) cubics per interval, for directional adding only (empty otherwise).
    up: Vec<IntervalCubic>,
}

impl EpidermisTable {
    /// The table from its node values: `down[k]` = (R1↓, T1↓) and `up[k]` = (R1↑, T1↑) (empty for symmetric adding)
    /// at σa = y², y = y_lo + (k − 1)·h, k = 0..=TABLE_INTERVALS + 2 (one extra node on each side for the stencil).
    pub(super) fn from_nodes(y_lo: f64, h: f64, down: &[[f64; 2]], up: &[[f64; 2]]) -> Self {
        assert_eq!(down.len(), TABLE_INTERVALS + 3, "one node per grid point");
        assert!(up.is_empty() || up.len() == down.len(), "lit-from-below nodes match");
        let cubics = |v: &[[f64; 2]]| -> Vec<IntervalCubic> {
            v.windows(4)
                .map(|n| IntervalCubic {
                    r: power_basis([n[0][0], n[1][0], n[2][0], n[3][0]]),
                    t: power_basis([n[0][1], n[1][1], n[2][1], n[3][1]]),
                })
                .collect()
        };
        let up = if up.is_empty() { Vec::new() } else { cubics(up) };
        Self { y_lo, inv_h: 1.0 / h, down: cubics(down), up }
    }

    /// The interval index k and local coordinate t of `sigma_a_per_mm`: x = (√σa − y_lo)/h, k = floor(x) clamped to
    /// `0..TABLE_INTERVALS` (as a truncating cast of the clamped x: the same integer, no libm `floor`), t = x − k.
    #[inline(always)]
    fn locate(&self, sigma_a_per_mm: f64) -> (usize, f64) {
        let x = (sigma_a_per_mm.sqrt() - self.y_lo) * self.inv_h;
        let k = x.max(0.0).min((TABLE_INTERVALS - 1) as f64) as usize;
        (k, x - k as f64)
    }

    /// (R1↓, T1↓) at `sigma_a_per_mm`.
    #[inline(always)]
    fn eval_down(&self, sigma_a_per_mm: f64) -> [f64; 2] {
        let (k, t) = self.locate(sigma_a_per_mm);
        let down: &[IntervalCubic; TABLE_INTERVALS] = self.down.as_slice().try_into().expect("one cubic per interval");
        let c = &down[k & (TABLE_INTERVALS - 1)];
        [horner(&c.r, t), horner(&c.t, t)]
    }

    /// (R1↓, T1↓, R1↑, T1↑) at `sigma_a_per_mm` (the ↑ pair is 0 for symmetric adding).
    #[inline]
    pub fn eval(&self, sigma_a_per_mm: f64) -> [f64; 4] {
        let (k, t) = self.locate(sigma_a_per_mm);
        let c = &self.down[k];
        let (r, t1) = (horner(&c.r, t), horner(&c.t, t));
        match self.up.get(k) {
            Some(u) => [r, t1, horner(&u.r, t), horner(&u.t, t)],
            None => [r, t1, 0.0, 0.0],
        }
    }
}

/// The constants of one band and one table row: σa,epi = Cm·σa,m + Che·σa,blood + (1 − Cm − Che)·σa,base (the
/// mixing rule of `spectral::skin_layers::epidermis_sigma_a_mixed`, with Che·σa,blood formed once), the dermis
/// reflectance R2 under the row and the band's linear-sRGB weights.
#[derive(Clone, Copy, Debug)]
pub(super) struct BandRow {
    pub melanin_sigma_a_per_mm: f64,
    pub che: f64,
    /// Che · σa,blood.
    pub che_blood_sigma_a_per_mm: f64,
    pub baseline_sigma_a_per_mm: f64,
    pub r2: f64,
    pub weights: [f64; 3],
}

/// Symmetric stack reflectance of one texel: the scalar form of the vectorised loop (same operations, same order).
#[inline(always)]
fn symmetric_texel(table: &EpidermisTable, k: &BandRow, cm: f64) -> f64 {
    let sigma_a =
        cm * k.melanin_sigma_a_per_mm + k.che_blood_sigma_a_per_mm + (1.0 - cm - k.che) * k.baseline_sigma_a_per_mm;
    let [r1, t1] = table.eval_down(sigma_a);
    // DJ05 adding as printed ("symmetric"), at k = 0.
    r1 + t1 * t1 * k.r2 / (1.0 - r1 * k.r2)
}

/// Scalar loop over `range` of the row.
#[inline(always)]
fn accumulate_scalar(
    table: &EpidermisTable,
    k: &BandRow,
    melanin: &[f64],
    acc: [&mut [f64]; 3],
    range: std::ops::Range<usize>,
) {
    let [acc_r, acc_g, acc_b] = acc;
    for x in range {
        let refl = symmetric_texel(table, k, melanin[x]);
        acc_r[x] += k.weights[0] * refl;
        acc_g[x] += k.weights[1] * refl;
        acc_b[x] += k.weights[2] * refl;
    }
}

/// Per-texel intermediates of the vectorised loop, reused across bands and rows (no allocation per row).
#[derive(Debug, Default)]
pub(super) struct RowScratch {
    interval: Vec<i32>,
    t: Vec<f64>,
}

/// Adds one band's weighted symmetric stack reflectance of every texel of a row (Cm = `melanin[x]`) to the
/// accumulator planes `acc` = (R, G, B). Bit-identical on every CPU path (see the module docs).
pub(super) fn accumulate_symmetric_row(
    table: &EpidermisTable,
    k: &BandRow,
    melanin: &[f64],
    acc: [&mut [f64]; 3],
    scratch: &mut RowScratch,
) {
    assert!(acc.iter().all(|a| a.len() == melanin.len()), "one accumulator per texel");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f") {
        // SAFETY: the CPU supports AVX-512F (checked at run time), which implies AVX2.
        return unsafe { avx512::accumulate_symmetric_row(table, k, melanin, acc, scratch) };
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked at run time).
        return unsafe { avx2::accumulate_symmetric_row(table, k, melanin, acc, scratch) };
    }
    let _ = scratch;
    accumulate_scalar(table, k, melanin, acc, 0..melanin.len())
}

/// `accumulate_symmetric_row` (the entry point of a vector path) over vectors of `$lanes` f64, written once for
/// the AVX2 and the AVX-512F loop: `$feature` is the target feature, `$cubics` gives the (R1, T1) cubics of `$lanes`
/// texels at their local coordinates, `$store_interval` stores `$lanes` i32 interval indices, and the rest are the
/// width's f64 intrinsics. The last `len % $lanes` texels take the scalar loop. Two passes over the row: (1) σa,
/// √σa and the interval (k, t) of every texel into `scratch`, (2) the look-up, adding and accumulation. Splitting
/// the long dependency chain (square root → index → load → cubic → division) lets the out-of-order core overlap many
/// more texels than one fused loop does (measured 2× faster). The same IEEE operations in the same order per lane
/// as [`symmetric_texel`] (no FMA contraction), so the same bits as the scalar loop.
#[cfg(target_arch = "x86_64")]
macro_rules! two_pass_row {
    (
        $feature:literal, $lanes:literal, $cubics:ident, $store_interval:ident,
        [$set1:ident, $setzero:ident, $loadu:ident, $storeu:ident, $add:ident, $sub:ident, $mul:ident, $div:ident,
         $sqrt:ident, $min:ident, $max:ident, $cvtt:ident, $cvt:ident]
    ) => {
        #[target_feature(enable = $feature)]
        pub(super) fn accumulate_symmetric_row(
            table: &EpidermisTable,
            k: &BandRow,
            melanin: &[f64],
            [acc_r, acc_g, acc_b]: [&mut [f64]; 3],
            scratch: &mut RowScratch,
        ) {
            let cubics: &[IntervalCubic; TABLE_INTERVALS] =
                table.down.as_slice().try_into().expect("one cubic per interval");
            let n = melanin.len();
            let nv = n - n % $lanes;
            scratch.interval.resize(nv, 0);
            scratch.t.resize(nv, 0.0);
            let one = $set1(1.0);
            {
                let (zero, k_max) = ($setzero(), $set1((TABLE_INTERVALS - 1) as f64));
                let mel = $set1(k.melanin_sigma_a_per_mm);
                let che_blood = $set1(k.che_blood_sigma_a_per_mm);
                let che = $set1(k.che);
                let base = $set1(k.baseline_sigma_a_per_mm);
                let (y_lo, inv_h) = ($set1(table.y_lo), $set1(table.inv_h));
                let intervals = scratch.interval.chunks_exact_mut($lanes);
                let lanes = melanin.chunks_exact($lanes).zip(intervals).zip(scratch.t.chunks_exact_mut($lanes));
                for ((cm_v, k_v), t_v) in lanes {
                    // SAFETY: `cm_v` is `$lanes` readable f64; the unaligned load has no alignment requirement.
                    let cm = unsafe { $loadu(cm_v.as_ptr()) };
                    // σa = Cm·σa,m + Che·σa,blood + ((1 − Cm) − Che)·σa,base
                    let sigma_a = $add($add($mul(cm, mel), che_blood), $mul($sub($sub(one, cm), che), base));
                    let x = $mul($sub($sqrt(sigma_a), y_lo), inv_h);
                    // max(x, 0) returns 0 for NaN (second operand) like f64::max; the clamp keeps the conversion
                    // in range.
                    let ki = $cvtt($min($max(x, zero), k_max));
                    let t = $sub(x, $cvt(ki));
                    // SAFETY: `k_v` is `$lanes` writable i32 and `t_v` `$lanes` writable f64; the unaligned stores
                    // have no alignment requirement.
                    unsafe {
                        $store_interval(k_v.as_mut_ptr().cast(), ki);
                        $storeu(t_v.as_mut_ptr(), t);
                    }
                }
            }
            let r2 = $set1(k.r2);
            let w = k.weights.map(|c| $set1(c));
            let lanes = scratch.interval.chunks_exact($lanes).zip(scratch.t.chunks_exact($lanes));
            let planes = acc_r.chunks_exact_mut($lanes).zip(acc_g.chunks_exact_mut($lanes));
            for ((k_v, t_v), ((ar, ag), ab)) in lanes.zip(planes.zip(acc_b.chunks_exact_mut($lanes))) {
                let (r1, t1) = $cubics(cubics, k_v, t_v);
                // R = R1 + T1² R2 / (1 − R1 R2)
                let refl = $add(r1, $div($mul($mul(t1, t1), r2), $sub(one, $mul(r1, r2))));
                for (a, wc) in [(ar, w[0]), (ag, w[1]), (ab, w[2])] {
                    // SAFETY: `a` is `$lanes` readable and writable f64; the unaligned accesses have no alignment
                    // requirement.
                    unsafe {
                        let sum = $add($loadu(a.as_ptr()), $mul(wc, refl));
                        $storeu(a.as_mut_ptr(), sum);
                    }
                }
            }
            accumulate_scalar(table, k, melanin, [acc_r, acc_g, acc_b], nv..n);
        }
    };
}

/// Four texels at a time with AVX2: the four intervals' coefficients are loaded as one 256-bit vector each and
/// transposed, so the look-up needs no gather.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{accumulate_scalar, BandRow, EpidermisTable, IntervalCubic, RowScratch, TABLE_INTERVALS};
    use std::arch::x86_64::*;

    /// Loads four f64.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn load(c: &[f64; 4]) -> __m256d {
        // SAFETY: `c` is a valid, readable [f64; 4]; the unaligned load has no alignment requirement.
        unsafe { _mm256_loadu_pd(c.as_ptr()) }
    }

    /// Transposes four rows of four lanes: out[i] = (a[i], b[i], c[i], d[i]).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn transpose(a: __m256d, b: __m256d, c: __m256d, d: __m256d) -> [__m256d; 4] {
        let ab_lo = _mm256_unpacklo_pd(a, b); // a0 b0 a2 b2
        let ab_hi = _mm256_unpackhi_pd(a, b); // a1 b1 a3 b3
        let cd_lo = _mm256_unpacklo_pd(c, d);
        let cd_hi = _mm256_unpackhi_pd(c, d);
        [
            _mm256_permute2f128_pd::<0x20>(ab_lo, cd_lo),
            _mm256_permute2f128_pd::<0x20>(ab_hi, cd_hi),
            _mm256_permute2f128_pd::<0x31>(ab_lo, cd_lo),
            _mm256_permute2f128_pd::<0x31>(ab_hi, cd_hi),
        ]
    }

    /// c0 + t (c1 + t (c2 + t c3)) per lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn horner(c: [__m256d; 4], t: __m256d) -> __m256d {
        let v = _mm256_add_pd(c[2], _mm256_mul_pd(t, c[3]));
        let v = _mm256_add_pd(c[1], _mm256_mul_pd(t, v));
        _mm256_add_pd(c[0], _mm256_mul_pd(t, v))
    }

    /// The (R1, T1) cubics of four texels at their local coordinates, as two 4-lane vectors.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn cubics4(cubics: &[IntervalCubic; TABLE_INTERVALS], k4: &[i32], t4: &[f64]) -> (__m256d, __m256d) {
        let t = load(t4.try_into().expect("4 lanes"));
        let c = [0, 1, 2, 3].map(|j| &cubics[k4[j] as usize & (TABLE_INTERVALS - 1)]);
        let r1 = horner(transpose(load(&c[0].r), load(&c[1].r), load(&c[2].r), load(&c[3].r)), t);
        let t1 = horner(transpose(load(&c[0].t), load(&c[1].t), load(&c[2].t), load(&c[3].t)), t);
        (r1, t1)
    }

    two_pass_row!(
        "avx2",
        4,
        cubics4,
        _mm_storeu_si128,
        [
            _mm256_set1_pd,
            _mm256_setzero_pd,
            _mm256_loadu_pd,
            _mm256_storeu_pd,
            _mm256_add_pd,
            _mm256_sub_pd,
            _mm256_mul_pd,
            _mm256_div_pd,
            _mm256_sqrt_pd,
            _mm256_min_pd,
            _mm256_max_pd,
            _mm256_cvttpd_epi32,
            _mm256_cvtepi32_pd
        ]
    );
}

/// The same loop eight texels at a time with AVX-512F: the square root and the division, which bound the AVX2
/// loop, run on 512-bit vectors (2.4× the AVX2 throughput of `sqrt` + `div` per element measured on the project's
/// AMD EPYC); the look-up and the cubics stay the AVX2 code, two groups of four texels per step. Same IEEE
/// operations in the same order per lane (no FMA contraction), so the same bits as the scalar loop.
#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::avx2::cubics4;
    use super::{accumulate_scalar, BandRow, EpidermisTable, IntervalCubic, RowScratch, TABLE_INTERVALS};
    use std::arch::x86_64::*;

    /// The (R1, T1) cubics of eight texels: two groups of four (lo in lanes 0–3).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn cubics8(cubics: &[IntervalCubic; TABLE_INTERVALS], k8: &[i32], t8: &[f64]) -> (__m512d, __m512d) {
        let (r_lo, t_lo) = cubics4(cubics, &k8[..4], &t8[..4]);
        let (r_hi, t_hi) = cubics4(cubics, &k8[4..], &t8[4..]);
        (join(r_lo, r_hi), join(t_lo, t_hi))
    }

    /// Two 4-lane vectors as one 8-lane vector (lo in lanes 0–3).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn join(lo: __m256d, hi: __m256d) -> __m512d {
        _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(lo), hi)
    }

    two_pass_row!(
        "avx512f",
        8,
        cubics8,
        _mm256_storeu_si256,
        [
            _mm512_set1_pd,
            _mm512_setzero_pd,
            _mm512_loadu_pd,
            _mm512_storeu_pd,
            _mm512_add_pd,
            _mm512_sub_pd,
            _mm512_mul_pd,
            _mm512_div_pd,
            _mm512_sqrt_pd,
            _mm512_min_pd,
            _mm512_max_pd,
            _mm512_cvttpd_epi32,
            _mm512_cvtepi32_pd
        ]
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> EpidermisTable {
        // A smooth stand-in for the totals (exact for cubics: the interpolation must reproduce them).
        let (y_lo, h) = (0.3, 0.01);
        let f = |y: f64| [0.2 + 0.1 * y - 0.05 * y * y, 0.9 - 0.3 * y + 0.02 * y * y * y];
        let nodes: Vec<[f64; 2]> = (0..TABLE_INTERVALS + 3).map(|k| f(y_lo + (k as f64 - 1.0) * h)).collect();
        EpidermisTable::from_nodes(y_lo, h, &nodes, &[])
    }

    #[test]
    fn cubic_nodes_are_reproduced_between_the_nodes() {
        let t = table();
        for i in 0..2000 {
            let y = 0.3 + 5.12 * i as f64 / 2000.0;
            let [r, tt, ru, tu] = t.eval(y * y);
            assert!((r - (0.2 + 0.1 * y - 0.05 * y * y)).abs() < 1e-13, "R at y = {y}");
            assert!((tt - (0.9 - 0.3 * y + 0.02 * y * y * y)).abs() < 1e-13, "T at y = {y}");
            assert_eq!((ru, tu), (0.0, 0.0));
        }
    }

    #[test]
    fn vector_loop_is_bit_identical_to_the_scalar_loop() {
        let t = table();
        // Lengths with and without a scalar tail; σa below, inside and beyond the table's range.
        for n in [1usize, 4, 7, 8, 13, 37, 256] {
            let melanin: Vec<f64> = (0..n).map(|i| 0.5 * (i as f64 / n as f64).powi(3)).collect();
            let k = BandRow {
                melanin_sigma_a_per_mm: 40.0,
                che: 0.02,
                che_blood_sigma_a_per_mm: 0.02 * 30.0,
                baseline_sigma_a_per_mm: 0.05,
                r2: 0.45,
                weights: [0.3, -0.1, 0.02],
            };
            let init: Vec<f64> = (0..n).map(|i| 0.1 * i as f64).collect();
            let init0 = init.clone();
            let (mut a, mut b) = ([init.clone(), init.clone(), init.clone()], [init.clone(), init.clone(), init]);
            let [ar, ag, ab] = &mut a;
            accumulate_symmetric_row(&t, &k, &melanin, [ar.as_mut_slice(), ag, ab], &mut RowScratch::default());
            let [br, bg, bb] = &mut b;
            accumulate_scalar(&t, &k, &melanin, [br.as_mut_slice(), bg, bb], 0..n);
            for c in 0..3 {
                assert!(a[c].iter().zip(&b[c]).all(|(x, y)| x.to_bits() == y.to_bits()), "n = {n}, channel {c}");
            }
            // Each vector path on its own (the dispatch above takes the widest the CPU has).
            #[cfg(target_arch = "x86_64")]
            for (name, present) in [
                ("avx2", std::arch::is_x86_feature_detected!("avx2")),
                ("avx512f", std::arch::is_x86_feature_detected!("avx512f")),
            ] {
                if !present {
                    continue;
                }
                let mut v = [init0.clone(), init0.clone(), init0.clone()];
                let [vr, vg, vb] = &mut v;
                let acc = [vr.as_mut_slice(), vg, vb];
                let mut scratch = RowScratch::default();
                // SAFETY: the CPU supports the path's feature (checked above).
                unsafe {
                    if name == "avx2" {
                        avx2::accumulate_symmetric_row(&t, &k, &melanin, acc, &mut scratch)
                    } else {
                        avx512::accumulate_symmetric_row(&t, &k, &melanin, acc, &mut scratch)
                    }
                }
                for c in 0..3 {
                    assert!(v[c].iter().zip(&b[c]).all(|(x, y)| x.to_bits() == y.to_bits()), "{name} n = {n}, {c}");
                }
            }
            assert!(a[0].iter().all(|v| v.is_finite()));
        }
    }
}
