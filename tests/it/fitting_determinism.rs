//! Fits and the fit asset are bit-identical for any thread count (the multi-start runs in parallel).

use rtbake::diffusion::materials;
use rtbake::diffusion::FdrForm;
use rtbake::fitting::{fit_sum_of_gaussians, FitSettings};

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

#[test]
fn fit_is_identical_for_one_and_three_threads() {
    let profile = materials::find("skin2").unwrap().dipole(FdrForm::Dj05);
    let settings = FitSettings { count: 5, shared_variances: true, normalize: true, starts: 6 };
    let a = in_pool(1, || fit_sum_of_gaussians(&profile, &settings).unwrap());
    let b = in_pool(3, || fit_sum_of_gaussians(&profile, &settings).unwrap());
    assert_eq!(a, b);
}

#[test]
fn fit_asset_bytes_are_identical_for_one_and_two_threads() {
    let asset = rtbake::bake::registry().into_iter().find(|a| a.name == "sss-gaussians-fit").unwrap();
    let params = (asset.default_params)();
    let a = in_pool(1, || (asset.bake)(&params).unwrap());
    let b = in_pool(2, || (asset.bake)(&params).unwrap());
    assert_eq!(a, b);
    let json: serde_json::Value =
        serde_json::from_slice(&a.iter().find(|f| f.path.ends_with(".json")).unwrap().bytes).unwrap();
    // skin1 dipole, shared 6-Gaussian fit, normalised: every channel within 1 %.
    for e in json["error_percent"].as_array().unwrap() {
        assert!(e.as_f64().unwrap() < 1.0, "{e}");
    }
}
