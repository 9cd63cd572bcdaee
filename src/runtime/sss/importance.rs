//! Importance-sampled screen-space SSS on the GPU: one full-screen pass over an N-sample disk kernel
//! ([`crate::sss_sampling::disk`]; the sampling of Unity HDRP's diffusion profiles, Golubev 2018) on a linear HDR
//! irradiance image (`Rgba16Float`, alpha = per-pixel strength, 0 = not skin: passes through) with a linear depth
//! image (`R32Float`). Resources created once in [`ImportanceSss::new`]; CPU twin
//! [`crate::runtime::sss::importance_cpu`]. A fragment pass or a compute pass ([`PassShape`]), both calling the
//! shader's one per-pixel function through the same sampler: the same bytes. Not tiled: the samples spread over a
//! disk out to the kernel's widest sample at the pixel's depth (TAP's SS Jittered: 13 taps out to red's wide
//! ring; a Burley kernel: out to its 0.999 radius), in every direction, so a 2-D workgroup tile would load an apron
//! many times its own area for each pixel's 13–1024 scattered fetches; the texture cache serves them instead. Bytes per pixel, each texel once: colour 8 and depth 4 in, 8 out.
//!
//! **Scale.** Depth is in world units; a world unit is `mm_per_world_unit` mm (default 125, the separable fit's
//! scale: a head 1 unit tall). A pinhole camera with vertical field of view FOVy maps a length L (world units) at
//! linear depth z to L·(H/2)·(1/tan(FOVy/2))/z pixels on an H-pixel-tall image, in x and y alike (square pixels).
//! So sample i lands at `pixel + (xᵢ, yᵢ)mm · strength · (H/2)·(1/tan(FOVy/2)) / (z · mm_per_world_unit)`, with the
//! strength (alpha) scaling the radius as the separable pass scales its step.
//!
//! **Depth.** Like the separable pass's follow-surface (not Unity's 3-D distance, which needs the profile itself
//! in the shader): a sample whose depth differs from the centre's by Δz is replaced by the centre colour in the
//! proportion s = saturate(|Δz|·mm_per_world_unit / cutoff_mm), cutoff_mm the kernel's 0.999 radius: a surface
//! farther away than the kernel reaches contributes nothing. Depth is fetched bilinearly (four loads: R32Float is
//! not filterable without `FLOAT32_FILTERABLE`).
//!
//! **Samples** live in the uniform block (≤ [`MAX_SAMPLES`] = 1024, 32 KiB): per sample (x mm, y mm, r mm, 0) and
//! the normalised (w_r, w_g, w_b, 0).

use crate::error::{check_positive, InvalidInput};
use crate::runtime::frame_pool;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::sss::{shape_from_env, PassShape, SssBlur, SssInputs, SssPass};
use crate::runtime::RuntimeError;
use crate::sss_sampling::ImportanceKernel;

/// Largest sample count the shader's uniform block holds.
pub const MAX_SAMPLES: usize = crate::sss_sampling::disk::MAX_SAMPLES;

/// The disk samples as the pass uploads them (f32).
#[derive(Clone, Debug, PartialEq)]
pub struct ImportanceSamples {
    /// Per sample: (x mm, y mm, r mm, 0).
    pub offsets_mm: Vec<[f32; 4]>,
    /// Per sample: normalised (w_r, w_g, w_b, 0); each channel sums to 1.
    pub weights: Vec<[f32; 4]>,
    /// The kernel's cut-off radius (F⁻¹(0.999) of the sampled channel), mm.
    pub cutoff_mm: f32,
}

impl ImportanceSamples {
    /// From a library kernel.
    pub fn from_kernel(k: &ImportanceKernel) -> Self {
        let offsets_mm = k
            .samples
            .iter()
            .map(|s| {
                let [x, y] = s.offset_mm();
                [x as f32, y as f32, s.r_mm as f32, 0.0]
            })
            .collect();
        let weights =
            k.samples.iter().map(|s| [s.weight[0] as f32, s.weight[1] as f32, s.weight[2] as f32, 0.0]).collect();
        Self { offsets_mm, weights, cutoff_mm: k.cutoff_mm as f32 }
    }

    /// Validates the count (1..=1024), finiteness and the cut-off (> 0).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let n = self.offsets_mm.len();
        if n == 0 || n > MAX_SAMPLES || self.weights.len() != n {
            return Err(InvalidInput::new(
                "samples",
                format!("must be 1..={MAX_SAMPLES} offsets with as many weights, got {n} and {}", self.weights.len()),
            ));
        }
        if self.offsets_mm.iter().chain(&self.weights).flatten().any(|v| !v.is_finite()) {
            return Err(InvalidInput::new("samples", "offsets and weights must be finite"));
        }
        check_positive("cutoff_mm", self.cutoff_mm as f64, "mm")?;
        Ok(())
    }
}

/// Shader parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImportanceSssParams {
    /// mm per world unit of the depth (`--mm-per-world-unit`, default 125).
    pub mm_per_world_unit: f32,
    /// Vertical field of view in degrees (`--fovy`).
    pub fovy_deg: f32,
    /// Attenuate samples across depth differences (`--follow-surface`).
    pub follow_surface: bool,
}

