//! Frames shaped like an engine's: a frame's buffers and textures come from a per-device pool
//! (`runtime::frame_pool`) and return to it after the frame, so a steady-state frame creates no buffer, texture or
//! pipeline and uploads nothing; a reused resource is not zero, so a frame after a different frame must give the
//! bytes of the same frame on a fresh device with the pool off (a pass that relied on zeroed memory shows here);
//! two threads rendering on one device never share a resource; a frame can stay on the device and be read back
//! on demand.

use crate::support::{baked_dir, gpu};
use rtbake::mesh::head::default_head;
use rtbake::mesh::Mesh;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::Gpu;
use rtbake::runtime::frame_pool::{
    buffers_created_on_this_thread, set_frame_pool_enabled, textures_created_on_this_thread,
};
use rtbake::runtime::gpu::{
    buffers_uploaded_on_this_thread, pipelines_created_on_this_thread, read_backs_on_this_thread,
};
use rtbake::runtime::skin::compute_raster::RasterShape;
use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
use rtbake::runtime::skin_passes::{SkinPasses, Wrinkles};
use rtbake::runtime::skin_render::{render_on_device_with, render_with, SkinRenderSettings, SkinShader, TsSettings};
use rtbake::runtime::wrinkle_pass::{parse_wrinkle_weights, WrinkleMaps};
use std::sync::Arc;

/// Texture-space diffusion with `map_size`² irradiance maps.
fn ts(map_size: u32) -> SkinShader {
    SkinShader::Ts(TsSettings { map_size, ..Default::default() })
}

fn settings(shader: SkinShader, heads: u32, distance_m: f32) -> SkinRenderSettings {
    SkinRenderSettings { shader, heads, distance_m, width: 96, height: 64, melanin: 0.02, stretch: Default::default() }
}

/// One frame through the one-encoder path.
fn frame(g: &Gpu, head: &Mesh, s: &SkinRenderSettings, passes: &SkinPasses, assets: &DemoAssets) -> Vec<u8> {
    set_shading_in_one_encoder(true);
    render_with(Some(g), head, s, passes, assets).unwrap().data
}

/// What a frame created and uploaded: buffers and textures through the pool, pipelines, uploaded buffers.
fn counts() -> [u64; 4] {
    [
        buffers_created_on_this_thread(),
        textures_created_on_this_thread(),
        pipelines_created_on_this_thread(),
        buffers_uploaded_on_this_thread(),
    ]
}

/// A 2×2 albedo map and an 8×8 normal map of bumps (unit vectors tilted ±0.3).
fn surface_maps() -> rtbake::runtime::skin::surface_maps::SurfaceMaps {
    use rtbake::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
    let albedo = vec![[0.6, 0.4, 0.3, 0.0], [0.5, 0.3, 0.25, 0.0], [0.55, 0.35, 0.3, 0.0], [0.45, 0.3, 0.2, 0.0]];
    let bumps = (0..64u32)
        .map(|i| {
            let (a, b) = (0.3 * ((i % 8) as f32).sin(), 0.3 * ((i / 8) as f32).cos());
            let l = (a * a + b * b + 1.0).sqrt();
            [a / l, b / l, 1.0 / l, 0.0]
        })
        .collect::<Vec<_>>();
    SurfaceMaps {
        albedo: Some(SurfaceMap { width: 2, height: 2, texels: Arc::new(albedo) }),
        normal: Some(SurfaceMap { width: 8, height: 8, texels: Arc::new(bumps) }),
    }
}

fn wrinkles(spec: &str) -> Wrinkles {
    Wrinkles {
        maps: WrinkleMaps::load(&baked_dir()).unwrap().into(),
        zone_weights: parse_wrinkle_weights(spec).unwrap(),
    }
}

