//! Texture-space diffusion frames shaped like an engine's: on a device the whole `run skin --shader ts` frame (the
//! G-buffer and shadow map, the irradiance maps lit on the device from the UV map cached per mesh, the 12 chained
//! blurs per head, the gather at each pixel's uv, the specular layer, bloom, the tone map) is recorded into one
//! command encoder and read back once; it agrees with the CPU twin and with the per-pass GPU path, and the
//! per-head counts of texels and pixels come back with the frame and match the per-pass path's — also with a scan's
//! surface maps, the wrinkle pass and 4× MSAA (synthetic maps always; the Lee Perry-Smith scan with its maps, the
//! reference frames of TAP's experiment, where `../shared` is there). The procedural demo (`run demo`) shades in one
//! submission too.

use crate::support::{baked_dir, gpu, head_frame_160x96, reference_file};
use rtbake::image_buf::Image;
use rtbake::mesh::head::default_head;
use rtbake::mesh::Mesh;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::Gpu;
use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
use rtbake::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps};
use rtbake::runtime::skin_passes::{SkinPasses, Wrinkles};
use rtbake::runtime::skin_render::{SkinRenderSettings, SkinShader, StretchPreset, TsSettings};
use rtbake::runtime::texture_space::{render_with, TsStats};
use rtbake::runtime::wrinkle_pass::{parse_wrinkle_weights, WrinkleMaps};

/// `frame` within 2/255 of `other` on ≥ 99 % of the channels (the tolerance of the TS chain's GPU/CPU test).
fn assert_close(frame: &[u8], other: &[u8], case: &str) {
    let close = frame.iter().zip(other).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
    assert!(close as f64 >= 0.99 * frame.len() as f64, "{case}: {close} of {} channels within 2/255", frame.len());
}

/// The frame's texel and pixel counts against the per-pass path's: the same UV map gives the same covered texels
/// and the same G-buffer the same pixels per head; culling and clipping are decided in f32 on the device and on
/// the host, equal but for texels on the 105° and frustum borders (≤ 0.5 %).
fn assert_same_counts(one: &TsStats, per_pass: &TsStats, case: &str) {
    assert_eq!(one.heads.len(), per_pass.heads.len(), "{case}");
    assert_eq!(one.d_ref_m, per_pass.d_ref_m, "{case}");
    for (a, b) in one.heads.iter().zip(&per_pass.heads) {
        assert_eq!((a.map_size, a.covered_texels, a.pixels), (b.map_size, b.covered_texels, b.pixels), "{case}");
        for (x, y, what) in [
            (a.culled_texels, b.culled_texels, "culled"),
            (a.clipped_texels, b.clipped_texels, "clipped"),
            (a.shaded_texels, b.shaded_texels, "shaded"),
        ] {
            assert!(x.abs_diff(y) as f64 <= 0.005 * b.covered_texels as f64, "{case}: {what} {x} vs {y}");
        }
        assert_eq!(a.covered_texels, a.culled_texels + a.clipped_texels + a.shaded_texels, "{case}");
    }
}

