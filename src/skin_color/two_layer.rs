//! Total diffuse reflectance of the spectral two-layer skin and its colour.
//!
//! Donner & Jensen, "A Spectral BSSRDF for Shading Human Skin", EGSR 2006; Donner et al., SIGGRAPH Asia 2008; the
//! skin-colour table of the thesis (Jimenez 2012, §7.6, Fig. 7.9). Per wavelength λ (380–780 nm):
//!
//! 1. layer coefficients from the chromophore fractions (`spectral::skin_layers`);
//! 2. per layer the multipole totals R̂(0), T̂(0) with the exact infinite image series (Donner & Jensen,
//!    SIGGRAPH 2005, `diffusion::multipole::Slab::totals(Series::Exact)`): epidermis with air above
//!    (η0 = η_epi / 1) and the index-matched dermis below (ηd = η_epi / η_derm = 1); dermis with ηd = η_derm / η_below;
//! 3. adding at k = 0 (DJ05 eq. as printed):
//!    symmetric (default)  R = R1 + T1² R2 / (1 − R1 R2)
//!    directional          R = R1↓ + T1↓ R2 T1↑ / (1 − R1↑ R2)   (R1↑, T1↑: the epidermis lit from below);
//! 4. XYZ under D65 (or E) with the CIE 1931 2° observer, Y(white) = 1, then linear sRGB (`spectral::colorimetry`).
//!
//! Point queries ([`TwoLayerSkinModel::evaluate`]) call the series for every wavelength. Whole tables
//! ([`TwoLayerSkinModel::linear_rgb_grid`]) compute the dermis once per row and take the epidermis totals from an
//! [`EpidermisTable`] per wavelength (exact-series nodes, cubic interpolation in √σa, agreement to f32 rounding).
//!
//! Validity of the thin epidermis: the multipole places its source at depth l = 1/σt′, which must lie inside the
//! layer (d > l). With the defaults the weakest case is λ = 780 nm, Cm = Chd = 0: σt′ = 4.025 mm⁻¹, l = 0.2484 mm
//! against d = 0.25 mm, so the published configuration is valid at every wavelength, by a margin of 0.6 %. Thinner
//! layers fail at the red end; [`ThinLayer::Reject`] (default) refuses them naming the wavelength and the limit,
//! [`ThinLayer::ClampTransmittance`] evaluates the series anyway and clamps a negative T̂(0) to 0 (what other
//! implementations do silently), recorded in the outputs' parameters.

use crate::diffusion::multipole::{Series, Slab};
use crate::diffusion::{FdrForm, ReducedCoefficients};
use crate::error::InvalidInput;
use crate::spectral::chromophores::ChromophoreSpectra;
use crate::spectral::colorimetry::{srgb8, ColorWeights, Illuminant, SpectralGrid};
use crate::spectral::skin_layers::{dermis_sigma_a_per_mm, epidermis_sigma_a_mixed, SkinPhysiology};
use serde::{Deserialize, Serialize};

use super::epidermis_table::{accumulate_symmetric_row, BandRow, RowScratch};
pub use super::epidermis_table::{EpidermisTable, TABLE_INTERVALS};

/// How the two layers' totals are combined at k = 0: the same choice as for layered profiles
/// (symmetric = DJ05 as printed, the published LUT's form; directional = Kubelka 1954).
pub use crate::diffusion::layered::Adding;

/// What to do where the epidermis is thinner than its transport mean free path 1/σt′.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThinLayer {
    /// Refuse with an error naming the wavelength and the limit (default).
    #[default]
    Reject,
    /// Evaluate anyway and clamp negative transmittance to 0.
    ClampTransmittance,
}

/// Model options besides the physiology.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelOptions {
    pub illuminant: Illuminant,
    pub adding: Adding,
    pub spectral_step_nm: u32,
    pub fdr_form: FdrForm,
    pub thin_layer: ThinLayer,
}

impl Default for ModelOptions {
    fn default() -> Self {
        Self {
            illuminant: Illuminant::D65,
            adding: Adding::Symmetric,
            spectral_step_nm: 1,
            fdr_form: FdrForm::Dj05,
            thin_layer: ThinLayer::Reject,
        }
    }
}

