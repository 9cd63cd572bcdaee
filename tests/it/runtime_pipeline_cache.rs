//! Frames shaped like an engine's: the shader modules and pipelines of `run skin` are compiled by the first frame
//! and reused by every later one (counted by `runtime::gpu::pipelines_created_on_this_thread`), and a frame
//! rendered from the cache is the same frame.

use crate::support::{baked_dir, gpu};
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::gpu::{cached_objects, pipelines_created_on_this_thread};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, StretchPreset, TsSettings};

/// One head at 0.6 m in a 160×96 frame.
fn small_frame(shader: SkinShader, stretch: StretchPreset) -> SkinRenderSettings {
    crate::support::head_frame_160x96(shader, 1, 0.6, stretch)
}

#[test]
fn no_pipeline_is_compiled_after_the_first_frame_of_each_shader() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let ts = TsSettings { map_size: 128, ..Default::default() };
    let shaders =
        [SkinShader::None, SkinShader::Separable, SkinShader::SsFull, SkinShader::SsJittered, SkinShader::Ts(ts)];
    // Bloom on: the compute chain (bloom) runs in every frame too.
    let passes = SkinPasses::default();
    for shader in shaders {
        let s = small_frame(shader, StretchPreset::Thesis);
        let before = pipelines_created_on_this_thread();
        let first = render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
        let compiled_first = pipelines_created_on_this_thread() - before;
        let second = render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
        let compiled_second = pipelines_created_on_this_thread() - before - compiled_first;
        eprintln!(
            "{shader:?}: {compiled_first} pipelines compiled by the first frame, {compiled_second} by the second"
        );
        assert_eq!(compiled_second, 0, "{shader:?}: the second frame compiled {compiled_second} pipelines");
        if shader == SkinShader::None {
            // A fresh device: the first frame compiles the G-buffer, skin-input, lighting and bloom pipelines.
            assert!(compiled_first >= 4, "{shader:?}: {compiled_first} pipelines on a fresh device");
        }
        assert_eq!(first.data, second.data, "{shader:?}: a frame from cached pipelines differs");
    }
    assert!(cached_objects(&g.device) >= 10, "{} objects cached", cached_objects(&g.device));
}

/// The bandwidth the benchmarks divide bytes by: measured by four 2×size copies, positive, finite and above what
/// any adapter moves (a software adapter copies at gigabytes per second); timestamps only when the device has them.
#[test]
fn the_copy_bandwidth_the_bounds_divide_by_is_measured() {
    let g = gpu();
    let c = rtbake::runtime::gpu::copy_bandwidth(&g.device, &g.queue, g.timestamps, 3);
    assert!(c.bytes_per_s.is_finite() && c.bytes_per_s > 1e8, "{c:?}");
    assert_eq!((c.copies, c.runs), (4, 3));
    assert!(!c.by_timestamps || g.timestamps);
    assert!(c.describe().contains("GB/s"), "{}", c.describe());
}

