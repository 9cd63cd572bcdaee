//! Importance-sampled screen-space SSS kernels: the disk sampling Unity HDRP's diffusion profiles use,
//! for any [`crate::diffusion::RadialProfile`] (Golubev, "Efficient Screen-Space Subsurface Scattering Using
//! Burley's Normalized Diffusion in Real-Time", SIGGRAPH 2018 course "Advances in Real-Time Rendering").
//!
//! - [`disk`]: N samples at the stratified quantiles of the widest channel's radial CDF, golden-angle spiral,
//!   reciprocal-pdf weights normalised per channel, the 0.999 cut-off radius;
//! - [`cdf`]: the tabulated radial CDF and its monotone inverse (profiles without Burley's closed form);
//! - [`compare`]: importance vs separable vs sum-of-Gaussians kernels at equal fetch budgets on a lit half-plane,
//!   against the exact convolution.
//!
//! Pure computation: no files, no GPU (the pass is `crate::runtime::importance_sss`, the files
//! `crate::bake::importance`).

pub mod cdf;
pub mod compare;
pub mod disk;
pub mod jittered;

pub use disk::{ImportanceKernel, SampledProfile};
