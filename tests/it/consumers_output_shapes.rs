//! Output files say how to read them: a sum-of-Gaussians parameter file names its array layout (per Gaussian for
//! shared variances, per channel otherwise), and the layout it names is the one its arrays have.

use crate::support::rtbake;

fn fit(extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["fit", "gaussians", "--material", "skin1", "--count", "3", "--json", "-q"];
    args.extend_from_slice(extra);
    let o = rtbake(&args);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn gaussian_fit_json_names_its_array_layout() {
    let shared = fit(&[]);
    assert_eq!(shared["array_layout"], rtbake::fitting::screen_space::ARRAY_LAYOUT_PER_GAUSSIAN);
    let w = shared["weights"].as_array().unwrap();
    assert_eq!(w.len(), 3, "one entry per Gaussian");
    assert!(w.iter().all(|g| g.as_array().unwrap().len() == 3), "[r, g, b] per Gaussian");
    assert_eq!(shared["variances"].as_array().unwrap().len(), 3);

    let per = fit(&["--per-channel"]);
    assert_eq!(per["array_layout"], rtbake::fitting::screen_space::ARRAY_LAYOUT_PER_CHANNEL);
    let w = per["weights"].as_array().unwrap();
    assert_eq!(w.len(), 3, "one entry per channel");
    assert!(w.iter().all(|c| c.as_array().unwrap().len() == 3), "3 Gaussians per channel");
    assert!(per["variances"][0].is_array());
    // The file reads back as the same sum either way.
    for v in [&shared, &per] {
        let file: rtbake::fitting::screen_space::GaussiansFile = serde_json::from_value(v.clone()).unwrap();
        assert_eq!(file.sum().unwrap().weights[0].len(), 3, "3 Gaussians");
    }
}
