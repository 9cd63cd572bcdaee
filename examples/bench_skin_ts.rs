//! Thesis Table 3.1 with rtbake's texture-space diffusion (`run skin --shader ts`): for each ch. 3 optimisation
//! (none, culled, depth-sized, clipped, all) the texels lit and blurred, the texels allocated, and the frame time
//! (whole `run skin` frame: G-buffer, shadow map, skin inputs, irradiance maps, blurs, gather, composite; median
//! and min–max of the runs after a warm-up), per number of heads and camera distance, with the speed-up of each
//! optimisation over none and the thesis' Table 3.1 speed-ups (all three optimisations, GeForce 8800 GTX, 1920×1200,
//! T_max = 2048, distances in the thesis' scene units) beside them.
//!
//!     cargo run --release --example bench_skin_ts                         # the adapter, 1280×720, T_max 1024
//!     cargo run --release --example bench_skin_ts -- cpu map=256 runs=3   # the CPU twins (small maps only)
//!
//! Options: `cpu`, `map=N` (T_max, 32..=2048), `runs=N`, `heads=1,4`, `distances=0.6,2.4`, `size=WxH`. The adapter is
//! printed: figures from llvmpipe/lavapipe are CPU figures, not GPU figures.

use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::create_headless;
use rtbake::runtime::skin_render::{SkinRenderSettings, SkinShader};
use rtbake::runtime::texture_space::{render, TsSettings, TsStats};
use std::path::PathBuf;
use std::time::Instant;

/// Thesis Table 3.1: speed-up of all three optimisations, rows 1, 2, 4, 8, 16 heads, distances 2.5–100.
const TABLE_3_1: [(u32, [f64; 6]); 5] = [
    (1, [1.17, 1.10, 1.39, 1.48, 1.53, 1.61]),
    (2, [1.40, 1.10, 1.46, 1.63, 1.88, 1.88]),
    (4, [1.66, 1.39, 1.58, 1.89, 2.10, 2.26]),
    (8, [1.86, 1.67, 1.95, 2.01, 2.34, 2.59]),
    (16, [2.01, 1.90, 2.28, 2.41, 2.50, 2.77]),
];

fn arg<'a>(name: &str, args: &'a [String]) -> Option<&'a str> {
    args.iter().find_map(|a| a.strip_prefix(name).and_then(|r| r.strip_prefix('=')))
}

fn list<T: std::str::FromStr>(s: &str) -> Vec<T> {
    s.split(',').map(|v| v.parse().ok().expect("a number")).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cpu = args.iter().any(|a| a == "cpu");
    let map: u32 = arg("map", &args).map_or(if cpu { 256 } else { 1024 }, |v| v.parse().expect("map=N"));
    let runs: usize = arg("runs", &args).map_or(5, |v| v.parse().expect("runs=N"));
    let heads: Vec<u32> = arg("heads", &args).map_or(vec![1, 4], list);
    let distances: Vec<f32> = arg("distances", &args).map_or(vec![0.6, 2.4], list);
    let (w, h): (u32, u32) = arg("size", &args).map_or((1280, 720), |v| {
        let (a, b) = v.split_once('x').expect("size=WxH");
        (a.parse().unwrap(), b.parse().unwrap())
    });
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let gpu = if cpu { None } else { Some(create_headless(&Default::default()).expect("an adapter")) };
    let head = default_head();
    println!("adapter: {}", gpu.as_ref().map(|g| g.describe()).unwrap_or_else(|| "CPU twins".into()));
    println!(
        "mesh: the default head, {} triangles; {w}x{h}; T_max {map}; {runs} runs after one warm-up",
        head.triangle_count()
    );
    println!(
        "{:<6} {:>6} {:<6} {:>12} {:>8} {:>12} {:>8} {:>24} {:>8}",
        "heads", "dist m", "opt", "shaded", "ratio", "map texels", "ratio", "frame ms med (min-max)", "speed-up"
    );
    let opts = [
        ("none", TsSettings { map_size: map, ..Default::default() }),
        ("cull", TsSettings { map_size: map, cull: true, ..Default::default() }),
        ("depth", TsSettings { map_size: map, depth_sized: true, ..Default::default() }),
        ("clip", TsSettings { map_size: map, clip: true, ..Default::default() }),
        ("all", TsSettings::optimised(map)),
    ];
    for &n in &heads {
        for &d in &distances {
            let mut base: Option<(TsStats, f64)> = None;
            for (name, ts) in opts {
                let s = SkinRenderSettings {
                    shader: SkinShader::Ts(ts),
                    heads: n,
                    distance_m: d,
                    width: w,
                    height: h,
                    melanin: 0.02,
                    stretch: Default::default(),
                };
                let run = || {
                    let t = Instant::now();
                    let (_, stats) = render(gpu.as_ref(), &head, &s, ts, &assets).expect("render");
                    (stats, t.elapsed().as_secs_f64() * 1e3)
                };
                // Progress on stderr (a software adapter takes minutes per row); the table stays on stdout.
                let started = Instant::now();
                eprint!("  {n} head(s) at {d} m, {name}: warm-up + {runs} runs ...");
                let (stats, _) = run();
                let mut v: Vec<f64> = (0..runs).map(|_| run().1).collect();
                eprintln!(" {:.1} s", started.elapsed().as_secs_f64());
                v.sort_by(f64::total_cmp);
                let med = v[v.len() / 2];
                let (b_stats, b_ms) = base.get_or_insert_with(|| (stats.clone(), med)).clone();
                println!(
                    "{:<6} {:>6.2} {:<6} {:>12} {:>8.3} {:>12} {:>8.3} {:>24} {:>8.2}",
                    n,
                    d,
                    name,
                    stats.shaded_texels(),
                    stats.shaded_texels() as f64 / b_stats.shaded_texels().max(1) as f64,
                    stats.map_texels(),
                    stats.map_texels() as f64 / b_stats.map_texels() as f64,
                    format!("{med:.1} ({:.1}-{:.1})", v[0], v[v.len() - 1]),
                    b_ms / med
                );
            }
        }
        if let Some((_, row)) = TABLE_3_1.iter().find(|(k, _)| *k == n) {
            println!(
                "       thesis Table 3.1, {n} head(s), all three, distances 2.5/5/10/20/50/100: {}",
                row.map(|x| format!("{x:.2}")).join(" ")
            );
        }
    }
    println!("d_ref of eq. 3.1 at this frame height: {:.2} m", {
        let s = SkinRenderSettings {
            shader: SkinShader::Ts(opts[0].1),
            heads: 1,
            distance_m: 1.0,
            width: w,
            height: h,
            melanin: 0.02,
            stretch: Default::default(),
        };
        render(gpu.as_ref(), &head, &s, opts[0].1, &assets).expect("render").1.d_ref_m
    });
}
