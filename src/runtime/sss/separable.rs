//! Separable subsurface scattering on the GPU (Jimenez et al., "Separable Subsurface Scattering", CGF 2015;
//! thesis ch. 6): a horizontal and a vertical pass over a linear HDR irradiance image (`Rgba16Float`, alpha =
//! per-pixel strength, 0 = not skin: passes through) with a linear depth image (`R32Float`), using an N-tap kernel
//! (rgb weight, a offset; centre first) and the published shader's conventions (sssWidth, FOVy,
//! follow-surface). Resources created once in [`SeparableSss::new`]; CPU twin [`crate::runtime::sss::separable_cpu`].

use crate::error::{check_positive, check_range, InvalidInput};
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::RuntimeError;

/// Largest kernel the shader's uniform block holds.
pub const MAX_TAPS: usize = 64;

/// Number of timed passes [`SeparableSss::encode`] records.
pub const SSS_PASSES: u32 = 2;

/// Kernel taps: (r, g, b weight, offset), centre tap first (offset 0), offsets in kernel units.
#[derive(Clone, Debug, PartialEq)]
pub struct SssKernel {
    pub taps: Vec<[f32; 4]>,
}

impl SssKernel {
    pub fn new(taps: Vec<[f32; 4]>) -> Result<Self, InvalidInput> {
        if taps.is_empty() || taps.len() > MAX_TAPS {
            return Err(InvalidInput::new("kernel", format!("must have 1..={MAX_TAPS} taps, got {}", taps.len())));
        }
        if taps.iter().flatten().any(|v| !v.is_finite()) {
            return Err(InvalidInput::new("kernel", "taps must be finite"));
        }
        Ok(Self { taps })
    }
}

/// Shader parameters (defaults of the published demo: sssWidth 0.012, FOVy 20°, follow-surface on).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssParams {
    /// Kernel width in world units (`--sss-width`).
    pub sss_width: f32,
    /// Vertical field of view in degrees (`--fovy`).
    pub fovy_deg: f32,
    /// Attenuate taps across depth discontinuities (`--follow-surface`).
    pub follow_surface: bool,
}

impl Default for SssParams {
    fn default() -> Self {
        Self { sss_width: 0.012, fovy_deg: 20.0, follow_surface: true }
    }
}

impl SssParams {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_positive("sss_width", self.sss_width as f64, "world units")?;
        check_range("fovy_deg", self.fovy_deg, 1.0, 179.0, "degrees")?;
        Ok(())
    }
    /// 1/tan(0.5·FOVy): distance to the projection window.
    pub fn dist_to_window(&self) -> f32 {
        1.0 / (0.5 * self.fovy_deg.to_radians()).tan()
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Params {
    rt: [f32; 4],
    cfg: [f32; 4],
    dir: [f32; 4],
    taps: [[f32; 4]; MAX_TAPS],
}

impl Params {
    /// The uniform block of one pass in direction `dir` (shared with the compute variant).
    pub(crate) fn new(width: u32, height: u32, kernel: &SssKernel, params: &SssParams, dir: [f32; 2]) -> Self {
        let mut taps = [[0.0f32; 4]; MAX_TAPS];
        taps[..kernel.taps.len()].copy_from_slice(&kernel.taps);
        Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            cfg: [
                params.sss_width,
                params.dist_to_window(),
                if params.follow_surface { 1.0 } else { 0.0 },
                kernel.taps.len() as f32,
            ],
            dir: [dir[0], dir[1], 0.0, 0.0],
            taps,
        }
    }
}

const SHADER: &str = include_str!("separable.wgsl");

/// Separable SSS for one frame size and kernel.
pub struct SeparableSss {
    color: wgpu::Texture,
    depth: wgpu::Texture,
    output: wgpu::Texture,
    pipe: wgpu::RenderPipeline,
    groups: [wgpu::BindGroup; 2],
    targets: [wgpu::TextureView; 2],
}

impl SeparableSss {
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        kernel: &SssKernel,
        params: &SssParams,
    ) -> Result<Self, RuntimeError> {
        crate::error::check_size("image", width as u64, height as u64)?;
        crate::runtime::device::check_image_fits(device, width, height, 8)?;
        params.validate()?;
        use wgpu::TextureFormat as F;
        let color = gpu::texture(device, "sss colour", width, height, F::Rgba16Float);
        let tmp = gpu::texture(device, "sss horizontal", width, height, F::Rgba16Float);
        let output = gpu::texture(device, "sss output", width, height, F::Rgba16Float);
        let depth = gpu::data_texture(device, "sss depth", width, height, F::R32Float);
        let module = gpu::shader(device, "separable_sss.wgsl", SHADER);
        let pipe = gpu::fullscreen_pipeline(device, "sss blur", &module, "fs_blur", F::Rgba16Float);
        let lin = gpu::linear_clamp_sampler(device);
        let mk = |dir: [f32; 2]| Params::new(width, height, kernel, params, dir);
        let ubo_h = gpu::uniform_buffer(device, "sss h", bytemuck::bytes_of(&mk([1.0, 0.0])));
        let ubo_v = gpu::uniform_buffer(device, "sss v", bytemuck::bytes_of(&mk([0.0, 1.0])));
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (cv, tv, dv) = (view(&color), view(&tmp), view(&depth));
        let layout = pipe.get_bind_group_layout(0);
        use wgpu::BindingResource as R;
        let groups = [
            gpu::bind_group(
                device,
                "sss h",
                &layout,
                &[
                    (0, ubo_h.as_entire_binding()),
                    (1, R::TextureView(&cv)),
                    (2, R::TextureView(&dv)),
                    (6, R::Sampler(&lin)),
                ],
            ),
            gpu::bind_group(
                device,
                "sss v",
                &layout,
                &[
                    (0, ubo_v.as_entire_binding()),
                    (1, R::TextureView(&tv)),
                    (2, R::TextureView(&dv)),
                    (6, R::Sampler(&lin)),
                ],
            ),
        ];
        let targets = [tv, view(&output)];
        Ok(Self { color, depth, output, pipe, groups, targets })
    }

    /// The irradiance input (`Rgba16Float`, linear, alpha = strength); other passes may render into it.
    pub fn input(&self) -> &wgpu::Texture {
        &self.color
    }
    /// The blurred result (`Rgba16Float`).
    pub fn output(&self) -> &wgpu::Texture {
        &self.output
    }

    /// Uploads a frame: `color` RGBA f32 (linear; alpha = strength), `depth` linear depth, both top row first.
    pub fn upload(&self, queue: &wgpu::Queue, color: &[f32], depth: &[f32]) -> Result<(), InvalidInput> {
        gpu::upload_sss_frame(queue, (&self.color, &self.depth), color, depth)
    }

    /// Records the horizontal and vertical passes.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        for k in 0..2 {
            let slot = timer.map(|(t, first)| (t, first + k as u32));
            gpu::draw_fullscreen(enc, "sss", &self.pipe, &self.groups[k], &self.targets[k], slot);
        }
    }

    /// Uploads, runs both passes and reads back RGBA f32.
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
        queue.submit([enc.finish()]);
        let bytes = gpu::read_texture(device, queue, &self.output)?;
        let half: &[half::f16] = bytemuck::cast_slice(&bytes);
        Ok(half.iter().map(|v| v.to_f32()).collect())
    }
}
