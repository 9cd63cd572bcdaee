//! Screen-space sum-of-Gaussians SSS on the GPU (Jimenez, Sundstedt, Gutierrez, "Screen-Space Perceptual
//! Rendering of Human Skin", ACM TAP 2009; thesis ch. 4): each Gaussian of a fit (d'Eon et al. 2007) is applied
//! on top of the previous one with the incremental variance vᵢ − vᵢ₋₁, as a horizontal and a vertical 7-tap blur
//! (Listing 4.1) stretched by eq. 4.1–4.4, skipped where the depth LOD test of eq. 4.6 says it is narrower than
//! half a pixel, and accumulated into the final target by hardware alpha blending with the per-channel blend
//! constant w′ᵢ = wᵢ / Σⱼ≤ᵢ wⱼ (eq. 4.8–4.9). The first Gaussian is the unblurred image (w′₁ = 1).
//!
//! Textures: diffuse `Rgba16Float` (linear, alpha = local SSS level, 0 = not skin), depth `R32Float` (linear,
//! loaded, never filtered), RT1/RT2/RTF `Rgba16Float`. CPU twin [`crate::runtime::sss::gaussian_cpu`].
//!
//! Two shapes ([`PassShape`]): the full-screen fragment passes of Listing 4.1 (below) or compute passes over
//! workgroup-memory line tiles ([`crate::runtime::sss::gaussian_tiled`]), which also fold the blend into the
//! vertical pass and read the input in place of the copies the fragment form starts with.

use crate::diffusion::sum_of_gaussians::SumOfGaussians;
use crate::error::{check_non_negative, check_positive, InvalidInput};
use crate::runtime::frame_pool;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::sss::gaussian_tiled::TiledChain;
use crate::runtime::sss::{shape_from_env, PassShape, SssBlur, SssInputs, SssPass};
use crate::runtime::RuntimeError;

/// The blurs derived from a sum-of-Gaussians fit.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussianBlurs {
    /// sqrt(vᵢ) in mm, ascending (used by the depth LOD test, eq. 4.6).
    pub sigma_mm: Vec<f32>,
    /// sqrt(vᵢ − vᵢ₋₁) in mm: the blur applied on top of the previous Gaussian (first: sqrt(v₁)).
    pub incremental_sigma_mm: Vec<f32>,
    /// w′ᵢ per channel (eq. 4.8); w′₁ = 1.
    pub blend: Vec<[f32; 3]>,
}

impl GaussianBlurs {
    /// From a fit with ascending variances (eq. 4.8 and the incremental variances of §4.2.1).
    pub fn from_sum_of_gaussians(fit: &SumOfGaussians) -> Result<Self, InvalidInput> {
        let v = &fit.variances_mm2;
        if v.is_empty() || v.len() != fit.weights.len() {
            return Err(InvalidInput::new("gaussians", "need as many weights as variances, at least one"));
        }
        if v.windows(2).any(|p| p[1] <= p[0]) || v[0] <= 0.0 {
            return Err(InvalidInput::new("gaussians", "variances must be positive and strictly ascending"));
        }
        let mut cum = [0.0f64; 3];
        let mut blend = Vec::new();
        for (i, w) in fit.weights.iter().enumerate() {
            let mut b = [1.0f32; 3];
            for c in 0..3 {
                cum[c] += w[c];
                if i > 0 {
                    b[c] = if cum[c] > 0.0 { (w[c] / cum[c]) as f32 } else { 0.0 };
                    // eq. 4.8
                }
            }
            blend.push(b);
        }
        let incremental_sigma_mm =
            (0..v.len()).map(|i| (v[i] - if i == 0 { 0.0 } else { v[i - 1] }).sqrt() as f32).collect();
        Ok(Self { sigma_mm: v.iter().map(|x| x.sqrt() as f32).collect(), incremental_sigma_mm, blend })
    }
}

/// Stretch and LOD parameters (thesis defaults: α = 31.5, β = 800, γ = 0.001 for a 1-unit head, 20° FOV,
/// 720-pixel viewport; lod 2.0 = the exact rule of eq. 4.6, the thesis ships 0.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianSssParams {
    pub alpha: f32,
    pub beta: f32,
    pub gamma: f32,
    pub lod_factor: f32,
}

impl Default for GaussianSssParams {
    fn default() -> Self {
        Self { alpha: 31.5, beta: 800.0, gamma: 0.001, lod_factor: 2.0 }
    }
}

/// Viewport height (pixels) for which α of eq. 4.1 is stated.
pub const ALPHA_VIEWPORT_HEIGHT_PX: f32 = 720.0;

