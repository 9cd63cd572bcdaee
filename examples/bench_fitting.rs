//! Benchmark of the sum-of-Gaussians fitter (anchor: a 6-Gaussian shared fit must take ≤ 0.5 s).
//!
//! `cargo run --release --example bench_fitting [-- RUNS]` prints, for each case, the median wall time of RUNS
//! (default 7, at least 5) runs and its ratio to the 0.5 s anchor, and checks that every run returns identical
//! results. Set RAYON_NUM_THREADS to compare thread counts (results must not change).

use rtbake::diffusion::materials;
use rtbake::diffusion::sum_of_gaussians::deon6;
use rtbake::diffusion::{FdrForm, RadialProfile};
use rtbake::fitting::{error_table, fit_sum_of_gaussians, FitSettings};
use std::time::Instant;

const ANCHOR_S: f64 = 0.5;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bench<T: PartialEq + std::fmt::Debug>(name: &str, runs: usize, anchor: Option<f64>, mut f: impl FnMut() -> T) {
    let mut times = Vec::new();
    let mut first: Option<T> = None;
    for _ in 0..runs {
        let t = Instant::now();
        let out = f();
        times.push(t.elapsed().as_secs_f64());
        match &first {
            None => first = Some(out),
            Some(x) => assert_eq!(x, &out, "{name}: results differ between runs"),
        }
    }
    let m = median(times.clone());
    let min = times.iter().cloned().fold(f64::INFINITY, f64::min);
    match anchor {
        Some(a) => println!(
            "{name:<48} median {:>8.1} ms  min {:>8.1} ms  ratio to {a} s anchor {:.3}",
            m * 1e3,
            min * 1e3,
            m / a
        ),
        None => println!("{name:<48} median {:>8.1} ms  min {:>8.1} ms", m * 1e3, min * 1e3),
    }
}

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(7).max(5);
    println!("threads: {}, runs: {runs}", rayon::current_num_threads());
    let shared6 = FitSettings { count: 6, shared_variances: true, normalize: true, starts: 8 };
    let skin1 = materials::find("skin1").unwrap().dipole(FdrForm::Dj05);
    bench("6-Gaussian shared fit, skin1 dipole (normalised)", runs, Some(ANCHOR_S), || {
        fit_sum_of_gaussians(&skin1, &shared6).unwrap()
    });
    let exact6 = FitSettings { normalize: false, ..shared6.clone() };
    bench("6-Gaussian shared fit, deon6 (exact recovery)", runs, Some(ANCHOR_S), || {
        fit_sum_of_gaussians(&deon6(), &exact6).unwrap()
    });
    let per4 = FitSettings { count: 4, shared_variances: false, normalize: false, starts: 8 };
    let cream = materials::find("cream").unwrap().dipole(FdrForm::Dj05);
    bench("4-Gaussian per-channel fit, cream dipole", runs, None, || fit_sum_of_gaussians(&cream, &per4).unwrap());
    bench("Jensen 2001 error table (33 per-channel fits)", runs, None, || error_table().unwrap());
    let _ = skin1.total_reflectance();
    // Default bakes of this area (each must stay under 1 s in release).
    for asset in rtbake::bake::registry() {
        if ["sss-gaussians", "sss-gaussians-fit", "transmittance"].contains(&asset.name) {
            let params = (asset.default_params)();
            bench(&format!("bake {}", asset.name), runs, Some(1.0), || (asset.bake)(&params).unwrap());
        }
    }
}
