//! The bake registry: every asset rtbake can write into `baked/`, with the files it produces.
//!
//! An [`Asset`] is a pure function from its JSON parameters to a list of [`BakedFile`]s (bytes + metadata);
//! it never touches the file system. `crate::manifest` writes them atomically and records them, and
//! `verify` re-runs the same function from the manifest's parameters and compares.
//!
//! Each area registers its assets in its own file (`aa.rs`, `sss.rs`, …) through an `assets()` function
//! collected by [`registry`].

use crate::image_buf::Image;
use crate::io::{self, exr::ExrPrecision, PixelFormat};
use serde_json::Value;

pub use crate::manifest::{BakedFile, ColorSpace, FileFormat, FileKind, FileMeta, SampleType};

/// Errors while baking an asset.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    #[error("{0}")]
    Invalid(#[from] crate::error::InvalidInput),
    #[error(transparent)]
    Io(#[from] io::IoError),
    #[error("{0}")]
    Other(String),
}

/// Parameters and threads → upper estimate of an asset's bake time, seconds ([`Asset::time_estimate`]).
pub type TimeEstimate = fn(&Value, usize) -> Result<f64, BakeError>;

/// A bakeable asset.
pub struct Asset {
    /// Name used on the command line (`rtbake bake NAME`) and in the manifest.
    pub name: &'static str,
    pub summary: &'static str,
    /// Parameters of the default bake (embedded defaults).
    pub default_params: fn() -> Value,
    /// Pure function: parameters → files. Must be deterministic for any thread count.
    pub bake: fn(&Value) -> Result<Vec<BakedFile>, BakeError>,
    /// Upper estimate of the wall time of [`Asset::bake`] on a number of threads, seconds, from the same
    /// parameters (validated the same way, so a bad parameter is named here first). Given for every asset whose
    /// parameters can make it run for minutes or more (Monte Carlo photon counts, table sizes); `rtbake bake`
    /// refuses a bake over its time budget (`--max-seconds`) before any work. `None`: the asset's accepted
    /// parameter ranges keep it to seconds.
    pub time_estimate: Option<TimeEstimate>,
}

/// The parameter key every asset accepts beside its own: `"ktx2_zstd": LEVEL` (1..=22) rewrites the asset's
/// uncompressed KTX2 files with Zstandard supercompression at that level ([`supercompress_ktx2`]). It is recorded
/// in the manifest with the other parameters, so `verify` recomputes the compressed bytes. `rtbake bake --zstd`
/// sets it for every asset it bakes.
pub const KTX2_ZSTD_PARAM: &str = "ktx2_zstd";

impl Asset {
    /// Runs the asset on `params`: strips and applies the common [`KTX2_ZSTD_PARAM`] key, then calls the asset's
    /// own [`Asset::bake`] with the rest. The bake directory and `verify` call this, never `bake` directly.
    pub fn run(&self, params: &Value) -> Result<Vec<BakedFile>, BakeError> {
        let (level, own) = split_zstd_param(self.name, params)?;
        let mut files = (self.bake)(&own)?;
        if let Some(level) = level {
            supercompress_ktx2(&mut files, level)?;
        }
        add_bevy_meta_files(&mut files);
        Ok(files)
    }

    /// [`Asset::time_estimate`] of `params` on `threads` threads (the common [`KTX2_ZSTD_PARAM`] key stripped as
    /// [`Asset::run`] does); 0 for an asset without one.
    pub fn time_estimate_seconds(&self, params: &Value, threads: usize) -> Result<f64, BakeError> {
        let (_, own) = split_zstd_param(self.name, params)?;
        match self.time_estimate {
            Some(estimate) => estimate(&own, threads.max(1)),
            None => Ok(0.0),
        }
    }
}

/// Adds a Bevy `<file>.meta` (`is_srgb: false`, [`io::bevy_meta`]) beside every linear data texture Bevy's image
/// loader opens, so a Bevy app loads the file as linear data without loading code of its own.
pub fn add_bevy_meta_files(files: &mut Vec<BakedFile>) {
    let metas = bevy_meta_files(files);
    files.extend(metas);
}

/// The Bevy `<file>.meta` files a set of baked files needs ([`add_bevy_meta_files`]), leaving out those the set
/// already holds: every command that writes textures (`bake`, `aa --out`, `maps … --out`, …) writes the same ones.
pub fn bevy_meta_files(files: &[BakedFile]) -> Vec<BakedFile> {
    let present: std::collections::HashSet<&str> = files.iter().map(|f| f.path.as_str()).collect();
    files
        .iter()
        .filter(|f| io::bevy_meta::wants_meta(f.meta.format.as_str(), f.meta.color_space.as_str()))
        .map(|f| io::bevy_meta::meta_path(&f.path))
        .filter(|meta| !present.contains(meta.as_str()))
        .map(|meta| {
            text_file(
                &meta,
                io::bevy_meta::linear_image_meta(),
                FileKind::BevyMeta,
                FileFormat::Ron,
                "Bevy asset settings for the texture of the same name (ImageLoader, is_srgb: false: linear data)",
            )
        })
        .collect()
}

/// One physiological skin point of an asset's parameters (the two-layer skin's concentrations).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SkinPoint {
    /// Cm, 0..=0.5.
    pub(crate) melanin_fraction: f64,
    /// Chd, 0..=0.32.
    pub(crate) hemoglobin_fraction: f64,
}

