//! The photon-lane engine of [`super::mc`]: [`LANES`] photon packets traced side by side, one event of every lane
//! per step, without branches on the photons' histories (MCML, Wang, Jacques & Zheng 1995, §3.2–3.8; the physics
//! is the one of the module docs of [`super::mc`]).
//!
//! Every step computes, for all lanes at once in packed arithmetic (`[f64; LANES]` structure-of-arrays values whose
//! every operation is one short loop the compiler vectorises): one Philox4x32-10 block per lane ([`super::rng`],
//! counter (photon index lo, photon index hi, channel, event number): the photon's stream is fixed by its index),
//! both the interaction (implicit capture, Henyey–Greenstein polar angle, azimuth, spin, Russian roulette; MCML
//! eq. 3.28–3.31) and the arrival at the face the packet heads for (Fresnel reflectance, MCML eq. 3.36–3.38,
//! reflection or Snell refraction), and keeps one of the two per lane by mask. The per-lane outcomes that need
//! scalar work — a packet leaving the stack (scored in R(r) or T(r)), losing the roulette, gliding forever in a
//! clear layer, or crossing into another layer (its layer constants are reloaded) — are handled after the step; a
//! lane whose packet has ended takes the chunk's next photon index, so the refill order depends only on the
//! histories. Thirty-two lanes, not the eight of one AVX-512 register: a step is one long dependency chain
//! (Philox rounds, logarithm, divisions, square roots), and four independent registers per value let the
//! processor overlap them (measured: 8 → 16 → 32 lanes took the van de Hulst slab from 0.25 to 0.14 to 0.12 CPU
//! seconds, `examples/bench_transport`).
//!
//! **Draws**: each event uses the four words of its block: word 0 → the optical depth s = −ln ξ when none is
//! pending (ξ = (w + 1)/2³² ∈ (0, 1]; fdlibm's logarithm, branch-free); word 1 → the HG ξ at an interaction or
//! the Fresnel ξ at a face; word 2 → the azimuth φ (2 bits of quadrant and 30 bits within it, sin and cos by
//! Taylor polynomials); word 3 → the roulette ξ. Unused words are skipped, so event e of photon k always reads
//! block e.
//!
//! **Determinism**: only IEEE-754 additions, multiplications, divisions, square roots, comparisons, selects and
//! exact conversions are used, and "fma" is never enabled, so the AVX-512F, AVX2 and portable paths ([`Path`])
//! round identically and give the same bytes; lanes keep their own absorption sums, added in lane order at the end
//! of a chunk, and exits are scored in lane order.

use super::mc::{Channel, Tally, ROULETTE_CHANCE, ROULETTE_THRESHOLD};
use super::rng::{M0, M1, W0, W1};

/// Photon packets traced side by side (the same on every path: the lane a photon gets decides the order of the
/// per-lane absorption sums, so it must not depend on the CPU; at most 32, the width of the step's outcome mask).
pub const LANES: usize = 32;
const _: () = assert!(LANES <= 32, "the outcome mask of a step is a u32");

/// The instruction set the lane loops are compiled for; every path gives the same bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    /// x86-64 with AVX-512F (runtime-detected).
    Avx512,
    /// x86-64 with AVX2 (runtime-detected).
    Avx2,
    /// Whatever the target's baseline is.
    Portable,
}

impl Path {
    /// The widest path this CPU supports.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                return Path::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return Path::Avx2;
            }
        }
        Path::Portable
    }

    /// Whether this CPU can run the path.
    pub fn supported(self) -> bool {
        match self {
            #[cfg(target_arch = "x86_64")]
            Path::Avx512 => std::arch::is_x86_feature_detected!("avx512f"),
            #[cfg(target_arch = "x86_64")]
            Path::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            Path::Portable => true,
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }
}