/// Errors of the skin-colour model.
#[derive(Debug, thiserror::Error)]
pub enum SkinColorError {
    #[error("{0}")]
    Invalid(#[from] InvalidInput),
}

/// The constants of one wavelength band.
#[derive(Clone, Copy, Debug)]
struct Band {
    spectra: ChromophoreSpectra,
    /// βm σa,em + (1 − βm) σa,pm.
    melanin: f64,
    /// γ σa,oxy + (1 − γ) σa,deoxy.
    blood: f64,
}

/// The evaluated two-layer model: per-wavelength constants and colour weights, ready for many (Cm, Chd) queries.
#[derive(Clone, Debug)]
pub struct TwoLayerSkinModel {
    physiology: SkinPhysiology,
    options: ModelOptions,
    weights: ColorWeights,
    bands: Vec<Band>,
}

/// Reflectance of the dermis (top-lit R̂(0)) at every band, for one Chd.
pub struct DermisReflectance(Vec<f64>);

impl TwoLayerSkinModel {
    pub fn new(physiology: &SkinPhysiology, options: &ModelOptions) -> Result<Self, SkinColorError> {
        physiology.validate()?;
        let grid = SpectralGrid::new(options.spectral_step_nm)?;
        let bands = grid
            .wavelengths_nm()
            .into_iter()
            .map(|l| {
                let spectra = physiology.spectra_at(l).expect("380–780 nm lies inside Prahl's table");
                Band {
                    melanin: spectra.melanin(physiology.melanin_blend),
                    blood: spectra.blood(physiology.oxygenation),
                    spectra,
                }
            })
            .collect();
        Ok(Self {
            physiology: physiology.clone(),
            options: options.clone(),
            weights: ColorWeights::new(grid, options.illuminant),
            bands,
        })
    }

    pub fn physiology(&self) -> &SkinPhysiology {
        &self.physiology
    }
    pub fn options(&self) -> &ModelOptions {
        &self.options
    }
    pub fn weights(&self) -> &ColorWeights {
        &self.weights
    }
    pub fn wavelengths_nm(&self) -> Vec<f64> {
        self.weights.grid.wavelengths_nm()
    }

    /// σa of the epidermis at `band` (the mixing rule exactly as printed; with the literal index form's far corner
    /// Cm + Che > 1 the baseline weight is negative, which the melanin term outweighs by orders of magnitude).
    #[inline]
    fn epidermis_sigma_a(&self, band: &Band, cm: f64, che: f64) -> f64 {
        epidermis_sigma_a_mixed(cm, band.melanin, che, band.blood, band.spectra.baseline)
    }

    #[inline]
    fn epidermis_slab(&self, band: &Band, sigma_a_per_mm: f64) -> Slab {
        let p = &self.physiology;
        Slab {
            sigma_a_per_mm,
            sigma_s_prime_per_mm: band.spectra.sigma_s_prime_epidermis,
            thickness_mm: p.epidermis_thickness_mm,
            eta_top: p.eta_epidermis / 1.0,
            eta_bottom: p.eta_epidermis / p.eta_dermis,
            fdr_form: self.options.fdr_form,
        }
    }

    /// Exact multipole totals of the epidermis: (R1↓, T1↓, R1↑, T1↑); the lit-from-below pair only for directional
    /// adding (zeros otherwise). Negative T is clamped with [`ThinLayer::ClampTransmittance`].
    #[inline]
    fn epidermis_totals(&self, band: &Band, sigma_a_per_mm: f64) -> [f64; 4] {
        let slab = self.epidermis_slab(band, sigma_a_per_mm);
        let (r1, t1) = slab.totals(Series::Exact);
        let (r1_up, t1_up) = match self.options.adding {
            Adding::Symmetric => (0.0, 0.0),
            Adding::Directional => slab.flipped().totals(Series::Exact),
        };
        if self.options.thin_layer == ThinLayer::ClampTransmittance {
            [r1, t1.max(0.0), r1_up, t1_up.max(0.0)]
        } else {
            [r1, t1, r1_up, t1_up]
        }
    }

