//! Benchmark of the separable-SSS fit (thesis eq. 6.3) and kernel generation.
//!
//! Run: `cargo run --release --example bench_separable [RUNS]` (RUNS >= 5, default 7). Prints the median wall time
//! of building the target kernel, fitting it, the SVD separability measure and generating a 17-tap kernel. The
//! thesis publishes no timing for its Matlab `fmincon` fit, so there is no anchor to compare with; the ratio printed
//! is fit time per objective evaluation budget (fit / one target build) to make regressions visible.

use rtbake::diffusion::materials;
use rtbake::diffusion::sum_of_gaussians::deon6;
use rtbake::diffusion::{FdrForm, RadialProfile};
use rtbake::separable::fit::{fit, separability, ObjectiveSpec, TargetKernel};
use rtbake::separable::kernel::{generate, KernelSpec};
use rtbake::separable::PUBLISHED;
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let t0 = Instant::now();
        let out = f();
        times.push(t0.elapsed());
        last = Some(out);
    }
    (median(times), last.expect("runs >= 1"))
}

fn bench_target(name: &str, profile: &dyn RadialProfile, spec: &ObjectiveSpec, runs: usize) {
    let (t_target, target) = time(runs, || TargetKernel::from_profile(profile, spec, name).unwrap());
    let (t_fit, result) = time(runs, || fit(&target).unwrap());
    let (t_svd, _) = time(runs, || separability(profile, spec).unwrap());
    println!(
        "{name:>8}: target {:>9.3} ms | fit {:>9.3} ms ({} Nelder-Mead iterations) | SVD {:>8.3} ms | fit/target {:.2}",
        t_target.as_secs_f64() * 1e3,
        t_fit.as_secs_f64() * 1e3,
        result.iterations,
        t_svd.as_secs_f64() * 1e3,
        t_fit.as_secs_f64() / t_target.as_secs_f64()
    );
    println!(
        "          strength {:.6?} falloff {:.6?} objective {:.6e} (Table 6.1: {:.6e}, ratio {:.4})",
        result.params.strength,
        result.params.falloff,
        result.objective(),
        result.objective_table_6_1(),
        result.objective() / result.objective_table_6_1()
    );
}

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(7).max(5);
    println!("separable-SSS benchmark, median of {runs} runs, {} rayon threads", rayon::current_num_threads());
    let spec = ObjectiveSpec::default();
    println!(
        "objective: {} nodes over ±{} mm (exponent {}), pixel {:.4} mm, width {}",
        spec.grid_nodes, spec.grid_extent_mm, spec.grid_exponent, spec.pixel_mm, spec.width
    );
    bench_target("deon6", &deon6(), &spec, runs);
    let skin1 = materials::find("skin1").unwrap().dipole(FdrForm::default());
    bench_target("skin1", &skin1, &spec, runs);

    let spec17 = KernelSpec::new(17, PUBLISHED);
    let (t_kernel, _) = time(runs.max(1000), || generate(&spec17).unwrap());
    println!("kernel N=17 f32: {:.3} µs", t_kernel.as_secs_f64() * 1e6);
}
