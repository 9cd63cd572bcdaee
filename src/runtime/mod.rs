//! The wgpu runtime: consumes `baked/` the way an engine would and renders headless.
//!
//! Every pass has a CPU reference implementation of the same algorithm in [`cpu`] (rayon, no adapter needed)
//! whose arithmetic mirrors the WGSL shaders; the tests compare the two on the same inputs.
//!
//! Invariants, stated as absences:
//! - only this module imports `wgpu`; the passes never create a device (they take `&wgpu::Device` /
//!   `&wgpu::Queue`); [`device::create_headless`] is the one place that does;
//! - no texture is ever sRGB: data textures are explicit `*Unorm` / float formats, colour images are uploaded as
//!   `Rgba8Unorm` and the shaders decode/encode sRGB themselves where linear blending is wanted;
//! - no pass needs `FLOAT32_FILTERABLE` or an f32 render target (lavapipe and llvmpipe run everything).

pub mod bloom;
pub mod chain;
pub(crate) mod compute_chain;
pub mod cpu;
pub mod demo;
pub mod device;
pub mod gaussian_sss;
pub mod gpu;
pub mod importance_sss;
pub mod loader;
pub mod mesh_raster;
pub mod mesh_skin_inputs;
pub mod mlaa;
pub mod moving_scene;
pub mod scene;
pub mod separable_sss;
pub mod skin_inputs;
pub mod skin_passes;
pub mod skin_render;
pub mod smaa;
pub mod smaa_edges;
pub mod smaa_modes;
pub mod texture_space;
pub mod transport_gpu;
pub mod wrinkle_pass;

/// Errors of the runtime.
#[derive(Debug, thiserror::Error)]
pub enum RuntimeError {
    #[error("no usable GPU adapter: {0}")]
    NoAdapter(String),
    #[error("GPU error: {0}")]
    Gpu(String),
    #[error("{0}")]
    Lut(#[from] loader::LutError),
    /// Bad input; kept as the error's source so the command maps it to exit code 2.
    #[error("{0}")]
    Invalid(#[from] crate::error::InvalidInput),
}
