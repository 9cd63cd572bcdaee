//! Transmittance through thin regions as a function of the distance s travelled inside the object (Jimenez,
//! Whelan, Sundstedt, Gutierrez, "Real-Time Realistic Skin Translucency", IEEE CG&A 30(4), 2010; thesis ch. 5):
//!
//! ```text
//! T_c(s) = Σᵢ wᵢ,c · exp(−s²/vᵢ)                 // eq. 5.12 (published form, also the published shader's)
//! ```
//!
//! Integrating a normalised 2-D Gaussian profile over a plane at depth s gives exp(−s²/(2v)) instead
//! ([`TransmittanceForm::Physical`], `--physical`). The weights and variances come from any preset or fitted sum of
//! Gaussians ([`crate::diffusion::sum_of_gaussians::RgbGaussians`]), per channel. T(0) = Σ w (= 1 for normalised profiles).
//!
//! **Table convention** (node-inclusive): texel i of n holds s = s_max·i/(n − 1); a shader samples with linear
//! filtering at u = s/s_max·(n − 1)/n + 0.5/n (clamp to edge). The optional 2-D variant repeats the row h times.

use crate::diffusion::sum_of_gaussians::RgbGaussians;
use crate::error::{check_positive, check_range, InvalidInput};
use crate::image_buf::ImageF32;

/// Which exponent the table uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TransmittanceForm {
    /// exp(−s²/v), as printed in the thesis (eq. 5.12) and used by the published shader.
    #[default]
    Published,
    /// exp(−s²/(2v)), the plane integral of a normalised 2-D Gaussian.
    Physical,
}

impl TransmittanceForm {
    pub fn formula(self) -> &'static str {
        match self {
            Self::Published => "T(s) = sum_i w_i exp(-s^2 / v_i) (thesis eq. 5.12, published form)",
            Self::Physical => "T(s) = sum_i w_i exp(-s^2 / (2 v_i)) (plane integral of normalised Gaussians)",
        }
    }
}

/// Default table width (texels).
pub const DEFAULT_SAMPLES: u32 = 256;
/// Default domain end, mm (red falls to 1e−4 near s ≈ 7 mm for d'Eon's skin).
pub const DEFAULT_S_MAX_MM: f64 = 8.0;
/// Largest accepted table width / height.
pub const MAX_SAMPLES: u32 = 16384;
/// Largest accepted domain end, mm.
pub const MAX_S_MAX_MM: f64 = 1e4;

/// Errors of the transmittance functions.
#[derive(Debug, thiserror::Error)]
pub enum TransmittanceError {
    #[error(transparent)]
    Invalid(#[from] InvalidInput),
}

/// T(s) per channel for one distance s ≥ 0 (mm).
pub fn transmittance(sum: &RgbGaussians, s_mm: f64, form: TransmittanceForm) -> [f64; 3] {
    let s2 = s_mm * s_mm;
    [0, 1, 2].map(|c| {
        sum.variances_mm2[c]
            .iter()
            .zip(&sum.weights[c])
            .map(|(v, w)| match form {
                TransmittanceForm::Published => w * (-s2 / v).exp(), // eq. 5.12
                TransmittanceForm::Physical => w * (-s2 / (2.0 * v)).exp(),
            })
            .sum()
    })
}

/// Validates distances (finite, ≥ 0, `--s`).
pub fn check_distances(s_mm: &[f64]) -> Result<(), InvalidInput> {
    if s_mm.is_empty() {
        return Err(InvalidInput::new("--s", "needs at least one distance in mm"));
    }
    for &s in s_mm {
        if !(s.is_finite() && s >= 0.0) {
            return Err(InvalidInput::new("--s", format!("distances must be finite numbers >= 0 mm, got {s}")));
        }
    }
    Ok(())
}

/// Evaluates T at each distance (any order).
pub fn evaluate(sum: &RgbGaussians, s_mm: &[f64], form: TransmittanceForm) -> Result<Vec<[f64; 3]>, InvalidInput> {
    check_distances(s_mm)?;
    Ok(s_mm.iter().map(|&s| transmittance(sum, s, form)).collect())
}

/// Table settings.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableSettings {
    /// Texels along s (`--samples`, 2..=16384).
    pub samples: u32,
    /// Rows (`--height`, 1..=16384); all identical (for APIs without 1-D textures).
    pub height: u32,
    /// Domain end s_max in mm (`--s-max`, > 0).
    pub s_max_mm: f64,
    pub form: TransmittanceForm,
}

