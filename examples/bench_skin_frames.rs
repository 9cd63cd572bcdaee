//! Frames shaped like an engine's: `run skin`'s frame (default passes: bloom on) per shader, first frame and
//! steady state (median of frames 2..=N), with the runtime's per-frame caches off — every frame compiles its shader
//! modules and pipelines and rasterises the texture-space UV maps on the host, as the runtime did before the
//! caches — and on, in one run on one adapter, and the ratio.
//!
//!     cargo run --release --example bench_skin_frames [-- WIDTH HEIGHT FRAMES [no-bloom]]   # 1280 720 5
//!
//! The adapter is printed: figures from llvmpipe/lavapipe are CPU figures, not GPU figures. Each frame includes
//! what `run skin` does per frame (uploads, the G-buffer read-back the host's geometry needs, the final read-back);
//! the last two columns count the queue submissions and host read-backs of a steady-state frame
//! (`runtime::gpu::submissions_on_this_thread`, `read_backs_on_this_thread`). `scripts/bench_skin_frames.sh` runs
//! this binary built from the tree before (each pass submitted and read back on its own) and after, in one run.
//! Tables come from the committed bake (`baked/`, or $RTBAKE_BAKED_DIR).

use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::create_headless;
use rtbake::runtime::gpu::{
    pipelines_created_on_this_thread, read_backs_on_this_thread, set_object_cache_enabled, submissions_on_this_thread,
};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, TsSettings};
use std::path::PathBuf;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (width, height) = (args.first().copied().unwrap_or(1280), args.get(1).copied().unwrap_or(720));
    let frames = args.get(2).copied().unwrap_or(5).max(3) as usize;
    let bloom = !std::env::args().any(|a| a == "no-bloom");
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let g = create_headless(&Default::default()).expect("an adapter");
    println!("adapter: {}", g.describe());
    let head = default_head();
    println!(
        "run skin frame, {} the default head ({} triangles), {width}x{height}; frame 1 and \
         the median of frames 2..={frames} (wall ms, host read-backs included); pipelines compiled per frame",
        if bloom { "default passes (bloom on)," } else { "no bloom," },
        head.triangle_count()
    );
    println!(
        "{:<12} {:>14} {:>14} {:>10} {:>14} {:>14} {:>10} {:>9} {:>8} {:>8}",
        "shader",
        "uncached 1st",
        "uncached 2..N",
        "pipes/fr",
        "cached 1st",
        "cached 2..N",
        "pipes 2..N",
        "speed-up",
        "submits",
        "reads"
    );
    for (name, shader) in [
        ("none", SkinShader::None),
        ("ss-jittered", SkinShader::SsJittered),
        ("ss-full", SkinShader::SsFull),
        ("separable", SkinShader::Separable),
        ("ts", SkinShader::Ts(TsSettings::default())),
    ] {
        let s = SkinRenderSettings {
            shader,
            heads: 1,
            distance_m: 0.6,
            width,
            height,
            melanin: 0.02,
            stretch: Default::default(),
        };
        let passes = if bloom { SkinPasses::default() } else { SkinPasses::none() };
        let run = |cached: bool| {
            set_object_cache_enabled(cached);
            let mut times = Vec::new();
            let mut pipes = Vec::new();
            let mut counts = (0, 0);
            for _ in 0..frames {
                let (t, p) = (Instant::now(), pipelines_created_on_this_thread());
                let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
                render_with(Some(&g), &head, &s, &passes, &assets).expect("render");
                times.push(t.elapsed().as_secs_f64() * 1e3);
                pipes.push(pipelines_created_on_this_thread() - p);
                counts = (submissions_on_this_thread() - sub, read_backs_on_this_thread() - read);
            }
            eprintln!("  {name} ({}): {times:.0?} ms", if cached { "cached" } else { "uncached" });
            (times[0], median(times[1..].to_vec()), pipes[1..].iter().sum::<u64>(), counts)
        };
        let (u1, us, up, _) = run(false);
        let (c1, cs, cp, (subs, reads)) = run(true);
        println!(
            "{name:<12} {u1:>14.1} {us:>14.1} {:>10.1} {c1:>14.1} {cs:>14.1} {cp:>10} {:>8.2}x {subs:>8} {reads:>8}",
            up as f64 / (frames - 1) as f64,
            us / cs
        );
    }
}