pub(crate) use crate::diffusion::source::jensen_material;

/// Splits the common `ktx2_zstd` key off an asset's parameters (validated: an integer level 1..=22).
fn split_zstd_param(asset: &str, params: &Value) -> Result<(Option<i32>, Value), BakeError> {
    let Some(obj) = params.as_object() else { return Ok((None, params.clone())) };
    let Some(v) = obj.get(KTX2_ZSTD_PARAM) else { return Ok((None, params.clone())) };
    let param = format!("{asset} parameter {KTX2_ZSTD_PARAM}");
    let level = match v.as_i64() {
        Some(l) if (1..=22).contains(&l) => l as i32,
        _ => {
            return Err(crate::error::InvalidInput::new(
                param,
                format!("expected an integer Zstandard level in 1..=22, got {v}"),
            )
            .into())
        }
    };
    let mut own = obj.clone();
    own.remove(KTX2_ZSTD_PARAM);
    Ok((Some(level), Value::Object(own)))
}

/// Every registered asset, in bake order.
pub fn registry() -> Vec<Asset> {
    let mut v = Vec::new();
    v.extend(aa::assets());
    v.extend(gaussians::assets());
    v.extend(transmittance::assets());
    v.extend(separable::assets());
    v.extend(importance::assets());
    v.extend(skin::assets());
    v.extend(facial::assets());
    v.extend(profiles::assets());
    v.extend(transport::assets());
    v.extend(burley::assets());
    v
}

pub mod aa;
pub mod burley;
pub mod facial;
pub mod gaussians;
pub mod importance;
pub mod profiles;
pub mod separable;
pub mod skin;
pub mod transmittance;
pub mod transport;
pub mod wrinkle_maps;

/// Writes an 8-bit UNORM texture as raw `.bin`, DDS (DX10 `{stem}.dds` and legacy-header `{stem}_dx9.dds`), KTX2
/// and PNG (`{stem}.bin`, …). `convention` describes the
/// layout for the manifest. PNG of RG data is RGB with B = 0 (what engines and browsers load as R, G), tagged linear.
pub fn unorm8_texture_files(
    stem: &str,
    img: &Image<u8>,
    kind: FileKind,
    convention: &str,
) -> Result<Vec<BakedFile>, BakeError> {
    unorm8_texture_files_in(stem, img, kind, convention, TextureFormats::BINARY)
}

/// Which files of a texture to encode: the bake writes them all, `rtbake aa --format` only those asked for
/// (encoding dominates the cost of large tables: the hex sources are ~6 bytes per texel byte, PNG compression
/// the rest).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureFormats {
    pub bin: bool,
    pub dds: bool,
    pub ktx2: bool,
    pub png: bool,
    /// C header (`stem.h`), for textures that have one.
    pub c_header: bool,
    /// Rust source (`stem.rs`), for textures that have one.
    pub rust_source: bool,
}

impl TextureFormats {
    /// The four binary containers (bin, DDS, KTX2, PNG).
    pub const BINARY: Self = Self { bin: true, dds: true, ktx2: true, png: true, c_header: false, rust_source: false };
    /// The binary containers and the C/Rust sources.
    pub const ALL: Self = Self { c_header: true, rust_source: true, ..Self::BINARY };
    /// Nothing (start of a selection).
    pub const NONE: Self =
        Self { bin: false, dds: false, ktx2: false, png: false, c_header: false, rust_source: false };
}

