//! Skin shading inputs on the GPU: hemoglobin from the appearance rig (Jimenez et al., "A Practical Appearance
//! Model for Dynamic Facial Color", SIGGRAPH Asia 2010; thesis eq. 7.6), albedo from the melanin × hemoglobin LUT
//! (eq. 7.7, normalised index u = cbrt(Cm/0.5), v = cbrt(Chd/0.32), node-inclusive), and transmittance T(s)·E
//! through thin regions (Jimenez et al., "Real-Time Realistic Skin Translucency", IEEE CG&A 2010; thesis eq.
//! 5.12–5.13, E = max(0.3 + dot(−N, L), 0)). One fragment pass, two `Rgba16Float` targets ([`SkinInputs::encode`],
//! the per-pass path), or the same arithmetic (`inputs_common.wgsl`) as a compute pass over storage buffers
//! recorded through `compute_chain::record` (`SkinInputs::record_compute`, the one-encoder frames: no copies in
//! or out of textures, and on GPUs with few raster units no full-screen fragment pass). CPU twin
//! [`crate::runtime::skin::inputs_cpu`].

use crate::error::InvalidInput;
use crate::runtime::compute_chain::{self, Stage};
use crate::runtime::frame_pool;
use crate::runtime::gpu;
use crate::runtime::RuntimeError;

/// Melanin volume fraction spanned by the LUT's u axis (thesis Table 7.1).
pub const CM_MAX: f32 = 0.5;
/// Dermal hemoglobin volume fraction spanned by the LUT's v axis (thesis Table 7.1).
pub const CHD_MAX: f32 = 0.32;
/// Largest number of rig targets (weights) the pass takes.
pub const MAX_RIG_TARGETS: usize = 8;

/// The skin LUTs as plain data.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinLuts {
    /// Albedo LUT width (melanin, columns) and height (hemoglobin, rows).
    pub albedo_size: (u32, u32),
    /// Linear RGB albedo, row-major, top row = lowest hemoglobin (v = 0).
    pub albedo: Vec<[f32; 3]>,
    /// T(s) for s = s_max·i/(n−1), i = 0..n−1 (node-inclusive), linear RGB.
    pub transmittance: Vec<[f32; 3]>,
    pub s_max_mm: f32,
}

/// The hemoglobin rig (eq. 7.6): per target i, low-resolution scale_i and bias_i maps.
#[derive(Clone, Debug, PartialEq)]
pub struct RigScaleBiasMaps {
    pub width: u32,
    pub height: u32,
    /// Per target: (scale, bias) per texel, row-major, top row first.
    pub targets: Vec<Vec<[f32; 2]>>,
}

/// Per-pixel inputs of one frame (all top row first, `width × height`).
#[derive(Clone, Debug, PartialEq)]
pub struct SkinFrame {
    pub width: u32,
    pub height: u32,
    /// Melanin volume fraction Cm.
    pub melanin: Vec<f32>,
    /// Mean-free neutral hemoglobin H0 (eq. 7.4).
    pub h0: Vec<f32>,
    /// Thickness s in mm for the transmittance lookup.
    pub thickness_mm: Vec<f32>,
    /// Unit normals.
    pub normals: Vec<[f32; 3]>,
}

fn invalid(param: &str, msg: String) -> InvalidInput {
    InvalidInput::new(param, msg)
}

impl SkinLuts {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let (w, h) = self.albedo_size;
        if w < 2 || h < 2 || self.albedo.len() != (w * h) as usize {
            return Err(invalid(
                "skin LUT",
                format!("needs >= 2x2 texels and {w}x{h} values, got {}", self.albedo.len()),
            ));
        }
        if self.transmittance.len() < 2 {
            return Err(invalid("transmittance table", "needs at least 2 texels".into()));
        }
        crate::error::check_positive("transmittance s_max_mm", self.s_max_mm as f64, "mm")?;
        Ok(())
    }
}

impl RigScaleBiasMaps {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let n = (self.width * self.height) as usize;
        if self.targets.is_empty() || self.targets.len() > MAX_RIG_TARGETS || self.targets.iter().any(|t| t.len() != n)
        {
            return Err(invalid(
                "hemoglobin rig",
                format!("needs 1..={MAX_RIG_TARGETS} targets of {}x{} texels", self.width, self.height),
            ));
        }
        Ok(())
    }
}

