//! The wrinkle pass of `run skin` (thesis ch. 8, Listing 8.1; Jimenez, Echevarria, Oat & Gutierrez, "Practical
//! and Realistic Facial Wrinkles Animation", GPU Pro 2, 2011): per covered pixel, at the mesh's texture
//! coordinates,
//!
//! ```text
//! xy    = base.xy + Σ_z mask_z(uv)·weight_z·wrinkle.xy(uv)      (Listing 8.1, zones z in Table 8.1 order)
//! n_ts  = normalize(xy, 1)                                       (partial-derivative normals, §8.2)
//! n     = n_ts.x·T + n_ts.y·B + n_ts.z·N,   T = normalize(t − N·(N·t)),   B = w·(N × T)
//! ```
//!
//! with `wrinkle.xy = 2·texel − 1` of the baked PD map and the masks of the two RGBA8 zone-mask maps, both read
//! with bilinear filtering ("linear instead of anisotropic", as the listing's caption says), and (t, w) the mesh's
//! tangent and handedness ([`crate::mesh::tangents`], interpolated by [`crate::runtime::skin::mesh_raster`]). The meshes carry no
//! base normal map, so `base.xy = 0` (a flat base in PD space). Zone weights come from expressions through Table 8.1
//! ([`crate::facial::wrinkles::zone_weights`]: `clamp(Σ_e w_e·W[e][z], 0, 1)`). With every weight 0 the
//! normal is N bit for bit (`n_ts = (0, 0, 1)` exactly), so the frame does not change.
//!
//! The wrinkled normal replaces the G-buffer's before lighting: the Lambert key light, transmittance's E and the
//! specular layer all see it. One compute dispatch over flat f32 buffers (`skin/wrinkles.wgsl`), submitted on its own
//! over a host G-buffer ([`wrinkled_normals`]) or recorded into a frame's command encoder over the device's
//! (`record`); CPU twin
//! [`crate::runtime::skin::wrinkles_cpu`].

use crate::baked_layout::path;
use crate::error::InvalidInput;
use crate::facial::wrinkles::{zone_weights, TABLE_8_1};
use crate::io::PixelFormat;
use crate::runtime::compute_chain::{self, Buffer};
use crate::runtime::gpu;
use crate::runtime::loader::{BakedDir, LutError, LutSpec};
use crate::runtime::skin::mesh_raster::MeshGBuffer;
use crate::runtime::skin::view_frame;
use crate::runtime::RuntimeError;
use std::path::Path;
use std::sync::Arc;

/// The parameter of the wrinkle weights (its flag is in the CLI's table).
pub const WRINKLES_PARAM: &str = "wrinkles";

/// The baked wrinkle maps, decoded: PD slopes `2·texel − 1` and zone masks `texel/255`.
#[derive(Clone, Debug, PartialEq)]
pub struct WrinkleMaps {
    pub pd_size: (u32, u32),
    /// (x, y) slopes per texel, row-major, top row first (DirectX green convention).
    pub pd: Vec<[f32; 2]>,
    pub mask_size: (u32, u32),
    /// Zone masks: `masks[0]` = (red, green, blue, brown), `masks[1]` = (cyan, magenta, orange, gray).
    pub masks: [Vec<[f32; 4]>; 2],
}

impl WrinkleMaps {
    /// Loads the example wrinkle maps of the bake directory through the manifest checks.
    pub fn load(dir: &Path) -> Result<Self, LutError> {
        let baked = BakedDir::open(dir)?;
        let raw = |p: &str, pf: PixelFormat| -> Result<(Vec<u8>, (u32, u32)), LutError> {
            let e = baked
                .manifest()
                .entry(p)
                .ok_or_else(|| LutError::NotInManifest { dir: dir.display().to_string(), path: p.to_string() })?;
            let (w, h) = (e.meta.width, e.meta.height);
            let spec = LutSpec { path: p.to_string(), pixel_format: pf, width: w, height: h };
            Ok((baked.lut(&spec)?, (w, h)))
        };
        let (pd, pd_size) = raw(path::WRINKLE_PD_EXAMPLE, PixelFormat::R8G8Unorm)?;
        let (m0, mask_size) = raw(path::WRINKLE_MASKS_EXAMPLE[0], PixelFormat::R8G8B8A8Unorm)?;
        let (m1, size1) = raw(path::WRINKLE_MASKS_EXAMPLE[1], PixelFormat::R8G8B8A8Unorm)?;
        if size1 != mask_size {
            return Err(LutError::Content {
                path: path::WRINKLE_MASKS_EXAMPLE[1].into(),
                message: format!("{size1:?}, the first mask map is {mask_size:?}"),
            });
        }
        let unorm = |b: u8| b as f32 / 255.0;
        let masks =
            |m: &[u8]| m.chunks_exact(4).map(|c| [unorm(c[0]), unorm(c[1]), unorm(c[2]), unorm(c[3])]).collect();
        Ok(WrinkleMaps {
            pd_size,
            pd: pd.chunks_exact(2).map(|c| [-1.0 + 2.0 * unorm(c[0]), -1.0 + 2.0 * unorm(c[1])]).collect(),
            mask_size,
            masks: [masks(&m0), masks(&m1)],
        })
    }

