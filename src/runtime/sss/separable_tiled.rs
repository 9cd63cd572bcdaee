//! Separable subsurface scattering as two compute passes over line segments held in workgroup memory (Jimenez et
//! al., "Separable Subsurface Scattering", CGF 2015; thesis ch. 6): the arithmetic of [`crate::runtime::sss::separable`]
//! (same parameters, same uniform block, same CPU twin [`crate::runtime::sss::separable_cpu`]), shaped for memory
//! traffic. The fragment pass fetches 17 bilinear colour samples and 68 depth texels per pixel through the texture
//! units; here a workgroup of 128 threads reads its 128-texel segment of a row (or column) and a 64-texel apron on
//! each side once into workgroup memory, and every tap is two reads of that memory (a tap of a 1-D pass lies on the
//! line, so its bilinear fetch is a lerp of two neighbours), so a pass moves each texel in and out once. Taps beyond
//! the apron read the textures. The result is written through a storage texture (`Rgba16Float`).

use crate::runtime::frame_pool;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::sss::separable::{sealed, SeparableForm};
use crate::runtime::sss::{SssBlur, SssInputs, SssPass};
use crate::runtime::RuntimeError;

const SHADER: &str = concat!(
    include_str!("separable_params.wgsl"),
    include_str!("line_tile.wgsl"),
    include_str!("separable_tiled.wgsl")
);
/// Texels a workgroup blurs along its line (the shader's `SEGMENT`).
const SEGMENT: u32 = 128;

/// Separable SSS (compute, workgroup-memory tiles) for one frame size and kernel.
pub type SeparableSssTiled = SssPass<TiledBlur>;

/// The two compute passes of [`SeparableSssTiled`].
pub struct TiledBlur {
    pipe: wgpu::ComputePipeline,
    groups: [wgpu::BindGroup; 2],
    dispatch: [[u32; 3]; 2],
}

impl sealed::Sealed for TiledBlur {}

impl SeparableForm for TiledBlur {
    const TARGET: fn(&wgpu::Device, &str, u32, u32, wgpu::TextureFormat) -> wgpu::Texture = frame_pool::storage_target;

    fn build(
        device: &wgpu::Device,
        inputs: &SssInputs,
        [ubo_h, ubo_v]: [wgpu::Buffer; 2],
        [tmp, output]: [&wgpu::Texture; 2],
        (width, height): (u32, u32),
    ) -> Result<Self, RuntimeError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = gpu::shader(device, "separable_tiled.wgsl", SHADER);
        let pipe = gpu::compute_pipeline(device, &module, "blur");
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (cv, tv, dv, ov) = (view(&inputs.color), view(tmp), view(&inputs.depth), view(output));
        let layout = pipe.get_bind_group_layout(0);
        use wgpu::BindingResource as R;
        let group = |label, ubo: &wgpu::Buffer, src: &wgpu::TextureView, dst: &wgpu::TextureView| {
            let entries = [
                (0, ubo.as_entire_binding()),
                (1, R::TextureView(src)),
                (2, R::TextureView(&dv)),
                (3, R::TextureView(dst)),
            ];
            gpu::bind_group(device, label, &layout, &entries)
        };
        let groups = [group("sss h", &ubo_h, &cv, &tv), group("sss v", &ubo_v, &tv, &ov)];
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RuntimeError::Gpu(format!("separable SSS (compute): {e}")));
        }
        let dispatch = [[width.div_ceil(SEGMENT), height, 1], [height.div_ceil(SEGMENT), width, 1]];
        Ok(TiledBlur { pipe, groups, dispatch })
    }
}

impl SssBlur for TiledBlur {
    /// Records the horizontal and vertical passes (timestamps in slots `first` and `first + 1`).
    fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        for k in 0..2 {
            let timestamp_writes = timer.map(|(t, first)| t.compute_pass_writes(first + k as u32));
            let mut pass =
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("sss"), timestamp_writes });
            pass.set_pipeline(&self.pipe);
            pass.set_bind_group(0, &self.groups[k], &[]);
            let [x, y, z] = self.dispatch[k];
            pass.dispatch_workgroups(x, y, z);
        }
    }
}
