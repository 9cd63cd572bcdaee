//! Spectrum → CIE XYZ → linear sRGB.
//!
//! Colorimetry as in CIE 15:2018 (§7, tristimulus values of object colours): for a reflectance R(λ) under an
//! illuminant S(λ) with the CIE 1931 2° observer (x̄, ȳ, z̄),
//!
//!   X = k Σλ R(λ) S(λ) x̄(λ) Δλ,  Y = k Σλ R(λ) S(λ) ȳ(λ) Δλ,  Z = k Σλ R(λ) S(λ) z̄(λ) Δλ,  k = 1 / Σλ S(λ) ȳ(λ) Δλ
//!
//! over 380–780 nm (the normalisation makes a perfect white reflector Y = 1), then linear sRGB with the
//! IEC 61966-2-1:1999 matrix:
//!
//!   [R G B]ᵀ = [ 3.2406 −1.5372 −0.4986 ; −0.9689 1.8758 0.0415 ; 0.0557 −0.2040 1.0570 ] · [X Y Z]ᵀ
//!
//! The matrix is folded into the per-wavelength weights, so a spectrum maps to linear RGB with one dot product per
//! channel. Under D65 a perfect white reflector maps to (1, 1, 1) within the 4-digit rounding of the matrix.

use super::data::{cie1931_2deg_cmf, cie_d65_spd, CIE_FIRST_NM, CIE_LEN};
use crate::error::InvalidInput;

/// XYZ → linear sRGB (IEC 61966-2-1:1999, D65 white), rows R, G, B.
pub const SRGB_FROM_XYZ: [[f64; 3]; 3] =
    [[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]];

/// First and last wavelength of the integration, nm.
pub const FIRST_NM: u32 = CIE_FIRST_NM;
pub const LAST_NM: u32 = CIE_FIRST_NM + CIE_LEN as u32 - 1;

/// Illuminant used to weight the reflectance spectrum.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Illuminant {
    /// CIE standard illuminant D65 (default; the sRGB white point).
    #[default]
    D65,
    /// Equal-energy illuminant E (S(λ) = 1). Its white is not the sRGB white, so white does not map to (1, 1, 1).
    EqualEnergy,
}

impl Illuminant {
    /// Relative spectral power at `lambda_nm` (an integer wavelength of the 380–780 nm, 1 nm table).
    fn spd(self, index: usize) -> f64 {
        match self {
            Self::D65 => cie_d65_spd()[index],
            Self::EqualEnergy => 1.0,
        }
    }
}

/// Wavelength sampling of the integration: 380, 380 + step, …, 780 nm.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralGrid {
    pub step_nm: u32,
}

impl SpectralGrid {
    /// `step_nm` must divide the 400 nm range (1, 2, 4, 5, 8, 10, 16, 20, 25, 40, 50 … ≤ 50).
    pub fn new(step_nm: u32) -> Result<Self, InvalidInput> {
        let span = LAST_NM - FIRST_NM;
        if step_nm == 0 || step_nm > 50 || !span.is_multiple_of(step_nm) {
            return Err(InvalidInput::new(
                "spectral_step_nm",
                format!("must divide the {span} nm range 380..=780 nm and be in 1..=50 nm, got {step_nm}"),
            ));
        }
        Ok(Self { step_nm })
    }

    /// Number of wavelengths.
    pub fn len(&self) -> usize {
        ((LAST_NM - FIRST_NM) / self.step_nm) as usize + 1
    }

    pub fn is_empty(&self) -> bool {
        false
    }

    /// Row of the 1 nm CIE tables for sample `i`.
    pub fn table_index(&self, i: usize) -> usize {
        i * self.step_nm as usize
    }

    pub fn wavelength_nm(&self, i: usize) -> f64 {
        (FIRST_NM as usize + self.table_index(i)) as f64
    }

    pub fn wavelengths_nm(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.wavelength_nm(i)).collect()
    }
}

