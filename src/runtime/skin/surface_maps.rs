//! The scanned head's surface maps in the G-buffer (thesis §7.6; the seeds' demos render the Lee Perry-Smith scan
//! with an albedo and a tangent-space normal map): per covered pixel, at the mesh's texture coordinates,
//!
//! ```text
//! albedo = bilinear(albedo map, uv)                                (linear RGB, decoded from sRGB on the host)
//! n_ts   = normalize(bilinear(normal map, uv))                     (unit tangent-space normal, rtbake's frame)
//! n      = normalize(n_ts.x·T + n_ts.y·B + n_ts.z·N),  B = w·(N × T)
//! ```
//!
//! with (T, w) the MikkTSpace tangent and handedness interpolated by [`crate::runtime::skin::mesh_raster`] and left
//! unnormalised, as MikkTSpace prescribes for the per-pixel frame (Mikkelsen 2008: the bitangent is rebuilt from the
//! cross product and only the result is normalised). Maps are read bilinearly, clamp to edge, texel centres at
//! (i + ½)/size (`bilinear_taps.wgsl`). The albedo is applied **after** the diffusion (post-scatter texturing,
//! thesis §7.6: "lateral color bleeding due to subsurface scattering is already explicitly captured as part of the
//! acquisition process, we use post-scattering texturing to avoid blurring the albedo twice"): it replaces the skin
//! LUT's albedo in [`crate::runtime::skin::lighting`]; the mapped normal replaces the G-buffer's before any lighting
//! (key light, transmittance's E, specular). Without a normal map the normal is the G-buffer's bit for bit.
//!
//! One compute dispatch over flat f32 buffers (`skin/surface_maps.wgsl`), submitted on its own over a host G-buffer
//! ([`surface_pixels`]) or recorded into a frame's command encoder over the device's (`record`); CPU twin
//! [`crate::runtime::skin::surface_maps_cpu`].

use crate::error::InvalidInput;
use crate::image_buf::ImageF32;
use crate::runtime::compute_chain::{self, Buffer};
use crate::runtime::skin::mesh_raster::MeshGBuffer;
use crate::runtime::skin::view_frame;
use crate::runtime::{gpu, RuntimeError};
use std::sync::Arc;

/// The parameter of the albedo map (its flag is in the CLI's table).
pub const ALBEDO_PARAM: &str = "albedo_map";
/// The parameter of the tangent-space normal map (its flag is in the CLI's table).
pub const NORMAL_MAP_PARAM: &str = "normal_map";

/// One decoded map: `width`×`height` texels of (x, y, z, 0), row-major, top row first. The texels are shared
/// (`Arc`): a frame's device keeps their upload for as long as it holds the same allocation (`record`), and
/// changing them (`Arc::make_mut`) while an upload is kept copies them into a new one.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMap {
    pub width: u32,
    pub height: u32,
    pub texels: Arc<Vec<[f32; 4]>>,
}

impl SurfaceMap {
    /// From a 3-channel linear map (`crate::shading::material_maps`' output); `param` names the flag.
    pub fn from_rgb(param: &str, img: &ImageF32) -> Result<Self, InvalidInput> {
        if img.channels != 3 || img.data.len() != (img.width * img.height * 3) as usize || img.width == 0 {
            return Err(InvalidInput::new(param, "needs a decoded 3-channel map of its stated size"));
        }
        let texels = Arc::new(img.data.chunks_exact(3).map(|c| [c[0], c[1], c[2], 0.0]).collect());
        Ok(SurfaceMap { width: img.width, height: img.height, texels })
    }

    /// Bytes of the map as the GPU pass stores it (one vec4 of f32 per texel).
    pub fn buffer_bytes(&self) -> u64 {
        16 * self.width as u64 * self.height as u64
    }
}

/// The scan's albedo (linear RGB) and tangent-space normal map (unit vectors, rtbake's DirectX frame); either may
/// be absent.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMaps {
    pub albedo: Option<SurfaceMap>,
    pub normal: Option<SurfaceMap>,
}