/// The shading of a `run skin` frame on a device is recorded into one command encoder (skin inputs, lit layer,
/// SSS, composite, bloom, tone map) and read back once, whatever the shader, with or without bloom: a frame
/// makes one submission and one read-back in all: the G-buffer and the back light's shadow map are rasterised into
/// the same encoder and the thickness, specular layer and rig at the mesh's uv (the committed bake has the rig) are
/// computed from them on the device, the wrinkle pass too. The frame agrees with the CPU twin and with the per-pass GPU path (within 2/255 on 99 % of
/// the channels), which makes more of both.
#[test]
fn a_screen_space_frame_submits_its_shading_once_and_reads_back_only_the_final_frame() {
    use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
    use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    assert!(assets.baked_rig.is_some(), "the committed bake has the example rig");
    let head = default_head();
    let shaders = [SkinShader::None, SkinShader::Separable, SkinShader::SsFull, SkinShader::SsJittered];
    for shader in shaders {
        let joy = rtbake::runtime::skin_passes::Wrinkles {
            maps: rtbake::runtime::wrinkle_pass::WrinkleMaps::load(&baked_dir()).unwrap().into(),
            zone_weights: rtbake::runtime::wrinkle_pass::parse_wrinkle_weights("joy=1").unwrap(),
        };
        let wrinkled = SkinPasses { wrinkles: Some(joy), ..SkinPasses::default() };
        for (passes, expected) in [(SkinPasses::default(), 1), (SkinPasses::none(), 1), (wrinkled, 1)] {
            let s = small_frame(shader, StretchPreset::Tap2009);
            // The first frame builds the pipelines; count the second.
            render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
            let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
            let frame = render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
            let (sub, read) = (submissions_on_this_thread() - sub, read_backs_on_this_thread() - read);
            let case = format!("{shader:?}, bloom {}, wrinkles {}", passes.bloom.is_some(), passes.wrinkles.is_some());
            assert_eq!((sub, read), (expected, expected), "{case}: {sub} submissions, {read} read-backs");
            // The per-pass path submits and reads back each pass on its own: the G-buffer and shadow map, the
            // wrinkle pass, the rig at uv, the skin-inputs pass, the SSS pass and bloom.
            set_shading_in_one_encoder(false);
            let (sub_p, read_p) = (submissions_on_this_thread(), read_backs_on_this_thread());
            let per_pass = render_with(Some(&g), &head, &s, &passes, &assets);
            let (sub_p, read_p) = (submissions_on_this_thread() - sub_p, read_backs_on_this_thread() - read_p);
            set_shading_in_one_encoder(true);
            let per_pass = per_pass.unwrap();
            let wrinkles = passes.wrinkles.is_some() as u64;
            let all = 3 + wrinkles + (shader != SkinShader::None) as u64 + passes.bloom.is_some() as u64;
            assert_eq!((sub_p, read_p), (all, all), "{case}: per pass");
            let cpu = render_with(None, &head, &s, &passes, &assets).unwrap();
            for (other, name) in [(&cpu, "the CPU twin"), (&per_pass, "the per-pass GPU frame")] {
                let close = frame.data.iter().zip(&other.data).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
                assert!(
                    close as f64 >= 0.99 * frame.data.len() as f64,
                    "{case}: {close} of {} channels within 2/255 of {name}",
                    frame.data.len()
                );
            }
        }
    }
}

/// A small albedo map (sRGB-decoded skin tones in a checkerboard of 4×4-texel squares) and a tangent-space normal
/// map of ripples (unit vectors tilted up to ±0.35), 48² and 40² texels.
fn synthetic_surface_maps() -> rtbake::runtime::skin::surface_maps::SurfaceMaps {
    use rtbake::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
    let checker = |i: u32| ((i % 48) / 4 + (i / 48) / 4).is_multiple_of(2);
    let albedo = (0..48 * 48).map(|i| if checker(i) { [0.55, 0.38, 0.3, 0.0] } else { [0.3, 0.15, 0.1, 0.0] });
    let ripple = (0..40 * 40u32).map(|i| {
        let (x, y) = ((i % 40) as f32, (i / 40) as f32);
        let (a, b) = (0.35 * (x * 0.9).cos(), 0.35 * (y * 0.7 + x * 0.2).sin());
        let l = (a * a + b * b + 1.0).sqrt();
        [a / l, b / l, 1.0 / l, 0.0]
    });
    SurfaceMaps {
        albedo: Some(SurfaceMap { width: 48, height: 48, texels: albedo.collect::<Vec<_>>().into() }),
        normal: Some(SurfaceMap { width: 40, height: 40, texels: ripple.collect::<Vec<_>>().into() }),
    }
}

/// (submissions, read-backs) of rendering `s` with `passes` on `g`, after a first frame that builds the pipelines,
/// and the frame.
fn counted_frame(
    g: &rtbake::runtime::device::Gpu,
    mesh: &rtbake::mesh::Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> ((u64, u64), Vec<u8>) {
    use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
    render_with(Some(g), mesh, s, passes, assets).unwrap();
    let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
    let frame = render_with(Some(g), mesh, s, passes, assets).unwrap();
    ((submissions_on_this_thread() - sub, read_backs_on_this_thread() - read), frame.data)
}

/// The fraction of channels of `a` within 2/255 of `b`.
fn close_fraction(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).filter(|(x, y)| x.abs_diff(**y) <= 2).count() as f64 / a.len() as f64
}

