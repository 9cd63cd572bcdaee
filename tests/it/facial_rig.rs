//! Hemoglobin appearance rig (thesis eq. 7.1-7.6) on the committed synthetic fixtures: fixtures are current,
//! the rig round-trips (w_neutral = 1 gives Hn; w_i = 1 gives the local statistics of Hi), flat maps stay
//! finite, results are identical for any thread count, and the bake assets are deterministic and readable.

use rtbake::bake::facial::RigDescription;
use rtbake::facial::disk_stats::{disk_stats, Border};
use rtbake::facial::hemoglobin_rig::{build_rig, evaluate, rig_weights, HemoglobinRig, RigSettings};
use rtbake::facial::{inputs, synthetic};
use std::path::PathBuf;

const FIXTURE_SIZE: u32 = 64;
const FIXTURE_SEED: u32 = 1;
const FIXTURE_TARGETS: [&str; 4] = ["joy", "anger", "fear", "disgust"];

fn fixture_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/facial")
}

/// Regenerates the fixtures with `RTBAKE_REGENERATE_FIXTURES=1`; otherwise compares them with the generator
/// (a missing fixture is a failure).
#[test]
fn committed_fixtures_match_the_generator() {
    let names: Vec<String> = FIXTURE_TARGETS.iter().map(|s| s.to_string()).collect();
    let set = synthetic::hemoglobin_set("targets", FIXTURE_SIZE, FIXTURE_SEED, &names).unwrap();
    let regen = std::env::var("RTBAKE_REGENERATE_FIXTURES").is_ok_and(|v| v == "1");
    for (name, img) in &set {
        let path = fixture_dir().join(format!("hemoglobin_{name}.png"));
        if regen {
            std::fs::create_dir_all(fixture_dir()).unwrap();
            std::fs::write(&path, rtbake::io::png::encode_u16(img).unwrap()).unwrap();
        }
        let bytes = std::fs::read(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (regenerate with RTBAKE_REGENERATE_FIXTURES=1)", path.display()));
        match rtbake::io::png::decode(&bytes, "fixture").unwrap() {
            rtbake::io::png::DecodedPng::U16(f) => assert_eq!(&f, img, "{} is stale", path.display()),
            _ => panic!("{} must be a 16-bit PNG", path.display()),
        }
    }
}

fn load_fixture(name: &str) -> Vec<f32> {
    let p = fixture_dir().join(format!("hemoglobin_{name}.png"));
    let m =
        inputs::decode_concentration("--neutral", &p.display().to_string(), &std::fs::read(&p).unwrap(), None).unwrap();
    assert_eq!((m.image.width, m.image.height), (FIXTURE_SIZE, FIXTURE_SIZE));
    m.image.data
}

/// (rig, neutral map, named target maps).
type FixtureRig = (HemoglobinRig, Vec<f32>, Vec<(String, Vec<f32>)>);

fn fixture_rig(radius: u32, rig_size: u32) -> FixtureRig {
    let neutral = load_fixture("neutral");
    let targets: Vec<(String, Vec<f32>)> = FIXTURE_TARGETS.iter().map(|n| (n.to_string(), load_fixture(n))).collect();
    let refs: Vec<(String, &[f32])> = targets.iter().map(|(n, v)| (n.clone(), v.as_slice())).collect();
    let settings = RigSettings { radius_texels: radius, border: Border::Clip, sigma_floor: 1e-4, rig_size };
    let rig = build_rig(&neutral, FIXTURE_SIZE, FIXTURE_SIZE, &refs, &settings).unwrap();
    (rig, neutral, targets)
}

fn names(rig: &HemoglobinRig) -> Vec<String> {
    rig.maps.iter().map(|m| m.name.clone()).collect()
}

#[test]
fn neutral_weight_reproduces_the_neutral_map() {
    for rig_size in [64, 16, 11] {
        let (rig, neutral, _) = fixture_rig(4, rig_size);
        let w = rig_weights(&names(&rig), &[("neutral".into(), 1.0)], false).unwrap();
        let h = evaluate(&rig, &w, 1.0);
        for (i, (&a, &b)) in h.iter().zip(&neutral).enumerate() {
            // Exact up to the f32 rounding of H0 = Hn − bias_0.
            let tol = 1.2e-7 * (rig.h0[i].abs().max(b.abs()));
            assert!((a - b).abs() <= tol, "rig {rig_size}: texel {i}: {a} vs {b}");
        }
    }
}

/// Mean relative error of local statistics of the evaluated map vs those of the target (eq. 7.3 holds locally).
fn local_stat_errors(rig: &HemoglobinRig, target: &str, target_map: &[f32], r: u32) -> (f64, f64) {
    let w = rig_weights(&names(rig), &[(target.into(), 1.0)], false).unwrap();
    let h = evaluate(rig, &w, 1.0);
    let s_eval = disk_stats(&h, rig.width, rig.height, r, Border::Clip).unwrap();
    let s_tgt = disk_stats(target_map, rig.width, rig.height, r, Border::Clip).unwrap();
    let n = s_eval.mean.len() as f64;
    let mu = s_eval.mean.iter().zip(&s_tgt.mean).map(|(a, b)| (a - b).abs() / b).sum::<f64>() / n;
    let sg = s_eval.sigma.iter().zip(&s_tgt.sigma).map(|(a, b)| (a - b).abs() / b).sum::<f64>() / n;
    (mu, sg)
}

#[test]
fn target_weight_reproduces_the_local_statistics_of_the_target() {
    // Full-resolution rig: only the approximation of eq. 7.3 (statistics vary inside the disk) remains.
    let (rig, _, targets) = fixture_rig(4, 64);
    for (name, map) in &targets {
        let (mu, sg) = local_stat_errors(&rig, name, map, 4);
        eprintln!("{name}: full-res rig: mean |Δμ|/μ = {mu:.5}, mean |Δσ|/σ = {sg:.5}");
        assert!(mu < 0.005, "{name}: mean |Δμ|/μ = {mu}");
        assert!(sg < 0.03, "{name}: mean |Δσ|/σ = {sg}");
        // Baseline: the neutral map's own statistics are much further from the target's.
        let (mu0, sg0) = local_stat_errors(&rig, "neutral", map, 4);
        assert!(mu0 > 4.0 * mu && sg0 > 2.0 * sg, "{name}: rig ({mu}, {sg}) vs neutral baseline ({mu0}, {sg0})");
    }
    // Stored at 16² (ratio 4), as a renderer would use it: still close.
    let (rig, _, targets) = fixture_rig(4, 16);
    for (name, map) in &targets {
        let (mu, sg) = local_stat_errors(&rig, name, map, 4);
        eprintln!("{name}: 16² rig: mean |Δμ|/μ = {mu:.5}, mean |Δσ|/σ = {sg:.5}");
        assert!(mu < 0.01, "{name} (16²): mean |Δμ|/μ = {mu}");
        assert!(sg < 0.04, "{name} (16²): mean |Δσ|/σ = {sg}");
    }
    // The evaluated map differs from the neutral one: the rig carries the target's perfusion change.
    // Its mean change (joy: more blood over the cheeks) matches the target's within 5 %.
    let (rig, neutral, targets) = fixture_rig(4, 64);
    let w = rig_weights(&names(&rig), &[("joy".into(), 1.0)], false).unwrap();
    let joy = evaluate(&rig, &w, 1.0);
    let mean_diff = |a: &[f32]| a.iter().zip(&neutral).map(|(a, b)| (a - b) as f64).sum::<f64>() / neutral.len() as f64;
    let (d_eval, d_target) = (mean_diff(&joy), mean_diff(&targets[0].1));
    assert!(d_target > 2e-4, "the joy fixture adds blood: {d_target}");
    assert!((d_eval - d_target).abs() < 0.05 * d_target, "mean change {d_eval} vs target {d_target}");
}

#[test]
fn flat_maps_give_finite_rigs_and_count_floored_texels() {
    let (w, h) = (40u32, 30u32);
    let flat = vec![0.05f32; (w * h) as usize];
    let bumpy: Vec<f32> = (0..w * h).map(|i| 0.05 + 0.01 * ((i * 37 % 11) as f32 / 11.0)).collect();
    let settings = RigSettings { radius_texels: 3, border: Border::Wrap, sigma_floor: 1e-4, rig_size: 8 };
    let rig = build_rig(&flat, w, h, &[("t".into(), &bumpy[..]), ("f".into(), &flat[..])], &settings).unwrap();
    assert_eq!(rig.sigma_floored_texels, (w * h) as u64);
    for m in &rig.maps {
        assert!(m.scale.iter().chain(&m.bias).all(|v| v.is_finite()), "{}", m.name);
    }
    assert!(rig.h0.iter().all(|v| v.is_finite()));
    let wts =
        rig_weights(&names(&rig), &[("t".into(), 0.5), ("f".into(), 0.25), ("neutral".into(), 0.25)], false).unwrap();
    assert!(evaluate(&rig, &wts, 1.27).iter().all(|v| v.is_finite()));
    // Flat target: scale 0 (σ = 0), bias = the constant.
    let f = rig.maps.iter().find(|m| m.name == "f").unwrap();
    assert!(f.scale.iter().all(|&s| s == 0.0) && f.bias.iter().all(|&b| b == 0.05));
}

#[test]
fn weights_are_validated() {
    let n: Vec<String> = ["neutral", "anger", "fear"].iter().map(|s| s.to_string()).collect();
    assert!(rig_weights(&n, &[("anger".into(), 0.7), ("neutral".into(), 0.3)], false).is_ok());
    let e = rig_weights(&n, &[("anger".into(), 0.7)], false).unwrap_err();
    assert!(e.to_string().contains("must sum to 1"), "{e}");
    let w = rig_weights(&n, &[("anger".into(), 0.7)], true).unwrap();
    assert_eq!(w, vec![0.0, 1.0, 0.0]);
    assert!(rig_weights(&n, &[("joy".into(), 1.0)], false).unwrap_err().to_string().contains("unknown target 'joy'"));
    assert!(rig_weights(&n, &[("fear".into(), f64::NAN)], true).is_err());
}

#[test]
fn same_bytes_for_any_thread_count() {
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let three = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
    let a = one.install(|| fixture_rig(5, 13).0);
    let b = three.install(|| fixture_rig(5, 13).0);
    assert_eq!(a, b);
    let asset = rtbake::bake::registry().into_iter().find(|a| a.name == "hemoglobin-rig-example").unwrap();
    let params = (asset.default_params)();
    let fa = one.install(|| (asset.bake)(&params).unwrap());
    let fb = three.install(|| (asset.bake)(&params).unwrap());
    assert_eq!(fa, fb);
}

/// The fused build (disk statistics band by band straight into the downsampling, buffers reused across maps) gives
/// the bits of the unfused chain: full-size `disk_stats`, σi / max(σn, ε), `resample_area`, `upsample_bilinear`.
/// Maps wider than one cache tile and taller than one band, a non-integer storage ratio, both borders.
#[test]
fn fused_rig_equals_full_size_statistics_and_area_resampling_bit_for_bit() {
    use rtbake::facial::resample::{resample_area, upsample_bilinear};
    let (w, h, r, rig_size) = (300u32, 150u32, 6u32, 37u32);
    let map = |seed: u32| -> Vec<f32> {
        let mut s = seed.wrapping_mul(2654435761).wrapping_add(1);
        (0..w * h)
            .map(|i| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                // Flat in the top rows (σn below the floor there), noisy below.
                if i < 20 * w {
                    0.25
                } else {
                    0.2 + (s % 10000) as f32 / 50000.0
                }
            })
            .collect()
    };
    let neutral = map(1);
    let targets = [("joy".to_string(), map(2)), ("anger".to_string(), map(3))];
    let refs: Vec<(String, &[f32])> = targets.iter().map(|(n, v)| (n.clone(), v.as_slice())).collect();
    for border in [Border::Clip, Border::Wrap] {
        let settings = RigSettings { radius_texels: r, border, sigma_floor: 1e-3, rig_size };
        let rig = build_rig(&neutral, w, h, &refs, &settings).unwrap();
        let down = |v: &[f64]| -> Vec<f32> {
            resample_area(v, w, h, 1, rig_size, rig_size).into_iter().map(|x| x as f32).collect()
        };
        let sn = disk_stats(&neutral, w, h, r, border).unwrap();
        let floored: Vec<f64> = sn.sigma.iter().map(|&s| s.max(1e-3)).collect();
        assert_eq!(rig.sigma_floored_texels, sn.sigma.iter().filter(|&&s| s < 1e-3).count() as u64);
        assert!(rig.sigma_floored_texels > 0, "the flat rows floor σn ({border:?})");
        assert_eq!(rig.maps[0].bias, down(&sn.mean), "{border:?} neutral bias");
        for ((_, t), m) in targets.iter().zip(&rig.maps[1..]) {
            let st = disk_stats(t, w, h, r, border).unwrap();
            let scale: Vec<f64> = st.sigma.iter().zip(&floored).map(|(s, n)| s / n).collect();
            assert_eq!(m.bias, down(&st.mean), "{border:?} {} bias", m.name);
            assert_eq!(m.scale, down(&scale), "{border:?} {} scale", m.name);
        }
        let b0 = upsample_bilinear(&rig.maps[0].bias, rig_size, rig_size, w, h);
        let h0: Vec<f32> = neutral.iter().zip(&b0).map(|(&hn, &b)| (hn as f64 - b) as f32).collect();
        assert_eq!(rig.h0, h0, "{border:?} H0");
    }
}

