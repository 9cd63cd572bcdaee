//! Bevy (`bevy_anti_alias` 0.20.1) ships its SMAA LUTs as `SMAAAreaLUT.ktx2` / `SMAASearchLUT.ktx2`, Zstandard-
//! supercompressed at level 15, and loads them with the `ktx2` crate + zstd. rtbake's Bevy-named files must hold
//! the same supercompressed level data byte for byte, the same header and data format descriptor, and decode
//! (ktx2 crate + zstd, Bevy's path) to the `.bin` payloads.

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
