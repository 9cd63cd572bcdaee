//! Edge detectors other than luma, predicated thresholding and matte/stencil masking, shared by SMAA
//! ([`crate::runtime::aa::smaa`]) and MLAA ([`crate::runtime::aa::mlaa`]); WGSL in `aa/edges.wgsl`, CPU twin
//! [`crate::runtime::aa::edges_cpu`].
//!
//! - **Colour** (thesis §10.4.1, "RGB color" among the detectors SMAA names): the contrast between two pixels is
//!   the largest absolute difference of their sRGB-encoded R, G, B, `c(a, b) = max_k |a_k − b_k|`, thresholded as
//!   luma is (`e_l = c(C, C_left) ≥ T`). SMAA adds local contrast adaptation, eq. 10.1:
//!   `c_max = max(c_l, c_r, c_b, c_t, c_2l)`, `e'_l = e_l ∧ c_l ≥ c_max / 2` (factor 2.0), with `c_2l` the edge
//!   left of the left neighbour, `c(C_left, C_leftleft)`, as the thesis draws it (Figure 10.5) and as the luma
//!   detector of `smaa.wgsl` does; MLAA uses no adaptation.
//! - **Depth** (thesis §9.3, Listing 9.1 — MLAA's main variant — and SMAA's depth detector): an edge where
//!   `|D − D_left| ≥ T_depth` (`|D − D_top|` for the top edge), in the units of the depth image. No local contrast
//!   adaptation (depth differences are not perceptual). Default `T_depth` = 0.01, SMAA's `SMAA_DEPTH_THRESHOLD`
//!   (0.1 · `SMAA_THRESHOLD`, SMAA.hlsl).
//! - **Predicated thresholding** (SMAA.hlsl `SMAA_PREDICATION`, after the PS3 MLAA of Killzone 3): the luma or
//!   colour threshold per edge is lowered where the depth image has an edge and raised elsewhere,
//!   `T' = scale · T · (1 − strength · [|D − D_n| ≥ T_pred])`; SMAA's defaults: `T_pred` 0.01, scale 2.0,
//!   strength 0.4.
//! - **Matte / stencil masking**: pixels whose mask byte is below 128 leave the pass exactly as they came in; the
//!   passes run everywhere, so pixels inside the matte still blend with their neighbours outside it (the fragment
//!   shape selects per pixel in a fourth, untimed pass; the compute shape in its blending pass).
//!
//! Every detector exists as a fragment pass and as a compute pass (the two `PassShape`s of
//! [`crate::runtime::aa::three_pass`]), both calling the same per-pixel WGSL functions: the same bytes.
//!
//! The luma detector without predication stays the passes' own (`fs_edges` of `smaa.wgsl` / `mlaa.wgsl`), so
//! default runs are unchanged.

use crate::error::{check_range, InvalidInput};
use crate::runtime::aa::pass_shape::{dispatch, grid, EdgeFormat, ShapedPass};
use crate::runtime::gpu;

/// SMAA's luma / colour threshold (SMAA.hlsl `SMAA_THRESHOLD`, preset HIGH; MLAA's listings use the same 0.1).
pub const COLOR_THRESHOLD: f32 = 0.1;
/// SMAA's depth threshold, `0.1 · SMAA_THRESHOLD` (SMAA.hlsl `SMAA_DEPTH_THRESHOLD`), in depth-image units.
pub const DEFAULT_DEPTH_THRESHOLD: f32 = 0.01;
/// Local contrast adaptation factor of SMAA (eq. 10.1's 0.5 · c_max; SMAA.hlsl
/// `SMAA_LOCAL_CONTRAST_ADAPTATION_FACTOR`).
pub const SMAA_LOCAL_CONTRAST_ADAPTATION: f32 = 2.0;

/// Which image the edge detection pass reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EdgeDetector {
    /// Luma of the sRGB-encoded colour (eq. 9.2), the passes' default.
    #[default]
    Luma,
    /// Largest R, G, B difference of the sRGB-encoded colour.
    Color,
    /// Depth differences (Listing 9.1); needs a depth image.
    Depth,
}

/// Predicated thresholding from the depth image (SMAA.hlsl's defaults in [`Predication::SMAA`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Predication {
    /// Depth difference that counts as a predication edge, depth-image units (`SMAA_PREDICATION_THRESHOLD`).
    pub threshold: f32,
    /// Factor on the global threshold, 1..=5 (`SMAA_PREDICATION_SCALE`).
    pub scale: f32,
    /// Local decrease where the depth has an edge, 0..=1 (`SMAA_PREDICATION_STRENGTH`).
    pub strength: f32,
}

