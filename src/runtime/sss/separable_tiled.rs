//! Separable subsurface scattering as two compute passes over line segments held in workgroup memory (Jimenez et
//! al., "Separable Subsurface Scattering", CGF 2015; thesis ch. 6): the arithmetic of [`crate::runtime::sss::separable`]
//! (same parameters, same uniform block, same CPU twin [`crate::runtime::sss::separable_cpu`]), shaped for memory
//! traffic. The fragment pass fetches 17 bilinear colour samples and 68 depth texels per pixel through the texture
//! units; here a workgroup of 128 threads reads its 128-texel segment of a row (or column) and a 64-texel apron on
//! each side once into workgroup memory, and every tap is two reads of that memory (a tap of a 1-D pass lies on the
//! line, so its bilinear fetch is a lerp of two neighbours), so a pass moves each texel in and out once. Taps beyond
//! the apron read the textures. The result is written through a storage texture (`Rgba16Float`).

use crate::error::InvalidInput;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::sss::separable::{Params, SssKernel, SssParams};
use crate::runtime::RuntimeError;

const SHADER: &str = include_str!("separable_tiled.wgsl");
/// Texels a workgroup blurs along its line (the shader's `SEGMENT`).
const SEGMENT: u32 = 128;

/// Separable SSS (compute, workgroup-memory tiles) for one frame size and kernel.
pub struct SeparableSssTiled {
    color: wgpu::Texture,
    depth: wgpu::Texture,
    output: wgpu::Texture,
    pipe: wgpu::ComputePipeline,
    groups: [wgpu::BindGroup; 2],
    dispatch: [[u32; 3]; 2],
}

impl SeparableSssTiled {
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
        let tmp = gpu::storage_texture(device, "sss horizontal", width, height, F::Rgba16Float);
        let output = gpu::storage_texture(device, "sss output", width, height, F::Rgba16Float);
        let depth = gpu::data_texture(device, "sss depth", width, height, F::R32Float);
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = gpu::shader(device, "separable_tiled.wgsl", SHADER);
        let pipe = gpu::compute_pipeline(device, &module, "blur");
        let ubo_h = gpu::uniform_buffer(
            device,
            "sss h",
            bytemuck::bytes_of(&Params::new(width, height, kernel, params, [1.0, 0.0])),
        );
        let ubo_v = gpu::uniform_buffer(
            device,
            "sss v",
            bytemuck::bytes_of(&Params::new(width, height, kernel, params, [0.0, 1.0])),
        );
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (cv, tv, dv, ov) = (view(&color), view(&tmp), view(&depth), view(&output));
        let layout = pipe.get_bind_group_layout(0);
        use wgpu::BindingResource as R;
        let group = |label, ubo: &wgpu::Buffer, src: &wgpu::TextureView, dst: &wgpu::TextureView| {
            gpu::bind_group(
                device,
                label,
                &layout,
                &[
                    (0, ubo.as_entire_binding()),
                    (1, R::TextureView(src)),
                    (2, R::TextureView(&dv)),
                    (3, R::TextureView(dst)),
                ],
            )
        };
        let groups = [group("sss h", &ubo_h, &cv, &tv), group("sss v", &ubo_v, &tv, &ov)];
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RuntimeError::Gpu(format!("separable SSS (compute): {e}")));
        }
        let dispatch = [[width.div_ceil(SEGMENT), height, 1], [height.div_ceil(SEGMENT), width, 1]];
        Ok(Self { color, depth, output, pipe, groups, dispatch })
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

    /// Records the horizontal and vertical passes (timestamps in slots `first` and `first + 1`).
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        for k in 0..2 {
            let timestamp_writes = timer.map(|(t, first)| wgpu::ComputePassTimestampWrites {
                query_set: &t.query_set,
                beginning_of_pass_write_index: Some(2 * (first + k as u32)),
                end_of_pass_write_index: Some(2 * (first + k as u32) + 1),
            });
            let mut pass =
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("sss"), timestamp_writes });
            pass.set_pipeline(&self.pipe);
            pass.set_bind_group(0, &self.groups[k], &[]);
            let [x, y, z] = self.dispatch[k];
            pass.dispatch_workgroups(x, y, z);
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
        gpu::read_texture_f16(device, queue, &self.output)
    }
}
