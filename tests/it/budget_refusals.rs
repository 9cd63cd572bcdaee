//! Every size range `--help` documents is one the machine can serve. Each heavy job estimates
//! its peak memory and its run time before any work (from the models' `memory_estimate_bytes` /
//! `time_estimate_seconds`) and refuses, with exit 2, the flags, the estimate and the budget named, whatever exceeds
//! `--max-memory` or `--max-seconds` (default 600 s); the largest sizes `--help` allows are refused in well under
//! two seconds, never aborted or panicked on, and nothing is written.

use crate::support::rtbake;
use std::path::Path;
use std::time::{Duration, Instant};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `args` + `--out/--output/--csv PATH` and checks a quick, clean refusal naming `flags` and `budget`.
fn refused(args: &[&str], out_flag: &str, out: &Path, flags: &[&str], budget: &str) {
    let mut a: Vec<&str> = args.to_vec();
    a.extend([out_flag, s(out)]);
    let t = Instant::now();
    let o = rtbake(&a);
    let took = t.elapsed();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{a:?}: {err}");
    assert!(took < Duration::from_secs(2), "{a:?}: refusal took {took:?}");
    for f in flags {
        assert!(err.contains(f), "{a:?}: message does not name {f}: {err}");
    }
    assert!(err.contains(budget) && (err.contains("estimated") || err.contains("needs about")), "{a:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{a:?} wrote {}", out.display());
}

#[test]
fn the_largest_sizes_help_allows_are_refused_up_front_when_they_exceed_the_time_budget() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("o");
    // Skin LUT 2048² with the direct evaluation (the "does not finish in 10 min"): a stated estimate.
    refused(
        &["skin-color", "--resolution", "2048", "--lut-evaluation", "direct", "--max-seconds", "60"],
        "--out",
        &out,
        &["--resolution 2048x2048", "--lut-evaluation direct", "--max-seconds"],
        "time budget of 60 s",
    );
    // Layered profile at the largest radius count and image-pair count.
    refused(
        &[
            "profile",
            "--skin-melanin",
            "0.1",
            "--skin-hemoglobin",
            "0.1",
            "--count",
            "1000000",
            "--dipole-pairs",
            "10000",
        ],
        "--csv",
        &out,
        &["--count (1000000 radii)", "--dipole-pairs 10000", "default --max-seconds 600"],
        "time budget of 600 s",
    );
    // Transmittance at its largest table: refused by memory under a small budget, by time under a short one.
    refused(
        &["transmittance", "--samples", "16384", "--height", "16384", "--max-memory", "4G"],
        "--out",
        &out,
        &["--samples 16384 --height 16384", "--max-memory"],
        "GiB",
    );
    refused(
        &["transmittance", "--samples", "16384", "--height", "16384", "--max-memory", "100G", "--max-seconds", "60"],
        "--out",
        &out,
        &["--samples 16384 --height 16384", "--max-seconds 60"],
        "time budget of 60 s",
    );
    // Monte Carlo transport at the largest photon count.
    refused(
        &["transport", "--material", "skin1", "--photons", "10000000000"],
        "--csv",
        &out,
        &["--photons 10000000000", "default --max-seconds 600"],
        "time budget of 600 s",
    );
    // The demo at its largest frame on the CPU.
    refused(
        &[
            "run",
            "demo",
            "--cpu",
            "--width",
            "16384",
            "--height",
            "16384",
            "--max-memory",
            "100G",
            "--max-seconds",
            "60",
        ],
        "--output",
        &out.with_extension("png"),
        &["--width 16384 --height 16384", "--max-seconds 60"],
        "time budget of 60 s",
    );
}

