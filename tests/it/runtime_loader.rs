//! The LUT loader refuses every LUT that does not match what the pass expects, with a clear error.

use rtbake::bake::{BakedFile, FileMeta};
use rtbake::baked_layout::path;
use rtbake::io::PixelFormat;
use rtbake::manifest::{ColorSpace, FileFormat, FileKind, Manifest, SampleType};
use rtbake::runtime::loader::{self, LutError, LutSpec};
use std::path::Path;

fn meta(pf: PixelFormat, w: u32, h: u32, color_space: ColorSpace) -> FileMeta {
    FileMeta {
        kind: FileKind::Lut,
        format: FileFormat::Raw,
        pixel_format: Some(pf),
        width: w,
        height: h,
        channels: pf.channels(),
        sample_type: SampleType::U8,
        color_space,
        convention: "test".into(),
        verify_tolerance: None,
        supercompression: None,
    }
}

/// Writes a bake dir with an SMAA area texture and search texture, letting `tweak` edit the area's metadata.
fn bake_dir(dir: &Path, tweak: impl FnOnce(&mut BakedFile)) {
    let mut area = BakedFile {
        path: path::SMAA_AREA.into(),
        bytes: (0..160 * 560 * 2).map(|i| (i % 251) as u8).collect(),
        meta: meta(PixelFormat::R8G8Unorm, 160, 560, ColorSpace::Linear),
    };
    let search = BakedFile {
        path: path::SMAA_SEARCH.into(),
        bytes: vec![7u8; 64 * 16],
        meta: meta(PixelFormat::R8Unorm, 64, 16, ColorSpace::Linear),
    };
    tweak(&mut area);
    let mut m = Manifest::new();
    m.set_asset("smaa", serde_json::json!({}), &[area.clone(), search.clone()]);
    for f in [&area, &search] {
        let p = dir.join(&f.path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, &f.bytes).unwrap();
    }
    std::fs::write(dir.join("manifest.json"), m.to_text()).unwrap();
}

#[test]
fn accepts_a_matching_bake() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |_| {});
    let luts = loader::load_smaa_textures(t.path()).unwrap();
    assert_eq!(luts.area.len(), 160 * 560 * 2);
    assert_eq!(luts.search, vec![7u8; 64 * 16]);
}

#[test]
fn refuses_srgb_lut() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |f| f.meta.color_space = ColorSpace::Srgb);
    let e = loader::load_smaa_textures(t.path()).unwrap_err();
    assert!(matches!(e, LutError::ColorSpace { .. }), "{e}");
    assert!(e.to_string().contains("AreaTex.bin") && e.to_string().contains("srgb"), "{e}");
}

#[test]
fn refuses_wrong_size() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |f| {
        f.meta.width = 80;
        f.bytes.truncate(80 * 560 * 2);
    });
    let e = loader::load_smaa_textures(t.path()).unwrap_err();
    assert!(matches!(e, LutError::Mismatch { field: "width x height", .. }), "{e}");
    assert!(e.to_string().contains("160x560") && e.to_string().contains("80x560"), "{e}");
}

#[test]
fn refuses_wrong_pixel_format() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |f| f.meta.pixel_format = Some(PixelFormat::R8G8B8A8Unorm));
    let e = loader::load_smaa_textures(t.path()).unwrap_err();
    assert!(matches!(e, LutError::Mismatch { field: "pixel_format", .. }), "{e}");
}

#[test]
fn refuses_wrong_container() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |f| f.meta.format = FileFormat::Png);
    let e = loader::load_smaa_textures(t.path()).unwrap_err();
    assert!(matches!(e, LutError::Mismatch { field: "format", .. }), "{e}");
}

#[test]
fn refuses_bad_checksum() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |_| {});
    let p = t.path().join(path::SMAA_AREA);
    let mut bytes = std::fs::read(&p).unwrap();
    bytes[1000] ^= 1;
    std::fs::write(&p, bytes).unwrap();
    let e = loader::load_smaa_textures(t.path()).unwrap_err();
    assert!(matches!(e, LutError::Checksum { .. }), "{e}");
    assert!(e.to_string().contains("sha256"), "{e}");
}

#[test]
fn refuses_truncated_file() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |_| {});
    let p = t.path().join(path::SMAA_AREA);
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..bytes.len() - 2]).unwrap();
    let e = loader::load_smaa_textures(t.path()).unwrap_err();
    assert!(matches!(e, LutError::Size { .. }), "{e}");
}

#[test]
fn refuses_missing_entry_and_missing_manifest() {
    let t = tempfile::tempdir().unwrap();
    bake_dir(t.path(), |_| {});
    let e = loader::load_lut(t.path(), &LutSpec::mlaa_area(33)).unwrap_err();
    assert!(matches!(e, LutError::NotInManifest { .. }), "{e}");
    assert!(e.to_string().contains("AreaMap33_v1.4.bin"), "{e}");
    let empty = tempfile::tempdir().unwrap();
    let e = loader::load_smaa_textures(empty.path()).unwrap_err();
    assert!(matches!(e, LutError::Manifest(_)), "{e}");
}

#[test]
fn float_lut_checks_sample_type() {
    let t = tempfile::tempdir().unwrap();
    let spec =
        LutSpec { path: "skin/table.bin".into(), pixel_format: PixelFormat::R16G16B16A16Sfloat, width: 4, height: 2 };
    let mut f = BakedFile {
        path: spec.path.clone(),
        bytes: vec![0u8; 4 * 2 * 8],
        meta: meta(PixelFormat::R16G16B16A16Sfloat, 4, 2, ColorSpace::Linear),
    };
    f.meta.sample_type = SampleType::F16;
    let write = |f: &BakedFile| {
        let mut m = Manifest::new();
        m.set_asset("skin", serde_json::json!({}), std::slice::from_ref(f));
        let p = t.path().join(&f.path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, &f.bytes).unwrap();
        std::fs::write(t.path().join("manifest.json"), m.to_text()).unwrap();
    };
    write(&f);
    assert_eq!(loader::load_lut(t.path(), &spec).unwrap().len(), 64);
    f.meta.sample_type = SampleType::F32;
    write(&f);
    let e = loader::load_lut(t.path(), &spec).unwrap_err();
    assert!(matches!(e, LutError::Mismatch { field: "sample_type", .. }), "{e}");
}
