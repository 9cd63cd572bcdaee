//! Morphological antialiasing (thesis ch. 9–10): each pass beside its WGSL and its CPU twin.
//!
//! - [`smaa`] (`smaa.wgsl`, [`smaa_cpu`]): SMAA 1x, Jimenez et al., Eurographics 2012;
//! - [`mlaa`] (`mlaa.wgsl`, [`mlaa_cpu`]): Jimenez's MLAA, GPU Pro 2, 2011 (Listings 9.1–9.5);
//! - [`edges`] (`edges.wgsl`, [`edges_cpu`]): the colour/depth edge detectors, predication and masks both share;
//! - [`modes`] (`modes.wgsl`, [`modes_cpu`]): SMAA S2x/T2x/4x over [`smaa::Smaa::with_subsample`];
//! - [`three_pass`]: the textures and the three passes SMAA and MLAA share, in either shape (compute or fragment);
//! - [`scene`], [`moving_scene`]: procedural test scenes with supersampled ground truth (CPU only).

pub mod edges;
pub mod edges_cpu;
pub mod mlaa;
pub mod mlaa_cpu;
pub mod modes;
pub mod modes_cpu;
pub mod moving_scene;
pub mod pass_shape;
pub mod scene;
pub mod smaa;
pub mod smaa_cpu;
pub mod three_pass;
