//! Screen-space subsurface scattering: each pass beside its WGSL and its CPU twin.
//!
//! - [`separable`] (`separable.wgsl`, [`separable_cpu`]): separable SSS, Jimenez et al., CGF 2015 (thesis ch. 6);
//!   [`separable_tiled`] (`separable_tiled.wgsl`) is the same pass as compute over workgroup-memory line tiles;
//! - [`gaussian`] (`gaussian.wgsl`, [`gaussian_cpu`]): the screen-space sum of Gaussians, TAP 2009 (thesis ch. 4);
//! - [`importance`] (`importance.wgsl`, [`importance_cpu`]): one pass over an importance-sampled disk kernel.
//!
//! Texture-space diffusion renders whole heads and lives with the skin frame ([`super::skin::texture_space`]).

pub mod gaussian;
pub mod gaussian_cpu;
pub mod importance;
pub mod importance_cpu;
pub mod separable;
pub mod separable_cpu;
pub mod separable_tiled;
