//! Separable subsurface scattering on the GPU (Jimenez et al., "Separable Subsurface Scattering", CGF 2015;
//! thesis ch. 6): a horizontal and a vertical pass over a linear HDR irradiance image (`Rgba16Float`, alpha =
//! per-pixel strength, 0 = not skin: passes through) with a linear depth image (`R32Float`), using an N-tap kernel
//! (rgb weight, a offset; centre first) and the published shader's conventions (sssWidth, FOVy,
//! follow-surface). Resources created once in [`SeparableSss::new`]; CPU twin [`crate::runtime::sss::separable_cpu`].

use crate::error::{check_positive, InvalidInput};
use crate::runtime::frame_pool;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::sss::{SssBlur, SssInputs, SssPass};
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
        super::check_fovy(self.fovy_deg)
    }
    /// 1/tan(0.5·FOVy): distance to the projection window ([`super::dist_to_window`]).
    pub fn dist_to_window(&self) -> f32 {
        super::dist_to_window(self.fovy_deg)
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

    /// Checks the frame size and the parameters (in that order, before any work), then creates the uniform buffers
    /// of the horizontal and the vertical pass: the common start of both forms of the pass.
    pub(crate) fn buffers(
        device: &wgpu::Device,
        (width, height): (u32, u32),
        kernel: &SssKernel,
        params: &SssParams,
    ) -> Result<[wgpu::Buffer; 2], RuntimeError> {
        SssInputs::check_size(device, width, height)?;
        params.validate()?;
        let block = |dir| Self::new(width, height, kernel, params, dir);
        let mk = |label, dir| frame_pool::uniform_buffer(device, label, bytemuck::bytes_of(&block(dir)));
        Ok([mk("sss h", [1.0, 0.0]), mk("sss v", [0.0, 1.0])])
    }
}

const SHADER: &str = concat!(
    include_str!("separable_params.wgsl"),
    include_str!("../fullscreen.wgsl"),
    include_str!("frame.wgsl"),
    include_str!("separable.wgsl")
);

/// Separable SSS for one frame size and kernel.
pub type SeparableSss = SssPass<SeparableBlur>;

/// The two fragment passes of [`SeparableSss`].
pub struct SeparableBlur {
    pipe: wgpu::RenderPipeline,
    groups: [wgpu::BindGroup; 2],
    targets: [wgpu::TextureView; 2],
}

/// A form of the separable pass: [`SeparableBlur`] (fragment) or [`super::separable_tiled::TiledBlur`] (compute),
/// built by the one constructor of both, [`SssPass::new`].
pub trait SeparableForm: SssBlur + Sized + sealed::Sealed {
    /// Makes the form's intermediate and output textures (a render target or a storage texture).
    const TARGET: fn(&wgpu::Device, &str, u32, u32, wgpu::TextureFormat) -> wgpu::Texture;

    /// The form's pipeline and bind groups over a frame of `size`: the horizontal pass reads `inputs`' colour with
    /// uniform block `ubo[0]` into `targets[0]`, the vertical pass reads that with `ubo[1]` into `targets[1]`.
    fn build(
        device: &wgpu::Device,
        inputs: &SssInputs,
        ubo: [wgpu::Buffer; 2],
        targets: [&wgpu::Texture; 2],
        size: (u32, u32),
    ) -> Result<Self, RuntimeError>;
}

pub(super) mod sealed {
    /// Only the two forms of this room are [`super::SeparableForm`]s (each module implements it for its own).
    pub trait Sealed {}
    impl Sealed for super::SeparableBlur {}
}

impl<B: SeparableForm> SssPass<B> {
    /// Checks the frame size and the parameters (before any work), then creates the frame, the uniform blocks of
    /// both directions, the two targets and the form's passes.
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        kernel: &SssKernel,
        params: &SssParams,
    ) -> Result<Self, RuntimeError> {
        let ubo = Params::buffers(device, (width, height), kernel, params)?;
        let inputs = SssInputs::new(device, "sss", width, height);
        let [tmp, output] = SssInputs::targets(device, "sss", (width, height), B::TARGET);
        let blur = B::build(device, &inputs, ubo, [&tmp, &output], (width, height))?;
        Ok(SssPass { inputs, output, blur })
    }
}

impl SeparableForm for SeparableBlur {
    const TARGET: fn(&wgpu::Device, &str, u32, u32, wgpu::TextureFormat) -> wgpu::Texture = frame_pool::target;

    fn build(
        device: &wgpu::Device,
        inputs: &SssInputs,
        [ubo_h, ubo_v]: [wgpu::Buffer; 2],
        [tmp, output]: [&wgpu::Texture; 2],
        _size: (u32, u32),
    ) -> Result<Self, RuntimeError> {
        let module = gpu::shader(device, "separable_sss.wgsl", SHADER);
        let pipe = gpu::fullscreen_pipeline(device, "sss blur", &module, "fs_blur", wgpu::TextureFormat::Rgba16Float);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (cv, tv) = (view(&inputs.color), view(tmp));
        let layout = pipe.get_bind_group_layout(0);
        let groups = [
            inputs.blur_group(device, "sss h", &layout, (&ubo_h, &cv), &[]),
            inputs.blur_group(device, "sss v", &layout, (&ubo_v, &tv), &[]),
        ];
        let targets = [tv, view(output)];
        Ok(SeparableBlur { pipe, groups, targets })
    }
}

impl SssBlur for SeparableBlur {
    /// Records the horizontal and vertical passes.
    fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        for k in 0..2 {
            let slot = timer.map(|(t, first)| (t, first + k as u32));
            gpu::draw_fullscreen(enc, "sss", &self.pipe, &self.groups[k], &self.targets[k], slot);
        }
    }
}
