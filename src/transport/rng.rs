//! Counter-based random numbers: Philox4x32-10 (J. K. Salmon, M. A. Moraes, R. O. Dror, D. E. Shaw, "Parallel
//! random numbers: as easy as 1, 2, 3", SC 2011, §4.2 and Random123's known-answer vectors).
//!
//! A block of four 32-bit outputs is a pure function of a 128-bit counter and a 64-bit key: ten rounds of
//! (c0, c1, c2, c3) → (hi(M1·c2) ⊕ c1 ⊕ k0, lo(M1·c2), hi(M0·c0) ⊕ c3 ⊕ k1, lo(M0·c0)) with M0 = 0xD2511F53,
//! M1 = 0xCD9E8D57, and the key bumped by the Weyl constants W0 = 0x9E3779B9, W1 = 0xBB67AE85 between rounds.
//! The transport keys it with the user's seed and counts (photon index, channel, block): every photon's stream is
//! fixed by its index alone, so no generator state is shared between threads and results do not depend on how
//! photons are scheduled.

pub(super) use rtbake_lanes::{M0, M1, W0, W1};

/// Philox4x32-10 of `counter` under `key`.
pub fn philox4x32_10(counter: [u32; 4], key: [u32; 2]) -> [u32; 4] {
    let mut c = counter;
    let mut k = key;
    for round in 0..10 {
        if round > 0 {
            k[0] = k[0].wrapping_add(W0);
            k[1] = k[1].wrapping_add(W1);
        }
        let p0 = u64::from(M0) * u64::from(c[0]);
        let p1 = u64::from(M1) * u64::from(c[2]);
        let (hi0, lo0) = ((p0 >> 32) as u32, p0 as u32);
        let (hi1, lo1) = ((p1 >> 32) as u32, p1 as u32);
        c = [hi1 ^ c[1] ^ k[0], lo1, hi0 ^ c[3] ^ k[1], lo0];
    }
    c
}

/// Philox4x32-10 of the two counters `c0`, `c1` under `key`, the two blocks' rounds interleaved (independent
/// multiply chains the processor overlaps; each output equals [`philox4x32_10`] of its counter).
#[inline]
fn philox4x32_10_x2(c0: [u32; 4], c1: [u32; 4], key: [u32; 2]) -> ([u32; 4], [u32; 4]) {
    let (mut a, mut b, mut k) = (c0, c1, key);
    for round in 0..10 {
        if round > 0 {
            k[0] = k[0].wrapping_add(W0);
            k[1] = k[1].wrapping_add(W1);
        }
        let pa0 = u64::from(M0) * u64::from(a[0]);
        let pa1 = u64::from(M1) * u64::from(a[2]);
        let pb0 = u64::from(M0) * u64::from(b[0]);
        let pb1 = u64::from(M1) * u64::from(b[2]);
        a = [(pa1 >> 32) as u32 ^ a[1] ^ k[0], pa1 as u32, (pa0 >> 32) as u32 ^ a[3] ^ k[1], pa0 as u32];
        b = [(pb1 >> 32) as u32 ^ b[1] ^ k[0], pb1 as u32, (pb0 >> 32) as u32 ^ b[3] ^ k[1], pb0 as u32];
    }
    (a, b)
}

/// The uniform stream of one photon in one channel: counter (index lo, index hi, channel, block); each Philox block
/// gives four 32-bit words, used in order. Blocks are generated two at a time (blocks 2j and 2j + 1), which changes
/// only the speed: the word sequence is the one of [`philox4x32_10`] at blocks 0, 1, 2, …
#[derive(Clone, Debug)]
pub struct PhotonRng {
    key: [u32; 2],
    counter: [u32; 4],
    words: [u32; WORDS],
    /// Next unused word of `words` (`WORDS` = exhausted).
    next: usize,
}

/// Words generated per refill (two Philox blocks; four, vectorised, measured slower).
const WORDS: usize = 8;

impl PhotonRng {
    pub fn new(seed: u64, photon_index: u64, channel: u32) -> Self {
        Self {
            key: [seed as u32, (seed >> 32) as u32],
            counter: [photon_index as u32, (photon_index >> 32) as u32, channel, 0],
            words: [0; WORDS],
            next: WORDS,
        }
    }

    /// The next 32-bit word of the stream.
    #[inline]
    pub fn word(&mut self) -> u32 {
        if self.next >= WORDS {
            self.refill();
        }
        let w = self.words[self.next];
        self.next += 1;
        w
    }

