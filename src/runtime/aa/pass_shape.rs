//! The two shapes an anti-aliasing pass takes on the GPU ([`PassShape`]: compute dispatches over 8×8-thread
//! workgroups, or full-screen fragment passes into render targets; the same bytes either way) and what the passes
//! of both shapes share: a one-output pass in either shape (`ShapedPass`: the edge detectors, the mask, the SMAA
//! modes' resolves), the workgroup grid, the frame textures and the format of the compute shape's edges
//! ([`EdgeFormat`]). [`crate::runtime::aa::three_pass`] builds the three passes of SMAA 1x and MLAA (thesis
//! ch. 9–10) on it; [`crate::runtime::aa::edges`] and [`crate::runtime::aa::modes`] build theirs.

use crate::error::InvalidInput;
use crate::runtime::gpu::{self, GpuTimer};

/// Threads per workgroup side of the compute shape (`@workgroup_size(8, 8)` in `three_pass.wgsl`).
const WORKGROUP: u32 = 8;

/// The form the three passes take on the GPU; the output bytes are the same.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PassShape {
    /// Compute passes: edges and blending over 8×8-thread workgroups, the weights on a list of the edge pixels.
    #[default]
    Compute,
    /// Three full-screen fragment passes into render targets (the shape before the compute passes).
    Fragment,
}

impl PassShape {
    /// The environment variable [`Self::from_env`] reads.
    pub const ENV: &'static str = "RTBAKE_AA_PASSES";

    /// `compute` or `fragment`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Compute => "compute",
            Self::Fragment => "fragment",
        }
    }

    /// `compute` or `fragment`; anything else is refused naming [`Self::ENV`].
    pub fn parse(value: &str) -> Result<Self, InvalidInput> {
        [Self::Compute, Self::Fragment]
            .into_iter()
            .find(|s| s.name() == value)
            .ok_or_else(|| InvalidInput::new(Self::ENV, format!("must be compute or fragment, got {value:?}")))
    }

    /// [`Self::ENV`] when set ([`Self::parse`]), else [`PassShape::Compute`].
    pub fn from_env() -> Result<Self, InvalidInput> {
        std::env::var(Self::ENV).map_or(Ok(Self::default()), |v| Self::parse(&v))
    }
}

/// The format of the compute shape's edges texture, which its edge pass writes as a storage texture
/// (`textureStore`, no buffer and no copy) and the weights pass filters bilinearly (.rg): `Rg8Unorm`, 2 bytes a
/// pixel, where the device lets a compute pass write it (an adapter-specific format feature,
/// `wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES`, which `runtime::device` requests where the adapter
/// allows it), else `Rgba8Unorm`, 4 bytes a pixel with B and A zero (a storage format every WebGPU device has). The
/// edge values are exactly 0 or 1, so R and G are the bytes the fragment shape renders into its `Rg8Unorm` target
/// either way (tested in both formats).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeFormat {
    Rg8,
    Rgba8,
}

thread_local! {
    static PORTABLE_EDGES: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Makes the compute-shape passes built on the calling thread write their edges as `Rgba8Unorm` even where the
/// device allows `Rg8Unorm` (true), or pick by the device (false, the default): tests and benchmarks compare the
/// two forms on one device.
pub fn set_portable_edges(on: bool) {
    PORTABLE_EDGES.with(|c| c.set(on));
}

impl EdgeFormat {
    /// The texture format.
    pub fn texture_format(self) -> wgpu::TextureFormat {
        match self {
            Self::Rg8 => wgpu::TextureFormat::Rg8Unorm,
            Self::Rgba8 => wgpu::TextureFormat::Rgba8Unorm,
        }
    }

    /// The storage format's WGSL name.
    fn wgsl(self) -> &'static str {
        match self {
            Self::Rg8 => "rg8unorm",
            Self::Rgba8 => "rgba8unorm",
        }
    }

    /// The format passes built on `device` from the calling thread write ([`set_portable_edges`] aside): `Rg8` where
    /// the device has the adapter's own format features and an `Rg8Unorm` storage texture can be created on it
    /// (probed once per device), else `Rgba8`.
    pub fn for_device(device: &wgpu::Device) -> Self {
        if PORTABLE_EDGES.with(|c| c.get())
            || !device.features().contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
        {
            return Self::Rgba8;
        }
        gpu::cached(device, "rg8unorm storage probe", &(), || {
            let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            drop(gpu::storage_texture(device, "rg8unorm storage probe", 1, 1, wgpu::TextureFormat::Rg8Unorm));
            match pollster::block_on(scope.pop()) {
                None => Self::Rg8,
                Some(_) => Self::Rgba8,
            }
        })
    }

    /// `source` (a module that includes `edge_store.wgsl`) with its edges texture declared in this format.
    pub(crate) fn in_source(self, source: &str) -> String {
        const DECL: &str = "var edges_out: texture_storage_2d<rg8unorm, write>;";
        debug_assert!(source.contains(DECL), "the module includes edge_store.wgsl");
        source.replace(DECL, &DECL.replace("rg8unorm", self.wgsl()))
    }
}

