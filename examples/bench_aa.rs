//! Benchmark of the antialiasing textures: `cargo run --release --example bench_aa [-- RUNS]`.
//!
//! Prints, for every texture, the median wall time of RUNS runs (default 9, at least 5) and, for the SMAA area
//! texture, the speed-up against the anchor: the upstream Python generator (`AreaTex.py`) needs about 310 s of CPU
//! time (`specs/smaa-mlaa.md`). Set `RAYON_NUM_THREADS` to fix the thread count; the bytes do not depend on it.

use rtbake::aa::mlaa_area::{mlaa_area_map, MlaaVersion};
use rtbake::aa::smaa_area::{smaa_area_texture, SmaaAreaParams};
use rtbake::aa::smaa_search;
use std::time::{Duration, Instant};

/// CPU time of the reference Python generator for the SMAA area texture (seconds).
const ANCHOR_SMAA_AREA_S: f64 = 310.0;

fn median_of(runs: usize, mut f: impl FnMut() -> usize) -> (Duration, usize) {
    let mut times = Vec::with_capacity(runs);
    let mut len = 0;
    for _ in 0..runs {
        let t = Instant::now();
        len = std::hint::black_box(f());
        times.push(t.elapsed());
    }
    times.sort();
    (times[runs / 2], len)
}

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(9).max(5);
    let threads = rayon::current_num_threads();
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    println!("rtbake bench_aa: median of {runs} runs, {threads} rayon threads, {cores} logical CPUs");
    println!("{:<34} {:>12} {:>10}", "texture", "median", "bytes");

    let report = |name: &str, (t, len): (Duration, usize)| {
        println!("{name:<34} {:>9.3} ms {len:>10}", t.as_secs_f64() * 1e3);
        t
    };

    let smaa = report(
        "SMAA AreaTex 160x560 (2.8+)",
        median_of(runs, || smaa_area_texture(&SmaaAreaParams::default()).unwrap().data.len()),
    );
    report(
        "SMAA AreaTex 160x560 (v2.8)",
        median_of(runs, || smaa_area_texture(&SmaaAreaParams::v2_8()).unwrap().data.len()),
    );
    report("SMAA SearchTex 64x16", median_of(runs, || smaa_search::search_texture().data.len()));
    report("SMAA SearchTex v2.8 66x33", median_of(runs, || smaa_search::search_texture_v2_8().data.len()));
    for &n in MlaaVersion::V1_4.published() {
        let name = format!("MLAA AreaMap{n} v1.4 {0}x{0}", 5 * n);
        report(&name, median_of(runs, || mlaa_area_map(MlaaVersion::V1_4, n).unwrap().data.len()));
    }
    for &n in MlaaVersion::V1_3.published() {
        let name = format!("MLAA AreaMap{n} v1.3 {0}x{0}", 5 * n);
        report(&name, median_of(runs, || mlaa_area_map(MlaaVersion::V1_3, n).unwrap().data.len()));
    }
    report(
        "MLAA AreaMap1023 v1.4 5115x5115",
        median_of(runs, || mlaa_area_map(MlaaVersion::V1_4, 1023).unwrap().data.len()),
    );
    report("MLAA 2.0 AreaTex 75x75", median_of(runs, || mlaa_area_map(MlaaVersion::V2, 15).unwrap().data.len()));

    let s = smaa.as_secs_f64();
    println!(
        "SMAA area texture: {:.3} ms wall vs {ANCHOR_SMAA_AREA_S} s CPU for the Python reference: {:.0}x faster \
         (goal: <= 100 ms on 2 cores)",
        s * 1e3,
        ANCHOR_SMAA_AREA_S / s
    );
}
