//! The photon-lane engine of rtbake's Monte Carlo transport (`rtbake::transport::mc`): [`LANES`] photon packets traced side by side, one event of every lane
//! per step, without branches on the photons' histories (MCML, Wang, Jacques & Zheng 1995, §3.2–3.8; the physics
//! is the one of the module docs of `rtbake::transport::mc`).
//!
//! Every step computes, for all lanes of a group at once in packed arithmetic (`[f64; G]` structure-of-arrays
//! values whose every operation is one short loop the compiler vectorises; groups below): one Philox4x32-10 block
//! per lane (`rtbake::transport::rng`, counter (photon index lo, photon index hi, channel, event number): the
//! photon's stream is fixed by its index),
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
//! **Groups**: a step runs the 32 lanes as 32/G groups of G lanes, one after the other, each group's whole step in
//! registers of the path's width — G = 32 on AVX-512F, 16 on AVX2, 4 on the portable path (`GROUP_*`). At SSE2's
//! width a 32-lane value is sixteen registers, so every intermediate of the step went through memory; in groups of
//! 4 a value is two registers, and the portable path takes 0.5–0.6 of its former CPU time (BENCHMARKS.md, "Monte
//! Carlo per core").
//! The grouping keeps every byte: lane i is lane i mod G of group ⌊i/G⌋ and traces the same photon as before; a
//! group's step reads and writes only its own lanes, with the same IEEE operations in the same order per lane; its
//! two branches on lane data (`isotropic.all()`, `at_face.any()`, now taken per group) only skip work whose results
//! every lane of the group discards by its selects; and everything after the step — exits and refills in lane
//! order 0..31, absorption in per-lane, per-layer sums added in lane order at the end of the chunk — is the same
//! loop over the same 32 lanes whatever G is. A lane's absorbed weight is added to its own layer's sum only (the
//! kernel used to add zero to the other layers' sums, which leaves a sum of non-negative weights, never −0.0,
//! bit-identical).
//! Tests: `every_group_width_gives_the_same_bytes` (G = 1 … 32) and the checksums of the ungrouped kernel on every
//! path.
//!
//! **Draws**: each event uses the four words of its block: word 0 → the optical depth s = −ln ξ when none is
//! pending (ξ = (w + 1)/2³² ∈ (0, 1]; fdlibm's logarithm, branch-free); word 1 → the HG ξ at an interaction or
//! the Fresnel ξ at a face; word 2 → the azimuth φ (2 bits of quadrant and 30 bits within it, sin and cos by
//! Taylor polynomials); word 3 → the roulette ξ. Unused words are skipped, so event e of photon k always reads
//! block e.
//!
//! **Determinism**: only IEEE-754 additions, multiplications, divisions, square roots, comparisons, selects and
//! exact conversions are used, and "fma" is never enabled, so the AVX-512F, AVX2 and portable paths ([`Path`])
//! round identically and give the same bytes whatever their group width; lanes keep their own absorption sums,
//! added in lane order at the end of a chunk, and exits are scored in lane order.

//! **Why a crate of its own**: this is the hot loop of every Monte Carlo asset and it depends on nothing else of
//! rtbake, so the workspace gives it `opt-level = 3` in the dev profile too (`[profile.dev.package.rtbake-lanes]`
//! in the root `Cargo.toml`): the README's `cargo run` then traces photons at release speed, and only the code
//! around it keeps the dev profile's opt-level 1.
//!
//! **Forcing a path** (benchmarks): `RTBAKE_LANE_PATH=portable|avx2|avx512` makes [`Path::detect`] return that
//! path when the CPU supports it (every path gives the same bytes, so this changes only the speed).

/// Weight below which Russian roulette is played (MCML's default, §3.6).
pub const ROULETTE_THRESHOLD: f64 = 1e-4;
/// A packet survives roulette with chance 1/m and weight ×m, m = 10 (MCML §3.6).
pub const ROULETTE_CHANCE: f64 = 10.0;

