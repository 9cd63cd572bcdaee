//! The 13-tap jittered kernel of TAP 2009's "SS Jittered" shader: a screen-space adaptation of Hable, Borshukov &
//! Hejl's skin kernel (Uncharted 2, 2009), "a single bidimensional convolution at thirteen jittered sample points,
//! which account for direct reflection (one point), mid-level scattering (six points), and wide red scattering (six
//! points)" (TAP 2009 §2, §4).
//!
//! Hable et al.'s own offsets and weights are not in the sources this crate follows, so the kernel is derived from a
//! sum-of-Gaussians profile R_c(r) = Σᵢ w_ic G(vᵢ, r) by splitting the disk at two radii:
//! - a: where green's normalised energy E_g(a) = Σᵢ w_ig (1 − e^(−a²/2vᵢ)) / Σᵢ w_ig reaches 1/2 — the direct tap
//!   carries E_c(a);
//! - b: where red's reaches 1/2 (at least 2a) — the six mid taps carry (E_c(b) − E_c(a))/6 each, at the
//!   energy-weighted mean radius of the annulus [a, b] (mean of the three channels' normalised profiles);
//! - the six wide taps carry red's (1 − E_r(b))/6 each, at red's energy-weighted mean radius beyond b; green and
//!   blue have no wide taps, and their remaining energy is added to the mid taps, so every channel sums to 1.
//!
//! Jitter: the rings are not regular — a fixed, seeded pattern moves each mid tap by up to ±12° and ±12 % of its
//! radius and each wide tap likewise, the wide ring offset by 30° from the mid ring, so the 12 taps do not line up
//! into visible spokes. The pattern is the same for every pixel (no per-pixel rotation).

use crate::diffusion::sum_of_gaussians::SumOfGaussians;
use crate::error::InvalidInput;

/// One tap: offset in mm and its normalised weight per channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JitteredTap {
    pub x_mm: f64,
    pub y_mm: f64,
    pub weight: [f64; 3],
}

impl JitteredTap {
    pub fn r_mm(&self) -> f64 {
        self.x_mm.hypot(self.y_mm)
    }
}

/// Normalised energy of channel `c` within radius `r_mm`.
fn energy(p: &SumOfGaussians, c: usize, r_mm: f64) -> f64 {
    let total: f64 = p.weights.iter().map(|w| w[c]).sum();
    p.variances_mm2.iter().zip(&p.weights).map(|(v, w)| w[c] * (1.0 - (-r_mm * r_mm / (2.0 * v)).exp())).sum::<f64>()
        / total
}

/// Radius where channel `c`'s normalised energy reaches `q` (bisection).
fn quantile(p: &SumOfGaussians, c: usize, q: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 10.0 * p.variances_mm2.last().copied().unwrap_or(1.0).sqrt());
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if energy(p, c, mid) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Energy-weighted mean radius over [lo, hi] of the given channels' normalised profiles (midpoint rule, 4000
/// steps): ∫ r · R 2πr dr / ∫ R 2πr dr.
fn mean_radius(p: &SumOfGaussians, channels: &[usize], lo: f64, hi: f64) -> f64 {
    let n = 4000;
    let h = (hi - lo) / n as f64;
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..n {
        let r = lo + (k as f64 + 0.5) * h;
        for &c in channels {
            let total: f64 = p.weights.iter().map(|w| w[c]).sum();
            let rr: f64 = p
                .variances_mm2
                .iter()
                .zip(&p.weights)
                .map(|(v, w)| w[c] * (-r * r / (2.0 * v)).exp() / (2.0 * std::f64::consts::PI * v))
                .sum::<f64>()
                / total;
            num += r * rr * r;
            den += rr * r;
        }
    }
    num / den
}

/// The fixed jitter: (angle offset in degrees, radius factor) per ring tap, from a 32-bit LCG seeded with 13.
fn jitter() -> [(f64, f64); 12] {
    let mut s: u32 = 13;
    let mut next = || {
        s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (s >> 8) as f64 / (1u32 << 24) as f64 * 2.0 - 1.0
    };
    std::array::from_fn(|_| (12.0 * next(), 1.0 + 0.12 * next()))
}

