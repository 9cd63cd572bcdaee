//! The photon-lane engine of [`super::mc`]: [`LANES`] photon packets traced side by side, one event of every lane
//! per step, without branches on the photons' histories (MCML, Wang, Jacques & Zheng 1995, §3.2–3.8; the physics
//! is the one of the module docs of [`super::mc`]).
//!
//! Every step computes, for all lanes at once over `[f64; LANES]` structure-of-arrays loops that the compiler
//! vectorises: one Philox4x32-10 block per lane ([`super::rng`], counter (photon index lo, photon index hi,
//! channel, event number): the photon's stream is fixed by its index), both the interaction (implicit capture,
//! Henyey–Greenstein polar angle, azimuth, Russian roulette; MCML eq. 3.28–3.31) and the arrival at the face the
//! packet heads for (Fresnel reflectance, MCML eq. 3.36–3.38, reflection or Snell refraction), and keeps one of the
//! two per lane by mask. The rare outcomes — a packet leaving the stack (scored in R(r) or T(r)), losing the
//! roulette, gliding forever in a clear layer, or crossing into another layer — are handled per lane after the
//! step; a lane whose packet has ended is refilled with the chunk's next photon index, so the refill order depends
//! only on the histories.
//!
//! **Draws**: each event uses the four words of its block: word 0 → the optical depth s = −ln ξ when none is
//! pending (ξ = (w + 1)/2³² ∈ (0, 1]; a branch-free logarithm, [`neg_ln`]); word 1 → the HG ξ at an interaction or
//! the Fresnel ξ at a face; word 2 → the azimuth φ (2 bits of quadrant and 30 bits within it,
//! [`azimuth_cos_sin`]); word 3 → the roulette ξ. Unused words are skipped, so event e of photon k always reads
//! block e.
//!
//! **Determinism**: only IEEE-754 additions, multiplications, divisions, square roots, comparisons and exact
//! conversions are used, and "fma" is never enabled, so the AVX-512F, AVX2 and portable paths ([`Path`]) round
//! identically and give the same bytes; lanes keep their own absorption sums, added in lane order at the end of a
//! chunk, and exits are scored in lane order.

use super::mc::{Channel, Tally, ROULETTE_CHANCE, ROULETTE_THRESHOLD};
use super::rng::{M0, M1, W0, W1};

/// Photon packets traced side by side (the same on every path: the lane a photon gets decides the order of the
/// per-lane absorption sums, so it must not depend on the CPU).
pub const LANES: usize = 8;

type F = [f64; LANES];
type U = [u32; LANES];

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

/// ln 2 split for an exact k·ln 2 (fdlibm `e_log.c`).
const LN2_HI: f64 = 6.931_471_803_691_238_164_90e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_700_02e-10;
/// fdlibm `e_log.c` minimax coefficients of (ln(1 + f) − 2s)/s ... in z = s², s = f/(2 + f), |error| < 2⁻⁵⁸.7.
const LG: [f64; 7] = [
    6.666_666_666_666_735_130e-1,
    3.999_999_999_940_941_908e-1,
    2.857_142_874_366_239_149e-1,
    2.222_219_843_214_978_396e-1,
    1.818_357_216_161_805_012e-1,
    1.531_383_769_920_937_332e-1,
    1.479_819_860_511_658_591e-1,
];

/// −ln x for a normal x in (0, 1], branch-free (fdlibm's `__ieee754_log`: x = 2ᵏ·(1 + f) with 1 + f in
/// `[√2/2, √2)`, ln(1 + f) = f − (f²/2 − s·(f²/2 + R(s²))), s = f/(2 + f); within an ulp or two of the exact value).
#[inline(always)]
pub fn neg_ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let hx = (bits >> 32) as u32;
    let mut k = (hx >> 20) as i32 - 1023;
    let hm = hx & 0x000f_ffff;
    let i = (hm + 0x95f64) & 0x0010_0000;
    let y = f64::from_bits((u64::from(hm | (i ^ 0x3ff0_0000)) << 32) | (bits & 0xffff_ffff));
    k += (i >> 20) as i32;
    let f = y - 1.0;
    let dk = f64::from(k);
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    let hfsq = 0.5 * f * f;
    ((hfsq - (s * (hfsq + r) + dk * LN2_LO)) - f) - dk * LN2_HI
}