/// One head with bloom and three heads with culling, clipping and depth-sized maps: the second frame makes one
/// submission and one read-back (the per-pass path 3 + 2 per head with shaded texels + bloom: 6 and 9), is within
/// 2/255 of the CPU twin and of the per-pass frame on ≥ 99 % of the channels and nearer the per-pass frame than the
/// frame without SSS by more than 2×, and its counts match the per-pass path's.
#[test]
fn a_texture_space_frame_submits_once_and_reads_back_only_the_final_frame() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    assert!(assets.baked_rig.is_some(), "the committed bake has the example rig");
    let head = default_head();
    let frame = |shader, heads, distance_m| head_frame_160x96(shader, heads, distance_m, StretchPreset::Thesis);
    let plain = TsSettings { map_size: 128, ..Default::default() };
    // One head with bloom; three heads (the outer ones partly outside the frame) with every ch. 3 optimisation,
    // so that texels are culled and clipped and the pixels are shared between heads.
    for (ts, heads, distance_m, passes) in
        [(plain, 1, 0.6, SkinPasses::default()), (TsSettings::optimised(128), 3, 0.45, SkinPasses::none())]
    {
        let s = frame(SkinShader::Ts(ts), heads, distance_m);
        let case = format!("{heads} heads, {ts:?}, bloom {}", passes.bloom.is_some());
        // The first frame builds the pipelines and uploads the UV map; count the second.
        render_with(Some(&g), &head, &s, ts, &passes, &assets).unwrap();
        let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let (one, one_stats) = render_with(Some(&g), &head, &s, ts, &passes, &assets).unwrap();
        let (sub, read) = (submissions_on_this_thread() - sub, read_backs_on_this_thread() - read);
        assert_eq!((sub, read), (1, 1), "{case}: {sub} submissions, {read} read-backs");
        // The per-pass path: the G-buffer and shadow map, the rig at uv, the frame's skin inputs, per head the
        // texels' skin inputs and the blurs with the gather, and bloom, each submitted and read back.
        set_shading_in_one_encoder(false);
        let (sub_p, read_p) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let per_pass = render_with(Some(&g), &head, &s, ts, &passes, &assets);
        let (sub_p, read_p) = (submissions_on_this_thread() - sub_p, read_backs_on_this_thread() - read_p);
        set_shading_in_one_encoder(true);
        let (per_pass, per_pass_stats) = per_pass.unwrap();
        let shaded_heads = per_pass_stats.heads.iter().filter(|h| h.shaded_texels > 0).count() as u64;
        let all = 3 + 2 * shaded_heads + passes.bloom.is_some() as u64;
        assert_eq!((sub_p, read_p), (all, all), "{case}: per pass");
        assert!(one_stats.heads.iter().all(|h| h.pixels > 0 && h.shaded_texels > 0), "{case}: {one_stats:?}");
        if ts.cull {
            assert!(one_stats.heads.iter().any(|h| h.culled_texels > 0 && h.clipped_texels > 0), "{case}");
        }
        assert_same_counts(&one_stats, &per_pass_stats, &case);
        let (cpu, _) = render_with(None, &head, &s, ts, &passes, &assets).unwrap();
        assert_close(&one.data, &cpu.data, &format!("{case}: the CPU twin"));
        assert_close(&one.data, &per_pass.data, &format!("{case}: the per-pass GPU frame"));
        // The diffusion is in the frame: it is nearer the per-pass TS frame than the frame without SSS is.
        let none = rtbake::runtime::skin_render::render_with(
            Some(&g),
            &head,
            &frame(SkinShader::None, heads, distance_m),
            &passes,
            &assets,
        )
        .unwrap();
        let distance = |a: &[u8]| a.iter().zip(&per_pass.data).map(|(x, y)| x.abs_diff(*y) as u64).sum::<u64>();
        let (d_one, d_none) = (distance(&one.data), distance(&none.data));
        eprintln!("{case}: per pass {sub_p} submissions / {read_p} read-backs; Σ|Δ| to the per-pass frame {d_one}, no SSS {d_none}; {one_stats:?}");
        assert!(2 * d_one < d_none, "{case}: Σ|Δ| {d_one} to the per-pass frame, the frame without SSS {d_none}");
    }
}

/// The procedural demo's shading (skin inputs, lit layer, SSS, composite, tone map) on a device is one submission
/// and one read-back, the per-pass path one each for the skin-inputs pass and the SSS pass; the frame agrees with
/// the CPU twin and with the per-pass path as `run skin`'s frames do.
#[test]
fn the_procedural_demo_shades_in_one_submission() {
    use rtbake::runtime::demo::{render, SssMethod};
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    for method in [SssMethod::Separable, SssMethod::Gaussians] {
        let case = format!("demo, {method:?}");
        render(Some(&g), 192, 108, &assets, method, None).unwrap();
        let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let one = render(Some(&g), 192, 108, &assets, method, None).unwrap();
        let (sub, read) = (submissions_on_this_thread() - sub, read_backs_on_this_thread() - read);
        assert_eq!((sub, read), (1, 1), "{case}: {sub} submissions, {read} read-backs");
        set_shading_in_one_encoder(false);
        let (sub_p, read_p) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let per_pass = render(Some(&g), 192, 108, &assets, method, None);
        let (sub_p, read_p) = (submissions_on_this_thread() - sub_p, read_backs_on_this_thread() - read_p);
        set_shading_in_one_encoder(true);
        eprintln!("{case}: per pass {sub_p} submissions / {read_p} read-backs");
        assert_eq!((sub_p, read_p), (2, 2), "{case}: per pass");
        let cpu = render(None, 192, 108, &assets, method, None).unwrap();
        assert_close(&one.data, &cpu.data, &format!("{case}: the CPU twin"));
        assert_close(&one.data, &per_pass.unwrap().data, &format!("{case}: the per-pass GPU frame"));
    }
}

