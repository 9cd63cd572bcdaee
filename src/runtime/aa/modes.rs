//! SMAA S2x, T2x and 4x on the GPU (thesis ch. 10; Jimenez, Echevarria, Sousa, Gutierrez, Eurographics 2012):
//! SMAA 1x ([`crate::runtime::aa::smaa::Smaa`]) run per sample with that sample's area-texture slices, then
//! - **S2x** (§10.4.3): two spatial samples at the D3D10.1 standard 2x pattern, SMAA on each, resolved by their mean;
//! - **T2x** (§10.4.4): one sample per frame, alternately jittered, and the temporal resolve of eq. 10.6–10.7:
//!   `w = 0.5·max(0, 1 − K·sqrt(|‖v_c‖ − ‖v_p‖|))`, `c = (1 − w)·c_c + w·c_p`, K = 30 as printed;
//! - **4x** = S2x + T2x: S2x per frame with the temporally jittered 4x offsets, then the T2x resolve.
//!
//! Sample positions and slices, in pixels with y down (the SMAA shader's tables are written with y up):
//!
//! | mode | frame | offsets from the pixel centre | subsample indices |
//! | --- | --- | --- | --- |
//! | 1x | any | (0, 0) | (0, 0, 0, 0) |
//! | S2x | any | (0.25, 0.25), (−0.25, −0.25) | (1, 1, 1, 0), (2, 2, 2, 0) |
//! | T2x | even / odd | (0.25, 0.25) / (−0.25, −0.25) | (1, 1, 1, 0) / (2, 2, 2, 0) |
//! | 4x | even | (0.375, 0.125), (−0.125, −0.375) | (5, 3, 1, 3), (4, 6, 2, 3) |
//! | 4x | odd | (0.125, 0.375), (−0.375, −0.125) | (3, 5, 1, 4), (6, 4, 2, 4) |
//!
//! Velocity (pixels per frame, `v = p(t) − p(t−1)`) enters twice: the resolve reprojects the previous SMAA'd frame
//! to `p − v` (nearest texel), and ‖v‖ in normalised screen units is stored in the colour's alpha as
//! `a = sqrt(5‖v‖)` before SMAA so that SMAA blends it across silhouettes like colour (thesis §10.4.4: "apply SMAA
//! also over the velocity buffer"); eq. 10.6 compares the current and the reprojected alpha. The history is the
//! previous frame's SMAA'd (for 4x: S2x-resolved) image, not the previous resolve.
//!
//! Multisampling: the samples of S2x/4x arrive as one image per sample (the scene is evaluated or rendered at each
//! sample position), which for SMAA is equivalent to a 2× multisampled colour buffer separated into its samples
//! (SMAA's own "separate" pass does exactly that); no multisampled texture is created. The CPU twin is
//! [`crate::runtime::aa::modes_cpu`]; the WGSL is `aa/modes.wgsl`.
//!
//! Every pass takes the frame's [`PassShape`] (the SMAA passes per sample, the S2x average and the temporal resolve:
//! compute passes by default, full-screen fragment passes with `RTBAKE_AA_PASSES=fragment`); the bytes are the same.

use crate::error::InvalidInput;
use crate::runtime::aa::moving_scene::MovingScene;
use crate::runtime::aa::pass_shape::{frame_texture, PassShape, ShapedPass};
use crate::runtime::aa::smaa::{Smaa, SmaaOptions, SmaaTextures, SubsampleIndices, SMAA_PASSES};
use crate::runtime::gpu::{self, GpuTimer};
use crate::runtime::RuntimeError;

/// K of eq. 10.6 as printed in the thesis ("we use a value of 30 for all our examples").
pub const DEFAULT_K: f32 = 30.0;

/// An SMAA mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SmaaMode {
    X1,
    S2x,
    T2x,
    X4,
}

/// One SMAA sample of a frame: where the scene is sampled and which area-texture slices SMAA uses for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeSample {
    /// Offset from the pixel centre, pixels, y down.
    pub offset_px: [f64; 2],
    pub subsample: SubsampleIndices,
}