impl GaussianSssParams {
    /// α scaled from the 720-pixel viewport it is stated for to a viewport `height_px` tall (the stretch of eq. 4.1
    /// is in pixels, so it grows with the resolution); β, γ and the LOD factor are unchanged.
    pub fn for_viewport_height(self, height_px: u32) -> Self {
        Self { alpha: self.alpha * height_px as f32 / ALPHA_VIEWPORT_HEIGHT_PX, ..self }
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_positive("alpha", self.alpha as f64, "")?;
        check_non_negative("beta", self.beta as f64, "")?;
        check_non_negative("gamma", self.gamma as f64, "")?;
        check_positive("lod_factor", self.lod_factor as f64, "")?;
        Ok(())
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    stretch: [f32; 4],
    blur: [f32; 4],
    blend: [f32; 4],
}

impl Params {
    /// The uniform block (`gaussian_params.wgsl`) of Gaussian `i`'s pass in direction `dir` over a `width`×`height`
    /// frame; `write_rt1` tells the compute form's vertical pass to write RT1 (all but the last Gaussian).
    fn new(
        (width, height): (u32, u32),
        (blurs, params): (&GaussianBlurs, &GaussianSssParams),
        i: usize,
        dir: [f32; 2],
        write_rt1: bool,
    ) -> Self {
        let [r, g, b] = blurs.blend[i];
        Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            stretch: [params.alpha, params.beta, params.gamma, params.lod_factor],
            blur: [blurs.incremental_sigma_mm[i], blurs.sigma_mm[i], dir[0], dir[1]],
            blend: [r, g, b, if write_rt1 { 1.0 } else { 0.0 }],
        }
    }

    /// The horizontal and vertical uniform buffers of every Gaussian after the first.
    fn buffers(
        device: &wgpu::Device,
        size: (u32, u32),
        fit: (&GaussianBlurs, &GaussianSssParams),
    ) -> Vec<[wgpu::Buffer; 2]> {
        let n = fit.0.sigma_mm.len();
        let buffer = |label, block: Params| frame_pool::uniform_buffer(device, label, bytemuck::bytes_of(&block));
        (1..n)
            .map(|i| {
                let last = i + 1 == n;
                [
                    buffer("gsss h", Self::new(size, fit, i, [1.0, 0.0], !last)),
                    buffer("gsss v", Self::new(size, fit, i, [0.0, 1.0], !last)),
                ]
            })
            .collect()
    }
}

const SHADER: &str = concat!(
    include_str!("gaussian_params.wgsl"),
    include_str!("../fullscreen.wgsl"),
    include_str!("frame.wgsl"),
    include_str!("gaussian.wgsl")
);

/// Screen-space sum-of-Gaussians SSS for one frame size and fit.
pub type GaussianSss = SssPass<GaussianChain>;

/// The passes of [`GaussianSss`]: per Gaussian after the first, a horizontal and a blended vertical pass, in one of
/// the two [`PassShape`]s.
pub enum GaussianChain {
    Fragment(Box<FragmentChain>),
    Compute(Box<TiledChain>),
}

/// The fragment form of [`GaussianChain`]: render targets RT1, RT2 and RTF, the vertical pass blending into RTF.
pub struct FragmentChain {
    width: u32,
    height: u32,
    input: wgpu::Texture,
    rt1: wgpu::Texture,
    rtf: wgpu::Texture,
    rt1_view: wgpu::TextureView,
    rt2_view: wgpu::TextureView,
    rtf_view: wgpu::TextureView,
    pipe_h: wgpu::RenderPipeline,
    pipe_v: wgpu::RenderPipeline,
    /// Per Gaussian after the first: (horizontal group, vertical group, w′).
    steps: Vec<(wgpu::BindGroup, wgpu::BindGroup, [f32; 3])>,
}

impl GaussianSss {
    /// The chain in the shape [`shape_from_env`] names (compute unless `RTBAKE_SSS_PASSES=fragment`).
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        blurs: &GaussianBlurs,
        params: &GaussianSssParams,
    ) -> Result<Self, RuntimeError> {
        Self::with_shape(device, (width, height), blurs, params, shape_from_env(PassShape::Compute)?)
    }

    /// As [`Self::new`] in the given shape (the benchmarks build both; the same CPU twin).
    pub fn with_shape(
        device: &wgpu::Device,
        (width, height): (u32, u32),
        blurs: &GaussianBlurs,
        params: &GaussianSssParams,
        shape: PassShape,
    ) -> Result<Self, RuntimeError> {
        SssInputs::check_size(device, width, height)?;
        params.validate()?;
        let inputs = SssInputs::new(device, "gsss", width, height);
        let ubos = Params::buffers(device, (width, height), (blurs, params));
        let (output, blur) = match shape {
            PassShape::Fragment => {
                let chain = FragmentChain::new(device, &inputs, (width, height), ubos, blurs);
                (chain.rtf.clone(), GaussianChain::Fragment(Box::new(chain)))
            }
            PassShape::Compute => {
                let chain = TiledChain::new(device, &inputs, (width, height), ubos)?;
                (chain.output().clone(), GaussianChain::Compute(Box::new(chain)))
            }
        };
        Ok(SssPass { inputs, output, blur })
    }

    /// Number of passes [`Self::encode`] records (two per Gaussian after the first).
    pub fn passes(&self) -> u32 {
        2 * match &self.blur {
            GaussianChain::Fragment(c) => c.steps.len(),
            GaussianChain::Compute(c) => c.steps(),
        } as u32
    }

    /// The shape the chain was built in.
    pub fn shape(&self) -> PassShape {
        match self.blur {
            GaussianChain::Fragment(_) => PassShape::Fragment,
            GaussianChain::Compute(_) => PassShape::Compute,
        }
    }
}

