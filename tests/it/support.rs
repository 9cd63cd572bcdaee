//! Shared helpers of the integration tests: the CLI runner, the one rule for external inputs, the device (a missing
//! adapter FAILS the test), golden LUTs, comparisons.
#![allow(dead_code)]

use rtbake::runtime::cpu::FilterPrecision;
use rtbake::runtime::device::{create_headless, Gpu};
use rtbake::runtime::smaa::SmaaTextures;
use std::path::PathBuf;

/// The headless device; panics (test failure, not a skip) when there is no adapter.
pub fn gpu() -> Gpu {
    match create_headless(&Default::default()) {
        Ok(g) => {
            eprintln!("adapter: {}", g.describe());
            g
        }
        Err(e) => panic!("runtime tests need an adapter (install mesa-vulkan-drivers for lavapipe): {e}"),
    }
}

/// The bilinear precision model of the test adapter.
pub fn precision(g: &Gpu) -> FilterPrecision {
    FilterPrecision::for_adapter(&g.adapter_info.name, g.adapter_info.device_type == wgpu::DeviceType::Cpu)
}

/// The committed bake directory (`baked/` beside the crate).
pub fn baked_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked")
}

/// rtbake's SMAA textures from the committed bake, through the manifest-checked loader.
pub fn baked_smaa() -> SmaaTextures {
    rtbake::runtime::loader::load_smaa_textures(&baked_dir()).unwrap_or_else(|e| panic!("{e}"))
}

