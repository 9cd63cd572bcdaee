//! TAP 2009 Table III's scaling experiment with rtbake's skin shaders: frame time of `run skin` (mesh G-buffer,
//! shadow map, skin inputs, SSS pass, composite; host read-backs between stages included, as the chain runs them
//! today) for 1, 3 and 5 heads at 1280×720, per shader, median and min–max of 5 runs after a warm-up, and the
//! change from 1 to 5 heads. TAP measured on a GeForce 8600M GS: SS Full 29 → 25 fps (−13 %), TS 26 → 9 fps
//! (−65 %), No SSS 51 → 40 fps. `ts` is rtbake's texture-space diffusion at its default 1024² map, no ch. 3
//! optimisation (d'Eon et al. 2007 as TAP ran it).
//!
//!     cargo run --release --example bench_skin_heads            # the adapter (WGPU_BACKEND/WGPU_ADAPTER_NAME)
//!     cargo run --release --example bench_skin_heads -- cpu     # the CPU twins
//!
//! The adapter is printed: figures from llvmpipe/lavapipe are CPU figures, not GPU figures. Tables come from the
//! committed bake (`baked/`, or $RTBAKE_BAKED_DIR) through the manifest-checked loader.

use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::create_headless;
use rtbake::runtime::skin_render::{render, SkinRenderSettings, SkinShader};
use rtbake::runtime::texture_space::TsSettings;
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let cpu = std::env::args().any(|a| a == "cpu");
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let gpu = if cpu { None } else { Some(create_headless(&Default::default()).expect("an adapter")) };
    println!("adapter: {}", gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU twins".into()));
    let head = default_head();
    println!("mesh: the default head, {} triangles; 1280x720; 5 runs after one warm-up", head.triangle_count());
    println!("{:<12} {:>22} {:>22} {:>22} {:>12}", "shader", "1 head ms", "3 heads ms", "5 heads ms", "1 -> 5");
    for (name, shader) in [
        ("none", SkinShader::None),
        ("ss-jittered", SkinShader::SsJittered),
        ("ss-full", SkinShader::SsFull),
        ("separable", SkinShader::Separable),
        ("ts", SkinShader::Ts(TsSettings::default())),
    ] {
        let mut row = Vec::new();
        for heads in [1u32, 3, 5] {
            let s = SkinRenderSettings {
                shader,
                heads,
                distance_m: 0.6 + 0.2 * heads as f32,
                width: 1280,
                height: 720,
                melanin: 0.02,
                stretch: Default::default(),
            };
            let run = || {
                let t = Instant::now();
                render(gpu.as_ref(), &head, &s, &assets).expect("render");
                t.elapsed().as_secs_f64() * 1e3
            };
            // Progress on stderr (a software adapter takes minutes per shader); the table stays on stdout.
            let started = Instant::now();
            eprint!("  {name}, {heads} head(s): warm-up + 5 runs ...");
            run();
            let mut v: Vec<f64> = (0..5).map(|_| run()).collect();
            eprintln!(" {:.1} s", started.elapsed().as_secs_f64());
            v.sort_by(f64::total_cmp);
            row.push((v[2], v[0], v[4]));
        }
        let cell = |(m, lo, hi): (f64, f64, f64)| format!("{m:.1} ({lo:.1}-{hi:.1})");
        println!(
            "{:<12} {:>22} {:>22} {:>22} {:>+11.0}%",
            name,
            cell(row[0]),
            cell(row[1]),
            cell(row[2]),
            (row[2].0 / row[0].0 - 1.0) * 100.0
        );
    }
}
