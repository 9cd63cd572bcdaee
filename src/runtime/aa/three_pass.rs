//! The three passes SMAA 1x and MLAA share (thesis ch. 9–10): edge detection (or the `EdgeStage` of another
//! detector), blending weights, neighbourhood blending, then the optional mask; the frame's textures, its upload
//! and read-back. [`crate::runtime::aa::smaa::Smaa`] and [`crate::runtime::aa::mlaa::Mlaa`] hand over their shader
//! module, uniform buffer and look-up tables (`PassSpec`); `ThreePass::build` makes the rest.
//!
//! Two shapes of the same arithmetic ([`PassShape`]): compute passes (`three_pass.wgsl`, the default: edges over
//! 8×8-thread workgroups, written straight into the edges texture the weights pass filters ([`EdgeFormat`]), which
//! also zero the weights and list the edge pixels (`edge_store.wgsl`), then the weights on the listed pixels only,
//! dispatched indirectly, then blending over 8×8 workgroups) or the three full-screen fragment passes they replace.
//! The other edge detectors and the mask (`EdgeStage`) take the same shape. Both call the same per-pixel WGSL
//! functions (`edges_px`, `weights_px`, `blend_px`) and write the same bytes (tested); the compute shape exists
//! because a fragment pass reaches only the part of a GPU its graphics pipeline spans (on an NVIDIA H100/H200, two
//! TPCs), while a compute pass runs on every SM. `RTBAKE_AA_PASSES=fragment` selects the fragment shape for the
//! default constructors, so one benchmark binary measures both.

use crate::error::InvalidInput;
use crate::runtime::aa::edges::{AaInputs, EdgeOut, EdgeOutputs, EdgeSettings, EdgeStage};
use crate::runtime::aa::pass_shape::{dispatch, frame_texture, grid};
pub use crate::runtime::aa::pass_shape::{set_portable_edges, EdgeFormat, PassShape};
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::RuntimeError;

/// The compute entry points appended after `smaa.wgsl` or `mlaa.wgsl`, after the edge store they share with the other
/// detectors' compute edge passes (`edge_store.wgsl`).
pub(crate) const COMPUTE_WGSL: &str = concat!(include_str!("edge_store.wgsl"), include_str!("three_pass.wgsl"));

/// The passes every three-pass frame records (edges, weights, blending).
const SMAA_OR_MLAA_PASSES: u32 = 3;

/// What a pass hands to [`ThreePass::build`]: the source of a module holding `fs_edges`/`fs_weights`/`fs_blend`
/// and the compute entry points of `three_pass.wgsl` (compiled with the device's [`EdgeFormat`]), its uniform buffer
/// (binding 0) and the weights pass's look-up textures and samplers.
pub(crate) struct PassSpec<'a> {
    /// `smaa` or `mlaa`: the labels' prefix.
    pub name: &'static str,
    /// The module's label and source.
    pub source: (&'static str, &'a str),
    pub ubo: &'a wgpu::Buffer,
    pub weight_luts: Vec<(u32, wgpu::BindingResource<'a>)>,
}

/// The passes of one shape: pipelines and bind groups of edges, weights and blending.
pub(crate) enum Passes {
    /// Render targets: the edges, weights and output views.
    Fragment { pipes: [wgpu::RenderPipeline; 3], groups: [wgpu::BindGroup; 3], views: [wgpu::TextureView; 3] },
    /// Edges (written into the edges texture, which another detector's compute pass writes instead; both list the
    /// edge pixels), dispatch arguments, weights on the list, blending; the edge list (count first) and the weights
    /// pass's indirect arguments.
    Compute {
        pipes: [wgpu::ComputePipeline; 4],
        groups: [wgpu::BindGroup; 4],
        edge_list: wgpu::Buffer,
        weights_args: wgpu::Buffer,
    },
}

