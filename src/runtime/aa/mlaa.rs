//! Jimenez's MLAA on the GPU (Jimenez, Masia, Echevarria, Navarro, Gutierrez, "Practical Morphological
//! Antialiasing", GPU Pro 2, 2011; thesis ch. 9, Listings 9.1–9.5): three passes — luma edge detection, blending
//! weights (distance search with two edgels per bilinear fetch, crossing edges at ±0.25, point-sampled area map of
//! maximum distance N), 4-neighbourhood blending. Search steps = (N − 1)/2 so the longest line fits the map.
//!
//! Textures: colour `Rgba8Unorm` (sRGB-encoded values), edges `Rg8Unorm`, weights `Rgba8Unorm`, area map
//! `Rg8Unorm` 5N×5N, output `Rgba8Unorm`. Created once in [`Mlaa::new`]; CPU twin [`crate::runtime::aa::mlaa_cpu`].
//! Listing 9.1's depth edges (its main variant), colour edges, predication and a matte/stencil mask:
//! [`Mlaa::with_options`] ([`crate::runtime::aa::edges`]).

use crate::aa::mlaa_area::MlaaVersion;
use crate::error::InvalidInput;
use crate::runtime::aa::edges::EdgeSettings;
use crate::runtime::aa::three_pass::{PassShape, PassSpec, ThreePass, COMPUTE_WGSL};
use crate::runtime::gpu;
use crate::runtime::RuntimeError;

/// Luma edge threshold of the MLAA listings.
pub const MLAA_THRESHOLD: f32 = 0.1;

/// Maximum distance N the runtime uses unless told otherwise (a map the default bake holds).
pub const DEFAULT_MAX_DISTANCE: u32 = 33;

/// Number of timed passes [`ThreePass::encode`] records.
pub const MLAA_PASSES: u32 = 3;

/// A Jimenez MLAA v1.4 area map: 5N×5N RG8 bytes (top row first) for maximum distance N, validated by
/// [`crate::aa::mlaa_area::validate`] (the one MLAA range).
#[derive(Clone, Debug, PartialEq)]
pub struct MlaaAreaMap {
    pub n: u32,
    pub bytes: Vec<u8>,
}

impl MlaaAreaMap {
    pub fn new(n: u32, bytes: Vec<u8>) -> Result<Self, InvalidInput> {
        crate::aa::mlaa_area::validate(MlaaVersion::V1_4, n)?;
        let want = (5 * n * 5 * n * 2) as usize;
        if bytes.len() != want {
            return Err(InvalidInput::new(
                "MLAA area map",
                format!("must be {0}x{0} RG8 ({want} bytes) for N = {n}, got {1} bytes", 5 * n, bytes.len()),
            ));
        }
        Ok(Self { n, bytes })
    }

    /// Search steps per direction: (N − 1)/2 (two pixels per step).
    pub fn search_steps(&self) -> u32 {
        (self.n - 1) / 2
    }
}

/// What [`Mlaa::with_options`] can set: the edge detector (Listing 9.1's depth variant, colour, predicated
/// thresholding; [`crate::runtime::aa::edges`], no local contrast adaptation) and the matte/stencil mask.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct MlaaOptions {
    pub edges: EdgeSettings,
    pub masked: bool,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    cfg: [f32; 4],
}

/// The MLAA shader: the full-screen triangle, the shared AA fetches, `mlaa.wgsl` and the compute entry points.
static SHADER: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    concat!(
        include_str!("../fullscreen.wgsl"),
        include_str!("srgb.wgsl"),
        include_str!("morphological.wgsl"),
        include_str!("mlaa.wgsl")
    )
    .to_owned()
        + COMPUTE_WGSL
});

/// MLAA for one frame size and area map. Create once, run per frame.
pub struct Mlaa(ThreePass);

impl std::ops::Deref for Mlaa {
    type Target = ThreePass;
    fn deref(&self) -> &ThreePass {
        &self.0
    }
}

impl Mlaa {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        map: &MlaaAreaMap,
    ) -> Result<Self, RuntimeError> {
        Self::with_options(device, queue, width, height, map, &MlaaOptions::default())
    }

    /// As [`Self::new`] with an edge detector and mask; depth and mask come through [`ThreePass::run_with`].
    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        map: &MlaaAreaMap,
        options: &MlaaOptions,
    ) -> Result<Self, RuntimeError> {
        Self::with_shape(device, queue, (width, height), map, options, PassShape::from_env()?)
    }

    /// As [`Self::with_options`] in the given [`PassShape`] (the benchmarks build both; same output bytes).
    pub fn with_shape(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        map: &MlaaAreaMap,
        options: &MlaaOptions,
        shape: PassShape,
    ) -> Result<Self, RuntimeError> {
        gpu::check_frame(device, width, height, 4)?;
        let area = gpu::texture(device, "mlaa area", 5 * map.n, 5 * map.n, wgpu::TextureFormat::Rg8Unorm);
        gpu::upload(queue, &area, &map.bytes);
        let params = Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            cfg: [map.n as f32, map.search_steps() as f32, MLAA_THRESHOLD, 0.0],
        };
        let ubo = gpu::uniform_buffer(device, "mlaa params", bytemuck::bytes_of(&params));
        let (lin, pnt) = (gpu::linear_clamp_sampler(device), gpu::nearest_clamp_sampler(device));
        let av = area.create_view(&Default::default());
        use wgpu::BindingResource as R;
        let weight_luts = vec![(3, R::TextureView(&av)), (6, R::Sampler(&lin)), (7, R::Sampler(&pnt))];
        let spec = PassSpec { name: "mlaa", source: ("mlaa.wgsl", &SHADER), ubo: &ubo, weight_luts };
        let edges = (&options.edges, 0.0, options.masked);
        Ok(Self(ThreePass::build(device, (width, height), spec, shape, edges)?))
    }
}