impl SmaaMode {
    pub const ALL: [Self; 4] = [Self::X1, Self::S2x, Self::T2x, Self::X4];

    pub fn name(self) -> &'static str {
        match self {
            Self::X1 => "1x",
            Self::S2x => "s2x",
            Self::T2x => "t2x",
            Self::X4 => "4x",
        }
    }

    /// Spatial samples per frame (1 or 2).
    pub fn samples_per_frame(self) -> usize {
        match self {
            Self::X1 | Self::T2x => 1,
            Self::S2x | Self::X4 => 2,
        }
    }

    /// Whether the previous frame is reprojected and blended (T2x, 4x).
    pub fn is_temporal(self) -> bool {
        matches!(self, Self::T2x | Self::X4)
    }

    /// The samples of frame `frame` (the table in the module doc).
    pub fn samples(self, frame: u64) -> Vec<ModeSample> {
        let s = |x: f64, y: f64, i: SubsampleIndices| ModeSample { offset_px: [x, y], subsample: i };
        let [a, b] = SubsampleIndices::SMAA_2X;
        let q = SubsampleIndices::SMAA_4X;
        let odd = frame % 2 == 1;
        match (self, odd) {
            (Self::X1, _) => vec![s(0.0, 0.0, SubsampleIndices::SMAA_1X)],
            (Self::S2x, _) => vec![s(0.25, 0.25, a), s(-0.25, -0.25, b)],
            (Self::T2x, false) => vec![s(0.25, 0.25, a)],
            (Self::T2x, true) => vec![s(-0.25, -0.25, b)],
            (Self::X4, false) => vec![s(0.375, 0.125, q[0]), s(-0.125, -0.375, q[1])],
            (Self::X4, true) => vec![s(0.125, 0.375, q[2]), s(-0.375, -0.125, q[3])],
        }
    }

    /// Frame slots a temporal mode alternates between (2), else 1.
    fn slots(self) -> usize {
        if self.is_temporal() {
            2
        } else {
            1
        }
    }
}

impl std::str::FromStr for SmaaMode {
    type Err = InvalidInput;
    fn from_str(s: &str) -> Result<Self, InvalidInput> {
        Self::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| InvalidInput::new("mode", format!("must be one of 1x, s2x, t2x, 4x, got {s:?}")))
    }
}

/// The temporal resolve of T2x and 4x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TemporalResolve {
    /// Reprojection to `p − v` with the velocity weighting of eq. 10.6 (K ≥ 0; K = 0 is reprojection without the
    /// weighting, w = 0.5).
    Reprojected { k: f32 },
    /// The plain 50/50 blend of the current and the previous frame at the same pixel (no reprojection).
    Plain,
}

impl Default for TemporalResolve {
    fn default() -> Self {
        Self::Reprojected { k: DEFAULT_K }
    }
}

impl TemporalResolve {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        match *self {
            Self::Reprojected { k } if !(k.is_finite() && (0.0..=1.0e4).contains(&k)) => {
                Err(InvalidInput::new("k", format!("must be finite and within 0..=10000, got {k}")))
            }
            _ => Ok(()),
        }
    }

    /// The (K, plain) pair of the shader's uniform.
    pub(crate) fn uniform(&self) -> (f32, f32) {
        match *self {
            Self::Reprojected { k } => (k, 0.0),
            Self::Plain => (0.0, 1.0),
        }
    }
}

/// One input frame of a mode: one RGBA8 sRGB-encoded image per sample of [`SmaaMode::samples`] (top row first;
/// alpha is ignored and replaced by the encoded velocity) and the frame's velocity buffer (RG, pixels per frame).
#[derive(Clone, Copy, Debug)]
pub struct ModeFrame<'a> {
    pub samples: &'a [Vec<u8>],
    pub velocity_px: &'a [f32],
}

