//! Monte Carlo transport as a profile model: the tallies of [`super::mc::simulate`] as a [`RadialProfile`], so every
//! consumer of diffusion profiles (tables, fits, kernels, transmittance, importance kernels) can take the transport
//! solution instead of the diffusion approximation (MCML, Wang, Jacques & Zheng 1995).
//!
//! R(r) is the annulus mean of each radial bin placed at the bin centre (i + ½)Δr, interpolated linearly between
//! centres, held at the first bin's value below the first centre and 0 beyond the last bin. The total ∫2πr R dr is
//! the Monte Carlo diffuse reflectance (every exit through the top, also beyond the last bin); its standard error
//! and the per-bin standard errors come from the independent batches ([`super::mc`]).
//!
//! Normalisation (the same for both models): per unit flux *entering* the top face. MCML launches each packet
//! with weight 1 − Rsp (the specular loss at normal incidence); the diffusion totals (and the skin-colour LUT) have
//! no entry loss, the renderer applies the entry Fresnel term itself. So R(r), T(r), the totals and their standard
//! errors are divided by 1 − Rsp here (+2.9 % at η = 1.4 against the raw tallies).
//!
//! Anisotropy: a diffusion layer gives σs′; the transport gets σs = σs′/(1 − g) with Henyey–Greenstein g, so both
//! models see the same reduced coefficients ([`super::stack::McStack::from_layer_stack`]).

use super::mc::{simulate, Estimate, McResult, McSettings};
use super::stack::McStack;
use crate::diffusion::RadialProfile;
use crate::error::InvalidInput;

/// A tissue-like Henyey–Greenstein anisotropy, the default of `--model mc`: g = 0.8, the value for skin in the
/// visible of van Gemert, Jacques, Sterenborg & Star, "Skin optics", IEEE Trans. Biomed. Eng. 36(12), 1989
/// (dermis g ≈ 0.8 at 633 nm), at the low end of the 0.8–0.95 S. L. Jacques lists for soft tissue ("Optical
/// properties of biological tissues: a review", Phys. Med. Biol. 58, R37, 2013).
pub const DEFAULT_TISSUE_G: f64 = 0.8;
/// Photons per channel (per wavelength for spectral skins) of a Monte Carlo profile by default.
pub const DEFAULT_PROFILE_PHOTONS: u64 = 100_000;
/// Radial bin of a Monte Carlo profile, mm.
pub const PROFILE_BIN_MM: f64 = 0.02;
/// Radial bins of a Monte Carlo profile (to 20 mm).
pub const PROFILE_BINS: usize = 1000;
/// Independent batches of a Monte Carlo profile's standard errors.
pub const PROFILE_BATCHES: u32 = 10;

/// The Monte Carlo settings of a profile (photons per channel, seed), validated: `photons` in
/// 1..=[`super::mc::MAX_PHOTONS`], errors name `photons`.
pub fn profile_settings(photons: u64, seed: u64) -> Result<McSettings, InvalidInput> {
    McSettings::new(photons, seed, PROFILE_BATCHES, PROFILE_BIN_MM, PROFILE_BINS)
}

/// A Monte Carlo result as a radial profile (module docs).
#[derive(Clone, Debug)]
pub struct McProfile {
    bin_mm: f64,
    r: Vec<[f64; 3]>,
    r_se: Vec<[f64; 3]>,
    t: Option<Vec<[f64; 3]>>,
    total_r: [Estimate; 3],
    total_t: Option<[f64; 3]>,
    photons: u64,
}

impl McProfile {
    /// From a finished run; `finite` says whether the stack has a bottom face (T(r) is then part of the profile).
    pub fn from_result(result: &McResult, finite: bool) -> Self {
        let bins = result.settings.bins;
        let col = |f: &dyn Fn(usize, usize) -> f64| -> Vec<[f64; 3]> {
            (0..bins).map(|i| [f(0, i), f(1, i), f(2, i)]).collect()
        };
        let ch = &result.channels;
        // Per unit entering flux (module docs): ÷ (1 − Rsp).
        let k = [0, 1, 2].map(|c| 1.0 / (1.0 - ch[c].specular_reflectance));
        Self {
            bin_mm: result.settings.bin_mm,
            r: col(&|c, i| k[c] * ch[c].reflectance_mm2[i].mean),
            r_se: col(&|c, i| k[c] * ch[c].reflectance_mm2[i].se),
            t: finite.then(|| col(&|c, i| k[c] * ch[c].transmittance_mm2[i].mean)),
            total_r: [0, 1, 2].map(|c| {
                let e = ch[c].diffuse_reflectance;
                Estimate { mean: k[c] * e.mean, se: k[c] * e.se }
            }),
            total_t: finite.then(|| [0, 1, 2].map(|c| k[c] * ch[c].transmittance.mean)),
            photons: result.photons,
        }
    }