/// The manifest metadata of an 8-bit UNORM texture file in `format` (`raw`, `dds`, `ktx2`, `png`).
fn unorm8_meta(img: &Image<u8>, kind: FileKind, convention: &str, format: FileFormat) -> FileMeta {
    let mut meta = FileMeta {
        kind,
        format,
        pixel_format: PixelFormat::unorm8_for(img.channels),
        width: img.width,
        height: img.height,
        channels: img.channels,
        sample_type: SampleType::U8,
        color_space: ColorSpace::Linear,
        convention: convention.into(),
        verify_tolerance: None,
        supercompression: None,
    };
    if format == FileFormat::Png && img.channels == 2 {
        meta.convention = format!("{convention}; PNG stores RGB with R, G in red and green and B = 0");
        meta.channels = 3;
        meta.pixel_format = None;
    }
    meta
}

/// The raw `{stem}.bin` of an 8-bit UNORM texture, taking the texture's bytes without a copy (a large MLAA map is
/// 52 MB: `rtbake aa … --format bin` encodes the other formats first, then moves the map into this file).
pub fn unorm8_bin_file(stem: &str, img: Image<u8>, kind: FileKind, convention: &str) -> BakedFile {
    let meta = unorm8_meta(&img, kind, convention, FileFormat::Raw);
    BakedFile { path: format!("{stem}.bin"), bytes: img.data, meta }
}

/// [`unorm8_texture_files`] restricted to the binary containers selected in `formats` (the sources are the
/// caller's).
pub fn unorm8_texture_files_in(
    stem: &str,
    img: &Image<u8>,
    kind: FileKind,
    convention: &str,
    formats: TextureFormats,
) -> Result<Vec<BakedFile>, BakeError> {
    let meta = |format: FileFormat| unorm8_meta(img, kind, convention, format);
    // The encoders are independent: PNG compression (the costly one) runs beside the containers.
    let (png, (dds, ktx2)) = rayon::join(
        || formats.png.then(|| io::png::encode_u8(img)).transpose(),
        || {
            rayon::join(
                || formats.dds.then(|| io::dds::encode_u8(img)).transpose(),
                || formats.ktx2.then(|| io::ktx2::encode_u8(img)).transpose(),
            )
        },
    );
    let mut files = Vec::new();
    if formats.bin {
        files.push(BakedFile { path: format!("{stem}.bin"), bytes: img.data.clone(), meta: meta(FileFormat::Raw) });
    }
    if let Some(bytes) = dds? {
        files.push(BakedFile { path: format!("{stem}.dds"), bytes, meta: meta(FileFormat::Dds) });
        // The legacy-header copy for readers without DX10 support (ImageMagick 6, OpenImageIO 2.4).
        let (name, ..) = io::dds::legacy_format(img.channels)
            .ok_or_else(|| BakeError::Other(format!("{stem}: no legacy DDS format for {} channels", img.channels)))?;
        let mut legacy = meta(FileFormat::Dds);
        legacy.convention = format!(
            "{}; legacy DDS header, {name}{}",
            legacy.convention,
            match img.channels {
                2 => " (R in L, G in A: sample .ra in D3D9, as SMAA_AREATEX_SELECT does)",
                4 => " (texels stored B, G, R, A)",
                _ => "",
            }
        );
        files.push(BakedFile { path: format!("{stem}_dx9.dds"), bytes: io::dds::encode_u8_legacy(img)?, meta: legacy });
    }
    if let Some(bytes) = ktx2? {
        files.push(BakedFile { path: format!("{stem}.ktx2"), bytes, meta: meta(FileFormat::Ktx2) });
    }
    if let Some(bytes) = png? {
        files.push(BakedFile { path: format!("{stem}.png"), bytes, meta: meta(FileFormat::Png) });
    }
    Ok(files)
}

/// Writes a linear float texture as EXR f32 (`{stem}.exr`), EXR f16 (`{stem}_f16.exr`), KTX2 half floats
/// (`{stem}.ktx2`) and an 8-bit sRGB-encoded viewing preview (`{stem}_preview_srgb.png`, labelled `srgb`).
/// `tolerance` is the absolute tolerance `verify` allows on the float payloads.
pub fn float_texture_files(
    stem: &str,
    img: &Image<f32>,
    kind: FileKind,
    convention: &str,
    tolerance: f64,
) -> Result<Vec<BakedFile>, BakeError> {
    let title = stem.rsplit('/').next().unwrap_or(stem);
    let axes = crate::plot::preview::PreviewAxes::texels(title, img.width, img.height);
    float_texture_files_with_preview(stem, img, kind, convention, tolerance, &axes)
}