    /// Adding at k = 0 of the epidermis totals `e` = (R1↓, T1↓, R1↑, T1↑) over a dermis of reflectance `r2`.
    #[inline]
    fn add_layers(&self, e: [f64; 4], r2: f64) -> f64 {
        let [r1, t1, r1_up, t1_up] = e;
        match self.options.adding {
            // DJ05 adding as printed ("symmetric"), at k = 0.
            Adding::Symmetric => r1 + t1 * t1 * r2 / (1.0 - r1 * r2),
            // Kubelka 1954 directional adding, at k = 0.
            Adding::Directional => r1 + t1 * r2 * t1_up / (1.0 - r1_up * r2),
        }
    }

    fn dermis_slab(&self, band: &Band, chd: f64) -> Slab {
        let p = &self.physiology;
        Slab {
            sigma_a_per_mm: dermis_sigma_a_per_mm(&band.spectra, chd, p.oxygenation),
            sigma_s_prime_per_mm: band.spectra.sigma_s_prime_dermis,
            thickness_mm: p.dermis_thickness_mm,
            eta_top: p.eta_dermis / p.eta_epidermis,
            eta_bottom: p.eta_dermis / p.eta_below_dermis,
            fdr_form: self.options.fdr_form,
        }
    }

    /// Checks the multipole validity d > 1/σt′ of both layers at every wavelength for every (Cm, Chd) in the box
    /// [0, cm_max] × [0, chd_max]. σa is linear in Cm and Chd, so the corners bound it; σt′ is smallest where σa is.
    pub fn check_validity(&self, cm_max: f64, chd_max: f64) -> Result<(), SkinColorError> {
        self.check_points(&[(0.0, 0.0), (cm_max, 0.0), (0.0, chd_max), (cm_max, chd_max)])
    }

    /// The validity check at the given (Cm, Chd) points (no-op with [`ThinLayer::ClampTransmittance`]); the error
    /// names the wavelength with the longest mean free path and the span of failing wavelengths.
    fn check_points(&self, points: &[(f64, f64)]) -> Result<(), SkinColorError> {
        if self.options.thin_layer == ThinLayer::ClampTransmittance {
            return Ok(());
        }
        for (layer, field) in [("epidermis", "epidermis_thickness_mm"), ("dermis", "dermis_thickness_mm")] {
            // (worst l, its λ, Cm, Chd), first and last failing λ.
            let mut worst: Option<(f64, f64, f64, f64)> = None;
            let mut span = (f64::INFINITY, f64::NEG_INFINITY);
            let mut thickness = 0.0;
            for band in &self.bands {
                for &(cm, chd) in points {
                    let slab = if layer == "epidermis" {
                        let che = self.physiology.epidermal_hemoglobin(chd);
                        self.epidermis_slab(band, self.epidermis_sigma_a(band, cm, che))
                    } else {
                        self.dermis_slab(band, chd)
                    };
                    let l = 1.0 / slab.sigma_t_prime();
                    thickness = slab.thickness_mm;
                    if slab.thickness_mm <= l {
                        let lambda = band.spectra.lambda_nm;
                        span = (span.0.min(lambda), span.1.max(lambda));
                        if worst.is_none_or(|w| l > w.0) {
                            worst = Some((l, lambda, cm, chd));
                        }
                    }
                }
            }
            if let Some((l, lambda, cm, chd)) = worst {
                return Err(InvalidInput::new(
                    field,
                    format!(
                        "must exceed the {layer}'s transport mean free path 1/sigma_t' = {l:.5} mm at {lambda} nm \
                         (Cm = {cm}, Chd = {chd}; too thin from {} to {} nm) for the multipole diffusion source to lie \
                         inside the layer, got {thickness} (`thin_layer` clamp-transmittance evaluates it anyway)",
                        span.0, span.1
                    ),
                )
                .into());
            }
        }
        Ok(())
    }

    /// Top-lit dermis reflectance R2 at every band for dermal hemoglobin `chd`.
    pub fn dermis_reflectance(&self, chd: f64) -> DermisReflectance {
        DermisReflectance(self.bands.iter().map(|b| self.dermis_slab(b, chd).total_reflectance_exact()).collect())
    }

