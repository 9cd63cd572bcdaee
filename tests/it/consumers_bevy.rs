//! Bevy (`bevy_anti_alias` 0.20.1) ships its SMAA LUTs as `SMAAAreaLUT.ktx2` / `SMAASearchLUT.ktx2`, Zstandard-
//! supercompressed at level 15, and loads them with the `ktx2` crate + zstd. rtbake's Bevy-named files must hold
//! the same supercompressed level data byte for byte, the same header and data format descriptor, and decode
//! (ktx2 crate + zstd, Bevy's path) to the `.bin` payloads. Every linear data texture Bevy's image loader opens
//! carries a `<file>.meta` with `is_srgb: false`, parsed here with RON into the shape of Bevy's `AssetMeta` /
//! `ImageLoaderSettings` (Bevy 0.20, `bevy_asset::meta`, `bevy_image::image_loader`), as Bevy's asset server does.

use crate::support::{baked_dir, reference_file};

fn baked_file(asset: &str, path: &str) -> Vec<u8> {
    let a = rtbake::bake::registry().into_iter().find(|a| a.name == asset).unwrap();
    let files = (a.bake)(&(a.default_params)()).unwrap();
    files.into_iter().find(|f| f.path == path).unwrap_or_else(|| panic!("{asset} does not bake {path}")).bytes
}

fn check(asset: &str, name: &str, bin: &str) {
    let ours = baked_file(asset, &format!("aa/smaa/{name}"));
    // The committed bake holds the same bytes.
    assert_eq!(std::fs::read(baked_dir().join("aa/smaa").join(name)).unwrap(), ours, "baked/aa/smaa/{name} is stale");
    let r = ktx2::Reader::new(&ours[..]).unwrap();
    assert_eq!(r.header().supercompression_scheme, Some(ktx2::SupercompressionScheme::Zstandard));
    let level = r.levels().next().unwrap();
    // Bevy's decode path: ktx2 level data through zstd.
    let raw = zstd::bulk::decompress(level.data, level.uncompressed_byte_length as usize).unwrap();
    assert_eq!(raw, std::fs::read(baked_dir().join("aa/smaa").join(bin)).unwrap(), "{name}: decoded payload");
    let rel = format!("consumers/bevy_anti_alias-0.20.1/{name}");
    let Some(path) = reference_file(&rel, "Bevy's SMAA KTX2 byte comparison") else { return };
    let bevy = std::fs::read(path).unwrap();
    let b = ktx2::Reader::new(&bevy[..]).unwrap();
    let bl = b.levels().next().unwrap();
    assert!(
        level.data == bl.data,
        "{name}: supercompressed level data differs from Bevy's ({} vs {} bytes)",
        level.data.len(),
        bl.data.len()
    );
    assert_eq!(level.uncompressed_byte_length, bl.uncompressed_byte_length);
    let (h, bh) = (r.header(), b.header());
    assert_eq!(
        (
            h.format,
            h.type_size,
            h.pixel_width,
            h.pixel_height,
            h.pixel_depth,
            h.layer_count,
            h.face_count,
            h.level_count
        ),
        (
            bh.format,
            bh.type_size,
            bh.pixel_width,
            bh.pixel_height,
            bh.pixel_depth,
            bh.layer_count,
            bh.face_count,
            bh.level_count
        ),
        "{name}: header"
    );
    let dfd = |bytes: &[u8]| {
        let off = u32::from_le_bytes(bytes[48..52].try_into().unwrap()) as usize;
        let len = u32::from_le_bytes(bytes[52..56].try_into().unwrap()) as usize;
        bytes[off..off + len].to_vec()
    };
    assert_eq!(dfd(&ours), dfd(&bevy), "{name}: data format descriptor");
    // What the README says: the 80-byte header is Bevy's byte for byte except kvdByteLength (bytes 60..64), since
    // the KTXwriter value names rtbake instead of KTX-Software; the KTXwriterScParams entry is the same.
    let differing: Vec<usize> = (0..80).filter(|&i| ours[i] != bevy[i]).collect();
    assert!(differing.iter().all(|i| (60..64).contains(i)), "{name}: header bytes {differing:?} differ");
    let kvd = |b: &[u8]| {
        let (off, len) =
            (u32::from_le_bytes(b[56..60].try_into().unwrap()), u32::from_le_bytes(b[60..64].try_into().unwrap()));
        b[off as usize..(off + len) as usize].to_vec()
    };
    let sc = b"KTXwriterScParams\0--zstd 15\0";
    assert!(kvd(&ours).windows(sc.len()).any(|w| w == sc) && kvd(&bevy).windows(sc.len()).any(|w| w == sc));
    assert!(kvd(&ours).windows(19).any(|w| w == b"KTXwriter\0rtbake 0."), "{name}: KTXwriter");
    assert_eq!(r.transfer_function(), Some(ktx2::TransferFunction::Linear));
}