impl Predication {
    /// SMAA.hlsl's defaults: threshold 0.01, scale 2.0, strength 0.4.
    pub const SMAA: Self = Self { threshold: 0.01, scale: 2.0, strength: 0.4 };

    /// Ranges of SMAA.hlsl's documentation: scale in 1..=5, strength in 0..=1, threshold finite and > 0.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        positive("predication_threshold", self.threshold)?;
        check_range("predication_scale", self.scale, 1.0, 5.0, "")?;
        check_range("predication_strength", self.strength, 0.0, 1.0, "")?;
        Ok(())
    }
}

impl Default for Predication {
    fn default() -> Self {
        Self::SMAA
    }
}

fn positive(param: &str, v: f32) -> Result<(), InvalidInput> {
    if !(v.is_finite() && v > 0.0) {
        return Err(InvalidInput::new(param, format!("must be a finite number > 0 (depth-image units), got {v}")));
    }
    Ok(())
}

/// How the edge detection pass of SMAA or MLAA finds edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeSettings {
    pub detector: EdgeDetector,
    /// Threshold of [`EdgeDetector::Depth`], depth-image units (default [`DEFAULT_DEPTH_THRESHOLD`]).
    pub depth_threshold: f32,
    /// Predicated thresholding of the luma or colour detector from the depth image.
    pub predication: Option<Predication>,
}

impl Default for EdgeSettings {
    fn default() -> Self {
        Self { detector: EdgeDetector::Luma, depth_threshold: DEFAULT_DEPTH_THRESHOLD, predication: None }
    }
}

impl EdgeSettings {
    /// Thresholds finite and positive, predication in its ranges and only with luma or colour detection.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        positive("depth_threshold", self.depth_threshold)?;
        if let Some(p) = &self.predication {
            if self.detector == EdgeDetector::Depth {
                return Err(InvalidInput::new(
                    "predication",
                    "applies to `edges` luma or color (it thresholds them from the depth); `edges` depth already \
                     reads the depth",
                ));
            }
            p.validate()?;
        }
        Ok(())
    }

    /// Whether the detection reads a depth image.
    pub fn needs_depth(&self) -> bool {
        self.detector == EdgeDetector::Depth || self.predication.is_some()
    }

    /// Luma without predication: the passes' own detector (`fs_edges`).
    pub fn is_plain_luma(&self) -> bool {
        self.detector == EdgeDetector::Luma && self.predication.is_none()
    }
}

/// The per-frame images beside the colour: depth (one f32 per pixel, top row first) and the matte (one byte per
/// pixel, ≥ 128 = inside).
#[derive(Clone, Copy, Debug, Default)]
pub struct AaInputs<'a> {
    pub depth: Option<&'a [f32]>,
    pub mask: Option<&'a [u8]>,
}

impl AaInputs<'_> {
    /// Checks what `settings` (and `masked`) need is there, has `w·h` values and (depth) is finite.
    pub fn validate(&self, w: u32, h: u32, settings: &EdgeSettings, masked: bool) -> Result<(), InvalidInput> {
        let n = w as usize * h as usize;
        match self.depth {
            None if settings.needs_depth() => {
                return Err(InvalidInput::new(
                    "depth",
                    "is required by `edges` depth and by `predication` (a one-channel depth image)",
                ))
            }
            Some(d) if settings.needs_depth() => {
                if d.len() != n {
                    return Err(InvalidInput::new(
                        "depth",
                        format!("must hold {w}x{h} = {n} values (the colour image's size), got {}", d.len()),
                    ));
                }
                if let Some(i) = d.iter().position(|v| !v.is_finite()) {
                    return Err(InvalidInput::new(
                        "depth",
                        format!("must be finite; pixel ({}, {}) is {}", i % w as usize, i / w as usize, d[i]),
                    ));
                }
            }
            _ => {}
        }
        match self.mask {
            None if masked => return Err(InvalidInput::new("mask", "is required by a masked pass")),
            Some(m) if m.len() != n => {
                return Err(InvalidInput::new(
                    "mask",
                    format!("must hold {w}x{h} = {n} bytes (the colour image's size), got {}", m.len()),
                ))
            }
            _ => {}
        }
        Ok(())
    }
}

