//! Spectral physics of skin: chromophore absorption, the two-layer skin coefficients and colorimetry.
//!
//! Donner & Jensen 2006 (EGSR, "A Spectral BSSRDF for Shading Human Skin"), Donner et al. 2008 (SIGGRAPH Asia,
//! "A Layered, Heterogeneous Reflectance Model for Acquiring and Rendering Human Skin"), thesis §7.6. Wavelengths in nm, coefficients in mm⁻¹.
//!
//! - [`data`]: embedded, attributed tables (Prahl hemoglobin extinction, CIE 1931 2° observer, D65): the published
//!   files themselves (`src/spectral/data/`), parsed once.
//! - [`chromophores`]: σa of melanins, baseline and blood, σs′ of both layers.
//! - [`skin_layers`]: the layer-mixing rule and per-channel RGB coefficients of the physiological two-layer skin.
//! - [`colorimetry`]: spectrum → XYZ (D65 or E, CIE 1931 2°) → linear sRGB.
//!
//! These modules know nothing about files, images or the GPU.

pub mod chromophores;
pub mod colorimetry;
pub mod data;
pub mod skin_layers;