/// A 32×32 albedo map of stripes across u (a dark band every 8 texels) and a 32×32 tangent-space normal map whose
/// normals lean up to 0.5 in x and y in slow waves across the map, with ripples of ±0.15 on top: the waves change
/// the texels' irradiance over centimetres, which the diffusion keeps; the ripples show in the specular layer.
fn synthetic_surface_maps() -> SurfaceMaps {
    let s = 32u32;
    let albedo = (0..s * s).map(|i| if (i % s) % 8 < 2 { [0.25, 0.12, 0.08, 0.0] } else { [0.6, 0.4, 0.3, 0.0] });
    let normal = (0..s * s).map(|i| {
        let (x, y) = ((i % s) as f32, (i / s) as f32);
        let tau = std::f32::consts::TAU / s as f32;
        let a = 0.5 * (x * tau).sin() + 0.15 * (x * 1.3).cos();
        let b = 0.5 * (y * tau).cos() + 0.15 * (y * 0.9 + x * 0.4).sin();
        let l = (a * a + b * b + 1.0).sqrt();
        [a / l, b / l, 1.0 / l, 0.0]
    });
    SurfaceMaps {
        albedo: Some(SurfaceMap { width: s, height: s, texels: albedo.collect::<Vec<_>>().into() }),
        normal: Some(SurfaceMap { width: s, height: s, texels: normal.collect::<Vec<_>>().into() }),
    }
}

/// A frame's (submissions, read-backs) and the frame with its counts.
type Counted = ((u64, u64), (Image<u8>, TsStats));