/// Philox4x32-10 multipliers and Weyl key increments (Salmon et al., SC'11).
pub const M0: u32 = 0xD251_1F53;
/// See [`M0`].
pub const M1: u32 = 0xCD9E_8D57;
/// See [`M0`].
pub const W0: u32 = 0x9E37_79B9;
/// See [`M0`].
pub const W1: u32 = 0xBB67_AE85;

/// Taylor coefficients of sin θ/θ − 1 in θ² (−1/3!, 1/5!, …, 1/15!), |θ| ≤ π/4.
pub const SIN_TAYLOR: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
/// Taylor coefficients of (cos θ − 1) in θ² (−1/2!, 1/4!, …, −1/18!), |θ| ≤ π/4.
pub const COS_TAYLOR: [f64; 9] = [
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
    -1.0 / 6_402_373_705_728_000.0,
];

/// Per-layer constants of one channel, with what the photon loop would otherwise divide by precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    /// Depth of the layer's top and bottom faces, mm (the bottom may be infinite).
    pub z_top_mm: f64,
    pub z_bottom_mm: f64,
    /// σt = σa + σs, mm⁻¹ (0: a clear layer).
    pub sigma_t_per_mm: f64,
    /// 1/σt, mm (unused in a clear layer).
    pub inv_sigma_t_mm: f64,
    /// σa/σt (0 in a clear layer).
    pub absorb_fraction: f64,
    /// Henyey–Greenstein sampling: isotropic (|g| < 10⁻⁶: cos θ = 2ξ − 1), else the constants
    /// 1 − g², 1 − g, 2g, 1 + g², 1/(2g) of cos θ = (1 + g² − ((1 − g²)/(1 − g + 2gξ))²)/(2g) (MCML eq. 3.28).
    pub isotropic: bool,
    pub hg: [f64; 5],
    /// Refractive index of the layer.
    pub eta: f64,
}

/// What every photon of one channel shares.
#[derive(Clone, Copy, Debug)]
pub struct Channel<'a> {
    /// The layers, top to bottom.
    pub media: &'a [Medium],
    /// Refractive index of the ambient medium above and below the stack.
    pub eta_above: f64,
    pub eta_below: f64,
    /// 1 − Rsp.
    pub start_weight: f64,
    /// The channel's Philox counter word.
    pub index: u32,
    /// The Philox key (photon k of the channel draws block e at counter (k, index, e)).
    pub seed: u64,
}

/// Raw weight sums of a chunk or batch of one channel (photon weights, not yet divided by the photon count or the
/// annulus area).
#[derive(Clone, Debug, PartialEq)]
pub struct Tally {
    /// Weight leaving through the top face per radial bin.
    pub r: Vec<f64>,
    /// Weight leaving through the bottom face per radial bin.
    pub t: Vec<f64>,
    /// Weight leaving through the top face (all radii).
    pub rd: f64,
    /// Weight leaving through the bottom face (all radii).
    pub td: f64,
    /// Weight absorbed per layer.
    pub absorbed: Vec<f64>,
    /// Interactions traced.
    pub interactions: u64,
}

impl Tally {
    /// Zero tallies for `bins` radial bins and `layers` layers.
    pub fn new(bins: usize, layers: usize) -> Self {
        Self { r: vec![0.0; bins], t: vec![0.0; bins], rd: 0.0, td: 0.0, absorbed: vec![0.0; layers], interactions: 0 }
    }
    /// Adds `o` bin by bin.
    pub fn add(&mut self, o: &Tally) {
        for (a, b) in self.r.iter_mut().zip(&o.r) {
            *a += b;
        }
        for (a, b) in self.t.iter_mut().zip(&o.t) {
            *a += b;
        }
        self.rd += o.rd;
        self.td += o.td;
        for (a, b) in self.absorbed.iter_mut().zip(&o.absorbed) {
            *a += b;
        }
        self.interactions += o.interactions;
    }
}

/// Photon packets traced side by side (the same on every path: the lane a photon gets decides the order of the
/// per-lane absorption sums, so it must not depend on the CPU; at most 32, the width of the step's outcome mask).
pub const LANES: usize = 32;
const _: () = assert!(LANES <= 32, "the outcome mask of a step is a u32");

