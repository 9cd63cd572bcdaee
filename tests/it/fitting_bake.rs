//! The `sss-gaussians`, `sss-gaussians-fit` and `transmittance` assets: pure, deterministic, complete file sets whose
//! parameters round-trip through JSON.

use rtbake::bake::{registry, Asset, BakedFile};

fn asset(name: &str) -> Asset {
    registry().into_iter().find(|a| a.name == name).unwrap_or_else(|| panic!("asset {name} registered"))
}

fn bake(name: &str) -> Vec<BakedFile> {
    let a = asset(name);
    let params = (a.default_params)();
    // Parameters round-trip through JSON text (the manifest stores them).
    let text = serde_json::to_string(&params).unwrap();
    let back: serde_json::Value = serde_json::from_str(&text).unwrap();
    (a.bake)(&back).unwrap()
}

#[test]
fn preset_asset_writes_json_includes_and_plots_for_both_presets() {
    let files = bake("sss-gaussians");
    for p in ["deon6", "deon4"] {
        for ext in [".json", ".hlsl", ".glsl", ".wgsl", "_plot.png", "_plot.svg"] {
            let path = format!("sss/gaussians/{p}{ext}");
            assert!(files.iter().any(|f| f.path == path), "missing {path}");
        }
    }
    let json: serde_json::Value =
        serde_json::from_slice(&files.iter().find(|f| f.path == "sss/gaussians/deon4.json").unwrap().bytes).unwrap();
    // Thesis example: 2.0062 − 0.2719 = 1.7343, width sqrt(1.7343).
    let inc = json["incremental_variances"].as_array().unwrap();
    assert!((inc[3].as_f64().unwrap() - 1.7343).abs() < 1e-12);
    assert!((json["std_devs"][3].as_f64().unwrap() - 1.7343f64.sqrt()).abs() < 1e-12);
    assert_eq!(json["blend_weights"][0], serde_json::json!([1.0, 1.0, 1.0]));
    let hlsl =
        String::from_utf8(files.iter().find(|f| f.path == "sss/gaussians/deon6.hlsl").unwrap().bytes.clone()).unwrap();
    assert!(hlsl.contains("static const int SSS_GAUSSIAN_COUNT = 6;"));
    assert!(hlsl.contains("static const float SSS_VARIANCES[6] = { 0.0064, 0.0484, 0.187, 0.567, 1.99, 7.41 };"));
    let wgsl =
        String::from_utf8(files.iter().find(|f| f.path == "sss/gaussians/deon6.wgsl").unwrap().bytes.clone()).unwrap();
    assert!(wgsl.contains("const SSS_BLEND_WEIGHTS: array<vec3<f32>, 6>"));
}

#[test]
fn transmittance_asset_is_complete_and_starts_at_one() {
    let files = bake("transmittance");
    for suffix in [".exr", "_f16.exr", ".ktx2", "_preview_srgb.png", "_linear16.png", ".json"] {
        let path = format!("transmittance/deon6_published{suffix}");
        assert!(files.iter().any(|f| f.path == path), "missing {path}");
    }
    let exr = files.iter().find(|f| f.path == "transmittance/deon6_published.exr").unwrap();
    assert!(exr.meta.convention.contains("u = s/s_max*(n-1)/n + 0.5/n"));
    let (img, _) = rtbake::io::exr::decode(&exr.bytes, "t").unwrap();
    assert_eq!((img.width, img.height), (256, 1));
    for c in 0..3 {
        assert!((img.get(0, 0, c) - 1.0).abs() < 1e-6);
    }
}

#[test]
fn bakes_are_deterministic() {
    for name in ["sss-gaussians", "transmittance"] {
        assert_eq!(bake(name), bake(name), "{name}");
    }
}
