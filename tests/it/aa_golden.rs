//! Conformance: every SMAA / MLAA texture regenerated with default parameters is byte-identical to the published
//! payload in `$RTBAKE_REFERENCE_DIR` (default `../shared/reference` beside the crate), checked both against the
//! folder's `SHA256SUMS` and against the file bytes. A missing reference folder is reported; with
//! `RTBAKE_REQUIRE_REFERENCE=1` it is a failure.

use rtbake::aa::mlaa_area::{mlaa_area_map, MlaaVersion};
use rtbake::aa::smaa_area::{smaa_area_texture, SmaaAreaParams};
use rtbake::aa::smaa_search;
use rtbake::image_buf::Image;
use sha2::{Digest, Sha256};
use std::collections::HashMap;
use std::path::PathBuf;

fn reference_dir() -> Option<PathBuf> {
    crate::support::reference_dir_for("golden SMAA/MLAA byte comparison")
}

fn sums(dir: &std::path::Path) -> HashMap<String, String> {
    let text = std::fs::read_to_string(dir.join("SHA256SUMS")).expect("SHA256SUMS readable");
    text.lines()
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            Some((it.next()?.to_string(), it.next()?.trim_start_matches('*').to_string()))
        })
        .map(|(h, f)| (f, h))
        .collect()
}

fn hex_sha256(b: &[u8]) -> String {
    Sha256::digest(b).iter().map(|x| format!("{x:02x}")).collect()
}

/// Compares `img` with `folder/name` (hash from SHA256SUMS and bytes); panics with the first differences.
fn check(dir: &std::path::Path, folder: &str, name: &str, img: &Image<u8>) {
    let d = dir.join(folder);
    let want_hash = sums(&d).get(name).cloned().unwrap_or_else(|| panic!("{name} not listed in {folder}/SHA256SUMS"));
    let want = std::fs::read(d.join(name)).unwrap_or_else(|e| panic!("{folder}/{name}: {e}"));
    assert_eq!(hex_sha256(&want), want_hash, "{folder}/{name} does not match its SHA256SUMS entry");
    let got_hash = hex_sha256(&img.data);
    if got_hash == want_hash && img.data == want {
        return;
    }
    let c = img.channels as usize;
    let w = img.width as usize;
    let mut diffs = Vec::new();
    for (i, (g, r)) in img.data.iter().zip(&want).enumerate() {
        if g != r {
            diffs.push((i / c % w, i / c / w, i % c, *g, *r));
        }
    }
    let first: Vec<String> =
        diffs.iter().take(8).map(|(x, y, ch, g, r)| format!("(x {x}, y {y}, ch {ch}: got {g}, want {r})")).collect();
    panic!(
        "{folder}/{name}: sha256 {got_hash} != {want_hash}; {} bytes generated vs {} expected; {} differing bytes; first: {}",
        img.data.len(),
        want.len(),
        diffs.len(),
        first.join(", ")
    );
}

#[test]
fn smaa_area_texture_matches_reference() {
    let Some(dir) = reference_dir() else { return };
    let img = smaa_area_texture(&SmaaAreaParams::default()).unwrap();
    check(&dir, "smaa", "AreaTex_RG8_160x560.bin", &img);
}

#[test]
fn smaa_area_texture_v2_8_matches_reference() {
    let Some(dir) = reference_dir() else { return };
    let img = smaa_area_texture(&SmaaAreaParams::v2_8()).unwrap();
    check(&dir, "smaa", "AreaTex_v2.8_RG8_160x560.bin", &img);
}

#[test]
fn smaa_search_textures_match_reference() {
    let Some(dir) = reference_dir() else { return };
    check(&dir, "smaa", "SearchTex_R8_64x16.bin", &smaa_search::search_texture());
    check(&dir, "smaa", "SearchTex_v2.8_R8_66x33.bin", &smaa_search::search_texture_v2_8());
    check(&dir, "smaa", "SearchTex_logical_precrop_R8_66x33.bin", &smaa_search::search_texture_logical_precrop());
}