/// Traces photons `first..first + count` of channel `ch` into `tally` on `path`.
///
/// # Panics
/// When `path` is not [`Path::supported`] on this CPU.
pub(super) fn trace_chunk(path: Path, ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
    assert!(path.supported(), "{path:?} is not supported by this CPU");
    match path {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU supports AVX-512F (checked above).
        Path::Avx512 => unsafe { x86::trace_avx512(ch, bin_mm, first, count, tally) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU supports AVX2 (checked above).
        Path::Avx2 => unsafe { x86::trace_avx2(ch, bin_mm, first, count, tally) },
        _ => trace(ch, bin_mm, first, count, tally),
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{trace, Channel, Tally};

    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn trace_avx512(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
        trace(ch, bin_mm, first, count, tally)
    }

    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn trace_avx2(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
        trace(ch, bin_mm, first, count, tally)
    }
}

/// `LANES` f64 values, one per lane. Every operation is a fixed-length loop of one IEEE operation, which the
/// compiler turns into packed instructions of the enabled width (a long fused loop body is not vectorised).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct V([f64; LANES]);
/// `LANES` u32 values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct W([u32; LANES]);
/// A per-lane condition: all ones (true) or zero (false) in 64 bits, the form of a packed comparison's result, so
/// that selects are bitwise on every instruction set.
#[derive(Clone, Copy, Debug, PartialEq)]
struct M([u64; LANES]);

/// The mask lane of a condition.
#[inline(always)]
fn mask(b: bool) -> u64 {
    u64::from(b).wrapping_neg()
}

macro_rules! lanewise {
    ($out:ident, |$($a:ident),*| $e:expr) => {{
        let mut r = $out::default();
        for i in 0..LANES {
            $(let $a = $a.0[i];)*
            r.0[i] = $e;
        }
        r
    }};
}

impl Default for M {
    fn default() -> Self {
        M([0; LANES])
    }
}

impl V {
    #[inline(always)]
    fn splat(v: f64) -> V {
        V([v; LANES])
    }
    #[inline(always)]
    fn lt(self, o: V) -> M {
        let a = self;
        lanewise!(M, |a, o| mask(a < o))
    }
    #[inline(always)]
    fn le(self, o: V) -> M {
        let a = self;
        lanewise!(M, |a, o| mask(a <= o))
    }
    #[inline(always)]
    fn eq(self, o: V) -> M {
        let a = self;
        lanewise!(M, |a, o| mask(a == o))
    }
    #[inline(always)]
    fn sqrt(self) -> V {
        let a = self;
        lanewise!(V, |a| a.sqrt())
    }
    /// max(v, 0) as a select (no NaN handling needed: the arguments are finite or discarded).
    #[inline(always)]
    fn pos(self) -> V {
        let a = self;
        lanewise!(V, |a| if a > 0.0 { a } else { 0.0 })
    }
    #[inline(always)]
    fn abs(self) -> V {
        let a = self;
        lanewise!(V, |a| a.abs())
    }
}

impl M {
    #[inline(always)]
    fn select(self, a: V, b: V) -> V {
        let m = self;
        lanewise!(V, |m, a, b| f64::from_bits((a.to_bits() & m) | (b.to_bits() & !m)))
    }
    #[inline(always)]
    fn select_w(self, a: W, b: W) -> W {
        let m = self;
        lanewise!(W, |m, a, b| (a & m as u32) | (b & !(m as u32)))
    }
    #[inline(always)]
    fn and(self, o: M) -> M {
        let a = self;
        lanewise!(M, |a, o| a & o)
    }
    #[inline(always)]
    fn or(self, o: M) -> M {
        let a = self;
        lanewise!(M, |a, o| a | o)
    }
    #[inline(always)]
    fn not(self) -> M {
        let a = self;
        lanewise!(M, |a| !a)
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.0.iter().fold(!0, |a, &b| a & b) != 0
    }
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |a, &b| a | b) != 0
    }
}

macro_rules! binop {
    ($tr:ident, $f:ident, $op:tt) => {
        impl std::ops::$tr for V {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: V) -> V {
                let a = self;
                lanewise!(V, |a, o| a $op o)
            }
        }
        impl std::ops::$tr<f64> for V {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: f64) -> V {
                let a = self;
                let o = V::splat(o);
                lanewise!(V, |a, o| a $op o)
            }
        }
    };
}
binop!(Add, add, +);
binop!(Sub, sub, -);
binop!(Mul, mul, *);
binop!(Div, div, /);

