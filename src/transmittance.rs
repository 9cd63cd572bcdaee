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
//! Burley's normalized diffusion (Christensen & Burley 2015) has the plane integral in closed form,
//! T_c(s) = A_c (e^(−s/d_c) + 3e^(−s/(3d_c)))/4 ([`crate::diffusion::burley::Burley::plane_transmittance`]): the
//! "transmission profile" engine bakers (Unreal's Subsurface Profile, Unity HDRP) derive from a Burley profile.
//! [`TransmittanceModel`] is either source; Burley has only the plane-integral ("physical") form.
//!
//! Green's transmittance (Green, "Real-time approximations to subsurface scattering", *GPU Gems* ch. 16, 2004;
//! thesis §5.3, the baseline §5.6 compares against) is Beer–Lambert attenuation through the thickness s the shadow
//! map measures, T_c(s) = exp(−s·σt,c) ([`BeerLambert`]): one exponential per channel, no multiple scattering and
//! no layers. For a layer given by σa and σs′ it uses the reduced extinction σt′ = σa + σs′ (the diffusion models'
//! coefficient; with the unreduced σt = σa + σs′/(1 − g) skin would be opaque past a fraction of a mm).
//!
//! **Table convention** (node-inclusive): texel i of n holds s = s_max·i/(n − 1); a shader samples with linear
//! filtering at u = s/s_max·(n − 1)/n + 0.5/n (clamp to edge). The optional 2-D variant repeats the row h times.

use crate::diffusion::burley::RgbBurley;
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
    #[error("{0}")]
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

/// Green's Beer–Lambert transmittance T_c(s) = exp(−s·σt,c) (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BeerLambert {
    /// Extinction coefficient per channel, mm⁻¹.
    pub sigma_t_per_mm: [f64; 3],
}

impl BeerLambert {
    /// Validates σt (finite, > 0, at most 10⁴ mm⁻¹), naming `param`.
    pub fn new(param: &str, sigma_t_per_mm: [f64; 3]) -> Result<BeerLambert, InvalidInput> {
        for v in sigma_t_per_mm {
            check_range(param, v, 1e-9, 1e4, "1/mm")?;
        }
        Ok(BeerLambert { sigma_t_per_mm })
    }

    /// From a layer's σa and σs′ (mm⁻¹): σt′ = σa + σs′ per channel.
    pub fn from_reduced(
        param: &str,
        sigma_a_per_mm: [f64; 3],
        sigma_s_prime_per_mm: [f64; 3],
    ) -> Result<BeerLambert, InvalidInput> {
        Self::new(param, [0, 1, 2].map(|c| sigma_a_per_mm[c] + sigma_s_prime_per_mm[c]))
    }

    /// T(s) per channel, s ≥ 0 mm.
    pub fn at(&self, s_mm: f64) -> [f64; 3] {
        self.sigma_t_per_mm.map(|st| (-s_mm * st).exp())
    }

    /// The n × h RGB table of [`TableSettings`] (its `form` does not apply and is ignored).
    pub fn table(&self, settings: &TableSettings) -> Result<ImageF32, TransmittanceError> {
        settings.validate()?;
        let row: Vec<f32> =
            (0..settings.samples).flat_map(|i| self.at(settings.s_of_texel(i)).map(|t| t as f32)).collect();
        Ok(ImageF32::from_vec(settings.samples, settings.height, 3, row.repeat(settings.height as usize)))
    }
}

/// The formula string of Green's transmittance.
pub const GREEN_FORMULA: &str = "T(s) = exp(-s sigma_t) (Green 2004, Beer-Lambert through the thickness)";

/// What a transmittance table is computed from.
#[derive(Clone, Debug, PartialEq)]
pub enum TransmittanceModel {
    /// A sum of Gaussians (a preset or a fit): eq. 5.12 or its plane-integral form.
    Gaussians(RgbGaussians),
    /// Burley's normalized diffusion per channel: the closed-form plane integral.
    Burley(RgbBurley),
}

