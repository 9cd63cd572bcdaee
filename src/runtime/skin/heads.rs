//! Heads from a triangle mesh, the geometry every `run skin` shader shares (TAP 2009 §5; thesis ch. 5 Listing 5.1):
//! the row of heads, its G-buffer ([`crate::runtime::skin::mesh_raster`], with the wrinkle pass and the rig's
//! hemoglobin at the mesh's uv when asked), the back light's shadow map and the thickness it gives, the
//! Kelemen/Szirmay-Kalos specular layer, and the MSAA coverage blend.

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::mesh::camera::Camera;
use crate::mesh::Mesh;
use crate::runtime::backend::Backend;
use crate::runtime::sampler;
use crate::runtime::skin::inputs::SkinFrame;
use crate::runtime::skin::lighting::{key_light_view, DemoAssets, Geometry, RigAtUvPixels, KEY_LIGHT_INTENSITY};
use crate::runtime::skin::mesh_raster::{self, MeshGBuffer, RasterJob};
use crate::runtime::skin::mesh_raster_cpu;
use crate::runtime::skin::passes::SkinPasses;
use crate::runtime::skin::settings::{
    SkinRenderSettings, HEAD_SPACING_M, SHADOW_MAP_SIZE, SHADOW_SHRINK_MM, WORLD_UNITS_PER_M,
};
use crate::runtime::RuntimeError;
use nalgebra::{Matrix4, Vector3, Vector4};

/// The background colour, RGBA8 sRGB.
pub(crate) const BACKGROUND: [u8; 4] = [46, 48, 52, 255];