impl std::ops::Neg for V {
    type Output = V;
    #[inline(always)]
    fn neg(self) -> V {
        let a = self;
        lanewise!(V, |a| -a)
    }
}

/// ln 2 split for an exact k·ln 2 (fdlibm `e_log.c`; its digits as published, hence the precision allowance).
#[allow(clippy::excessive_precision)]
const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-1;
#[allow(clippy::excessive_precision)]
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
/// fdlibm `e_log.c` minimax coefficients Lg1..Lg7 of R(z) ≈ (ln(1 + f) − 2s)/s in z = s², s = f/(2 + f).
#[allow(clippy::excessive_precision)]
const LG: [f64; 7] = [
    6.666_666_666_666_735_130e-1,
    3.999_999_999_940_941_908e-1,
    2.857_142_874_366_239_149e-1,
    2.222_219_843_214_978_396e-1,
    1.818_357_216_161_805_012e-1,
    1.531_383_769_920_937_332e-1,
    1.479_819_860_511_658_591e-1,
];

/// −ln x for normal x in (0, 1] per lane, branch-free (fdlibm's `__ieee754_log`: x = 2ᵏ·(1 + f) with 1 + f in
/// `[√2/2, √2)`, ln(1 + f) = f − (f²/2 − s·(f²/2 + R(s²))), s = f/(2 + f); within an ulp or two).
#[inline(always)]
fn neg_ln(x: V) -> V {
    let mut y = V::default();
    let mut dk = V::default();
    for i in 0..LANES {
        let bits = x.0[i].to_bits();
        let hx = (bits >> 32) as u32;
        let hm = hx & 0x000f_ffff;
        let t = (hm + 0x95f64) & 0x0010_0000;
        y.0[i] = f64::from_bits((u64::from(hm | (t ^ 0x3ff0_0000)) << 32) | (bits & 0xffff_ffff));
        // k = exponent − 1023 + (t ≠ 0), exactly as an f64.
        dk.0[i] = f64::from(((hx >> 20) + (t >> 20)) as i32 - 1023);
    }
    let f = y - 1.0;
    let s = f / (f + 2.0);
    let z = s * s;
    let w = z * z;
    let t1 = w * ((w * ((w * LG[5]) + LG[3])) + LG[1]);
    let t2 = z * ((w * ((w * ((w * LG[6]) + LG[4])) + LG[2])) + LG[0]);
    let r = t2 + t1;
    let hfsq = f * f * 0.5;
    ((hfsq - (s * (hfsq + r) + dk * LN2_LO)) - f) - dk * LN2_HI
}

// The Taylor coefficients of sin and cos on |θ| ≤ π/4, shared with the Bessel functions' reduction.
use crate::diffusion::bessel::{COS_TAYLOR as COS, SIN_TAYLOR as SIN};

/// (cos φ, sin φ) per lane of the azimuth φ = (q + ½)·π/2 + θ of a 32-bit word: q = its top two bits (the
/// quadrant), θ = ((low 30 bits + ½)/2³⁰ − ½)·π/2 ∈ (−π/4, π/4) — φ uniform on `[0, 2π)` on a grid of 2π/2³², by
/// polynomials and selects (no table, no branch): cos(π/4 + θ) = (cos θ − sin θ)/√2,
/// sin(π/4 + θ) = (cos θ + sin θ)/√2, then q quarter turns.
#[inline(always)]
fn azimuth_cos_sin(word: W) -> (V, V) {
    let low = lanewise!(V, |word| f64::from((word & 0x3fff_ffff) as i32));
    let t = ((low + 0.5) * (1.0 / 1_073_741_824.0) - 0.5) * std::f64::consts::FRAC_PI_2;
    let z = t * t;
    let mut ps = V::splat(SIN[7]);
    for c in SIN[..7].iter().rev() {
        ps = ps * z + *c;
    }
    let sin_t = t + t * z * ps;
    let mut pc = V::splat(COS[8]);
    for c in COS[..8].iter().rev() {
        pc = pc * z + *c;
    }
    let cos_t = z * pc + 1.0;
    let c = (cos_t - sin_t) * std::f64::consts::FRAC_1_SQRT_2;
    let s = (cos_t + sin_t) * std::f64::consts::FRAC_1_SQRT_2;
    // Quarter turns: q = 1: (−s, c); q = 2: (−c, −s); q = 3: (s, −c).
    let odd = lanewise!(M, |word| mask(word & 0x4000_0000 != 0));
    let half = lanewise!(M, |word| mask(word & 0x8000_0000 != 0));
    let (c1, s1) = (odd.select(-s, c), odd.select(c, s));
    (half.select(-c1, c1), half.select(-s1, s1))
}