/// The formula string of Burley's transmission (recorded in sidecars and conventions).
pub const BURLEY_FORMULA: &str =
    "T(s) = A (exp(-s/d) + 3 exp(-s/(3 d))) / 4 (plane integral of Burley's normalized diffusion)";

impl TransmittanceModel {
    /// Checks that `form` applies: Burley has only the plane integral (`physical`).
    pub fn check_form(&self, form: TransmittanceForm) -> Result<(), InvalidInput> {
        match (self, form) {
            (Self::Burley(_), TransmittanceForm::Published) => Err(InvalidInput::new(
                "form",
                "a Burley profile has only the plane-integral ('physical') transmittance; the published \
                 exp(-s^2/v) form applies to sums of Gaussians",
            )),
            _ => Ok(()),
        }
    }

    /// T(s) per channel (s ≥ 0 mm); `form` is checked by [`Self::check_form`].
    pub fn at(&self, s_mm: f64, form: TransmittanceForm) -> [f64; 3] {
        match self {
            Self::Gaussians(sum) => transmittance(sum, s_mm, form),
            Self::Burley(b) => b.0.map(|c| c.plane_transmittance(s_mm)),
        }
    }

    /// The formula of the table in `form`.
    pub fn formula(&self, form: TransmittanceForm) -> &'static str {
        match self {
            Self::Gaussians(_) => form.formula(),
            Self::Burley(_) => BURLEY_FORMULA,
        }
    }

    /// Evaluates T at each distance (any order).
    pub fn evaluate(&self, s_mm: &[f64], form: TransmittanceForm) -> Result<Vec<[f64; 3]>, InvalidInput> {
        check_distances(s_mm)?;
        self.check_form(form)?;
        Ok(s_mm.iter().map(|&s| self.at(s, form)).collect())
    }

    /// Bakes the n×h RGB float table.
    pub fn table(&self, settings: &TableSettings) -> Result<ImageF32, TransmittanceError> {
        settings.validate()?;
        self.check_form(settings.form)?;
        let n = settings.samples;
        let row: Vec<f32> =
            (0..n).flat_map(|i| self.at(settings.s_of_texel(i), settings.form).map(|t| t as f32)).collect();
        let mut data = Vec::with_capacity(row.len() * settings.height as usize);
        for _ in 0..settings.height {
            data.extend_from_slice(&row);
        }
        Ok(ImageF32::from_vec(n, settings.height, 3, data))
    }
}