#[test]
fn bevy_named_area_lut_matches_bevys_supercompressed_bytes() {
    check("smaa-area", "SMAAAreaLUT.ktx2", "AreaTex.bin");
}

#[test]
fn bevy_named_search_lut_matches_bevys_supercompressed_bytes() {
    check("smaa-search", "SMAASearchLUT.ktx2", "SearchTex.bin");
}

#[test]
fn manifest_describes_the_supercompression() {
    let m = rtbake::manifest::Manifest::load(&baked_dir()).unwrap();
    for name in ["SMAAAreaLUT.ktx2", "SMAASearchLUT.ktx2"] {
        let e = m.entry(&format!("aa/smaa/{name}")).unwrap_or_else(|| panic!("{name} not in the manifest"));
        assert_eq!((e.meta.format.as_str(), e.meta.color_space.as_str()), ("ktx2", "linear"));
        assert_eq!(e.meta.supercompression.as_deref(), Some("zstd-15"));
    }
    assert_eq!(m.entry("aa/smaa/AreaTex.ktx2").unwrap().meta.supercompression, None);
}

#[test]
fn aa_command_writes_zstd_ktx2_with_the_zstd_flag() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let o = crate::support::rtbake(&[
        "aa",
        "smaa-search",
        "--format",
        "ktx2",
        "--zstd",
        "15",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let ours = std::fs::read(out.join("SearchTex.ktx2")).unwrap();
    let bevy_named = baked_file("smaa-search", "aa/smaa/SMAASearchLUT.ktx2");
    let level = |b: &[u8]| ktx2::Reader::new(b).unwrap().levels().next().unwrap().data.to_vec();
    assert_eq!(level(&ours), level(&bevy_named), "same level data as the Bevy-named file");
    let (_, w, h, payload, _) = rtbake::io::ktx2::decode(&ours, "SearchTex.ktx2").unwrap();
    assert_eq!((w, h, payload.len()), (64, 16, 1024));
    // Out of range: exit 2, names the flag, writes nothing.
    let bad = dir.path().join("bad");
    let o = crate::support::rtbake(&["aa", "smaa-search", "--zstd", "23", "--out", bad.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["param"], "--zstd", "{v}");
    assert!(!bad.exists());
}

/// Bevy's `AssetMetaMinimal` (read first, to pick the loader).
#[derive(serde::Deserialize)]
struct AssetMetaMinimal {
    asset: AssetActionMinimal,
}
#[derive(serde::Deserialize)]
enum AssetActionMinimal {
    Load { loader: String },
    Process { processor: String },
    Ignore,
}

/// Bevy's `AssetMeta<ImageLoader, ()>`: the fields and their serde attributes as Bevy declares them.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AssetMeta {
    meta_format_version: String,
    #[serde(default)]
    processed_info: Option<ron::Value>,
    asset: AssetAction,
}
#[derive(serde::Deserialize)]
#[allow(dead_code)] // Bevy's shape; only the Load variant's settings are checked.
enum AssetAction {
    Load { loader: String, settings: ImageLoaderSettings },
    Process { processor: String, settings: ron::Value },
    Ignore,
}
/// Bevy's `ImageLoaderSettings` (no serde default on the struct: `format`, `is_srgb`, `sampler`, `asset_usage`
/// must be present).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ImageLoaderSettings {
    format: ImageFormatSetting,
    #[serde(default)]
    texture_format: Option<ron::Value>,
    is_srgb: bool,
    sampler: ImageSampler,
    asset_usage: RenderAssetUsages,
    #[serde(default)]
    array_layout: Option<ron::Value>,
}
#[derive(serde::Deserialize, PartialEq, Debug)]
enum ImageFormatSetting {
    FromExtension,
    Format(String),
    Guess,
}
#[derive(serde::Deserialize, PartialEq, Debug)]
enum ImageSampler {
    Default,
    Descriptor(ron::Value),
}
/// bitflags' human-readable form: the flag names joined by `|`.
#[derive(serde::Deserialize)]
struct RenderAssetUsages(String);

