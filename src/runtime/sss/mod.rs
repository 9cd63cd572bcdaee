//! Screen-space subsurface scattering: each pass beside its WGSL and its CPU twin.
//!
//! - [`separable`] (`separable.wgsl`, [`separable_cpu`]): separable SSS, Jimenez et al., CGF 2015 (thesis ch. 6);
//!   [`separable_tiled`] (`separable_tiled.wgsl`) is the same pass as compute over workgroup-memory line tiles;
//! - [`gaussian`] (`gaussian.wgsl`, [`gaussian_cpu`]): the screen-space sum of Gaussians, TAP 2009 (thesis ch. 4);
//!   [`gaussian_tiled`] (`gaussian_tiled.wgsl`) is the same chain as compute over workgroup-memory line tiles;
//! - [`importance`] (`importance.wgsl`, [`importance_cpu`]): one pass over an importance-sampled disk kernel
//!   (fragment or compute, the same per-pixel function).
//!
//! A [`PassShape`] picks the form of each pass: compute (the default on GPUs) or the full-screen fragment passes they
//! replace ([`SHAPE_ENV`] `RTBAKE_SSS_PASSES=fragment`, so one benchmark binary measures both).
//!
//! Texture-space diffusion renders whole heads and lives with the skin frame ([`super::skin::texture_space`]).
//!
//! Shared by the four: [`SssPass`] (the input frame, the output and upload / encode / run; each module's `new`
//! builds its blur), the camera scale [`dist_to_window`], the blur bind group and frame checks of `SssInputs`, the
//! WGSL preludes `frame.wgsl` (depth binding, sampler, depth fetches), `separable_params.wgsl` (the uniform block
//! of both separable forms) and `gaussian_params.wgsl` (the uniform block and stretch of both Gaussian forms), `line_tile.wgsl` (the
//! workgroup line tile of both tiled forms), and `blur_cpu` (the frame loop and tap of the one-kernel CPU twins).

mod blur_cpu;
pub mod gaussian;
pub mod gaussian_cpu;
pub mod gaussian_tiled;
pub mod importance;
pub mod importance_cpu;
pub mod separable;
pub mod separable_cpu;
pub mod separable_tiled;

use crate::error::{check_range, InvalidInput};
use crate::runtime::frame_pool;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::RuntimeError;

/// The camera's part in every screen-space kernel's scale: 1/tan(FOVy/2), the distance to the projection window of a
/// pinhole camera with vertical field of view `fovy_deg`. A length L (world units) at linear depth z covers
/// L·(H/2)·(1/tan(FOVy/2))/z pixels of an H-pixel-tall image, in x and y alike (square pixels): the separable pass
/// steps `sssWidth · dist_to_window / z` in normalised height units, the importance pass scales its mm offsets by
/// `(H/2) · dist_to_window / (z · mm_per_world_unit)`.
pub fn dist_to_window(fovy_deg: f32) -> f32 {
    1.0 / (0.5 * fovy_deg.to_radians()).tan()
}

/// The form of a screen-space SSS pass on the GPU, the one type of the AA passes: [`PassShape::Compute`] (the
/// separable and Gaussian blurs over workgroup-memory line tiles, the importance-sampled gather over 8×8-thread
/// workgroups) or [`PassShape::Fragment`] (the full-screen fragment passes they replace); the same arithmetic and the
/// same CPU twin either way. On an NVIDIA H100/H200 a fragment pass reaches only the TPCs its graphics pipeline
/// spans, a compute pass every SM.
pub use crate::runtime::aa::three_pass::PassShape;

/// The environment variable that picks the SSS passes' [`PassShape`] (`compute` or `fragment`).
pub const SHAPE_ENV: &str = "RTBAKE_SSS_PASSES";

/// The SSS passes' shape: [`SHAPE_ENV`] when set (anything but `compute` or `fragment` is refused naming it), else
/// `default`.
pub fn shape_from_env(default: PassShape) -> Result<PassShape, InvalidInput> {
    match std::env::var(SHAPE_ENV) {
        Ok(v) => PassShape::parse(&v)
            .map_err(|_| InvalidInput::new(SHAPE_ENV, format!("must be compute or fragment, got {v:?}"))),
        Err(_) => Ok(default),
    }
}

/// The shape for an adapter: [`SHAPE_ENV`] when set, else the fragment passes on a software rasteriser (where
/// workgroup barriers are emulated and the tiles are slower; same arithmetic, same twin), compute on a GPU.
pub fn shape_for_adapter(software: bool) -> Result<PassShape, InvalidInput> {
    shape_from_env(if software { PassShape::Fragment } else { PassShape::Compute })
}

/// The vertical field of view every pass accepts: 1° to 179°.
pub(crate) fn check_fovy(fovy_deg: f32) -> Result<(), InvalidInput> {
    check_range("fovy_deg", fovy_deg, 1.0, 179.0, "degrees").map(drop)
}

/// The frame every screen-space SSS pass reads: the irradiance (`Rgba16Float`, linear, alpha = per-pixel strength,
/// 0 = not skin) and the linear depth (`R32Float`, loaded, never filtered). Public only as the frame a
/// [`separable::SeparableForm`] builds on; its textures and methods are the passes' own.
pub struct SssInputs {
    pub(crate) color: wgpu::Texture,
    pub(crate) depth: wgpu::Texture,
}