/// Validates distances (finite, ≥ 0, `--s`).
pub fn check_distances(s_mm: &[f64]) -> Result<(), InvalidInput> {
    if s_mm.is_empty() {
        return Err(InvalidInput::new("s_mm", "needs at least one distance in mm"));
    }
    for &s in s_mm {
        if !(s.is_finite() && s >= 0.0) {
            return Err(InvalidInput::new("s_mm", format!("distances must be finite numbers >= 0 mm, got {s}")));
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
        check_range("samples", self.samples, 2, MAX_SAMPLES, "texels")?;
        check_range("height", self.height, 1, MAX_SAMPLES, "texels")?;
        check_positive("s_max_mm", self.s_max_mm, "mm")?;
        if self.s_max_mm > MAX_S_MAX_MM {
            return Err(InvalidInput::new(
                "s_max_mm",
                format!("must be in (0, {MAX_S_MAX_MM}] mm, got {}", self.s_max_mm),
            ));
        }
        Ok(())
    }

    /// Peak memory of baking this table with its files (f32 table, f16 copies, EXR/KTX2/PNG encodings), in bytes:
    /// 56 bytes per texel + 32 MiB, from peak RSS measured at 512² and 2048² texels (51 B/texel).
    pub fn memory_estimate_bytes(&self) -> u64 {
        56 * self.samples as u64 * self.height as u64 + (32 << 20)
    }

    /// s of texel i (node-inclusive).
    pub fn s_of_texel(&self, i: u32) -> f64 {
        self.s_max_mm * i as f64 / (self.samples - 1) as f64
    }

    /// The convention string recorded in the manifest.
    pub fn convention(&self) -> String {
        self.convention_for(self.form.formula())
    }

    /// The convention string of a table of `formula` (a [`TransmittanceModel::formula`]).
    pub fn convention_for(&self, formula: &str) -> String {
        format!(
            "RGB = T(s) per channel, {}; x = texel i of n = {} holds s = s_max*i/(n-1) mm with s_max = {} mm \
             (node-inclusive); sample with linear filtering and clamp at u = s/s_max*(n-1)/n + 0.5/n; {} identical rows",
            formula,
            self.samples,
            self.s_max_mm,
            self.height
        )
    }
}

/// Bakes the n×h RGB float table of a sum of Gaussians ([`TransmittanceModel::table`]).
pub fn table(sum: &RgbGaussians, settings: &TableSettings) -> Result<ImageF32, TransmittanceError> {
    TransmittanceModel::Gaussians(sum.clone()).table(settings)
}

impl TableSettings {
    /// Wall time of baking this table with its files (the budget check): 1.4 µs per texel, dominated by the
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

    /// The model's Gaussian table is the Gaussian function's table; a Burley table holds the closed-form plane
    /// integral at every texel and refuses the published exp(−s²/v) form.
    #[test]
    fn model_tables() {
        use crate::diffusion::burley::{Burley, RgbBurley};
        let sum = RgbGaussians::from(&deon6());
        let settings = TableSettings { samples: 16, ..TableSettings::default() };
        let g = TransmittanceModel::Gaussians(sum.clone()).table(&settings).unwrap();
        assert_eq!(g.data, table(&sum, &settings).unwrap().data);
        let b =
            RgbBurley([Burley::new(0.8, 0.5).unwrap(), Burley::new(0.5, 0.2).unwrap(), Burley::new(0.3, 0.1).unwrap()]);
        let m = TransmittanceModel::Burley(b);
        assert!(m.table(&settings).is_err(), "published form refused");
        let physical = TableSettings { form: TransmittanceForm::Physical, ..settings };
        let img = m.table(&physical).unwrap();
        for i in 0..16u32 {
            for c in 0..3 {
                let want = b.0[c].plane_transmittance(physical.s_of_texel(i)) as f32;
                assert_eq!(img.data[3 * i as usize + c], want);
            }
        }
        assert_eq!(img.data[..3], [0.8, 0.5, 0.3]);
    }

    /// Green's T(s): T(0) = 1, each channel falls by e per 1/σt mm, the table's texels are the formula at their
    /// nodes; for Jensen et al. 2001's Skin1 (σa, σs′) red carries furthest; bad σt is named.
    #[test]
    fn green_beer_lambert() {
        let skin = BeerLambert::from_reduced("sigma", [0.032, 0.17, 0.48], [0.74, 0.88, 1.01]).unwrap();
        assert_eq!(skin.at(0.0), [1.0; 3]);
        let st = skin.sigma_t_per_mm;
        for (c, &st_c) in st.iter().enumerate() {
            assert!((skin.at(1.0 / st_c)[c] - (-1f64).exp()).abs() < 1e-12);
        }
        let t = skin.at(2.0);
        assert!(t[0] > t[1] && t[1] > t[2], "{t:?}");
        let settings = TableSettings { samples: 5, height: 2, s_max_mm: 4.0, form: TransmittanceForm::Physical };
        let table = skin.table(&settings).unwrap();
        assert_eq!((table.width, table.height, table.channels), (5, 2, 3));
        assert_eq!(table.data[3..6], skin.at(1.0).map(|v| v as f32));
        assert_eq!(table.row(0), table.row(1));
        assert_eq!(BeerLambert::new("sigma_t", [1.0, -1.0, 1.0]).unwrap_err().param, "sigma_t");
        assert!(BeerLambert::new("sigma_t", [1.0, f64::NAN, 1.0]).is_err());
    }
}