#[test]
fn example_rig_asset_is_complete_and_readable() {
    let asset = rtbake::bake::registry().into_iter().find(|a| a.name == "hemoglobin-rig-example").unwrap();
    let params = (asset.default_params)();
    // Params round-trip through JSON.
    let params: serde_json::Value = serde_json::from_str(&serde_json::to_string(&params).unwrap()).unwrap();
    let files = (asset.bake)(&params).unwrap();
    assert!(files.iter().all(|f| f.path.starts_with("facial/hemoglobin/example/")));
    let rig_json = files.iter().find(|f| f.path.ends_with("/rig.json")).unwrap();
    let desc: RigDescription = serde_json::from_slice(&rig_json.bytes).unwrap();
    assert_eq!(desc.schema, "rtbake-hemoglobin-rig/1");
    assert_eq!(desc.maps[0].name, "neutral");
    assert_eq!(desc.maps.len(), 5);
    assert_eq!(desc.rig_size, [32, 32]);
    for m in &desc.maps {
        for f in [&m.scale_exr, &m.bias_exr, &m.scale_exr_f16, &m.bias_exr_f16, &m.scale_bias_ktx2, &m.scale_preview] {
            assert!(files.iter().any(|x| x.path.ends_with(&format!("/{f}"))), "missing {f}");
        }
        // KTX2 RG16F: R = scale, G = bias; matches the f32 EXRs within half precision.
        let ktx = files.iter().find(|x| x.path.ends_with(&format!("/{}", m.scale_bias_ktx2))).unwrap();
        let (fmt, w, h, data, linear) = rtbake::io::ktx2::decode(&ktx.bytes, "t").unwrap();
        assert_eq!((fmt, w, h, linear), (83, 32, 32, true));
        let exr = files.iter().find(|x| x.path.ends_with(&format!("/{}", m.bias_exr))).unwrap();
        let (bias, _) = rtbake::io::exr::decode(&exr.bytes, "t").unwrap();
        let g = half::f16::from_le_bytes([data[2], data[3]]).to_f32();
        assert!((g - bias.data[0]).abs() <= 1e-3 * bias.data[0].abs());
    }
    assert_eq!(files, (asset.bake)(&params).unwrap(), "bake must be deterministic");
}

