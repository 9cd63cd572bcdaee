//! Antialiasing textures in `baked/aa/`: SMAA area/search (current and v2.8) and Jimenez MLAA area maps.
//!
//! | asset | parameters (JSON, defaults) | files (each as `.bin`, `.dds`, `.ktx2`, `.png`) |
//! | --- | --- | --- |
//! | `smaa-area` | [`SmaaAreaParams`] (16, 20, 7 + 5 offsets, U smoothing) | `aa/smaa/AreaTex` + `AreaTex.h`, `AreaTex.rs`, `SMAAAreaLUT.ktx2` |
//! | `smaa-area-v2.8` | [`SmaaAreaParams`] with `u_smoothing: false` | `aa/smaa/AreaTex_v2.8` |
//! | `smaa-search` | `{}` | `aa/smaa/SearchTex` + `SearchTex.h`, `SearchTex.rs`, `SMAASearchLUT.ktx2` |
//! | `smaa-search-v2.8` | `{}` | `aa/smaa/SearchTex_v2.8` (0/1/2) and `aa/smaa/SearchTex_logical_precrop` (0/127/254) |
//! | `mlaa-v1.4` | [`MlaaBakeParams`] `{"max_distances": [9, 17, 33, 65, 129]}` | `aa/mlaa/AreaMap{N}_v1.4` |
//! | `mlaa-v1.3` | `{"max_distances": [9, 16, 32]}` | `aa/mlaa/AreaMap{N}_v1.3` |
//! | `mlaa-v2` | `{"max_distances": [15]}` | `aa/mlaa/AreaTex_MLAAv2` (`AreaTex{N}_MLAAv2` for N ≠ 15) |
//!
//! The `.bin` payloads of the defaults are byte-identical to the published textures (`tests/aa_golden.rs`). PNGs of
//! RG textures are RGB with B = 0. `SMAAAreaLUT.ktx2` / `SMAASearchLUT.ktx2` are the same payloads named and stored
//! as Bevy (`bevy_anti_alias`) ships them: KTX2 with Zstandard supercompression at level 15. The same file builders serve `rtbake aa` (variants).

use super::{parse_params, text_file, unorm8_texture_files_in, Asset, BakeError, BakedFile, TextureFormats};
use crate::aa::mlaa_area::{mlaa_area_map_with_progress, MlaaAreaError, MlaaVersion};
use crate::aa::smaa_area::{smaa_area_texture, SmaaAreaError, SmaaAreaParams};
use crate::aa::smaa_search;
use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::io::source::{c_header_u8, rust_source_u8, DataNotice};
use crate::manifest::{FileFormat, FileKind};
use serde::{Deserialize, Serialize};
use serde_json::Value;

pub use crate::baked_layout::path::{self, MLAA_DIR, SMAA_DIR};

impl From<SmaaAreaError> for BakeError {
    fn from(e: SmaaAreaError) -> Self {
        match e {
            SmaaAreaError::Invalid(i) => BakeError::Invalid(i),
        }
    }
}

impl From<MlaaAreaError> for BakeError {
    fn from(e: MlaaAreaError) -> Self {
        match e {
            MlaaAreaError::Invalid(i) => BakeError::Invalid(i),
        }
    }
}

/// Parameters of the MLAA assets: the cell sizes `N` (texels per cell, upstream `NUM_DISTANCES`) to bake.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MlaaBakeParams {
    pub max_distances: Vec<u32>,
}

/// Parameters of the search-texture assets: none (the tables are fixed by the shader's fetch offsets).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

/// Which search table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchKind {
    /// The shipped 64 × 16 texture (127·d, cropped, flipped).
    Current,
    /// The v2.8 66 × 33 table storing d (0/1/2).
    V2_8,
    /// The 66 × 33 table storing 127·d before crop and flip.
    LogicalPrecrop,
}

fn from_line(asset: &str) -> String {
    format!("`rtbake bake {asset}`")
}