impl ModeFrame<'_> {
    /// Sample count, sizes and finiteness of the velocities.
    pub fn check(&self, mode: SmaaMode, w: u32, h: u32) -> Result<(), InvalidInput> {
        let n = w as usize * h as usize;
        if self.samples.len() != mode.samples_per_frame() {
            return Err(InvalidInput::new(
                "samples",
                format!(
                    "SMAA {} needs {} sample image(s) per frame, got {}",
                    mode.name(),
                    mode.samples_per_frame(),
                    self.samples.len()
                ),
            ));
        }
        if let Some(s) = self.samples.iter().find(|s| s.len() != 4 * n) {
            return Err(InvalidInput::new(
                "samples",
                format!("must hold {w}x{h} RGBA8 ({} bytes), got {}", 4 * n, s.len()),
            ));
        }
        if self.velocity_px.len() != 2 * n {
            return Err(InvalidInput::new(
                "velocity",
                format!("must hold {w}x{h} RG values ({}), got {}", 2 * n, self.velocity_px.len()),
            ));
        }
        if let Some(i) = self.velocity_px.iter().position(|v| !v.is_finite()) {
            return Err(InvalidInput::new(
                "velocity",
                format!(
                    "must be finite, pixel ({}, {}) is {}",
                    (i / 2) % w as usize,
                    (i / 2) / w as usize,
                    self.velocity_px[i]
                ),
            ));
        }
        Ok(())
    }
}

/// `a = sqrt(5‖v‖)` with ‖v‖ the length of `v_px` in normalised screen units (SMAA's velocity-in-alpha encoding,
/// stored as UNORM8).
pub fn velocity_alpha(v_px: [f32; 2], w: u32, h: u32) -> u8 {
    let (x, y) = (v_px[0] / w as f32, v_px[1] / h as f32);
    crate::runtime::sampler::unorm8((5.0 * (x * x + y * y).sqrt()).sqrt())
}

/// A copy of `rgba` with alpha replaced by [`velocity_alpha`] of each pixel.
pub fn with_velocity_alpha(rgba: &[u8], velocity_px: &[f32], w: u32, h: u32) -> Vec<u8> {
    let mut out = rgba.to_vec();
    for (p, v) in out.chunks_mut(4).zip(velocity_px.chunks(2)) {
        p[3] = velocity_alpha([v[0], v[1]], w, h);
    }
    out
}

/// The inputs of frame `frame` of the [`MovingScene`] sequence for `mode`: the scene sampled at each of the
/// frame's sample offsets at time `frame`, and its velocity buffer at the pixel centres.
pub fn scene_frame(scene: &MovingScene, mode: SmaaMode, frame: u64) -> (Vec<Vec<u8>>, Vec<f32>) {
    let t = frame as f64;
    let samples = mode.samples(frame).iter().map(|s| scene.render(t, s.offset_px)).collect();
    (samples, scene.velocity(t))
}

/// The displayed image of a mode's output: alpha (the encoded velocity) set to 255.
pub fn opaque(mut rgba: Vec<u8>) -> Vec<u8> {
    rgba.chunks_mut(4).for_each(|p| p[3] = 255);
    rgba
}

/// Peak memory (bytes) and wall time (s) of `rtbake run smaa --mode` on `frames` frames of `w`×`h`, `kept` of
/// which are held for writing: per sample the SMAA 1x figures of [`crate::runtime::chain::antialias_estimate`] (0.8 µs/px on
/// the CPU path, a tenth of it plus 1 s of set-up on the GPU), doubled for the scene or file decoding and the
/// resolves; memory 24 B/px per sample plus 12 B/px of velocity and history, 4 B/px per kept frame, 32 MiB.
pub fn estimate(w: u32, h: u32, mode: SmaaMode, frames: u64, kept: u64, gpu: bool) -> (u64, f64) {
    let px = w as f64 * h as f64;
    let n = mode.samples_per_frame() as f64;
    let cpu_s = 2.0 * 0.8e-6 * px * n * frames as f64;
    let seconds = if gpu { 1.0 + 0.1 * cpu_s + 0.4e-6 * px * n * frames as f64 } else { 0.2 + cpu_s };
    let bytes = (24.0 * n + 12.0 + 4.0 * kept as f64) * px + (32u64 << 20) as f64;
    (bytes as u64, seconds)
}