impl Default for ImportanceSssParams {
    fn default() -> Self {
        Self { mm_per_world_unit: 125.0, fovy_deg: 20.0, follow_surface: true }
    }
}

impl ImportanceSssParams {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_positive("mm_per_world_unit", self.mm_per_world_unit as f64, "mm")?;
        super::check_fovy(self.fovy_deg)
    }
    /// 1/tan(0.5·FOVy): distance to the projection window ([`super::dist_to_window`]).
    pub fn dist_to_window(&self) -> f32 {
        super::dist_to_window(self.fovy_deg)
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    cfg: [f32; 4],
    samples: [[f32; 4]; 2 * MAX_SAMPLES],
}

const SHADER: &str =
    concat!(include_str!("../fullscreen.wgsl"), include_str!("frame.wgsl"), include_str!("importance.wgsl"));

/// Importance-sampled SSS for one frame size and kernel.
pub type ImportanceSss = SssPass<ImportanceBlur>;

/// The one pass of [`ImportanceSss`], in either [`PassShape`] (the same per-pixel function, the same bytes).
pub enum ImportanceBlur {
    /// A full-screen fragment pass into the output (a render target).
    Fragment { pipe: wgpu::RenderPipeline, group: wgpu::BindGroup, target: wgpu::TextureView },
    /// A compute pass over 8×8-pixel workgroups into the output (a storage texture).
    Compute { pipe: wgpu::ComputePipeline, group: wgpu::BindGroup, groups: [u32; 2] },
}

/// Pixels per workgroup side of the compute shape (`cs_blur`'s `@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;

impl ImportanceSss {
    /// The pass in the shape [`shape_from_env`] names (compute unless `RTBAKE_SSS_PASSES=fragment`).
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        samples: &ImportanceSamples,
        params: &ImportanceSssParams,
    ) -> Result<Self, RuntimeError> {
        Self::with_shape(device, (width, height), samples, params, shape_from_env(PassShape::Compute)?)
    }

    /// As [`Self::new`] in the given shape (the benchmarks build both; the same output bytes).
    pub fn with_shape(
        device: &wgpu::Device,
        (width, height): (u32, u32),
        samples: &ImportanceSamples,
        params: &ImportanceSssParams,
        shape: PassShape,
    ) -> Result<Self, RuntimeError> {
        SssInputs::check_size(device, width, height)?;
        params.validate()?;
        samples.validate()?;
        use wgpu::TextureFormat as F;
        let inputs = SssInputs::new(device, "isss", width, height);
        let module = gpu::shader(device, "importance_sss.wgsl", SHADER);
        let mut p: Params = bytemuck::Zeroable::zeroed();
        let n = samples.offsets_mm.len();
        for i in 0..n {
            p.samples[2 * i] = samples.offsets_mm[i];
            p.samples[2 * i + 1] = samples.weights[i];
        }
        p.rt = [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32];
        p.cfg = [
            0.5 * height as f32 * params.dist_to_window() / params.mm_per_world_unit,
            params.mm_per_world_unit / samples.cutoff_mm,
            if params.follow_surface { 1.0 } else { 0.0 },
            n as f32,
        ];
        let ubo = frame_pool::uniform_buffer(device, "isss params", bytemuck::bytes_of(&p));
        let cv = inputs.color.create_view(&Default::default());
        let (output, blur) = match shape {
            PassShape::Fragment => {
                let output = frame_pool::target(device, "isss output", width, height, F::Rgba16Float);
                let pipe = gpu::fullscreen_pipeline(device, "isss blur", &module, "fs_blur", F::Rgba16Float);
                let group = inputs.blur_group(device, "isss", &pipe.get_bind_group_layout(0), (&ubo, &cv), &[]);
                let target = output.create_view(&Default::default());
                (output, ImportanceBlur::Fragment { pipe, group, target })
            }
            PassShape::Compute => {
                let output = frame_pool::storage_target(device, "isss output", width, height, F::Rgba16Float);
                let pipe = gpu::compute_pipeline(device, &module, "cs_blur");
                let ov = output.create_view(&Default::default());
                let layout = pipe.get_bind_group_layout(0);
                let group = inputs.blur_group(device, "isss", &layout, (&ubo, &cv), &[(3, &ov)]);
                let groups = [width.div_ceil(WORKGROUP), height.div_ceil(WORKGROUP)];
                (output, ImportanceBlur::Compute { pipe, group, groups })
            }
        };
        Ok(SssPass { inputs, output, blur })
    }
}

impl SssBlur for ImportanceBlur {
    /// Records the pass.
    fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        match self {
            Self::Fragment { pipe, group, target } => gpu::draw_fullscreen(enc, "isss", pipe, group, target, timer),
            Self::Compute { pipe, group, groups } => {
                let timestamp_writes = timer.map(|(t, i)| t.compute_pass_writes(i));
                let mut pass =
                    enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("isss"), timestamp_writes });
                pass.set_pipeline(pipe);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(groups[0], groups[1], 1);
            }
        }
    }
}
