//! The committed `baked/` directory: it verifies (every sha256, every recomputation), its antialiasing
//! textures are byte-identical to the upstream golden files, and every asset bakes to the same bytes with one
//! thread or many.

use rtbake::baked_dir::{verify, FileStatus};
use std::path::{Path, PathBuf};

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn reference_dir() -> Option<PathBuf> {
    crate::support::reference_dir_for("baked/ vs the upstream golden textures")
}

#[test]
fn committed_baked_dir_verifies() {
    let dir = crate_dir().join("baked");
    let report = verify(&dir, &rtbake::bake::registry()).expect("baked/manifest.json readable");
    let bad: Vec<String> = report
        .files
        .iter()
        .filter(|f| f.status != FileStatus::Ok)
        .map(|f| format!("{:?} {} {}", f.status, f.path, f.detail))
        .collect();
    assert!(bad.is_empty(), "baked/ does not verify (re-run scripts/bake.sh):\n{}", bad.join("\n"));
    // Every registered asset is in the committed bake.
    let manifest = rtbake::manifest::Manifest::load(&dir).unwrap();
    for a in rtbake::bake::registry() {
        assert!(manifest.asset_params(a.name).is_some(), "asset {} missing from baked/", a.name);
    }
}

/// (file in baked/, golden file under the reference folder)
const GOLDEN: &[(&str, &str)] = &[
    ("aa/smaa/AreaTex.bin", "smaa/AreaTex_RG8_160x560.bin"),
    ("aa/smaa/SearchTex.bin", "smaa/SearchTex_R8_64x16.bin"),
    ("aa/smaa/AreaTex_v2.8.bin", "smaa/AreaTex_v2.8_RG8_160x560.bin"),
    ("aa/smaa/SearchTex_v2.8.bin", "smaa/SearchTex_v2.8_R8_66x33.bin"),
    ("aa/smaa/SearchTex_logical_precrop.bin", "smaa/SearchTex_logical_precrop_R8_66x33.bin"),
    ("aa/mlaa/AreaMap9_v1.4.bin", "mlaa/AreaMap9_v1.4_RG8_45x45.bin"),
    ("aa/mlaa/AreaMap17_v1.4.bin", "mlaa/AreaMap17_v1.4_RG8_85x85.bin"),
    ("aa/mlaa/AreaMap33_v1.4.bin", "mlaa/AreaMap33_v1.4_RG8_165x165.bin"),
    ("aa/mlaa/AreaMap65_v1.4.bin", "mlaa/AreaMap65_v1.4_RG8_325x325.bin"),
    ("aa/mlaa/AreaMap129_v1.4.bin", "mlaa/AreaMap129_v1.4_RG8_645x645.bin"),
    ("aa/mlaa/AreaMap9_v1.3.bin", "mlaa/AreaMap9_v1.3_RG8_45x45.bin"),
    ("aa/mlaa/AreaMap16_v1.3.bin", "mlaa/AreaMap16_v1.3_RG8_80x80.bin"),
    ("aa/mlaa/AreaMap32_v1.3.bin", "mlaa/AreaMap32_v1.3_RG8_160x160.bin"),
    ("aa/mlaa/AreaTex_MLAAv2.bin", "mlaa/AreaTex_MLAAv2_RG8_75x75.bin"),
];

#[test]
fn baked_aa_textures_equal_the_golden_files() {
    let Some(reference) = reference_dir() else { return };
    let baked = crate_dir().join("baked");
    let sums = std::fs::read_to_string(reference.join("smaa/SHA256SUMS")).unwrap()
        + &std::fs::read_to_string(reference.join("mlaa/SHA256SUMS")).unwrap();
    for (mine, golden) in GOLDEN {
        let ours = std::fs::read(baked.join(mine)).unwrap_or_else(|e| panic!("baked/{mine}: {e}"));
        let theirs = std::fs::read(reference.join(golden)).unwrap();
        let sha = rtbake::manifest::sha256_hex(&ours);
        let name = Path::new(golden).file_name().unwrap().to_string_lossy();
        assert!(sums.contains(&format!("{sha}  {name}")), "baked/{mine} sha256 {sha} not the published one of {name}");
        assert!(ours == theirs, "baked/{mine} differs from {golden}");
        // The DDS/KTX2/PNG siblings carry the same payload.
        let stem = mine.trim_end_matches(".bin");
        let (_, _, _, dds) =
            rtbake::io::dds::decode(&std::fs::read(baked.join(format!("{stem}.dds"))).unwrap(), stem).unwrap();
        assert!(dds == theirs, "baked/{stem}.dds payload differs from {golden}");
        let (_, _, _, ktx, linear) =
            rtbake::io::ktx2::decode(&std::fs::read(baked.join(format!("{stem}.ktx2"))).unwrap(), stem).unwrap();
        assert!(ktx == theirs && linear, "baked/{stem}.ktx2 payload differs from {golden} or is not linear");
        // PNGs of RG textures are RGB with B = 0 (what engines load); R8 textures are gray.
        let channels = if golden.contains("_RG8_") { 2 } else { 1 };
        let png = rtbake::io::png::decode(&std::fs::read(baked.join(format!("{stem}.png"))).unwrap(), stem).unwrap();
        let img =
            png.into_u8_channels(channels).unwrap_or_else(|| panic!("baked/{stem}.png: not 8-bit {channels}-channel"));
        assert!(img.data == theirs, "baked/{stem}.png differs from {golden}");
    }
}

#[test]
fn every_asset_bakes_identically_with_one_thread_or_two() {
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for asset in rtbake::bake::registry() {
        let params = (asset.default_params)();
        let a = one.install(|| (asset.bake)(&params)).unwrap();
        let b = two.install(|| (asset.bake)(&params)).unwrap();
        assert_eq!(a.len(), b.len(), "{}", asset.name);
        for (x, y) in a.iter().zip(&b) {
            assert!(
                x.path == y.path && x.bytes == y.bytes,
                "{}: {} differs between 1 and 2 threads",
                asset.name,
                x.path
            );
        }
    }
}
