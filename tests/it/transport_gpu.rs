//! The GPU transport (`runtime::transport_gpu`) against the CPU reference (`transport::simulate`): the same seed,
//! the same tallies within 4 combined standard errors (total R, total T, R(r) bins), energy conservation of the GPU
//! result within its own standard errors, the WGSL Philox against Random123's known answers, determinism per
//! device, and bad input refused with a typed error. Photon counts stay small: the test adapter is a software
//! rasteriser (llvmpipe/lavapipe).

use crate::support::*;
use rtbake::runtime::transport_gpu::{philox_blocks, simulate_gpu, GpuPlan, TransportGpu};
use rtbake::runtime::RuntimeError;
use rtbake::transport::rng::philox4x32_10;
use rtbake::transport::{simulate, Estimate, McLayer, McResult, McSettings, McStack};

/// |a − b| ≤ 4·√(SEa² + SEb²), and the bound is not vacuous (some SE > 0 unless both are exactly 0).
fn assert_agree(what: &str, a: Estimate, b: Estimate) {
    let se = (a.se * a.se + b.se * b.se).sqrt();
    assert!(
        (a.mean - b.mean).abs() <= 4.0 * se,
        "{what}: GPU {} ± {} vs CPU {} ± {} ({:.1} combined SE)",
        a.mean,
        a.se,
        b.mean,
        b.se,
        (a.mean - b.mean).abs() / se
    );
}

/// Energy: Rsp + Rd + T + ΣA = 1 within 4 standard errors (summed).
fn assert_energy(r: &McResult, what: &str) {
    for (c, ch) in r.channels.iter().enumerate() {
        let total = ch.specular_reflectance
            + ch.diffuse_reflectance.mean
            + ch.transmittance.mean
            + ch.absorbed.iter().map(|a| a.mean).sum::<f64>();
        let se = ch.diffuse_reflectance.se + ch.transmittance.se + ch.absorbed.iter().map(|a| a.se).sum::<f64>();
        assert!((total - 1.0).abs() <= 4.0 * se + 1e-6, "{what} channel {c}: R + T + A = {total} (SE sum {se})");
    }
}

/// Both paths on one stack: totals, absorbed per layer and the given R(r) bins agree channel by channel.
fn compare_paths(stack: &McStack, settings: &McSettings, bins: &[usize], what: &str) -> (McResult, McResult) {
    let g = gpu();
    let gpu_result = simulate_gpu(&g.device, &g.queue, stack, settings).unwrap_or_else(|e| panic!("{e}"));
    let cpu_result = simulate(stack, settings);
    assert_eq!(gpu_result.photons, cpu_result.photons);
    for c in 0..3 {
        let (a, b) = (&gpu_result.channels[c], &cpu_result.channels[c]);
        eprintln!(
            "{what} ch {c}: Rd GPU {:.5} ± {:.5} CPU {:.5} ± {:.5}; T GPU {:.5} ± {:.5} CPU {:.5} ± {:.5}; \
             interactions GPU {} CPU {}",
            a.diffuse_reflectance.mean,
            a.diffuse_reflectance.se,
            b.diffuse_reflectance.mean,
            b.diffuse_reflectance.se,
            a.transmittance.mean,
            a.transmittance.se,
            b.transmittance.mean,
            b.transmittance.se,
            a.interactions,
            b.interactions
        );
        assert_eq!(a.specular_reflectance, b.specular_reflectance);
        assert_agree(&format!("{what} ch {c} total R"), a.diffuse_reflectance, b.diffuse_reflectance);
        assert_agree(&format!("{what} ch {c} total T"), a.transmittance, b.transmittance);
        for (j, (x, y)) in a.absorbed.iter().zip(&b.absorbed).enumerate() {
            assert_agree(&format!("{what} ch {c} absorbed in layer {j}"), *x, *y);
        }
        for &i in bins {
            assert!(b.reflectance_mm2[i].se > 0.0, "{what}: bin {i} must be populated for the check to mean anything");
            assert_agree(&format!("{what} ch {c} R(r) bin {i}"), a.reflectance_mm2[i], b.reflectance_mm2[i]);
        }
        // The interaction counts are Monte Carlo counts too: within 2 % (a missed or doubled step shows up).
        let ratio = a.interactions as f64 / b.interactions as f64;
        assert!((ratio - 1.0).abs() < 0.02, "{what} ch {c}: interactions GPU/CPU {ratio}");
    }
    assert_energy(&gpu_result, what);
    (gpu_result, cpu_result)
}

