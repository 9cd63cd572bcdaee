//! Texture-space diffusion frames shaped like an engine's: on a device the whole `run skin --shader ts` frame (the
//! G-buffer and shadow map, the irradiance maps lit on the device from the UV map cached per mesh, the 12 chained
//! blurs per head, the gather at each pixel's uv, the specular layer, bloom, the tone map) is recorded into one
//! command encoder and read back once; it agrees with the CPU twin and with the per-pass GPU path, and the
//! per-head counts of texels and pixels come back with the frame and match the per-pass path's. The procedural
//! demo (`run demo`) shades in one submission too.

use crate::support::{baked_dir, gpu};
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{SkinRenderSettings, SkinShader, StretchPreset, TsSettings};
use rtbake::runtime::texture_space::{render_with, TsStats};

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
    let frame = |shader, heads, distance_m| SkinRenderSettings {
        shader,
        heads,
        distance_m,
        width: 160,
        height: 96,
        melanin: 0.02,
        stretch: StretchPreset::Thesis,
    };
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
