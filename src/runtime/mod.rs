//! The wgpu runtime: consumes `baked/` the way an engine would and renders headless.
//!
//! Rooms by feature: [`aa`] (SMAA, MLAA, edges, modes), [`sss`] (separable, sum of Gaussians, importance-sampled),
//! [`skin`] (the skin renderer's passes and frames), [`transport`] (Monte Carlo on the GPU). Each pass `x.rs` sits
//! beside its WGSL `x.wgsl` and its CPU twin `x_cpu.rs` (rayon, no adapter needed), whose arithmetic mirrors the
//! shader; the tests compare the two on the same inputs. Shared plumbing: [`gpu`] (textures, full-screen
//! pipelines, read-back), `compute_chain`, [`sampler`] (the CPU's sampler emulation), [`device`], [`loader`]
//! (the bake directory). [`chain`] holds the whole-image entry points.
//!
//! Invariants, stated as absences:
//! - only this module imports `wgpu`; the passes never create a device (they take `&wgpu::Device` /
//!   `&wgpu::Queue`); [`device::create_headless`] is the one place that does;
//! - no texture is ever sRGB: data textures are explicit `*Unorm` / float formats, colour images are uploaded as
//!   `Rgba8Unorm` and the shaders decode/encode sRGB themselves where linear blending is wanted;
//! - no pass needs `FLOAT32_FILTERABLE` or an f32 render target (lavapipe and llvmpipe run everything).

pub mod aa;
pub mod backend;
pub mod chain;
pub(crate) mod compute_chain;
pub mod device;
pub mod frame_pool;
pub mod gpu;
pub mod loader;
pub mod resolve_order;
pub mod sampler;
pub mod skin;
pub mod sss;
pub mod transport;

// The flat module paths of the callers (`bin/`, tests, examples), each an alias of its room's module.
pub use aa::{edges as smaa_edges, mlaa, modes as smaa_modes, moving_scene, scene, smaa};
pub use skin::{inputs as skin_inputs, mesh_raster, passes as skin_passes, texture_space};

/// The skin passes under the callers' flat paths, with the function that runs each on a backend.
pub mod bloom {
    pub use super::chain::bloom_for;
    pub use super::skin::bloom::*;
}
/// See [`bloom`].
pub mod mesh_skin_inputs {
    pub use super::chain::hemoglobin_for_gbuffer;
    pub use super::skin::mesh_inputs::*;
}
/// See [`bloom`].
pub mod wrinkle_pass {
    pub use super::chain::wrinkled_normals_for;
    pub use super::skin::wrinkles::*;
}
pub use sss::{gaussian as gaussian_sss, importance as importance_sss, separable as separable_sss};
pub use transport::mc_gpu as transport_gpu;

/// `run demo` under the callers' flat path: the procedural frame and the assets and methods of the shared lighting.
pub mod demo {
    pub use super::skin::demo::*;
    pub use super::skin::lighting::{synthetic_rig, DemoAssets, SssMethod};
}

/// `run skin` under the callers' flat path: the frame, its settings and the heads' shared geometry.
pub mod skin_render {
    pub use super::skin::frame::*;
    pub use super::skin::heads::{row_of_heads, specular_layer};
    pub use super::skin::settings::*;
}

/// The CPU twins under the callers' flat paths, and the sampler emulation they share ([`sampler`]).
pub mod cpu {
    pub use super::aa::{edges_cpu as smaa_edges, mlaa_cpu as mlaa, modes_cpu as smaa_modes, smaa_cpu as smaa};
    pub use super::sampler::*;
    pub use super::skin::{
        bloom_cpu as bloom, inputs_cpu as skin_inputs, mesh_inputs_cpu as mesh_skin_inputs,
        mesh_raster_cpu as mesh_raster, texture_space_cpu as texture_space, wrinkles_cpu as wrinkle_pass,
    };
    pub use super::sss::{
        gaussian_cpu as gaussian_sss, importance_cpu as importance_sss, separable_cpu as separable_sss,
    };
}

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