/// MCML paper Table 2 (van de Hulst 1980): μa = 10 cm⁻¹, μs = 90 cm⁻¹, g = 0.75, n = 1, d = 0.02 cm:
/// Rd 0.09739, Tt 0.66096 — the GPU agrees with the CPU and, pooled over its three channels, with the table.
#[test]
fn gpu_matches_cpu_on_the_van_de_hulst_slab() {
    let layer =
        McLayer { thickness_mm: 0.2, eta: 1.0, sigma_a_per_mm: [1.0; 3], sigma_s_per_mm: [9.0; 3], g: [0.75; 3] };
    let stack = McStack::new(1.0, 1.0, vec![layer]).unwrap();
    let settings = McSettings::new(100_000, 1, 10, 0.01, 50).unwrap();
    let (g, _) = compare_paths(&stack, &settings, &[0, 5, 20], "van de Hulst");
    let rd = g.channels.iter().map(|c| c.diffuse_reflectance.mean).sum::<f64>() / 3.0;
    let rd_se = g.channels.iter().map(|c| c.diffuse_reflectance.se.powi(2)).sum::<f64>().sqrt() / 3.0;
    let tt = g.channels.iter().map(|c| c.transmittance.mean).sum::<f64>() / 3.0;
    let tt_se = g.channels.iter().map(|c| c.transmittance.se.powi(2)).sum::<f64>().sqrt() / 3.0;
    eprintln!("GPU van de Hulst: Rd {rd:.5} ± {rd_se:.5} (0.09739), Tt {tt:.5} ± {tt_se:.5} (0.66096)");
    assert!((rd - 0.09739).abs() < 4.0 * rd_se, "Rd {rd} ± {rd_se}");
    assert!((tt - 0.66096).abs() < 4.0 * tt_se, "Tt {tt} ± {tt_se}");
    assert!(rd_se < 0.001 && tt_se < 0.001, "the check must be tight enough to fail: {rd_se}, {tt_se}");
}

/// Two layers with mismatched indices (air / 1.5 / 1.33 / 1.2): Fresnel at every face, total internal
/// reflection, a per-channel absorption; the GPU agrees with the CPU, and the same seed on the same device gives
/// the same bytes.
#[test]
fn gpu_matches_cpu_on_a_mismatched_two_layer_stack() {
    let stack = McStack::new(
        1.0,
        1.2,
        vec![
            McLayer {
                thickness_mm: 0.15,
                eta: 1.5,
                sigma_a_per_mm: [0.2, 0.8, 2.0],
                sigma_s_per_mm: [20.0; 3],
                g: [0.8; 3],
            },
            McLayer {
                thickness_mm: 0.6,
                eta: 1.33,
                sigma_a_per_mm: [0.05, 0.3, 1.0],
                sigma_s_per_mm: [8.0; 3],
                g: [0.5, 0.6, 0.7],
            },
        ],
    )
    .unwrap();
    let settings = McSettings::new(30_000, 7, 10, 0.05, 40).unwrap();
    let (g1, _) = compare_paths(&stack, &settings, &[0, 3, 10], "two-layer");
    assert!((g1.channels[0].specular_reflectance - 0.04).abs() < 1e-12);
    // Deterministic per device: integer (fixed-point) sums do not depend on the order of the atomics.
    let g = gpu();
    let pipeline = TransportGpu::new(&g.device).unwrap();
    let g2 = pipeline.simulate(&g.device, &g.queue, &stack, &settings, &|_| {}).unwrap();
    assert_eq!(g1, g2, "the same seed on the same device gives the same result");
    let other = pipeline.simulate(&g.device, &g.queue, &stack, &McSettings { seed: 8, ..settings }, &|_| {}).unwrap();
    assert_ne!(g1.channels[0].diffuse_reflectance, other.channels[0].diffuse_reflectance);
    // Segments of 700 photons (5 per batch, the last short) dispatched 3 workgroups wide (4 deep along z): every
    // photon keeps its index, and integer sums give the same bytes.
    let split = pipeline.split(700, 3).unwrap();
    let g3 = split.simulate(&g.device, &g.queue, &stack, &settings, &|_| {}).unwrap();
    assert_eq!(g1, g3, "segmenting and the dispatch shape do not change the result");
}

