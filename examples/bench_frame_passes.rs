//! Every pass of `run skin`'s frame timed on the GPU beside its bytes-moved bound: the frame (the default head,
//! default passes: bloom on) per shader, its passes recorded into one command encoder as `run skin` records them,
//! profiled by `rtbake::runtime::gpu::set_pass_profiling` (timestamps around each compute pass of the frame's
//! compute chains: frame geometry, the rig at uv, lit layer, composite, bloom's down/up levels and combine, tone
//! map; the work between them — the G-buffer and shadow-map raster (each its own span), the SSS passes,
//! the texture/buffer copies — as spans between the timed points).
//!
//!     cargo run --release --example bench_frame_passes [-- WIDTH HEIGHT FRAMES [both|compute|render]]
//!                                                                 # 1920 1080 7 both
//!     cargo run --release --example bench_frame_passes -- 1920 1080 7 slices=4x1,16x4
//!
//! `slices=RxC,…` times the first shader's frame with the compute rasteriser once per slicing of the triangles'
//! boxes (`rtbake::runtime::skin::compute_raster::Slices`: R row slices × C column slices per triangle; without
//! it, the default slicing for the mesh's triangle count).
//!
//! The last argument picks how the one-sample G-buffer and shadow map are rasterised
//! (`rtbake::runtime::skin::compute_raster::RasterShape`, `RTBAKE_RASTER` in `run skin`): `both` (the default)
//! prints every shader's table first with the compute rasteriser (its three passes per G-buffer timed with their
//! bounds, written straight into the geometry pass's buffers), then with the render pass and its copies (the shape
//! before), so the two are compared in one run on one adapter.
//!
//! Printed: the adapter, the copy bandwidth (buffer-to-buffer copies in the same run,
//! `rtbake::runtime::gpu::copy_bandwidth`), then per shader and pass the median GPU ms over FRAMES frames after one
//! warm-up frame, the MB the pass must move (`compute_chain`'s rule: each storage buffer it reads and each it
//! writes counted whole, once), the bound = bytes / copy bandwidth, time/bound, and `OVER 4x` where the pass
//! takes more than four times its bound. Spans have no bound (their work is not a chain's; the SSS passes have
//! theirs in `bench_runtime`). Where the adapter has no timestamps, or is a software adapter whose timestamps do
//! not cover compute work (llvmpipe/lavapipe), it says so and prints the bytes and bounds with the wall time per
//! frame only. Tables come from the committed bake (`baked/`, or $RTBAKE_BAKED_DIR).