/// Workgroups of 8×8 threads covering `threads_x` × `threads_y` threads.
pub(crate) fn grid(threads_x: u32, threads_y: u32) -> (u32, u32) {
    (threads_x.div_ceil(WORKGROUP), threads_y.div_ceil(WORKGROUP))
}

/// Records one compute pass: `pipe` with bind group 0 `group` over `groups` workgroups, optional timestamps.
pub(crate) fn dispatch(
    enc: &mut wgpu::CommandEncoder,
    label: &str,
    pipe: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    (x, y): (u32, u32),
    writes: Option<wgpu::ComputePassTimestampWrites<'_>>,
) {
    let mut pass =
        enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: writes });
    pass.set_pipeline(pipe);
    pass.set_bind_group(0, group, &[]);
    pass.dispatch_workgroups(x, y, 1);
}

/// A pass with one output in either shape: a full-screen draw into a render target or a compute dispatch over
/// 8×8-thread workgroups writing a storage texture (the edge, mask and SMAA mode passes beside the three).
pub(crate) enum ShapedPass {
    Draw(wgpu::RenderPipeline, wgpu::BindGroup),
    Dispatch(wgpu::ComputePipeline, wgpu::BindGroup),
}

impl ShapedPass {
    /// `entry` of `module` (`cs_*`: a compute pass; else a fragment entry drawn into a `format` target), with its
    /// bind group from `entries`.
    pub(crate) fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        entry: &str,
        format: wgpu::TextureFormat,
        entries: &[(u32, wgpu::BindingResource<'_>)],
    ) -> Self {
        if entry.starts_with("cs_") {
            let pipe = gpu::compute_pipeline(device, module, entry);
            let bg = gpu::bind_group(device, entry, &pipe.get_bind_group_layout(0), entries);
            Self::Dispatch(pipe, bg)
        } else {
            let pipe = gpu::fullscreen_pipeline(device, entry, module, entry, format);
            let bg = gpu::bind_group(device, entry, &pipe.get_bind_group_layout(0), entries);
            Self::Draw(pipe, bg)
        }
    }

    /// 1 for a draw, 0 for a dispatch.
    pub(crate) fn render_passes(&self) -> u32 {
        matches!(self, Self::Draw(..)) as u32
    }

    /// Records the pass over a `w`×`h` frame (one thread per pixel): a draw into `target`, or a dispatch (whose
    /// bind group holds the storage view of the output); `slot` receives its timestamps.
    pub(crate) fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        target: &wgpu::TextureView,
        (w, h): (u32, u32),
        slot: Option<(&GpuTimer, u32)>,
    ) {
        match self {
            Self::Draw(pipe, bg) => gpu::draw_fullscreen(enc, label, pipe, bg, target, slot),
            Self::Dispatch(pipe, bg) => {
                dispatch(enc, label, pipe, bg, grid(w, h), slot.map(|(t, i)| t.compute_pass_writes(i)))
            }
        }
    }
}

/// A frame texture (`Rgba8Unorm`) the passes write: a render target and, for the compute shape, a storage texture.
pub(crate) fn frame_texture(device: &wgpu::Device, label: &str, (w, h): (u32, u32), shape: PassShape) -> wgpu::Texture {
    use wgpu::TextureUsages as U;
    let storage = if shape == PassShape::Compute { U::STORAGE_BINDING } else { U::empty() };
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: U::TEXTURE_BINDING | U::RENDER_ATTACHMENT | U::COPY_DST | U::COPY_SRC | storage,
        view_formats: &[],
    })
}