    /// Stack reflectance at `band` given the dermis reflectance `r2`.
    #[inline]
    fn stack_reflectance(&self, band: &Band, cm: f64, che: f64, r2: f64) -> f64 {
        self.add_layers(self.epidermis_totals(band, self.epidermis_sigma_a(band, cm, che)), r2)
    }

    /// Total diffuse reflectance spectrum R(λ) on the model's grid, without range checks (callers validate: see
    /// [`Self::check_validity`] and `skin_layers::check_concentrations`).
    pub fn reflectance_unchecked(&self, cm: f64, chd: f64, dermis: &DermisReflectance) -> Vec<f64> {
        let che = self.physiology.epidermal_hemoglobin(chd);
        self.bands.iter().zip(&dermis.0).map(|(b, &r2)| self.stack_reflectance(b, cm, che, r2)).collect()
    }

    /// Bounds of the epidermal σa over [0, cm_max] × [0, chd_max] at `band` (σa is linear in Cm and Che, so the
    /// corners bound it).
    fn epidermis_sigma_a_range(&self, band: &Band, cm_max: f64, chd_max: f64) -> (f64, f64) {
        let che_max = self.physiology.epidermal_hemoglobin(chd_max);
        let corners = [(0.0, 0.0), (cm_max, 0.0), (0.0, che_max), (cm_max, che_max)];
        corners
            .iter()
            .map(|&(cm, che)| self.epidermis_sigma_a(band, cm, che))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
    }

    /// One [`EpidermisTable`] per band covering the box [0, cm_max] × [0, chd_max], or `None` for bands where it
    /// cannot be used (σa ≤ 0, or a node where the epidermis is thinner than 1/σt′): those are evaluated directly.
    pub fn epidermis_tables(&self, cm_max: f64, chd_max: f64) -> Vec<Option<EpidermisTable>> {
        use rayon::prelude::*;
        self.bands
            .par_iter()
            .map(|band| {
                let (lo, hi) = self.epidermis_sigma_a_range(band, cm_max, chd_max);
                if !(lo > 0.0 && hi.is_finite()) {
                    return None;
                }
                // Grid in y = √σa (a degenerate range still gets a proper grid around it).
                let (y_lo, y_hi) = (lo.sqrt() - 1e-6, hi.sqrt() + 1e-6);
                let h = (y_hi - y_lo) / TABLE_INTERVALS as f64;
                if y_lo - h <= 0.0 {
                    return None;
                }
                let mut rt = Vec::with_capacity(TABLE_INTERVALS + 3);
                let mut up = Vec::new();
                for k in 0..TABLE_INTERVALS + 3 {
                    // Nodes at y_lo + (k − 1)·h: one extra node on each side for the 4-point stencil.
                    let y = y_lo + (k as f64 - 1.0) * h;
                    let sigma_a = y * y;
                    let slab = self.epidermis_slab(band, sigma_a);
                    if slab.thickness_mm <= 1.0 / slab.sigma_t_prime() {
                        return None;
                    }
                    let e = self.epidermis_totals(band, sigma_a);
                    rt.push([e[0], e[1]]);
                    if self.options.adding == Adding::Directional {
                        up.push([e[2], e[3]]);
                    }
                }
                Some(EpidermisTable::from_nodes(y_lo, h, &rt, &up))
            })
            .collect()
    }