/// Parses a `.meta` the way Bevy's asset server does and returns its image-loader settings.
fn parse_bevy_meta(text: &[u8]) -> Result<ImageLoaderSettings, String> {
    let minimal: AssetMetaMinimal = ron::de::from_bytes(text).map_err(|e| e.to_string())?;
    match minimal.asset {
        AssetActionMinimal::Load { loader } if loader == "bevy_image::image_loader::ImageLoader" => {}
        AssetActionMinimal::Load { loader } => return Err(format!("loader {loader}")),
        AssetActionMinimal::Process { processor } => return Err(format!("processor {processor}")),
        AssetActionMinimal::Ignore => return Err("Ignore".into()),
    }
    let meta: AssetMeta = ron::de::from_bytes(text).map_err(|e| e.to_string())?;
    if meta.meta_format_version != "1.0" {
        return Err(format!("meta_format_version {}", meta.meta_format_version));
    }
    assert!(meta.processed_info.is_none(), "source assets carry no processed_info");
    match meta.asset {
        AssetAction::Load { settings, .. } => Ok(settings),
        _ => Err("not a Load action".into()),
    }
}

fn check_linear_meta(path: &str, text: &[u8]) {
    let s = parse_bevy_meta(text).unwrap_or_else(|e| panic!("{path}.meta: {e}"));
    assert!(!s.is_srgb, "{path}.meta: is_srgb must be false");
    assert_eq!((s.format, s.sampler), (ImageFormatSetting::FromExtension, ImageSampler::Default), "{path}");
    assert!(s.texture_format.is_none() && s.array_layout.is_none(), "{path}");
    let mut flags: Vec<&str> = s.asset_usage.0.split('|').map(str::trim).collect();
    flags.sort();
    assert_eq!(flags, ["MAIN_WORLD", "RENDER_WORLD"], "{path}: asset_usage");
}