/// A scanned head's surface maps (albedo after the diffusion, thesis §7.6; the tangent-space normal map in the
/// MikkTSpace frame), the wrinkle pass (Listing 8.1) and 4× MSAA with its coverage blend: each alone and all
/// together, every frame is one submission and one read-back on a device, and agrees with the CPU twin and with the
/// per-pass GPU path (which submits the G-buffer, the surface-map pass, the wrinkle pass, the rig at uv, the
/// skin-inputs pass, the SSS pass and bloom one by one) within 2/255 on ≥ 99 % of the channels — with MSAA also on
/// ≥ 90 % of the silhouette's pixels, where the coverage blend acts. The procedural head with small synthetic maps.
#[test]
fn surface_maps_wrinkles_and_msaa_frames_submit_once_and_agree_with_the_cpu_twin() {
    use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
    use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let wrinkles = rtbake::runtime::skin_passes::Wrinkles {
        maps: rtbake::runtime::wrinkle_pass::WrinkleMaps::load(&baked_dir()).unwrap().into(),
        zone_weights: rtbake::runtime::wrinkle_pass::parse_wrinkle_weights("joy=1,surprise=1,anger=1").unwrap(),
    };
    let maps = SkinPasses { surface_maps: Some(synthetic_surface_maps()), ..SkinPasses::default() };
    let wrinkled = SkinPasses { wrinkles: Some(wrinkles), ..SkinPasses::default() };
    let msaa = SkinPasses { msaa: 4, ..SkinPasses::default() };
    let all = SkinPasses { surface_maps: maps.surface_maps.clone(), msaa: 4, ..wrinkled.clone() };
    let cases = [("surface maps", maps), ("wrinkles", wrinkled), ("msaa 4", msaa), ("all three", all)];
    for shader in [SkinShader::Separable, SkinShader::SsFull] {
        let s = small_frame(shader, StretchPreset::Tap2009);
        let plain = render_with(Some(&g), &head, &s, &SkinPasses::default(), &assets).unwrap().data;
        for (name, passes) in &cases {
            let case = format!("{shader:?}, {name}");
            let (counts, frame) = counted_frame(&g, &head, &s, passes, &assets);
            assert_eq!(counts, (1, 1), "{case}: (submissions, read-backs)");
            set_shading_in_one_encoder(false);
            let (sub_p, read_p) = (submissions_on_this_thread(), read_backs_on_this_thread());
            let per_pass = render_with(Some(&g), &head, &s, passes, &assets);
            let (sub_p, read_p) = (submissions_on_this_thread() - sub_p, read_backs_on_this_thread() - read_p);
            set_shading_in_one_encoder(true);
            let per_pass = per_pass.unwrap().data;
            if passes.msaa > 1 {
                // The silhouette, where the coverage blend acts: the pixels the per-pass frame changes by more than
                // 2/255 against its one-sample frame. The device frame agrees there too.
                set_shading_in_one_encoder(false);
                let one = SkinPasses { msaa: 1, ..passes.clone() };
                let one = render_with(Some(&g), &head, &s, &one, &assets).unwrap().data;
                set_shading_in_one_encoder(true);
                let edge = |a: &[u8], b: &[u8]| a.iter().zip(b).any(|(x, y)| x.abs_diff(*y) > 2);
                let (mut edges, mut agree) = (0, 0);
                for ((p, o), f) in per_pass.chunks(4).zip(one.chunks(4)).zip(frame.chunks(4)) {
                    if edge(p, o) {
                        edges += 1;
                        agree += !edge(p, f) as usize;
                    }
                }
                eprintln!("{case}: {agree} of {edges} edge pixels agree");
                assert!(edges >= 100 && agree * 10 >= edges * 9, "{case}: {agree} of {edges} edge pixels agree");
            }
            let extra = passes.surface_maps.is_some() as u64 + passes.wrinkles.is_some() as u64;
            assert_eq!((sub_p, read_p), (5 + extra, 5 + extra), "{case}: per pass");
            let cpu = render_with(None, &head, &s, passes, &assets).unwrap().data;
            for (other, what) in [(&cpu, "the CPU twin"), (&per_pass, "the per-pass GPU frame")] {
                let f = close_fraction(&frame, other);
                assert!(f >= 0.99, "{case}: {:.2} % of channels within 2/255 of {what}", 100.0 * f);
            }
            // The passes change the device's frame (so the device ran them): the maps and MSAA's edges many
            // pixels, the wrinkles those of their zones.
            let changed = frame.chunks(4).zip(plain.chunks(4)).filter(|(a, b)| a != b).count();
            eprintln!("{case}: {changed} pixels changed");
            assert!(changed >= 100, "{case}: {changed} pixels changed");
        }
    }
}

const SCAN: &str = "the Lee Perry-Smith head scan (reference/heads/lee-perry-smith)";

