//! The typed loaders of the float and JSON tables (separable kernel, sum-of-Gaussians fit, T(s), skin colour
//! LUT): accepted from the committed `baked/`, refused with a clear error when the manifest declares sRGB, the
//! size is wrong or the checksum does not match (synthetic bake directories built from the committed files).

use rtbake::bake::BakedFile;
use rtbake::baked_layout::path;
use rtbake::diffusion::sum_of_gaussians::deon6;
use rtbake::manifest::{ColorSpace, FileFormat, Manifest, SampleType};
use rtbake::runtime::loader::{self, LutError};
use std::path::{Path, PathBuf};

fn baked() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked")
}

/// The committed files at `paths` with their committed manifest metadata.
fn committed(paths: &[&str]) -> Vec<BakedFile> {
    let m = Manifest::load(&baked()).unwrap();
    paths
        .iter()
        .map(|p| BakedFile {
            path: p.to_string(),
            bytes: std::fs::read(baked().join(p)).unwrap(),
            meta: m.entry(p).unwrap_or_else(|| panic!("{p} not in baked/manifest.json")).meta.clone(),
        })
        .collect()
}

/// A bake directory holding `files` (after `tweak`) and a manifest describing them.
fn bake_dir(dir: &Path, mut files: Vec<BakedFile>, tweak: impl FnOnce(&mut [BakedFile])) {
    tweak(&mut files);
    let mut m = Manifest::new();
    m.set_asset("test", serde_json::json!({}), &files);
    for f in &files {
        let p = dir.join(&f.path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, &f.bytes).unwrap();
    }
    std::fs::write(dir.join("manifest.json"), m.to_text()).unwrap();
}

/// Flips one byte of `path` in `dir` after the manifest was written.
fn corrupt(dir: &Path, path: &str, at: usize) {
    let p = dir.join(path);
    let mut b = std::fs::read(&p).unwrap();
    let i = at.min(b.len() - 1);
    b[i] ^= 0x01;
    std::fs::write(p, b).unwrap();
}

type Load = fn(&Path) -> Result<(), LutError>;

fn load_kernel(d: &Path) -> Result<(), LutError> {
    loader::load_separable_kernel(d, path::SEPARABLE_KERNEL_DEFAULT).map(|_| ())
}
fn load_gaussians(d: &Path) -> Result<(), LutError> {
    loader::load_gaussians(d, path::GAUSSIANS_DEFAULT).map(|_| ())
}
fn load_t(d: &Path) -> Result<(), LutError> {
    loader::load_transmittance(d, path::TRANSMITTANCE_DEFAULT).map(|_| ())
}
fn load_skin(d: &Path) -> Result<(), LutError> {
    loader::load_skin_lut(d, path::SKIN_LUT).map(|_| ())
}

/// (the loaded file, every file the loader reads, loader).
fn cases() -> Vec<(&'static str, Vec<String>, Load)> {
    let side = |p: &str| path::sidecar(p);
    vec![
        (path::SEPARABLE_KERNEL_DEFAULT, vec![path::SEPARABLE_KERNEL_DEFAULT.into()], load_kernel as Load),
        (path::GAUSSIANS_DEFAULT, vec![path::GAUSSIANS_DEFAULT.into()], load_gaussians),
        (
            path::TRANSMITTANCE_DEFAULT,
            vec![path::TRANSMITTANCE_DEFAULT.into(), side(path::TRANSMITTANCE_DEFAULT)],
            load_t,
        ),
        (path::SKIN_LUT, vec![path::SKIN_LUT.into(), side(path::SKIN_LUT)], load_skin),
    ]
}

fn files(paths: &[String]) -> Vec<BakedFile> {
    committed(&paths.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn copies_of_the_committed_tables_are_accepted() {
    for (path, paths, load) in cases() {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |_| {});
        load(t.path()).unwrap_or_else(|e| panic!("{path}: {e}"));
    }
}

#[test]
fn tables_declared_srgb_are_refused() {
    for (path, paths, load) in cases() {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |f| f[0].meta.color_space = ColorSpace::Srgb);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::ColorSpace { .. }), "{path}: {e}");
        assert!(e.to_string().contains(path) && e.to_string().contains("srgb"), "{e}");
    }
}

#[test]
fn tables_with_a_bad_checksum_are_refused() {
    for (path, paths, load) in cases() {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |_| {});
        corrupt(t.path(), path, 200);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Checksum { .. }), "{path}: {e}");
        assert!(e.to_string().contains("sha256") && e.to_string().contains(path), "{e}");
    }
}

