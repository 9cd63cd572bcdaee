//! The passes of the thesis' skin shader that `run skin` adds around its SSS shader, chosen
//! per frame: the rig's eq. 7.6 in texture space ([`crate::runtime::skin::mesh_inputs`], thesis §7.6) and the wrinkle pass
//! ([`crate::runtime::skin::wrinkles`], thesis ch. 8 Listing 8.1) before shading, and bloom on the final HDR frame before
//! tone mapping ([`crate::runtime::skin::bloom`], thesis ch. 4), and the G-buffer's sample count (MSAA). The default is the
//! neutral pose, no wrinkles, bloom on and one sample per pixel.

use crate::runtime::skin::bloom::BloomParams;
use crate::runtime::skin::mesh_inputs::RigPose;
use crate::runtime::skin::wrinkles::WrinkleMaps;

/// The wrinkle pass's maps and zone weights (Table 8.1 columns, each in `0..=1`).
#[derive(Clone, Debug, PartialEq)]
pub struct Wrinkles {
    /// Shared: the frame uploads them once per device while the same `Arc` is kept (`wrinkles::record`).
    pub maps: std::sync::Arc<WrinkleMaps>,
    pub zone_weights: [f32; 8],
}

/// What `run skin` adds to the SSS shader of [`crate::runtime::skin::settings::SkinRenderSettings`].
#[derive(Clone, Debug, PartialEq)]
pub struct SkinPasses {
    /// The rig's pose (eq. 7.6 weights and global state); None: the neutral pose (weight 1 on neutral, g = 1).
    pub rig_pose: Option<RigPose>,
    /// The wrinkle pass on the G-buffer's normals; None: no wrinkle pass.
    pub wrinkles: Option<Wrinkles>,
    /// Bloom; None: off.
    pub bloom: Option<BloomParams>,
    /// Samples per pixel of the G-buffer raster, 1 or 4 (MSAA, [`crate::runtime::skin::mesh_raster::RasterJob::samples`]).
    pub msaa: u32,
    /// A scanned head's albedo and tangent-space normal map at the mesh's uv
    /// ([`crate::runtime::skin::surface_maps`]); None: the skin LUT's albedo and the mesh's normals.
    pub surface_maps: Option<crate::runtime::skin::surface_maps::SurfaceMaps>,
}

impl Default for SkinPasses {
    /// `run skin`'s defaults: neutral pose, no wrinkles, bloom on, one sample.
    fn default() -> Self {
        SkinPasses { bloom: Some(BloomParams::default()), ..SkinPasses::none() }
    }
}

impl SkinPasses {
    /// Nothing around the SSS shader: neutral pose, no wrinkles, no bloom, one sample (what
    /// [`crate::runtime::skin::frame::render`] and the Table III benchmark `bench_skin_heads` measure).
    pub fn none() -> Self {
        SkinPasses { rig_pose: None, wrinkles: None, bloom: None, msaa: 1, surface_maps: None }
    }
}
