//! Frames shaped like an engine's: `run skin`'s frame (default passes: bloom on) per shader on a device, its
//! shading recorded into one command encoder with one read-back ("one encoder", the runtime's path) against each
//! pass submitted and read back on its own ("per pass", the path before;
//! `runtime::skin::shade_frame::set_shading_in_one_encoder(false)`), in one run on one adapter: the first frame of
//! each on a fresh device (shader modules and pipelines compiled), then frames of the two paths alternating on one
//! device, and the median of frames 2..=N of each, their ratio and the queue submissions and host read-backs of a
//! steady-state frame (`runtime::gpu::submissions_on_this_thread`, `read_backs_on_this_thread`).
//!
//!     cargo run --release --example bench_skin_frames [-- WIDTH HEIGHT FRAMES [no-bloom]]   # 1280 720 7
//!
//! The adapter is printed: figures from llvmpipe/lavapipe are CPU figures, not GPU figures (there a read-back is a
//! copy within host memory). Each frame includes what `run skin` does per frame (uploads, the final read-back; on
//! the per-pass path also the G-buffer read-back the host's geometry needs). Texture-space diffusion ("ts") has a one-encoder path too
//! (its irradiance maps lit, blurred and gathered on the device; one read-back of the frame and its texel counts). Tables come from the committed bake (`baked/`, or $RTBAKE_BAKED_DIR).

use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::{create_headless, Gpu};
use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, TsSettings};
use std::path::PathBuf;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One frame on `g` through the one-encoder path or not: wall ms, submissions, read-backs.
fn frame(g: &Gpu, one_encoder: bool, s: &SkinRenderSettings, passes: &SkinPasses, assets: &DemoAssets) -> [f64; 3] {
    set_shading_in_one_encoder(one_encoder);
    let head = default_head();
    let (sub, read, t) = (submissions_on_this_thread(), read_backs_on_this_thread(), Instant::now());
    render_with(Some(g), &head, s, passes, assets).expect("render");
    let ms = t.elapsed().as_secs_f64() * 1e3;
    [ms, (submissions_on_this_thread() - sub) as f64, (read_backs_on_this_thread() - read) as f64]
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (width, height) = (args.first().copied().unwrap_or(1280), args.get(1).copied().unwrap_or(720));
    let frames = args.get(2).copied().unwrap_or(7).max(3) as usize;
    let bloom = !std::env::args().any(|a| a == "no-bloom");
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let device = || create_headless(&Default::default()).expect("an adapter");
    let g = device();
    println!("adapter: {}", g.describe());
    println!(
        "run skin frame, {} the default head ({} triangles), {width}x{height}; frame 1 (a fresh device) and the \
         median of frames 2..={frames} (the two paths alternating), wall ms; submissions / read-backs per frame",
        if bloom { "default passes (bloom on)," } else { "no bloom," },
        default_head().triangle_count()
    );
    println!(
        "{:<12} {:>13} {:>13} {:>13} {:>13} {:>8} {:>13} {:>13}",
        "shader",
        "1st per-pass",
        "1st one-enc",
        "2..N per-pass",
        "2..N one-enc",
        "ratio",
        "per-pass s/r",
        "one-enc s/r"
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
        let first = [false, true].map(|one| frame(&device(), one, &s, &passes, &assets)[0]);
        let (mut per_pass, mut one_enc) = (Vec::new(), Vec::new());
        for _ in 0..frames {
            per_pass.push(frame(&g, false, &s, &passes, &assets));
            one_enc.push(frame(&g, true, &s, &passes, &assets));
        }
        let ms = |v: &[[f64; 3]]| median(v[1..].iter().map(|f| f[0]).collect());
        let (p, o) = (ms(&per_pass), ms(&one_enc));
        let counts = |v: &[[f64; 3]]| format!("{}/{}", v[frames - 1][1], v[frames - 1][2]);
        eprintln!("  {name}: per pass {:.0?} ms, one encoder {:.0?} ms", per_pass, one_enc);
        println!(
            "{name:<12} {:>13.1} {:>13.1} {p:>13.1} {o:>13.1} {:>7.2}x {:>13} {:>13}",
            first[0],
            first[1],
            p / o,
            counts(&per_pass),
            counts(&one_enc)
        );
    }
}
