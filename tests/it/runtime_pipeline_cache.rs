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
    SkinRenderSettings { shader, heads: 1, distance_m: 0.6, width: 160, height: 96, melanin: 0.02, stretch }
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
/// computed from them on the device. With the wrinkle pass the G-buffer is read back for it (the host's
/// geometry): three. The frame agrees with the CPU twin and with the per-pass GPU path (within 2/255 on 99 % of
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
            maps: rtbake::runtime::wrinkle_pass::WrinkleMaps::load(&baked_dir()).unwrap(),
            zone_weights: rtbake::runtime::wrinkle_pass::parse_wrinkle_weights("joy=1").unwrap(),
        };
        let wrinkled = SkinPasses { wrinkles: Some(joy), ..SkinPasses::default() };
        // The wrinkle pass runs on the host's G-buffer: the raster and the wrinkle pass before the shading.
        for (passes, expected) in [(SkinPasses::default(), 1), (SkinPasses::none(), 1), (wrinkled, 3)] {
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