impl FragmentChain {
    fn new(
        device: &wgpu::Device,
        inputs: &SssInputs,
        (width, height): (u32, u32),
        ubos: Vec<[wgpu::Buffer; 2]>,
        blurs: &GaussianBlurs,
    ) -> Self {
        use wgpu::TextureFormat as F;
        let rt1 = frame_pool::target(device, "gsss rt1", width, height, F::Rgba16Float);
        let rt2 = frame_pool::target(device, "gsss rt2", width, height, F::Rgba16Float);
        let rtf = frame_pool::target(device, "gsss rtf", width, height, F::Rgba16Float);
        let module = gpu::shader(device, "gaussian_sss.wgsl", SHADER);
        let pipe_h = gpu::fullscreen_pipeline(device, "gsss horizontal", &module, "fs_horizontal", F::Rgba16Float);
        let blend = wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Constant,
                dst_factor: wgpu::BlendFactor::OneMinusConstant,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
        };
        let targets = [
            Some(wgpu::ColorTargetState { format: F::Rgba16Float, blend: None, write_mask: wgpu::ColorWrites::ALL }),
            Some(wgpu::ColorTargetState {
                format: F::Rgba16Float,
                blend: Some(blend),
                write_mask: wgpu::ColorWrites::ALL,
            }),
        ];
        let pipe_v = gpu::fullscreen_pipeline_with(device, "gsss vertical", &module, "fs_vertical", &targets);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (iv, rt1_view, rt2_view, rtf_view) = (view(&inputs.color), view(&rt1), view(&rt2), view(&rtf));
        let (lh, lv) = (pipe_h.get_bind_group_layout(0), pipe_v.get_bind_group_layout(0));
        let steps = ubos
            .iter()
            .zip(&blurs.blend[1..])
            .map(|([uh, uv], w)| {
                let gh = inputs.blur_group(device, "gsss h", &lh, (uh, &rt1_view), &[(3, &iv)]);
                let gv = inputs.blur_group(device, "gsss v", &lv, (uv, &rt2_view), &[(3, &iv)]);
                (gh, gv, *w)
            })
            .collect();
        let input = inputs.color.clone();
        FragmentChain { width, height, input, rt1, rtf, rt1_view, rt2_view, rtf_view, pipe_h, pipe_v, steps }
    }
}

impl SssBlur for GaussianChain {
    /// Records the whole chain; pass k (0-based, H and V alternating) uses timer slot `first + k`.
    fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        match self {
            Self::Fragment(c) => c.encode(enc, timer),
            Self::Compute(c) => c.encode(enc, timer),
        }
    }
}

impl FragmentChain {
    fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        let full = wgpu::Extent3d { width: self.width, height: self.height, depth_or_array_layers: 1 };
        let whole = |t| wgpu::TexelCopyTextureInfo {
            texture: t,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        };
        enc.copy_texture_to_texture(whole(&self.input), whole(&self.rt1), full);
        enc.copy_texture_to_texture(whole(&self.input), whole(&self.rtf), full);
        for (k, (gh, gv, w)) in self.steps.iter().enumerate() {
            let slot = |j: u32| timer.map(|(t, first)| (t, first + 2 * k as u32 + j));
            gpu::draw_fullscreen(enc, "gsss horizontal", &self.pipe_h, gh, &self.rt2_view, slot(0));
            let load = wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store };
            let attachment = |view| {
                Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops: load })
            };
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gsss vertical"),
                color_attachments: &[attachment(&self.rt1_view), attachment(&self.rtf_view)],
                depth_stencil_attachment: None,
                timestamp_writes: slot(1).map(|(t, i)| t.render_pass_writes(i)),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipe_v);
            pass.set_bind_group(0, gv, &[]);
            pass.set_blend_constant(wgpu::Color { r: w[0] as f64, g: w[1] as f64, b: w[2] as f64, a: 1.0 });
            pass.draw(0..3, 0..1);
        }
    }
}
