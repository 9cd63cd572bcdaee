//! A linear projection of monochromatic profiles onto RGB: the spatially resolved reflectance spectrum R(r, λ) of a
//! spectral material reduced to linear-sRGB channels,
//!
//!   R_c(r) = Σ_λ w_c(λ) R(r, λ),        T_c(r) = Σ_λ w_c(λ) T(r, λ),
//!
//! with the colorimetric weights w_c(λ) of `crate::spectral` (D65, CIE 1931 2°, IEC 61966-2-1 matrix). The map is
//! linear in R(r, λ), so ∫ 2πr R_c(r) dr = Σ_λ w_c(λ) R̂(0, λ): the profile's total is the colour of the total
//! reflectance spectrum — the skin-colour LUT's colour for a physiological skin (CIE 15:2018 §7; the spectral
//! BSSRDF of Donner & Jensen 2006 reduced after, not before, the transport).
//!
//! The monochromatic profiles are any [`RadialProfile`]s whose three channels carry three wavelengths (a layered
//! multipole or a Monte Carlo run with per-channel coefficients), so each evaluation serves three wavelengths.
//!
//! Negative values: the weights have negative lobes (the sRGB sensitivities), and far from the source only deep red
//! light is left, which lies outside the sRGB gamut: for skin, G and B of the exact projection turn slightly
//! negative beyond r ≈ 0.2–1 mm (a fraction of a percent of the channel's total). A profile a renderer or a fit
//! can use is non-negative, so with `clip_negative` R_c(r) and T_c(r) are max(0, ·); the totals stay the exact
//! projection (the colour), and [`RadialProfile::clipped_negative_mass`] reports ∫2πr max(0, −R_c) dr, by which the
//! clipped profile's integral exceeds the total.

use super::RadialProfile;

/// One group of three wavelengths: the profile whose channels k = 0, 1, 2 are the wavelengths, and
/// `weights[k][c]`, the weight of wavelength k in output channel c.
pub struct ProjectedPart {
    pub profile: Box<dyn RadialProfile + Send>,
    pub weights: [[f64; 3]; 3],
}

/// The projected profile (module docs). Parts are summed in order, so results do not depend on threads.
pub struct ProjectedProfile {
    parts: Vec<ProjectedPart>,
    clip_negative: bool,
}

fn clip(v: [f64; 3], on: bool) -> [f64; 3] {
    if on {
        v.map(|x| x.max(0.0))
    } else {
        v
    }
}

fn project(parts: &[ProjectedPart], each: impl Fn(&ProjectedPart) -> [f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for p in parts {
        let v = each(p);
        for (k, vk) in v.iter().enumerate() {
            for (c, o) in out.iter_mut().enumerate() {
                *o += p.weights[k][c] * vk;
            }
        }
    }
    out
}

fn project_many(parts: &[ProjectedPart], n: usize, each: impl Fn(&ProjectedPart) -> Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    let mut out = vec![[0.0; 3]; n];
    for p in parts {
        for (o, v) in out.iter_mut().zip(each(p)) {
            for (k, vk) in v.iter().enumerate() {
                for (c, oc) in o.iter_mut().enumerate() {
                    *oc += p.weights[k][c] * vk;
                }
            }
        }
    }
    out
}

impl ProjectedProfile {
    /// # Panics
    /// With no parts.
    pub fn new(parts: Vec<ProjectedPart>, clip_negative: bool) -> Self {
        assert!(!parts.is_empty(), "a projection needs at least one wavelength group");
        Self { parts, clip_negative }
    }

    /// The exact (unclipped) projection of R at `r_mm`.
    pub fn projected_reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        project(&self.parts, |p| p.profile.reflectance_mm2(r_mm))
    }

    pub fn parts(&self) -> &[ProjectedPart] {
        &self.parts
    }

    /// Σ_λ w_c(λ) x(λ) of per-wavelength values given per part (e.g. standard errors squared use the squared
    /// weights: see [`Self::project_variance`]).
    pub fn project_values(&self, per_part: &[[f64; 3]]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (p, v) in self.parts.iter().zip(per_part) {
            for (wk, vk) in p.weights.iter().zip(v) {
                for (c, o) in out.iter_mut().enumerate() {
                    *o += wk[c] * vk;
                }
            }
        }
        out
    }

    /// Σ_λ w_c(λ)² σ²(λ) for independent per-wavelength estimates with standard errors σ (per part).
    pub fn project_variance(&self, se_per_part: &[[f64; 3]]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (p, v) in self.parts.iter().zip(se_per_part) {
            for (wk, vk) in p.weights.iter().zip(v) {
                for (c, o) in out.iter_mut().enumerate() {
                    *o += wk[c] * wk[c] * vk * vk;
                }
            }
        }
        out
    }
}