/// After two frames of the same settings on a fresh device (the first compiles and uploads, the second may be the first
/// to find everything kept), a third creates no buffer, no texture and no pipeline and uploads nothing, per
/// shader with bloom and with surface maps, wrinkles and 4× MSAA; and the first frame did create buffers and
/// textures (the counters count).
#[test]
fn a_steady_state_frame_creates_and_uploads_nothing() {
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let all = SkinPasses {
        surface_maps: Some(surface_maps()),
        wrinkles: Some(wrinkles("joy=1")),
        msaa: 4,
        ..SkinPasses::default()
    };
    let cases = [
        (SkinShader::None, SkinPasses::default()),
        (SkinShader::Separable, SkinPasses::default()),
        (SkinShader::SsFull, SkinPasses::default()),
        (SkinShader::SsJittered, SkinPasses::default()),
        (SkinShader::Separable, all.clone()),
        (ts(128), SkinPasses::default()),
        (ts(128), all),
    ];
    // Both shapes of the G-buffer raster: the render pass's targets are textures, the compute rasteriser's
    // buffers (4× MSAA always takes the render pass).
    for shape in [RasterShape::Render, RasterShape::Compute] {
        RasterShape::set_on_this_thread(Some(shape));
        for (shader, passes) in &cases {
            // A fresh device: the first frame finds nothing pooled.
            let g = gpu();
            let s = settings(*shader, 1, 0.6);
            let before = counts();
            let first = frame(&g, &head, &s, passes, &assets);
            let after_first = counts();
            assert!(after_first[0] > before[0], "{shader:?}: the first frame creates its buffers");
            // The SSS pass's textures and the render pass's G-buffer (the compute frame's skin inputs and the compute
            // rasteriser create no texture).
            let sss = matches!(shader, SkinShader::Separable | SkinShader::SsFull | SkinShader::SsJittered);
            let textures = sss || shape == RasterShape::Render || passes.msaa > 1;
            assert_eq!(
                after_first[1] > before[1],
                textures,
                "{shader:?}, {shape:?}: textures created by the first frame"
            );
            frame(&g, &head, &s, passes, &assets);
            let before = counts();
            let third = frame(&g, &head, &s, passes, &assets);
            let made = counts().iter().zip(before).map(|(a, b)| a - b).collect::<Vec<_>>();
            assert_eq!(made, [0, 0, 0, 0], "{shader:?}, {shape:?}: buffers, textures, pipelines created and uploads");
            assert_eq!(first, third, "{shader:?}, {shape:?}: a frame from pooled resources differs");
        }
    }
    RasterShape::set_on_this_thread(None);
}

/// Frame B after a different frame A on the same device (another shader, heads, camera, bloom on or off), from
/// A's pooled buffers and textures, is byte-identical to B on a fresh device with the pool off (every resource
/// new and zeroed): no pass of B reads what A left. For each screen-space shader with bloom, and for surface maps
/// with wrinkles and 4× MSAA.
#[test]
fn a_frame_after_a_different_frame_is_the_frame_of_a_fresh_device() {
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let bloom = SkinPasses::default();
    let none = SkinPasses::none();
    let mapped = SkinPasses {
        surface_maps: Some(surface_maps()),
        wrinkles: Some(wrinkles("joy=1,anger=1")),
        msaa: 4,
        ..SkinPasses::default()
    };
    let other_maps = SkinPasses { wrinkles: Some(wrinkles("surprise=1")), msaa: 4, ..SkinPasses::none() };
    // (A, B): A differs in shader, heads, distance and bloom.
    let cases = [
        ((settings(SkinShader::SsFull, 2, 0.9), &none), (settings(SkinShader::None, 1, 0.6), &bloom)),
        ((settings(SkinShader::None, 3, 1.2), &none), (settings(SkinShader::Separable, 1, 0.5), &bloom)),
        ((settings(SkinShader::SsJittered, 1, 0.4), &bloom), (settings(SkinShader::SsFull, 2, 0.7), &bloom)),
        ((settings(SkinShader::Separable, 2, 1.0), &none), (settings(SkinShader::SsJittered, 1, 0.6), &bloom)),
        ((settings(SkinShader::SsFull, 2, 0.8), &other_maps), (settings(SkinShader::Separable, 1, 0.6), &mapped)),
        // Texture space: another map size, heads and camera; then with maps, wrinkles and MSAA after a
        // screen-space frame.
        ((settings(ts(64), 2, 0.9), &none), (settings(ts(128), 1, 0.6), &bloom)),
        ((settings(SkinShader::SsFull, 2, 0.8), &bloom), (settings(ts(128), 1, 0.5), &mapped)),
    ];
    // Both raster shapes (the compute rasteriser's key buffers must start empty in every frame).
    for shape in [RasterShape::Render, RasterShape::Compute] {
        RasterShape::set_on_this_thread(Some(shape));
        let g = gpu();
        for ((sa, pa), (sb, pb)) in &cases {
            let a = frame(&g, &head, sa, pa, &assets);
            let before = buffers_created_on_this_thread();
            let b = frame(&g, &head, sb, pb, &assets);
            let reused = buffers_created_on_this_thread() - before;
            let fresh_device = gpu();
            set_frame_pool_enabled(false);
            let fresh = frame(&fresh_device, &head, sb, pb, &assets);
            set_frame_pool_enabled(true);
            assert_ne!(a, b, "{:?} after {:?}: the two frames differ", sb.shader, sa.shader);
            assert!(b == fresh, "{:?} after {:?}, {shape:?}: B from A's pooled resources differs from B on a fresh device ({} of {} bytes; {reused} buffers created for B)",
            sb.shader, sa.shader, b.iter().zip(&fresh).filter(|(x, y)| x != y).count(), b.len());
        }
    }
    RasterShape::set_on_this_thread(None);
}