/// Per lane a uniform in (0, 1] on the grid k/2³² (k = 1..=2³²) from a word, by an exact signed conversion.
#[inline(always)]
fn unit(word: W) -> V {
    lanewise!(V, |word| (f64::from((word ^ 0x8000_0000) as i32) + 2_147_483_649.0) * (1.0 / 4_294_967_296.0))
}

/// The ten round keys of Philox4x32-10 under `seed` (the key bumped by the Weyl constants between rounds).
fn round_keys(seed: u64) -> [[u32; 2]; 10] {
    let mut keys = [[0u32; 2]; 10];
    let mut key = [seed as u32, (seed >> 32) as u32];
    for (round, k) in keys.iter_mut().enumerate() {
        if round > 0 {
            key = [key[0].wrapping_add(W0), key[1].wrapping_add(W1)];
        }
        *k = key;
    }
    keys
}

/// Philox4x32-10 of the counters `c` per lane under the round keys `keys` ([`super::rng::philox4x32_10`]). The
/// words are carried in 64-bit lanes so that the 32×32 → 64-bit products are packed multiplies of the low halves
/// with no repacking: a product's low half is the next round's word as it stands (the high bits it carries along
/// are masked off before the next multiply and at the end).
#[inline(always)]
fn block(c: [W; 4], keys: &[[u32; 2]; 10]) -> [W; 4] {
    let [mut c0, mut c1, mut c2, mut c3] = c.map(|w| lanewise!(P, |w| u64::from(w)));
    for k in keys {
        let (k0, k1) = (u64::from(k[0]), u64::from(k[1]));
        let p0 = lanewise!(P, |c0| (c0 & 0xffff_ffff) * u64::from(M0));
        let p1 = lanewise!(P, |c2| (c2 & 0xffff_ffff) * u64::from(M1));
        c0 = lanewise!(P, |p1, c1| (p1 >> 32) ^ c1 ^ k0);
        c1 = p1;
        c2 = lanewise!(P, |p0, c3| (p0 >> 32) ^ c3 ^ k1);
        c3 = p0;
    }
    [c0, c1, c2, c3].map(|p| lanewise!(W, |p| p as u32))
}

/// 64-bit products per lane.
#[derive(Clone, Copy, Debug, Default)]
struct P([u64; LANES]);

/// The per-lane copy of one layer's constants (reloaded when a packet changes layer).
#[derive(Clone, Copy, Debug, Default)]
struct LayerConsts {
    z_top: f64,
    z_bottom: f64,
    sigma_t: f64,
    inv_sigma_t: f64,
    absorb: f64,
    isotropic: bool,
    /// 1 − g², 1 − g, 2g, 1 + g², 1/(2g).
    hg: [f64; 5],
    /// η of the layer over η of the medium above and below (the neighbour layer or the ambient medium).
    ratio_above: f64,
    ratio_below: f64,
    /// The first layer, the last (leaving through that face ends the packet).
    top: bool,
    bottom: bool,
}

/// Structure-of-arrays state of the lanes.
#[derive(Clone, Debug, Default)]
struct Lanes {
    x: V,
    y: V,
    z: V,
    ux: V,
    uy: V,
    uz: V,
    w: V,
    /// Optical depth left of the current step (0: draw a new one).
    s: V,
    z_top: V,
    z_bottom: V,
    sigma_t: V,
    inv_sigma_t: V,
    absorb: V,
    isotropic: M,
    hg: [V; 5],
    ratio_above: V,
    ratio_below: V,
    top: M,
    bottom: M,
    photon_lo: W,
    photon_hi: W,
    event: W,
    /// Whether the lane traces a photon of the chunk (false once the chunk has none left for it).
    live: M,
    /// Per lane: weight absorbed in this step (0 elsewhere), the outcome code (`END_*`, 0 = continues) and 1 where
    /// a live packet interacted.
    dw: V,
    code: W,
    interacted: W,
    /// 1 − Rsp.
    start_weight: f64,
}