    pub fn validate(&self) -> Result<(), InvalidInput> {
        let (pw, ph) = self.pd_size;
        let (mw, mh) = self.mask_size;
        let n = (mw * mh) as usize;
        if pw == 0
            || ph == 0
            || self.pd.len() != (pw * ph) as usize
            || n == 0
            || self.masks.iter().any(|m| m.len() != n)
        {
            return Err(InvalidInput::new(
                "wrinkle maps",
                "PD map and masks must be non-empty and of their stated size",
            ));
        }
        Ok(())
    }

    /// Σ_z mask_z(uv)·weight_z at (u, v): where it is 0 the pass leaves the normal as it is.
    pub fn mask_weight_at(&self, u: f32, v: f32, weights: &[f32; 8]) -> f32 {
        let (mw, mh) = self.mask_size;
        let m1 = crate::runtime::sampler::bilinear(&self.masks[0], mw, mh, u, v);
        let m2 = crate::runtime::sampler::bilinear(&self.masks[1], mw, mh, u, v);
        (0..4).map(|k| m1[k] * weights[k] + m2[k] * weights[4 + k]).sum()
    }
}

/// Zone weights (Table 8.1 columns) from `NAME=WEIGHT,…` (`--wrinkles`): NAME one of Table 8.1's expressions (joy,
/// surprise, fear, anger, disgust, sad), WEIGHT in 0..=1 (a blend-shape weight), each name at most once.
pub fn parse_wrinkle_weights(spec: &str) -> Result<[f32; 8], InvalidInput> {
    let known: Vec<&str> = TABLE_8_1.iter().map(|(n, _)| *n).collect();
    let mut pairs: Vec<(&str, f64)> = Vec::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (name, w) = item.split_once('=').ok_or_else(|| {
            InvalidInput::new(WRINKLES_PARAM, format!("{item:?}: expected NAME=WEIGHT with NAME one of {known:?}"))
        })?;
        let name = name.trim();
        if !known.contains(&name) {
            return Err(InvalidInput::new(WRINKLES_PARAM, format!("unknown expression {name:?}; known: {known:?}")));
        }
        if pairs.iter().any(|(n, _)| *n == name) {
            return Err(InvalidInput::new(WRINKLES_PARAM, format!("expression {name:?} given twice")));
        }
        let w: f64 = w.trim().parse().map_err(|_| {
            InvalidInput::new(WRINKLES_PARAM, format!("weight of {name:?} must be a number in 0..=1, got {w:?}"))
        })?;
        crate::error::check_range(WRINKLES_PARAM, w, 0.0, 1.0, &format!("(weight of {name})"))?;
        pairs.push((name, w));
    }
    if pairs.is_empty() {
        return Err(InvalidInput::new(WRINKLES_PARAM, format!("needs NAME=WEIGHT pairs, NAME one of {known:?}")));
    }
    Ok(zone_weights(&pairs)?.map(|v| v as f32))
}

/// The largest per-pixel buffer [`wrinkled_normals`] allocates for a `width`×`height` G-buffer, bytes: the uv and
/// coverage, the normals, the tangents and the result, each one vec4 of f32 per pixel (the PD map and zone masks
/// are the baked maps, independent of the frame).
pub fn largest_buffer_bytes(width: u32, height: u32) -> u64 {
    compute_chain::vec4_per_pixel_bytes(width, height)
}

const SOURCE: &str = include_str!("wrinkles.wgsl");

/// The uniform block of a `width`×`height` frame with `maps` and `weights`, and the masks as one flat buffer.
fn pass_inputs(
    width: u32,
    height: u32,
    maps: &WrinkleMaps,
    weights: &[f32; 8],
) -> (compute_chain::MapParams, Vec<f32>) {
    (pass_params(width, height, maps, weights), pass_masks(maps))
}

