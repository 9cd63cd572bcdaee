//! The three full-screen passes SMAA 1x and MLAA share (thesis ch. 9–10): edge detection (or the
//! `EdgeStage` of another detector), blending weights, neighbourhood blending, then the optional mask; the
//! frame's textures, its upload and read-back. [`crate::runtime::aa::smaa::Smaa`] and
//! [`crate::runtime::aa::mlaa::Mlaa`] build the pipelines and bind groups and hand them over.

use crate::error::InvalidInput;
use crate::runtime::aa::edges::{AaInputs, EdgeStage};
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::RuntimeError;

/// The resources of a three-pass morphological antialiasing frame; the passes deref to it.
pub struct ThreePass {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) color: wgpu::Texture,
    pub(crate) edges: wgpu::Texture,
    pub(crate) weights: wgpu::Texture,
    pub(crate) output: wgpu::Texture,
    /// Render targets of the edges, weights and blending passes.
    pub(crate) views: [wgpu::TextureView; 3],
    pub(crate) pipes: [wgpu::RenderPipeline; 3],
    pub(crate) groups: [wgpu::BindGroup; 3],
    pub(crate) extra: EdgeStage,
    /// Debug labels of the three passes and of the submission.
    pub(crate) labels: [&'static str; 3],
    pub(crate) name: &'static str,
}

impl ThreePass {
    /// The frame size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
    /// The input texture (`Rgba8Unorm`, sRGB-encoded values); other passes may render into it directly.
    pub fn input(&self) -> &wgpu::Texture {
        &self.color
    }
    /// The antialiased output (`Rgba8Unorm`, sRGB-encoded values; masked when the options say so).
    pub fn output(&self) -> &wgpu::Texture {
        self.extra.masked_output().unwrap_or(&self.output)
    }
    /// The edges texture (`Rg8Unorm`: R left edge, G top edge).
    pub fn edges(&self) -> &wgpu::Texture {
        &self.edges
    }
    /// The blending-weights texture (`Rgba8Unorm`).
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
        for (k, label) in self.labels.iter().enumerate() {
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
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(self.name) });
        self.encode(&mut enc, None);
        queue.submit([enc.finish()]);
        gpu::read_texture(device, queue, self.output())
    }
}