const END_TOP: u32 = 1;
const END_BOTTOM: u32 = 2;
const END_ROULETTE: u32 = 3;
const END_GLIDE: u32 = 4;
const CROSSED: u32 = 5;

impl Lanes {
    fn load_layer(&mut self, i: usize, m: &LayerConsts) {
        self.z_top.0[i] = m.z_top;
        self.z_bottom.0[i] = m.z_bottom;
        self.sigma_t.0[i] = m.sigma_t;
        self.inv_sigma_t.0[i] = m.inv_sigma_t;
        self.absorb.0[i] = m.absorb;
        self.isotropic.0[i] = mask(m.isotropic);
        for (h, v) in self.hg.iter_mut().zip(m.hg) {
            h.0[i] = v;
        }
        self.ratio_above.0[i] = m.ratio_above;
        self.ratio_below.0[i] = m.ratio_below;
        self.top.0[i] = mask(m.top);
        self.bottom.0[i] = mask(m.bottom);
    }

    /// Lane `i` starts photon `k` (or, with `live` false, a placeholder whose tallies are masked out) with weight
    /// `start_weight`; its layer constants are the caller's (those of the first layer).
    fn launch(&mut self, i: usize, k: u64, live: bool) {
        self.x.0[i] = 0.0;
        self.y.0[i] = 0.0;
        self.z.0[i] = 0.0;
        self.ux.0[i] = 0.0;
        self.uy.0[i] = 0.0;
        self.uz.0[i] = 1.0;
        self.w.0[i] = self.start_weight;
        self.s.0[i] = 0.0;
        self.photon_lo.0[i] = k as u32;
        self.photon_hi.0[i] = (k >> 32) as u32;
        self.event.0[i] = 0;
        self.live.0[i] = mask(live);
    }