/// Two threads rendering different frames on one device at once, three frames each, give the bytes each frame has
/// when rendered alone: no buffer or texture is shared between their frames.
#[test]
fn two_threads_on_one_device_share_no_frame_resources() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let jobs = [
        (settings(SkinShader::Separable, 1, 0.6), SkinPasses::default()),
        (settings(SkinShader::SsFull, 2, 0.9), SkinPasses::default()),
    ];
    let alone: Vec<Vec<u8>> = jobs.iter().map(|(s, p)| frame(&g, &head, s, p, &assets)).collect();
    std::thread::scope(|scope| {
        let handles: Vec<_> = jobs
            .iter()
            .map(|(s, p)| {
                let (g, head, assets) = (&g, &head, &assets);
                scope.spawn(move || (0..3).map(|_| frame(g, head, s, p, assets)).collect::<Vec<_>>())
            })
            .collect();
        for (k, h) in handles.into_iter().enumerate() {
            for (i, f) in h.join().unwrap().iter().enumerate() {
                assert!(*f == alone[k], "thread {k} frame {i} differs from the frame rendered alone");
            }
        }
    });
}

/// A frame left on the device makes no read-back; its read-back is one and gives `render_with`'s bytes.
#[test]
fn a_frame_left_on_the_device_is_read_back_on_demand() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let s = settings(SkinShader::Separable, 1, 0.6);
    let passes = SkinPasses::default();
    let image = frame(&g, &head, &s, &passes, &assets);
    let reads = read_backs_on_this_thread();
    let resident = render_on_device_with(&g, &head, &s, &passes, &assets).unwrap();
    assert_eq!(read_backs_on_this_thread() - reads, 0, "read-backs of a frame left on the device");
    assert_eq!(resident.size(), (96, 64));
    // A later frame must not reuse the resident frame's buffer.
    let other =
        render_with(Some(&g), &head, &settings(SkinShader::None, 2, 0.9), &SkinPasses::none(), &assets).unwrap();
    assert_ne!(other.data, image);
    let reads = read_backs_on_this_thread();
    let back = resident.read_back(&g).unwrap();
    assert_eq!(read_backs_on_this_thread() - reads, 1);
    assert!(back.data == image, "the resident frame's read-back differs from render_with's frame");
    let e = render_on_device_with(&g, &head, &settings(SkinShader::Ts(Default::default()), 1, 0.6), &passes, &assets)
        .unwrap_err();
    assert!(e.to_string().contains("shader"), "{e}");
}