/// Uniform block of `smaa_edges.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    cfg: [f32; 4],
    pred: [f32; 4],
}

const SHADER: &str = concat!(
    include_str!("../fullscreen.wgsl"),
    include_str!("srgb.wgsl"),
    include_str!("edges.wgsl"),
    include_str!("edge_store.wgsl")
);

/// Where [`EdgeStage::encode_edges`] writes: the fragment shape's edges target (with the timer slot of the edges
/// pass) or the compute shape's edges storage texture (with the timestamps of the edges slot).
pub(crate) enum EdgeOut<'a> {
    Render(&'a wgpu::TextureView, Option<(&'a gpu::GpuTimer, u32)>),
    Texture(Option<wgpu::ComputePassTimestampWrites<'a>>),
}

/// What the compute shape's edge pass writes (`edge_store.wgsl`): the edges texture (in `format`) the weights pass
/// filters, the list of edge pixels the weights pass runs on (count first) and the weights texture it zeroes.
pub(crate) struct EdgeOutputs<'a> {
    pub edges: &'a wgpu::TextureView,
    pub format: EdgeFormat,
    pub list: &'a wgpu::Buffer,
    pub weights: &'a wgpu::TextureView,
}

/// The GPU side of this module for one pass: the depth and mask textures, the edge pass replacing the pass's
/// luma detector (unless plain luma) and, in the fragment shape, the mask composite (when masked); the edge pass as a
/// fragment or compute pass (the frame's [`PassShape`](super::pass_shape::PassShape); same bytes).
pub(crate) struct EdgeStage {
    settings: EdgeSettings,
    size: (u32, u32),
    depth: Option<wgpu::Texture>,
    mask: Option<wgpu::Texture>,
    edges: Option<ShapedPass>,
    composite: Option<(ShapedPass, wgpu::Texture, wgpu::TextureView)>,
}