impl SssInputs {
    /// Checks the frame size and that a frame of 8 bytes per texel fits the device: before any other check or work.
    pub(crate) fn check_size(device: &wgpu::Device, width: u32, height: u32) -> Result<(), RuntimeError> {
        gpu::check_frame(device, width, height, 8)
    }

    /// Creates the two textures, labelled `"{label} colour"` and `"{label} depth"`.
    pub(crate) fn new(device: &wgpu::Device, label: &str, width: u32, height: u32) -> Self {
        use wgpu::TextureFormat as F;
        let color = frame_pool::target(device, &format!("{label} colour"), width, height, F::Rgba16Float);
        let depth = frame_pool::data_target(device, &format!("{label} depth"), width, height, F::R32Float);
        Self { color, depth }
    }

    /// The intermediate (`"{label} horizontal"`) and output (`"{label} output"`) `Rgba16Float` textures of a
    /// two-pass blur, made by `make` (a render target or a storage texture).
    pub(crate) fn targets(
        device: &wgpu::Device,
        label: &str,
        (width, height): (u32, u32),
        make: fn(&wgpu::Device, &str, u32, u32, wgpu::TextureFormat) -> wgpu::Texture,
    ) -> [wgpu::Texture; 2] {
        let mk = |name| make(device, &format!("{label} {name}"), width, height, wgpu::TextureFormat::Rgba16Float);
        [mk("horizontal"), mk("output")]
    }

    /// Uploads a frame: `color` RGBA f32 (linear; alpha = strength), `depth` linear depth, both top row first.
    pub(crate) fn upload(&self, queue: &wgpu::Queue, color: &[f32], depth: &[f32]) -> Result<(), InvalidInput> {
        gpu::upload_sss_frame(queue, (&self.color, &self.depth), color, depth)
    }

    /// The bind group of a fragment pass that blurs `src`: uniforms at binding 0, `src` at 1, this frame's depth at
    /// 2, the linear clamp sampler at 6, and `extra` texture views at their bindings.
    pub(crate) fn blur_group(
        &self,
        device: &wgpu::Device,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        (ubo, src): (&wgpu::Buffer, &wgpu::TextureView),
        extra: &[(u32, &wgpu::TextureView)],
    ) -> wgpu::BindGroup {
        use wgpu::BindingResource as R;
        let lin = gpu::linear_clamp_sampler(device);
        let dv = self.depth.create_view(&Default::default());
        let mut entries = vec![(0, ubo.as_entire_binding()), (1, R::TextureView(src)), (2, R::TextureView(&dv))];
        entries.extend(extra.iter().map(|&(b, v)| (b, R::TextureView(v))));
        entries.push((6, R::Sampler(&lin)));
        gpu::bind_group(device, label, layout, &entries)
    }
}

/// What a screen-space SSS pass records into a command encoder: its passes over [`SssPass`]'s frame.
pub trait SssBlur {
    /// Records the passes; the k-th (0-based) uses timer slot `first + k`.
    fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>);
}

/// A screen-space SSS pass for one frame size: its input frame (irradiance and linear depth), its output
/// (`Rgba16Float`) and the blur `B` that reads the one and writes the other ([`separable::SeparableSss`],
/// [`gaussian::GaussianSss`], [`importance::ImportanceSss`], [`separable_tiled::SeparableSssTiled`]). Created by
/// each blur's `new` (one for both separable forms, [`separable::SeparableForm`]).
pub struct SssPass<B> {
    inputs: SssInputs,
    output: wgpu::Texture,
    blur: B,
}

impl<B: SssBlur> SssPass<B> {
    /// The irradiance input (`Rgba16Float`, linear, alpha = strength); other passes may render into it.
    pub fn input(&self) -> &wgpu::Texture {
        &self.inputs.color
    }
    /// The blurred result (`Rgba16Float`).
    pub fn output(&self) -> &wgpu::Texture {
        &self.output
    }

    /// Uploads a frame: `color` RGBA f32 (linear; alpha = strength), `depth` linear depth, both top row first.
    pub fn upload(&self, queue: &wgpu::Queue, color: &[f32], depth: &[f32]) -> Result<(), InvalidInput> {
        self.inputs.upload(queue, color, depth)
    }

    /// The linear depth the pass reads (`R32Float`): a frame that computes it on the device copies it there.
    pub(crate) fn depth(&self) -> &wgpu::Texture {
        &self.inputs.depth
    }

    /// Uploads the linear depth alone (top row first): the irradiance comes from an earlier pass of the same
    /// command encoder, copied into [`SssPass::input`].
    pub fn upload_depth(&self, queue: &wgpu::Queue, depth: &[f32]) -> Result<(), InvalidInput> {
        let d = &self.inputs.depth;
        if depth.len() != d.width() as usize * d.height() as usize {
            return Err(InvalidInput::new("depth", format!("must be {}x{} values", d.width(), d.height())));
        }
        gpu::upload(queue, d, bytemuck::cast_slice(depth));
        Ok(())
    }

    /// Records the blur's passes; the k-th (0-based) uses timer slot `first + k`.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        self.blur.encode(enc, timer)
    }

    /// Uploads a frame, runs the blur and reads back RGBA f32.
    pub fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        color: &[f32],
        depth: &[f32],
    ) -> Result<Vec<f32>, RuntimeError> {
        self.upload(queue, color, depth)?;
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("sss") });
        self.encode(&mut enc, None);
        // One submission: the read-back's copy joins the blur's encoder.
        Ok(gpu::f16_to_f32(&gpu::read_textures(device, queue, enc, &[&self.output])?[0]))
    }
}
