//! Loads LUTs from a bake directory the way an engine should: through `manifest.json`, checking every property
//! that a silent mismatch would break before a byte reaches the GPU.
//!
//! For each LUT: the manifest must list it; container `raw`; pixel format, width, height, channels and sample
//! type as the pass expects; colour space `linear` (a LUT declared sRGB would be decoded by the hardware and
//! quietly disable SMAA — bevy #21425); file size = width·height·bytes per texel; sha256 as recorded. Any
//! mismatch is a [`LutError`] naming the file, the property, what was expected and what was found.
//!
//! The paths of the baked files are the constants below — the one place to change when the bake layout moves.

use crate::io::PixelFormat;
use crate::manifest::{sha256_hex, Manifest, ManifestError};
use std::path::Path;

/// SMAA area texture in `baked/` (RG8 160×560).
pub const SMAA_AREA_PATH: &str = "aa/smaa/AreaTex.bin";
/// SMAA search texture in `baked/` (R8 64×16).
pub const SMAA_SEARCH_PATH: &str = "aa/smaa/SearchTex.bin";

/// Jimenez MLAA v1.4 area map for maximum distance `n` in `baked/` (RG8 5n×5n).
pub fn mlaa_area_path(n: u32) -> String {
    format!("aa/mlaa/AreaMap{n}_v1.4.bin")
}

/// What a pass expects of one LUT.
#[derive(Clone, Debug, PartialEq)]
pub struct LutSpec {
    /// Path relative to the bake directory, as in the manifest.
    pub path: String,
    pub pixel_format: PixelFormat,
    pub width: u32,
    pub height: u32,
}

impl LutSpec {
    pub fn smaa_area() -> Self {
        Self { path: SMAA_AREA_PATH.into(), pixel_format: PixelFormat::R8G8Unorm, width: 160, height: 560 }
    }
    pub fn smaa_search() -> Self {
        Self { path: SMAA_SEARCH_PATH.into(), pixel_format: PixelFormat::R8Unorm, width: 64, height: 16 }
    }
    pub fn mlaa_area(n: u32) -> Self {
        Self { path: mlaa_area_path(n), pixel_format: PixelFormat::R8G8Unorm, width: 5 * n, height: 5 * n }
    }
}

/// A LUT that cannot be used as it is.
#[derive(Debug, thiserror::Error)]
pub enum LutError {
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    #[error("{path}: not listed in the manifest of {dir} (re-run `rtbake bake`)")]
    NotInManifest { dir: String, path: String },
    #[error("{path}: manifest says {field} = {found}, the runtime needs {expected}")]
    Mismatch { path: String, field: &'static str, expected: String, found: String },
    #[error(
        "{path}: declared colour space {found:?}; LUTs must be linear (an sRGB-decoded LUT silently breaks the pass)"
    )]
    ColorSpace { path: String, found: String },
    #[error("{path}: cannot read: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("{path}: {found} bytes, expected {expected} ({what})")]
    Size { path: String, expected: usize, found: usize, what: String },
    #[error("{path}: sha256 {found} does not match the manifest's {expected} (corrupted or modified file)")]
    Checksum { path: String, expected: String, found: String },
}

/// Reads `dir/manifest.json` and loads one LUT after checking it against `spec`.
pub fn load_lut(dir: &Path, spec: &LutSpec) -> Result<Vec<u8>, LutError> {
    let manifest = Manifest::load(dir)?;
    load_lut_with(dir, &manifest, spec)
}

/// Loads one LUT described by an already-parsed manifest.
pub fn load_lut_with(dir: &Path, manifest: &Manifest, spec: &LutSpec) -> Result<Vec<u8>, LutError> {
    let path = spec.path.clone();
    let entry = manifest
        .entry(&spec.path)
        .ok_or_else(|| LutError::NotInManifest { dir: dir.display().to_string(), path: path.clone() })?;
    let m = &entry.meta;
    let mismatch = |field: &'static str, expected: String, found: String| LutError::Mismatch {
        path: path.clone(),
        field,
        expected,
        found,
    };
    if m.color_space != "linear" {
        return Err(LutError::ColorSpace { path: path.clone(), found: m.color_space.clone() });
    }
    if m.format != "raw" {
        return Err(mismatch("format", "\"raw\"".into(), format!("{:?}", m.format)));
    }
    if m.pixel_format != Some(spec.pixel_format) {
        return Err(mismatch("pixel_format", format!("{:?}", spec.pixel_format), format!("{:?}", m.pixel_format)));
    }
    if (m.width, m.height) != (spec.width, spec.height) {
        return Err(mismatch(
            "width x height",
            format!("{}x{}", spec.width, spec.height),
            format!("{}x{}", m.width, m.height),
        ));
    }
    if m.channels != spec.pixel_format.channels() {
        return Err(mismatch("channels", spec.pixel_format.channels().to_string(), m.channels.to_string()));
    }
    let want_sample = sample_type(spec.pixel_format);
    if m.sample_type != want_sample {
        return Err(mismatch("sample_type", want_sample.into(), m.sample_type.clone()));
    }
    let file = dir.join(&spec.path);
    let bytes = std::fs::read(&file).map_err(|e| LutError::Read { path: file.display().to_string(), source: e })?;
    let expected = (spec.width * spec.height * spec.pixel_format.bytes_per_texel()) as usize;
    if bytes.len() != expected {
        return Err(LutError::Size {
            path,
            expected,
            found: bytes.len(),
            what: format!("{}x{} {:?}", spec.width, spec.height, spec.pixel_format),
        });
    }
    let sha = sha256_hex(&bytes);
    if sha != entry.sha256 {
        return Err(LutError::Checksum { path, expected: entry.sha256.clone(), found: sha });
    }
    Ok(bytes)
}

/// The manifest's `sample_type` for a pixel format.
fn sample_type(pf: PixelFormat) -> &'static str {
    match pf {
        PixelFormat::R8Unorm | PixelFormat::R8G8Unorm | PixelFormat::R8G8B8A8Unorm => "u8",
        PixelFormat::R16Sfloat | PixelFormat::R16G16Sfloat | PixelFormat::R16G16B16A16Sfloat => "f16",
        PixelFormat::R32Sfloat | PixelFormat::R32G32B32A32Sfloat => "f32",
    }
}

/// SMAA area + search textures from a bake directory.
pub fn load_smaa_textures(dir: &Path) -> Result<crate::runtime::smaa::SmaaTextures, LutError> {
    let manifest = Manifest::load(dir)?;
    let area = load_lut_with(dir, &manifest, &LutSpec::smaa_area())?;
    let search = load_lut_with(dir, &manifest, &LutSpec::smaa_search())?;
    Ok(crate::runtime::smaa::SmaaTextures { area, search })
}

/// MLAA v1.4 area map of maximum distance `n` from a bake directory.
pub fn load_mlaa_area(dir: &Path, n: u32) -> Result<Vec<u8>, LutError> {
    load_lut(dir, &LutSpec::mlaa_area(n))
}