impl EdgeStage {
    /// `color` is the pass's input view, `aa_output` its blended output; `lca` the local contrast adaptation
    /// factor (0: none, MLAA). `compute`: what the compute shape's edge pass writes; `None` for the fragment
    /// shape, whose edge pass renders into the edges texture.
    pub(crate) fn new(
        device: &wgpu::Device,
        (width, height): (u32, u32),
        (color, aa_output): (&wgpu::TextureView, &wgpu::TextureView),
        (settings, lca, masked): (&EdgeSettings, f32, bool),
        compute: Option<EdgeOutputs<'_>>,
    ) -> Result<Self, InvalidInput> {
        settings.validate()?;
        use wgpu::TextureFormat as F;
        let depth = settings.needs_depth().then(|| gpu::data_texture(device, "aa depth", width, height, F::R32Float));
        let mask = masked.then(|| gpu::data_texture(device, "aa mask", width, height, F::R8Unorm));
        let pred = settings.predication.unwrap_or_default();
        let metric = if settings.detector == EdgeDetector::Color { 1.0 } else { 0.0 };
        let params = Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            cfg: [COLOR_THRESHOLD, lca, metric, 0.0],
            pred: [pred.threshold, pred.scale, pred.strength, settings.depth_threshold],
        };
        let needs_module = !settings.is_plain_luma() || masked;
        // The fragment shape never binds the edges storage texture: any valid declaration of it will do.
        let format = compute.as_ref().map_or(EdgeFormat::Rgba8, |c| c.format);
        let module = needs_module.then(|| gpu::shader(device, "smaa_edges.wgsl", &format.in_source(SHADER)));
        let ubo = gpu::uniform_buffer(device, "aa edge params", bytemuck::bytes_of(&params));
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let prefix = if compute.is_some() { "cs" } else { "fs" };
        use wgpu::BindingResource as R;
        let edges = match (&module, settings.is_plain_luma()) {
            (Some(module), false) => {
                let entry = match (settings.detector, settings.predication.is_some()) {
                    (EdgeDetector::Depth, _) => "edges_depth",
                    (_, true) => "edges_color_predicated",
                    (_, false) => "edges_color",
                };
                let dv = depth.as_ref().map(view);
                let mut entries = vec![(0, ubo.as_entire_binding())];
                if settings.detector != EdgeDetector::Depth {
                    entries.push((1, R::TextureView(color)));
                }
                if let Some(dv) = &dv {
                    entries.push((2, R::TextureView(dv)));
                }
                if let Some(out) = &compute {
                    let edges = (8, R::TextureView(out.edges));
                    entries.extend([edges, (9, R::TextureView(out.weights)), (11, out.list.as_entire_binding())]);
                }
                Some(ShapedPass::new(device, module, &format!("{prefix}_{entry}"), F::Rg8Unorm, &entries))
            }
            _ => None,
        };
        // The compute shape blends and masks in one pass (`cs_blend_masked` of three_pass.wgsl, [`Self::mask`]).
        let composite = match (&module, &mask, &compute) {
            (Some(module), Some(mask), None) => {
                let out = gpu::texture(device, "aa masked output", width, height, F::Rgba8Unorm);
                let (mv, ov) = (view(mask), view(&out));
                let entries = [(1, R::TextureView(color)), (3, R::TextureView(aa_output)), (4, R::TextureView(&mv))];
                let pass = ShapedPass::new(device, module, "fs_mask", F::Rgba8Unorm, &entries);
                Some((pass, out, ov))
            }
            _ => None,
        };
        Ok(Self { settings: *settings, size: (width, height), depth, mask, edges, composite })
    }

    /// Validates and uploads the depth and mask this stage reads.
    pub(crate) fn upload(&self, queue: &wgpu::Queue, inputs: &AaInputs) -> Result<(), InvalidInput> {
        let (w, h) = self.size;
        inputs.validate(w, h, &self.settings, self.mask.is_some())?;
        if let (Some(t), Some(d)) = (&self.depth, inputs.depth) {
            gpu::upload(queue, t, bytemuck::cast_slice(d));
        }
        if let (Some(t), Some(m)) = (&self.mask, inputs.mask) {
            gpu::upload(queue, t, m);
        }
        Ok(())
    }

    /// Records the edge pass into `out` and returns true, or returns false when the pass's own luma detector is to
    /// run. The compute shape writes the edges texture (two pixels per thread).
    pub(crate) fn encode_edges(&self, enc: &mut wgpu::CommandEncoder, out: EdgeOut<'_>) -> bool {
        let (w, h) = self.size;
        match (&self.edges, out) {
            (Some(ShapedPass::Draw(pipe, bg)), EdgeOut::Render(target, slot)) => {
                gpu::draw_fullscreen(enc, "aa edges", pipe, bg, target, slot)
            }
            (Some(ShapedPass::Dispatch(pipe, bg)), EdgeOut::Texture(writes)) => {
                dispatch(enc, "aa edges", pipe, bg, grid(w.div_ceil(2), h), writes)
            }
            (None, _) => return false,
            _ => unreachable!("the edge stage is built in the frame's shape"),
        }
        true
    }

    /// Records the mask composite (nothing when unmasked).
    pub(crate) fn encode_mask(&self, enc: &mut wgpu::CommandEncoder) {
        if let Some((pass, _, view)) = &self.composite {
            pass.encode(enc, "aa mask", view, self.size, None);
        }
    }

    /// Render passes this stage records (the edge detector and the mask in the fragment shape).
    pub(crate) fn render_passes(&self) -> u32 {
        let mask = self.composite.as_ref().map(|c| &c.0);
        self.edges.iter().chain(mask).map(ShapedPass::render_passes).sum()
    }

    /// Bytes per pixel the edge pass reads (each input image once at its format): the colour (RGBA8) unless the
    /// detector reads depth alone, the depth (`R32Float`) when it reads depth.
    pub(crate) fn edge_input_bytes_per_pixel(&self) -> u64 {
        let colour = if self.settings.detector == EdgeDetector::Depth { 0 } else { 4 };
        colour + if self.settings.needs_depth() { 4 } else { 0 }
    }

    /// Bytes per pixel of the mask (`R8Unorm`) the blending (or the composite) reads, 0 when unmasked.
    pub(crate) fn mask_bytes_per_pixel(&self) -> u64 {
        self.mask.is_some() as u64
    }

    /// The mask texture, when masked (the compute shape's blending pass reads it).
    pub(crate) fn mask(&self) -> Option<&wgpu::Texture> {
        self.mask.as_ref()
    }

    /// The fragment shape's masked output, when masked (the compute shape masks in its blending pass).
    pub(crate) fn masked_output(&self) -> Option<&wgpu::Texture> {
        self.composite.as_ref().map(|c| &c.1)
    }
}