impl SkinFrame {
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let n = (self.width * self.height) as usize;
        if self.melanin.len() != n || self.h0.len() != n || self.thickness_mm.len() != n || self.normals.len() != n {
            return Err(invalid("skin frame", format!("all maps must be {}x{}", self.width, self.height)));
        }
        Ok(())
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    light: [f32; 4],
    lut: [f32; 4],
    cfg: [f32; 4],
    weights: [[f32; 4]; 2],
    rows: [f32; 4],
}

const SHADER: &str =
    concat!(include_str!("../fullscreen.wgsl"), include_str!("inputs_common.wgsl"), include_str!("inputs.wgsl"));
const COMPUTE: &str = concat!(include_str!("inputs_common.wgsl"), include_str!("inputs_compute.wgsl"));

fn f16_bytes(v: impl Iterator<Item = f32>) -> Vec<u8> {
    let h: Vec<half::f16> = v.map(half::f16::from_f32).collect();
    bytemuck::cast_slice(&h).to_vec()
}

/// The maps texels of `frame`, (Cm, H0, thickness mm, 0) per pixel.
pub(crate) fn maps_texels(frame: &SkinFrame) -> Vec<[f32; 4]> {
    (0..frame.melanin.len()).map(|i| [frame.melanin[i], frame.h0[i], frame.thickness_mm[i], 0.0]).collect()
}

/// Skin inputs for one frame size, LUTs and rig: the tables (kept per device and content, `TABLES`) and the
/// uniform block; for the fragment pass ([`SkinInputs::new`]) also its targets, input textures and pipeline, which
/// a compute-only frame (`SkinInputs::for_compute`) never creates.
pub struct SkinInputs {
    width: u32,
    height: u32,
    fragment: Option<FragmentPass>,
    /// The compute pass's copies of the rig, the albedo LUT and the T(s) table: the half floats of the textures.
    tables: [wgpu::Buffer; 3],
    params: Params,
}

/// The fragment pass's textures, pipeline, bind group and uniform buffer.
struct FragmentPass {
    maps: wgpu::Texture,
    normals: wgpu::Texture,
    albedo: wgpu::Texture,
    transmitted: wgpu::Texture,
    albedo_view: wgpu::TextureView,
    transmitted_view: wgpu::TextureView,
    pipe: wgpu::RenderPipeline,
    group: wgpu::BindGroup,
    ubo: wgpu::Buffer,
}

/// The half floats of the rig (its layers one after the other), of the albedo LUT and of the T(s) table
/// (Rgba16Float texels), as their textures and the compute pass's tables hold them.
fn table_halves(luts: &SkinLuts, rig: &RigScaleBiasMaps) -> [Vec<u8>; 3] {
    let rig_halves = rig.targets.iter().flat_map(|t| f16_bytes(t.iter().flatten().copied())).collect();
    let lut_halves = f16_bytes(luts.albedo.iter().flat_map(|c| [c[0], c[1], c[2], 1.0]));
    let t_halves = f16_bytes(luts.transmittance.iter().flat_map(|c| [c[0], c[1], c[2], 1.0]));
    [rig_halves, lut_halves, t_halves]
}

/// A 64-bit hash of the tables' content: the key of [`TABLES`] (the LUTs and the rig are small; hashing them is
/// far cheaper than uploading them).
fn tables_key(luts: &SkinLuts, rig: &RigScaleBiasMaps) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    let bits = |v: &mut dyn Iterator<Item = f32>, h: &mut std::collections::hash_map::DefaultHasher| {
        v.for_each(|x| x.to_bits().hash(h))
    };
    (luts.albedo_size, luts.albedo.len(), luts.transmittance.len(), luts.s_max_mm.to_bits()).hash(&mut h);
    bits(&mut luts.albedo.iter().flatten().copied(), &mut h);
    bits(&mut luts.transmittance.iter().flatten().copied(), &mut h);
    (rig.width, rig.height, rig.targets.len()).hash(&mut h);
    bits(&mut rig.targets.iter().flatten().flatten().copied(), &mut h);
    h.finish()
}