/// The resources of a three-pass morphological antialiasing frame; the passes deref to it.
pub struct ThreePass {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) color: wgpu::Texture,
    pub(crate) edges: wgpu::Texture,
    pub(crate) weights: wgpu::Texture,
    pub(crate) output: wgpu::Texture,
    pub(crate) passes: Passes,
    pub(crate) extra: EdgeStage,
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
    /// The edges texture (R left edge, G top edge): `Rg8Unorm`, or in the compute shape the device's
    /// [`EdgeFormat`] (`Rgba8Unorm` with B and A zero where `Rg8Unorm` is no storage format); [`Self::read_edges`]
    /// reads it back as RG bytes either way.
    pub fn edges(&self) -> &wgpu::Texture {
        &self.edges
    }

    /// Reads the edges texture back as two bytes per pixel (R left edge, G top edge; top row first), whatever its
    /// format.
    pub fn read_edges(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<u8>, RuntimeError> {
        let bytes = gpu::read_texture(device, queue, &self.edges)?;
        let texel = gpu::bytes_per_texel(self.edges.format()) as usize;
        Ok(bytes.chunks_exact(texel).flat_map(|t| [t[0], t[1]]).collect())
    }
    /// The blending-weights texture (`Rgba8Unorm`).
    pub fn weights(&self) -> &wgpu::Texture {
        &self.weights
    }

    /// The bytes each pass (edges, weights, blending) must move, the figure its bytes-moved bound divides by the
    /// copy bandwidth: every image it reads and writes counted whole and once at its texture's format — edges: the
    /// detector's inputs (`EdgeStage`: colour RGBA8 and/or depth `R32Float`) in, the edges out (2 or 4 bytes a
    /// pixel, [`EdgeFormat`]); weights: the edges in, the weights (RGBA8) out; blending: the colour and the weights
    /// in, the output out (and, masked, the compute shape's mask, `R8Unorm`; the fragment shape masks in a fourth
    /// pass). The look-up tables, the texels the searches read again, the edge list and the weights the compute edge
    /// pass zeroes are left out: a bound, not a model.
    pub fn pass_bytes(&self) -> [u64; 3] {
        let px = self.width as u64 * self.height as u64;
        let edges = gpu::bytes_per_texel(self.edges.format()) as u64;
        [
            (self.extra.edge_input_bytes_per_pixel() + edges) * px,
            (edges + 4) * px,
            (12 + if self.shape() == PassShape::Compute { self.extra.mask_bytes_per_pixel() } else { 0 }) * px,
        ]
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

    /// Creates the textures, pipelines and bind groups of one frame size and shape (`lca`: the local contrast
    /// adaptation factor of another edge detector, 0 for none).
    pub(crate) fn build(
        device: &wgpu::Device,
        (width, height): (u32, u32),
        spec: PassSpec<'_>,
        shape: PassShape,
        (edge_settings, lca, masked): (&EdgeSettings, f32, bool),
    ) -> Result<Self, RuntimeError> {
        let name = spec.name;
        // The edge list is a storage binding that packs x and y in 16 bits each; a frame beyond the device's limits
        // or 65536 pixels a side takes the fragment shape (same bytes) rather than failing.
        let list_bytes = 4 + 4 * width as u64 * height as u64;
        let limits = device.limits();
        let fits = list_bytes <= limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
            && width.max(height) <= 1 << 16;
        let shape = if fits { shape } else { PassShape::Fragment };
        let label = |what: &str| format!("{name} {what}");
        let size = (width, height);
        let edge_format = EdgeFormat::for_device(device);
        let module = gpu::shader(device, spec.source.0, &edge_format.in_source(spec.source.1));
        // A storage texture too in either shape: `encode_on_buffer` unpacks a frame into it.
        let color = frame_texture(device, &label("colour"), size, PassShape::Compute);
        let edges = match shape {
            PassShape::Fragment => gpu::texture(device, &label("edges"), width, height, wgpu::TextureFormat::Rg8Unorm),
            PassShape::Compute => {
                gpu::storage_texture(device, &label("edges"), width, height, edge_format.texture_format())
            }
        };
        let weights = frame_texture(device, &label("weights"), size, shape);
        let output = frame_texture(device, &label("output"), size, shape);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (cv, ev, wv, ov) = (view(&color), view(&edges), view(&weights), view(&output));
        use wgpu::BindingResource as R;
        let ubo = || (0, spec.ubo.as_entire_binding());
        let mut weights_entries = vec![ubo(), (2, R::TextureView(&ev))];
        weights_entries.extend(spec.weight_luts.iter().cloned());
        let entries = [
            vec![ubo(), (1, R::TextureView(&cv))],
            weights_entries,
            vec![ubo(), (1, R::TextureView(&cv)), (5, R::TextureView(&wv))],
        ];
        let group = |stage: &str, layout: &wgpu::BindGroupLayout, entries: &[(u32, R<'_>)]| {
            gpu::bind_group(device, &label(stage), layout, entries)
        };
        let buffer = |what: &str, size: u64, usage: wgpu::BufferUsages| {
            let usage = usage | wgpu::BufferUsages::STORAGE;
            let desc = wgpu::BufferDescriptor { label: Some(&label(what)), size, usage, mapped_at_creation: false };
            device.create_buffer(&desc)
        };
        use wgpu::BufferUsages as B;
        // The compute shape's edge list and indirect arguments of the weights pass.
        let buffers = (shape == PassShape::Compute)
            .then(|| (buffer("edge list", list_bytes, B::COPY_DST), buffer("weights dispatch", 12, B::INDIRECT)));
        let outputs =
            buffers.as_ref().map(|(list, _)| EdgeOutputs { edges: &ev, format: edge_format, list, weights: &wv });
        let extra = EdgeStage::new(device, size, (&cv, &ov), (edge_settings, lca, masked), outputs)?;
        let passes = match buffers {
            None => {
                let pipes =
                    [("edges", "fs_edges", true), ("weights", "fs_weights", false), ("blend", "fs_blend", false)].map(
                        |(stage, entry, rg)| {
                            let format =
                                if rg { wgpu::TextureFormat::Rg8Unorm } else { wgpu::TextureFormat::Rgba8Unorm };
                            gpu::fullscreen_pipeline(device, &label(stage), &module, entry, format)
                        },
                    );
                let stages = ["edges", "weights", "blend"];
                let groups = [0, 1, 2].map(|k| group(stages[k], &pipes[k].get_bind_group_layout(0), &entries[k]));
                Passes::Fragment { pipes, groups, views: [ev.clone(), wv.clone(), ov.clone()] }
            }
            Some((edge_list, weights_args)) => {
                let mask_view = extra.mask().map(|t| t.create_view(&Default::default()));
                let mask_entry: Vec<_> = mask_view.iter().map(|v| (13, R::TextureView(v))).collect();
                let [edges_entries, mut weights_entries, blend_entries] = entries;
                let list = || (11, edge_list.as_entire_binding());
                let weights_out = || (9, R::TextureView(&wv));
                weights_entries.extend([weights_out(), list()]);
                let entries = [
                    [edges_entries, vec![(8, R::TextureView(&ev)), weights_out(), list()]].concat(),
                    vec![list(), (12, weights_args.as_entire_binding())],
                    weights_entries,
                    [blend_entries, vec![(10, R::TextureView(&ov))], mask_entry].concat(),
                ];
                let blend = if masked { "cs_blend_masked" } else { "cs_blend" };
                let stages = ["cs_edges", "cs_edge_args", "cs_weights_list", blend];
                let pipes = stages.map(|e| gpu::compute_pipeline(device, &module, e));
                let groups = [0, 1, 2, 3].map(|k| group(stages[k], &pipes[k].get_bind_group_layout(0), &entries[k]));
                Passes::Compute { pipes, groups, edge_list, weights_args }
            }
        };
        Ok(Self { width, height, color, edges, weights, output, passes, extra, name })
    }

    /// The shape the passes were built in.
    pub fn shape(&self) -> PassShape {
        match self.passes {
            Passes::Fragment { .. } => PassShape::Fragment,
            Passes::Compute { .. } => PassShape::Compute,
        }
    }

    /// Render (fragment) passes [`Self::encode`] records: the three of the fragment shape and the edge detector's and
    /// mask's in that shape; none in the compute shape.
    pub fn render_passes(&self) -> u32 {
        let own = match self.passes {
            Passes::Fragment { .. } => SMAA_OR_MLAA_PASSES,
            Passes::Compute { .. } => 0,
        };
        own + self.extra.render_passes()
    }

    /// Records the three passes; `timer` slots `first..first+3` receive their timestamps (in the compute shape the
    /// weights slot spans the dispatch arguments and the weights).
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        let slot = |k: u32| timer.map(|(t, first)| (t, first + k));
        match &self.passes {
            Passes::Fragment { pipes, groups, views } => {
                for k in 0..3 {
                    if k == 0 && self.extra.encode_edges(enc, EdgeOut::Render(&views[0], slot(0))) {
                        continue;
                    }
                    let label = format!("{} {}", self.name, ["edges", "weights", "blend"][k]);
                    gpu::draw_fullscreen(enc, &label, &pipes[k], &groups[k], &views[k], slot(k as u32));
                }
            }
            Passes::Compute { pipes, groups, edge_list, weights_args } => {
                let (w, h) = (self.width, self.height);
                let run = |enc: &mut wgpu::CommandEncoder, k: usize, groups_xy, writes| {
                    dispatch(enc, self.name, &pipes[k], &groups[k], groups_xy, writes)
                };
                // The begin (or end) timestamp of slot `k` alone: a slot spanning several passes.
                let half = |k: u32, begin: bool| {
                    slot(k).map(|(t, i)| wgpu::ComputePassTimestampWrites {
                        query_set: &t.query_set,
                        beginning_of_pass_write_index: begin.then_some(2 * i),
                        end_of_pass_write_index: (!begin).then_some(2 * i + 1),
                    })
                };
                enc.clear_buffer(edge_list, 0, Some(4));
                let edges_slot = || slot(0).map(|(t, i)| t.compute_pass_writes(i));
                if !self.extra.encode_edges(enc, EdgeOut::Texture(edges_slot())) {
                    run(enc, 0, grid(w.div_ceil(2), h), edges_slot());
                }
                run(enc, 1, (1, 1), half(1, true));
                {
                    let desc = wgpu::ComputePassDescriptor { label: Some(self.name), timestamp_writes: half(1, false) };
                    let mut pass = enc.begin_compute_pass(&desc);
                    pass.set_pipeline(&pipes[2]);
                    pass.set_bind_group(0, &groups[2], &[]);
                    pass.dispatch_workgroups_indirect(weights_args, 0);
                }
                run(enc, 3, grid(w, h), slot(2).map(|(t, i)| t.compute_pass_writes(i)));
            }
        }
        self.extra.encode_mask(enc);
    }

    /// Records the passes over the frame in `frame`, a storage buffer of packed RGBA8 pixels (`width·height` u32, R in
    /// the low byte, sRGB-encoded, top row first: as the skin frame's compute chains leave it) and writes the
    /// antialiased frame back into it, all into `enc`: a compute pass unpacks the buffer into the input texture
    /// (instead of [`Self::upload`]), the passes run as [`Self::encode`] records them, and a compute pass packs the
    /// output back (`frame_buffer.wgsl`; both conversions exact). A frame shaded on the device is so antialiased
    /// in its own submission and read back once; the bytes are those of [`Self::run`] on the same pixels (tested).
    pub fn encode_on_buffer(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        frame: &wgpu::Buffer,
    ) -> Result<(), InvalidInput> {
        let (w, h) = (self.width, self.height);
        let need = 4 * w as u64 * h as u64;
        if frame.size() < need || !frame.usage().contains(wgpu::BufferUsages::STORAGE) {
            return Err(InvalidInput::new(
                "frame",
                format!("must be a storage buffer of at least {w}x{h}x4 = {need} bytes, got {}", frame.size()),
            ));
        }
        let module = gpu::shader(device, "frame_buffer.wgsl", include_str!("frame_buffer.wgsl"));
        use wgpu::BindingResource as R;
        let (input, output) =
            (self.color.create_view(&Default::default()), self.output().create_view(&Default::default()));
        let frame_binding = || (0, frame.as_entire_binding());
        let pass = |enc: &mut wgpu::CommandEncoder, entry: &str, entries: &[(u32, R<'_>)]| {
            let pipe = gpu::compute_pipeline(device, &module, entry);
            let group = gpu::bind_group(device, entry, &pipe.get_bind_group_layout(0), entries);
            dispatch(enc, entry, &pipe, &group, grid(w, h), None);
        };
        pass(enc, "cs_unpack", &[frame_binding(), (1, R::TextureView(&input))]);
        // With per-pass profiling on (`gpu::set_pass_profiling`), the three passes come back timed beside their
        // bytes ([`Self::pass_bytes`]); the unpack and pack passes fall in the spans around them.
        match gpu::profile_timer(device, SMAA_OR_MLAA_PASSES) {
            Some(timer) => {
                self.encode(enc, timer.as_ref().map(|t| (t, 0)));
                let stages = ["edges", "weights", "blend"];
                let labels = stages.map(|s| format!("{}: {s}", self.name));
                let passes = labels.into_iter().zip(self.pass_bytes()).map(|(l, b)| (l, Some(b))).collect();
                gpu::profile_passes(timer, passes);
            }
            None => self.encode(enc, None),
        }
        pass(enc, "cs_pack", &[frame_binding(), (2, R::TextureView(&output))]);
        Ok(())
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