/// The WGSL Philox4x32-10 (with its 16-bit-half products) gives Random123's known answers and the CPU's blocks.
#[test]
fn gpu_philox_matches_the_known_answers_and_the_cpu() {
    let g = gpu();
    let mut counters = vec![[0u32; 4], [u32::MAX; 4], [0x243f_6a88, 0x85a3_08d3, 0x1319_8a2e, 0x0370_7344]];
    // And a spread of counters under another key, against the CPU.
    let mut x = 0x1234_5678u32;
    for _ in 0..200 {
        let mut c = [0u32; 4];
        for v in &mut c {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            *v = x;
        }
        counters.push(c);
    }
    let kat = philox_blocks(&g.device, &g.queue, &counters[..1], [0, 0]).unwrap();
    assert_eq!(kat[0], [0x6627_e8d5, 0xe169_c58d, 0xbc57_ac4c, 0x9b00_dbd8]);
    let kat = philox_blocks(&g.device, &g.queue, &counters[1..2], [u32::MAX; 2]).unwrap();
    assert_eq!(kat[0], [0x408f_276d, 0x41c8_3b0e, 0xa20b_c7c6, 0x6d54_51fd]);
    let kat = philox_blocks(&g.device, &g.queue, &counters[2..3], [0xa409_3822, 0x299f_31d0]).unwrap();
    assert_eq!(kat[0], [0xd16c_fe09, 0x94fd_cceb, 0x5001_e420, 0x2412_6ea1]);
    let key = [0xdead_beef, 0x0bad_f00d];
    let gpu_blocks = philox_blocks(&g.device, &g.queue, &counters, key).unwrap();
    for (c, b) in counters.iter().zip(&gpu_blocks) {
        assert_eq!(*b, philox4x32_10(*c, key), "counter {c:x?}");
    }
}

/// Sizes the device cannot hold are refused with a typed error naming the field, before any work; bad settings
/// never reach the GPU (the library's constructors refuse them).
#[test]
fn gpu_transport_refuses_bad_input() {
    let g = gpu();
    let layer =
        McLayer { thickness_mm: 0.2, eta: 1.4, sigma_a_per_mm: [1.0; 3], sigma_s_per_mm: [9.0; 3], g: [0.0; 3] };
    let stack = McStack::new(1.0, 1.0, vec![layer]).unwrap();
    // More bins than this device's storage binding holds (with its real limits, smaller than 100 000 bins x 16 B
    // x 3 on no adapter we know of, so shrink the limit instead): bad input naming `bins`.
    let settings = McSettings::new(1000, 1, 10, 0.01, 10_000).unwrap();
    let small = wgpu::Limits { max_storage_buffer_binding_size: 64 * 1024, ..g.device.limits() };
    match GpuPlan::new(&small, &stack, &settings) {
        Err(RuntimeError::Invalid(e)) => {
            assert_eq!(e.param, "bins");
            assert!(e.message.contains("max_storage_buffer_binding_size"), "{}", e.message);
        }
        other => panic!("expected a refusal naming bins, got {other:?}"),
    }
    // The device's real limits hold the largest accepted bin count.
    let most = McSettings::new(1000, 1, 10, 0.01, 100_000).unwrap();
    GpuPlan::new(&g.device.limits(), &stack, &most).expect("100 000 bins fit the test adapter");
    // Bad settings are refused by the constructor the GPU path shares with the CPU path.
    assert_eq!(McSettings::new(0, 1, 10, 0.01, 10).unwrap_err().param, "photons");
    assert_eq!(McSettings::new(10, 1, 1, 0.01, 10).unwrap_err().param, "batches");
}