/// Convention string of an SMAA area texture with these parameters.
pub fn smaa_area_convention(p: &SmaaAreaParams, width: u32, height: u32) -> String {
    let n = p.ortho_max_distance;
    let m = p.diag_max_distance;
    let ortho = p.ortho_offsets.iter().map(|o| format!("{o}")).collect::<Vec<_>>().join(", ");
    let diag = p.diag_offsets.iter().map(|o| format!("({}, {})", o[0], o[1])).collect::<Vec<_>>().join(", ");
    format!(
        "SMAA area texture {width}x{height} RG8 UNORM, linear (not sRGB), top row first (v = 0 is the first row). \
         Orthogonal half: columns 0..{w_o}, {ko} slices of {s_o} rows (slice k = subsample offset k, offsets [{ortho}] \
         px; SMAA 1x -> 0, S2x/T2x -> 1 and 2, 4x -> 3..6); each slice a 5x5 grid of {n}x{n} cells, cell (e1, e2) at \
         (x, y) = ({n}*e1, {s_o}*k + {n}*e2), e in {{0,1,3,4}} = crossing edges at the left/right end (row and column 2 \
         unused); texel (i, j) = left distance i^2, right distance j^2 px (quadratic). Diagonal half: columns \
         {w_o}..{width}, {kd} slices of {s_d} rows (offsets [{diag}] px), a 4x4 grid of {m}x{m} cells at \
         ({w_o} + {m}*e1, {s_d}*k + {m}*e2), e in 0..3; texel (i, j) = left i, right j px (linear). R = coverage on the \
         negative side of the edge, G = positive side; value floor(255*area). U-shape smoothing {smooth}. Shader \
         constants: SMAA_AREATEX_MAX_DISTANCE {n}, SMAA_AREATEX_MAX_DISTANCE_DIAG {m}, SMAA_AREATEX_PIXEL_SIZE \
         (1.0 / float2({width}.0, {height}.0)), SMAA_AREATEX_SUBTEX_SIZE {subtex}{note}",
        w_o = 5 * n,
        s_o = 5 * n,
        s_d = 4 * m,
        ko = p.ortho_offsets.len(),
        kd = p.diag_offsets.len(),
        subtex = if height.is_multiple_of(5 * n) {
            format!("(1.0 / {}.0)", height / (5 * n))
        } else {
            format!("({}.0 / {height}.0)", 5 * n)
        },
        smooth = if p.u_smoothing { "on (SMAA 2.8+, distance 32)" } else { "off (v2.8 texture)" },
        note = if 5 * n == 4 * m {
            ""
        } else {
            "; NOTE: 5*ortho != 4*diag, the stock shader (diagonal half at texcoord.x + 0.5) needs adapting"
        },
    )
}

/// Files of an SMAA area texture under `stem` (`stem.bin`, …) in `formats`; the upstream-compatible C header is
/// `stem.h` (`AREATEX_*`, `areaTexBytes`), the Rust source `stem.rs` (`AREATEX_*`, `AREATEX_BYTES`).
pub fn smaa_area_files(
    stem: &str,
    params: &SmaaAreaParams,
    formats: TextureFormats,
    from: &str,
) -> Result<Vec<BakedFile>, BakeError> {
    let img = smaa_area_texture(params)?;
    let convention = smaa_area_convention(params, img.width, img.height);
    texture_with_sources(stem, &img, &convention, formats, ("AREATEX", "areaTexBytes"), from)
}

/// Convention string of a search table.
pub fn search_convention(kind: SearchKind) -> String {
    let logical = "logical 66x33 table: x = 32*R of the bilinear edges fetch at offset (-0.25, -0.125) (left search \
                   x in 0..32, right search x + 33), y = 32*G; R/G = (1*e0 + 3*e1 + 7*e2 + 21*e3)/32 of the four edge \
                   bits; d = extra pixels (0..2) for the last search step";
    match kind {
        SearchKind::Current => format!(
            "SMAA search texture 64x16 R8 UNORM, linear (not sRGB), top row first: {logical}; stored 127*d, rows \
             17..32 and columns 0..63 of the table flipped vertically (row r = logical row 32 - r). Shader constants: \
             SMAA_SEARCHTEX_SIZE float2(66.0, 33.0), SMAA_SEARCHTEX_PACKED_SIZE float2(64.0, 16.0); the shader \
             scales the fetched value by 255/127"
        ),
        SearchKind::V2_8 => {
            format!("SMAA v2.8 search table 66x33 R8 UNORM, linear, top row first, uncropped and unflipped: {logical}; stored d")
        }
        SearchKind::LogicalPrecrop => format!(
            "SMAA search table 66x33 R8 UNORM, linear, top row first, before crop and flip (debugging): {logical}; \
             stored 127*d"
        ),
    }
}