/// Per-wavelength weights that turn a reflectance spectrum into XYZ or linear sRGB by a dot product.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorWeights {
    pub grid: SpectralGrid,
    pub illuminant: Illuminant,
    /// k·S(λ)·(x̄, ȳ, z̄)(λ)·Δλ; Σ of the Y column is exactly 1.
    pub xyz: Vec<[f64; 3]>,
    /// `SRGB_FROM_XYZ` applied to `xyz`: the linear-sRGB sensitivities under the illuminant (can be negative).
    pub linear_srgb: Vec<[f64; 3]>,
}

impl ColorWeights {
    pub fn new(grid: SpectralGrid, illuminant: Illuminant) -> Self {
        let n = grid.len();
        let mut xyz: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = grid.table_index(i);
                let s = illuminant.spd(t);
                let c = cie1931_2deg_cmf()[t];
                [s * c[0], s * c[1], s * c[2]]
            })
            .collect();
        // k = 1 / Σ S ȳ Δλ; Δλ cancels between numerator and normalisation.
        let k = 1.0 / xyz.iter().map(|w| w[1]).sum::<f64>();
        for w in &mut xyz {
            for c in w.iter_mut() {
                *c *= k;
            }
        }
        // IEC 61966-2-1 XYZ → linear sRGB folded into the weights.
        let linear_srgb = xyz.iter().map(|w| mat3_mul(&SRGB_FROM_XYZ, *w)).collect();
        Self { grid, illuminant, xyz, linear_srgb }
    }

    /// XYZ of a reflectance spectrum sampled on `self.grid`.
    pub fn xyz_of(&self, reflectance: &[f64]) -> [f64; 3] {
        dot3(&self.xyz, reflectance)
    }

    /// Linear sRGB of a reflectance spectrum sampled on `self.grid`.
    pub fn linear_srgb_of(&self, reflectance: &[f64]) -> [f64; 3] {
        dot3(&self.linear_srgb, reflectance)
    }
}

fn dot3(w: &[[f64; 3]], r: &[f64]) -> [f64; 3] {
    assert_eq!(w.len(), r.len(), "spectrum length must match the spectral grid");
    let mut acc = [0.0; 3];
    for (wi, &ri) in w.iter().zip(r) {
        acc[0] += wi[0] * ri;
        acc[1] += wi[1] * ri;
        acc[2] += wi[2] * ri;
    }
    acc
}

/// 3×3 matrix times vector.
pub fn mat3_mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// XYZ → linear sRGB.
pub fn xyz_to_linear_srgb(xyz: [f64; 3]) -> [f64; 3] {
    mat3_mul(&SRGB_FROM_XYZ, xyz)
}

/// Linear sRGB → 8-bit sRGB-encoded (IEC 61966-2-1 transfer function, clamped to [0, 1], rounded), the same
/// encoding as the viewing-preview PNGs.
pub fn srgb8(linear: [f64; 3]) -> [u8; 3] {
    linear.map(|v| (crate::color::srgb::encode(v) * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_white_has_unit_luminance_and_maps_to_srgb_white() {
        let w = ColorWeights::new(SpectralGrid::new(1).unwrap(), Illuminant::D65);
        let ones = vec![1.0; w.grid.len()];
        let xyz = w.xyz_of(&ones);
        assert!((xyz[1] - 1.0).abs() < 1e-12);
        // D65 white point x = 0.3127, y = 0.3290 (CIE 15:2018 Table T.3, 2°).
        let s = xyz[0] + xyz[1] + xyz[2];
        assert!((xyz[0] / s - 0.3127).abs() < 2e-4 && (xyz[1] / s - 0.3290).abs() < 2e-4, "{xyz:?}");
        for c in w.linear_srgb_of(&ones) {
            assert!((c - 1.0).abs() < 1e-3, "{c}");
        }
    }

    #[test]
    fn grid_rejects_steps_that_do_not_divide_the_range() {
        assert_eq!(SpectralGrid::new(5).unwrap().len(), 81);
        assert_eq!(SpectralGrid::new(1).unwrap().len(), 401);
        assert!(SpectralGrid::new(3).is_err());
        assert!(SpectralGrid::new(0).is_err());
    }
}