#[test]
fn tables_whose_length_differs_from_the_manifest_are_refused() {
    for (path, paths, load) in cases() {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |_| {});
        let p = t.path().join(path);
        let mut b = std::fs::read(&p).unwrap();
        b.truncate(b.len() - 3);
        std::fs::write(&p, b).unwrap();
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Size { .. }), "{path}: {e}");
    }
}

#[test]
fn float_tables_declared_with_the_wrong_size_are_refused() {
    for (path, paths, load) in cases().into_iter().filter(|c| c.0.ends_with(".exr")) {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |f| f[0].meta.width /= 2);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Content { .. }), "{path}: {e}");
        assert!(e.to_string().contains("the manifest declares 128x"), "{e}");
        // A declared 1-texel table is refused before decoding.
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |f| f[0].meta.width = 1);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Mismatch { field: "width x height", .. }), "{path}: {e}");
    }
}

#[test]
fn float_tables_declared_half_or_wrong_format_are_refused() {
    for (path, paths, load) in cases().into_iter().filter(|c| c.0.ends_with(".exr")) {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |f| f[0].meta.sample_type = SampleType::F16);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Mismatch { field: "sample_type", .. }), "{path}: {e}");
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |f| f[0].meta.format = FileFormat::Ktx2);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Mismatch { field: "format", .. }), "{path}: {e}");
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), files(&paths), |f| f[0].meta.channels = 4);
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Mismatch { field: "channels", .. }), "{path}: {e}");
    }
}

/// Rewrites a JSON file's content (the manifest then describes the edited file).
fn edit_json(f: &mut BakedFile, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut v: serde_json::Value = serde_json::from_slice(&f.bytes).unwrap();
    edit(&mut v);
    f.bytes = serde_json::to_vec_pretty(&v).unwrap();
}

#[test]
fn inconsistent_json_content_is_refused() {
    let kernel = || files(&[path::SEPARABLE_KERNEL_DEFAULT.into()]);
    let gauss = || files(&[path::GAUSSIANS_DEFAULT.into()]);
    let refused = |fs: Vec<BakedFile>, edit: &dyn Fn(&mut serde_json::Value), load: Load, needle: &str| {
        let t = tempfile::tempdir().unwrap();
        bake_dir(t.path(), fs, |f| edit_json(&mut f[0], edit));
        let e = load(t.path()).unwrap_err();
        assert!(matches!(e, LutError::Content { .. }) && e.to_string().contains(needle), "{needle}: {e}");
    };
    refused(kernel(), &|v| v["samples"] = 16.into(), load_kernel, "\"samples\" = 16 but \"kernel\" has 17 taps");
    refused(kernel(), &|v| v["kernel"][3][0] = 0.5.into(), load_kernel, "channel r weights sum");
    refused(kernel(), &|v| v["step_divisor"] = 2.0.into(), load_kernel, "step_divisor 2");
    refused(kernel(), &|v| v["schema"] = "other/2".into(), load_kernel, "schema \"other/2\"");
    refused(gauss(), &|v| v["blend_weights"][2][0] = 0.3.into(), load_gaussians, "blend_weights[2][0]");
    refused(gauss(), &|v| v["shared_variances"] = false.into(), load_gaussians, "shared_variances");
    refused(gauss(), &|v| v["incremental_variances"][1] = 0.05.into(), load_gaussians, "incremental_variances[1]");
}

#[test]
fn committed_separable_kernel_is_the_published_17_tap_kernel() {
    let k = loader::load_separable_kernel(&baked(), path::SEPARABLE_KERNEL_DEFAULT).unwrap();
    assert_eq!(k.kernel.taps.len(), 17);
    assert_eq!(k.range, 2.0);
    assert_eq!(k.sss_width, Some(0.012));
    assert_eq!(k.kernel.taps[0][3], 0.0);
    assert_eq!(k.kernel.taps[1][3], -2.0);
    assert_eq!(k.kernel.taps[16][3], 2.0);
    // Red is the widest channel: least weight in the centre tap.
    let c = k.kernel.taps[0];
    assert!(c[0] < c[1] && c[1] < c[2], "{c:?}");
}

#[test]
fn committed_gaussian_fit_is_deon6_with_eq_4_8_blend_weights() {
    let g = loader::load_gaussians(&baked(), path::GAUSSIANS_DEFAULT).unwrap();
    assert_eq!(g.fit, deon6());
    assert_eq!(g.blurs.blend.len(), 6);
    assert_eq!(g.blurs.blend[0], [1.0; 3]);
    // w'_2 (red) = 0.1 / (0.233 + 0.1)
    assert!((g.blurs.blend[1][0] as f64 - 0.1 / 0.333).abs() < 1e-6);
    assert!((g.blurs.incremental_sigma_mm[1] as f64 - (0.0484f64 - 0.0064).sqrt()).abs() < 1e-6);
    assert_eq!((g.params.alpha, g.params.beta, g.params.gamma), (31.5, 800.0, 0.001));
}