/// Files of a search table under `stem` in `formats`; the sources are `stem.h` (`SEARCHTEX_*`, `searchTexBytes`)
/// and `stem.rs` (`SEARCHTEX_*`, `SEARCHTEX_BYTES`).
pub fn search_files(
    kind: SearchKind,
    stem: &str,
    formats: TextureFormats,
    from: &str,
) -> Result<Vec<BakedFile>, BakeError> {
    let img = match kind {
        SearchKind::Current => smaa_search::search_texture(),
        SearchKind::V2_8 => smaa_search::search_texture_v2_8(),
        SearchKind::LogicalPrecrop => smaa_search::search_texture_logical_precrop(),
    };
    texture_with_sources(stem, &img, &search_convention(kind), formats, ("SEARCHTEX", "searchTexBytes"), from)
}

/// Convention string of an MLAA area map.
pub fn mlaa_convention(version: MlaaVersion, n: u32) -> String {
    let (dist, plus) = match version {
        MlaaVersion::V2 => ("quadratic: texel i <-> distance i^2 px (look up with sqrt(distance))", "v1.4 \"+\" rule"),
        MlaaVersion::V1_4 => {
            ("linear 0..N-1 px", "a \"+\" end (4) counts only against a single crossing edge, as its opposite")
        }
        MlaaVersion::V1_3 => ("linear 0..N-1 px", "a \"+\" end (4) adds its half to both R and G"),
    };
    format!(
        "Jimenez MLAA {label} area map {s}x{s} RG8 UNORM, linear (not sRGB), top row first: 5x5 grid of {n}x{n} cells, \
         cell (e1, e2) at ({n}*e1, {n}*e2), e1/e2 = crossing edges at the left/right end in {{0,1,3,4}} (row and column \
         2 unused); texel (x, y) in a cell = (left, right) distance, {dist}; R = area for crossing edge type 3, G = \
         type 1; each half stored floor(255*area) and the halves added; {plus}. Shader: NUM_DISTANCES {n}, AREA_SIZE \
         {s}, point sample at (N*round(4*e) + distance) / (AREA_SIZE - 1)",
        label = version.label(),
        s = 5 * n,
    )
}

/// Default file stem (without folder) of an MLAA map ([`crate::baked_layout::path::mlaa_area_name`]).
pub use crate::baked_layout::path::mlaa_area_name as mlaa_stem;

/// Files of an MLAA area map under `stem` in `formats`; the sources are `stem.h` (`AREAMAP_*`, `areaMapBytes`)
/// and `stem.rs` (`AREAMAP_*`, `AREAMAP_BYTES`).
pub fn mlaa_files(
    version: MlaaVersion,
    n: u32,
    stem: &str,
    formats: TextureFormats,
    from: &str,
) -> Result<Vec<BakedFile>, BakeError> {
    mlaa_files_with_progress(version, n, stem, formats, from, &|_, _| {})
}

/// [`mlaa_files`], reporting the map's rows as they are computed (`progress(rows_done, rows)`).
pub fn mlaa_files_with_progress(
    version: MlaaVersion,
    n: u32,
    stem: &str,
    formats: TextureFormats,
    from: &str,
    progress: &dyn Fn(u32, u32),
) -> Result<Vec<BakedFile>, BakeError> {
    let img = mlaa_area_map_with_progress(version, n, progress)?;
    let convention = mlaa_convention(version, n);
    // Every other format first, then the map itself moves into the `.bin` (no copy of up to 52 MB).
    let others = TextureFormats { bin: false, ..formats };
    let mut files = texture_with_sources(stem, &img, &convention, others, ("AREAMAP", "areaMapBytes"), from)?;
    if formats.bin {
        files.insert(0, crate::bake::unorm8_bin_file(stem, img, FileKind::Lut, &convention));
    }
    Ok(files)
}

