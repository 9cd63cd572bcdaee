//! The `burley-profiles` bake asset: every Jensen 2001 material and physiological skin gets a Burley fit
//! that is the optimum of its own metric (never worse than the artist mapping A = Rd, ℓ = 1/σ_tr it is reported
//! beside), errors that `rtbake evaluate` reproduces, and transmission profiles whose Burley table is the closed-form
//! plane integral of the fitted profile (T(0) = A) and whose Gaussian table starts at the Gaussians' total.

use rtbake::bake::{registry, BakedFile};
use rtbake::diffusion::burley::{Burley, RgbBurley};
use rtbake::diffusion::materials::JENSEN_2001;
use serde_json::Value;

fn baked() -> Vec<BakedFile> {
    let asset = registry().into_iter().find(|a| a.name == "burley-profiles").expect("asset registered");
    (asset.bake)(&(asset.default_params)()).expect("bakes")
}

fn json(files: &[BakedFile], path: &str) -> Value {
    let f = files.iter().find(|f| f.path == path).unwrap_or_else(|| panic!("{path} not baked"));
    serde_json::from_slice(&f.bytes).unwrap()
}

fn rgb(v: &Value) -> [f64; 3] {
    [0, 1, 2].map(|c| v[c].as_f64().unwrap())
}

#[test]
fn burley_fits_cover_every_case_and_beat_the_artist_mapping() {
    let files = baked();
    let fits = json(&files, "burley/fits.json");
    let cases = fits["cases"].as_array().unwrap();
    assert_eq!(cases.len(), JENSEN_2001.len() + 3);
    for case in cases {
        let name = case["case"].as_str().unwrap();
        let fit = &case["fit"];
        let albedo = rgb(&fit["burley"]["albedo"]);
        let d = rgb(&fit["burley"]["d_mm"]);
        let fit_err = rgb(&fit["errors"]["relative_l2_percent"]);
        for c in 0..3 {
            assert!((0.0..=1.0).contains(&albedo[c]) && d[c] > 0.0, "{name}: {fit}");
            // A Burley profile is not a dipole or a layered multipole: the fits are honest, not exact (measured
            // 28–50 % in r·R(r)).
            assert!(fit_err[c] > 1.0 && fit_err[c] < 60.0, "{name}: {fit_err:?}");
        }
        // The plot of each case is baked.
        assert!(files.iter().any(|f| f.path == format!("burley/{name}.svg")), "{name}");
        if name.starts_with("dipole/") {
            let artist = &case["artist"];
            let a_err = rgb(&artist["errors"]["relative_l2_percent"]);
            let totals = rgb(&case["target_totals"]);
            for c in 0..3 {
                assert!(
                    fit_err[c] <= a_err[c] + 1e-9,
                    "{name} channel {c}: fit {} % vs artist {} %",
                    fit_err[c],
                    a_err[c]
                );
                assert_eq!(artist["burley"]["albedo"][c].as_f64().unwrap(), totals[c], "{name}: artist A = Rd");
            }
        } else {
            assert!(case["artist"].is_null(), "{name}: a layer stack has no single sigma_tr");
        }
    }
    // The recorded errors are `evaluate`'s: recompute skin1's with the library.
    let skin1 = cases.iter().find(|c| c["case"] == "dipole/skin1").unwrap();
    let b = RgbBurley([0, 1, 2].map(|c| {
        Burley::new(
            skin1["fit"]["burley"]["albedo"][c].as_f64().unwrap(),
            skin1["fit"]["burley"]["d_mm"][c].as_f64().unwrap(),
        )
        .unwrap()
    }));
    let target = rtbake::diffusion::materials::find("skin1").unwrap().dipole(rtbake::diffusion::FdrForm::Dj05);
    let e = rtbake::fitting::evaluate::compare_profiles(&b, &target, false).unwrap();
    for (a, b) in rgb(&skin1["fit"]["errors"]["relative_l2_percent"]).iter().zip(e.relative_l2_percent) {
        assert!((a - b).abs() <= 1e-9 * b, "{a} vs {b}");
    }
}