/// The frame of `passes` on `g` after a first frame that builds the pipelines and uploads the maps, with the
/// (submissions, read-backs) of the second; then the per-pass path's frame with its counts.
fn one_encoder_and_per_pass(
    g: &Gpu,
    head: &Mesh,
    s: &SkinRenderSettings,
    ts: TsSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> (Counted, Counted) {
    let counted = || {
        let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let frame = render_with(Some(g), head, s, ts, passes, assets).unwrap();
        ((submissions_on_this_thread() - sub, read_backs_on_this_thread() - read), frame)
    };
    render_with(Some(g), head, s, ts, passes, assets).unwrap();
    let one = counted();
    set_shading_in_one_encoder(false);
    let per_pass = std::panic::catch_unwind(std::panic::AssertUnwindSafe(counted));
    set_shading_in_one_encoder(true);
    (one, per_pass.unwrap_or_else(|e| std::panic::resume_unwind(e)))
}

/// The pixels where `frame` shows what `passes` add: of the pixels where the per-pass frame with them differs by
/// more than 2/255 from `without` (the per-pass frame without them), (how many, how many of them `frame` matches
/// within 2/255 in every channel).
fn where_the_passes_act(frame: &[u8], per_pass: &[u8], without: &[u8]) -> (usize, usize) {
    let differ = |a: &[u8], b: &[u8]| a.iter().zip(b).any(|(x, y)| x.abs_diff(*y) > 2);
    let acting = per_pass.chunks(4).zip(without.chunks(4)).zip(frame.chunks(4)).filter(|((p, w), _)| differ(p, w));
    acting.fold((0, 0), |(n, agree), ((p, _), f)| (n + 1, agree + !differ(p, f) as usize))
}

/// Texture-space diffusion with a scanned head's surface maps (post-scatter albedo, thesis §7.6; the normal map in
/// the MikkTSpace frame on the pixels and on the irradiance map's texels), the wrinkle pass (Listing 8.1) and 4×
/// MSAA with its coverage blend — each alone and all together, on one head and on three heads with every ch. 3
/// optimisation (depth-sized maps of two sizes): the second frame is one submission and one read-back (the
/// per-pass path: 3 + the surface-map pass + the wrinkle pass + 2 per head with shaded texels + bloom); it is within
/// 2/255 of the CPU twin and of the per-pass frame on ≥ 99 % of the channels, its texel and pixel counts match the
/// per-pass path's, and where the maps and MSAA change the per-pass frame (the per-pass frame without them differs by
/// more than 2/255: the maps' pixels, MSAA's silhouette; at least 60 pixels) it matches the per-pass frame on ≥ 90 %
/// of those pixels. (The wrinkle pass bends only the pixels' normals — the texels keep the mesh's, as on the host —
/// so in a TS frame it shows only in the specular layer: 0 pixels of this frame change, 9 by 1/255 at 320×192; the
/// geometry's own test, `frame_geometry`'s, shows the pass runs in the encoder.)
#[test]
fn texture_space_frames_with_surface_maps_wrinkles_and_msaa_submit_once() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let wrinkles = Wrinkles {
        maps: WrinkleMaps::load(&baked_dir()).unwrap().into(),
        zone_weights: parse_wrinkle_weights("joy=1,surprise=1,anger=1").unwrap(),
    };
    let maps = SkinPasses { surface_maps: Some(synthetic_surface_maps()), ..SkinPasses::default() };
    let wrinkled = SkinPasses { wrinkles: Some(wrinkles), ..SkinPasses::default() };
    let msaa = SkinPasses { msaa: 4, ..SkinPasses::default() };
    let all = SkinPasses { surface_maps: maps.surface_maps.clone(), msaa: 4, ..wrinkled.clone() };
    let plain = TsSettings { map_size: 128, ..Default::default() };
    let optimised = TsSettings::optimised(128);
    let cases = [
        ("surface maps", &maps, plain, 1, 0.6),
        ("wrinkles", &wrinkled, plain, 1, 0.6),
        ("msaa 4", &msaa, plain, 1, 0.6),
        ("all three", &all, plain, 1, 0.6),
        ("all three, 3 heads optimised", &all, optimised, 3, 0.45),
    ];
    for (name, passes, ts, heads, distance_m) in cases {
        let s = head_frame_160x96(SkinShader::Ts(ts), heads, distance_m, StretchPreset::Thesis);
        let ((counts, (one, one_stats)), (counts_p, (per_pass, per_pass_stats))) =
            one_encoder_and_per_pass(&g, &head, &s, ts, passes, &assets);
        assert_eq!(counts, (1, 1), "{name}: (submissions, read-backs)");
        let shaded_heads = per_pass_stats.heads.iter().filter(|h| h.shaded_texels > 0).count() as u64;
        let extra = passes.surface_maps.is_some() as u64 + passes.wrinkles.is_some() as u64;
        let all = 3 + extra + 2 * shaded_heads + passes.bloom.is_some() as u64;
        assert_eq!(counts_p, (all, all), "{name}: per pass");
        assert!(one_stats.heads.iter().all(|h| h.pixels > 0 && h.shaded_texels > 0), "{name}: {one_stats:?}");
        assert_same_counts(&one_stats, &per_pass_stats, name);
        let (cpu, _) = render_with(None, &head, &s, ts, passes, &assets).unwrap();
        assert_close(&one.data, &cpu.data, &format!("{name}: the CPU twin"));
        assert_close(&one.data, &per_pass.data, &format!("{name}: the per-pass GPU frame"));
        if passes.surface_maps.is_none() && passes.msaa == 1 {
            continue;
        }
        let bare = SkinPasses { bloom: passes.bloom, ..SkinPasses::none() };
        set_shading_in_one_encoder(false);
        let without = render_with(Some(&g), &head, &s, ts, &bare, &assets);
        set_shading_in_one_encoder(true);
        let (without, _) = without.unwrap();
        let (acting, agree) = where_the_passes_act(&one.data, &per_pass.data, &without.data);
        eprintln!("{name}: the passes change {acting} pixels of the per-pass frame, the device frame matches {agree}");
        assert!(acting >= 60 && agree * 10 >= acting * 9, "{name}: {agree} of {acting} pixels match");
    }
}

const SCAN: &str = "the Lee Perry-Smith head scan (reference/heads/lee-perry-smith)";

/// The Lee Perry-Smith scan framed as `run skin --mesh-units auto --uv-origin bottom-left` frames it, and its
/// albedo and normal map, or None (SKIPPED) without `../shared`.
fn scan_with_maps() -> Option<(Mesh, SurfaceMaps)> {
    use rtbake::mesh::framing::{to_metres, MeshOrigin, MeshUnits};
    let glb = reference_file("heads/lee-perry-smith/LeePerrySmith.glb", SCAN)?;
    let color = reference_file("heads/lee-perry-smith/color.jpg", SCAN)?;
    let normal = reference_file("heads/lee-perry-smith/normal.jpg", SCAN)?;
    let read = |p: &std::path::Path| std::fs::read(p).unwrap();
    let mesh = rtbake::mesh::gltf::parse_gltf("scan", &read(&glb), &|uri: &str| Err(format!("{uri}: not needed")))
        .unwrap()
        .with_uv_origin(rtbake::mesh::UvOrigin::TopLeft, rtbake::mesh::UvOrigin::BottomLeft);
    let auto = MeshUnits::parse("mesh_units", "auto").unwrap();
    let mesh = to_metres(&mesh, auto, MeshOrigin::Head, "mesh_units").unwrap();
    let picture = |p: &std::path::Path| rtbake::io::picture::decode_u8("map", "scan", &read(p)).unwrap();
    let green = rtbake::facial::wrinkles::GreenConvention::OpenGl;
    let maps = SurfaceMaps::from_pictures(Some(&picture(&color)), Some(&picture(&normal)), green).unwrap();
    Some((mesh, maps))
}

