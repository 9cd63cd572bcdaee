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
use crate::runtime::aa::edges::{EdgeSettings, EdgeStage};
use crate::runtime::aa::three_pass::ThreePass;
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

const SHADER: &str = concat!(
    include_str!("../fullscreen.wgsl"),
    include_str!("srgb.wgsl"),
    include_str!("morphological.wgsl"),
    include_str!("mlaa.wgsl")
);

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
        gpu::check_frame(device, width, height, 4)?;
        use wgpu::TextureFormat as F;
        let color = gpu::texture(device, "mlaa colour", width, height, F::Rgba8Unorm);
        let edges = gpu::texture(device, "mlaa edges", width, height, F::Rg8Unorm);
        let weights = gpu::texture(device, "mlaa weights", width, height, F::Rgba8Unorm);
        let output = gpu::texture(device, "mlaa output", width, height, F::Rgba8Unorm);
        let area = gpu::texture(device, "mlaa area", 5 * map.n, 5 * map.n, F::Rg8Unorm);
        gpu::upload(queue, &area, &map.bytes);
        let params = Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            cfg: [map.n as f32, map.search_steps() as f32, MLAA_THRESHOLD, 0.0],
        };
        let ubo = gpu::uniform_buffer(device, "mlaa params", bytemuck::bytes_of(&params));
        let module = gpu::shader(device, "mlaa.wgsl", SHADER);
        let pipes = [
            gpu::fullscreen_pipeline(device, "mlaa edges", &module, "fs_edges", F::Rg8Unorm),
            gpu::fullscreen_pipeline(device, "mlaa weights", &module, "fs_weights", F::Rgba8Unorm),
            gpu::fullscreen_pipeline(device, "mlaa blend", &module, "fs_blend", F::Rgba8Unorm),
        ];
        let lin = gpu::linear_clamp_sampler(device);
        let pnt = gpu::nearest_clamp_sampler(device);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (cv, ev, wv, av) = (view(&color), view(&edges), view(&weights), view(&area));
        use wgpu::BindingResource as R;
        let groups = [
            gpu::bind_group(
                device,
                "mlaa edges",
                &pipes[0].get_bind_group_layout(0),
                &[(0, ubo.as_entire_binding()), (1, R::TextureView(&cv))],
            ),
            gpu::bind_group(
                device,
                "mlaa weights",
                &pipes[1].get_bind_group_layout(0),
                &[
                    (0, ubo.as_entire_binding()),
                    (2, R::TextureView(&ev)),
                    (3, R::TextureView(&av)),
                    (6, R::Sampler(&lin)),
                    (7, R::Sampler(&pnt)),
                ],
            ),
            gpu::bind_group(
                device,
                "mlaa blend",
                &pipes[2].get_bind_group_layout(0),
                &[(0, ubo.as_entire_binding()), (1, R::TextureView(&cv)), (5, R::TextureView(&wv))],
            ),
        ];
        let ov = view(&output);
        let extra = EdgeStage::new(device, (width, height), (&cv, &ov), &options.edges, 0.0, options.masked)?;
        let views = [ev, wv, ov];
        let labels = ["mlaa edges", "mlaa weights", "mlaa blend"];
        let name = "mlaa";
        Ok(Self(ThreePass { width, height, color, edges, weights, output, views, pipes, groups, extra, labels, name }))
    }
}
