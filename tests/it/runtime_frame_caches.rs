//! Frames shaped like an engine's: a frame on a device uploads its mesh (vertices with their tangents, indices)
//! and a scan's surface maps once, and later frames of the same mesh and maps reuse them (counted by
//! `runtime::gpu::buffers_uploaded_on_this_thread`) and are the same frame; a different mesh, or maps whose texels
//! changed, are uploaded again and give a different frame.

use crate::support::{baked_dir, gpu, head_frame_160x96};
use rtbake::mesh::head::default_head;
use rtbake::mesh::Mesh;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::Gpu;
use rtbake::runtime::gpu::buffers_uploaded_on_this_thread;
use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
use rtbake::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinShader, StretchPreset};
use std::sync::Arc;

/// A 2×2 albedo map of skin tones and a 24×24 tangent-space normal map of ripples (unit vectors tilted ±0.3).
fn maps() -> SurfaceMaps {
    let albedo = vec![[0.6, 0.4, 0.3, 0.0], [0.5, 0.3, 0.25, 0.0], [0.55, 0.35, 0.3, 0.0], [0.45, 0.3, 0.2, 0.0]];
    let ripple = (0..24 * 24u32)
        .map(|i| {
            let (a, b) = (0.3 * ((i % 24) as f32 * 0.9).sin(), 0.3 * ((i / 24) as f32 * 0.7).cos());
            let l = (a * a + b * b + 1.0).sqrt();
            [a / l, b / l, 1.0 / l, 0.0]
        })
        .collect::<Vec<_>>();
    SurfaceMaps {
        albedo: Some(SurfaceMap { width: 2, height: 2, texels: Arc::new(albedo) }),
        normal: Some(SurfaceMap { width: 24, height: 24, texels: Arc::new(ripple) }),
    }
}

/// One separable-SSS frame of `head` with `maps` at 0.6 m, 160×96, through the one-encoder path: its RGBA8 bytes
/// and the buffers uploaded for it.
fn frame(g: &Gpu, head: &Mesh, maps: &SurfaceMaps, assets: &DemoAssets) -> (Vec<u8>, u64) {
    set_shading_in_one_encoder(true);
    let s = head_frame_160x96(SkinShader::Separable, 1, 0.6, StretchPreset::Thesis);
    let passes = SkinPasses { surface_maps: Some(maps.clone()), ..SkinPasses::none() };
    let before = buffers_uploaded_on_this_thread();
    let img = render_with(Some(g), head, &s, &passes, assets).unwrap();
    (img.data, buffers_uploaded_on_this_thread() - before)
}

/// On a fresh device the first frame uploads eleven buffers (the mesh for the shadow map and its MikkTSpace split
/// for the view, vertices and indices each, the two maps, the skin-inputs pass's three tables — rig, albedo LUT,
/// T(s) — and the baked rig's two — scale/bias texels, H0); the second frame, with the same mesh and the same maps
/// (cloned: the texels are shared), uploads none and is byte-identical.
#[test]
fn a_second_frame_of_the_same_mesh_and_maps_uploads_nothing_and_is_the_same_frame() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let (head, maps) = (default_head(), maps());
    let (first, uploaded_first) = frame(&g, &head, &maps, &assets);
    assert_eq!(uploaded_first, 11, "buffers uploaded by the first frame on a fresh device");
    let (second, uploaded_second) = frame(&g, &head, &maps.clone(), &assets);
    assert_eq!(uploaded_second, 0, "buffers uploaded by the second frame");
    assert_eq!(first, second, "a frame from the kept buffers differs");
}

/// Maps of the same size with one albedo texel changed (through `Arc::make_mut`, while their first upload is kept)
/// are uploaded again (both maps) and change the frame; a mesh scaled by 5 % is uploaded again (vertices and
/// indices, plain and split) with the maps served from the cache, and changes the frame too.
#[test]
fn a_changed_map_or_a_different_mesh_is_uploaded_again() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let (head, maps) = (default_head(), maps());
    let (first, _) = frame(&g, &head, &maps, &assets);
    let mut changed = maps.clone();
    let albedo = changed.albedo.as_mut().unwrap();
    Arc::make_mut(&mut albedo.texels)[0] = [0.05, 0.02, 0.01, 0.0];
    assert_eq!(changed.albedo.as_ref().unwrap().texels.len(), maps.albedo.as_ref().unwrap().texels.len());
    let (recoloured, uploaded) = frame(&g, &head, &changed, &assets);
    assert_eq!(uploaded, 2, "buffers uploaded for maps with one texel changed");
    assert_ne!(first, recoloured, "one albedo texel of four changed the frame");
    let mut scaled = head.clone();
    scaled.positions.iter_mut().for_each(|p| p.iter_mut().for_each(|c| *c *= 1.05));
    let (other, uploaded) = frame(&g, &scaled, &maps, &assets);
    assert_eq!(uploaded, 4, "buffers uploaded for a different mesh");
    assert_ne!(first, other, "a scaled mesh changed the frame");
}