/// Taylor coefficients (−1)ⁿ/(2n + 1)! and (−1)ⁿ/(2n)!, n = 1.., of sin and cos on |θ| ≤ π/4 (the first omitted
/// terms are below 10⁻¹⁶).
const SIN: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];
const COS: [f64; 9] = [
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

/// (cos φ, sin φ) of the azimuth φ = (q + ½)·π/2 + θ of a 32-bit word: q = its top two bits (the quadrant),
/// θ = ((low 30 bits + ½)/2³⁰ − ½)·π/2 ∈ (−π/4, π/4) — φ uniform on `[0, 2π)` on a grid of 2π/2³², by polynomials
/// and selects (no table, no branch): cos(π/4 + θ) = (cos θ − sin θ)/√2, sin(π/4 + θ) = (cos θ + sin θ)/√2, then q
/// quarter turns.
#[inline(always)]
pub fn azimuth_cos_sin(word: u32) -> (f64, f64) {
    let q = word >> 30;
    let frac = (f64::from((word & 0x3fff_ffff) as i32) + 0.5) * (1.0 / 1_073_741_824.0);
    let t = (frac - 0.5) * std::f64::consts::FRAC_PI_2;
    let z = t * t;
    let mut ps = SIN[7];
    for c in SIN[..7].iter().rev() {
        ps = ps * z + c;
    }
    let sin_t = t + t * z * ps;
    let mut pc = COS[8];
    for c in COS[..8].iter().rev() {
        pc = pc * z + c;
    }
    let cos_t = 1.0 + z * pc;
    let c = (cos_t - sin_t) * std::f64::consts::FRAC_1_SQRT_2;
    let s = (cos_t + sin_t) * std::f64::consts::FRAC_1_SQRT_2;
    // Quarter turns: q = 1: (−s, c); q = 2: (−c, −s); q = 3: (s, −c).
    let (c1, s1) = if q & 1 != 0 { (-s, c) } else { (c, s) };
    if q & 2 != 0 {
        (-c1, -s1)
    } else {
        (c1, s1)
    }
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

/// Philox4x32-10 of `c` under the round keys `keys` ([`super::rng::philox4x32_10`], written for one lane of a
/// vectorised loop: the 32×32 → 64-bit products become packed multiplies).
#[inline(always)]
fn block(mut c: [u32; 4], keys: &[[u32; 2]; 10]) -> [u32; 4] {
    for k in keys {
        let p0 = u64::from(M0) * u64::from(c[0]);
        let p1 = u64::from(M1) * u64::from(c[2]);
        c = [(p1 >> 32) as u32 ^ c[1] ^ k[0], p1 as u32, (p0 >> 32) as u32 ^ c[3] ^ k[1], p0 as u32];
    }
    c
}

/// A uniform in (0, 1] on the grid k/2³² (k = 1..=2³²) from a word, by an exact signed conversion.
#[inline(always)]
fn unit(word: u32) -> f64 {
    (f64::from((word ^ 0x8000_0000) as i32) + 2_147_483_649.0) * (1.0 / 4_294_967_296.0)
}

#[inline(always)]
fn pos(v: f64) -> f64 {
    if v > 0.0 {
        v
    } else {
        0.0
    }
}

/// The per-lane copy of one layer's constants (reloaded when a packet changes layer).
#[derive(Clone, Copy, Debug, Default)]
struct LayerConsts {
    z_top: f64,
    z_bottom: f64,
    sigma_t: f64,
    inv_sigma_t: f64,
    absorb: f64,
    /// 1 for an isotropic layer (cos θ = 2ξ − 1), else 0.
    iso: f64,
    /// 1 − g², 1 − g, 2g, 1 + g², 1/(2g).
    hg: [f64; 5],
    eta: f64,
    n_above: f64,
    n_below: f64,
    /// 1 in the first layer, 1 in the last (leaving through that face ends the packet).
    top: f64,
    bottom: f64,
}

/// Structure-of-arrays state of the lanes.
#[derive(Clone, Debug, Default)]
struct Lanes {
    x: F,
    y: F,
    z: F,
    ux: F,
    uy: F,
    uz: F,
    w: F,
    /// Optical depth left of the current step (0: draw a new one).
    s: F,
    z_top: F,
    z_bottom: F,
    sigma_t: F,
    inv_sigma_t: F,
    absorb: F,
    iso: F,
    hg: [F; 5],
    eta: F,
    n_above: F,
    n_below: F,
    top: F,
    bottom: F,
    photon_lo: U,
    photon_hi: U,
    event: U,
    /// 1 while the lane traces a photon of the chunk, 0 once the chunk has none left for it.
    live: F,
    /// Per lane: weight absorbed in this step (0 elsewhere) and the outcome code (`END_*`, 0 = continues).
    dw: F,
    code: U,
    interacted: U,
}

const END_TOP: u32 = 1;
const END_BOTTOM: u32 = 2;
const END_ROULETTE: u32 = 3;
const END_GLIDE: u32 = 4;
const CROSSED: u32 = 5;

impl Lanes {
    fn load_layer(&mut self, i: usize, m: &LayerConsts) {
        self.z_top[i] = m.z_top;
        self.z_bottom[i] = m.z_bottom;
        self.sigma_t[i] = m.sigma_t;
        self.inv_sigma_t[i] = m.inv_sigma_t;
        self.absorb[i] = m.absorb;
        self.iso[i] = m.iso;
        for (h, v) in self.hg.iter_mut().zip(m.hg) {
            h[i] = v;
        }
        self.eta[i] = m.eta;
        self.n_above[i] = m.n_above;
        self.n_below[i] = m.n_below;
        self.top[i] = m.top;
        self.bottom[i] = m.bottom;
    }

    /// Lane `i` starts photon `k` (or, with `live` false, a placeholder whose tallies are masked out).
    fn launch(&mut self, i: usize, k: u64, live: bool, start_weight: f64, first_layer: &LayerConsts) {
        self.x[i] = 0.0;
        self.y[i] = 0.0;
        self.z[i] = 0.0;
        self.ux[i] = 0.0;
        self.uy[i] = 0.0;
        self.uz[i] = 1.0;
        self.w[i] = start_weight;
        self.s[i] = 0.0;
        self.photon_lo[i] = k as u32;
        self.photon_hi[i] = (k >> 32) as u32;
        self.event[i] = 0;
        self.live[i] = if live { 1.0 } else { 0.0 };
        self.load_layer(i, first_layer);
    }

    /// One event of every lane (module docs). Writes `dw`, `code` and `interacted`; no branch on lane data.
    #[inline(always)]
    fn step(&mut self, channel: u32, keys: &[[u32; 2]; 10]) {
        for i in 0..LANES {
            // One Philox4x32-10 block: counter (photon lo, photon hi, channel, event).
            let c = block([self.photon_lo[i], self.photon_hi[i], channel, self.event[i]], keys);
            self.event[i] = self.event[i].wrapping_add(1);
            let xi1 = unit(c[1]);

            let (x, y, z) = (self.x[i], self.y[i], self.z[i]);
            let (ux, uy, uz) = (self.ux[i], self.uy[i], self.uz[i]);
            let w = self.w[i];
            let s = if self.s[i] == 0.0 { neg_ln(unit(c[0])) } else { self.s[i] };
            let sigma_t = self.sigma_t[i];
            let down = uz > 0.0;
            let face_z = if down { self.z_bottom[i] } else { self.z_top[i] };
            let d_step = s * self.inv_sigma_t[i];
            let z_step = z + uz * d_step;
            // Strictly short of the face it heads for (always for uz = 0, which meets no face).
            let interact = sigma_t > 0.0 && (uz == 0.0 || (z_step - face_z) * uz < 0.0);
            let d_face = (face_z - z) / uz;
            let glide = !interact && !(d_face.abs() < f64::INFINITY);
            let d = if interact { d_step } else { d_face };

            // Interaction: implicit capture, HG polar angle, azimuth, spin, roulette.
            let dw = w * self.absorb[i];
            let w_int = w - dw;
            let [a, b, c2, d2, e] = [self.hg[0][i], self.hg[1][i], self.hg[2][i], self.hg[3][i], self.hg[4][i]];
            let f = a / (b + c2 * xi1);
            let hg = (d2 - f * f) * e;
            let hg = if hg < -1.0 {
                -1.0
            } else if hg > 1.0 {
                1.0
            } else {
                hg
            };
            let cos_t = if self.iso[i] != 0.0 { 2.0 * xi1 - 1.0 } else { hg };
            let (cos_p, sin_p) = azimuth_cos_sin(c[2]);
            let sin2_t = pos(1.0 - cos_t * cos_t);
            let sin_t = sin2_t.sqrt();
            let one_minus_uz2 = 1.0 - uz * uz;
            let q = (sin2_t / one_minus_uz2).sqrt();
            let polar = uz.abs() > 0.99999;
            let sx = if polar { sin_t * cos_p } else { q * (ux * uz * cos_p - uy * sin_p) + ux * cos_t };
            let sy = if polar { sin_t * sin_p } else { q * (uy * uz * cos_p + ux * sin_p) + uy * cos_t };
            let sz = if polar {
                if uz < 0.0 {
                    -cos_t
                } else {
                    cos_t
                }
            } else {
                -q * one_minus_uz2 * cos_p + uz * cos_t
            };
            let low = w_int < ROULETTE_THRESHOLD;
            let survive = unit(c[3]) <= 1.0 / ROULETTE_CHANCE && w_int != 0.0;
            let w_int = if low && survive { w_int * ROULETTE_CHANCE } else { w_int };
            let lost = low && !survive;

            // Face: Fresnel reflection or refraction into the neighbour.
            let n_i = self.eta[i];
            let n_t = if down { self.n_below[i] } else { self.n_above[i] };
            let cos_i = uz.abs();
            let ratio = n_i / n_t;
            let sin_t2 = ratio * ratio * pos(1.0 - cos_i * cos_i);
            let cos_tr = pos(1.0 - sin_t2).sqrt();
            let rs = (n_i * cos_i - n_t * cos_tr) / (n_i * cos_i + n_t * cos_tr);
            let rp = (n_i * cos_tr - n_t * cos_i) / (n_i * cos_tr + n_t * cos_i);
            let same = n_i == n_t;
            let refl = if same {
                0.0
            } else if sin_t2 >= 1.0 {
                1.0
            } else {
                0.5 * (rs * rs + rp * rp)
            };
            let reflect = refl > 0.0 && (refl >= 1.0 || xi1 <= refl);
            let cos_tr = if same { cos_i } else { cos_tr };
            let fx = if reflect { ux } else { ux * ratio };
            let fy = if reflect { uy } else { uy * ratio };
            let fz = if reflect {
                -uz
            } else if down {
                cos_tr
            } else {
                -cos_tr
            };
            let s_face = if sigma_t > 0.0 { pos(s - d_face * sigma_t) } else { s };
            let leaves = !reflect && (if down { self.bottom[i] != 0.0 } else { self.top[i] != 0.0 });

            self.x[i] = x + ux * d;
            self.y[i] = y + uy * d;
            self.z[i] = if interact { z_step } else { face_z };
            self.ux[i] = if interact { sx } else { fx };
            self.uy[i] = if interact { sy } else { fy };
            self.uz[i] = if interact { sz } else { fz };
            self.w[i] = if interact { w_int } else { w };
            self.s[i] = if interact { 0.0 } else { s_face };
            let live = self.live[i] != 0.0;
            self.dw[i] = if interact && live { dw } else { 0.0 };
            self.interacted[i] = u32::from(interact && live);
            self.code[i] = if interact {
                if lost {
                    END_ROULETTE
                } else {
                    0
                }
            } else if glide {
                END_GLIDE
            } else if leaves {
                if down {
                    END_BOTTOM
                } else {
                    END_TOP
                }
            } else if reflect {
                0
            } else {
                CROSSED
            };
        }
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
            iso: if m.hg.isotropic { 1.0 } else { 0.0 },
            hg: [m.hg.one_minus_g2, m.hg.one_minus_g, m.hg.two_g, m.hg.one_plus_g2, m.hg.inv_two_g],
            eta: m.eta,
            n_above: if j == 0 { ch.eta_above } else { media[j - 1].eta },
            n_below: if j == last { ch.eta_below } else { media[j + 1].eta },
            top: if j == 0 { 1.0 } else { 0.0 },
            bottom: if j == last { 1.0 } else { 0.0 },
        })
        .collect();
    let keys = round_keys(ch.seed);
    let inv_bin = 1.0 / bin_mm;
    let bins = tally.r.len();
    let end = first + count;
    let mut next = first;
    let mut lanes = Lanes::default();
    let mut layer = [0usize; LANES];
    for i in 0..LANES {
        lanes.launch(i, next, next < end, ch.start_weight, &consts[0]);
        next = (next + 1).min(end);
    }
    // Absorbed weight per layer and lane.
    let mut absorbed = vec![[0.0f64; LANES]; media.len()];
    let mut live_count = LANES.min(count as usize);
    while live_count > 0 {
        lanes.step(ch.index, &keys);
        if media.len() == 1 {
            for (a, dw) in absorbed[0].iter_mut().zip(&lanes.dw) {
                *a += dw;
            }
        } else {
            for (j, acc) in absorbed.iter_mut().enumerate() {
                for i in 0..LANES {
                    acc[i] += if layer[i] == j { lanes.dw[i] } else { 0.0 };
                }
            }
        }
        let mut interactions = 0u32;
        let mut special = 0u32;
        for i in 0..LANES {
            interactions += lanes.interacted[i];
            special |= u32::from(lanes.code[i] != 0) << i;
        }
        tally.interactions += u64::from(interactions);
        while special != 0 {
            let i = special.trailing_zeros() as usize;
            special &= special - 1;
            let live = lanes.live[i] != 0.0;
            let w = lanes.w[i];
            match lanes.code[i] {
                CROSSED => {
                    layer[i] = if lanes.uz[i] > 0.0 { layer[i] + 1 } else { layer[i] - 1 };
                    lanes.load_layer(i, &consts[layer[i]]);
                    continue;
                }
                END_GLIDE if live => absorbed[layer[i]][i] += w,
                code @ (END_TOP | END_BOTTOM) if live => {
                    let r = (lanes.x[i] * lanes.x[i] + lanes.y[i] * lanes.y[i]).sqrt();
                    let (total, bins_of) = if code == END_TOP {
                        (&mut tally.rd, &mut tally.r)
                    } else {
                        (&mut tally.td, &mut tally.t)
                    };
                    *total += w;
                    let bin = (r * inv_bin) as usize;
                    if bin < bins {
                        bins_of[bin] += w;
                    }
                }
                _ => {}
            }
            // The packet has ended: the lane takes the chunk's next photon, or idles once there is none.
            if live {
                live_count -= 1;
            }
            let more = live && next < end;
            if more {
                live_count += 1;
            }
            layer[i] = 0;
            lanes.launch(i, next, more, ch.start_weight, &consts[0]);
            if more {
                next += 1;
            }
        }
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

    /// The branch-free −ln x against the library logarithm: within 2 ulp over the whole (0, 1] grid of the draws.
    #[test]
    fn neg_ln_matches_the_library() {
        let mut worst = 0.0f64;
        for j in 0..200_000u64 {
            let word = (j.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) as u32;
            for x in [unit(word), unit(j as u32), unit(u32::MAX - j as u32)] {
                let exact = -x.ln();
                let got = neg_ln(x);
                if exact != 0.0 {
                    worst = worst.max(((got - exact) / exact).abs());
                } else {
                    assert_eq!(got, 0.0);
                }
            }
        }
        assert!(worst < 4.5e-16, "worst relative error {worst:e}");
    }

    /// The polynomial azimuth against the library sin/cos of (q + ½)π/2 + θ, and unit length.
    #[test]
    fn azimuth_matches_the_library() {
        let mut worst = 0.0f64;
        for j in 0..200_000u64 {
            let word = (j.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) as u32;
            let (c, s) = azimuth_cos_sin(word);
            let phi = ((f64::from(word) + 0.5) / 4_294_967_296.0) * std::f64::consts::TAU;
            let (es, ec) = phi.sin_cos();
            worst = worst.max((c - ec).abs()).max((s - es).abs()).max((c * c + s * s - 1.0).abs());
        }
        assert!(worst < 1e-15, "worst error {worst:e}");
    }

    /// The lane loop's Philox block is the reference Philox4x32-10 of its counter, and its uniform is (w + 1)/2³².
    #[test]
    fn lane_draws_are_the_philox_blocks() {
        let seed = 0x0123_4567_89ab_cdef_u64;
        let keys = round_keys(seed);
        for (photon, event) in [(0u64, 0u32), (0x1_0000_0005, 7), (u64::MAX, u32::MAX)] {
            let c = [photon as u32, (photon >> 32) as u32, 2, event];
            let expected = super::super::rng::philox4x32_10(c, [seed as u32, (seed >> 32) as u32]);
            assert_eq!(block(c, &keys), expected);
        }
        for w in [0u32, 1, 0x7fff_ffff, 0x8000_0000, u32::MAX] {
            assert_eq!(unit(w), (f64::from(w) + 1.0) / 4_294_967_296.0);
        }
    }
}