#[test]
fn wrinkle_assets_bake() {
    for name in ["wrinkle-expression-weights", "wrinkle-maps-example"] {
        let asset = rtbake::bake::registry().into_iter().find(|a| a.name == name).unwrap();
        let files = (asset.bake)(&(asset.default_params)()).unwrap();
        assert!(!files.is_empty() && files.iter().all(|f| f.path.starts_with("facial/wrinkles/")), "{name}");
    }
    let asset = rtbake::bake::registry().into_iter().find(|a| a.name == "wrinkle-expression-weights").unwrap();
    let files = (asset.bake)(&(asset.default_params)()).unwrap();
    let v: serde_json::Value = serde_json::from_slice(&files[0].bytes).unwrap();
    assert_eq!(v["expressions"]["anger"][0], -0.6);
    assert_eq!(v["weights_float4"]["fear"][1][3], 0.6);
}

#[test]
fn evaluation_is_affine_in_the_weights_and_applies_the_global_scale() {
    // eq. 7.6 is linear in w: H(0.3·anger + 0.7·neutral) = 0.3·H(anger) + 0.7·H(neutral); g multiplies H.
    let (rig, _, _) = fixture_rig(4, 16);
    let n = names(&rig);
    let eval = |pairs: &[(&str, f64)], g: f64| {
        let p: Vec<(String, f64)> = pairs.iter().map(|(a, b)| (a.to_string(), *b)).collect();
        evaluate(&rig, &rig_weights(&n, &p, false).unwrap(), g)
    };
    let mix = eval(&[("anger", 0.3), ("neutral", 0.7)], 1.0);
    let a = eval(&[("anger", 1.0)], 1.0);
    let z = eval(&[("neutral", 1.0)], 1.0);
    for i in 0..mix.len() {
        let want = 0.3 * a[i] as f64 + 0.7 * z[i] as f64;
        assert!((mix[i] as f64 - want).abs() < 1e-6, "texel {i}");
    }
    let flushed = eval(&[("anger", 1.0)], 1.27);
    assert!(flushed.iter().zip(&a).all(|(f, a)| (*f as f64 - 1.27 * *a as f64).abs() < 1e-6));
}