impl SurfaceMaps {
    /// The maps from 8-bit pictures: `albedo` sRGB-encoded, `normal` a tangent-space normal map whose green channel
    /// follows `green` — decoded and validated by [`crate::shading::material_maps`] (RGB or RGBA, edges in
    /// range, a normal map's texels near unit length), refused naming [`ALBEDO_PARAM`] / [`NORMAL_MAP_PARAM`].
    pub fn from_pictures(
        albedo: Option<&crate::image_buf::ImageU8>,
        normal: Option<&crate::image_buf::ImageU8>,
        green: crate::facial::wrinkles::GreenConvention,
    ) -> Result<Self, InvalidInput> {
        use crate::shading::material_maps::{albedo_linear, normals_unit};
        let albedo = match albedo {
            Some(img) => Some(SurfaceMap::from_rgb(ALBEDO_PARAM, &albedo_linear(ALBEDO_PARAM, img)?)?),
            None => None,
        };
        let normal = match normal {
            Some(img) => Some(SurfaceMap::from_rgb(NORMAL_MAP_PARAM, &normals_unit(NORMAL_MAP_PARAM, img, green)?.0)?),
            None => None,
        };
        Ok(SurfaceMaps { albedo, normal })
    }

    /// Checks both maps against a storage-binding limit of `storage` bytes (the GPU pass stores a vec4 of f32 per
    /// texel), naming the flag and the limit.
    pub fn check_fits(&self, storage: u64) -> Result<(), InvalidInput> {
        for (flag, m) in [(ALBEDO_PARAM, &self.albedo), (NORMAL_MAP_PARAM, &self.normal)] {
            let Some(m) = m else { continue };
            if m.buffer_bytes() > storage {
                return Err(InvalidInput::new(
                    flag,
                    format!(
                        "{}x{} texels need a {}-byte storage buffer, over this GPU's limit of {storage} bytes \
                         (max_storage_buffer_binding_size); use a smaller map, or `cpu`",
                        m.width,
                        m.height,
                        m.buffer_bytes()
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// What the pass gives each pixel: the mapped view-space normal (the G-buffer's where not covered or with no
/// normal map) and, with an albedo map, the linear albedo (zero where not covered).
#[derive(Clone, Debug, PartialEq)]
pub struct SurfacedPixels {
    pub normals: Vec<[f32; 3]>,
    pub albedo: Option<Vec<[f32; 3]>>,
}

/// The largest per-pixel buffer [`surface_pixels`] allocates for a `width`×`height` G-buffer, bytes: the result, two
/// vec4 of f32 per pixel (the maps are checked separately: [`SurfaceMap::buffer_bytes`]).
pub fn largest_buffer_bytes(width: u32, height: u32) -> u64 {
    32 * width as u64 * height as u64
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    // frame width, height, albedo width, height
    size: [f32; 4],
    // normal map width, height, has albedo, has normal map
    normal: [f32; 4],
}

/// The stand-in the pass binds for an absent map: one texel, (0, 0, 1) (one allocation, so that its upload is kept
/// with the present map's).
fn flat_map() -> SurfaceMap {
    static FLAT: std::sync::LazyLock<SurfaceMap> =
        std::sync::LazyLock::new(|| SurfaceMap { width: 1, height: 1, texels: Arc::new(vec![[0.0, 0.0, 1.0, 0.0]]) });
    FLAT.clone()
}

/// The uniform block of a `width`×`height` frame and the two maps the pass binds (`flat` for an absent one).
fn pass_inputs<'a>(
    width: u32,
    height: u32,
    maps: &'a SurfaceMaps,
    flat: &'a SurfaceMap,
) -> (Params, &'a SurfaceMap, &'a SurfaceMap) {
    let a = maps.albedo.as_ref().unwrap_or(flat);
    let nm = maps.normal.as_ref().unwrap_or(flat);
    let params = Params {
        size: [width as f32, height as f32, a.width as f32, a.height as f32],
        normal: [
            nm.width as f32,
            nm.height as f32,
            maps.albedo.is_some() as u8 as f32,
            maps.normal.is_some() as u8 as f32,
        ],
    };
    (params, a, nm)
}

/// The pass on the GPU (see the module doc).
pub fn surface_pixels(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    g: &MeshGBuffer,
    maps: &SurfaceMaps,
) -> Result<SurfacedPixels, RuntimeError> {
    maps.check_fits(device.limits().max_storage_buffer_binding_size)?;
    let flat = flat_map();
    let (params, a, nm) = pass_inputs(g.width, g.height, maps, &flat);
    let out = view_frame::run(
        device,
        queue,
        "surface maps",
        SOURCE,
        bytemuck::bytes_of(&params),
        g,
        [
            Buffer::Data(bytemuck::cast_slice(a.texels.as_slice())),
            Buffer::Data(bytemuck::cast_slice(nm.texels.as_slice())),
        ],
        largest_buffer_bytes(g.width, g.height),
    )?;
    let f: &[f32] = bytemuck::cast_slice(&out);
    let normals = f.chunks_exact(8).map(|c| [c[0], c[1], c[2]]).collect();
    let albedo = maps.albedo.as_ref().map(|_| f.chunks_exact(8).map(|c| [c[4], c[5], c[6]]).collect());
    Ok(SurfacedPixels { normals, albedo })
}

const SOURCE: &str = include_str!("surface_maps.wgsl");

/// The texels of the two maps a frame binds, compared by allocation: two keys are equal only while they hold the
/// same `Arc`s, which the kept entry itself holds, so an allocation cannot be freed and reused by other maps while
/// its upload is kept, and texels changed through `Arc::make_mut` move to a new allocation. Hashing the content
/// instead would read both maps every frame (2 × 16 MB for the scan's 1024² maps), the cost the cache avoids.
struct MapsKey(wgpu::Device, [Arc<Vec<[f32; 4]>>; 2]);

impl PartialEq for MapsKey {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0 && self.1.iter().zip(&other.1).all(|(a, b)| Arc::ptr_eq(a, b))
    }
}

/// Uploaded map pairs kept across frames (a command renders one scan; a benchmark or a test a few).
static MAP_BUFFERS: gpu::Kept<MapsKey, [wgpu::Buffer; 2]> = gpu::Kept::new(MAPS_KEPT);
/// Map pairs kept, per process.
const MAPS_KEPT: usize = 6;

/// The two maps on `device` (`flat` for an absent one), uploaded once while the same texels are kept
/// ([`MAP_BUFFERS`]), every frame while [`gpu::object_cache_enabled`] is off; each upload counted in
/// [`gpu::buffers_uploaded_on_this_thread`].
fn map_buffers(device: &wgpu::Device, a: &SurfaceMap, nm: &SurfaceMap) -> [wgpu::Buffer; 2] {
    let key = MapsKey(device.clone(), [a.texels.clone(), nm.texels.clone()]);
    MAP_BUFFERS.get_or_insert_with(key, || {
        [a, nm].map(|m| {
            gpu::count_buffer_upload();
            let bytes: &[u8] = bytemuck::cast_slice(m.texels.as_slice());
            compute_chain::storage_buffer(device, "surface maps", bytes.len() as u64, Some(bytes))
        })
    })
}

/// Records the pass into a frame's command encoder over the device's per-pixel `frame` of a `size` frame
/// ((u, v, covered, coverage), view normal, view tangent: [`view_frame::record`]), writing per pixel (mapped
/// normal, 0), (linear albedo, 0) into `out` (2 vec4 of f32 per pixel): the maps are uploaded on their first
/// frame and kept ([`map_buffers`]), nothing is read back.
pub(crate) fn record(
    device: &wgpu::Device,
    enc: &mut wgpu::CommandEncoder,
    size: (u32, u32),
    frame: [&wgpu::Buffer; 3],
    maps: &SurfaceMaps,
    out: &wgpu::Buffer,
) -> Result<(), RuntimeError> {
    maps.check_fits(device.limits().max_storage_buffer_binding_size)?;
    let flat = flat_map();
    let (params, a, nm) = pass_inputs(size.0, size.1, maps, &flat);
    let params = bytemuck::bytes_of(&params);
    let [a, b] = map_buffers(device, a, nm);
    view_frame::record(device, enc, "surface maps", SOURCE, params, size, frame, [&a, &b], out)
}