/// Hable's 13 taps for `profile` (see the module doc). The profile needs positive variances and a positive total
/// in every channel.
pub fn hable13(profile: &SumOfGaussians) -> Result<Vec<JitteredTap>, InvalidInput> {
    if profile.variances_mm2.is_empty()
        || profile.variances_mm2.len() != profile.weights.len()
        || profile.variances_mm2.iter().any(|v| !(v.is_finite() && *v > 0.0))
        || (0..3).any(|c| profile.weights.iter().map(|w| w[c]).sum::<f64>() <= 0.0)
    {
        return Err(InvalidInput::new(
            "gaussians",
            "need positive variances, as many weights, and a positive total in each channel",
        ));
    }
    let a = quantile(profile, 1, 0.5);
    let b = quantile(profile, 0, 0.5).max(2.0 * a);
    let far = b + 10.0 * profile.variances_mm2.last().unwrap().sqrt();
    let r_mid = mean_radius(profile, &[0, 1, 2], a, b);
    let r_wide = mean_radius(profile, &[0], b, far);
    let e = |c: usize, r: f64| energy(profile, c, r);
    let centre: [f64; 3] = std::array::from_fn(|c| e(c, a));
    let mid: [f64; 3] = std::array::from_fn(|c| if c == 0 { e(0, b) - e(0, a) } else { 1.0 - e(c, a) } / 6.0);
    let wide = [(1.0 - e(0, b)) / 6.0, 0.0, 0.0];
    let j = jitter();
    let mut taps = vec![JitteredTap { x_mm: 0.0, y_mm: 0.0, weight: centre }];
    for (ring, radius, base_deg, weight) in [(0usize, r_mid, 0.0, mid), (1, r_wide, 30.0, wide)] {
        for k in 0..6 {
            let (dtheta, fr) = j[6 * ring + k];
            let t = (base_deg + 60.0 * k as f64 + dtheta).to_radians();
            taps.push(JitteredTap { x_mm: radius * fr * t.cos(), y_mm: radius * fr * t.sin(), weight });
        }
    }
    Ok(taps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::sum_of_gaussians::deon6;

    #[test]
    fn thirteen_taps_normalised_per_channel_with_red_widest() {
        let taps = hable13(&deon6()).unwrap();
        assert_eq!(taps.len(), 13);
        for c in 0..3 {
            let s: f64 = taps.iter().map(|t| t.weight[c]).sum();
            assert!((s - 1.0).abs() < 1e-12, "channel {c} sums to {s}");
        }
        // Only red reaches the wide ring, which lies outside the mid ring.
        assert!(taps[7..].iter().all(|t| t.weight[1] == 0.0 && t.weight[2] == 0.0 && t.weight[0] > 0.0));
        let r_mid = taps[1..7].iter().map(JitteredTap::r_mm).fold(0.0, f64::max);
        assert!(taps[7..].iter().all(|t| t.r_mm() > r_mid));
        // Second moments: red > green > blue, and red's within a factor 2 of the profile's E[r²] = 2 Σ w v.
        let m2 = |c: usize| taps.iter().map(|t| t.weight[c] * t.r_mm().powi(2)).sum::<f64>();
        assert!(m2(0) > m2(1) && m2(1) > m2(2), "{} {} {}", m2(0), m2(1), m2(2));
        let p = deon6();
        let total: f64 = p.weights.iter().map(|w| w[0]).sum();
        let profile_m2 = 2.0 * p.variances_mm2.iter().zip(&p.weights).map(|(v, w)| v * w[0]).sum::<f64>() / total;
        assert!(m2(0) > 0.5 * profile_m2 && m2(0) < 2.0 * profile_m2, "{} vs {profile_m2}", m2(0));
        // The jitter stays within its bounds: no two ring taps closer than 30° − 2·12° apart in angle.
        let ang: Vec<f64> = taps[1..].iter().map(|t| t.y_mm.atan2(t.x_mm).to_degrees().rem_euclid(360.0)).collect();
        let mut sorted = ang.clone();
        sorted.sort_by(f64::total_cmp);
        assert!(sorted.windows(2).all(|w| w[1] - w[0] >= 6.0 - 1e-9), "{sorted:?}");
    }

    #[test]
    fn bad_profiles_are_refused() {
        let mut p = deon6();
        p.variances_mm2[0] = 0.0;
        assert_eq!(hable13(&p).unwrap_err().param, "gaussians");
        let mut p = deon6();
        p.weights.iter_mut().for_each(|w| w[2] = 0.0);
        assert!(hable13(&p).is_err());
    }
}