#[test]
fn committed_transmittance_matches_eq_5_12_on_its_nodes() {
    let t = loader::load_transmittance(&baked(), path::TRANSMITTANCE_DEFAULT).unwrap();
    assert_eq!(t.values.len(), 256);
    assert_eq!(t.s_max_mm, 8.0);
    let fit = deon6();
    for (i, v) in t.values.iter().enumerate() {
        let s = 8.0 * i as f64 / 255.0;
        for c in 0..3 {
            let want: f64 =
                fit.variances_mm2.iter().zip(&fit.weights).map(|(var, w)| w[c] * (-s * s / var).exp()).sum(); // eq. 5.12
            assert!((v[c] as f64 - want).abs() < 1e-6, "T({s})[{c}] = {} vs {want}", v[c]);
        }
    }
}

#[test]
fn committed_skin_lut_is_256_square_linear_albedo() {
    let l = loader::load_skin_lut(&baked(), path::SKIN_LUT).unwrap();
    assert_eq!((l.width, l.height, l.albedo.len()), (256, 256, 65536));
    assert!(l.albedo.iter().flatten().all(|v| (0.0..1.0).contains(v)));
    let at = |i: usize, j: usize| l.albedo[j * 256 + i];
    // More melanin (columns) darkens, blue most; more hemoglobin (rows) reddens (green drops more than red).
    let (pale, dark) = (at(40, 40), at(255, 40));
    assert!((0..3).all(|c| dark[c] < pale[c]) && dark[2] / pale[2] < dark[0] / pale[0], "{pale:?} {dark:?}");
    let flushed = at(40, 255);
    assert!(flushed[1] / pale[1] < flushed[0] / pale[0], "{pale:?} {flushed:?}");
    let luts = loader::load_skin_luts(&baked(), path::SKIN_LUT, path::TRANSMITTANCE_DEFAULT).unwrap();
    luts.validate().unwrap();
}

#[test]
fn committed_hemoglobin_rig_loads_with_neutral_first() {
    let r = loader::load_hemoglobin_rig(&baked(), path::RIG_EXAMPLE).unwrap();
    assert_eq!(r.names[0], "neutral");
    assert_eq!(r.rig.targets.len(), r.names.len());
    assert_eq!((r.rig.width, r.rig.height), (32, 32));
    assert_eq!((r.h0.width, r.h0.height), (128, 128));
    // The neutral map has scale 1 (eq. 7.5: sigma_n / sigma_n).
    assert!(r.rig.targets[0].iter().all(|sb| (sb[0] - 1.0).abs() < 1e-6));
    let (lo, hi) = r.rig.targets.iter().flatten().fold((f32::MAX, f32::MIN), |(a, b), sb| (a.min(sb[1]), b.max(sb[1])));
    let h0 = r.h0.data.iter().fold(0.0f32, |a, v| a.max(v.abs()));
    eprintln!("bias range {lo}..{hi}, |H0| <= {h0}, global {:?}", r.global_scales);
    assert!(lo >= 0.0 && hi <= 0.32 && h0 < 0.1);
    // Bilinear H0 at a texel centre is that texel.
    assert_eq!(r.h0_at(5.5 / 128.0, 7.5 / 128.0), r.h0.data[7 * 128 + 5]);
}

#[test]
fn hemoglobin_rig_map_declared_srgb_or_corrupted_is_refused() {
    let m = Manifest::load(&baked()).unwrap();
    let paths: Vec<String> =
        m.files.iter().filter(|e| e.path.starts_with("facial/hemoglobin/example/")).map(|e| e.path.clone()).collect();
    let bias = "facial/hemoglobin/example/joy_bias.exr";
    let i = paths.iter().position(|p| p == bias).unwrap();
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), files(&paths), |f| f[i].meta.color_space = ColorSpace::Srgb);
    let e = loader::load_hemoglobin_rig(t.path(), path::RIG_EXAMPLE).unwrap_err();
    assert!(matches!(e, LutError::ColorSpace { .. }) && e.to_string().contains(bias), "{e}");
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), files(&paths), |_| {});
    corrupt(t.path(), bias, 300);
    let e = loader::load_hemoglobin_rig(t.path(), path::RIG_EXAMPLE).unwrap_err();
    assert!(matches!(e, LutError::Checksum { .. }), "{e}");
}
