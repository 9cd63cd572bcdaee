//! The machine bounds `scripts/bench.sh` compares the heavy jobs with, measured on the machine it runs on, and the
//! SIMD path each job takes on this CPU.
//!
//! - Memory bandwidth: STREAM's triad `a[i] = b[i] + s·c[i]` (McCalpin, "STREAM: Sustainable Memory Bandwidth in
//!   High Performance Computers") over three 64 MiB f64 arrays on every rayon thread, counting 24 bytes per element
//!   (two reads, one write; write-allocate not counted, as STREAM does); best of 5.
//! - f64 FLOP rate: 96 independent fused multiply-add chains per thread on the widest vector path this CPU has
//!   (AVX-512F, AVX2+FMA, or the baseline's separate multiply and add), 2 flops per FMA; best of 3.
//! - SIMD paths: the same run-time selection the library makes (skin-colour LUT rows and the Monte Carlo lanes:
//!   AVX-512F, else AVX2, else portable; the hemoglobin rig's disk statistics: AVX2, else portable).
//!
//!     cargo run --release --example bench_bounds
//!
//! Output (parsed by `scripts/bench.sh`):
//!     bounds: memory 19.5 GB/s, f64 63.5 GFLOP/s, 2 threads, FMA path avx512f
//!     simd: skin-lut avx512f, transport avx512f, rig avx2

use rayon::prelude::*;
use std::hint::black_box;
use std::time::Instant;

const ELEMENTS: usize = 8 << 20;
const CHAINS: usize = 12;
const LANES: usize = 8;
const ITERATIONS: usize = 4_000_000;

/// GB/s of the triad on every thread (best of 5).
fn memory_gb_per_s() -> f64 {
    let b = vec![1.0f64; ELEMENTS];
    let c = vec![2.0f64; ELEMENTS];
    let mut a = vec![0.0f64; ELEMENTS];
    let s = black_box(3.0);
    let chunk = ELEMENTS / (4 * rayon::current_num_threads()).max(1);
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        a.par_chunks_mut(chunk).zip(b.par_chunks(chunk)).zip(c.par_chunks(chunk)).for_each(|((a, b), c)| {
            for i in 0..a.len() {
                a[i] = b[i] + s * c[i];
            }
        });
        best = best.min(t.elapsed().as_secs_f64());
        black_box(&a);
    }
    24.0 * ELEMENTS as f64 / best / 1e9
}

#[inline(always)]
fn fma_chains(a: f64, b: f64) -> f64 {
    let mut acc = [[1.0f64; LANES]; CHAINS];
    for _ in 0..ITERATIONS {
        for v in acc.iter_mut() {
            for x in v.iter_mut() {
                *x = x.mul_add(a, b);
            }
        }
    }
    acc.iter().flatten().sum()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
unsafe fn fma_avx512(a: f64, b: f64) -> f64 {
    fma_chains(a, b)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn fma_avx2(a: f64, b: f64) -> f64 {
    fma_chains(a, b)
}

/// Baseline: a separate multiply and add (2 flops) — no FMA instruction without the feature.
fn mul_add_portable(a: f64, b: f64) -> f64 {
    let mut acc = [[1.0f64; LANES]; CHAINS];
    for _ in 0..ITERATIONS {
        for v in acc.iter_mut() {
            for x in v.iter_mut() {
                *x = *x * a + b;
            }
        }
    }
    acc.iter().flatten().sum()
}

/// The widest FMA path of this CPU: (name, kernel).
fn fma_path() -> (&'static str, fn(f64, f64) -> f64) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: AVX-512F and FMA checked at run time.
            return ("avx512f", |a, b| unsafe { fma_avx512(a, b) });
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            // SAFETY: AVX2 and FMA checked at run time.
            return ("avx2+fma", |a, b| unsafe { fma_avx2(a, b) });
        }
    }
    ("portable", mul_add_portable)
}

/// GFLOP/s of `kernel` on every thread at once (best of 3).
fn flop_rate(kernel: fn(f64, f64) -> f64) -> f64 {
    let threads = rayon::current_num_threads();
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let t = Instant::now();
        let s: f64 = (0..threads).into_par_iter().map(|_| kernel(black_box(0.999_999_9), black_box(1e-9))).sum();
        best = best.min(t.elapsed().as_secs_f64());
        black_box(s);
    }
    (threads * ITERATIONS * CHAINS * LANES * 2) as f64 / best / 1e9
}

/// The path the library's run-time selection takes: AVX-512F, else AVX2, else portable (`wide`), or AVX2 else
/// portable.
fn simd_path(wide: bool) -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if wide && std::arch::is_x86_feature_detected!("avx512f") {
            return "avx512f";
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            return "avx2";
        }
    }
    "portable"
}

fn main() {
    let (name, kernel) = fma_path();
    let memory = memory_gb_per_s();
    let flops = flop_rate(kernel);
    let transport = match rtbake::transport::lanes::Path::detect() {
        rtbake::transport::lanes::Path::Avx512 => "avx512f",
        rtbake::transport::lanes::Path::Avx2 => "avx2",
        rtbake::transport::lanes::Path::Portable => "portable",
    };
    println!(
        "bounds: memory {memory:.1} GB/s, f64 {flops:.1} GFLOP/s, {} threads, FMA path {name}",
        rayon::current_num_threads()
    );
    println!("simd: skin-lut {}, transport {transport}, rig {}", simd_path(true), simd_path(false));
}