/// [`float_texture_files`] with the preview labelled by `axes` (title, axis names with units, ticks): the preview is
/// the table's sRGB-encoded colours scaled up inside that frame (a one-row table becomes a band), see
/// [`crate::plot::preview`].
pub fn float_texture_files_with_preview(
    stem: &str,
    img: &Image<f32>,
    kind: FileKind,
    convention: &str,
    tolerance: f64,
    axes: &crate::plot::preview::PreviewAxes,
) -> Result<Vec<BakedFile>, BakeError> {
    let meta =
        |format: FileFormat, pf: Option<PixelFormat>, st: SampleType, cs: ColorSpace, tol: Option<f64>| FileMeta {
            kind,
            format,
            pixel_format: pf,
            width: img.width,
            height: img.height,
            channels: if format == FileFormat::Ktx2 {
                pf.map(|p| p.channels()).unwrap_or(img.channels)
            } else {
                img.channels
            },
            sample_type: st,
            color_space: cs,
            convention: convention.into(),
            verify_tolerance: tol,
            supercompression: None,
        };
    let half_tol = tolerance.max(1e-3);
    let preview_img = crate::plot::preview::labelled_preview(&io::png::srgb_preview_pixels(img), axes);
    let mut preview = meta(FileFormat::Png, None, SampleType::U8, ColorSpace::Srgb, Some(1.0));
    preview.kind = FileKind::Preview;
    (preview.width, preview.height, preview.channels) = (preview_img.width, preview_img.height, 3);
    preview.convention = format!(
        "{convention}; preview for viewing only (do not sample): the table's colours sRGB-encoded (alpha dropped), \
         each texel drawn as a block inside a frame with title, axis names and ticks"
    );
    // The four encoders are independent and run side by side (same bytes; errors reported in file order).
    let ((exr_f32, exr_f16), (ktx2, png)) = rayon::join(
        || rayon::join(|| io::exr::encode(img, ExrPrecision::F32), || io::exr::encode(img, ExrPrecision::F16)),
        || rayon::join(|| io::ktx2::encode_f16(img), || io::png::encode_u8_as(&preview_img, io::png::PngColor::Srgb)),
    );
    Ok(vec![
        BakedFile {
            path: format!("{stem}.exr"),
            bytes: exr_f32?,
            meta: meta(FileFormat::Exr, None, SampleType::F32, ColorSpace::Linear, Some(tolerance)),
        },
        BakedFile {
            path: format!("{stem}_f16.exr"),
            bytes: exr_f16?,
            meta: meta(FileFormat::Exr, None, SampleType::F16, ColorSpace::Linear, Some(half_tol)),
        },
        BakedFile {
            path: format!("{stem}.ktx2"),
            bytes: ktx2?,
            meta: meta(
                FileFormat::Ktx2,
                PixelFormat::f16_for(img.channels),
                SampleType::F16,
                ColorSpace::Linear,
                Some(half_tol),
            ),
        },
        BakedFile { path: format!("{stem}_preview_srgb.png"), bytes: png?, meta: preview },
    ])
}

/// Rewrites every uncompressed KTX2 file of `files` with Zstandard supercompression at `level` (1..=22) and records
/// it in the file's metadata (`supercompression: zstd-<level>`). Other files are left as they are.
pub fn supercompress_ktx2(files: &mut [BakedFile], level: i32) -> Result<(), BakeError> {
    crate::error::check_range("zstd level", level, 1, 22, "")?;
    use rayon::prelude::*;
    // Independent files, compressed side by side (the first error in file order is reported).
    let results: Vec<Result<(), BakeError>> = files
        .par_iter_mut()
        .filter(|f| f.meta.format == FileFormat::Ktx2 && f.meta.supercompression.is_none())
        .map(|f| {
            f.bytes = io::ktx2::supercompress(&f.bytes, &f.path, level)?;
            f.meta.supercompression = Some(io::ktx2::Supercompression::Zstd(level).label());
            Ok(())
        })
        .collect();
    results.into_iter().collect()
}

/// A pretty-printed JSON file (stable key order, trailing newline).
pub fn json_file(path: &str, value: &Value, kind: FileKind, convention: &str) -> BakedFile {
    let mut text = serde_json::to_string_pretty(value).expect("JSON values always serialise");
    text.push('\n');
    BakedFile { path: path.into(), bytes: text.into_bytes(), meta: FileMeta::text(kind, FileFormat::Json, convention) }
}