    /// Linear sRGB of the grid `melanin` (columns) × `hemoglobin` (rows) into `out` (row-major RGB f32), with the
    /// epidermis totals from `tables` where present (see [`EpidermisTable`]) and directly otherwise. Every texel sums
    /// its bands in ascending wavelength order, so the result does not depend on how rows are split across threads.
    /// No range checks (see [`Self::check_validity`]).
    pub fn linear_rgb_grid(
        &self,
        melanin: &[f64],
        hemoglobin: &[f64],
        tables: &[Option<EpidermisTable>],
        out: &mut [f32],
    ) {
        let w = melanin.len();
        assert_eq!(out.len(), 3 * w * hemoglobin.len(), "output size");
        assert_eq!(tables.len(), self.bands.len(), "one table slot per band");
        let ches: Vec<f64> = hemoglobin.iter().map(|&chd| self.physiology.epidermal_hemoglobin(chd)).collect();
        let dermis: Vec<DermisReflectance> = hemoglobin.iter().map(|&chd| self.dermis_reflectance(chd)).collect();
        // Accumulator planes R, G, B (one f64 per texel each), so that the vectorised loop reads and writes whole
        // vectors.
        let n = out.len() / 3;
        let mut acc = vec![0.0f64; 3 * n];
        let (acc_r, acc_gb) = acc.split_at_mut(n);
        let (acc_g, acc_b) = acc_gb.split_at_mut(n);
        let mut scratch = RowScratch::default();
        for (b, (band, table)) in self.bands.iter().zip(tables).enumerate() {
            let wt = self.weights.linear_srgb[b];
            let rows = acc_r.chunks_exact_mut(w).zip(acc_g.chunks_exact_mut(w)).zip(acc_b.chunks_exact_mut(w));
            for (r, ((ar, ag), ab)) in rows.enumerate() {
                let (r2, che) = (dermis[r].0[b], ches[r]);
                // The table/direct choice is made once per band and row, not per texel (monomorphised loops).
                match table {
                    Some(t) if self.options.adding == Adding::Symmetric => {
                        let k = BandRow {
                            melanin_sigma_a_per_mm: band.melanin,
                            che,
                            che_blood_sigma_a_per_mm: che * band.blood,
                            baseline_sigma_a_per_mm: band.spectra.baseline,
                            r2,
                            weights: wt,
                        };
                        accumulate_symmetric_row(t, &k, melanin, [ar, ag, ab], &mut scratch);
                    }
                    Some(t) => self.accumulate_row([ar, ag, ab], melanin, band, che, r2, wt, |sa| t.eval(sa)),
                    None => self
                        .accumulate_row([ar, ag, ab], melanin, band, che, r2, wt, |sa| self.epidermis_totals(band, sa)),
                }
            }
        }
        for (i, o) in out.chunks_exact_mut(3).enumerate() {
            o.copy_from_slice(&[acc_r[i] as f32, acc_g[i] as f32, acc_b[i] as f32]);
        }
    }

    /// Adds band `band`'s weighted stack reflectance of every texel of one row to the accumulator planes `acc`
    /// (the directional and direct paths; symmetric tabulated adding takes `epidermis_table::accumulate_symmetric_row`).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn accumulate_row(
        &self,
        acc: [&mut [f64]; 3],
        melanin: &[f64],
        band: &Band,
        che: f64,
        r2: f64,
        wt: [f64; 3],
        totals: impl Fn(f64) -> [f64; 4],
    ) {
        let [acc_r, acc_g, acc_b] = acc;
        for (x, &cm) in melanin.iter().enumerate() {
            let refl = self.add_layers(totals(self.epidermis_sigma_a(band, cm, che)), r2);
            acc_r[x] += wt[0] * refl;
            acc_g[x] += wt[1] * refl;
            acc_b[x] += wt[2] * refl;
        }
    }

    /// Evaluates one point with full validation (`allow_unphysiological` lifts Table 7.1's ranges).
    pub fn evaluate(&self, cm: f64, chd: f64, allow_unphysiological: bool) -> Result<SkinColorSample, SkinColorError> {
        crate::spectral::skin_layers::check_concentrations(
            "melanin",
            cm,
            "hemoglobin",
            chd,
            &self.physiology,
            allow_unphysiological,
        )?;
        self.check_points(&[(cm, chd)])?;
        let dermis = self.dermis_reflectance(chd);
        let reflectance = self.reflectance_unchecked(cm, chd, &dermis);
        let linear_rgb = self.weights.linear_srgb_of(&reflectance);
        Ok(SkinColorSample { melanin: cm, hemoglobin: chd, linear_rgb, srgb8: srgb8(linear_rgb), reflectance })
    }
}

/// One evaluated point.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinColorSample {
    pub melanin: f64,
    pub hemoglobin: f64,
    pub linear_rgb: [f64; 3],
    pub srgb8: [u8; 3],
    /// R(λ) on the model's wavelength grid.
    pub reflectance: Vec<f64>,
}