#[test]
fn every_linear_texture_bevy_loads_has_a_meta_with_is_srgb_false() {
    let mut checked = 0;
    for name in ["smaa-area", "smaa-search", "mlaa-v1.3", "transmittance"] {
        let a = rtbake::bake::registry().into_iter().find(|a| a.name == name).unwrap();
        let files = a.run(&(a.default_params)()).unwrap();
        let by_path: std::collections::HashMap<&str, &rtbake::bake::BakedFile> =
            files.iter().map(|f| (f.path.as_str(), f)).collect();
        for f in &files {
            let meta = by_path.get(format!("{}.meta", f.path).as_str());
            let bevy_opens = matches!(f.meta.format.as_str(), "ktx2" | "dds" | "png");
            if bevy_opens && f.meta.color_space.as_str() == "linear" {
                let m = meta.unwrap_or_else(|| panic!("{name}: {} has no .meta", f.path));
                assert_eq!((m.meta.format.as_str(), m.meta.kind.as_str()), ("ron", "bevy-meta"));
                check_linear_meta(&f.path, &m.bytes);
                checked += 1;
            } else {
                // sRGB previews and plots load correctly with Bevy's default; other formats are not images.
                assert!(meta.is_none(), "{name}: {} has a .meta", f.path);
            }
        }
    }
    assert!(checked >= 10, "only {checked} textures checked");
    // Bad input: Bevy refuses a meta without is_srgb or with an unknown field; the parse above is that strict.
    let good = rtbake::io::bevy_meta::linear_image_meta();
    let without = good.replace("            is_srgb: false,\n", "");
    let e = parse_bevy_meta(without.as_bytes()).err().expect("a meta without is_srgb parsed");
    assert!(e.contains("is_srgb"), "{e}");
    let unknown = good.replace("is_srgb: false,", "is_srgb: false, srgb: false,");
    assert!(parse_bevy_meta(unknown.as_bytes()).is_err(), "an unknown field parsed");
}

#[test]
fn every_committed_linear_texture_has_its_bevy_meta() {
    let m = rtbake::manifest::Manifest::load(&baked_dir()).unwrap();
    let mut n = 0;
    for e in &m.files {
        if matches!(e.meta.format.as_str(), "ktx2" | "dds" | "png") && e.meta.color_space.as_str() == "linear" {
            let p = format!("{}.meta", e.path);
            assert!(m.entry(&p).is_some(), "{p} not in the manifest");
            check_linear_meta(&e.path, &std::fs::read(baked_dir().join(&p)).unwrap());
            n += 1;
        }
    }
    assert!(n > 50, "{n}");
}

/// A Bevy user who writes textures with a command instead of `bake` (`aa … --out assets/`, `transmittance --out`,
/// `maps synthetic` → `maps hemoglobin --out`) gets the same `.meta` beside every linear data texture; sRGB previews
/// get none.
#[test]
fn commands_writing_textures_put_the_bevy_meta_beside_each_linear_one() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = |n: &str| tmp.path().join(n);
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let runs: Vec<Vec<String>> = vec![
        vec![
            "aa".into(),
            "smaa-area".into(),
            "--format".into(),
            "ktx2,dds,png".into(),
            "--out".into(),
            s(&dir("area")),
        ],
        vec!["aa".into(), "mlaa-v1.4".into(), "--max-distance".into(), "9".into(), "--out".into(), s(&dir("mlaa"))],
        vec!["transmittance".into(), "--samples".into(), "64".into(), "--out".into(), s(&dir("t"))],
    ];
    let mut metas = 0;
    for args in &runs {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = crate::support::rtbake(&argv);
        assert_eq!(o.status.code(), Some(0), "{argv:?}: {}", String::from_utf8_lossy(&o.stderr));
        let out = std::path::Path::new(args.last().unwrap());
        let mut textures = 0;
        for e in std::fs::read_dir(out).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("").to_string();
            if !matches!(ext.as_str(), "ktx2" | "dds" | "png") {
                continue;
            }
            textures += 1;
            let meta = out.join(format!("{name}.meta"));
            // Previews and plots are sRGB pictures for people; everything else Bevy opens is linear data.
            let srgb_picture = name.contains("preview") || name.contains("plot");
            if srgb_picture {
                assert!(!meta.exists(), "{argv:?}: {name} is an sRGB picture and has a .meta");
            } else {
                let text = std::fs::read(&meta).unwrap_or_else(|_| panic!("{argv:?}: {name} has no .meta"));
                check_linear_meta(&name, &text);
                metas += 1;
            }
        }
        assert!(textures >= 2, "{argv:?}: only {textures} textures written");
    }
    assert!(metas >= 6, "only {metas} .meta files checked");
}
