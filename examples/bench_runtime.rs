//! Per-pass timings of the runtime at 720p and 1080p, and the CPU reference SMAA at 1080p on 2 threads.
//!
//!     cargo run --release --example bench_runtime
//!
//! GPU passes are timed with timestamp queries when the adapter supports them, else by wall time of
//! submit + wait (which includes driver overhead). The adapter is printed first: figures from a software
//! rasteriser (lavapipe/llvmpipe) are CPU figures, not GPU figures. Thesis anchors: SMAA 1x 1.02 ms at 1080p
//! (GTX 470); Jimenez MLAA 0.44 ms at 720p (9800 GTX+). CPU anchor: Reshetov's CPU MLAA, 350 ms; goal ≤ 100 ms.
//! LUTs: the upstream golden textures from $RTBAKE_REFERENCE_DIR (default ../shared/reference).

use rtbake::runtime::cpu::{self, FilterPrecision};
use rtbake::runtime::device::{create_headless, DeviceOptions};
use rtbake::runtime::gpu::GpuTimer;
use rtbake::runtime::mlaa::{Mlaa, MlaaAreaMap};
use rtbake::runtime::scene::render_shapes;
use rtbake::runtime::smaa::{Smaa, SmaaTextures};
use std::path::PathBuf;
use std::time::Instant;

const RUNS: usize = 7;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn reference(rel: &str) -> Vec<u8> {
    let dir = std::env::var_os("RTBAKE_REFERENCE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/reference"));
    std::fs::read(dir.join(rel)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(rel).display()))
}

type Encode<'a> = dyn Fn(&mut wgpu::CommandEncoder, Option<(&GpuTimer, u32)>) + 'a;

/// Times `encode` (3 passes) RUNS times; returns per-pass medians (timestamps) or the wall-time median.
fn time_passes(g: &rtbake::runtime::device::Gpu, encode: &Encode<'_>) -> (Vec<f64>, f64) {
    let timer = g.timestamps.then(|| GpuTimer::new(&g.device, 3));
    let mut per_pass: Vec<Vec<f64>> = vec![Vec::new(); 3];
    let mut wall = Vec::new();
    for run in 0..RUNS + 1 {
        let mut enc = g.device.create_command_encoder(&Default::default());
        encode(&mut enc, timer.as_ref().map(|t| (t, 0)));
        if let Some(t) = &timer {
            t.resolve(&mut enc);
        }
        let t0 = Instant::now();
        g.queue.submit([enc.finish()]);
        g.device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if run == 0 {
            continue; // warm-up (pipeline compilation on first use)
        }
        wall.push(ms);
        if let Some(t) = &timer {
            for (k, v) in t.read_ms(&g.device, &g.queue).unwrap().into_iter().enumerate() {
                per_pass[k].push(v);
            }
        }
    }
    let pp = if timer.is_some() { per_pass.into_iter().map(median).collect() } else { Vec::new() };
    (pp, median(wall))
}

fn main() {
    let g = create_headless(&DeviceOptions { timestamps: true }).expect("an adapter");
    println!("adapter: {}", g.describe());
    println!("timestamps: {}", if g.timestamps { "yes (per-pass GPU time)" } else { "no (wall time only)" });
    let luts =
        SmaaTextures::new(reference("smaa/AreaTex_RG8_160x560.bin"), reference("smaa/SearchTex_R8_64x16.bin")).unwrap();
    let n = 33;
    let map = MlaaAreaMap::new(n, reference(&format!("mlaa/AreaMap{n}_v1.4_RG8_165x165.bin"))).unwrap();
    println!("medians of {RUNS} runs; scene: procedural shapes (rtbake::runtime::scene)");
    for (w, h) in [(1280u32, 720u32), (1920, 1080)] {
        let img = render_shapes(w, h, 1);
        let smaa = Smaa::new(&g.device, &g.queue, w, h, &luts).unwrap();
        smaa.upload(&g.queue, &img).unwrap();
        let (pp, wall) = time_passes(&g, &|e, t| smaa.encode(e, t));
        print_line(&format!("SMAA 1x {w}x{h}"), &pp, wall, "thesis 1.02 ms @1080p GTX 470");
        let mlaa = Mlaa::new(&g.device, &g.queue, w, h, &map).unwrap();
        mlaa.upload(&g.queue, &img).unwrap();
        let (pp, wall) = time_passes(&g, &|e, t| mlaa.encode(e, t));
        print_line(&format!("MLAA N={n} {w}x{h}"), &pp, wall, "thesis 0.44 ms @720p 9800 GTX+");
    }
    // CPU reference SMAA at 1080p on 2 threads.
    let (w, h) = (1920, 1080);
    let img = render_shapes(w, h, 1);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let times: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            let out = pool.install(|| cpu::smaa::smaa(&img, w, h, &luts, FilterPrecision::Exact));
            std::hint::black_box(out.output.len());
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let m = median(times);
    println!(
        "CPU reference SMAA 1x 1920x1080, 2 threads: {m:.1} ms (goal <= 100 ms: {}; vs Reshetov CPU MLAA 350 ms: {:.2}x)",
        if m <= 100.0 { "met" } else { "NOT met" },
        350.0 / m
    );
}

fn print_line(name: &str, per_pass: &[f64], wall: f64, anchor: &str) {
    if per_pass.is_empty() {
        println!("{name}: wall {wall:.2} ms (submit+wait)  [{anchor}]");
    } else {
        let total: f64 = per_pass.iter().sum();
        println!(
            "{name}: edges {:.2} ms, weights {:.2} ms, blend {:.2} ms, total {total:.2} ms (wall {wall:.2} ms)  [{anchor}]",
            per_pass[0], per_pass[1], per_pass[2]
        );
    }
}