/// Uniform block of `smaa_temporal.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    resolve: [f32; 4],
}

const SHADER: &str = concat!(include_str!("../fullscreen.wgsl"), include_str!("srgb.wgsl"), include_str!("modes.wgsl"));

/// The SMAA passes of one frame slot and, for two samples, their S2x average.
struct Slot {
    passes: Vec<Smaa>,
    average: Option<(wgpu::Texture, wgpu::TextureView, ShapedPass)>,
}

impl Slot {
    fn result(&self) -> &wgpu::Texture {
        match &self.average {
            Some((t, _, _)) => t,
            None => self.passes[0].output(),
        }
    }
}

/// One SMAA mode for one frame size, with its history. Create once, then per frame [`Self::upload`],
/// [`Self::encode`], submit, [`Self::advance`] (or [`Self::run_frame`]).
pub struct SmaaModes {
    mode: SmaaMode,
    resolve: TemporalResolve,
    width: u32,
    height: u32,
    slots: Vec<Slot>,
    velocity: wgpu::Texture,
    ubo: wgpu::Buffer,
    /// Temporal modes: the resolve target and its pass per slot (current = that slot).
    temporal: Option<(wgpu::Texture, wgpu::TextureView, Vec<ShapedPass>)>,
    frame: u64,
}

impl SmaaModes {
    /// The passes in the shape `RTBAKE_AA_PASSES` names ([`PassShape::from_env`]).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        luts: &SmaaTextures,
        mode: SmaaMode,
        resolve: TemporalResolve,
    ) -> Result<Self, RuntimeError> {
        let shape = PassShape::from_env()?;
        Self::with_shape(device, queue, (width, height), luts, (mode, resolve), shape)
    }

    /// As [`Self::new`] in the given [`PassShape`] (same output bytes).
    pub fn with_shape(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        luts: &SmaaTextures,
        (mode, resolve): (SmaaMode, TemporalResolve),
        shape: PassShape,
    ) -> Result<Self, RuntimeError> {
        gpu::check_frame(device, width, height, 8)?;
        resolve.validate()?;
        use wgpu::BindingResource as R;
        use wgpu::TextureFormat as F;
        let module = gpu::shader(device, "smaa_temporal.wgsl", SHADER);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (k, plain) = resolve.uniform();
        let params = Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            resolve: [k, plain, 0.0, 0.0],
        };
        let ubo = gpu::uniform_buffer(device, "smaa temporal params", bytemuck::bytes_of(&params));
        let mut slots = Vec::new();
        // The shape the SMAA passes took (a frame too large for the compute shape's buffers takes the fragment one).
        let mut shape = shape;
        for s in 0..mode.slots() {
            let passes = mode
                .samples(s as u64)
                .into_iter()
                .map(|m| {
                    let options = SmaaOptions { subsample: m.subsample, ..Default::default() };
                    Smaa::with_shape(device, queue, (width, height), luts, &options, shape)
                })
                .collect::<Result<Vec<_>, _>>()?;
            shape = passes[0].shape();
            let average = (passes.len() == 2).then(|| {
                let t = frame_texture(device, "smaa s2x resolve", (width, height), shape);
                let v = view(&t);
                let (a, b) = (view(passes[0].output()), view(passes[1].output()));
                let mut entries = vec![(1, R::TextureView(&a)), (2, R::TextureView(&b))];
                if shape == PassShape::Compute {
                    entries.extend([(0, ubo.as_entire_binding()), (4, R::TextureView(&v))]);
                }
                let entry = if shape == PassShape::Compute { "cs_average" } else { "fs_average" };
                let pass = ShapedPass::new(device, &module, entry, F::Rgba8Unorm, &entries);
                (t, v, pass)
            });
            slots.push(Slot { passes, average });
        }
        let velocity = gpu::data_texture(device, "smaa velocity", width, height, F::Rg32Float);
        let temporal = mode.is_temporal().then(|| {
            let out = frame_texture(device, "smaa temporal resolve", (width, height), shape);
            let out_view = view(&out);
            let vel_view = view(&velocity);
            let passes = (0..2)
                .map(|s| {
                    let (cur, prev) = (view(slots[s].result()), view(slots[1 - s].result()));
                    let mut entries = vec![
                        (0, ubo.as_entire_binding()),
                        (1, R::TextureView(&cur)),
                        (2, R::TextureView(&prev)),
                        (3, R::TextureView(&vel_view)),
                    ];
                    if shape == PassShape::Compute {
                        entries.push((4, R::TextureView(&out_view)));
                    }
                    let entry = if shape == PassShape::Compute { "cs_resolve" } else { "fs_resolve" };
                    ShapedPass::new(device, &module, entry, F::Rgba8Unorm, &entries)
                })
                .collect();
            (out, out_view, passes)
        });
        Ok(Self { mode, resolve, width, height, slots, velocity, ubo, temporal, frame: 0 })
    }

    /// The shape the passes were built in.
    pub fn shape(&self) -> PassShape {
        self.slots[0].passes[0].shape()
    }

    /// Render (fragment) passes one frame records: none in the compute shape.
    pub fn render_passes(&self) -> u32 {
        let slot = &self.slots[self.slot()];
        let smaa: u32 = slot.passes.iter().map(|p| p.render_passes()).sum();
        let average = slot.average.as_ref().map_or(0, |a| a.2.render_passes());
        let temporal = self.temporal.as_ref().map_or(0, |t| t.2[self.slot()].render_passes());
        smaa + average + temporal
    }

    pub fn mode(&self) -> SmaaMode {
        self.mode
    }

    pub fn resolve(&self) -> TemporalResolve {
        self.resolve
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Index of the frame the next [`Self::upload`] belongs to.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    fn slot(&self) -> usize {
        (self.frame % self.slots.len() as u64) as usize
    }

    /// Number of timestamp slots [`Self::encode`] records: 3 per SMAA sample, then the S2x average, then the
    /// temporal resolve.
    pub fn timed_passes(&self) -> u32 {
        let s = &self.slots[0];
        SMAA_PASSES * s.passes.len() as u32 + s.average.is_some() as u32 + self.temporal.is_some() as u32
    }

    /// The displayed image of the last encoded frame (`Rgba8Unorm`, sRGB-encoded; alpha holds the encoded
    /// velocity).
    pub fn output(&self) -> &wgpu::Texture {
        match &self.temporal {
            Some((t, _, _)) => t,
            None => self.slots[0].result(),
        }
    }

    /// Uploads the current frame's samples (alpha replaced by the encoded velocity) and velocity.
    pub fn upload(&self, queue: &wgpu::Queue, frame: &ModeFrame<'_>) -> Result<(), InvalidInput> {
        let (w, h) = (self.width, self.height);
        frame.check(self.mode, w, h)?;
        for (pass, rgba) in self.slots[self.slot()].passes.iter().zip(frame.samples) {
            pass.upload(queue, &with_velocity_alpha(rgba, frame.velocity_px, w, h))?;
        }
        gpu::upload(queue, &self.velocity, bytemuck::cast_slice(frame.velocity_px));
        let (k, plain) = self.resolve.uniform();
        let has_history = if self.frame > 0 { 1.0 } else { 0.0 };
        let params =
            Params { rt: [1.0 / w as f32, 1.0 / h as f32, w as f32, h as f32], resolve: [k, plain, has_history, 0.0] };
        queue.write_buffer(&self.ubo, 0, bytemuck::bytes_of(&params));
        Ok(())
    }

    /// Records the current frame's passes; `timer` slots `first..first + timed_passes()` receive their timestamps.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, timer: Option<(&GpuTimer, u32)>) {
        let slot = &self.slots[self.slot()];
        let mut k = 0u32;
        for pass in &slot.passes {
            pass.encode(enc, timer.map(|(t, first)| (t, first + k)));
            k += SMAA_PASSES;
        }
        let at = |k: u32| timer.map(|(t, first)| (t, first + k));
        let size = (self.width, self.height);
        if let Some((_, v, pass)) = &slot.average {
            pass.encode(enc, "smaa s2x average", v, size, at(k));
            k += 1;
        }
        if let Some((_, v, passes)) = &self.temporal {
            passes[self.slot()].encode(enc, "smaa temporal resolve", v, size, at(k));
        }
    }

    /// Ends the current frame: the next upload belongs to the next frame (the current result becomes history).
    pub fn advance(&mut self) {
        self.frame += 1;
    }

    /// Uploads, runs and reads back one frame, then advances.
    pub fn run_frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &ModeFrame<'_>,
    ) -> Result<Vec<u8>, RuntimeError> {
        self.upload(queue, frame)?;
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("smaa modes") });
        self.encode(&mut enc, None);
        queue.submit([enc.finish()]);
        let out = gpu::read_texture(device, queue, self.output())?;
        self.advance();
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_tables_match_the_smaa_shader_and_cancel_out() {
        // Each mode's offsets over its frames average to the pixel centre, and S2x's slices are T2x's.
        for mode in SmaaMode::ALL {
            let frames = if mode.is_temporal() { 2 } else { 1 };
            let all: Vec<ModeSample> = (0..frames).flat_map(|f| mode.samples(f)).collect();
            assert_eq!(all.len(), frames as usize * mode.samples_per_frame());
            let mean = |k: usize| all.iter().map(|s| s.offset_px[k]).sum::<f64>() / all.len() as f64;
            assert_eq!((mean(0), mean(1)), (0.0, 0.0), "{mode:?}");
            all.iter().for_each(|s| s.subsample.validate().unwrap());
        }
        let s2x: Vec<_> = SmaaMode::S2x.samples(0).into_iter().map(|s| s.subsample).collect();
        let t2x: Vec<_> = (0..2).map(|f| SmaaMode::T2x.samples(f)[0].subsample).collect();
        assert_eq!(s2x, t2x);
        assert_eq!("T2X".parse::<SmaaMode>().unwrap(), SmaaMode::T2x);
        assert_eq!("8x".parse::<SmaaMode>().unwrap_err().param, "mode");
    }

    #[test]
    fn velocity_alpha_encodes_sqrt_of_5_times_the_normalised_length() {
        assert_eq!(velocity_alpha([0.0, 0.0], 100, 50), 0);
        // ‖v‖ = 0.2 screen units → a = 1.
        assert_eq!(velocity_alpha([20.0, 0.0], 100, 50), 255);
        assert_eq!(velocity_alpha([0.0, 10.0], 100, 50), 255);
        // 0.05 → sqrt(0.25) = 0.5.
        assert_eq!(velocity_alpha([3.0, 4.0], 100, 100), 128);
    }

    #[test]
    fn frames_with_wrong_sample_count_sizes_or_non_finite_velocity_are_refused() {
        let img = vec![vec![0u8; 4 * 6]];
        let v = vec![0.0f32; 12];
        assert!(ModeFrame { samples: &img, velocity_px: &v }.check(SmaaMode::T2x, 3, 2).is_ok());
        assert_eq!(
            ModeFrame { samples: &img, velocity_px: &v }.check(SmaaMode::S2x, 3, 2).unwrap_err().param,
            "samples"
        );
        assert_eq!(
            ModeFrame { samples: &img, velocity_px: &v[..10] }.check(SmaaMode::X1, 3, 2).unwrap_err().param,
            "velocity"
        );
        let mut bad = v.clone();
        bad[5] = f32::INFINITY;
        let e = ModeFrame { samples: &img, velocity_px: &bad }.check(SmaaMode::X1, 3, 2).unwrap_err();
        assert!(e.message.contains("(2, 0)"), "{}", e.message);
        assert!(TemporalResolve::Reprojected { k: f32::NAN }.validate().is_err());
    }
}