/// The HLSL, GLSL and WGSL includes of `stem` (`{stem}.hlsl`, `{stem}.glsl`, `{stem}.wgsl`), each the text
/// `include(lang)`.
pub fn shader_include_files(
    stem: &str,
    convention: &str,
    include: impl Fn(io::source::ShaderLang) -> String,
) -> Vec<BakedFile> {
    io::source::ShaderLang::ALL
        .into_iter()
        .map(|lang| {
            let path = format!("{stem}.{}", lang.extension());
            text_file(&path, include(lang), FileKind::ShaderInclude, lang.into(), convention)
        })
        .collect()
}

/// A text file (source, CSV, SVG …).
pub fn text_file(path: &str, text: String, kind: FileKind, format: FileFormat, convention: &str) -> BakedFile {
    BakedFile { path: path.into(), bytes: text.into_bytes(), meta: FileMeta::text(kind, format, convention) }
}

/// A kernel's file stem in an asset's parameters (`param` names the field): 1..=64 characters of `[A-Za-z0-9_-]`,
/// not starting with `-`.
pub fn check_kernel_name(param: &str, name: &str) -> Result<(), BakeError> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        && !name.starts_with('-');
    if ok {
        Ok(())
    } else {
        Err(crate::error::InvalidInput::new(param, format!("must be 1..=64 characters of [A-Za-z0-9_-], got {name:?}"))
            .into())
    }
}

/// Deserialises asset parameters, naming the asset in the error.
pub fn parse_params<T: serde::de::DeserializeOwned>(asset: &str, params: &Value) -> Result<T, BakeError> {
    serde_json::from_value(params.clone()).map_err(|e| {
        // serde names unknown and missing fields itself; a wrong type is located against the asset's defaults.
        let field = registry()
            .iter()
            .find(|a| a.name == asset)
            .and_then(|a| type_mismatch(&(a.default_params)(), params, String::new()));
        let param = match field {
            Some(path) => format!("{asset} parameter {path}:"),
            None => format!("{asset} parameters"),
        };
        BakeError::Invalid(crate::error::InvalidInput::new(param, e.to_string()))
    })
}

/// The first path (`table.samples`, `kernels[0].strength[2]`) where `given` has another JSON type than the
/// asset's default `template` (a null default accepts anything; an integer default refuses fractions and
/// negative numbers).
fn type_mismatch(template: &Value, given: &Value, path: String) -> Option<String> {
    let here = || if path.is_empty() { "(top level)".to_string() } else { path.clone() };
    match (template, given) {
        (Value::Null, _) => None,
        (Value::Object(t), Value::Object(g)) => g.iter().find_map(|(k, v)| {
            let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
            t.get(k).and_then(|tv| type_mismatch(tv, v, p))
        }),
        (Value::Array(t), Value::Array(g)) => {
            let elem = t.first()?;
            g.iter().enumerate().find_map(|(i, v)| type_mismatch(elem, v, format!("{path}[{i}]")))
        }
        (Value::Number(t), Value::Number(g)) => {
            let integer = t.is_u64() || t.is_i64();
            let unsigned = t.is_u64();
            let bad = (integer && !(g.is_u64() || g.is_i64())) || (unsigned && !g.is_u64());
            bad.then(here)
        }
        (Value::Bool(_), Value::Bool(_)) | (Value::String(_), Value::String(_)) => None,
        _ => Some(here()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// `asset`'s default parameters and their typed form `P`, asserting that `P` writes them back unchanged (no
    /// field lost or renamed between the embedded defaults and the struct the bake parses).
    pub(crate) fn default_params_round_trip<P: serde::Serialize + serde::de::DeserializeOwned>(
        asset: &Asset,
    ) -> (Value, P) {
        let v = (asset.default_params)();
        let p: P = serde_json::from_value(v.clone()).unwrap();
        assert_eq!(serde_json::to_value(&p).unwrap(), v, "{}", asset.name);
        (v, p)
    }

    #[test]
    fn the_default_bake_is_estimated_within_the_cli_time_budget() {
        // `rtbake bake` refuses a bake whose estimates add up to more than --max-seconds (600 s by default): the
        // README's bake command depends on the default parameters staying under it, and the Monte Carlo assets
        // (whose photon counts a user can raise without bound in time) must carry an estimate.
        let mut total = 0.0;
        for asset in registry() {
            let s = asset.time_estimate_seconds(&(asset.default_params)(), 2).unwrap();
            assert!(s.is_finite() && s >= 0.0, "{}: {s}", asset.name);
            total += s;
        }
        assert!(total > 1.0 && total < 600.0, "{total}");
        for name in ["diffusion-profiles", "transport-report", "skin-color-mc-difference"] {
            assert!(registry().iter().any(|a| a.name == name && a.time_estimate.is_some()), "{name}");
        }
    }
}
