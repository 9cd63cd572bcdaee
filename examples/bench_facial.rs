//! Benchmark of the hemoglobin rig bake (thesis eq. 7.1-7.6): neutral + 8 targets at 4096², r = 32 texels,
//! scale/bias stored at 256². Anchor (the first rig bake): <= 10 s on 2 cores; performance goal: <= 2.5 s (2× its load/FP bound).
//!
//! `cargo run --release --example bench_facial [-- SIZE RADIUS RUNS]`; set RAYON_NUM_THREADS=2 to match the anchor.
//! Inputs are the project's synthetic maps (512² tiles repeated; content does not affect the run time).
//!
//! Measured on the project's 2-core AMD EPYC machine (other builds running, load average 1–1.4),
//! RAYON_NUM_THREADS=2, 5 runs, 2026-11-24, before and after the performance work alternately (before = commit e7a7600): wall
//! median 3.15–3.23 s before (min 3.10, max 3.25; CPU 5.63–5.73 s), 1.48–1.49 s after (min 1.44, max 1.51; CPU
//! 2.81–2.83 s): 2.2× faster, 0.59–0.60× the 2.5 s goal.

use rtbake::facial::disk_stats::Border;
use rtbake::facial::hemoglobin_rig::{build_rig, RigSettings};
use rtbake::facial::synthetic;
use std::time::Instant;

fn tiled(tile: &[f64], t: usize, size: usize) -> Vec<f32> {
    let mut out = vec![0.0f32; size * size];
    for y in 0..size {
        for x in 0..size {
            out[y * size + x] = tile[(y % t) * t + x % t] as f32;
        }
    }
    out
}

/// CPU seconds (user + system) of this process so far, from /proc/self/stat (Linux; 0 elsewhere). On a shared
/// machine the wall time depends on the load; CPU time / threads is the uncontended wall-time estimate.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return 0.0 };
    let after = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0 // utime, stime (fields 14, 15) at USER_HZ = 100
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let size: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(4096);
    let radius: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(32);
    let runs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let t = 512.min(size);
    let neutral = tiled(&synthetic::hemoglobin_map(t as u32, 1, None), t, size);
    let targets: Vec<(String, Vec<f32>)> = synthetic::EXPRESSIONS
        .iter()
        .map(|e| (e.name.to_string(), tiled(&synthetic::hemoglobin_map(t as u32, 1, Some(e)), t, size)))
        .collect();
    let refs: Vec<(String, &[f32])> = targets.iter().map(|(n, v)| (n.clone(), v.as_slice())).collect();
    let settings = RigSettings { radius_texels: radius, border: Border::Clip, sigma_floor: 1e-4, rig_size: 256 };
    let threads = rayon::current_num_threads();
    let (c0, t0) = (cpu_seconds(), Instant::now());
    let st = rtbake::facial::disk_stats::disk_stats(&neutral, size as u32, size as u32, radius, Border::Clip).unwrap();
    std::hint::black_box(&st);
    drop(st);
    eprintln!("one disk_stats: {:.3} s wall, {:.3} s CPU", t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
    let mut times = Vec::new();
    let mut cpu = Vec::new();
    for run in 0..runs {
        let (c0, t0) = (cpu_seconds(), Instant::now());
        let rig = build_rig(&neutral, size as u32, size as u32, &refs, &settings).expect("rig");
        let dt = t0.elapsed().as_secs_f64();
        let dc = cpu_seconds() - c0;
        std::hint::black_box(&rig);
        eprintln!("run {run}: {dt:.3} s wall, {dc:.3} s CPU");
        times.push(dt);
        cpu.push(dc);
    }
    cpu.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let cpu_median = cpu[cpu.len() / 2];
    times.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let median = times[times.len() / 2];
    let mp = (1 + targets.len()) as f64 * (size * size) as f64 / 1e6;
    println!(
        "CPU time per run: median {cpu_median:.3} s -> uncontended estimate on {threads} cores {:.3} s (ratio to 10 s anchor {:.2})",
        cpu_median / threads as f64,
        cpu_median / threads as f64 / 10.0
    );
    println!(
        "hemoglobin rig: neutral + {} targets at {size}x{size}, r = {radius}, rig 256x256, {threads} threads: \
         wall median {median:.3} s of {runs} runs (min {:.3}, max {:.3}), {:.1} MP/s; anchor 10 s -> ratio {:.2}; \
         goal 2.5 s -> ratio {:.2}",
        targets.len(),
        times[0],
        times[times.len() - 1],
        mp / median,
        median / 10.0,
        median / 2.5
    );
}
