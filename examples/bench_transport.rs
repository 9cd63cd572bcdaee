//! Benchmark: Monte Carlo photon transport (`rtbake::transport`), photon histories per second, on the two cases of
//! MCML 2.0's `samples/sample1/sample1.mci` (Wang, Jacques & Zheng 1995):
//! (a) van de Hulst's slab: μa = 10 cm⁻¹, μs = 90 cm⁻¹, g = 0.75, n = 1, d = 0.02 cm, air both sides;
//! (b) a semi-infinite medium: μa = 10 cm⁻¹, μs = 90 cm⁻¹, g = 0, n = 1.5 under air.
//! The goal is ≥ 2× MCML per core; the GPU transport's goal is ≥ 10⁹ interaction steps/s on an H100.
//!
//! `cargo run --release --example bench_transport` runs each case in rounds (5, or `RTBAKE_BENCH_ROUNDS`) of
//! rtbake on 1 thread, MCML (when `RTBAKE_MCML` names an MCML 2.0 binary: one channel, its own tallies at the
//! sample's grid) and rtbake on the default rayon pool, alternately, so that the load of the shared machine falls on
//! both alike. It prints the median and min–max wall time per pool, the 1-thread run's CPU time (photon histories
//! = 3 channels × photons, and interactions, per CPU second), MCML's wall and CPU time (user + system of the child),
//! and the per-core ratio: rtbake's histories per CPU second over MCML's photons per CPU second, median and min–max
//! of the per-round ratios. CPU time, not wall time, is the per-core measure on a machine whose cores other
//! processes share (wall time there counts their turns). It also checks that every run and pool gave the same bytes.
//!
//! Measured 2026-11-25 (commit e288609, the photon-lane engine `transport::lanes` on its AVX-512F path, 5 rounds,
//! shared 2-core machine at load 2, `RTBAKE_MCML=/tmp/mcml/mcml RTBAKE_BENCH_ROUNDS=5`): (a) CPU median 0.117 s
//! (0.111–0.118) = 25.6 M histories per CPU second vs MCML's 7.0 M photons → 3.67× per core (per round
//! 3.63–3.85); (b) 0.221 s (0.220–0.222) = 2.72 M vs 0.61 M → 4.42× (4.35–4.65). Goal 2×: met. The scalar engine
//! before it (b64e702), same session and method: 1.20× (1.19–1.23) and 1.42× (1.40–1.46). The same code with the
//! AVX2 path forced (2 runs of 3 rounds): 2.21–2.39× and 2.52–2.57×; the portable path (SSE2): 0.39× and 0.41×.
//!
//! When an adapter is found (`WGPU_BACKEND`, `WGPU_ADAPTER_NAME` as for the runtime) the GPU path
//! (`runtime::transport_gpu`, pipeline compiled once, one warm-up run) is timed the same way: median and min–max
//! wall time of 5 runs (dispatches, read-backs and the CPU-side reduction included), photons/s, interaction
//! steps/s (absorption + scattering events, the CPU figure's unit; face crossings are not counted), the ratio to the
//! CPU figure of this run and to the 10⁹ steps/s goal, and the adapter's name. A software adapter (llvmpipe,
//! lavapipe) is labelled as such: its figures are CPU figures.

use rtbake::runtime::device::{create_headless, Gpu};
use rtbake::runtime::transport_gpu::TransportGpu;
use rtbake::transport::{simulate, McLayer, McSettings, McStack};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU time of this process (all threads), s. On the shared machine other processes take turns on the cores, so
/// wall time depends on their load; CPU time counts only the time this work ran on a core.
fn process_cpu_s() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec for the call.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID)");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// User + system CPU time of the waited-for children (MCML runs), s.
fn children_cpu_s() -> f64 {
    // SAFETY: an all-zero rusage is a valid value of the plain C struct.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `ru` is a valid, writable rusage for the call.
    let rc = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut ru) };
    assert_eq!(rc, 0, "getrusage(RUSAGE_CHILDREN)");
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(ru.ru_utime) + tv(ru.ru_stime)
}

