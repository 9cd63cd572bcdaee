//! Separable subsurface scattering (J. Jimenez, *Practical Real-Time Strategies for Photorealistic Skin Rendering
//! and Antialiasing*, PhD thesis, 2012, ch. 6; J. Jimenez et al., "Separable Subsurface Scattering and Photorealistic
//! Eyes Rendering", SIGGRAPH 2012 course *Advances in Real-Time Rendering in Games*, with the published
//! `SeparableSSS` shader and demo).
//!
//! The 2-D diffusion kernel `S[x, y]` of skin is replaced by the product `s[x]·s[y]` of one 1-D kernel (eq. 6.1)
//!
//! ```text
//! s(w, t, f)[x] = p[x·w/(0.001 + f)]·t + δ(x)·(1 − t)
//! ```
//!
//! with per-channel *strength* t and *falloff* f and a global *width* w; p is the red channel of d'Eon et al.'s
//! 6-Gaussian skin profile without its narrowest Gaussian (which the delta term stands in for).
//!
//! - [`kernel`]: the N-tap runtime kernel exactly as the published shader expects it (offsets, area rule, centre
//!   first, per-channel normalisation, strength mix), in f32 (reproduces the shipped digits) or f64.
//! - [`fit`]: fitting strength and falloff to the exact 2-D kernel of any [`crate::diffusion::RadialProfile`]
//!   (eq. 6.2–6.3) under an explicit, recorded objective, and the separability (first singular value) of a target.
//!
//! These modules know nothing about files or the GPU; `crate::bake::separable` turns kernels into files.

pub mod fit;
pub mod kernel;

use serde::{Deserialize, Serialize};

/// Per-channel strength and falloff of the separable kernel (eq. 6.1). Width is not part of the kernel taps: the
/// runtime applies it as `sssWidth` when it scales the tap offsets.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeparableParams {
    /// t per channel (R, G, B), in 0..=1: the fraction of light that is scattered (1 − t stays at the centre).
    pub strength: [f64; 3],
    /// f per channel (R, G, B), >= 0: scales the profile's radius (smaller = narrower kernel).
    pub falloff: [f64; 3],
}

/// The presets of the published SeparableSSS demo (`SeparableSSS.h` and its demo defaults).
pub const PUBLISHED: SeparableParams = SeparableParams { strength: [0.48, 0.41, 0.28], falloff: [1.0, 0.37, 0.3] };

/// `sssWidth` of the published demo, world units (a head about 1 unit tall).
pub const PUBLISHED_SSS_WIDTH: f64 = 0.012;

/// Thesis Table 6.1: the parameters the thesis obtained by optimising eq. 6.3 (sample set and weighting unpublished).
pub const TABLE_6_1: SeparableParams = SeparableParams { strength: [0.78, 0.70, 0.75], falloff: [0.57, 0.13, 0.08] };

/// Thesis Table 6.1: width (world units, the shader's `sssWidth`).
pub const TABLE_6_1_WIDTH: f64 = 0.014;

/// Channel names for error messages and reports.
pub const CHANNELS: [&str; 3] = ["red", "green", "blue"];
