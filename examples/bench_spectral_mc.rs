//! Benchmark of a spectral Monte Carlo skin profile: the physiological skin (Cm 0.1, Chd 0.1) per wavelength
//! (380–780 nm, 10 nm; 14 runs of three wavelengths) at the tissue-like g = 0.8, with enough photons per wavelength
//! for a standard error of the projected total R of at most 1 % in every channel; the goal is ≤ 30 s on the
//! project's 2-core machine.
//!
//! `cargo run --release --example bench_spectral_mc [-- RUNS [PHOTONS]]` prints the median and min–max wall time of
//! RUNS (default 3) runs, the totals with their standard errors, and whether the 1 % and 30 s goals are met. Every
//! run must return identical totals.

use rtbake::diffusion::layered::Adding;
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::source::TransportModel;
use rtbake::diffusion::FdrForm;
use rtbake::spectral::skin_layers::{physiological_skin_source, SkinPhysiology, SkinProjection};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(3).max(1);
    let photons: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(25_000);
    let transport = TransportModel::monte_carlo(0.8, photons, 1).expect("valid settings");
    let (source, _) = physiological_skin_source(
        &SkinPhysiology::default(),
        &SkinProjection::default(),
        0.1,
        0.1,
        Adding::Symmetric,
        Series::Exact,
        FdrForm::Dj05,
        transport,
    )
    .expect("valid skin");
    let mut times = Vec::new();
    let mut first: Option<([f64; 3], [f64; 3])> = None;
    for _ in 0..runs {
        let t = Instant::now();
        let profile = source.build().expect("builds");
        let out = (profile.total_reflectance(), profile.total_reflectance_se().expect("Monte Carlo"));
        times.push(t.elapsed().as_secs_f64());
        match &first {
            None => first = Some(out),
            Some(x) => assert_eq!(x, &out, "results differ between runs"),
        }
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let (total, se) = first.expect("at least one run");
    let worst = (0..3).map(|c| se[c] / total[c]).fold(0.0, f64::max);
    println!(
        "spectral Monte Carlo skin (Cm 0.1, Chd 0.1, g 0.8, 41 wavelengths x {photons} photons), {} thread(s): \
         wall median {median:.2} s (min {:.2}, max {:.2}) of {runs}; total R {total:.5?} +- {se:.5?} \
         (worst relative SE {:.2} %); goals: SE <= 1 % {}, <= 30 s {}",
        rayon::current_num_threads(),
        times[0],
        times[times.len() - 1],
        100.0 * worst,
        if worst <= 0.01 { "met" } else { "NOT met" },
        if median <= 30.0 { "met" } else { "NOT met" },
    );
}