/// The KTX2 file Bevy embeds for this texture: same payload, Zstandard level 15 ([`crate::io::ktx2::BEVY_ZSTD_LEVEL`]).
pub fn bevy_zstd_file(path: &str, img: &Image<u8>, convention: &str) -> Result<BakedFile, BakeError> {
    use crate::io::{self, ktx2::Supercompression};
    let sc = Supercompression::Zstd(io::ktx2::BEVY_ZSTD_LEVEL);
    let mut meta = super::unorm8_meta(img, FileKind::Lut, convention, FileFormat::Ktx2);
    meta.convention = format!("{convention}; named and supercompressed as Bevy's bevy_anti_alias ships it");
    meta.supercompression = Some(sc.label());
    Ok(BakedFile { path: path.into(), bytes: io::ktx2::encode_u8_with(img, sc)?, meta })
}

fn texture_with_sources(
    stem: &str,
    img: &Image<u8>,
    convention: &str,
    formats: TextureFormats,
    (prefix, array): (&str, &str),
    from: &str,
) -> Result<Vec<BakedFile>, BakeError> {
    let mut files = unorm8_texture_files_in(stem, img, FileKind::Lut, convention, formats)?;
    let note = format!("{convention}; generated source, bytes identical to {stem}.bin");
    let notice = if prefix == "AREAMAP" { DataNotice::Mlaa } else { DataNotice::Smaa };
    if formats.c_header {
        let header = c_header_u8(prefix, array, img, from, notice);
        files.push(text_file(&format!("{stem}.h"), header, FileKind::CHeader, FileFormat::C, &note));
    }
    if formats.rust_source {
        let rust = rust_source_u8(prefix, img, from, notice);
        files.push(text_file(&format!("{stem}.rs"), rust, FileKind::RustSource, FileFormat::Rust, &note));
    }
    Ok(files)
}

fn json<T: Serialize>(v: T) -> Value {
    serde_json::to_value(v).expect("parameters serialise")
}

fn mlaa_defaults(version: MlaaVersion) -> Value {
    json(MlaaBakeParams { max_distances: version.published().to_vec() })
}

fn bake_mlaa(asset: &str, version: MlaaVersion, params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: MlaaBakeParams = parse_params(asset, params)?;
    if p.max_distances.is_empty() {
        return Err(InvalidInput::new("max_distances", "must list at least one cell size").into());
    }
    for (i, &n) in p.max_distances.iter().enumerate() {
        let field = format!("max_distances[{i}]");
        crate::aa::mlaa_area::validate(version, n).map_err(|e| InvalidInput::new(&field, e.message))?;
        if p.max_distances[..i].contains(&n) {
            return Err(InvalidInput::new(field, format!("repeats cell size {n}")).into());
        }
    }
    let mut files = Vec::new();
    for &n in &p.max_distances {
        let stem = path::mlaa_area_stem(version, n);
        files.extend(mlaa_files(version, n, &stem, TextureFormats::BINARY, &from_line(asset))?);
    }
    Ok(files)
}