impl RadialProfile for ProjectedProfile {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        clip(self.projected_reflectance_mm2(r_mm), self.clip_negative)
    }
    fn total_reflectance(&self) -> [f64; 3] {
        project(&self.parts, |p| p.profile.total_reflectance())
    }
    fn transmittance_mm2(&self, r_mm: f64) -> Option<[f64; 3]> {
        let t: Option<Vec<[f64; 3]>> = self.parts.iter().map(|p| p.profile.transmittance_mm2(r_mm)).collect();
        t.map(|t| clip(self.project_values(&t), self.clip_negative))
    }
    fn total_transmittance(&self) -> Option<[f64; 3]> {
        let t: Option<Vec<[f64; 3]>> = self.parts.iter().map(|p| p.profile.total_transmittance()).collect();
        t.map(|t| self.project_values(&t))
    }
    fn reflectance_se_mm2(&self, r_mm: f64) -> Option<[f64; 3]> {
        let se: Option<Vec<[f64; 3]>> = self.parts.iter().map(|p| p.profile.reflectance_se_mm2(r_mm)).collect();
        se.map(|s| self.project_variance(&s).map(f64::sqrt))
    }
    fn total_reflectance_se(&self) -> Option<[f64; 3]> {
        let se: Option<Vec<[f64; 3]>> = self.parts.iter().map(|p| p.profile.total_reflectance_se()).collect();
        se.map(|s| self.project_variance(&s).map(f64::sqrt))
    }
    fn clipped_negative_mass(&self) -> Option<[f64; 3]> {
        if !self.clip_negative {
            return None;
        }
        // ∫2πr max(0, −R_c) dr over [1e-4, 200] mm in log r (24 panels of 32 Gauss–Legendre nodes).
        let rule = super::quadrature::gl32();
        let (ua, ub, panels) = ((1e-4f64).ln(), 200f64.ln(), 24);
        let h = (ub - ua) / panels as f64;
        let radii: Vec<f64> = (0..panels)
            .flat_map(|p| rule.0.iter().map(move |x| (ua + (p as f64 + 0.5) * h + 0.5 * h * x).exp()))
            .collect();
        let raw = project_many(&self.parts, radii.len(), |p| p.profile.reflectance_many(&radii));
        let mut out = [0.0; 3];
        for (i, (r, v)) in radii.iter().zip(&raw).enumerate() {
            let w = rule.1[i % rule.1.len()];
            for c in 0..3 {
                out[c] += 0.5 * h * w * 2.0 * std::f64::consts::PI * r * r * (-v[c]).max(0.0);
            }
        }
        Some(out)
    }
    fn reflectance_many(&self, radii_mm: &[f64]) -> Vec<[f64; 3]> {
        let v = project_many(&self.parts, radii_mm.len(), |p| p.profile.reflectance_many(radii_mm));
        v.into_iter().map(|x| clip(x, self.clip_negative)).collect()
    }
    fn transmittance_many(&self, radii_mm: &[f64]) -> Option<Vec<[f64; 3]>> {
        if self.parts.iter().any(|p| p.profile.total_transmittance().is_none()) {
            return None;
        }
        let v = project_many(&self.parts, radii_mm.len(), |p| {
            p.profile.transmittance_many(radii_mm).expect("every part has a transmittance")
        });
        Some(v.into_iter().map(|x| clip(x, self.clip_negative)).collect())
    }
    fn profile_many(&self, radii_mm: &[f64]) -> (Vec<[f64; 3]>, Option<Vec<[f64; 3]>>) {
        let n = radii_mm.len();
        let mut r = vec![[0.0; 3]; n];
        let mut t = self.parts.iter().all(|p| p.profile.total_transmittance().is_some()).then(|| vec![[0.0; 3]; n]);
        for p in &self.parts {
            let (pr, pt) = p.profile.profile_many(radii_mm);
            let add = |out: &mut [[f64; 3]], v: &[[f64; 3]]| {
                for (o, v) in out.iter_mut().zip(v) {
                    for (k, vk) in v.iter().enumerate() {
                        for (c, oc) in o.iter_mut().enumerate() {
                            *oc += p.weights[k][c] * vk;
                        }
                    }
                }
            };
            add(&mut r, &pr);
            if let (Some(t), Some(pt)) = (t.as_mut(), pt.as_ref()) {
                add(t, pt);
            }
        }
        let on = self.clip_negative;
        (r.into_iter().map(|x| clip(x, on)).collect(), t.map(|t| t.into_iter().map(|x| clip(x, on)).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::dipole::{Dipole, DipoleRgb};
    use crate::diffusion::FdrForm;

    /// The projection is linear: the total of the projected profile is the projection of the totals, and the
    /// numerical integral ∫2πr R_c dr of the projected profile matches it.
    #[test]
    fn projection_is_linear_in_the_profiles() {
        let dip = |s: [f64; 3]| -> Box<dyn RadialProfile + Send> {
            let d = [0, 1, 2].map(|c| Dipole::new(s[c], 1.0 + c as f64, 1.3, FdrForm::Dj05).unwrap());
            Box::new(DipoleRgb(d))
        };
        let w1 = [[0.5, 0.1, -0.05], [0.2, 0.6, 0.0], [0.3, 0.3, 1.05]];
        let w2 = [[0.1, 0.0, 0.2], [0.0, 0.2, 0.0], [-0.1, 0.0, 0.1]];
        let p = ProjectedProfile::new(
            vec![
                ProjectedPart { profile: dip([0.01, 0.05, 0.2]), weights: w1 },
                ProjectedPart { profile: dip([0.5, 0.02, 0.1]), weights: w2 },
            ],
            false,
        );
        let t1 = dip([0.01, 0.05, 0.2]).total_reflectance();
        let t2 = dip([0.5, 0.02, 0.1]).total_reflectance();
        let expect = [0, 1, 2].map(|c| (0..3).map(|k| w1[k][c] * t1[k] + w2[k][c] * t2[k]).sum::<f64>());
        let total = p.total_reflectance();
        let integral = crate::diffusion::quadrature::radial_total(|r| p.reflectance_mm2(r), 1e-6, 200.0, 64);
        for c in 0..3 {
            assert!((total[c] - expect[c]).abs() < 1e-15, "{c}");
            assert!((integral[c] - total[c]).abs() < 1e-6 * total[c].abs(), "{c}: {integral:?} vs {total:?}");
        }
        let many = p.reflectance_many(&[0.1, 1.0]);
        assert_eq!(many[1], p.reflectance_mm2(1.0));
    }
}