impl Default for TableSettings {
    fn default() -> Self {
        Self { samples: DEFAULT_SAMPLES, height: 1, s_max_mm: DEFAULT_S_MAX_MM, form: TransmittanceForm::Published }
    }
}

impl TableSettings {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("--samples", self.samples, 2, MAX_SAMPLES, "texels")?;
        check_range("--height", self.height, 1, MAX_SAMPLES, "texels")?;
        check_positive("--s-max", self.s_max_mm, "mm")?;
        if self.s_max_mm > MAX_S_MAX_MM {
            return Err(InvalidInput::new(
                "--s-max",
                format!("must be in (0, {MAX_S_MAX_MM}] mm, got {}", self.s_max_mm),
            ));
        }
        Ok(())
    }

    /// Peak memory of baking this table with its files (f32 table, f16 copies, EXR/KTX2/PNG encodings), in bytes:
    /// 56 bytes per texel + 32 MiB, from peak RSS measured at 512² and 2048² texels (51 B/texel; issue 15).
    pub fn memory_estimate_bytes(&self) -> u64 {
        56 * self.samples as u64 * self.height as u64 + (32 << 20)
    }

    /// s of texel i (node-inclusive).
    pub fn s_of_texel(&self, i: u32) -> f64 {
        self.s_max_mm * i as f64 / (self.samples - 1) as f64
    }

    /// The convention string recorded in the manifest.
    pub fn convention(&self) -> String {
        format!(
            "RGB = T(s) per channel, {}; x = texel i of n = {} holds s = s_max*i/(n-1) mm with s_max = {} mm \
             (node-inclusive); sample with linear filtering and clamp at u = s/s_max*(n-1)/n + 0.5/n; {} identical rows",
            self.form.formula(),
            self.samples,
            self.s_max_mm,
            self.height
        )
    }
}

/// Bakes the n×h RGB float table.
pub fn table(sum: &RgbGaussians, settings: &TableSettings) -> Result<ImageF32, TransmittanceError> {
    settings.validate()?;
    let n = settings.samples;
    let row: Vec<f32> =
        (0..n).flat_map(|i| transmittance(sum, settings.s_of_texel(i), settings.form).map(|t| t as f32)).collect();
    let mut data = Vec::with_capacity(row.len() * settings.height as usize);
    for _ in 0..settings.height {
        data.extend_from_slice(&row);
    }
    Ok(ImageF32::from_vec(n, settings.height, 3, data))
}

impl TableSettings {
    /// Wall time of baking this table with its files (issue 15's budget check): 1.4 µs per texel, dominated by the
    /// PNG and EXR encoders, plus 0.1 s; 16384 × 16384 took about 6 min on the project's 2-core machine.
    pub fn time_estimate_seconds(&self) -> f64 {
        0.1 + 1.4e-6 * self.samples as f64 * self.height as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::sum_of_gaussians::deon6;

    #[test]
    fn published_and_physical_forms() {
        let sum = RgbGaussians::from(&deon6());
        let t0 = transmittance(&sum, 0.0, TransmittanceForm::Published);
        assert!((t0[0] - 1.0).abs() < 1e-12 && (t0[1] - 1.0).abs() < 1e-12 && (t0[2] - 1.0).abs() < 1e-12);
        // exp(−s²/(2v)) at s equals exp(−(s/√2)²/v).
        let p = transmittance(&sum, 2.0, TransmittanceForm::Physical);
        let q = transmittance(&sum, 2.0 / 2f64.sqrt(), TransmittanceForm::Published);
        for c in 0..3 {
            assert!((p[c] - q[c]).abs() < 1e-15);
        }
    }
}