/// Median, min and max.
fn stats(v: &[f64]) -> (f64, f64, f64) {
    let (lo, hi) = v.iter().fold((f64::MAX, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    (median(v.to_vec()), lo, hi)
}

/// MCML input for one run (lengths in cm).
fn mci(thickness_cm: &str, n: f64, g: f64, photons: u64) -> String {
    format!(
        "mcmli2.0\n  air 1.0 0 0 0\n  medium {n} 10 90 {g}\nend\nout.mco A\n  air\n  medium {thickness_cm}\n  air\nend\n\
         pencil\n0\n0.01 0.01 0.1\n10 100 1 1\nRd_r\n{photons} 10:00\n1E-4\n1\nend\n"
    )
}

fn main() {
    let layer = |t: f64, eta: f64, g: f64| McLayer {
        thickness_mm: t,
        eta,
        sigma_a_per_mm: [1.0; 3],
        sigma_s_per_mm: [9.0; 3],
        g: [g; 3],
    };
    let cases = [
        (
            "(a) van de Hulst slab, 0.2 mm, g 0.75, n 1",
            McStack::new(1.0, 1.0, vec![layer(0.2, 1.0, 0.75)]).unwrap(),
            1_000_000u64,
            "0.02",
            1.0,
            0.75,
        ),
        (
            "(b) semi-infinite, g 0, n 1.5",
            McStack::new(1.0, 1.5, vec![layer(f64::INFINITY, 1.5, 0.0)]).unwrap(),
            200_000,
            "1E8",
            1.5,
            0.0,
        ),
    ];
    let threads = rayon::current_num_threads();
    let mcml = std::env::var_os("RTBAKE_MCML");
    if mcml.is_none() {
        println!(
            "MCML comparison left out: RTBAKE_MCML is unset. To include it, build MCML 2.0 (Wang's distribution, \
             github.com/lhvwang/MCML, folder V2/MCML2.0; make the buffer FindDataLine returns `static` for a modern \
             compiler), e.g. `gcc -O3 -march=native -o mcml *.c -lm`, and run with RTBAKE_MCML=/path/to/mcml"
        );
    }
    let gpu: Option<(Gpu, TransportGpu)> = match create_headless(&Default::default()) {
        Ok(g) => {
            println!("GPU adapter: {}", g.describe());
            let pipeline = TransportGpu::new(&g.device).expect("transport pipeline");
            Some((g, pipeline))
        }
        Err(e) => {
            println!("GPU: none ({e}); CPU figures only");
            None
        }
    };
    let rounds: usize = std::env::var("RTBAKE_BENCH_ROUNDS").ok().and_then(|v| v.parse().ok()).unwrap_or(5);
    let pools: Vec<(usize, rayon::ThreadPool)> = [1, threads]
        .into_iter()
        .map(|n| (n, rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap()))
        .collect();
    for (name, stack, photons, thickness_cm, n, g) in cases {
        let settings = McSettings::new(photons, 1, 10, 0.1, 100).unwrap();
        let histories = 3.0 * photons as f64;
        let dir = std::env::temp_dir().join(format!("rtbake_bench_mcml_{}", std::process::id()));
        if mcml.is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join("in.mci"), mci(thickness_cm, n, g, photons)).unwrap();
        }
        // Rounds of (rtbake on 1 thread, MCML, rtbake on the pool), so that the load of the shared machine
        // falls on both alike. Per core = CPU time of the 1-thread run and of MCML (user + system), taken per
        // round; wall times are printed too.
        let mut wall: Vec<Vec<f64>> = vec![Vec::new(); pools.len()];
        let mut cpu_one = Vec::new();
        let (mut mcml_wall, mut mcml_cpu, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        let mut results = Vec::new();
        for _ in 0..rounds {
            for (i, (_, pool)) in pools.iter().enumerate() {
                let (t0, c0) = (Instant::now(), process_cpu_s());
                let r = pool.install(|| simulate(&stack, &settings));
                wall[i].push(t0.elapsed().as_secs_f64());
                if i == 0 {
                    cpu_one.push(process_cpu_s() - c0);
                }
                results.push(r);
                if let (0, Some(bin)) = (i, &mcml) {
                    let (t0, c0) = (Instant::now(), children_cpu_s());
                    let out = std::process::Command::new(bin).arg("in.mci").current_dir(&dir).output().unwrap();
                    assert!(out.status.success(), "MCML failed: {}", String::from_utf8_lossy(&out.stderr));
                    mcml_wall.push(t0.elapsed().as_secs_f64());
                    let c = children_cpu_s() - c0;
                    mcml_cpu.push(c);
                    ratios.push((histories / cpu_one.last().unwrap()) / (photons as f64 / c));
                }
            }
        }
        assert!(results.windows(2).all(|w| w[0] == w[1]), "the same bytes for every run and thread count");
        let r = &results[0];
        let interactions: u64 = r.channels.iter().map(|c| c.interactions).sum();
        let mut per_pool = Vec::new();
        for ((pool_threads, _), t) in pools.iter().zip(&wall) {
            let (m, lo, hi) = stats(t);
            print!(
                "{name}: {pool_threads} thread(s): wall median {m:.3} s (min {lo:.3}, max {hi:.3}) for {histories:.0} \
                 histories = {:.3e} photons/s",
                histories / m
            );
            if *pool_threads == 1 {
                let (c, clo, chi) = stats(&cpu_one);
                print!(
                    "; CPU median {c:.3} s (min {clo:.3}, max {chi:.3}) = {:.3e} photons/s, {:.3e} interactions/s",
                    histories / c,
                    interactions as f64 / c
                );
            }
            println!("; Rd {:.5}, T {:.5}", r.channels[0].diffuse_reflectance.mean, r.channels[0].transmittance.mean);
            per_pool.push((*pool_threads, histories / m, interactions as f64 / m));
        }
        if mcml.is_some() {
            let (m, lo, hi) = stats(&mcml_wall);
            let (c, clo, chi) = stats(&mcml_cpu);
            let (rm, rlo, rhi) = stats(&ratios);
            println!(
                "{name}: MCML 2.0 (1 thread): wall median {m:.3} s (min {lo:.3}, max {hi:.3}); CPU median {c:.3} s \
                 (min {clo:.3}, max {chi:.3}) for {photons} photons = {:.3e} photons/s; rtbake per core / MCML \
                 (CPU time) = {rm:.2} (per round: min {rlo:.2}, max {rhi:.2}; {rounds} rounds); rtbake on {threads} \
                 threads / MCML (wall) = {:.2}",
                photons as f64 / c,
                per_pool[1].1 / (photons as f64 / m)
            );
            let _ = std::fs::remove_dir_all(&dir);
        }
        if let Some((g, pipeline)) = &gpu {
            let run = || pipeline.simulate(&g.device, &g.queue, &stack, &settings, &|_| {}).expect("GPU transport");
            let warm = run();
            let mut times = Vec::new();
            for _ in 0..5 {
                let t0 = Instant::now();
                let r = run();
                times.push(t0.elapsed().as_secs_f64());
                assert_eq!(r, warm, "the same seed on the same device gives the same result");
            }
            let (lo, hi) = times.iter().fold((f64::MAX, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
            let t = median(times);
            let interactions: u64 = warm.channels.iter().map(|c| c.interactions).sum();
            let steps = interactions as f64 / t;
            println!(
                "{name}: GPU {}: median {t:.3} s (min {lo:.3}, max {hi:.3}) for {histories:.0} histories = {:.3e} \
                 photons/s, {steps:.3e} interaction steps/s ({:.2}x the CPU's {threads} threads, {:.3}x the 1e9 \
                 steps/s goal); Rd {:.5} ± {:.5}, T {:.5} ± {:.5}",
                g.adapter_info.name,
                histories / t,
                steps / per_pool[1].2,
                steps / 1e9,
                warm.channels[0].diffuse_reflectance.mean,
                warm.channels[0].diffuse_reflectance.se,
                warm.channels[0].transmittance.mean,
                warm.channels[0].transmittance.se
            );
        }
    }
}
