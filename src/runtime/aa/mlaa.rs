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
use crate::runtime::aa::edges::{AaInputs, EdgeSettings, EdgeStage};
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::RuntimeError;

/// Luma edge threshold of the MLAA listings.
pub const MLAA_THRESHOLD: f32 = 0.1;

/// Maximum distance N the runtime uses unless told otherwise (a map the default bake holds).
pub const DEFAULT_MAX_DISTANCE: u32 = 33;

/// Number of timed passes [`Mlaa::encode`] records.
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

const SHADER: &str = include_str!("mlaa.wgsl");

/// MLAA for one frame size and area map. Create once, run per frame.
pub struct Mlaa {
    width: u32,
    height: u32,
    color: wgpu::Texture,
    edges: wgpu::Texture,
    weights: wgpu::Texture,
    output: wgpu::Texture,
    views: [wgpu::TextureView; 3],
    pipes: [wgpu::RenderPipeline; 3],
    groups: [wgpu::BindGroup; 3],
    extra: EdgeStage,
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

    /// As [`Self::new`] with an edge detector and mask; depth and mask come through [`Self::run_with`].
    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        map: &MlaaAreaMap,
        options: &MlaaOptions,
    ) -> Result<Self, RuntimeError> {
        crate::error::check_size("image", width as u64, height as u64)?;
        crate::runtime::device::check_image_fits(device, width, height, 4)?;
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
        Ok(Self { width, height, color, edges, weights, output, views, pipes, groups, extra })
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
    pub fn input(&self) -> &wgpu::Texture {
        &self.color
    }
    /// The antialiased output (masked when the options say so).
    pub fn output(&self) -> &wgpu::Texture {
        self.extra.masked_output().unwrap_or(&self.output)
    }
    pub fn edges(&self) -> &wgpu::Texture {
        &self.edges
    }
    pub fn weights(&self) -> &wgpu::Texture {
        &self.weights
    }

    /// Uploads one frame (`width·height·4` bytes, RGBA8, sRGB-encoded, top row first).
    pub fn upload(&self, queue: &wgpu::Queue, rgba: &[u8]) -> Result<(), InvalidInput> {
        let want = self.width as usize * self.height as usize * 4;
        if rgba.len() != want {
            return Err(InvalidInput::new("image", format!("must hold {want} RGBA8 bytes, got {}", rgba.len())));
        }
        gpu::upload(queue, &self.color, rgba);
        Ok(())
    }

    /// Records the three passes; `timer` slots `first..first+3` receive their timestamps.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        for (k, label) in ["mlaa edges", "mlaa weights", "mlaa blend"].iter().enumerate() {
            let slot = timer.map(|(t, first)| (t, first + k as u32));
            if k == 0 && self.extra.encode_edges(enc, &self.views[0], slot) {
                continue;
            }
            gpu::draw_fullscreen(enc, label, &self.pipes[k], &self.groups[k], &self.views[k], slot);
        }
        self.extra.encode_mask(enc);
    }

    /// Validates and uploads the depth and mask the options read (named `--depth`/`--mask`).
    pub fn upload_inputs(&self, queue: &wgpu::Queue, inputs: &AaInputs) -> Result<(), InvalidInput> {
        self.extra.upload(queue, inputs)
    }

    /// Uploads `rgba`, runs the three passes and reads the result back.
    pub fn run(&self, device: &wgpu::Device, queue: &wgpu::Queue, rgba: &[u8]) -> Result<Vec<u8>, RuntimeError> {
        self.run_with(device, queue, rgba, &AaInputs::default())
    }

    /// As [`Self::run`] with the depth and mask the options read.
    pub fn run_with(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        rgba: &[u8],
        inputs: &AaInputs,
    ) -> Result<Vec<u8>, RuntimeError> {
        self.upload(queue, rgba)?;
        self.upload_inputs(queue, inputs)?;
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("mlaa") });
        self.encode(&mut enc, None);
        queue.submit([enc.finish()]);
        gpu::read_texture(device, queue, self.output())
    }
}