    /// One event of every lane (module docs). Writes `dw`, `code` and `interacted`; no branch on lane data.
    #[inline(always)]
    fn step(&mut self, channel: u32, keys: &[[u32; 2]; 10]) {
        let [r0, r1, r2, r3] = block([self.photon_lo, self.photon_hi, W([channel; LANES]), self.event], keys);
        let event = self.event;
        self.event = lanewise!(W, |event| event.wrapping_add(1));
        let xi1 = unit(r1);
        let zero = V::splat(0.0);

        let (x, y, z, ux, uy, uz, w) = (self.x, self.y, self.z, self.ux, self.uy, self.uz, self.w);
        let s = self.s.eq(zero).select(neg_ln(unit(r0)), self.s);
        let sigma_t = self.sigma_t;
        let down = zero.lt(uz);
        let face_z = down.select(self.z_bottom, self.z_top);
        let d_step = s * self.inv_sigma_t;
        let z_step = z + uz * d_step;
        // Strictly short of the face it heads for (always for uz = 0, which meets no face).
        let interact = zero.lt(sigma_t).and(uz.eq(zero).or(((z_step - face_z) * uz).lt(zero)));

        // Interaction: implicit capture, HG polar angle, azimuth, spin, roulette.
        let dw = w * self.absorb;
        let w_int = w - dw;
        let [a, b, c, e, f] = self.hg;
        let iso = xi1 * 2.0 - 1.0;
        let cos_t = if self.isotropic.all() {
            iso
        } else {
            let q = a / (b + c * xi1);
            let hg = (e - q * q) * f;
            let hg = hg.lt(V::splat(-1.0)).select(V::splat(-1.0), V::splat(1.0).lt(hg).select(V::splat(1.0), hg));
            self.isotropic.select(iso, hg)
        };
        let (cos_p, sin_p) = azimuth_cos_sin(r2);
        let sin2_t = (-(cos_t * cos_t) + 1.0).pos();
        let one_minus_uz2 = -(uz * uz) + 1.0;
        // Along the z axis (|uz| > 0.99999, e.g. a packet's first interaction) the frame is the lab frame: there
        // the one square root gives sin θ itself.
        let polar = V::splat(0.99999).lt(uz.abs());
        let a = (sin2_t / polar.select(V::splat(1.0), one_minus_uz2)).sqrt();
        let sx = polar.select(a * cos_p, a * (ux * uz * cos_p - uy * sin_p) + ux * cos_t);
        let sy = polar.select(a * sin_p, a * (uy * uz * cos_p + ux * sin_p) + uy * cos_t);
        let sz = polar.select(uz.lt(zero).select(-cos_t, cos_t), -a * one_minus_uz2 * cos_p + uz * cos_t);
        let low = w_int.lt(V::splat(ROULETTE_THRESHOLD));
        let survive = unit(r3).le(V::splat(1.0 / ROULETTE_CHANCE)).and(w_int.eq(zero).not());
        let w_int = low.and(survive).select(w_int * ROULETTE_CHANCE, w_int);
        let lost = low.and(survive.not());

        // Face (only when some lane is at one): Fresnel reflection or refraction into the neighbour.
        let at_face = interact.not();
        let splat = |v: u32| W([v; LANES]);
        let (d, fx, fy, fz, s_face, face_code) = if at_face.any() {
            let d_face = (face_z - z) / uz;
            let glide = interact.or(d_face.abs().lt(V::splat(f64::INFINITY))).not();
            // n_i/n_t, and R = ½(rs² + rp²) with rs = (ρ cos_i − cos_t)/(ρ cos_i + cos_t),
            // rp = (ρ cos_t − cos_i)/(ρ cos_t + cos_i), ρ = n_i/n_t, over one common denominator.
            let ratio = down.select(self.ratio_below, self.ratio_above);
            let cos_i = uz.abs();
            let sin_t2 = ratio * ratio * (-(cos_i * cos_i) + 1.0).pos();
            let cos_tr = (-sin_t2 + 1.0).pos().sqrt();
            let (a, b) = (ratio * cos_i - cos_tr, ratio * cos_i + cos_tr);
            let (c, e) = (ratio * cos_tr - cos_i, ratio * cos_tr + cos_i);
            let (ae, cb, be) = (a * e, c * b, b * e);
            let same = ratio.eq(V::splat(1.0));
            let refl = same
                .select(zero, V::splat(1.0).le(sin_t2).select(V::splat(1.0), (ae * ae + cb * cb) / (be * be) * 0.5));
            let reflect = zero.lt(refl).and(V::splat(1.0).le(refl).or(xi1.le(refl)));
            let cos_tr = same.select(cos_i, cos_tr);
            let fx = reflect.select(ux, ux * ratio);
            let fy = reflect.select(uy, uy * ratio);
            let fz = reflect.select(-uz, down.select(cos_tr, -cos_tr));
            let s_face = zero.lt(sigma_t).select((s - d_face * sigma_t).pos(), s);
            let crossing = reflect.not();
            let leaves = crossing.and(down.select_m(self.bottom, self.top));
            let code = leaves.select_w(
                down.select_w(splat(END_BOTTOM), splat(END_TOP)),
                crossing.select_w(splat(CROSSED), splat(0)),
            );
            let code = glide.select_w(splat(END_GLIDE), code);
            (interact.select(d_step, d_face), fx, fy, fz, s_face, code)
        } else {
            (d_step, ux, uy, uz, s, splat(0))
        };

        self.x = x + ux * d;
        self.y = y + uy * d;
        self.z = interact.select(z_step, face_z);
        self.ux = interact.select(sx, fx);
        self.uy = interact.select(sy, fy);
        self.uz = interact.select(sz, fz);
        self.w = interact.select(w_int, w);
        self.s = interact.select(zero, s_face);
        let live = self.live;
        self.dw = interact.and(live).select(dw, zero);
        self.interacted = lanewise!(W, |interact, live| (interact & live) as u32 & 1);
        self.code = interact.select_w(lost.select_w(splat(END_ROULETTE), splat(0)), face_code);
    }
}