/// Lanes per group on each path (crate docs, "Groups"): the widths that ran fastest in CPU seconds of
/// `examples/lane_paths` on the problems of `scripts/bench_mcml.sh` (project's 2-core AMD EPYC, 2026-11-26):
/// AVX-512F (32 registers of 8 doubles) the whole 32, 16 lanes 3–6 % slower; AVX2 (16 registers of 4) 16, with
/// 32 lanes 10–23 % slower and 8 lanes 0–9 %; SSE2 (16 registers of 2) 4, with 8 lanes 5–17 % and 2 lanes
/// 12–18 % slower. aarch64's NEON also has registers of 2 doubles and takes the portable width, not measured here.
const GROUP_AVX512: usize = 32;
const GROUP_AVX2: usize = 16;
const GROUP_PORTABLE: usize = 4;

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
    /// The widest path this CPU supports, or the one `RTBAKE_LANE_PATH` names if the CPU supports it (crate docs).
    pub fn detect() -> Self {
        let forced = match std::env::var("RTBAKE_LANE_PATH").as_deref() {
            Ok("portable") => Some(Path::Portable),
            Ok("avx2") => Some(Path::Avx2),
            Ok("avx512") => Some(Path::Avx512),
            _ => None,
        };
        if let Some(path) = forced.filter(|p| p.supported()) {
            return path;
        }
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
pub fn trace_chunk(path: Path, ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
    assert!(path.supported(), "{path:?} is not supported by this CPU");
    match path {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU supports AVX-512F (checked above).
        Path::Avx512 => unsafe { x86::trace_avx512(ch, bin_mm, first, count, tally) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU supports AVX2 (checked above).
        Path::Avx2 => unsafe { x86::trace_avx2(ch, bin_mm, first, count, tally) },
        _ => trace::<GROUP_PORTABLE>(ch, bin_mm, first, count, tally),
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{trace, Channel, Tally, GROUP_AVX2, GROUP_AVX512};

    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn trace_avx512(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
        trace::<GROUP_AVX512>(ch, bin_mm, first, count, tally)
    }

    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn trace_avx2(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
        trace::<GROUP_AVX2>(ch, bin_mm, first, count, tally)
    }
}

/// `N` f64 values, one per lane of a group. Every operation is a fixed-length loop of one IEEE operation, which the
/// compiler turns into packed instructions of the enabled width (a long fused loop body is not vectorised).
#[derive(Clone, Copy, Debug, PartialEq)]
struct V<const N: usize>([f64; N]);
/// `N` u32 values.
#[derive(Clone, Copy, Debug, PartialEq)]
struct W<const N: usize>([u32; N]);
/// A per-lane condition: all ones (true) or zero (false) in 64 bits, the form of a packed comparison's result, so
/// that selects are bitwise on every instruction set.
#[derive(Clone, Copy, Debug, PartialEq)]
struct M<const N: usize>([u64; N]);

/// The mask lane of a condition.
#[inline(always)]
fn mask(b: bool) -> u64 {
    u64::from(b).wrapping_neg()
}

macro_rules! lanewise {
    ($out:ty, |$($a:ident),*| $e:expr) => {{
        let mut r = <$out>::default();
        for i in 0..r.0.len() {
            $(let $a = $a.0[i];)*
            r.0[i] = $e;
        }
        r
    }};
}

impl<const N: usize> Default for V<N> {
    fn default() -> Self {
        V([0.0; N])
    }
}

impl<const N: usize> Default for W<N> {
    fn default() -> Self {
        W([0; N])
    }
}

impl<const N: usize> Default for M<N> {
    fn default() -> Self {
        M([0; N])
    }
}

impl<const N: usize> V<N> {
    #[inline(always)]
    fn splat(v: f64) -> V<N> {
        V([v; N])
    }
    #[inline(always)]
    fn lt(self, o: V<N>) -> M<N> {
        let a = self;
        lanewise!(M<N>, |a, o| mask(a < o))
    }
    #[inline(always)]
    fn le(self, o: V<N>) -> M<N> {
        let a = self;
        lanewise!(M<N>, |a, o| mask(a <= o))
    }
    #[inline(always)]
    fn eq(self, o: V<N>) -> M<N> {
        let a = self;
        lanewise!(M<N>, |a, o| mask(a == o))
    }
    #[inline(always)]
    fn sqrt(self) -> V<N> {
        let a = self;
        lanewise!(V<N>, |a| a.sqrt())
    }
    /// max(v, 0) as a select (no NaN handling needed: the arguments are finite or discarded).
    #[inline(always)]
    fn pos(self) -> V<N> {
        let a = self;
        lanewise!(V<N>, |a| if a > 0.0 { a } else { 0.0 })
    }
    #[inline(always)]
    fn abs(self) -> V<N> {
        let a = self;
        lanewise!(V<N>, |a| a.abs())
    }
}

impl<const N: usize> M<N> {
    #[inline(always)]
    fn select(self, a: V<N>, b: V<N>) -> V<N> {
        let m = self;
        lanewise!(V<N>, |m, a, b| f64::from_bits((a.to_bits() & m) | (b.to_bits() & !m)))
    }
    #[inline(always)]
    fn select_w(self, a: W<N>, b: W<N>) -> W<N> {
        let m = self;
        lanewise!(W<N>, |m, a, b| (a & m as u32) | (b & !(m as u32)))
    }
    #[inline(always)]
    fn and(self, o: M<N>) -> M<N> {
        let a = self;
        lanewise!(M<N>, |a, o| a & o)
    }
    #[inline(always)]
    fn or(self, o: M<N>) -> M<N> {
        let a = self;
        lanewise!(M<N>, |a, o| a | o)
    }
    #[inline(always)]
    fn not(self) -> M<N> {
        let a = self;
        lanewise!(M<N>, |a| !a)
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
        impl<const N: usize> std::ops::$tr for V<N> {
            type Output = V<N>;
            #[inline(always)]
            fn $f(self, o: V<N>) -> V<N> {
                let a = self;
                lanewise!(V<N>, |a, o| a $op o)
            }
        }
        impl<const N: usize> std::ops::$tr<f64> for V<N> {
            type Output = V<N>;
            #[inline(always)]
            fn $f(self, o: f64) -> V<N> {
                let a = self;
                let o = V::<N>::splat(o);
                lanewise!(V<N>, |a, o| a $op o)
            }
        }
    };
}
binop!(Add, add, +);
binop!(Sub, sub, -);
binop!(Mul, mul, *);
binop!(Div, div, /);

impl<const N: usize> std::ops::Neg for V<N> {
    type Output = V<N>;
    #[inline(always)]
    fn neg(self) -> V<N> {
        let a = self;
        lanewise!(V<N>, |a| -a)
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
fn neg_ln<const N: usize>(x: V<N>) -> V<N> {
    let mut y = V::default();
    let mut dk = V::default();
    for i in 0..N {
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

use {COS_TAYLOR as COS, SIN_TAYLOR as SIN};

/// (cos φ, sin φ) per lane of the azimuth φ = (q + ½)·π/2 + θ of a 32-bit word: q = its top two bits (the
/// quadrant), θ = ((low 30 bits + ½)/2³⁰ − ½)·π/2 ∈ (−π/4, π/4) — φ uniform on `[0, 2π)` on a grid of 2π/2³², by
/// polynomials and selects (no table, no branch): cos(π/4 + θ) = (cos θ − sin θ)/√2,
/// sin(π/4 + θ) = (cos θ + sin θ)/√2, then q quarter turns.
#[inline(always)]
fn azimuth_cos_sin<const N: usize>(word: W<N>) -> (V<N>, V<N>) {
    let low = lanewise!(V<N>, |word| f64::from((word & 0x3fff_ffff) as i32));
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
    let odd = lanewise!(M<N>, |word| mask(word & 0x4000_0000 != 0));
    let half = lanewise!(M<N>, |word| mask(word & 0x8000_0000 != 0));
    let (c1, s1) = (odd.select(-s, c), odd.select(c, s));
    (half.select(-c1, c1), half.select(-s1, s1))
}

/// Per lane a uniform in (0, 1] on the grid k/2³² (k = 1..=2³²) from a word, by an exact signed conversion.
#[inline(always)]
fn unit<const N: usize>(word: W<N>) -> V<N> {
    lanewise!(V<N>, |word| (f64::from((word ^ 0x8000_0000) as i32) + 2_147_483_649.0) * (1.0 / 4_294_967_296.0))
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

/// Philox4x32-10 of the counters `c` per lane under the round keys `keys` (Salmon et al., SC'11): per round the
/// 32×32 → 64-bit products M0·c₀ and M1·c₂ split into high and low words. Written as products of zero-extended
/// words, at the paths' group widths the compiler forms them with packed 32×32 → 64 multiplies (SSE2 `pmuludq`,
/// AVX2/AVX-512F `vpmuludq`; seen in the disassembly). Over the whole 32 lanes at SSE2's width it multiplied one
/// lane at a time, hence the 16-bit schoolbook products the kernel used before its groups; in groups of 4 those
/// are the slower form (the portable path took 1.5× the CPU time with them). Exact integer arithmetic, so the same
/// words on every path.
#[inline(always)]
fn block<const N: usize>(c: [W<N>; 4], keys: &[[u32; 2]; 10]) -> [W<N>; 4] {
    let [mut c0, mut c1, mut c2, mut c3] = c;
    for k in keys {
        let mut n = [W::default(); 4];
        for i in 0..N {
            let p0 = u64::from(c0.0[i]) * u64::from(M0);
            let p1 = u64::from(c2.0[i]) * u64::from(M1);
            n[0].0[i] = (p1 >> 32) as u32 ^ c1.0[i] ^ k[0];
            n[1].0[i] = p1 as u32;
            n[2].0[i] = (p0 >> 32) as u32 ^ c3.0[i] ^ k[1];
            n[3].0[i] = p0 as u32;
        }
        [c0, c1, c2, c3] = n;
    }
    [c0, c1, c2, c3]
}

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
struct Lanes<const N: usize> {
    x: V<N>,
    y: V<N>,
    z: V<N>,
    ux: V<N>,
    uy: V<N>,
    uz: V<N>,
    w: V<N>,
    /// Optical depth left of the current step (0: draw a new one).
    s: V<N>,
    z_top: V<N>,
    z_bottom: V<N>,
    sigma_t: V<N>,
    inv_sigma_t: V<N>,
    absorb: V<N>,
    isotropic: M<N>,
    hg: [V<N>; 5],
    ratio_above: V<N>,
    ratio_below: V<N>,
    top: M<N>,
    bottom: M<N>,
    photon_lo: W<N>,
    photon_hi: W<N>,
    event: W<N>,
    /// Whether the lane traces a photon of the chunk (false once the chunk has none left for it).
    live: M<N>,
    /// Per lane: weight absorbed in this step (0 elsewhere), the outcome code (`END_*`, 0 = continues) and 1 where
    /// a live packet interacted.
    dw: V<N>,
    code: W<N>,
    interacted: W<N>,
}

const END_TOP: u32 = 1;
const END_BOTTOM: u32 = 2;
const END_ROULETTE: u32 = 3;
const END_GLIDE: u32 = 4;
const CROSSED: u32 = 5;

impl<const N: usize> Lanes<N> {
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
    /// `start_weight` (1 − Rsp); its layer constants are the caller's (those of the first layer).
    fn launch(&mut self, i: usize, k: u64, live: bool, start_weight: f64) {
        self.x.0[i] = 0.0;
        self.y.0[i] = 0.0;
        self.z.0[i] = 0.0;
        self.ux.0[i] = 0.0;
        self.uy.0[i] = 0.0;
        self.uz.0[i] = 1.0;
        self.w.0[i] = start_weight;
        self.s.0[i] = 0.0;
        self.photon_lo.0[i] = k as u32;
        self.photon_hi.0[i] = (k >> 32) as u32;
        self.event.0[i] = 0;
        self.live.0[i] = mask(live);
    }

    /// One event of every lane (module docs). Writes `dw`, `code` and `interacted`; no branch on lane data.
    #[inline(always)]
    fn step(&mut self, channel: u32, keys: &[[u32; 2]; 10]) {
        let [r0, r1, r2, r3] = block([self.photon_lo, self.photon_hi, W([channel; N]), self.event], keys);
        let event = self.event;
        self.event = lanewise!(W<N>, |event| event.wrapping_add(1));
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
        let splat = |v: u32| W([v; N]);
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
        self.interacted = lanewise!(W<N>, |interact, live| (interact & live) as u32 & 1);
        self.code = interact.select_w(lost.select_w(splat(END_ROULETTE), splat(0)), face_code);
    }
}

impl<const N: usize> M<N> {
    #[inline(always)]
    fn select_m(self, a: M<N>, b: M<N>) -> M<N> {
        let m = self;
        lanewise!(M<N>, |m, a, b| (a & m) | (b & !m))
    }
}

/// The lane engine over one chunk (module docs); compiled into each [`Path`]'s target-feature function.
#[inline(always)]
fn trace<const G: usize>(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
    const { assert!(G > 0 && LANES.is_multiple_of(G), "a group width divides LANES") };
    let media = ch.media;
    let last = media.len() - 1;
    let consts: Vec<LayerConsts> = media
        .iter()
        .enumerate()
        .map(|(j, m)| LayerConsts {
            z_top: m.z_top_mm,
            z_bottom: m.z_bottom_mm,
            sigma_t: m.sigma_t_per_mm,
            inv_sigma_t: m.inv_sigma_t_mm,
            absorb: m.absorb_fraction,
            isotropic: m.isotropic,
            hg: m.hg,
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
    // Lane i is lane i % G of group i / G (crate docs: the grouping changes no lane's arithmetic).
    let mut groups = vec![Lanes::<G>::default(); LANES / G];
    let mut layer = [0usize; LANES];
    for i in 0..LANES {
        let lanes = &mut groups[i / G];
        lanes.load_layer(i % G, &consts[0]);
        lanes.launch(i % G, next, next < end, ch.start_weight);
        next = (next + 1).min(end);
    }
    // Exit weights (R then T, module docs of the loop below) and the totals Rd, Td.
    let mut exits = vec![0.0f64; 2 * (bins + 1)];
    let mut totals = [0.0f64; 2];
    // Absorbed weight per layer and lane.
    let mut absorbed = vec![[0.0f64; LANES]; media.len()];
    let mut live_count = LANES.min(count as usize);
    while live_count > 0 {
        let mut interactions = 0u32;
        let mut special = 0u32;
        for (g, lanes) in groups.iter_mut().enumerate() {
            lanes.step(ch.index, &keys);
            for (j, &dw) in lanes.dw.0.iter().enumerate() {
                let i = g * G + j;
                absorbed[layer[i]][i] += dw;
            }
            for (j, (&n, &code)) in lanes.interacted.0.iter().zip(&lanes.code.0).enumerate() {
                interactions += n;
                special |= u32::from(code != 0) << (g * G + j);
            }
        }
        tally.interactions += u64::from(interactions);
        while special != 0 {
            let i = special.trailing_zeros() as usize;
            special &= special - 1;
            let (lanes, j) = (&mut groups[i / G], i % G);
            let live = lanes.live.0[j] != 0;
            let w = lanes.w.0[j];
            let code = lanes.code.0[j];
            if code == CROSSED {
                layer[i] = if lanes.uz.0[j] > 0.0 { layer[i] + 1 } else { layer[i] - 1 };
                lanes.load_layer(j, &consts[layer[i]]);
                continue;
            }
            if code == END_GLIDE && live {
                absorbed[layer[i]][i] += w;
            }
            // Exits (and, adding zero, roulette losses and placeholders) scored without a branch: R bins at
            // 0..bins, T bins at bins + 1.., each followed by an overflow slot for radii beyond the last bin.
            let (x, y) = (lanes.x.0[j], lanes.y.0[j]);
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
                lanes.load_layer(j, &consts[0]);
            }
            lanes.launch(j, next, more, ch.start_weight);
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

    /// Philox4x32-10 of one counter, written round by round from its definition (Salmon et al., SC'11).
    fn philox4x32_10(mut c: [u32; 4], mut k: [u32; 2]) -> [u32; 4] {
        for round in 0..10 {
            if round > 0 {
                k = [k[0].wrapping_add(W0), k[1].wrapping_add(W1)];
            }
            let p0 = u64::from(M0) * u64::from(c[0]);
            let p1 = u64::from(M1) * u64::from(c[2]);
            c = [(p1 >> 32) as u32 ^ c[1] ^ k[0], p1 as u32, (p0 >> 32) as u32 ^ c[3] ^ k[1], p0 as u32];
        }
        c
    }

    /// The reference above reproduces Random123's known-answer vectors.
    #[test]
    fn philox_reference_matches_the_known_answers() {
        assert_eq!(philox4x32_10([0; 4], [0; 2]), [0x6627_e8d5, 0xe169_c58d, 0xbc57_ac4c, 0x9b00_dbd8]);
        assert_eq!(philox4x32_10([u32::MAX; 4], [u32::MAX; 2]), [0x408f_276d, 0x41c8_3b0e, 0xa20b_c7c6, 0x6d54_51fd]);
        assert_eq!(
            philox4x32_10([0x243f_6a88, 0x85a3_08d3, 0x1319_8a2e, 0x0370_7344], [0xa409_3822, 0x299f_31d0]),
            [0xd16c_fe09, 0x94fd_cceb, 0x5001_e420, 0x2412_6ea1]
        );
    }

    /// Words spread over the whole u32 range, `LANES` at a time.
    fn words(j: u64) -> W<LANES> {
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
            let expected = philox4x32_10(c, [seed as u32, (seed >> 32) as u32]);
            assert_eq!(got.map(|w| w.0[i]), expected, "lane {i}");
        }
        let w: W<LANES> = W(std::array::from_fn(|i| [0, 1, 0x7fff_ffff, 0x8000_0000, u32::MAX, 3, 4, 5][i % 8]));
        let u = unit(w);
        for i in 0..LANES {
            assert_eq!(u.0[i], (f64::from(w.0[i]) + 1.0) / 4_294_967_296.0);
        }
    }

    /// A layer of the test stacks: thickness (mm, `inf` for a semi-infinite one), η, σa, σs′ (mm⁻¹), HG g.
    fn medium(z_top_mm: f64, thickness_mm: f64, eta: f64, sigma_a: f64, sigma_s_prime: f64, g: f64) -> Medium {
        let sigma_t = sigma_a + sigma_s_prime / (1.0 - g);
        Medium {
            z_top_mm,
            z_bottom_mm: z_top_mm + thickness_mm,
            sigma_t_per_mm: sigma_t,
            inv_sigma_t_mm: if sigma_t > 0.0 { 1.0 / sigma_t } else { 0.0 },
            absorb_fraction: if sigma_t > 0.0 { sigma_a / sigma_t } else { 0.0 },
            isotropic: g.abs() < 1e-6,
            hg: [1.0 - g * g, 1.0 - g, 2.0 * g, 1.0 + g * g, 0.5 / g],
            eta,
        }
    }

    /// Every branch of the step: a clear top layer (packets cross it without interacting, reflect at its faces and
    /// cross into the next layer), a forward-scattering layer (g 0.8), an isotropic slab over a mismatched boundary
    /// (transmission, T(r)).
    fn three_layers() -> Vec<Medium> {
        vec![
            medium(0.0, 0.1, 1.45, 0.0, 0.0, 0.0),
            medium(0.1, 0.3, 1.4, 1.2, 4.0, 0.8),
            medium(0.4, 0.6, 1.33, 0.2, 2.0, 0.0),
        ]
    }

    /// Photons `0..photons` of channel 1 under seed 7 in chunks of 1000 (the last one partial, so lanes idle at
    /// its end), summed chunk by chunk as `rtbake::transport::mc` does.
    fn run(media: &[Medium], photons: u64, chunk: impl Fn(&Channel<'_>, u64, u64, &mut Tally)) -> Tally {
        let ch = Channel { media, eta_above: 1.0, eta_below: 1.0, start_weight: 0.966, index: 1, seed: 7 };
        let mut tally = Tally::new(40, media.len());
        for first in (0..photons).step_by(1000) {
            let mut t = Tally::new(40, media.len());
            chunk(&ch, first, 1000.min(photons - first), &mut t);
            tally.add(&t);
        }
        tally
    }

    /// FNV-1a over the bits of every tally (the checksum `examples/lane_paths` prints).
    fn checksum(t: &Tally) -> u64 {
        let words = t.r.iter().chain(&t.t).chain(&t.absorbed).chain([&t.rd, &t.td]).map(|v| v.to_bits());
        words.chain([t.interactions]).fold(0xcbf2_9ce4_8422_2325, |h, w| (h ^ w).wrapping_mul(0x0000_0100_0000_01b3))
    }

    /// Every group width gives the same tallies, bit for bit, on every branch of the step: the grouping changes
    /// which instructions run, not any lane's arithmetic or the order of the sums (crate docs, "Groups").
    #[test]
    fn every_group_width_gives_the_same_bytes() {
        let media = three_layers();
        let whole = run(&media, 2500, |ch, first, n, t| trace::<32>(ch, 0.05, first, n, t));
        assert!(whole.rd > 0.0 && whole.td > 0.0 && whole.absorbed[1] > 0.0 && whole.absorbed[2] > 0.0, "{whole:?}");
        assert_eq!(run(&media, 2500, |ch, first, n, t| trace::<16>(ch, 0.05, first, n, t)), whole, "16");
        assert_eq!(run(&media, 2500, |ch, first, n, t| trace::<8>(ch, 0.05, first, n, t)), whole, "8");
        assert_eq!(run(&media, 2500, |ch, first, n, t| trace::<4>(ch, 0.05, first, n, t)), whole, "4");
        assert_eq!(run(&media, 2500, |ch, first, n, t| trace::<2>(ch, 0.05, first, n, t)), whole, "2");
        assert_eq!(run(&media, 2500, |ch, first, n, t| trace::<1>(ch, 0.05, first, n, t)), whole, "1");
    }

    /// FNV-1a checksums of [`three_layers`] and of a semi-infinite isotropic layer (η 1.3, σa 0.1, σs′ 1.0),
    /// 2500 photons each, from the kernel of commit 56f3260 (all three paths agreed).
    const GOLDEN_THREE_LAYERS: u64 = 0x906e_47c1_e619_f557;
    const GOLDEN_SEMI_INFINITE: u64 = 0x6bbc_1894_6efc_e27e;

    /// Every path this CPU supports gives the tallies of the 32-lane kernel before the paths were grouped
    /// (commit 56f3260, whose `trace_chunk` printed these checksums for the same runs on its AVX-512F, AVX2 and
    /// portable paths): grouping and the Philox products' new form changed no byte.
    #[test]
    fn every_path_gives_the_bytes_of_the_ungrouped_kernel() {
        let single = [medium(0.0, f64::INFINITY, 1.3, 0.1, 1.0, 0.0)];
        for path in [Path::Avx512, Path::Avx2, Path::Portable].into_iter().filter(|p| p.supported()) {
            let trace = |ch: &Channel<'_>, first, n, t: &mut Tally| trace_chunk(path, ch, 0.05, first, n, t);
            assert_eq!(checksum(&run(&three_layers(), 2500, trace)), GOLDEN_THREE_LAYERS, "{path:?}");
            assert_eq!(checksum(&run(&single, 2500, trace)), GOLDEN_SEMI_INFINITE, "{path:?}");
        }
    }
}