/// `rtbake transport --gpu` writes the CPU path's CSV and JSON layout (same columns, same keys), the JSON naming
/// the path and the adapter, and the totals agree with the CPU run of the same seed within 4 combined SE.
#[test]
fn cli_gpu_writes_the_same_layout_and_names_the_adapter() {
    let dir = tempfile::tempdir().unwrap();
    let run = |gpu: bool, tag: &str| {
        let (csv, out) = (dir.path().join(format!("{tag}.csv")), dir.path().join(format!("{tag}.json")));
        let mut args = vec![
            "transport",
            "--material",
            "skin1",
            "--thickness-mm",
            "1",
            "--photons",
            "5000",
            "--seed",
            "3",
            "--bin-mm",
            "0.2",
            "--bins",
            "20",
            "-q",
        ];
        let (c, o) = (csv.to_str().unwrap().to_string(), out.to_str().unwrap().to_string());
        args.extend(["--csv", &c, "--out", &o]);
        if gpu {
            args.push("--gpu");
        }
        let res = rtbake(&args);
        assert!(res.status.success(), "{args:?}: {}", String::from_utf8_lossy(&res.stderr));
        let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
        (std::fs::read_to_string(&csv).unwrap(), json)
    };
    let (gpu_csv, gpu_json) = run(true, "gpu");
    let (cpu_csv, cpu_json) = run(false, "cpu");
    let header = |s: &str| s.lines().find(|l| !l.starts_with('#')).unwrap().to_string();
    assert_eq!(header(&gpu_csv), header(&cpu_csv));
    assert_eq!(header(&gpu_csv), "r_mm,R_r,R_g,R_b,T_r,T_g,T_b");
    assert_eq!(gpu_csv.lines().count(), cpu_csv.lines().count());
    let keys = |v: &serde_json::Value| v.as_object().unwrap().keys().cloned().collect::<Vec<_>>();
    assert_eq!(keys(&gpu_json), keys(&cpu_json));
    assert!(gpu_json["provenance"]["path"].as_str().unwrap().starts_with("gpu"), "{}", gpu_json["provenance"]);
    assert!(cpu_json["provenance"]["path"].as_str().unwrap().starts_with("cpu"), "{}", cpu_json["provenance"]);
    let adapter = gpu_json["provenance"]["adapter"].as_str().unwrap();
    assert!(!adapter.is_empty() && cpu_json["provenance"].get("adapter").is_none());
    for c in 0..3 {
        for key in ["total_R", "total_T"] {
            let est = |v: &serde_json::Value| Estimate {
                mean: v[key][c]["mean"].as_f64().unwrap(),
                se: v[key][c]["se"].as_f64().unwrap(),
            };
            assert_agree(&format!("CLI {key} ch {c}"), est(&gpu_json), est(&cpu_json));
        }
    }
}

/// No adapter (here: `WGPU_ADAPTER_NAME` matching none): exit 2 naming `--gpu`, nothing written.
#[test]
fn cli_gpu_without_an_adapter_exits_2_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("mc.csv");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rtbake"))
        .args(["transport", "--material", "skin1", "--photons", "100", "--gpu", "--csv", csv.to_str().unwrap()])
        .env("WGPU_ADAPTER_NAME", "no-such-adapter-rtbake-test")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("--gpu") && err.contains("no-such-adapter-rtbake-test"), "{err}");
    assert!(!csv.exists());
}