/// The compute pass's tables uploaded per (device, content): a command uses one set; a test process a few per
/// device.
static TABLES: gpu::Kept<(wgpu::Device, u64), [wgpu::Buffer; 3]> = gpu::Kept::new(8);

/// Bytes of a padded row of a `width`-texel image of `bytes_per_texel` in a texture copy.
fn padded_row_bytes(width: u32, bytes_per_texel: u32) -> u32 {
    (width * bytes_per_texel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT
}

fn data_texture(
    device: &wgpu::Device,
    label: &str,
    w: u32,
    h: u32,
    layers: u32,
    f: wgpu::TextureFormat,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: f,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

/// Where [`SkinInputs::upload`] takes the maps texture (Cm, H0, thickness) from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapsFrom {
    /// The frame's own values, uploaded from the host.
    Frame,
    /// Written on the device by the caller's pass (the rig at the mesh's uv), not uploaded.
    Device,
}

impl SkinInputs {
    /// The pass with its fragment path (textures, pipeline): [`SkinInputs::encode`], [`SkinInputs::run`] and
    /// the compute pass.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        luts: &SkinLuts,
        rig: &RigScaleBiasMaps,
    ) -> Result<Self, RuntimeError> {
        let mut pass = Self::for_compute(device, width, height, luts, rig)?;
        use wgpu::TextureFormat as F;
        // The per-pixel textures from the frame's pool when a frame is open (each fully written before it is read:
        // the maps and normals uploaded or copied whole, the targets cleared by the pass).
        let maps = frame_pool::data_target(device, "skin maps", width, height, F::Rgba32Float);
        let normals = frame_pool::data_target(device, "skin normals", width, height, F::Rgba32Float);
        let k = rig.targets.len() as u32;
        let [rig_halves, lut_halves, t_halves] = table_halves(luts, rig);
        // At least two layers: the GL backend cannot view a one-layer texture as a 2D array.
        let rig_tex = data_texture(device, "skin rig", rig.width, rig.height, k.max(2), F::Rg16Float);
        let layer_bytes = (4 * rig.width * rig.height) as usize;
        for i in 0..k as usize {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &rig_tex,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: i as u32 },
                    aspect: wgpu::TextureAspect::All,
                },
                &rig_halves[i * layer_bytes..(i + 1) * layer_bytes],
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(rig.width * 4),
                    rows_per_image: Some(rig.height),
                },
                wgpu::Extent3d { width: rig.width, height: rig.height, depth_or_array_layers: 1 },
            );
        }
        let (lw, lh) = luts.albedo_size;
        let lut_tex = gpu::texture(device, "skin albedo LUT", lw, lh, F::Rgba16Float);
        gpu::upload(queue, &lut_tex, &lut_halves);
        let nt = luts.transmittance.len() as u32;
        let t_tex = gpu::texture(device, "skin T(s)", nt, 1, F::Rgba16Float);
        gpu::upload(queue, &t_tex, &t_halves);
        let albedo = frame_pool::target(device, "skin albedo", width, height, F::Rgba16Float);
        let transmitted = frame_pool::target(device, "skin transmitted", width, height, F::Rgba16Float);
        let ubo = frame_pool::uniform_buffer(device, "skin params", bytemuck::bytes_of(&pass.params));
        let module = gpu::shader(device, "skin_inputs.wgsl", SHADER);
        let target = |f| Some(wgpu::ColorTargetState { format: f, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let targets = [target(F::Rgba16Float), target(F::Rgba16Float)];
        let pipe = gpu::fullscreen_pipeline_with(device, "skin inputs", &module, "fs_skin", &targets);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let rig_view = rig_tex.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        use wgpu::BindingResource as R;
        let (mv, nv, lv, tv) = (view(&maps), view(&normals), view(&lut_tex), view(&t_tex));
        let group = gpu::bind_group(
            device,
            "skin inputs",
            &pipe.get_bind_group_layout(0),
            &[
                (0, ubo.as_entire_binding()),
                (1, R::TextureView(&mv)),
                (2, R::TextureView(&nv)),
                (3, R::TextureView(&rig_view)),
                (4, R::TextureView(&lv)),
                (5, R::TextureView(&tv)),
            ],
        );
        let (albedo_view, transmitted_view) = (view(&albedo), view(&transmitted));
        pass.fragment =
            Some(FragmentPass { maps, normals, albedo, transmitted, albedo_view, transmitted_view, pipe, group, ubo });
        Ok(pass)
    }

    /// The pass for a frame that runs it as a compute pass only ([`SkinInputs::record_compute`]): its tables
    /// (uploaded once per device and content while kept) and uniform block, no texture, no pipeline.
    pub(crate) fn for_compute(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        luts: &SkinLuts,
        rig: &RigScaleBiasMaps,
    ) -> Result<Self, RuntimeError> {
        gpu::check_frame(device, width, height, 16)?;
        luts.validate()?;
        rig.validate()?;
        let what = "skin inputs";
        let rig_bytes = 4 * (rig.width * rig.height) as u64 * rig.targets.len() as u64;
        compute_chain::check_buffers(device, what, &[rig_bytes])?;
        let tables = TABLES.get_or_insert_with((device.clone(), tables_key(luts, rig)), || {
            table_halves(luts, rig).map(|b| {
                gpu::count_buffer_upload();
                compute_chain::storage_buffer(device, what, b.len() as u64, Some(&b))
            })
        });
        let (lw, lh) = luts.albedo_size;
        let nt = luts.transmittance.len() as u32;
        let params = Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            light: [0.0, 0.0, 1.0, 0.0],
            lut: [lw as f32, lh as f32, nt as f32, luts.s_max_mm],
            cfg: [rig.targets.len() as f32, 0.0, 0.0, 0.0],
            weights: [[0.0; 4]; 2],
            rows: [
                (padded_row_bytes(width, 16) / 16) as f32,
                (padded_row_bytes(width, 8) / 4) as f32,
                rig.width as f32,
                rig.height as f32,
            ],
        };
        Ok(Self { width, height, fragment: None, tables, params })
    }

    /// Bytes of a padded row of one of the compute pass's two Rgba16Float output images (the layout a
    /// texture-to-buffer copy of [`Self::albedo`] gives).
    pub(crate) fn half_row_bytes(&self) -> u64 {
        padded_row_bytes(self.width, 8) as u64
    }

    fn fragment(&self) -> &FragmentPass {
        self.fragment.as_ref().expect("the fragment pass's textures exist (SkinInputs::new)")
    }

    /// Albedo (rgb) and hemoglobin H (a), `Rgba16Float`.
    pub fn albedo(&self) -> &wgpu::Texture {
        &self.fragment().albedo
    }
    /// T(s)·E (rgb) and E (a), `Rgba16Float`.
    pub fn transmitted(&self) -> &wgpu::Texture {
        &self.fragment().transmitted
    }

    /// The maps texture the pass reads, (Cm, H0, thickness mm, 0) per pixel, `Rgba32Float`: a frame that
    /// computes H on the device writes it there ([`MapsFrom::Device`]).
    pub(crate) fn maps(&self) -> &wgpu::Texture {
        &self.fragment().maps
    }

    /// Uploads a frame and the per-frame rig weights and light direction (unit, towards the light); the maps
    /// texture from the frame with [`MapsFrom::Frame`], or left to the caller to fill on the device
    /// ([`MapsFrom::Device`]).
    pub fn upload(
        &mut self,
        queue: &wgpu::Queue,
        frame: &SkinFrame,
        rig_weights: &[f32],
        light_dir: [f32; 3],
        maps: MapsFrom,
    ) -> Result<(), InvalidInput> {
        frame.validate()?;
        if (frame.width, frame.height) != (self.width, self.height) {
            return Err(invalid("skin frame", format!("must be {}x{}", self.width, self.height)));
        }
        self.upload_lights(queue, rig_weights, light_dir)?;
        let normals: Vec<f32> = frame.normals.iter().flat_map(|v| [v[0], v[1], v[2], 0.0]).collect();
        gpu::upload(queue, &self.fragment().normals, bytemuck::cast_slice(&normals));
        if maps == MapsFrom::Frame {
            gpu::upload(queue, &self.fragment().maps, bytemuck::cast_slice(&maps_texels(frame)));
        }
        Ok(())
    }

    /// The per-frame rig weights and light direction alone: the caller fills the maps and normals on the device.
    pub(crate) fn upload_lights(
        &mut self,
        queue: &wgpu::Queue,
        rig_weights: &[f32],
        light_dir: [f32; 3],
    ) -> Result<(), InvalidInput> {
        if rig_weights.len() != self.params.cfg[0] as usize {
            return Err(invalid(
                "rig_weights",
                format!("needs one weight per rig target ({}), got {}", self.params.cfg[0], rig_weights.len()),
            ));
        }
        let mut w = [[0.0f32; 4]; 2];
        for (i, v) in rig_weights.iter().enumerate() {
            w[i / 4][i % 4] = *v;
        }
        self.params.weights = w;
        self.params.light = [light_dir[0], light_dir[1], light_dir[2], 0.0];
        if let Some(f) = &self.fragment {
            queue.write_buffer(&f.ubo, 0, bytemuck::bytes_of(&self.params));
        }
        Ok(())
    }

    /// Records the pass.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder) {
        let f = self.fragment();
        let att = |v| {
            Some(wgpu::RenderPassColorAttachment {
                view: v,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("skin inputs"),
            color_attachments: &[att(&f.albedo_view), att(&f.transmitted_view)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&f.pipe);
        pass.set_bind_group(0, &f.group, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Records the pass as a compute pass through `compute_chain::record` (`inputs_compute.wgsl`, the fragment
    /// pass's arithmetic) over `maps` (Cm, H0, thickness mm, 0) and `normals` (normal, 0), Rgba32Float rows padded
    /// as [`Self::maps`]'s, writing albedo + H then T(s)·E + E into `out` as two Rgba16Float images with rows padded
    /// as [`Self::albedo`]'s (the layout a texture-to-buffer copy of the two targets gives). The buffers are
    /// [`compute_chain::STORAGE_USAGE`] and at least that large; the rig weights and light are the last uploaded.
    pub(crate) fn record_compute(
        &self,
        device: &wgpu::Device,
        enc: &mut wgpu::CommandEncoder,
        [maps, normals]: [&wgpu::Buffer; 2],
        out: &wgpu::Buffer,
    ) {
        let [rig, lut, t] = &self.tables;
        let bound = [maps, normals, rig, lut, t, out];
        let stages = [Stage::new("main", compute_chain::groups_8x8(self.width, self.height))];
        compute_chain::record(device, enc, "skin inputs", COMPUTE, bytemuck::bytes_of(&self.params), &bound, &stages);
    }

    /// Uploads, runs and reads back (albedo+H, T·E+E) as RGBA f32.
    pub fn run(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &SkinFrame,
        rig_weights: &[f32],
        light_dir: [f32; 3],
    ) -> Result<(Vec<f32>, Vec<f32>), RuntimeError> {
        self.upload(queue, frame, rig_weights, light_dir, MapsFrom::Frame)?;
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("skin") });
        self.encode(&mut enc);
        // One submission, both targets read back with one wait.
        let mut read = gpu::read_textures(device, queue, enc, &[self.albedo(), self.transmitted()])?;
        let transmitted = gpu::f16_to_f32(&read.pop().expect("two targets"));
        Ok((gpu::f16_to_f32(&read.pop().expect("two targets")), transmitted))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::device::{create_headless, DeviceOptions};

    /// A 20×12 frame (rows padded on both sides) with a 5×4 LUT, a 7-texel T(s) and a 3×2 rig of three targets,
    /// values spread so every bilinear weight and clamp occurs.
    fn case() -> (SkinLuts, RigScaleBiasMaps, SkinFrame) {
        let (lw, lh) = (5u32, 4u32);
        let albedo = (0..lw * lh).map(|i| [0.1 + 0.03 * i as f32, 0.7 - 0.02 * i as f32, 0.3 + 0.01 * (i % 3) as f32]);
        let transmittance = (0..7).map(|i| [(-0.5 * i as f32).exp(), (-(i as f32)).exp(), (-2.0 * i as f32).exp()]);
        let luts = SkinLuts {
            albedo_size: (lw, lh),
            albedo: albedo.collect(),
            transmittance: transmittance.collect(),
            s_max_mm: 5.0,
        };
        let target = |k: f32| (0..6).map(|i| [0.8 + 0.1 * k + 0.05 * i as f32, 0.02 * k + 0.01 * i as f32]).collect();
        let rig = RigScaleBiasMaps { width: 3, height: 2, targets: vec![target(0.0), target(1.0), target(2.0)] };
        let (w, h) = (20u32, 12u32);
        let n = (w * h) as usize;
        let at = |i: usize| ((i % w as usize) as f32 / w as f32, (i / w as usize) as f32 / h as f32);
        let frame = SkinFrame {
            width: w,
            height: h,
            melanin: (0..n).map(|i| 0.6 * at(i).0).collect(),
            h0: (0..n).map(|i| 0.3 * at(i).1 - 0.02).collect(),
            thickness_mm: (0..n).map(|i| 6.0 * at(i).0 * at(i).1).collect(),
            normals: (0..n)
                .map(|i| {
                    let a = 6.0 * at(i).0 + at(i).1;
                    [a.cos(), 0.0, a.sin()]
                })
                .collect(),
        };
        (luts, rig, frame)
    }

    /// The compute pass over storage buffers writes the fragment pass's two Rgba16Float images in the padded-row
    /// layout a texture-to-buffer copy of the targets gives: the same f32 arithmetic (`inputs_common.wgsl`), so
    /// every value within one half-float ulp (the render target's conversion and `pack2x16float` may round the
    /// same f32 differently; on llvmpipe about half the albedo values differ by one ulp).
    #[test]
    fn the_compute_pass_writes_the_fragment_pass_half_floats_within_one_ulp() {
        let g = create_headless(&DeviceOptions::default()).expect("an adapter (lavapipe)");
        let (device, queue) = (&g.device, &g.queue);
        let (luts, rig, frame) = case();
        let (weights, light) = ([0.5f32, 0.3, 0.2], [0.0f32, 0.6, -0.8]);
        let mut pass = SkinInputs::new(device, queue, frame.width, frame.height, &luts, &rig).unwrap();
        let (albedo, transmitted) = pass.run(device, queue, &frame, &weights, light).unwrap();

        let (w, h) = (frame.width as usize, frame.height as usize);
        let (row32, row16) =
            (gpu::padded_row_bytes(pass.maps()) as usize, gpu::padded_row_bytes(pass.albedo()) as usize);
        assert!(row32 > 16 * w && row16 > 8 * w, "rows are padded on both sides");
        let padded = |texels: Vec<[f32; 4]>| {
            let mut out = vec![0.0f32; row32 / 4 * h];
            for (y, row) in texels.chunks_exact(w).enumerate() {
                out[y * row32 / 4..][..4 * w].copy_from_slice(bytemuck::cast_slice(row));
            }
            compute_chain::storage_buffer(device, "test", (4 * out.len()) as u64, Some(bytemuck::cast_slice(&out)))
        };
        let maps = padded(maps_texels(&frame));
        let normals = padded(frame.normals.iter().map(|v| [v[0], v[1], v[2], 0.0]).collect());
        let out_bytes = (2 * row16 * h) as u64;
        let out = compute_chain::storage_buffer(device, "test", out_bytes, None);
        let mut enc = device.create_command_encoder(&Default::default());
        pass.record_compute(device, &mut enc, [&maps, &normals], &out);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: out_bytes,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        enc.copy_buffer_to_buffer(&out, 0, &readback, 0, out_bytes);
        gpu::submit(queue, enc.finish());
        let got = gpu::map_read(device, &readback).unwrap();

        for (k, want) in [albedo, transmitted].iter().enumerate() {
            let mut image = Vec::with_capacity(8 * w * h);
            for y in 0..h {
                image.extend_from_slice(&got[(k * h + y) * row16..][..8 * w]);
            }
            let image = gpu::f16_to_f32(&image);
            let ulps = |a: f32, b: f32| {
                let bits = |v: f32| half::f16::from_f32(v).to_bits() as i32;
                (bits(a) - bits(b)).abs()
            };
            let worst = image.iter().zip(want).map(|(a, b)| ulps(*a, *b)).max().unwrap_or(0);
            let at = image.iter().zip(want).position(|(a, b)| ulps(*a, *b) == worst).unwrap_or(0);
            assert!(worst <= 1, "image {k}: {worst} half-float ulps at {at}: {} vs {}", image[at], want[at]);
            assert!(want.iter().any(|v| *v > 0.05), "image {k} is not blank");
        }
    }
}
