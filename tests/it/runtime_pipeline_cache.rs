//! Frames shaped like an engine's: the shader modules and pipelines of `run skin` are compiled by the first frame
//! and reused by every later one (counted by `runtime::gpu::pipelines_created_on_this_thread`), and a frame
//! rendered from the cache is the same frame.

use crate::support::{baked_dir, gpu};
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::gpu::{cached_objects, pipelines_created_on_this_thread};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, StretchPreset, TsSettings};

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
        let s = SkinRenderSettings {
            shader,
            heads: 1,
            distance_m: 0.6,
            width: 160,
            height: 96,
            melanin: 0.02,
            stretch: StretchPreset::Thesis,
        };
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
/// SSS, composite, bloom, tone map) and read back once, whatever the shader and with or without bloom: a frame
/// makes one submission and one read-back for its G-buffer and the back light's shadow map together, one for the
/// rig at the mesh's uv (the committed bake has the rig) and one for all of its shading. The frame agrees with the
/// CPU twin as the per-pass frame did (within 2/255 on 99 % of the channels).
#[test]
fn a_screen_space_frame_submits_its_shading_once_and_reads_back_only_the_final_frame() {
    use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    assert!(assets.baked_rig.is_some(), "the committed bake has the example rig");
    let head = default_head();
    let shaders = [SkinShader::None, SkinShader::Separable, SkinShader::SsFull, SkinShader::SsJittered];
    for shader in shaders {
        for passes in [SkinPasses::default(), SkinPasses::none()] {
            let s = SkinRenderSettings {
                shader,
                heads: 1,
                distance_m: 0.6,
                width: 160,
                height: 96,
                melanin: 0.02,
                stretch: StretchPreset::Tap2009,
            };
            // The first frame builds the pipelines; count the second.
            render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
            let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
            let frame = render_with(Some(&g), &head, &s, &passes, &assets).unwrap();
            let (sub, read) = (submissions_on_this_thread() - sub, read_backs_on_this_thread() - read);
            let bloom = passes.bloom.is_some();
            // G-buffer and shadow map, rig at uv, shading.
            assert_eq!((sub, read), (3, 3), "{shader:?} bloom {bloom}: {sub} submissions, {read} read-backs");
            let cpu = render_with(None, &head, &s, &passes, &assets).unwrap();
            let close = frame.data.iter().zip(&cpu.data).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
            assert!(
                close as f64 >= 0.99 * frame.data.len() as f64,
                "{shader:?} bloom {bloom}: {close} of {} channels within 2/255 of the CPU twin",
                frame.data.len()
            );
        }
    }
}