/// The pass's uniform block: the frame's and the maps' sizes and the zone weights.
fn pass_params(width: u32, height: u32, maps: &WrinkleMaps, weights: &[f32; 8]) -> compute_chain::MapParams {
    compute_chain::MapParams {
        size: [width as f32, height as f32, maps.pd_size.0 as f32, maps.pd_size.1 as f32],
        cfg: [maps.mask_size.0 as f32, maps.mask_size.1 as f32, 0.0, 0.0],
        weights: [[weights[0], weights[1], weights[2], weights[3]], [weights[4], weights[5], weights[6], weights[7]]],
    }
}

/// The two zone masks one after the other, as the pass binds them.
fn pass_masks(maps: &WrinkleMaps) -> Vec<f32> {
    maps.masks.iter().flatten().flatten().copied().collect()
}

/// The wrinkled view-space normals of `g` (uncovered pixels keep theirs), on the GPU.
pub fn wrinkled_normals(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    g: &MeshGBuffer,
    maps: &WrinkleMaps,
    weights: &[f32; 8],
) -> Result<Vec<[f32; 3]>, RuntimeError> {
    maps.validate()?;
    let (params, masks) = pass_inputs(g.width, g.height, maps, weights);
    let out = view_frame::run(
        device,
        queue,
        "wrinkle pass",
        SOURCE,
        bytemuck::bytes_of(&params),
        g,
        [Buffer::Data(bytemuck::cast_slice(&maps.pd)), Buffer::Data(bytemuck::cast_slice(&masks))],
        largest_buffer_bytes(g.width, g.height),
    )?;
    let f: &[f32] = bytemuck::cast_slice(&out);
    Ok(f.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Records the pass into a frame's command encoder over the device's per-pixel `frame` of a `size` frame
/// ((u, v, covered, coverage), view normal, view tangent: [`view_frame::record`]), writing (wrinkled normal, 0)
/// per pixel into `out`: the maps are uploaded, nothing is read back.
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    size: (u32, u32),
    frame: [&wgpu::Buffer; 3],
    maps: &Arc<WrinkleMaps>,
    weights: &[f32; 8],
    out: &wgpu::Buffer,
) -> Result<(), RuntimeError> {
    maps.validate()?;
    let what = "wrinkle pass";
    let mask_bytes = 4 * maps.masks.iter().map(|m| 4 * m.len() as u64).sum::<u64>();
    compute_chain::check_buffers(device, what, &[8 * maps.pd.len() as u64, mask_bytes])?;
    let params = pass_params(size.0, size.1, maps, weights);
    let key = MapsKey(device.clone(), maps.clone());
    let [a, b] = MAP_BUFFERS.get_or_insert_with(key, || {
        let masks = pass_masks(maps);
        let bytes: [&[u8]; 2] = [bytemuck::cast_slice(&maps.pd), bytemuck::cast_slice(&masks)];
        bytes.map(|m| {
            gpu::count_buffer_upload();
            compute_chain::storage_buffer(device, what, m.len() as u64, Some(m))
        })
    });
    view_frame::record(device, enc, what, SOURCE, bytemuck::bytes_of(&params), size, frame, [&a, &b], out)
}

/// The maps a frame binds, compared by allocation (as the surface maps' cache compares theirs): equal only while
/// they are the same `Arc`, which the kept entry holds, so the allocation cannot be reused by other maps.
struct MapsKey(wgpu::Device, Arc<WrinkleMaps>);

impl PartialEq for MapsKey {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0 && Arc::ptr_eq(&self.1, &other.1)
    }
}

/// Uploaded wrinkle maps kept across frames, per device and maps (a command uses one set).
static MAP_BUFFERS: gpu::Kept<MapsKey, [wgpu::Buffer; 2]> = gpu::Kept::new(4);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_map_to_table_8_1_zone_weights() {
        let w = parse_wrinkle_weights("joy=1").unwrap();
        assert_eq!(w, [1.0, 1.0, 0.2, 0.2, 0.0, 0.0, 0.0, 0.0]);
        // Surprise and anger cancel on the forehead (thesis Fig. 8.5): clamp(0.8 − 0.8, 0, 1) = 0.
        let w = parse_wrinkle_weights("surprise=1, anger=1").unwrap();
        assert_eq!(w[2], 0.0);
        assert_eq!(w[6], 1.0);
        for bad in ["", "smile=1", "joy", "joy=2", "joy=-0.1", "joy=x", "joy=1,joy=0.5"] {
            assert_eq!(parse_wrinkle_weights(bad).unwrap_err().param, WRINKLES_PARAM, "{bad:?}");
        }
    }
}
