//! The screen-space sum of Gaussians (Jimenez, Sundstedt, Gutierrez, ACM TAP 2009; thesis ch. 4) as compute passes
//! over line segments held in workgroup memory: the arithmetic of [`crate::runtime::sss::gaussian`] (same uniform
//! block, same CPU twin [`crate::runtime::sss::gaussian_cpu`]), shaped for memory traffic. Per Gaussian after the
//! first, a horizontal pass (source → RT2) and a vertical pass (RT2 → RT1 and the running sum); a workgroup of 128
//! threads reads its 128-texel segment of a row (or column) and a 64-texel apron either side once into workgroup
//! memory, and each of the 7 taps is a lerp of two neighbours there (taps beyond the apron read the texture).
//!
//! Bytes per pixel, each texel once (RGBA16F = 8, depth R32F = 4). The fragment form: two copies of the input
//! (RT1, RTF) before the chain (32), per Gaussian a horizontal pass reading RT1, the depth and the input's alpha
//! (the matte) and writing RT2 (28), and a vertical pass reading RT2, the depth and the matte, writing RT1 and
//! blending into RTF, read and written (44): 32 + 72 per Gaussian, 392 for d'Eon's six. This form: no copies (the
//! first Gaussian reads the input as its source and its previous sum), the matte from the source's own alpha
//! (RT1 and RT2 carry the input's alpha), the blend folded into the vertical pass as a read of the previous sum and
//! a write of the next (ping-pong between two textures ending in the output); horizontal 20, vertical 36, the last
//! vertical 28 (it writes no RT1): 56 per Gaussian, 272 for d'Eon's six.

use crate::runtime::frame_pool;
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::sss::SssInputs;
use crate::runtime::RuntimeError;

const SHADER: &str =
    concat!(include_str!("gaussian_params.wgsl"), include_str!("line_tile.wgsl"), include_str!("gaussian_tiled.wgsl"));
/// Texels a workgroup blurs along its line (the shader's `SEGMENT`).
const SEGMENT: u32 = 128;

/// The compute form of [`crate::runtime::sss::gaussian::GaussianChain`].
pub struct TiledChain {
    /// The input (`Rgba16Float`), copied to the output when the fit has one Gaussian (nothing to blur).
    input: wgpu::Texture,
    output: wgpu::Texture,
    pipes: [wgpu::ComputePipeline; 2],
    /// Per Gaussian after the first: the horizontal and the vertical bind group.
    steps: Vec<[wgpu::BindGroup; 2]>,
    dispatch: [[u32; 3]; 2],
}

impl TiledChain {
    /// The passes over `inputs` for the uniform blocks `ubos` (horizontal, vertical per Gaussian after the first).
    pub(crate) fn new(
        device: &wgpu::Device,
        inputs: &SssInputs,
        (width, height): (u32, u32),
        ubos: Vec<[wgpu::Buffer; 2]>,
    ) -> Result<Self, RuntimeError> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = gpu::shader(device, "gaussian_tiled.wgsl", SHADER);
        let pipes =
            [gpu::compute_pipeline(device, &module, "blur_h"), gpu::compute_pipeline(device, &module, "blur_v")];
        let storage = |name| {
            let label = format!("gsss {name}");
            frame_pool::storage_target(device, &label, width, height, wgpu::TextureFormat::Rgba16Float)
        };
        let (rt1, rt2, sum, output) = (storage("rt1"), storage("rt2"), storage("sum"), storage("rtf"));
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (iv, rt1v, rt2v, sumv, outv, dv) =
            (view(&inputs.color), view(&rt1), view(&rt2), view(&sum), view(&output), view(&inputs.depth));
        let (lh, lv) = (pipes[0].get_bind_group_layout(0), pipes[1].get_bind_group_layout(0));
        let m = ubos.len();
        // The running sum ping-pongs so that the last vertical pass writes the output.
        let sum_out = |k: usize| if (m - 1 - k).is_multiple_of(2) { &outv } else { &sumv };
        use wgpu::BindingResource as R;
        let steps = ubos
            .iter()
            .enumerate()
            .map(|(k, [uh, uv])| {
                let src = if k == 0 { &iv } else { &rt1v };
                let sum_in = if k == 0 { &iv } else { sum_out(k - 1) };
                let h = [(0, uh.as_entire_binding()), (1, R::TextureView(src)), (2, R::TextureView(&dv))];
                let h = [h.as_slice(), &[(3, R::TextureView(&rt2v))]].concat();
                let v = [
                    (0, uv.as_entire_binding()),
                    (1, R::TextureView(&rt2v)),
                    (2, R::TextureView(&dv)),
                    (3, R::TextureView(&rt1v)),
                    (4, R::TextureView(sum_in)),
                    (5, R::TextureView(sum_out(k))),
                ];
                [gpu::bind_group(device, "gsss h", &lh, &h), gpu::bind_group(device, "gsss v", &lv, &v)]
            })
            .collect();
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(RuntimeError::Gpu(format!("sum-of-Gaussians SSS (compute): {e}")));
        }
        let dispatch = [[width.div_ceil(SEGMENT), height, 1], [height.div_ceil(SEGMENT), width, 1]];
        Ok(TiledChain { input: inputs.color.clone(), output, pipes, steps, dispatch })
    }

    /// The final sum (`Rgba16Float`, a storage texture).
    pub(crate) fn output(&self) -> &wgpu::Texture {
        &self.output
    }

    /// Gaussians blurred (all but the first).
    pub(crate) fn steps(&self) -> usize {
        self.steps.len()
    }

    /// Records the chain; pass k (0-based, H and V alternating) uses timer slot `first + k`.
    pub(crate) fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        if self.steps.is_empty() {
            let whole = |texture| wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            };
            enc.copy_texture_to_texture(whole(&self.input), whole(&self.output), self.input.size());
        }
        for (k, groups) in self.steps.iter().enumerate() {
            for (j, (pipe, group)) in self.pipes.iter().zip(groups).enumerate() {
                let slot = (2 * k + j) as u32;
                let timestamp_writes = timer.map(|(t, first)| t.compute_pass_writes(first + slot));
                let mut pass =
                    enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("gsss"), timestamp_writes });
                pass.set_pipeline(pipe);
                pass.set_bind_group(0, group, &[]);
                let [x, y, z] = self.dispatch[j];
                pass.dispatch_workgroups(x, y, z);
            }
        }
    }
}