    /// Runs the transport in `stack` and keeps the tallies as a profile.
    pub fn simulate(stack: &McStack, settings: &McSettings) -> Self {
        let finite = stack.layers().iter().all(|l| l.thickness_mm.is_finite());
        Self::from_result(&simulate(stack, settings), finite)
    }

    /// Photons traced per channel.
    pub fn photons(&self) -> u64 {
        self.photons
    }

    /// Total diffuse reflectance per channel with its standard error.
    pub fn total_reflectance_estimate(&self) -> [Estimate; 3] {
        self.total_r
    }

    fn interpolate(&self, col: &[[f64; 3]], r_mm: f64) -> [f64; 3] {
        let x = r_mm / self.bin_mm - 0.5;
        let n = col.len();
        if x <= 0.0 {
            return col[0];
        }
        let i = x.floor() as usize;
        if i + 1 >= n {
            // Beyond the last centre: the last annulus up to its outer edge, then 0.
            return if r_mm <= n as f64 * self.bin_mm { col[n - 1] } else { [0.0; 3] };
        }
        let f = x - i as f64;
        [0, 1, 2].map(|c| col[i][c] + f * (col[i + 1][c] - col[i][c]))
    }
}

impl RadialProfile for McProfile {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        self.interpolate(&self.r, r_mm)
    }
    fn total_reflectance(&self) -> [f64; 3] {
        self.total_r.map(|e| e.mean)
    }
    fn transmittance_mm2(&self, r_mm: f64) -> Option<[f64; 3]> {
        self.t.as_ref().map(|t| self.interpolate(t, r_mm))
    }
    fn total_transmittance(&self) -> Option<[f64; 3]> {
        self.total_t
    }
    fn reflectance_se_mm2(&self, r_mm: f64) -> Option<[f64; 3]> {
        Some(self.interpolate(&self.r_se, r_mm))
    }
    fn total_reflectance_se(&self) -> Option<[f64; 3]> {
        Some(self.total_r.map(|e| e.se))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transport::stack::McLayer;

    #[test]
    fn profile_interpolates_bin_centres_and_counts_entering_light() {
        let layer = McLayer::from_reduced(1.0, 1.4, [0.1, 0.2, 0.4], [2.0, 2.0, 2.0], 0.0).unwrap();
        let stack = McStack::new(1.0, 1.0, vec![layer]).unwrap();
        let settings = McSettings::new(4000, 3, 4, 0.1, 20).unwrap();
        let result = simulate(&stack, &settings);
        let p = McProfile::from_result(&result, true);
        // Rsp at η = 1.4 under air: ((1.4 − 1)/(1.4 + 1))² = 1/36.
        let k = 1.0 / (1.0 - 1.0 / 36.0);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        for c in 0..3 {
            let ch = &result.channels[c];
            assert!((ch.specular_reflectance - 1.0 / 36.0).abs() < 1e-15);
            assert!(close(p.total_reflectance()[c], k * ch.diffuse_reflectance.mean));
            assert!(close(p.total_reflectance_se().unwrap()[c], k * ch.diffuse_reflectance.se));
            // At a bin centre the profile is that bin's annulus mean; halfway, the mean of the two neighbours.
            assert!(close(p.reflectance_mm2(0.35)[c], k * ch.reflectance_mm2[3].mean), "{c}");
            let mid = 0.5 * k * (ch.reflectance_mm2[3].mean + ch.reflectance_mm2[4].mean);
            assert!(close(p.reflectance_mm2(0.4)[c], mid));
            assert!(close(p.reflectance_mm2(0.0)[c], k * ch.reflectance_mm2[0].mean));
            assert_eq!(p.reflectance_mm2(2.5)[c], 0.0);
        }
        assert!(p.total_transmittance().unwrap().iter().all(|&t| t > 0.0));
    }
}