/// The reference frames of TAP's experiment: TS on the Lee Perry-Smith scan with its albedo and normal map
/// (512² irradiance map, TAP's near camera), with and without 4× MSAA, is one submission and one read-back; within
/// 2/255 of the per-pass GPU frame on ≥ 99 % of the channels and, where the maps change the per-pass frame, on
/// ≥ 90 % of those pixels; against the CPU twin within the scan's tolerance (`skin_surface_maps`: ≥ 95 % of the
/// channels within 2/255 and RMSE < 0.007 — the CPU rasteriser rounds the scan's uv to neighbouring texels of its
/// 1024² maps). SKIPPED without `../shared`.
#[test]
fn texture_space_on_the_scan_with_its_maps_submits_once() {
    let Some((mesh, maps)) = scan_with_maps() else { return };
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let height_m = rtbake::mesh::framing::head_height_units(&mesh) * mesh.mm_per_unit / 1000.0;
    let near = rtbake::mesh::framing::TapDistance::Near.camera_distance_m(height_m);
    let ts = TsSettings { map_size: 512, ..Default::default() };
    let s = SkinRenderSettings {
        shader: SkinShader::Ts(ts),
        heads: 1,
        distance_m: near,
        width: 192,
        height: 108,
        melanin: 0.02,
        stretch: StretchPreset::Thesis,
    };
    // The one-encoder frame against the per-pass frame with the same rasteriser (the render pass, which the
    // per-pass path always takes); the compute rasteriser (a GPU's default) is held to the CPU twin below.
    use rtbake::runtime::skin::compute_raster::RasterShape;
    for msaa in [1, 4] {
        let name = format!("the scan, msaa {msaa}");
        let passes = SkinPasses { surface_maps: Some(maps.clone()), msaa, ..SkinPasses::default() };
        RasterShape::set_on_this_thread(Some(RasterShape::Render));
        let ((counts, (one, one_stats)), (_, (per_pass, per_pass_stats))) =
            one_encoder_and_per_pass(&g, &mesh, &s, ts, &passes, &assets);
        RasterShape::set_on_this_thread(None);
        assert_eq!(counts, (1, 1), "{name}: (submissions, read-backs)");
        assert_same_counts(&one_stats, &per_pass_stats, &name);
        assert_close(&one.data, &per_pass.data, &format!("{name}: the per-pass GPU frame"));
        let bare = SkinPasses { msaa, ..SkinPasses::default() };
        set_shading_in_one_encoder(false);
        let without = render_with(Some(&g), &mesh, &s, ts, &bare, &assets);
        set_shading_in_one_encoder(true);
        let (acting, agree) = where_the_passes_act(&one.data, &per_pass.data, &without.unwrap().0.data);
        eprintln!("{name}: the maps change {acting} pixels of the per-pass frame, the device frame matches {agree}");
        assert!(acting >= 1000 && agree * 10 >= acting * 9, "{name}: {agree} of {acting} pixels match");
        let (cpu, _) = render_with(None, &mesh, &s, ts, &passes, &assets).unwrap();
        let mut frames = vec![("render raster", one.data)];
        if msaa == 1 {
            RasterShape::set_on_this_thread(Some(RasterShape::Compute));
            let compute = render_with(Some(&g), &mesh, &s, ts, &passes, &assets);
            RasterShape::set_on_this_thread(None);
            frames.push(("compute raster", compute.unwrap().0.data));
        }
        for (shape, frame) in frames {
            let close = frame.iter().zip(&cpu.data).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
            let sq: f64 = frame.iter().zip(&cpu.data).map(|(a, b)| (*a as f64 - *b as f64).powi(2)).sum();
            let rmse = (sq / frame.len() as f64).sqrt() / 255.0;
            eprintln!(
                "{name}, {shape}: {close} of {} channels within 2/255 of the CPU twin, RMSE {rmse:.4}",
                frame.len()
            );
            let fine = close as f64 >= 0.95 * frame.len() as f64 && rmse < 0.007;
            assert!(fine, "{name}, {shape}: the CPU twin, {close} within 2/255, RMSE {rmse}");
        }
    }
}