#[test]
fn transmission_profiles_start_at_the_albedo_and_follow_the_closed_form() {
    let files = baked();
    let fits = json(&files, "burley/fits.json");
    for (case, stem) in
        [("dipole/skin1", "dipole_skin1"), ("skin/two_layer_cm0.1_chd0.1", "skin_two_layer_cm0.1_chd0.1")]
    {
        let rec = fits["cases"].as_array().unwrap().iter().find(|c| c["case"] == case).unwrap();
        let side = json(&files, &format!("burley/transmission/{stem}_burley_physical.json"));
        assert_eq!(side["burley"]["albedo"], rec["fit"]["burley"]["albedo"]);
        assert!(side.get("variances_mm2").is_none());
        let exr = files.iter().find(|f| f.path == format!("burley/transmission/{stem}_burley_physical.exr")).unwrap();
        let img = image::load_from_memory_with_format(&exr.bytes, image::ImageFormat::OpenExr).unwrap().to_rgb32f();
        let n = img.width();
        let s_max = side["s_max_mm"].as_f64().unwrap();
        for i in [0, 1, n / 3, n - 1] {
            let s = s_max * i as f64 / (n - 1) as f64;
            for c in 0..3 {
                let b = Burley::new(
                    rec["fit"]["burley"]["albedo"][c].as_f64().unwrap(),
                    rec["fit"]["burley"]["d_mm"][c].as_f64().unwrap(),
                )
                .unwrap();
                let got = img.get_pixel(i, 0)[c] as f64;
                assert!((got - b.plane_transmittance(s)).abs() <= 1e-7, "{case} texel {i} channel {c}");
            }
        }
        // The KTX2 copy read the way Bevy reads KTX2 (the `ktx2` crate): RGBA16F, one level, texel 0 = A.
        let ktx = files.iter().find(|f| f.path == format!("burley/transmission/{stem}_burley_physical.ktx2")).unwrap();
        let reader = ktx2::Reader::new(&ktx.bytes[..]).unwrap();
        assert_eq!(reader.header().format, Some(ktx2::Format::R16G16B16A16_SFLOAT));
        assert_eq!((reader.header().pixel_width, reader.header().pixel_height), (n, 1));
        let level = reader.levels().next().unwrap();
        assert_eq!(level.data.len(), n as usize * 8);
        for c in 0..3 {
            let h = half::f16::from_le_bytes([level.data[2 * c], level.data[2 * c + 1]]).to_f64();
            let a = rec["fit"]["burley"]["albedo"][c].as_f64().unwrap();
            assert!((h - a).abs() <= 1e-3 * a.max(1e-2), "{case} KTX2 texel 0 channel {c}: {h} vs {a}");
        }
        // The Gaussian table's T(0) is the Gaussians' total Σw.
        let g = json(&files, &format!("burley/transmission/{stem}_gaussians4_physical.json"));
        let exr =
            files.iter().find(|f| f.path == format!("burley/transmission/{stem}_gaussians4_physical.exr")).unwrap();
        let img = image::load_from_memory_with_format(&exr.bytes, image::ImageFormat::OpenExr).unwrap().to_rgb32f();
        for c in 0..3 {
            let total: f64 = g["weights"][c].as_array().unwrap().iter().map(|w| w.as_f64().unwrap()).sum();
            assert!((img.get_pixel(0, 0)[c] as f64 - total).abs() <= 1e-6 * total.max(1e-3), "{case} channel {c}");
        }
    }
}

/// Every Burley fit gets its importance-sampled kernel (N = 40): the library's kernel of the fitted profile (closed-form
/// CDF), weights summing to 1 per channel, its unnormalised weights to about the fitted albedo, and the binary table
/// of 40 records of 8 f32.
#[test]
fn every_burley_fit_has_its_importance_kernel() {
    use rtbake::sss_sampling::disk::{ImportanceKernel, SampledProfile};
    let files = baked();
    let fits = json(&files, "burley/fits.json");
    for rec in fits["cases"].as_array().unwrap() {
        let stem = rec["case"].as_str().unwrap().replace('/', "_");
        let k = json(&files, &format!("burley/kernels/{stem}_n40.json"));
        assert_eq!(k["inversion"], "burley-closed-form");
        let samples = k["kernel"].as_array().unwrap();
        assert_eq!(samples.len(), 40);
        let b = RgbBurley([0, 1, 2].map(|c| {
            Burley::new(
                rec["fit"]["burley"]["albedo"][c].as_f64().unwrap(),
                rec["fit"]["burley"]["d_mm"][c].as_f64().unwrap(),
            )
            .unwrap()
        }));
        let lib = ImportanceKernel::new(SampledProfile::Burley(&b), 40).unwrap();
        for c in 0..3 {
            let sum: f64 = samples.iter().map(|s| s["weight"][c].as_f64().unwrap()).sum();
            assert!((sum - 1.0).abs() < 1e-6, "{stem} channel {c}: {sum}");
            let raw: f64 = samples.iter().map(|s| s["weight_unnormalised"][c].as_f64().unwrap()).sum();
            assert!((raw - b.0[c].albedo).abs() < 0.15 * b.0[c].albedo, "{stem} channel {c}: {raw} vs A");
        }
        assert!((samples[7]["r_mm"].as_f64().unwrap() - lib.samples[7].r_mm).abs() < 1e-6 * lib.samples[7].r_mm);
        let bin = files.iter().find(|f| f.path == format!("burley/kernels/{stem}_n40_f32x8.bin")).unwrap();
        assert_eq!(bin.bytes.len(), 40 * 8 * 4);
    }
}