/// `heads` copies of `mesh`, `HEAD_SPACING_M` apart along x, centred on x = 0 (mesh units are converted with
/// `mm_per_unit`).
pub fn row_of_heads(mesh: &Mesh, heads: u32) -> Result<Mesh, InvalidInput> {
    if heads == 1 {
        return Ok(mesh.clone());
    }
    let spacing = HEAD_SPACING_M * 1000.0 / mesh.mm_per_unit;
    let n = mesh.positions.len() as u32;
    let (mut pos, mut nrm, mut uvs, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..heads {
        let dx = (k as f32 - 0.5 * (heads - 1) as f32) * spacing;
        pos.extend(mesh.positions.iter().map(|p| [p[0] + dx, p[1], p[2]]));
        nrm.extend_from_slice(&mesh.normals);
        uvs.extend_from_slice(&mesh.uvs);
        idx.extend(mesh.indices.iter().map(|i| i + k * n));
    }
    Mesh::new("heads", pos, nrm, uvs, idx, mesh.mm_per_unit)
}

/// The light camera of the shadow map: 1.5 m from the heads towards the back light (`back`, view space), looking at
/// them.
pub(crate) fn light_camera(cam: &Camera, back: [f32; 3]) -> Camera {
    // View → world for directions: the transpose of the view rotation.
    let view = cam.view();
    let l = Vector3::from(back);
    let rot = view.fixed_view::<3, 3>(0, 0).transpose();
    let dir = rot * l;
    let target = Vector3::from(cam.target);
    let eye = target + dir * 1.5;
    Camera { eye: eye.into(), target: cam.target, up: [0.0, 1.0, 0.0], fov_y_deg: 40.0, near: 0.3, far: 3.0 }
}

/// The view-space ray through the centre of pixel `i` of a `w`×`h` image, scaled to view depth 1 (z = −1).
pub(crate) fn view_ray(cam: &Camera, w: u32, h: u32, i: usize) -> [f32; 3] {
    let t = (0.5 * cam.fov_y_deg.to_radians()).tan();
    let aspect = w as f32 / h as f32;
    let (px, py) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
    let (xn, yn) = (px / w as f32 * 2.0 - 1.0, 1.0 - py / h as f32 * 2.0);
    [xn * t * aspect, yn * t, -1.0]
}

/// The back light's shadow map (linear depth in mm from the light), and the thickness it gives (Listing 5.1).
pub(crate) struct ShadowMap {
    map: MeshGBuffer,
    light_view: Matrix4<f32>,
    light_vp: Matrix4<f32>,
    mm_per_unit: f32,
}

impl ShadowMap {
    /// The shadow map `map` rasterised by [`light_camera`] for the back light `back` of the frame seen by `cam`,
    /// of a mesh of `mm_per_unit`.
    fn new(map: MeshGBuffer, cam: &Camera, back: [f32; 3], mm_per_unit: f32) -> Self {
        let light = light_camera(cam, back);
        let light_view = light.view();
        Self { map, light_view, light_vp: light.projection(1.0) * light_view, mm_per_unit }
    }

    /// The thickness (mm) the back light crosses to reach the surface point `p_world` with unit normal `n_world`
    /// (mesh units): Listing 5.1's distance between the point, shrunk 5 mm along its normal so that the surface
    /// facing the light does not read its own depth back as a thickness (acne), and the shadow map's nearest
    /// surface along the same light ray; 0 outside the map or where it saw nothing.
    pub(crate) fn thickness_mm(&self, p_world: [f32; 3], n_world: [f32; 3]) -> f32 {
        let shrink = SHADOW_SHRINK_MM / self.mm_per_unit;
        let p = Vector4::new(
            p_world[0] - n_world[0] * shrink,
            p_world[1] - n_world[1] * shrink,
            p_world[2] - n_world[2] * shrink,
            1.0,
        );
        let c = self.light_vp * p;
        let s = SHADOW_MAP_SIZE as f32;
        let (sx, sy) = ((c.x / c.w * 0.5 + 0.5) * s, (0.5 - c.y / c.w * 0.5) * s);
        let d_light_mm = -(self.light_view * p).z * self.mm_per_unit;
        let (ix, iy) = (sx.floor() as i64, sy.floor() as i64);
        let inside = (0..SHADOW_MAP_SIZE as i64).contains(&ix) && (0..SHADOW_MAP_SIZE as i64).contains(&iy);
        let j = (iy * SHADOW_MAP_SIZE as i64 + ix) as usize;
        if inside && self.map.covered[j] {
            (d_light_mm - self.map.depth_mm[j]).max(0.0)
        } else {
            0.0
        }
    }
}

/// Per covered pixel of `g` (seen by `cam`), the thickness (mm) the back light crosses to reach it
/// ([`ShadowMap::thickness_mm`] of the pixel's world position and normal).
fn thickness_mm(g: &MeshGBuffer, cam: &Camera, shadow: &ShadowMap, mm_per_unit: f32) -> Vec<f32> {
    let (w, h) = (g.width, g.height);
    let inv_view = cam.view().try_inverse().expect("a look-at view is invertible");
    let mut out = vec![0.0f32; (w * h) as usize];
    for (i, o) in out.iter_mut().enumerate() {
        if !g.covered[i] {
            continue;
        }
        let ray = view_ray(cam, w, h, i);
        let depth = g.depth_mm[i] / mm_per_unit;
        let p = inv_view * Vector4::new(ray[0] * depth, ray[1] * depth, -depth, 1.0);
        let nv = g.normal_view[i];
        let n = inv_view * Vector4::new(nv[0], nv[1], nv[2], 0.0);
        *o = shadow.thickness_mm([p.x, p.y, p.z], [n.x, n.y, n.z]);
    }
    out
}

/// The Kelemen/Szirmay-Kalos specular of skin under the key light per covered pixel (view space: V points from
/// the surface to the eye at the origin), scaled like the diffuse layer's key light.
pub fn specular_layer(g: &MeshGBuffer, cam: &Camera) -> Vec<f32> {
    specular_layer_lit(g, cam, key_light_view())
}

/// [`specular_layer`] under the key light `l` (view space, unit).
pub fn specular_layer_lit(g: &MeshGBuffer, cam: &Camera, l: [f32; 3]) -> Vec<f32> {
    use crate::shading::kelemen::{specular, SKIN_F0, SKIN_RHO_S, SKIN_ROUGHNESS};
    let (w, h) = (g.width, g.height);
    (0..(w * h) as usize)
        .map(|i| {
            if !g.covered[i] {
                return 0.0;
            }
            // The view ray through the pixel, reversed: from the surface to the eye.
            let ray = view_ray(cam, w, h, i);
            let d = [-ray[0], -ray[1], 1.0];
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let v = [d[0] / len, d[1] / len, d[2] / len];
            KEY_LIGHT_INTENSITY * specular(g.normal_view[i], l, v, SKIN_ROUGHNESS, SKIN_RHO_S, SKIN_F0)
        })
        .collect()
}

/// The geometry of the heads' frame (see the module doc): skin inputs, view depth in metres, skin mask; the
/// G-buffer it came from and the back light's shadow map. With `rig_in_frame_encoder` the baked rig's hemoglobin
/// at the mesh's uv is left to the frame's command encoder ([`Geometry::rig_at_uv`], `frame.h0` 0); otherwise
/// it is evaluated here, on `gpu` or its CPU twin.
pub(crate) fn geometry(
    gpu: Backend<'_>,
    mesh: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
    rig_in_frame_encoder: bool,
) -> Result<(Geometry, MeshGBuffer, ShadowMap), RuntimeError> {
    let cam = s.camera();
    let (w, h, msaa) = (s.width, s.height, passes.msaa);
    // The view's G-buffer and the back light's shadow map (one sample), on a device in one submission.
    let light = light_camera(&cam, assets.lights.back_view);
    let (s_map, one) = (SHADOW_MAP_SIZE, 1);
    let light_tangents = crate::mesh::tangents::vertex_tangents(mesh);
    // A normal map is baked in MikkTSpace: the mesh's frame, with vertices split where its corners disagree.
    let mikk = passes.surface_maps.as_ref().map(|_| crate::mesh::tangents::mikktspace_tangents(mesh));
    let (split, tangents) = match &mikk {
        Some((m, t)) => (m, t.as_slice()),
        None => (mesh, light_tangents.as_slice()),
    };
    let (mut g, shadow_map) = gpu.run(
        |d| {
            let jobs = [
                RasterJob { mesh: split, tangents, camera: &cam, width: w, height: h, samples: msaa },
                RasterJob {
                    mesh,
                    tangents: &light_tangents,
                    camera: &light,
                    width: s_map,
                    height: s_map,
                    samples: one,
                },
            ];
            let mut maps = mesh_raster::rasterise_jobs(&d.device, &d.queue, &jobs)?;
            let shadow = maps.pop().expect("two G-buffers");
            Ok((maps.pop().expect("two G-buffers"), shadow))
        },
        || {
            let g = mesh_raster_cpu::rasterise_with_tangents(split, tangents, &cam, w, h, msaa)?;
            Ok((g, mesh_raster_cpu::rasterise(mesh, &light, s_map, s_map)))
        },
    )?;
    let mut albedo = None;
    if let Some(maps) = &passes.surface_maps {
        let px = crate::runtime::chain::surface_pixels_for(gpu, &g, maps)?;
        g.normal_view = px.normals;
        albedo = px.albedo;
    }
    if let Some(w) = &passes.wrinkles {
        g.normal_view = crate::runtime::chain::wrinkled_normals_for(gpu, &g, &w.maps, &w.zone_weights)?;
    }
    let shadow = ShadowMap::new(shadow_map, &cam, assets.lights.back_view, mesh.mm_per_unit);
    let thickness = thickness_mm(&g, &cam, &shadow, mesh.mm_per_unit);
    let specular = specular_layer_lit(&g, &cam, assets.lights.key_view);
    let n = (s.width * s.height) as usize;
    let mut frame = SkinFrame {
        width: s.width,
        height: s.height,
        melanin: vec![0.0; n],
        h0: vec![0.0; n],
        thickness_mm: vec![assets.luts.s_max_mm; n],
        normals: vec![[0.0, 0.0, 1.0]; n],
    };
    let (mut hemoglobin, mut rig_at_uv) = (None, None);
    if let Some(r) = &assets.baked_rig {
        let neutral = crate::runtime::skin::mesh_inputs::RigPose::neutral(r.names.len());
        let pose = passes.rig_pose.as_ref().unwrap_or(&neutral);
        if rig_in_frame_encoder {
            rig_at_uv = Some(RigAtUvPixels { uv: g.uv.clone(), pose: pose.clone() });
        } else {
            hemoglobin = Some(crate::runtime::chain::hemoglobin_for_gbuffer(gpu, &g, r, pose)?);
        }
    }
    let mut depth = vec![100.0f32; n];
    for i in 0..n {
        if !g.covered[i] {
            continue;
        }
        frame.melanin[i] = s.melanin;
        frame.h0[i] = match (&hemoglobin, &rig_at_uv) {
            (Some(hb), _) => hb[i],
            (None, Some(_)) => 0.0,
            (None, None) => 0.006 * ((g.uv[i][0] * 400.0).sin() * (g.uv[i][1] * 300.0).cos()),
        };
        frame.thickness_mm[i] = thickness[i].min(assets.luts.s_max_mm);
        frame.normals[i] = g.normal_view[i];
        depth[i] = g.depth_mm[i] / 1000.0 * WORLD_UNITS_PER_M;
    }
    let skin = g.covered.clone();
    Ok((Geometry { frame, depth, skin, specular: Some(specular), albedo, rig_at_uv }, g, shadow))
}

/// MSAA: partly covered pixels of `frame` blend the shaded skin with the background by their `coverage`, in linear
/// light.
pub(crate) fn blend_coverage(frame: &mut Image<u8>, coverage: &[f32]) {
    for (i, &cov) in coverage.iter().enumerate().filter(|(_, &c)| c > 0.0 && c < 1.0) {
        for (px, &bg) in frame.data[4 * i..4 * i + 3].iter_mut().zip(&BACKGROUND) {
            let skin = sampler::srgb_to_linear(*px as f32 / 255.0);
            let bg = sampler::srgb_to_linear(bg as f32 / 255.0);
            *px = sampler::unorm8(sampler::linear_to_srgb(cov * skin + (1.0 - cov) * bg));
        }
    }
}
