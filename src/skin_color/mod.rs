//! Skin colour from melanin and hemoglobin: the spectral two-layer model and its lookup table.
//!
//! Thesis (Jimenez 2012) §7.6, eq. 7.7, Table 7.1, Fig. 7.9; Jimenez et al., "A Practical Appearance Model for
//! Dynamic Facial Color", SIGGRAPH Asia 2010; the model of Donner et al. 2008 / Donner & Jensen 2006.
//! Every constant is stated where it is used (the defaults on [`SkinColorParams`], the layer forms in
//! [`crate::spectral::skin_layers`], the colorimetry in [`crate::spectral::colorimetry`]).
//!
//! - [`two_layer`]: R(λ) of the epidermis-over-dermis stack (multipole totals + adding) and its linear sRGB colour.
//! - [`epidermis_table`]: the epidermis' totals tabulated against √σa and the table's vectorised row loop.
//! - [`lut`]: the cube-root-indexed melanin × hemoglobin table and its texel convention.
//! - [`SkinColorParams`]: every parameter with the published defaults, as JSON (asset parameters) and CLI flags
//!   (`--melanin-blend` ↔ `melanin_blend`).

pub mod epidermis_table;
pub mod lut;
pub mod monte_carlo;
pub mod two_layer;

use crate::diffusion::FdrForm;
use crate::spectral::colorimetry::Illuminant;
use crate::spectral::skin_layers::SkinPhysiology;
use lut::{IndexForm, LutEvaluation, LutLayout};
use serde::{Deserialize, Serialize};
use two_layer::{Adding, ModelOptions, SkinColorError, ThinLayer, TwoLayerSkinModel};

/// Every parameter of the skin-colour model and table. Defaults: the published LUT (βm = 0.61, Che = 0.25·Chd,
/// γ = 0.75, 150 g/L, 64500 g/mol, 0.25 mm over 20 mm, η = 1.4, D65, symmetric adding, normalised cube-root index,
/// 256 × 256, 1 nm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkinColorParams {
    /// βm: eumelanin share of the melanin (0–1).
    pub melanin_blend: f64,
    /// Che / Chd (0–1).
    pub epidermal_hemoglobin_ratio: f64,
    /// γ: blood oxygenation (0–1).
    pub oxygenation: f64,
    pub hemoglobin_g_per_l: f64,
    pub hemoglobin_molar_mass_g_per_mol: f64,
    pub epidermis_thickness_mm: f64,
    pub dermis_thickness_mm: f64,
    pub eta_epidermis: f64,
    pub eta_dermis: f64,
    pub eta_below_dermis: f64,
    pub illuminant: Illuminant,
    pub adding: Adding,
    /// Wavelength step of the 380–780 nm integration (must divide 400; 1 = published).
    pub spectral_step_nm: u32,
    pub fdr_form: FdrForm,
    pub thin_layer: ThinLayer,
    /// Lift Table 7.1's ranges for point queries (volume fractions in [0, 1]).
    pub allow_unphysiological: bool,
    pub index_form: IndexForm,
    /// Columns (melanin axis).
    pub width: u32,
    /// Rows (hemoglobin axis).
    pub height: u32,
    /// How the table evaluates the epidermis totals (tabulated exact series by default).
    pub lut_evaluation: LutEvaluation,
}

impl Default for SkinColorParams {
    fn default() -> Self {
        let p = SkinPhysiology::default();
        let o = ModelOptions::default();
        Self {
            melanin_blend: p.melanin_blend,
            epidermal_hemoglobin_ratio: p.epidermal_hemoglobin_ratio,
            oxygenation: p.oxygenation,
            hemoglobin_g_per_l: p.hemoglobin_g_per_l,
            hemoglobin_molar_mass_g_per_mol: p.hemoglobin_molar_mass_g_per_mol,
            epidermis_thickness_mm: p.epidermis_thickness_mm,
            dermis_thickness_mm: p.dermis_thickness_mm,
            eta_epidermis: p.eta_epidermis,
            eta_dermis: p.eta_dermis,
            eta_below_dermis: p.eta_below_dermis,
            illuminant: o.illuminant,
            adding: o.adding,
            spectral_step_nm: o.spectral_step_nm,
            fdr_form: o.fdr_form,
            thin_layer: o.thin_layer,
            allow_unphysiological: false,
            index_form: IndexForm::NormalizedCbrt,
            width: 256,
            height: 256,
            lut_evaluation: LutEvaluation::Tabulated,
        }
    }
}

impl SkinColorParams {
    pub fn physiology(&self) -> SkinPhysiology {
        SkinPhysiology {
            melanin_blend: self.melanin_blend,
            epidermal_hemoglobin_ratio: self.epidermal_hemoglobin_ratio,
            oxygenation: self.oxygenation,
            hemoglobin_g_per_l: self.hemoglobin_g_per_l,
            hemoglobin_molar_mass_g_per_mol: self.hemoglobin_molar_mass_g_per_mol,
            epidermis_thickness_mm: self.epidermis_thickness_mm,
            dermis_thickness_mm: self.dermis_thickness_mm,
            eta_epidermis: self.eta_epidermis,
            eta_dermis: self.eta_dermis,
            eta_below_dermis: self.eta_below_dermis,
        }
    }

    pub fn model_options(&self) -> ModelOptions {
        ModelOptions {
            illuminant: self.illuminant,
            adding: self.adding,
            spectral_step_nm: self.spectral_step_nm,
            fdr_form: self.fdr_form,
            thin_layer: self.thin_layer,
        }
    }

    /// Validated table layout (size checked before anything is allocated).
    pub fn layout(&self) -> Result<LutLayout, SkinColorError> {
        Ok(LutLayout::new(self.width, self.height, self.index_form)?)
    }

    /// Validates every parameter and builds the model.
    pub fn model(&self) -> Result<TwoLayerSkinModel, SkinColorError> {
        TwoLayerSkinModel::new(&self.physiology(), &self.model_options())
    }
}