impl M {
    #[inline(always)]
    fn select_m(self, a: M, b: M) -> M {
        let m = self;
        lanewise!(M, |m, a, b| (a & m) | (b & !m))
    }
}

/// The lane engine over one chunk (module docs); compiled into each [`Path`]'s target-feature function.
#[inline(always)]
fn trace(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
    let media = ch.media;
    let last = media.len() - 1;
    let consts: Vec<LayerConsts> = media
        .iter()
        .enumerate()
        .map(|(j, m)| LayerConsts {
            z_top: m.z_top_mm,
            z_bottom: m.z_bottom_mm,
            sigma_t: m.sigma_t,
            inv_sigma_t: m.inv_sigma_t,
            absorb: m.absorb_fraction,
            isotropic: m.hg.isotropic,
            hg: [m.hg.one_minus_g2, m.hg.one_minus_g, m.hg.two_g, m.hg.one_plus_g2, m.hg.inv_two_g],
            ratio_above: m.eta / if j == 0 { ch.eta_above } else { media[j - 1].eta },
            ratio_below: m.eta / if j == last { ch.eta_below } else { media[j + 1].eta },
            top: j == 0,
            bottom: j == last,
        })
        .collect();
    let keys = round_keys(ch.seed);
    let inv_bin = 1.0 / bin_mm;
    let bins = tally.r.len();
    let end = first + count;
    let mut next = first;
    let mut lanes = Lanes { start_weight: ch.start_weight, ..Lanes::default() };
    let mut layer = [0usize; LANES];
    for i in 0..LANES {
        lanes.load_layer(i, &consts[0]);
        lanes.launch(i, next, next < end);
        next = (next + 1).min(end);
    }
    // Exit weights (R then T, module docs of the loop below) and the totals Rd, Td.
    let mut exits = vec![0.0f64; 2 * (bins + 1)];
    let mut totals = [0.0f64; 2];
    // Absorbed weight per layer and lane.
    let mut absorbed = vec![[0.0f64; LANES]; media.len()];
    let mut live_count = LANES.min(count as usize);
    while live_count > 0 {
        lanes.step(ch.index, &keys);
        if media.len() == 1 {
            for (a, dw) in absorbed[0].iter_mut().zip(&lanes.dw.0) {
                *a += dw;
            }
        } else {
            for (j, acc) in absorbed.iter_mut().enumerate() {
                for i in 0..LANES {
                    acc[i] += if layer[i] == j { lanes.dw.0[i] } else { 0.0 };
                }
            }
        }
        let mut interactions = 0u32;
        let mut special = 0u32;
        for i in 0..LANES {
            interactions += lanes.interacted.0[i];
            special |= u32::from(lanes.code.0[i] != 0) << i;
        }
        tally.interactions += u64::from(interactions);
        while special != 0 {
            let i = special.trailing_zeros() as usize;
            special &= special - 1;
            let live = lanes.live.0[i] != 0;
            let w = lanes.w.0[i];
            let code = lanes.code.0[i];
            if code == CROSSED {
                layer[i] = if lanes.uz.0[i] > 0.0 { layer[i] + 1 } else { layer[i] - 1 };
                lanes.load_layer(i, &consts[layer[i]]);
                continue;
            }
            if code == END_GLIDE && live {
                absorbed[layer[i]][i] += w;
            }
            // Exits (and, adding zero, roulette losses and placeholders) scored without a branch: R bins at
            // 0..bins, T bins at bins + 1.., each followed by an overflow slot for radii beyond the last bin.
            let (x, y) = (lanes.x.0[i], lanes.y.0[i]);
            let bin = (((x * x + y * y).sqrt() * inv_bin) as usize).min(bins);
            let w_exit = if live && code <= END_BOTTOM { w } else { 0.0 };
            let bottom = code == END_BOTTOM;
            exits[bin + usize::from(bottom) * (bins + 1)] += w_exit;
            totals[usize::from(bottom)] += w_exit;
            // The packet has ended: the lane takes the chunk's next photon, or idles (a placeholder whose tallies
            // are masked out) once there is none.
            let more = live && next < end;
            if live && !more {
                live_count -= 1;
            }
            if layer[i] != 0 {
                layer[i] = 0;
                lanes.load_layer(i, &consts[0]);
            }
            lanes.launch(i, next, more);
            next += u64::from(more);
        }
    }
    tally.rd += totals[0];
    tally.td += totals[1];
    for (t, e) in tally.r.iter_mut().zip(&exits[..bins]) {
        *t += e;
    }
    for (t, e) in tally.t.iter_mut().zip(&exits[bins + 1..2 * bins + 1]) {
        *t += e;
    }
    for (t, acc) in tally.absorbed.iter_mut().zip(&absorbed) {
        for a in acc {
            *t += a;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Words spread over the whole u32 range, `LANES` at a time.
    fn words(j: u64) -> W {
        let mut w = W::default();
        for (i, v) in w.0.iter_mut().enumerate() {
            let n = j * LANES as u64 + i as u64;
            *v = match n % 3 {
                0 => (n.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) as u32,
                1 => n as u32,
                _ => u32::MAX - n as u32,
            };
        }
        w
    }

    /// The branch-free −ln ξ against the library logarithm over the draws' grid (0, 1]: within 4.5·10⁻¹⁶ relative.
    #[test]
    fn neg_ln_matches_the_library() {
        let mut worst = 0.0f64;
        for j in 0..60_000 {
            let x = unit(words(j));
            let got = neg_ln(x);
            for i in 0..LANES {
                let exact = -x.0[i].ln();
                if exact == 0.0 {
                    assert_eq!(got.0[i], 0.0);
                } else {
                    worst = worst.max(((got.0[i] - exact) / exact).abs());
                }
            }
        }
        assert!(worst < 4.5e-16, "worst relative error {worst:e}");
    }

    /// The polynomial azimuth against the library sin/cos of 2π(word + ½)/2³², and unit length: within 10⁻¹⁵.
    #[test]
    fn azimuth_matches_the_library() {
        let mut worst = 0.0f64;
        for j in 0..60_000 {
            let w = words(j);
            let (c, s) = azimuth_cos_sin(w);
            for i in 0..LANES {
                let phi = ((f64::from(w.0[i]) + 0.5) / 4_294_967_296.0) * std::f64::consts::TAU;
                let (es, ec) = phi.sin_cos();
                let (c, s) = (c.0[i], s.0[i]);
                worst = worst.max((c - ec).abs()).max((s - es).abs()).max((c * c + s * s - 1.0).abs());
            }
        }
        assert!(worst < 1e-15, "worst error {worst:e}");
    }

    /// The lanes' Philox block is the reference Philox4x32-10 of each lane's counter, and the uniform is
    /// (w + 1)/2³².
    #[test]
    fn lane_draws_are_the_philox_blocks() {
        let seed = 0x0123_4567_89ab_cdef_u64;
        let keys = round_keys(seed);
        let special: [u64; 8] = [0, 1, 5, 0x1_0000_0005, 77, u64::MAX, 1 << 40, 12345];
        let photons: [u64; LANES] = std::array::from_fn(|i| special[i % 8] ^ (i as u64 / 8) << 20);
        let lo = W(photons.map(|k| k as u32));
        let hi = W(photons.map(|k| (k >> 32) as u32));
        let event = W(std::array::from_fn(|i| [0, 1, 2, 3, 7, u32::MAX, 100, 9][i % 8] ^ (i as u32 / 8)));
        let got = block([lo, hi, W([2; LANES]), event], &keys);
        for i in 0..LANES {
            let c = [lo.0[i], hi.0[i], 2, event.0[i]];
            let expected = super::super::rng::philox4x32_10(c, [seed as u32, (seed >> 32) as u32]);
            assert_eq!(got.map(|w| w.0[i]), expected, "lane {i}");
        }
        let w = W(std::array::from_fn(|i| [0, 1, 0x7fff_ffff, 0x8000_0000, u32::MAX, 3, 4, 5][i % 8]));
        let u = unit(w);
        for i in 0..LANES {
            assert_eq!(u.0[i], (f64::from(w.0[i]) + 1.0) / 4_294_967_296.0);
        }
    }
}
