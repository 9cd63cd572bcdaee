//! Per-pass GPU profiling of `run skin`'s frame (`runtime::gpu::set_pass_profiling`): a profiled frame is the same
//! frame, its passes come back in recording order with the spans between them, GPU times where the device has
//! timestamp queries, and each compute-chain pass's bytes moved equal a hand count of the buffers it reads and
//! writes (`inputs_compute.wgsl`, `shade_frame.wgsl`: each storage buffer an entry point reads, and each it
//! writes, counted whole, once).

use crate::support::baked_dir;
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::{create_headless, DeviceOptions};
use rtbake::runtime::gpu::{set_pass_profiling, take_pass_profile};
use rtbake::runtime::skin::compute_raster::RasterShape;
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader};

#[test]
fn a_profiled_frame_is_the_same_frame_with_its_passes_in_order_and_their_bytes_counted() {
    let g = create_headless(&DeviceOptions { timestamps: true }).expect("an adapter (lavapipe)");
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let (width, height, shader, stretch) = (64u32, 32u32, SkinShader::Separable, Default::default());
    let s = SkinRenderSettings { shader, heads: 1, distance_m: 0.6, width, height, melanin: 0.02, stretch };
    let head = default_head();
    let passes = SkinPasses::default();
    RasterShape::set_on_this_thread(Some(RasterShape::Compute));
    let plain = render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
    RasterShape::set_on_this_thread(None);
    assert!(take_pass_profile(&g.device, &g.queue).unwrap().is_empty(), "profiling is off by default");
    set_pass_profiling(true);
    // The compute rasteriser, which a GPU takes by default (a software adapter the render pass).
    RasterShape::set_on_this_thread(Some(RasterShape::Compute));
    let profiled = render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
    RasterShape::set_on_this_thread(None);
    let profile = take_pass_profile(&g.device, &g.queue).unwrap();
    set_pass_profiling(false);
    assert_eq!(plain.data, profiled.data, "profiling changed the frame's bytes");

    // Recording order: the compute rasteriser's three passes for the view's G-buffer and for the shadow map
    // (`runtime::skin::compute_raster`, `RTBAKE_RASTER=compute`, a GPU's default), the device geometry, the rig at
    // uv, the background fill, the skin-inputs pass, the shading chain around the SSS
    // passes, bloom (one level at 32 rows) and the tone map; spans where other work lies between two chain
    // recordings.
    let labels: Vec<&str> = profile.iter().map(|p| p.label.as_str()).collect();
    let expected = [
        "frame start → view raster: depth",
        "view raster: depth",
        "view raster: visible",
        "view raster: resolve",
        "view raster: resolve → shadow raster: depth",
        "shadow raster: depth",
        "shadow raster: visible",
        "shadow raster: resolve",
        "shadow raster: resolve → frame geometry: main",
        "frame geometry: main",
        "frame geometry: main → mesh skin inputs: main",
        "mesh skin inputs: main",
        "mesh skin inputs: into_skin_maps",
        "mesh skin inputs: into_skin_maps → skin frame: background",
        "skin frame: background",
        "skin frame: background → skin inputs: main",
        "skin inputs: main",
        "skin inputs: main → skin frame: lit",
        "skin frame: lit",
        "skin frame: pack",
        "skin frame: pack → skin frame: composite",
        "skin frame: composite",
        "skin frame: composite → bloom: down",
        "bloom: down",
        "bloom: combine",
        "bloom: combine → skin frame: tonemap",
        "skin frame: tonemap",
    ];
    assert_eq!(labels, expected);
    for p in &profile {
        assert_eq!(p.span, p.label.contains(" → "), "{p:?}");
        assert_eq!(p.span, p.bytes.is_none(), "{p:?}");
        assert_eq!(p.gpu_ms.is_some(), g.timestamps, "{p:?}");
        assert!(p.gpu_ms.is_none_or(|ms| ms.is_finite()), "{p:?}");
    }

    // The shading chain's buffers at 64×32 (n pixels): skin16, two Rgba16Float images in rows padded to 512
    // bytes (16n); geo, two vec4 per pixel (32n); diffuse (16n); sss16, one padded Rgba16Float image (8n); hdr
    // and its bloomed copy, bloom's first and last buffers (16n each); rgba, RGBA8 (4n).
    let n = (width * height) as u64;
    let (skin16, geo, diffuse, sss16, hdr, bloomed, rgba) = (16 * n, 32 * n, 16 * n, 8 * n, 16 * n, 16 * n, 4 * n);
    let bytes = |label: &str| profile.iter().find(|p| p.label == label).and_then(|p| p.bytes);
    // skin inputs: reads the geometry's maps and normals (one vec4 per pixel each, 64 × 16 bytes = a padded row),
    // the rig (two halves per texel per target: the screen-space frame's neutral rig, 2×2 texels, one target),
    // the albedo LUT and the T(s) table (Rgba16Float), writes skin16.
    let (maps, normals, rig) = (16 * n, 16 * n, 4 * 4);
    let (lw, lh) = assets.luts.albedo_size;
    let (lut, t_table) = (8 * (lw * lh) as u64, 8 * assets.luts.transmittance.len() as u64);
    let round16 = |b: u64| b.div_ceil(16) * 16;
    let tables = round16(rig) + round16(lut) + round16(t_table);
    assert_eq!(bytes("skin inputs: main"), Some(maps + normals + tables + skin16));
    // lit: reads skin16 (albedo, transmitted) and geo, writes diffuse.
    assert_eq!(bytes("skin frame: lit"), Some(skin16 + geo + diffuse));
    // pack: reads diffuse, writes sss16.
    assert_eq!(bytes("skin frame: pack"), Some(diffuse + sss16));
    // composite: reads geo, the background in rgba, diffuse, sss16 and skin16 (post-scatter albedo), writes hdr.
    assert_eq!(bytes("skin frame: composite"), Some(geo + rgba + diffuse + sss16 + skin16 + hdr));
    // tonemap: reads hdr, bloomed, geo and rgba, writes rgba.
    assert_eq!(bytes("skin frame: tonemap"), Some(hdr + bloomed + geo + rgba + rgba));

    // The rasteriser's passes over the mesh (48-byte vertices, u32 indices), a u32 depth key and a u32 triangle
    // key per pixel, and the G-buffer's two f16 targets in rows padded to 256 bytes (the view: 64 × 8 = 512 bytes
    // a row; the 512² shadow map: 4096): depth reads the mesh and reads and writes the depth keys (atomicMax);
    // visible reads the mesh and the depth keys and reads and writes the triangle keys; resolve reads the mesh and
    // the triangle keys and writes the G-buffer.
    let mesh = 48 * head.positions.len() as u64 + 4 * head.indices.len() as u64;
    for (what, pixels, row) in [("view", n, 512), ("shadow", 512 * 512, 4096)] {
        let (keys, gbuffer) = (4 * pixels, 2 * row * pixels / (row / 8));
        assert_eq!(bytes(&format!("{what} raster: depth")), Some(mesh + 2 * keys), "{what}");
        assert_eq!(bytes(&format!("{what} raster: visible")), Some(mesh + 3 * keys), "{what}");
        assert_eq!(bytes(&format!("{what} raster: resolve")), Some(mesh + keys + gbuffer), "{what}");
    }
}