use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::{create_headless, DeviceOptions};
use rtbake::runtime::gpu::{copy_bandwidth, set_pass_profiling, take_pass_profile, PassTime};
use rtbake::runtime::skin::compute_raster::{RasterShape, Slices};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, StretchPreset, TsSettings};
use std::path::PathBuf;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// What a span between two timed points of the frame holds, named by the passes it lies between.
fn span_holds(label: &str) -> &'static str {
    let (from, to) = label.split_once(" → ").unwrap_or(("", label));
    match to {
        "view G-buffer rasterised" => "the view's G-buffer raster (render pass; uploads and clears before it)",
        "shadow map rasterised" => "the 512² shadow-map raster (render pass)",
        "view raster: depth" => "clearing the view raster's key buffers (uploads before it)",
        "shadow raster: depth" => "clearing the shadow raster's key buffers",
        "frame geometry: main" if from.starts_with("shadow raster") => "nothing (barrier)",
        "frame geometry: main" => "the G-buffer and shadow map copied into the geometry pass's buffers",
        "skin frame: lit" => "copies",
        "skin frame: composite" => "SSS passes, copies",
        _ => "whatever lies between the two chain recordings (barriers, copies)",
    }
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (width, height) = (args.first().copied().unwrap_or(1920), args.get(1).copied().unwrap_or(1080));
    let frames = args.get(2).copied().unwrap_or(7).max(1) as usize;
    let word = |a: &String| a.parse::<u32>().is_err() && !a.starts_with("slices=");
    let mut shapes = match std::env::args().skip(1).find(word).as_deref() {
        None | Some("both") => vec![RasterShape::Compute, RasterShape::Render],
        Some(one) => vec![RasterShape::parse(one).expect("the last argument: both, compute or render")],
    };
    // `slices=RxC[,RxC…]`: the compute rasteriser's slicings of the triangle boxes compared on the first shader.
    let slicings: Vec<Option<Slices>> = match std::env::args().skip(1).find(|a| a.starts_with("slices=")) {
        Some(a) => a["slices=".len()..].split(',').map(|v| Some(Slices::parse(v).expect("slices=RxC,…"))).collect(),
        None => vec![None],
    };
    if slicings[0].is_some() {
        shapes = vec![RasterShape::Compute];
    }
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let g = create_headless(&DeviceOptions { timestamps: true }).expect("an adapter");
    println!("adapter: {}", g.describe());
    // A software adapter's timestamps bracket its render passes but not its compute work.
    let timed = g.timestamps && !g.is_software();
    println!(
        "timestamps: {}",
        match (g.timestamps, timed) {
            (true, true) => "yes (per-pass GPU time)",
            (true, false) => "present, but a software adapter's do not cover compute work: wall time per frame only",
            _ => "no (wall time per frame only)",
        }
    );
    let bw = copy_bandwidth(&g.device, &g.queue, g.timestamps, 7);
    println!("{}", bw.describe());
    let bound_ms = |bytes: u64| bytes as f64 / bw.bytes_per_s * 1e3;
    let head = default_head();
    println!(
        "run skin frame, default passes (bloom on), the default head ({} triangles), {width}x{height}, median of \
         {frames} frames after one warm-up",
        head.triangle_count()
    );
    println!(
        "bytes moved: each storage buffer a pass reads and each it writes counted whole, once (bloom's levels share \
         one buffer and the frame geometry samples a shadow map: for them an upper bound, time/bound a lower bound)"
    );
    let names = ["none", "separable", "ss-full", "ss-jittered", "ts"];
    let ts = SkinShader::Ts(TsSettings::default());
    let shaders = [SkinShader::None, SkinShader::Separable, SkinShader::SsFull, SkinShader::SsJittered, ts];
    let stretch = StretchPreset::default();
    let shader_count = if slicings[0].is_some() { 1 } else { names.len() };
    let runs = shapes.iter().flat_map(|&r| slicings.iter().map(move |&c| (r, c)));
    let runs = runs.flat_map(|(r, c)| names.into_iter().zip(shaders).take(shader_count).map(move |n| (r, c, n)));
    for (shape, slicing, (name, shader)) in runs {
        RasterShape::set_on_this_thread(Some(shape));
        Slices::set_on_this_thread(slicing);
        let name = match slicing {
            Some(c) => format!("{name} (raster: {}, slices {}x{})", shape.name(), c.rows, c.columns),
            None => format!("{name} (raster: {})", shape.name()),
        };
        let s = SkinRenderSettings { shader, heads: 1, distance_m: 0.6, width, height, melanin: 0.02, stretch };
        let mut profiles: Vec<Vec<PassTime>> = Vec::new();
        let mut wall = Vec::new();
        for frame in 0..=frames {
            set_pass_profiling(true);
            let t = Instant::now();
            render_with(Some(&g), &head, &s, &SkinPasses::default(), &assets).expect("render");
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let p = take_pass_profile(&g.device, &g.queue).expect("pass profile");
            set_pass_profiling(false);
            if frame > 0 {
                wall.push(ms);
                profiles.push(p);
            }
        }
        let first = &profiles[0];
        assert!(
            profiles.iter().all(|p| p.len() == first.len() && p.iter().zip(first).all(|(a, b)| a.label == b.label)),
            "{name}: the frames recorded different passes"
        );
        println!("== {name}: wall {:.2} ms per frame (submit + wait, uploads and read-back included)", median(wall));
        if first.is_empty() {
            println!("  no compute-chain pass recorded (this shader's frame does not go through compute chains)");
            continue;
        }
        println!("  {:<52} {:>10} {:>10} {:>10} {:>10}", "pass", "GPU ms", "MB moved", "bound ms", "time/bound");
        let (mut chain_ms, mut chain_bytes, mut all_ms) = (0.0, 0u64, 0.0);
        for (k, p) in first.iter().enumerate() {
            let ms = timed.then(|| median(profiles.iter().map(|f| f[k].gpu_ms.unwrap_or(f64::NAN)).collect()));
            let cell = ms.map_or("-".to_string(), |m| format!("{m:.4}"));
            all_ms += ms.unwrap_or(0.0);
            match (p.span, p.bytes) {
                (true, _) => {
                    println!("  {:<52} {cell:>10}  span: {}", p.label, span_holds(&p.label));
                }
                (false, Some(b)) => {
                    let bound = bound_ms(b);
                    chain_ms += ms.unwrap_or(0.0);
                    chain_bytes += b;
                    let ratio = ms.map(|m| m / bound);
                    println!(
                        "  {:<52} {cell:>10} {:>10.2} {bound:>10.4} {:>10}{}",
                        p.label,
                        b as f64 * 1e-6,
                        ratio.map_or("-".to_string(), |r| format!("{r:.1}")),
                        if ratio.is_some_and(|r| r > 4.0) { "  OVER 4x" } else { "" }
                    );
                }
                (false, None) => println!("  {:<52} {cell:>10}  (bytes unknown: module not analysed)", p.label),
            }
        }
        let bound = bound_ms(chain_bytes);
        match timed {
            true => println!(
                "  chain passes: {chain_ms:.3} ms, {:.1} MB, bound {bound:.4} ms, time/bound {:.1}; all timed pieces \
                 {all_ms:.3} ms",
                chain_bytes as f64 * 1e-6,
                chain_ms / bound
            ),
            false => println!("  chain passes: {:.1} MB, bound {bound:.4} ms", chain_bytes as f64 * 1e-6),
        }
    }
}