/// The Lee Perry-Smith scan with its albedo and normal map (framed as a 230 mm head, `--mesh-units auto`), with
/// and without 4× MSAA: one submission and one read-back on a device; within 2/255 on ≥ 99 % of the channels of
/// the per-pass GPU frame (the same rasteriser: a software adapter's device frame takes the render pass; the CPU
/// twin's rasteriser rounds the scan's uv differently enough to pick neighbouring texels of its 1024² maps:
/// `skin_surface_maps`' scan test, 95 %, the bound of the compute rasteriser, which shares the twin's arithmetic).
/// SKIPPED without `../shared`.
#[test]
fn the_scanned_heads_frame_with_its_maps_is_one_submission() {
    use crate::support::reference_file;
    use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
    let Some(glb) = reference_file("heads/lee-perry-smith/LeePerrySmith.glb", SCAN) else { return };
    let Some(color) = reference_file("heads/lee-perry-smith/color.jpg", SCAN) else { return };
    let Some(normal) = reference_file("heads/lee-perry-smith/normal.jpg", SCAN) else { return };
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let dir = glb.parent().unwrap().to_path_buf();
    let read = |p: &std::path::Path| std::fs::read(p).unwrap();
    let mesh = rtbake::mesh::gltf::parse_gltf("scan", &read(&glb), &|uri: &str| {
        std::fs::read(dir.join(uri)).map_err(|e| e.to_string())
    })
    .unwrap()
    // The scan's maps are bottom-left (`run skin --uv-origin bottom-left`).
    .with_uv_origin(rtbake::mesh::UvOrigin::TopLeft, rtbake::mesh::UvOrigin::BottomLeft);
    use rtbake::mesh::framing::{to_metres, MeshOrigin, MeshUnits};
    let mesh =
        to_metres(&mesh, MeshUnits::parse("mesh_units", "auto").unwrap(), MeshOrigin::Head, "mesh_units").unwrap();
    let picture = |p: &std::path::Path| rtbake::io::picture::decode_u8("map", "scan", &read(p)).unwrap();
    let maps = rtbake::runtime::skin::surface_maps::SurfaceMaps::from_pictures(
        Some(&picture(&color)),
        Some(&picture(&normal)),
        rtbake::facial::wrinkles::GreenConvention::OpenGl,
    )
    .unwrap();
    let mut s = small_frame(SkinShader::Separable, StretchPreset::Tap2009);
    (s.width, s.height, s.distance_m) = (192, 108, 0.3);
    // The one-encoder frame against the per-pass frame with the same rasteriser (the render pass; the per-pass
    // path always takes it), then the compute rasteriser (a GPU's default) against the same per-pass frame.
    use rtbake::runtime::skin::compute_raster::RasterShape;
    for msaa in [1, 4] {
        let passes = SkinPasses { surface_maps: Some(maps.clone()), msaa, ..SkinPasses::default() };
        RasterShape::set_on_this_thread(Some(RasterShape::Render));
        let (counts, frame) = counted_frame(&g, &mesh, &s, &passes, &assets);
        assert_eq!(counts, (1, 1), "msaa {msaa}: (submissions, read-backs)");
        set_shading_in_one_encoder(false);
        let per_pass = render_with(Some(&g), &mesh, &s, &passes, &assets);
        set_shading_in_one_encoder(true);
        let per_pass = per_pass.unwrap().data;
        let f = close_fraction(&frame, &per_pass);
        eprintln!("the scan, msaa {msaa}: {:.2} % of channels within 2/255 of the per-pass frame", 100.0 * f);
        assert!(f >= 0.99, "msaa {msaa}: {:.2} % of channels within 2/255 of the per-pass frame", 100.0 * f);
        if msaa == 1 {
            // The compute rasteriser (a GPU's default) has the CPU twin's arithmetic: its uv picks neighbouring
            // texels of the maps as the twin's do, so the twin's 95 % (measured 98.1 %).
            RasterShape::set_on_this_thread(Some(RasterShape::Compute));
            let (counts, compute) = counted_frame(&g, &mesh, &s, &passes, &assets);
            RasterShape::set_on_this_thread(None);
            assert_eq!(counts, (1, 1), "compute raster: (submissions, read-backs)");
            let f = close_fraction(&compute, &per_pass);
            assert!(f >= 0.95, "compute raster: {:.2} % of channels within 2/255 of the per-pass frame", 100.0 * f);
        }
        let skin = frame.chunks(4).filter(|p| p[..3] != [46, 48, 52]).count();
        assert!(skin * 5 > frame.len() / 4, "msaa {msaa}: the head covers {skin} pixels");
    }
}