#[test]
fn mlaa_area_maps_match_reference() {
    let Some(dir) = reference_dir() else { return };
    for (version, label) in [(MlaaVersion::V1_4, "v1.4"), (MlaaVersion::V1_3, "v1.3")] {
        for &n in version.published() {
            let img = mlaa_area_map(version, n).unwrap();
            check(&dir, "mlaa", &format!("AreaMap{n}_{label}_RG8_{0}x{0}.bin", 5 * n), &img);
        }
    }
    let img = mlaa_area_map(MlaaVersion::V2, 15).unwrap();
    check(&dir, "mlaa", "AreaTex_MLAAv2_RG8_75x75.bin", &img);
}

#[test]
fn smaa_area_texture_is_the_same_on_one_thread() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let one = pool.install(|| smaa_area_texture(&SmaaAreaParams::default()).unwrap());
    let many = smaa_area_texture(&SmaaAreaParams::default()).unwrap();
    assert_eq!(one, many);
}

/// The spec: the v2.8 texture differs from the current one in 408 texels, all in the orthogonal U cells (1,1) and
/// (3,3) of subsample slices with short lines (U smoothing only acts for d < 32).
#[test]
fn u_smoothing_changes_only_short_u_cells() {
    let cur = smaa_area_texture(&SmaaAreaParams::default()).unwrap();
    let old = smaa_area_texture(&SmaaAreaParams::v2_8()).unwrap();
    let mut texels = 0;
    for y in 0..cur.height {
        for x in 0..cur.width {
            if (0..2).any(|c| cur.get(x, y, c) != old.get(x, y, c)) {
                texels += 1;
                let cell = (x / 16, (y % 80) / 16);
                assert!(x < 80 && (cell == (1, 1) || cell == (3, 3)), "texel ({x},{y}) outside the U cells");
                let (left, right) = ((x % 16).pow(2), (y % 16).pow(2));
                assert!(left + right + 1 < 32, "texel ({x},{y}) has d >= 32");
            }
        }
    }
    assert_eq!(texels, 408);
}

/// Every `.bin` the registered `aa` assets bake with their default parameters is a published payload.
#[test]
fn baked_assets_match_reference() {
    let Some(dir) = reference_dir() else { return };
    let map = [
        ("aa/smaa/AreaTex.bin", "smaa/AreaTex_RG8_160x560.bin"),
        ("aa/smaa/AreaTex_v2.8.bin", "smaa/AreaTex_v2.8_RG8_160x560.bin"),
        ("aa/smaa/SearchTex.bin", "smaa/SearchTex_R8_64x16.bin"),
        ("aa/smaa/SearchTex_v2.8.bin", "smaa/SearchTex_v2.8_R8_66x33.bin"),
        ("aa/smaa/SearchTex_logical_precrop.bin", "smaa/SearchTex_logical_precrop_R8_66x33.bin"),
        ("aa/mlaa/AreaTex_MLAAv2.bin", "mlaa/AreaTex_MLAAv2_RG8_75x75.bin"),
    ];
    let mut expected: HashMap<String, String> = map.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect();
    for (v, ns) in [("v1.4", &[9, 17, 33, 65, 129][..]), ("v1.3", &[9, 16, 32][..])] {
        for n in ns {
            expected
                .insert(format!("aa/mlaa/AreaMap{n}_{v}.bin"), format!("mlaa/AreaMap{n}_{v}_RG8_{0}x{0}.bin", 5 * n));
        }
    }
    let mut seen = 0;
    for asset in
        rtbake::bake::registry().into_iter().filter(|a| a.name.starts_with("smaa-") || a.name.starts_with("mlaa-"))
    {
        for f in (asset.bake)(&(asset.default_params)()).unwrap() {
            if !f.path.ends_with(".bin") {
                continue;
            }
            let reference =
                expected.get(&f.path).unwrap_or_else(|| panic!("{}: unexpected .bin {}", asset.name, f.path));
            let (folder, name) = reference.split_once('/').unwrap();
            assert_eq!(Some(&hex_sha256(&f.bytes)), sums(&dir.join(folder)).get(name), "{} vs {reference}", f.path);
            seen += 1;
        }
    }
    assert_eq!(seen, expected.len(), "every published texture is baked");
}
