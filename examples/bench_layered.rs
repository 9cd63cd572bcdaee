//! Benchmark: a three-layer skin-like profile (epidermis 0.25 mm, upper dermis 0.5 mm, dermis 20 mm; air above)
//! evaluated at 1000 log-spaced radii in [0.001, 100] mm × 3 channels, R(r) and T(r), exact image series,
//! symmetric adding — construction (k-space sampling) included. Goal (layered profiles): ≤ 20 ms.
//!
//! `cargo run --release --example bench_layered` prints the median wall time of 9 runs, the ratio to the 20 ms goal,
//! the CPU time per run (all threads; wall time on a loaded machine overstates the work) and a checksum that must
//! not change with `RAYON_NUM_THREADS`.

use rtbake::diffusion::layered::{Adding, Layer, LayerStack, LayeredProfile};
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::table::log_radii;
use rtbake::diffusion::{FdrForm, RadialProfile};
use std::time::Instant;

const GOAL_MS: f64 = 20.0;

/// CPU time of this process (all threads, user + system), ms, from /proc/self/stat (Linux; 0 elsewhere).
fn cpu_ms() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return 0.0 };
    // Fields after the ")" closing the command name: state is field 3; utime, stime are fields 14, 15.
    let rest = stat.rsplit_once(')').map_or("", |x| x.1);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 =
        f.get(11).and_then(|v| v.parse().ok()).unwrap_or(0.0) + f.get(12).and_then(|v| v.parse().ok()).unwrap_or(0.0);
    ticks * 10.0 // USER_HZ = 100 on Linux
}

fn main() {
    let stack = LayerStack::new(
        1.0,
        1.0,
        vec![
            Layer { thickness_mm: 0.25, eta: 1.4, sigma_a: [0.2, 0.5, 1.2], sigma_s_prime: [5.0, 6.0, 7.0] },
            Layer { thickness_mm: 0.5, eta: 1.38, sigma_a: [0.03, 0.1, 0.2], sigma_s_prime: [2.0, 2.5, 3.0] },
            Layer { thickness_mm: 20.0, eta: 1.36, sigma_a: [0.01, 0.05, 0.1], sigma_s_prime: [1.5, 2.0, 2.5] },
        ],
    )
    .expect("valid stack");
    let radii = log_radii(1e-3, 100.0, 1000).expect("valid grid");
    let mut times = Vec::new();
    let mut checksum = 0u64;
    let mut k_max = 0.0;
    let runs = 9;
    let cpu0 = cpu_ms();
    for _ in 0..runs {
        let t0 = Instant::now();
        let p = LayeredProfile::new(&stack, Adding::Symmetric, Series::Exact, FdrForm::Dj05).expect("profile");
        let (r, t) = p.profile_many(&radii);
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        k_max = p.k_max();
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        for v in r.iter().chain(t.as_ref().expect("stack has T").iter()).flatten() {
            h = (h ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3);
        }
        checksum = h;
    }
    let cpu_per_run = (cpu_ms() - cpu0) / runs as f64;
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    println!(
        "layered 3-layer profile, 1000 radii x 3 channels (R and T), exact series: median {median:.2} ms over {} runs \
         (min {:.2}, max {:.2}); goal {GOAL_MS} ms, ratio {:.2}; CPU time {cpu_per_run:.1} ms/run (all threads); \
         k_max {k_max:.1} /mm; threads {}; checksum {checksum:016x}",
        times.len(),
        times[0],
        times[times.len() - 1],
        median / GOAL_MS,
        rayon::current_num_threads()
    );
}