    #[inline(never)]
    fn refill(&mut self) {
        let mut c1 = self.counter;
        c1[3] = c1[3].wrapping_add(1);
        let (a, b) = philox4x32_10_x2(self.counter, c1, self.key);
        self.words = [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]];
        self.counter[3] = self.counter[3].wrapping_add(2);
        self.next = 0;
    }

    /// A uniform in (0, 1] on the grid k/2³² (k = 1..=2³²; never 0, so −ln ξ ≤ 22.2 is finite). 32 bits resolve
    /// optical depths to 2⁻³² and angles to 1.5 nrad, far below Monte Carlo noise (MCML's `ran3` has fewer).
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (f64::from(self.word()) + 1.0) * (1.0 / 4_294_967_296.0)
    }

    /// A uniform in (−1, 1) on the grid (k + ½)/2³¹ (k = −2³¹..2³¹ − 1; symmetric about 0, never 0 or ±1).
    #[inline]
    pub fn signed_uniform(&mut self) -> f64 {
        (f64::from(self.word() as i32) + 0.5) * (1.0 / 2_147_483_648.0)
    }

    /// (cos φ, sin φ) of an azimuth φ uniform on `[0, 2π)`, without trigonometry: a point (a, b) uniform in the unit
    /// disk by rejection from the square (acceptance π/4, two words per try), then the double angle
    /// cos φ = (a² − b²)/(a² + b²), sin φ = 2ab/(a² + b²) (von Neumann 1951; the angle of (a, b) is uniform, so is
    /// twice it modulo 2π).
    #[inline]
    pub fn azimuth_cos_sin(&mut self) -> (f64, f64) {
        loop {
            let (a, b) = (self.signed_uniform(), self.signed_uniform());
            let (a2, b2) = (a * a, b * b);
            let s = a2 + b2;
            if s < 1.0 {
                let inv = 1.0 / s;
                return ((a2 - b2) * inv, 2.0 * a * b * inv);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random123 `kat_vectors`, philox4x32 with 10 rounds.
    #[test]
    fn known_answers() {
        assert_eq!(philox4x32_10([0; 4], [0; 2]), [0x6627_e8d5, 0xe169_c58d, 0xbc57_ac4c, 0x9b00_dbd8]);
        assert_eq!(philox4x32_10([u32::MAX; 4], [u32::MAX; 2]), [0x408f_276d, 0x41c8_3b0e, 0xa20b_c7c6, 0x6d54_51fd]);
        assert_eq!(
            philox4x32_10([0x243f_6a88, 0x85a3_08d3, 0x1319_8a2e, 0x0370_7344], [0xa409_3822, 0x299f_31d0]),
            [0xd16c_fe09, 0x94fd_cceb, 0x5001_e420, 0x2412_6ea1]
        );
    }

    #[test]
    fn uniforms_in_range_with_the_right_mean_and_distinct_streams() {
        let mut a = PhotonRng::new(7, 0, 0);
        let mut b = PhotonRng::new(7, 1, 0);
        let n = 20_000;
        let (mut sum, mut same) = (0.0, 0);
        for _ in 0..n {
            let (x, y) = (a.uniform(), b.uniform());
            assert!(x > 0.0 && x <= 1.0);
            sum += x;
            same += usize::from(x == y);
        }
        // mean 1/2, standard error sqrt(1/12/n) ≈ 0.002
        assert!((sum / n as f64 - 0.5).abs() < 0.01, "mean {}", sum / n as f64);
        assert_eq!(same, 0);
    }

    /// The paired generation yields the word sequence of single blocks 0, 1, 2, … exactly.
    #[test]
    fn words_are_the_philox_blocks_in_order() {
        let (seed, photon, channel) = (0x0123_4567_89ab_cdef_u64, 0x1_0000_0005_u64, 2);
        let mut rng = PhotonRng::new(seed, photon, channel);
        for block in 0..5u32 {
            let c = [photon as u32, (photon >> 32) as u32, channel, block];
            let expected = philox4x32_10(c, [seed as u32, (seed >> 32) as u32]);
            for w in expected {
                assert_eq!(rng.word(), w, "block {block}");
            }
        }
    }

    /// The disk method's azimuth: unit length, and cos φ, sin φ, cos 2φ, sin 2φ average 0 (uniform φ) within
    /// 4 standard errors (each has variance 1/2), with quadrant counts of a uniform φ.
    #[test]
    fn azimuth_is_a_uniform_unit_vector() {
        let mut rng = PhotonRng::new(11, 3, 1);
        let n = 40_000;
        let mut sums = [0.0f64; 4];
        let mut quadrants = [0usize; 4];
        for _ in 0..n {
            let (c, s) = rng.azimuth_cos_sin();
            assert!((c * c + s * s - 1.0).abs() < 1e-12);
            sums[0] += c;
            sums[1] += s;
            sums[2] += c * c - s * s;
            sums[3] += 2.0 * c * s;
            quadrants[usize::from(c < 0.0) * 2 + usize::from(s < 0.0)] += 1;
        }
        let se = (0.5 / n as f64).sqrt();
        for (i, v) in sums.iter().enumerate() {
            assert!((v / n as f64).abs() < 4.0 * se, "moment {i}: {}", v / n as f64);
        }
        // Each quadrant: binomial(n, 1/4), SE = sqrt(n · 3/16).
        let q_se = (n as f64 * 3.0 / 16.0).sqrt();
        for q in quadrants {
            assert!((q as f64 - n as f64 / 4.0).abs() < 4.0 * q_se, "{quadrants:?}");
        }
    }
}