/// rtbake's MLAA v1.4 area map for maximum distance n from the committed bake, through the loader.
pub fn baked_mlaa(n: u32) -> Vec<u8> {
    rtbake::runtime::loader::load_mlaa_area(&baked_dir(), n).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs the `rtbake` binary built for these tests.
pub fn rtbake(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_rtbake")).args(args).output().expect("run rtbake")
}

/// The golden reference folder: `$RTBAKE_REFERENCE_DIR`, default `../shared/reference` beside the crate.
pub fn reference_dir() -> PathBuf {
    std::env::var_os("RTBAKE_REFERENCE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| crate_dir().join("../shared/reference"))
}

/// The crate root.
pub fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Whether CI asked for every external input (`RTBAKE_REQUIRE_REFERENCE=1`).
pub fn external_inputs_required() -> bool {
    std::env::var("RTBAKE_REQUIRE_REFERENCE").as_deref() == Ok("1")
}

/// The one rule for a missing external input: fail under `RTBAKE_REQUIRE_REFERENCE=1`, otherwise say plainly what
/// was not checked. The message goes straight to the process' stderr (not through the test harness' capture), so
/// a plain `cargo test` shows it.
pub fn skip_missing(what: &str, path: &std::path::Path, env_var: &str) {
    let msg = format!(
        "SKIPPED{}: {what} — {} not found ({}; set {env_var}; see README \"Tests and ../shared\")",
        test_name(),
        path.display(),
        origin_of(path, env_var)
    );
    if external_inputs_required() {
        panic!("{msg}, but RTBAKE_REQUIRE_REFERENCE=1");
    }
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{msg}");
}

/// ` [module::test]` of the running test (the harness names each test's thread after it), so that skips of
/// different tests over the same input read differently.
pub fn test_name() -> String {
    std::thread::current().name().filter(|n| *n != "main").map(|n| format!(" [{n}]")).unwrap_or_default()
}

/// Where a missing external input comes from: the data tables by the variable that overrides their folder
/// (whatever path it names), the reference files by their place under `../shared/reference`.
fn origin_of(path: &std::path::Path, env_var: &str) -> &'static str {
    let p = path.to_string_lossy();
    if env_var == "RTBAKE_DATA_DIR" {
        return "the physical data tables of ../shared/data (spectra, absorption coefficients)";
    }
    if p.contains("consumers/bevy_anti_alias") {
        "Bevy's SMAA LUTs, from the bevy_anti_alias 0.20.1 crate on crates.io"
    } else if p.contains("consumers/separable-sss") {
        "SeparableSSS.h of github.com/iryoku/separable-sss"
    } else if p.contains("heads/") {
        "the Lee Perry-Smith head scan as distributed with the three.js examples"
    } else {
        "the upstream SMAA (github.com/iryoku/smaa) and Jimenez MLAA textures of ../shared/reference, not \
         redistributed in a clone"
    }
}

/// The reference folder if it holds the golden files; otherwise reports the skip of `what` under the rule above.
pub fn reference_dir_for(what: &str) -> Option<PathBuf> {
    let dir = reference_dir();
    if dir.join("smaa/SHA256SUMS").is_file() && dir.join("mlaa/SHA256SUMS").is_file() {
        return Some(dir);
    }
    skip_missing(what, &dir, "RTBAKE_REFERENCE_DIR");
    None
}

/// The reference folder for the runtime's golden-texture comparisons.
pub fn reference_dir_checked() -> Option<PathBuf> {
    reference_dir_for("comparison with the upstream golden SMAA/MLAA textures")
}

/// One file of the reference folder (e.g. `consumers/separable-sss/SeparableSSS.h`), or the skip of `what`.
pub fn reference_file(rel: &str, what: &str) -> Option<PathBuf> {
    let path = reference_dir().join(rel);
    if path.is_file() {
        return Some(path);
    }
    skip_missing(what, &path, "RTBAKE_REFERENCE_DIR");
    None
}

/// The physical data tables (`$RTBAKE_DATA_DIR`, default `../shared/data`), or the skip of `what`.
pub fn data_dir_for(what: &str) -> Option<PathBuf> {
    let dir =
        std::env::var_os("RTBAKE_DATA_DIR").map(PathBuf::from).unwrap_or_else(|| crate_dir().join("../shared/data"));
    if dir.is_dir() {
        return Some(dir);
    }
    skip_missing(what, &dir, "RTBAKE_DATA_DIR");
    None
}

fn read(rel: &str) -> Vec<u8> {
    let p = reference_dir().join(rel);
    std::fs::read(&p).unwrap_or_else(|e| panic!("golden file {} missing: {e}", p.display()))
}

/// The upstream SMAA textures (golden bytes).
pub fn golden_smaa() -> SmaaTextures {
    SmaaTextures::new(read("smaa/AreaTex_RG8_160x560.bin"), read("smaa/SearchTex_R8_64x16.bin")).unwrap()
}

/// The upstream MLAA v1.4 area map for maximum distance n.
pub fn golden_mlaa(n: u32) -> Vec<u8> {
    read(&format!("mlaa/AreaMap{n}_v1.4_RG8_{}x{}.bin", 5 * n, 5 * n))
}

/// Fraction of samples that differ by at most `tol`, and the largest difference.
pub fn within(a: &[u8], b: &[u8], tol: u8) -> (f64, u8) {
    assert_eq!(a.len(), b.len());
    let mut ok = 0usize;
    let mut max = 0u8;
    for (x, y) in a.iter().zip(b) {
        let d = x.abs_diff(*y);
        max = max.max(d);
        if d <= tol {
            ok += 1;
        }
    }
    (ok as f64 / a.len() as f64, max)
}

/// Fraction of pixels (all `ch` channels) within `tol`.
pub fn pixels_within(a: &[u8], b: &[u8], ch: usize, tol: u8) -> f64 {
    let n = a.len() / ch;
    let ok =
        a.chunks(ch).zip(b.chunks(ch)).filter(|(p, q)| p.iter().zip(*q).all(|(x, y)| x.abs_diff(*y) <= tol)).count();
    ok as f64 / n as f64
}

/// Whether an external program runs (`cmd args…` exits 0); otherwise the one rule for missing inputs applies to
/// `what` (SKIPPED on stderr, or a failure under `RTBAKE_REQUIRE_REFERENCE=1`). `install` says how CI gets it.
pub fn tool_available(what: &str, cmd: &str, args: &[&str], install: &str) -> bool {
    let ok = std::process::Command::new(cmd)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !ok {
        let msg = format!(
            "SKIPPED{}: {what} — `{cmd} {}` does not run ({install}; .ci/run installs it)",
            test_name(),
            args.join(" ")
        );
        if external_inputs_required() {
            panic!("{msg}, but RTBAKE_REQUIRE_REFERENCE=1");
        }
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "{msg}");
    }
    ok
}