#[test]
fn the_hemoglobin_rig_estimates_its_disk_statistics_before_reading_the_targets() {
    let t = tempfile::tempdir().unwrap();
    let fx = t.path().join("fx");
    let o = rtbake(&["maps", "synthetic", "--size", "64", "--targets", "anger", "--out", s(&fx)]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let anger = format!("anger={}", s(&fx.join("anger.png")));
    let out = t.path().join("rig");
    // r = 31 is the largest radius a 64² map allows.
    let neutral = fx.join("neutral.png");
    let args = ["maps", "hemoglobin", "--neutral", s(&neutral), "--target", &anger, "--radius", "31"];
    let mut tight = args.to_vec();
    tight.extend(["--max-seconds", "0.00001"]);
    refused(&tight, "--out", &out, &["--radius 31 on 2 maps of 64x64", "--max-seconds"], "time budget");
    let mut small = args.to_vec();
    small.extend(["--max-memory", "1M"]);
    refused(&small, "--out", &out, &["--radius 31 on 2 maps of 64x64", "--max-memory"], "MiB");
    // Within both budgets it runs.
    let mut ok = args.to_vec();
    ok.extend(["--rig-size", "8", "--out", s(&out)]);
    let o = rtbake(&ok);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn bad_time_budgets_are_refused_naming_the_flag() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("o");
    for bad in ["0", "-5", "soon", "inf", "NaN"] {
        let o = rtbake(&["transmittance", "--samples", "64", "--max-seconds", bad, "--out", s(&out)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--max-seconds"), "{bad}: {err}");
        assert!(!out.exists());
    }
}

/// The estimates are within a factor of the measured cost where measuring is cheap (memory: the buffers counted).
#[test]
fn estimates_scale_with_the_work() {
    use rtbake::skin_color::lut::{self, LutEvaluation, LutLayout};
    let small = LutLayout::new(64, 64, Default::default()).unwrap();
    let big = LutLayout::new(2048, 2048, Default::default()).unwrap();
    let ts = lut::time_estimate_seconds(&small, LutEvaluation::Tabulated, 401, 2);
    let tb = lut::time_estimate_seconds(&big, LutEvaluation::Tabulated, 401, 2);
    assert!((tb - 1.0) / (ts - 1.0) > 1000.0, "time grows with the texels: {ts} {tb}");
    let td = lut::time_estimate_seconds(&big, LutEvaluation::Direct, 401, 2);
    assert!(td > 5.0 * tb, "direct is slower: {td} vs {tb}");
    assert!(lut::time_estimate_seconds(&big, LutEvaluation::Tabulated, 401, 1) > tb, "fewer threads, more time");
    // The rig's memory counts at least the decoded maps and the f64 statistics.
    let m = rtbake::facial::hemoglobin_rig::memory_estimate_bytes(1024, 1024, 9);
    assert!(m >= 1024 * 1024 * (9 * 4 + 2 * 16), "{m}");
    use rtbake::diffusion::multipole::Series;
    let exact = rtbake::diffusion::layered::profile_time_estimate_seconds(2, 1_000_000, Series::Exact, 2);
    let pairs =
        rtbake::diffusion::layered::profile_time_estimate_seconds(2, 1_000_000, Series::Truncated { pairs: 10_000 }, 2);
    assert!(exact > 10.0 && exact < 600.0, "the default 10⁶-radius skin profile is served: {exact}");
    assert!(pairs > 600.0, "10⁶ radii at 10 000 pairs is refused by default: {pairs}");
}

/// `run smaa|mlaa|sss` estimate their pass from the decoded input's size before running it.
#[test]
fn run_passes_estimate_from_the_input_size() {
    let t = tempfile::tempdir().unwrap();
    let baked = crate::support::baked_dir();
    let b = s(&baked);
    let frame = t.path().join("f.png");
    let inputs = t.path().join("si");
    let o = rtbake(&[
        "run",
        "demo",
        "--cpu",
        "--width",
        "64",
        "--height",
        "48",
        "--output",
        s(&frame),
        "--sss-inputs",
        s(&inputs),
        "--baked-dir",
        b,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let out = t.path().join("o.png");
    for pass in ["smaa", "mlaa"] {
        let args = ["run", pass, "--cpu", "--input", s(&frame), "--baked-dir", b, "--max-seconds", "0.00001"];
        refused(&args, "--output", &out, &["--input", "(64x48)", "--max-seconds"], "time budget");
        let args = ["run", pass, "--cpu", "--input", s(&frame), "--baked-dir", b, "--max-memory", "1M"];
        refused(&args, "--output", &out, &["--input", "(64x48)", "--max-memory"], "MiB");
    }
    let (color, depth) = (inputs.join("irradiance.exr"), inputs.join("depth.exr"));
    let out = t.path().join("o.exr");
    let args =
        ["run", "sss", "--cpu", "--color", s(&color), "--depth", s(&depth), "--baked-dir", b, "--max-memory", "1M"];
    refused(&args, "--output", &out, &["--color", "(64x48)", "--max-memory"], "MiB");
    // Within the default budgets the same passes run.
    let o = rtbake(&[
        "run",
        "smaa",
        "--cpu",
        "--input",
        s(&frame),
        "--baked-dir",
        b,
        "--output",
        s(&t.path().join("ok.png")),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `maps wrinkles` and `maps wrinkle-masks` estimate from the decoded input before the conversion.
#[test]
fn wrinkle_conversions_estimate_from_the_input_size() {
    let t = tempfile::tempdir().unwrap();
    let normal = t.path().join("n.png");
    let px: Vec<u8> = (0..64 * 64).flat_map(|_| [140u8, 120, 240]).collect();
    std::fs::write(&normal, rtbake::io::png::encode_u8(&rtbake::Image::from_vec(64, 64, 3, px)).unwrap()).unwrap();
    let zone = t.path().join("z.png");
    std::fs::write(
        &zone,
        rtbake::io::png::encode_u8(&rtbake::Image::from_vec(64, 64, 1, vec![90u8; 64 * 64])).unwrap(),
    )
    .unwrap();
    let out = t.path().join("o");
    let args = ["maps", "wrinkles", "--normal", s(&normal), "--max-memory", "1M"];
    refused(&args, "--out", &out, &["--normal", "(64x64)", "--max-memory"], "MiB");
    let zone_arg = format!("red={}", s(&zone));
    let args = ["maps", "wrinkle-masks", "--zone", &zone_arg, "--max-seconds", "0.001"];
    refused(&args, "--out", &out, &["--zone x1", "(64x64", "--max-seconds"], "time budget");
    let o = rtbake(&["maps", "wrinkles", "--normal", s(&normal), "--size", "16", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `maps synthetic` and `maps rig-eval` (whose output is the rig's full size, up to 16384²) estimate before any
/// work: refused under small budgets with the flags named; at the sizes `--help` allows the estimates are served by
/// the default budgets (measured at 4096² with the release build: synthetic 40.8 s / 300 MB for 5 maps, rig-eval
/// 2.0 s / 267 MB).
#[test]
fn synthetic_maps_and_rig_evaluation_estimate_before_any_work() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("o");
    let all = "joy,anger,fear,disgust,sadness,surprise,exercise,alcohol";
    let args = ["maps", "synthetic", "--size", "8192", "--targets", all, "--max-seconds", "60"];
    refused(&args, "--out", &out, &["--size 8192 with 9 maps", "--targets", "--max-seconds"], "time budget of 60 s");
    let args = ["maps", "synthetic", "--size", "512", "--max-memory", "20M"];
    refused(&args, "--out", &out, &["--size 512", "--max-memory"], "MiB");
    let (bytes, seconds) = rtbake::facial::synthetic::hemoglobin_set_estimate(8192, 9);
    assert!(
        bytes < 6 << 30 && seconds < 600.0,
        "the largest synthetic set is served by default: {bytes} B, {seconds} s"
    );

    // A small rig, then its evaluation under a budget too small for its full size.
    let syn = t.path().join("syn");
    let o = rtbake(&["maps", "synthetic", "--size", "32", "--targets", "joy", "--out", s(&syn), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let rig = t.path().join("rig");
    let target = format!("joy={}", s(&syn.join("joy.png")));
    let o = rtbake(&[
        "maps",
        "hemoglobin",
        "--neutral",
        s(&syn.join("neutral.png")),
        "--target",
        &target,
        "--radius",
        "4",
        "--rig-size",
        "8",
        "--out",
        s(&rig),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let rig_json = rig.join("rig.json");
    let eval_out = t.path().join("h.exr");
    let args = ["maps", "rig-eval", "--rig", s(&rig_json), "--weights", "joy=1", "--max-memory", "1M"];
    refused(&args, "--out", &eval_out, &["--rig", "(full size 32x32)", "--max-memory"], "MiB");
    let o = rtbake(&["maps", "rig-eval", "--rig", s(&rig_json), "--weights", "joy=1", "--out", s(&eval_out)]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    use rtbake::facial::hemoglobin_rig::{evaluate_memory_estimate_bytes, evaluate_time_estimate_seconds};
    // The thesis' 256² storage at the largest full size is served; 9 full-size 16384² scale/bias pairs (18 GiB
    // of stored maps) are not.
    let bytes = evaluate_memory_estimate_bytes(16384, 16384, 256, 256, 9);
    assert!(bytes > 6 << 30 && bytes < 7 << 30, "16384² from 256² maps: {bytes} B");
    assert!(evaluate_memory_estimate_bytes(16384, 16384, 16384, 16384, 9) > 24 << 30);
    assert!(evaluate_time_estimate_seconds(16384, 16384) < 600.0);
}

/// A high-albedo slab (marble, reduced albedo ≈ 0.999) takes ~1.5 CPU-s per 10⁵ photons in the dev and the release
/// build alike (the lane kernel is built at opt-level 3 in both): 3·10⁶ photons are estimated well over a 30 s
/// budget from the slab's optics and refused before any photon is traced.
#[test]
fn a_high_albedo_slab_over_the_time_budget_is_refused() {
    let t = tempfile::tempdir().unwrap();
    refused(
        &["transport", "--material", "marble", "--photons", "3000000", "--max-seconds", "30"],
        "--csv",
        &t.path().join("marble.csv"),
        &["--photons 3000000", "--max-seconds 30"],
        "time budget of 30 s",
    );
}
