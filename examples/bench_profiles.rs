//! Benchmark of the profile tools (tabulated, Burley, layered) against the existing Gaussian fit, measured side by side in one run.
//!
//! `cargo run --release --example bench_profiles [-- RUNS]` prints, for each job, the median and min–max wall time
//! of RUNS (default 7, at least 5) runs and its ratio to the anchor: the existing 6-Gaussian shared fit of the skin1
//! dipole (`rtbake fit gaussians --material skin1 --count 6`). Every run must return identical results. Jobs: the
//! Burley fit of the same dipole, a 1000-sample importance-sampled kernel bake (kernel + JSON, shader includes and
//! binary table) from the skin1 dipole (tabulated CDF) and from a Burley profile (closed-form CDF), and the default
//! bakes of `burley-profiles` and `sss-importance-kernels`. Set RAYON_NUM_THREADS to compare thread counts.

use rtbake::diffusion::burley::{RgbBurley, ShapeFit};
use rtbake::diffusion::{materials, FdrForm};
use rtbake::fitting::burley_fit::fit_burley;
use rtbake::fitting::{fit_sum_of_gaussians, FitSettings};
use rtbake::sss_sampling::disk::{ImportanceKernel, SampledProfile};
use serde_json::json;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median, min and max wall time (s) of `runs` runs of `f`, checking that every run returns the same result.
fn time<T: PartialEq + std::fmt::Debug>(name: &str, runs: usize, mut f: impl FnMut() -> T) -> (f64, f64, f64) {
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
    let (min, max) = times.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
    (median(times), min, max)
}

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(7).max(5);
    println!("threads: {}, runs: {runs}", rayon::current_num_threads());
    let skin1 = materials::find("skin1").unwrap().dipole(FdrForm::Dj05);
    let anchor_name = "anchor: 6-Gaussian shared fit, skin1 dipole";
    let settings = FitSettings { count: 6, ..FitSettings::default() };
    let anchor = time(anchor_name, runs, || fit_sum_of_gaussians(&skin1, &settings).unwrap().error_percent);
    let burley = RgbBurley::from_mean_free_path([0.8, 0.5, 0.3], [1.0, 0.5, 0.25], ShapeFit::DiffuseTransmission)
        .expect("valid Burley parameters");
    let bake_kernel = |k: &ImportanceKernel| {
        let files =
            rtbake::bake::importance::kernel_files("k", "bench_n1000", k, &json!({"bench": true}), "bench_profiles");
        files.iter().map(|f| f.bytes.len()).sum::<usize>()
    };
    let registry = rtbake::bake::registry();
    let asset = |name: &str| registry.iter().find(|a| a.name == name).expect("registered");
    let (bp, ik) = (asset("burley-profiles"), asset("sss-importance-kernels"));
    let (bp_params, ik_params) = ((bp.default_params)(), (ik.default_params)());
    let jobs: Vec<(&str, (f64, f64, f64))> = vec![
        ("Burley fit, skin1 dipole", time("burley", runs, || fit_burley(&skin1).unwrap().error_percent)),
        (
            "1000-sample importance kernel bake, skin1 dipole",
            time("kernel skin1", runs, || {
                bake_kernel(&ImportanceKernel::new(SampledProfile::Tabulated(&skin1), 1000).unwrap())
            }),
        ),
        (
            "1000-sample importance kernel bake, Burley",
            time("kernel burley", runs, || {
                bake_kernel(&ImportanceKernel::new(SampledProfile::Burley(&burley), 1000).unwrap())
            }),
        ),
        (
            "bake burley-profiles (14 fits, 14 kernels, 4 tables)",
            time("bake bp", runs, || (bp.bake)(&bp_params).unwrap().len()),
        ),
        ("bake sss-importance-kernels (9 kernels)", time("bake ik", runs, || (ik.bake)(&ik_params).unwrap().len())),
    ];
    let row = |name: &str, (m, lo, hi): (f64, f64, f64)| {
        println!(
            "{name:<54} median {:>8.2} ms  (min {:>8.2}, max {:>8.2})  ratio to anchor {:>6.3}",
            m * 1e3,
            lo * 1e3,
            hi * 1e3,
            m / anchor.0
        );
    };
    row(anchor_name, anchor);
    for (name, t) in jobs {
        row(name, t);
    }
}