/// The files of the committed bake whose manifest entry has this container format, as (path, entry).
pub fn baked_files_of_format(format: &str) -> Vec<(PathBuf, rtbake::manifest::Entry)> {
    let dir = baked_dir();
    let manifest = rtbake::manifest::Manifest::load(&dir).expect("baked/manifest.json");
    manifest.files.into_iter().filter(|e| e.meta.format.as_str() == format).map(|e| (dir.join(&e.path), e)).collect()
}

/// Mean absolute error (0..255 scale, RGB) of RGBA8 `img` against `truth` over the pixels selected by `mask`
/// (the edge error of the antialiasing quality checks), and PSNR (dB) over all pixels.
pub fn edge_error_and_psnr(img: &[u8], truth: &[u8], mask: &[bool]) -> (f64, f64) {
    let (mut sum, mut n, mut se) = (0.0f64, 0usize, 0.0f64);
    for (i, (p, q)) in img.chunks(4).zip(truth.chunks(4)).enumerate() {
        for k in 0..3 {
            let d = p[k] as f64 - q[k] as f64;
            se += d * d;
            if mask[i] {
                sum += d.abs();
                n += 1;
            }
        }
    }
    let mse = se / (img.len() / 4 * 3) as f64;
    (sum / n as f64, 10.0 * (255.0f64 * 255.0 / mse).log10())
}

/// Where a GPU/CPU comparison named `name` leaves its images: `CARGO_TARGET_TMPDIR/gpu-cpu-diffs/NAME/`.
pub fn comparison_dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gpu-cpu-diffs").join(name)
}

/// Writes the GPU and CPU images of a comparison (`w`×`h`, `ch` interleaved 8-bit channels) and their difference
/// (|gpu − cpu| per channel, ×16 so that a 1/255 step is visible; alpha 255) as `gpu.png`, `cpu.png` and
/// `difference.png` into [`comparison_dir`]`(name)`, and returns that folder.
pub fn write_comparison(name: &str, (w, h, ch): (u32, u32, u32), gpu: &[u8], cpu: &[u8]) -> PathBuf {
    use rtbake::image_buf::Image;
    let dir = comparison_dir(name);
    std::fs::create_dir_all(&dir).unwrap();
    let diff: Vec<u8> = gpu
        .iter()
        .zip(cpu)
        .enumerate()
        .map(|(i, (a, b))| if ch == 4 && i % 4 == 3 { 255 } else { a.abs_diff(*b).saturating_mul(16) })
        .collect();
    for (file, data) in [("gpu.png", gpu), ("cpu.png", cpu), ("difference.png", &diff[..])] {
        let png = rtbake::io::png::encode_u8(&Image::from_vec(w, h, ch, data.to_vec())).unwrap();
        std::fs::write(dir.join(file), png).unwrap();
    }
    dir
}

/// Asserts a GPU/CPU agreement `ok` (described by `what`); when it fails, writes the two images and their
/// difference ([`write_comparison`]) and names the folder in the panic message.
pub fn assert_gpu_matches_cpu(name: &str, ok: bool, what: &str, size: (u32, u32, u32), gpu: &[u8], cpu: &[u8]) {
    if !ok {
        let dir = write_comparison(name, size, gpu, cpu);
        panic!("{name}: GPU and CPU differ: {what}; gpu.png, cpu.png and difference.png are in {}", dir.display());
    }
}

/// Linear f32 samples as 8-bit for viewing a comparison (clamped to [0, 1], ×255, rounded).
pub fn unorm8_of(samples: &[f32]) -> Vec<u8> {
    samples.iter().map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8).collect()
}

/// The runtime tests' small `run skin` frame: `heads` of the default spacing at `distance_m`, 160×96, melanin 0.02.
pub fn head_frame_160x96(
    shader: rtbake::runtime::skin_render::SkinShader,
    heads: u32,
    distance_m: f32,
    stretch: rtbake::runtime::skin_render::StretchPreset,
) -> rtbake::runtime::skin_render::SkinRenderSettings {
    rtbake::runtime::skin_render::SkinRenderSettings {
        shader,
        heads,
        distance_m,
        width: 160,
        height: 96,
        melanin: 0.02,
        stretch,
    }
}