pub fn assets() -> Vec<Asset> {
    vec![
        Asset {
            time_estimate: None,
            name: "smaa-area",
            summary: "SMAA area texture 160x560 RG8 (SMAA 2.8+, U-shape smoothing) + AreaTex.h / AreaTex.rs",
            default_params: || json(SmaaAreaParams::default()),
            bake: |v| {
                let p: SmaaAreaParams = parse_params("smaa-area", v)?;
                let img = smaa_area_texture(&p)?;
                let convention = smaa_area_convention(&p, img.width, img.height);
                let stem = path::SMAA_AREA_STEM;
                let names = ("AREATEX", "areaTexBytes");
                let from = from_line("smaa-area");
                let mut files = texture_with_sources(stem, &img, &convention, TextureFormats::ALL, names, &from)?;
                files.push(bevy_zstd_file(path::SMAA_AREA_BEVY, &img, &convention)?);
                Ok(files)
            },
        },
        Asset {
            time_estimate: None,
            name: "smaa-area-v2.8",
            summary: "SMAA area texture 160x560 RG8 as in v2.8 (no U-shape smoothing)",
            default_params: || json(SmaaAreaParams::v2_8()),
            bake: |v| {
                let p: SmaaAreaParams = parse_params("smaa-area-v2.8", v)?;
                smaa_area_files(path::SMAA_AREA_V2_8_STEM, &p, TextureFormats::BINARY, &from_line("smaa-area-v2.8"))
            },
        },
        Asset {
            time_estimate: None,
            name: "smaa-search",
            summary: "SMAA search texture 64x16 R8 + SearchTex.h / SearchTex.rs",
            default_params: || json(NoParams {}),
            bake: |v| {
                let _: NoParams = parse_params("smaa-search", v)?;
                let mut files = search_files(
                    SearchKind::Current,
                    path::SMAA_SEARCH_STEM,
                    TextureFormats::ALL,
                    &from_line("smaa-search"),
                )?;
                let convention = search_convention(SearchKind::Current);
                files.push(bevy_zstd_file(path::SMAA_SEARCH_BEVY, &smaa_search::search_texture(), &convention)?);
                Ok(files)
            },
        },
        Asset {
            time_estimate: None,
            name: "smaa-search-v2.8",
            summary: "SMAA v2.8 search table 66x33 (0/1/2) and the logical pre-crop table (0/127/254)",
            default_params: || json(NoParams {}),
            bake: |v| {
                let _: NoParams = parse_params("smaa-search-v2.8", v)?;
                let from = from_line("smaa-search-v2.8");
                let mut f = search_files(SearchKind::V2_8, path::SMAA_SEARCH_V2_8_STEM, TextureFormats::BINARY, &from)?;
                f.extend(search_files(
                    SearchKind::LogicalPrecrop,
                    path::SMAA_SEARCH_PRECROP_STEM,
                    TextureFormats::BINARY,
                    &from,
                )?);
                Ok(f)
            },
        },
        Asset {
            time_estimate: None,
            name: "mlaa-v1.4",
            summary: "Jimenez MLAA v1.4+ area maps AreaMap{9,17,33,65,129} (5N x 5N RG8)",
            default_params: || mlaa_defaults(MlaaVersion::V1_4),
            bake: |v| bake_mlaa("mlaa-v1.4", MlaaVersion::V1_4, v),
        },
        Asset {
            time_estimate: None,
            name: "mlaa-v1.3",
            summary: "Jimenez MLAA v1.3 area maps AreaMap{9,16,32} (5N x 5N RG8)",
            default_params: || mlaa_defaults(MlaaVersion::V1_3),
            bake: |v| bake_mlaa("mlaa-v1.3", MlaaVersion::V1_3, v),
        },
        Asset {
            time_estimate: None,
            name: "mlaa-v2",
            summary: "MLAA 2.0 area texture 75x75 RG8 (15x15 cells, quadratic distances)",
            default_params: || mlaa_defaults(MlaaVersion::V2),
            bake: |v| bake_mlaa("mlaa-v2", MlaaVersion::V2, v),
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifest::ColorSpace;

    #[test]
    fn every_asset_bakes_its_defaults_under_aa_and_params_round_trip() {
        for a in assets() {
            let params = (a.default_params)();
            let text = serde_json::to_string(&params).unwrap();
            let back: Value = serde_json::from_str(&text).unwrap();
            let files = (a.bake)(&back).unwrap_or_else(|e| panic!("{}: {e}", a.name));
            assert!(!files.is_empty());
            for f in &files {
                assert!(f.path.starts_with("aa/smaa/") || f.path.starts_with("aa/mlaa/"), "{}", f.path);
                assert!(matches!(f.meta.color_space, ColorSpace::Linear | ColorSpace::NotApplicable));
            }
            assert_eq!((a.bake)(&back).unwrap(), files, "{}: deterministic", a.name);
        }
    }

    #[test]
    fn bad_params_are_invalid_input() {
        let a = assets().into_iter().find(|a| a.name == "mlaa-v1.4").unwrap();
        let e = (a.bake)(&serde_json::json!({"max_distances": [16]})).unwrap_err();
        assert!(matches!(e, BakeError::Invalid(_)) && e.to_string().contains("odd"), "{e}");
        assert!(e.to_string().starts_with("max_distances[0]"), "{e}");
        let e = (a.bake)(&serde_json::json!({"max_distances": [9, 9]})).unwrap_err();
        assert!(e.to_string().contains("repeats"), "{e}");
        let a = assets().into_iter().find(|a| a.name == "smaa-area").unwrap();
        let mut p = json(SmaaAreaParams::default());
        p["ortho_offsets"] = serde_json::json!([0.0, 0.7]);
        assert!(matches!((a.bake)(&p).unwrap_err(), BakeError::Invalid(_)));
        assert!(matches!((a.bake)(&serde_json::json!({"bogus": 1})).unwrap_err(), BakeError::Invalid(_)));
    }

    #[test]
    fn smaa_headers_use_upstream_names() {
        let f = search_files(SearchKind::Current, "SearchTex", TextureFormats::ALL, "test").unwrap();
        let h = std::str::from_utf8(&f.iter().find(|f| f.path == "SearchTex.h").unwrap().bytes).unwrap().to_string();
        assert!(h.contains("#define SEARCHTEX_WIDTH 64") && h.contains("#define SEARCHTEX_HEIGHT 16"));
        assert!(h.contains("static const unsigned char searchTexBytes[]"));
        let rs = std::str::from_utf8(&f.iter().find(|f| f.path == "SearchTex.rs").unwrap().bytes).unwrap().to_string();
        assert!(rs.contains("pub static SEARCHTEX_BYTES: [u8; SEARCHTEX_SIZE]"));
        let conv = smaa_area_convention(&SmaaAreaParams::default(), 160, 560);
        assert!(conv.contains("SMAA_AREATEX_MAX_DISTANCE 16") && conv.contains("SMAA_AREATEX_MAX_DISTANCE_DIAG 20"));
        assert!(conv.contains("SMAA_AREATEX_SUBTEX_SIZE (1.0 / 7.0)") && !conv.contains("NOTE"));
    }

    #[test]
    fn containers_hold_the_raw_bytes_as_linear_unorm() {
        use crate::io::{self, PixelFormat};
        let mut files = search_files(SearchKind::Current, "s", TextureFormats::BINARY, "test").unwrap();
        files.extend(mlaa_files(MlaaVersion::V1_4, 9, "m", TextureFormats::BINARY, "test").unwrap());
        for stem in ["s", "m"] {
            let get = |ext: &str| files.iter().find(|f| f.path == format!("{stem}.{ext}")).unwrap();
            let raw = &get("bin").bytes;
            let (pf, w, h, dds) = io::dds::decode(&get("dds").bytes, "dds").unwrap();
            let want_pf = if stem == "s" { PixelFormat::R8Unorm } else { PixelFormat::R8G8Unorm };
            assert_eq!(pf, want_pf);
            assert_eq!((w as usize * h as usize * pf.channels() as usize, &dds), (raw.len(), raw));
            let (vk, _, _, ktx, linear) = io::ktx2::decode(&get("ktx2").bytes, "ktx2").unwrap();
            assert_eq!(vk, io::ktx2::vk_format(want_pf));
            assert!(linear, "KTX2 transfer function must be linear, not sRGB");
            assert_eq!(&ktx, raw);
            let png = io::png::decode(&get("png").bytes, "png").unwrap();
            assert_eq!(&png.into_u8_channels(want_pf.channels()).expect("8-bit PNG").data, raw);
        }
    }
}
