//! Loads LUTs from a bake directory the way an engine should: through `manifest.json`, checking every property
//! that a silent mismatch would break before a byte reaches the GPU.
//!
//! For each LUT: the manifest must list it; container `raw`; pixel format, width, height, channels and sample
//! type as the pass expects; colour space `linear` (a LUT declared sRGB would be decoded by the hardware and
//! quietly disable SMAA — bevy #21425); file size = width·height·bytes per texel; sha256 as recorded. Any
//! mismatch is a [`LutError`] naming the file, the property, what was expected and what was found.
//!
//! The float and JSON tables get the same manifest checks and then content checks, each in a typed loader:
//! [`load_separable_kernel`] (schema, tap count = `samples`, centre first, channels sum to 1, step divisor 3),
//! [`load_gaussians`] (shared variances, recorded w′ᵢ and incremental variances = eq. 4.8 / vᵢ − vᵢ₋₁),
//! [`load_transmittance`] and [`load_skin_lut`] (EXR f32, decoded size/channels/precision = declared, sidecar
//! JSON consistent: node-inclusive T(s) with T(0) = 1; LUT index ranges 0.5 / 0.32), [`load_hemoglobin_rig`]
//! (every scale/bias map and H0 of the rig JSON). JSON files may declare colour space `n/a`; texel data must be
//! `linear`; non-raw files must also have the manifest's `size_bytes`.
//!
//! The paths, schema ids and sidecar types are those of [`crate::baked_layout`], which the bakers write: the one
//! place to change when the bake layout moves.

use crate::baked_layout::{
    path, schema, GaussiansFile, ImportanceKernelFile, RigDescription, SeparableKernelFile, SkinLutSidecar,
    TransmittanceSidecar,
};
use crate::io::PixelFormat;
use crate::manifest::{sha256_hex, ColorSpace, Entry, FileFormat, Manifest, ManifestError, SampleType};
use std::path::{Path, PathBuf};

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
        Self { path: path::SMAA_AREA.into(), pixel_format: PixelFormat::R8G8Unorm, width: 160, height: 560 }
    }
    pub fn smaa_search() -> Self {
        Self { path: path::SMAA_SEARCH.into(), pixel_format: PixelFormat::R8Unorm, width: 64, height: 16 }
    }
    pub fn mlaa_area(n: u32) -> Self {
        Self { path: path::mlaa_area_v1_4(n), pixel_format: PixelFormat::R8G8Unorm, width: 5 * n, height: 5 * n }
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
    /// The file passed the manifest checks but its content is not what the runtime can use.
    #[error("{path}: {message}")]
    Content { path: String, message: String },
}

/// A bake directory opened once: its `manifest.json` read and parsed when opened, then every asset handed out typed
/// after the manifest checks ([`LutError`] on any mismatch). The `load_*` functions open one for a single asset.
pub struct BakedDir {
    dir: PathBuf,
    manifest: Manifest,
}

impl BakedDir {
    /// Reads `dir/manifest.json`.
    pub fn open(dir: &Path) -> Result<Self, LutError> {
        Ok(Self { dir: dir.to_path_buf(), manifest: Manifest::load(dir)? })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// The parsed manifest.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// One LUT after checking it against `spec` ([`load_lut`]).
    pub fn lut(&self, spec: &LutSpec) -> Result<Vec<u8>, LutError> {
        load_lut_with(&self.dir, &self.manifest, spec)
    }

    /// The MLAA v1.4 area map of maximum distance `n` ([`load_mlaa_area`]).
    pub fn mlaa_area(&self, n: u32) -> Result<Vec<u8>, LutError> {
        self.lut(&LutSpec::mlaa_area(n))
    }

    /// SMAA area + search textures from a bake directory.
    pub fn smaa_textures(&self) -> Result<crate::runtime::aa::smaa::SmaaTextures, LutError> {
        smaa_textures_in(&self.dir, &self.manifest)
    }

    /// Loads a separable-SSS kernel JSON (`rtbake-separable-kernel/1`) after the manifest checks; refuses a kernel
    /// whose tap count differs from `samples`, whose first tap is not the centre, whose channels do not each sum to 1
    /// (±1e-4), or whose `step_divisor` is not the 3 the shader hard-codes.
    pub fn separable_kernel(&self, path: &str) -> Result<BakedKernel, LutError> {
        separable_kernel_in(&self.dir, &self.manifest, path)
    }

    /// Loads a separable-SSS kernel from its raw little-endian `f32 × 4 × N` file (`{stem}_f32x4.bin`, the layout
    /// `SeparableSSS.h`'s runtime `kernel[SSSS_N_SAMPLES]` takes) after the manifest checks (format raw, f32,
    /// R32G32B32A32, 1 row); the taps get the same content checks as the JSON (centre first, channels sum to 1).
    pub fn separable_kernel_f32x4(&self, path: &str) -> Result<crate::runtime::sss::separable::SssKernel, LutError> {
        separable_kernel_f32x4_in(&self.dir, &self.manifest, path)
    }

    /// Loads an importance-sampled disk kernel JSON (`rtbake-importance-kernel/1`: `sss/importance/*.json`,
    /// `burley/kernels/*.json`) after the manifest checks, as the importance SSS pass takes it: offsets (x, y, r in mm)
    /// and per-channel weights. Refuses a kernel whose sample count differs from `samples`, whose radii disagree with
    /// the offsets (1e-6 mm relative), whose channels do not each sum to 1 (±1e-4), or with a non-positive cut-off.
    pub fn importance_kernel(
        &self,
        path: &str,
    ) -> Result<crate::runtime::sss::importance::ImportanceSamples, LutError> {
        importance_kernel_in(&self.dir, &self.manifest, path)
    }

    /// Loads a sum-of-Gaussians JSON (`sss/gaussians/*.json`) after the manifest checks. The pass blurs all three
    /// channels with one σ per Gaussian, so `shared_variances` must be true. The recorded `blend_weights` and
    /// `incremental_variances` must agree with eq. 4.8 and vᵢ − vᵢ₋₁ recomputed from `weights` and `variances`
    /// (1e-6): a file edited in one place only is refused.
    pub fn gaussians(&self, path: &str) -> Result<BakedGaussians, LutError> {
        gaussians_in(&self.dir, &self.manifest, path)
    }

    /// Loads T(s) (EXR f32 RGB, `width` samples, identical rows) and its sidecar JSON (`s_max_mm`, `samples`,
    /// node-inclusive texel convention), both through the manifest checks. Refuses a table whose rows differ, whose
    /// sidecar disagrees with the EXR's width, whose convention is not node-inclusive, or whose T(0) is not ≈ 1
    /// per channel (±1e-3; eq. 5.12 at s = 0 is Σ wᵢ).
    pub fn transmittance(&self, path: &str) -> Result<TransmittanceTable, LutError> {
        transmittance_in(&self.dir, &self.manifest, path)
    }

    /// Loads the skin colour LUT (EXR f32 RGB, ≥ 2×2) and its sidecar JSON through the manifest checks. The pass
    /// indexes it with u = cbrt(Cm/0.5), v = cbrt(Chd/0.32), node-inclusive ([`crate::runtime::skin::inputs::CM_MAX`],
    /// [`crate::runtime::skin::inputs::CHD_MAX`]); a sidecar with other ranges or another size is refused.
    pub fn skin_lut(&self, path: &str) -> Result<AlbedoLut, LutError> {
        skin_lut_in(&self.dir, &self.manifest, path)
    }

    /// The skin LUTs of the pass from a bake directory: the albedo LUT at `skin_lut` and T(s) at `transmittance`.
    pub fn skin_luts(
        &self,
        skin_lut: &str,
        transmittance: &str,
    ) -> Result<crate::runtime::skin::inputs::SkinLuts, LutError> {
        skin_luts_in(&self.dir, &self.manifest, skin_lut, transmittance)
    }

    /// Loads a hemoglobin rig (`rtbake-hemoglobin-rig/1`) and every map it names (paths relative to the rig file's
    /// folder), each through the manifest checks: single-channel f32 EXRs, scale/bias at `rig_size`, H0 at
    /// `full_size`. Refuses more targets than the pass holds ([`crate::runtime::skin::inputs::MAX_RIG_TARGETS`]), a
    /// first map that is not the neutral one, and values outside the dermal-hemoglobin range the skin LUT indexes.
    pub fn hemoglobin_rig(&self, path: &str) -> Result<BakedRig, LutError> {
        hemoglobin_rig_in(&self.dir, &self.manifest, path)
    }
}

/// Loads one LUT described by an already-parsed manifest.
pub fn load_lut_with(dir: &Path, manifest: &Manifest, spec: &LutSpec) -> Result<Vec<u8>, LutError> {
    let expect = Expect {
        format: FileFormat::Raw,
        pixel_format: Some(spec.pixel_format),
        size: Some((spec.width, spec.height)),
        channels: Some(spec.pixel_format.channels()),
        sample_type: sample_type(spec.pixel_format),
        data: DataKind::Texture,
    };
    Ok(read_checked(dir, manifest, &spec.path, &expect)?.0)
}

/// Whether a file is texel data (colour space must be `linear`) or a text/JSON table (`linear` or `n/a`).
#[derive(Clone, Copy, PartialEq)]
enum DataKind {
    Texture,
    Table,
}

/// What the runtime expects of one manifest entry (`None`: not checked here).
struct Expect {
    format: FileFormat,
    pixel_format: Option<PixelFormat>,
    size: Option<(u32, u32)>,
    channels: Option<u32>,
    sample_type: SampleType,
    data: DataKind,
}

/// Checks `path`'s manifest entry against `expect`, reads the file, checks its length against the manifest's
/// `size_bytes` and its sha256. Returns the bytes and the entry.
fn read_checked<'m>(
    dir: &Path,
    manifest: &'m Manifest,
    path: &str,
    expect: &Expect,
) -> Result<(Vec<u8>, &'m Entry), LutError> {
    let entry = manifest
        .entry(path)
        .ok_or_else(|| LutError::NotInManifest { dir: dir.display().to_string(), path: path.to_string() })?;
    let m = &entry.meta;
    let mismatch = |field: &'static str, expected: String, found: String| LutError::Mismatch {
        path: path.to_string(),
        field,
        expected,
        found,
    };
    let colour_ok = m.color_space == ColorSpace::Linear
        || (expect.data == DataKind::Table && m.color_space == ColorSpace::NotApplicable);
    if !colour_ok {
        return Err(LutError::ColorSpace { path: path.to_string(), found: m.color_space.to_string() });
    }
    if m.format != expect.format {
        return Err(mismatch("format", format!("{:?}", expect.format.as_str()), format!("{:?}", m.format.as_str())));
    }
    if let Some(pf) = expect.pixel_format {
        if m.pixel_format != Some(pf) {
            return Err(mismatch("pixel_format", format!("{pf:?}"), format!("{:?}", m.pixel_format)));
        }
    }
    if let Some((w, h)) = expect.size {
        if (m.width, m.height) != (w, h) {
            return Err(mismatch("width x height", format!("{w}x{h}"), format!("{}x{}", m.width, m.height)));
        }
    }
    if let Some(c) = expect.channels {
        if m.channels != c {
            return Err(mismatch("channels", c.to_string(), m.channels.to_string()));
        }
    }
    if m.sample_type != expect.sample_type {
        return Err(mismatch("sample_type", expect.sample_type.to_string(), m.sample_type.to_string()));
    }
    let file = dir.join(path);
    let bytes = std::fs::read(&file).map_err(|e| LutError::Read { path: file.display().to_string(), source: e })?;
    // Raw texels: the length follows from the size and format; other containers: the manifest's size_bytes.
    if let (true, Some(pf), Some((w, h))) = (expect.format == FileFormat::Raw, expect.pixel_format, expect.size) {
        let expected = (w * h * pf.bytes_per_texel()) as usize;
        if bytes.len() != expected {
            return Err(LutError::Size {
                path: path.to_string(),
                expected,
                found: bytes.len(),
                what: format!("{w}x{h} {pf:?}"),
            });
        }
    } else if bytes.len() as u64 != entry.size_bytes {
        return Err(LutError::Size {
            path: path.to_string(),
            expected: entry.size_bytes as usize,
            found: bytes.len(),
            what: "size_bytes in the manifest".into(),
        });
    }
    let sha = sha256_hex(&bytes);
    if sha != entry.sha256 {
        return Err(LutError::Checksum { path: path.to_string(), expected: entry.sha256.clone(), found: sha });
    }
    Ok((bytes, entry))
}

/// The manifest's `sample_type` for a pixel format.
fn sample_type(pf: PixelFormat) -> SampleType {
    match pf {
        PixelFormat::R8Unorm | PixelFormat::R8G8Unorm | PixelFormat::R8G8B8A8Unorm => SampleType::U8,
        PixelFormat::R16Sfloat | PixelFormat::R16G16Sfloat | PixelFormat::R16G16B16A16Sfloat => SampleType::F16,
        PixelFormat::R32Sfloat | PixelFormat::R32G32B32A32Sfloat => SampleType::F32,
    }
}

fn smaa_textures_in(dir: &Path, manifest: &Manifest) -> Result<crate::runtime::aa::smaa::SmaaTextures, LutError> {
    let area = load_lut_with(dir, manifest, &LutSpec::smaa_area())?;
    let search = load_lut_with(dir, manifest, &LutSpec::smaa_search())?;
    Ok(crate::runtime::aa::smaa::SmaaTextures { area, search })
}

// ---------------------------------------------------------------------------------------------------------------
// Typed loaders for the float and JSON tables (same manifest checks as the AA LUTs, then content checks).

fn content(path: &str, message: impl Into<String>) -> LutError {
    LutError::Content { path: path.to_string(), message: message.into() }
}

/// Reads a JSON table listed in the manifest (`format` json, `sample_type` text, colour space linear or n/a).
fn load_json(dir: &Path, manifest: &Manifest, path: &str) -> Result<serde_json::Value, LutError> {
    let expect = Expect {
        format: FileFormat::Json,
        pixel_format: None,
        size: None,
        channels: None,
        sample_type: SampleType::Text,
        data: DataKind::Table,
    };
    let (bytes, _) = read_checked(dir, manifest, path, &expect)?;
    serde_json::from_slice(&bytes).map_err(|e| content(path, format!("not valid JSON: {e}")))
}

/// Reads a float EXR listed in the manifest (`format` exr, `sample_type` f32, linear, `channels` channels) and
/// checks that the decoded image has the declared size, channel count and precision.
fn load_exr_f32(
    dir: &Path,
    manifest: &Manifest,
    path: &str,
    channels: u32,
    min_size: (u32, u32),
) -> Result<crate::image_buf::Image<f32>, LutError> {
    let expect = Expect {
        format: FileFormat::Exr,
        pixel_format: None,
        size: None,
        channels: Some(channels),
        sample_type: SampleType::F32,
        data: DataKind::Texture,
    };
    let (bytes, entry) = read_checked(dir, manifest, path, &expect)?;
    let (w, h) = (entry.meta.width, entry.meta.height);
    if w < min_size.0 || h < min_size.1 {
        return Err(LutError::Mismatch {
            path: path.to_string(),
            field: "width x height",
            expected: format!("at least {}x{}", min_size.0, min_size.1),
            found: format!("{w}x{h}"),
        });
    }
    let (img, precision) = crate::io::exr::decode(&bytes, path).map_err(|e| content(path, e.to_string()))?;
    if (img.width, img.height, img.channels) != (w, h, channels) {
        return Err(content(
            path,
            format!(
                "decodes to {}x{} with {} channels, the manifest declares {w}x{h} with {channels}",
                img.width, img.height, img.channels
            ),
        ));
    }
    if precision != crate::io::exr::ExrPrecision::F32 {
        return Err(content(path, "decodes to half floats, the manifest declares sample_type f32"));
    }
    if img.data.iter().any(|v| !v.is_finite()) {
        return Err(content(path, "holds non-finite values"));
    }
    Ok(img)
}

/// Deserialises a whole file into its contract type ([`crate::baked_layout`]), naming the field that does not fit.
fn typed<T: serde::de::DeserializeOwned>(v: serde_json::Value, path: &str) -> Result<T, LutError> {
    serde_json::from_value(v).map_err(|e| content(path, format!("does not match its schema: {e}")))
}

/// A JSON value of a contract type in the shape the pass needs.
fn shaped<T: serde::de::DeserializeOwned>(v: &serde_json::Value, path: &str, key: &str) -> Result<T, LutError> {
    serde_json::from_value(v.clone()).map_err(|e| content(path, format!("field \"{key}\" has the wrong shape: {e}")))
}

/// A baked separable-SSS kernel (schema `rtbake-separable-kernel/1`).
#[derive(Clone, Debug, PartialEq)]
pub struct BakedKernel {
    /// Taps `[r, g, b, offset]`, centre first, as the pass takes them.
    pub kernel: crate::runtime::sss::separable::SssKernel,
    /// Largest |offset| in kernel units.
    pub range: f64,
    /// The world-space width the kernel was made for, if the file records it.
    pub sss_width: Option<f32>,
}

fn separable_kernel_in(dir: &Path, manifest: &Manifest, path: &str) -> Result<BakedKernel, LutError> {
    let v = load_json(dir, manifest, path)?;
    separable_kernel_from_json(&v, path)
}

fn separable_kernel_f32x4_in(
    dir: &Path,
    manifest: &Manifest,
    path: &str,
) -> Result<crate::runtime::sss::separable::SssKernel, LutError> {
    let expect = Expect {
        format: FileFormat::Raw,
        pixel_format: Some(PixelFormat::R32G32B32A32Sfloat),
        size: None,
        channels: Some(4),
        sample_type: SampleType::F32,
        data: DataKind::Table,
    };
    let (bytes, entry) = read_checked(dir, manifest, path, &expect)?;
    let taps = crate::separable::kernel::taps_from_f32x4_le(&bytes).map_err(|e| content(path, e.to_string()))?;
    if taps.len() != entry.meta.width as usize || entry.meta.height != 1 {
        return Err(content(
            path,
            format!("{} taps, manifest says {}x{}", taps.len(), entry.meta.width, entry.meta.height),
        ));
    }
    if taps[0][3] != 0.0 {
        return Err(content(path, "kernel[0] must be the centre tap (offset 0)"));
    }
    for c in 0..3 {
        let sum: f64 = taps.iter().map(|t| t[c] as f64).sum();
        if (sum - 1.0).abs() > 1e-4 {
            return Err(content(path, format!("channel {c} weights sum to {sum}, expected 1 (±1e-4)")));
        }
    }
    crate::runtime::sss::separable::SssKernel::new(taps).map_err(|e| content(path, e.to_string()))
}

/// The content checks of [`load_separable_kernel`] on an already-parsed kernel file (`path` names it in errors);
/// for kernel files outside a bake directory, which have no manifest entry to check against.
pub fn separable_kernel_from_json(v: &serde_json::Value, path: &str) -> Result<BakedKernel, LutError> {
    let found = v.get("schema").and_then(|s| s.as_str()).unwrap_or_default();
    if found != schema::SEPARABLE_KERNEL {
        return Err(content(path, format!("schema {found:?}, the runtime reads {:?}", schema::SEPARABLE_KERNEL)));
    }
    let file: SeparableKernelFile = typed(v.clone(), path)?;
    let taps: Vec<[f32; 4]> = file.kernel.iter().map(|t| t.map(|x| x as f32)).collect();
    let samples = file.samples;
    if taps.len() != samples {
        return Err(content(path, format!("\"samples\" = {samples} but \"kernel\" has {} taps", taps.len())));
    }
    if taps.first().is_some_and(|t| t[3] != 0.0) {
        return Err(content(path, "kernel[0] must be the centre tap (offset 0)"));
    }
    for c in 0..3 {
        let sum: f64 = taps.iter().map(|t| t[c] as f64).sum();
        if (sum - 1.0).abs() > 1e-4 {
            return Err(content(path, format!("channel {} weights sum to {sum}, must be 1", ["r", "g", "b"][c])));
        }
    }
    let step = file.step_divisor;
    if step != 3.0 {
        return Err(content(path, format!("step_divisor {step}; the separable SSS shader divides the step by 3")));
    }
    let range = file.range;
    let sss_width = file.sss_width.map(|w| w as f32);
    let kernel = crate::runtime::sss::separable::SssKernel::new(taps).map_err(|e| content(path, e.to_string()))?;
    Ok(BakedKernel { kernel, range, sss_width })
}

fn importance_kernel_in(
    dir: &Path,
    manifest: &Manifest,
    path: &str,
) -> Result<crate::runtime::sss::importance::ImportanceSamples, LutError> {
    let v = load_json(dir, manifest, path)?;
    importance_kernel_from_json(&v, path)
}

/// The content checks of [`load_importance_kernel`] on a parsed kernel file.
pub fn importance_kernel_from_json(
    v: &serde_json::Value,
    path: &str,
) -> Result<crate::runtime::sss::importance::ImportanceSamples, LutError> {
    let found = v.get("schema").and_then(|s| s.as_str()).unwrap_or_default();
    if found != schema::IMPORTANCE_KERNEL {
        return Err(content(path, format!("schema {found:?}, the runtime reads {:?}", schema::IMPORTANCE_KERNEL)));
    }
    let file: ImportanceKernelFile = typed(v.clone(), path)?;
    if file.kernel.len() != file.samples {
        return Err(content(path, format!("\"samples\" = {} but \"kernel\" has {}", file.samples, file.kernel.len())));
    }
    for (i, s) in file.kernel.iter().enumerate() {
        let r = s.x_mm.hypot(s.y_mm);
        if (r - s.r_mm).abs() > 1e-6 * s.r_mm.max(1e-3) {
            return Err(content(path, format!("kernel[{i}]: |(x_mm, y_mm)| = {r} but r_mm = {}", s.r_mm)));
        }
    }
    for c in 0..3 {
        let sum: f64 = file.kernel.iter().map(|s| s.weight[c]).sum();
        if (sum - 1.0).abs() > 1e-4 {
            return Err(content(path, format!("channel {} weights sum to {sum}, must be 1", ["r", "g", "b"][c])));
        }
    }
    let samples = crate::runtime::sss::importance::ImportanceSamples {
        offsets_mm: file.kernel.iter().map(|s| [s.x_mm as f32, s.y_mm as f32, s.r_mm as f32, 0.0]).collect(),
        weights: file
            .kernel
            .iter()
            .map(|s| [s.weight[0] as f32, s.weight[1] as f32, s.weight[2] as f32, 0.0])
            .collect(),
        cutoff_mm: file.cutoff_mm as f32,
    };
    samples.validate().map_err(|e| content(path, e.to_string()))?;
    Ok(samples)
}

/// A baked sum-of-Gaussians fit with the screen-space parameters derived from it.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedGaussians {
    pub fit: crate::diffusion::sum_of_gaussians::SumOfGaussians,
    /// Incremental blurs and blend weights w′ᵢ (eq. 4.8), checked against the values recorded in the file.
    pub blurs: crate::runtime::sss::gaussian::GaussianBlurs,
    /// α, β, γ as recorded (lod factor: the exact rule of eq. 4.6).
    pub params: crate::runtime::sss::gaussian::GaussianSssParams,
}

fn gaussians_in(dir: &Path, manifest: &Manifest, path: &str) -> Result<BakedGaussians, LutError> {
    use crate::runtime::sss::gaussian::{GaussianBlurs, GaussianSssParams};
    let file: GaussiansFile = typed(load_json(dir, manifest, path)?, path)?;
    if !file.shared_variances {
        return Err(content(path, "per-channel variances; the screen-space pass needs shared_variances = true"));
    }
    let variances_mm2: Vec<f64> = shaped(&file.variances, path, "variances")?;
    let weights: Vec<[f64; 3]> = shaped(&file.weights, path, "weights")?;
    let blend: Vec<[f64; 3]> = shaped(&file.blend_weights, path, "blend_weights")?;
    let incremental: Vec<f64> = shaped(&file.incremental_variances, path, "incremental_variances")?;
    let n = variances_mm2.len();
    if weights.len() != n || blend.len() != n || incremental.len() != n {
        return Err(content(path, format!("{n} variances but weights/blend_weights/incremental_variances differ")));
    }
    let fit = crate::diffusion::sum_of_gaussians::SumOfGaussians { variances_mm2, weights };
    let blurs = GaussianBlurs::from_sum_of_gaussians(&fit).map_err(|e| content(path, e.to_string()))?;
    for i in 0..n {
        for (c, (&got, &recorded)) in blurs.blend[i].iter().zip(&blend[i]).enumerate() {
            if (got as f64 - recorded).abs() > 1e-6 {
                return Err(content(path, format!("blend_weights[{i}][{c}] = {recorded} but eq. 4.8 gives {got}")));
            }
        }
        let inc = (blurs.incremental_sigma_mm[i] as f64).powi(2);
        if (inc - incremental[i]).abs() > 1e-6 * incremental[i].max(1.0) {
            return Err(content(
                path,
                format!("incremental_variances[{i}] = {} but v_i - v_(i-1) = {inc}", incremental[i]),
            ));
        }
    }
    let params = GaussianSssParams {
        alpha: file.lod_thresholds.alpha as f32,
        beta: file.lod_thresholds.beta as f32,
        gamma: file.lod_thresholds.gamma as f32,
        ..GaussianSssParams::default()
    };
    params.validate().map_err(|e| content(path, e.to_string()))?;
    Ok(BakedGaussians { fit, blurs, params })
}

/// A baked transmittance table T(s), node-inclusive: texel i holds s = s_max·i/(n−1).
#[derive(Clone, Debug, PartialEq)]
pub struct TransmittanceTable {
    pub values: Vec<[f32; 3]>,
    pub s_max_mm: f32,
}

fn transmittance_in(dir: &Path, manifest: &Manifest, path: &str) -> Result<TransmittanceTable, LutError> {
    let img = load_exr_f32(dir, manifest, path, 3, (2, 1))?;
    let side_path = path::sidecar(path);
    let side: TransmittanceSidecar = typed(load_json(dir, manifest, &side_path)?, &side_path)?;
    if side.samples != img.width {
        return Err(content(&side_path, format!("samples = {}, the table {path} is {} wide", side.samples, img.width)));
    }
    let conv = &side.texel_convention;
    if conv != TransmittanceSidecar::TEXEL_CONVENTION {
        return Err(content(
            &side_path,
            format!("texel_convention {conv:?}; the pass samples {:?}", TransmittanceSidecar::TEXEL_CONVENTION),
        ));
    }
    let s_max_mm = side.s_max_mm;
    if !(s_max_mm.is_finite() && s_max_mm > 0.0) {
        return Err(content(&side_path, format!("s_max_mm must be > 0, got {s_max_mm}")));
    }
    let row = (3 * img.width) as usize;
    if img.data.chunks(row).any(|r| r != &img.data[..row]) {
        return Err(content(path, "rows differ; T(s) is one row (repeated rows must be identical)"));
    }
    let values: Vec<[f32; 3]> = img.data[..row].chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    if values[0].iter().any(|t| (t - 1.0).abs() > 1e-3) {
        return Err(content(path, format!("T(0) = {:?}; a normalised profile gives 1 per channel", values[0])));
    }
    Ok(TransmittanceTable { values, s_max_mm: s_max_mm as f32 })
}

/// The skin colour LUT: linear RGB albedo, columns = melanin, rows = hemoglobin (top row Chd = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoLut {
    pub width: u32,
    pub height: u32,
    pub albedo: Vec<[f32; 3]>,
}

fn skin_lut_in(dir: &Path, manifest: &Manifest, path: &str) -> Result<AlbedoLut, LutError> {
    use crate::runtime::skin::inputs::{CHD_MAX, CM_MAX};
    let img = load_exr_f32(dir, manifest, path, 3, (2, 2))?;
    let side_path = path::sidecar(path);
    let side: SkinLutSidecar = typed(load_json(dir, manifest, &side_path)?, &side_path)?;
    let (w, h) = (side.width, side.height);
    if (w, h) != (img.width, img.height) {
        return Err(content(&side_path, format!("says {w}x{h}, the LUT {path} is {}x{}", img.width, img.height)));
    }
    let (cm, chd) = (side.index.melanin_max, side.index.hemoglobin_max);
    if cm as f32 != CM_MAX || chd as f32 != CHD_MAX {
        return Err(content(
            &side_path,
            format!("index ranges Cm <= {cm}, Chd <= {chd}; the pass indexes Cm <= {CM_MAX}, Chd <= {CHD_MAX}"),
        ));
    }
    let albedo = img.data.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok(AlbedoLut { width: img.width, height: img.height, albedo })
}

fn skin_luts_in(
    dir: &Path,
    manifest: &Manifest,
    skin_lut: &str,
    transmittance: &str,
) -> Result<crate::runtime::skin::inputs::SkinLuts, LutError> {
    let lut = skin_lut_in(dir, manifest, skin_lut)?;
    let t = transmittance_in(dir, manifest, transmittance)?;
    Ok(crate::runtime::skin::inputs::SkinLuts {
        albedo_size: (lut.width, lut.height),
        albedo: lut.albedo,
        transmittance: t.values,
        s_max_mm: t.s_max_mm,
    })
}

/// A baked hemoglobin rig (eq. 7.6): the per-target (scale, bias) maps the pass takes and the full-resolution H0.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedRig {
    /// Targets in the file's order (`maps[0]` = neutral).
    pub rig: crate::runtime::skin::inputs::RigScaleBiasMaps,
    /// Target names, same order.
    pub names: Vec<String>,
    /// Mean-free neutral hemoglobin H0 (eq. 7.4), `full_size`, top row first.
    pub h0: crate::image_buf::Image<f32>,
    /// Global state factors g of eq. 7.6 by target name (e.g. anger 1.27).
    pub global_scales: Vec<(String, f64)>,
}

impl BakedRig {
    /// H0 sampled bilinearly (clamp to edge) at texture coordinates (u, v) ∈ [0, 1]², texel centres at
    /// (i + 0.5)/size, as the rig's `sampling` field states.
    pub fn h0_at(&self, u: f32, v: f32) -> f32 {
        let (w, h) = (self.h0.width as i64, self.h0.height as i64);
        let (x, y) = (u * w as f32 - 0.5, v * h as f32 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: i64, j: i64| self.h0.data[(j.clamp(0, h - 1) * w + i.clamp(0, w - 1)) as usize];
        let (i, j) = (x0 as i64, y0 as i64);
        let top = at(i, j) + (at(i + 1, j) - at(i, j)) * fx;
        let bottom = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * fx;
        top + (bottom - top) * fy
    }
}

fn hemoglobin_rig_in(dir: &Path, manifest: &Manifest, path: &str) -> Result<BakedRig, LutError> {
    use crate::runtime::skin::inputs::{RigScaleBiasMaps, MAX_RIG_TARGETS};
    let v = load_json(dir, manifest, path)?;
    let found = v.get("schema").and_then(|s| s.as_str()).unwrap_or_default();
    if found != schema::HEMOGLOBIN_RIG {
        return Err(content(path, format!("schema {found:?}, the runtime reads {:?}", schema::HEMOGLOBIN_RIG)));
    }
    let desc: RigDescription = typed(v, path)?;
    if desc.maps.len() > MAX_RIG_TARGETS {
        return Err(content(path, format!("{} maps; the pass takes 1..={MAX_RIG_TARGETS}", desc.maps.len())));
    }
    let folder = path.rsplit_once('/').map(|(d, _)| d).unwrap_or_default();
    // Each map through the manifest checks; the first refusal is returned as itself (its LutError kind), not as
    // the reader's message.
    let mut refused: Option<LutError> = None;
    let expect = Expect {
        format: FileFormat::Exr,
        pixel_format: None,
        size: None,
        channels: Some(1),
        sample_type: SampleType::F32,
        data: DataKind::Texture,
    };
    let read = &mut |file: &str| {
        let p = path::in_dir(folder, file);
        read_checked(dir, manifest, &p, &expect).map(|(bytes, _)| bytes).map_err(|e| {
            let message = e.to_string();
            refused.get_or_insert(e);
            crate::error::InvalidInput::new(p.as_str(), message)
        })
    };
    let rig = crate::baked_layout::rig_from_description(path, &desc, read);
    if let Some(e) = refused {
        return Err(e);
    }
    let rig = rig.map_err(|e| content(path, e.message))?;
    let mut names = Vec::with_capacity(rig.maps.len());
    let mut targets = Vec::with_capacity(rig.maps.len());
    for m in &rig.maps {
        if let Some(b) = m.bias.iter().find(|b| !(-0.01..=0.5).contains(*b)) {
            return Err(content(
                path,
                format!("{}: bias {b} is not a dermal hemoglobin volume fraction (LUT range 0..0.32)", m.name),
            ));
        }
        targets.push(m.scale.iter().zip(&m.bias).map(|(&s, &b)| [s, b]).collect());
        names.push(m.name.clone());
    }
    let h0 = crate::image_buf::Image::from_vec(rig.width, rig.height, 1, rig.h0);
    let global_scales = desc.global_scales.iter().filter_map(|(k, g)| g.as_f64().map(|g| (k.clone(), g))).collect();
    let rig = RigScaleBiasMaps { width: rig.rig_width, height: rig.rig_height, targets };
    rig.validate().map_err(|e| content(path, e.to_string()))?;
    Ok(BakedRig { rig, names, h0, global_scales })
}

// One asset from a bake directory: each opens a [`BakedDir`] (reads the manifest) for that asset alone.

/// Reads `dir/manifest.json` and loads one LUT after checking it against `spec`.
pub fn load_lut(dir: &Path, spec: &LutSpec) -> Result<Vec<u8>, LutError> {
    BakedDir::open(dir)?.lut(spec)
}

/// MLAA v1.4 area map of maximum distance `n` from a bake directory.
pub fn load_mlaa_area(dir: &Path, n: u32) -> Result<Vec<u8>, LutError> {
    BakedDir::open(dir)?.mlaa_area(n)
}

/// [`BakedDir::smaa_textures`] of a bake directory opened for it alone.
pub fn load_smaa_textures(dir: &Path) -> Result<crate::runtime::aa::smaa::SmaaTextures, LutError> {
    BakedDir::open(dir)?.smaa_textures()
}

/// [`BakedDir::separable_kernel`] of a bake directory opened for it alone.
pub fn load_separable_kernel(dir: &Path, path: &str) -> Result<BakedKernel, LutError> {
    BakedDir::open(dir)?.separable_kernel(path)
}

/// [`BakedDir::separable_kernel_f32x4`] of a bake directory opened for it alone.
pub fn load_separable_kernel_f32x4(
    dir: &Path,
    path: &str,
) -> Result<crate::runtime::sss::separable::SssKernel, LutError> {
    BakedDir::open(dir)?.separable_kernel_f32x4(path)
}

/// [`BakedDir::importance_kernel`] of a bake directory opened for it alone.
pub fn load_importance_kernel(
    dir: &Path,
    path: &str,
) -> Result<crate::runtime::sss::importance::ImportanceSamples, LutError> {
    BakedDir::open(dir)?.importance_kernel(path)
}

/// [`BakedDir::gaussians`] of a bake directory opened for it alone.
pub fn load_gaussians(dir: &Path, path: &str) -> Result<BakedGaussians, LutError> {
    BakedDir::open(dir)?.gaussians(path)
}

/// [`BakedDir::transmittance`] of a bake directory opened for it alone.
pub fn load_transmittance(dir: &Path, path: &str) -> Result<TransmittanceTable, LutError> {
    BakedDir::open(dir)?.transmittance(path)
}

/// [`BakedDir::skin_lut`] of a bake directory opened for it alone.
pub fn load_skin_lut(dir: &Path, path: &str) -> Result<AlbedoLut, LutError> {
    BakedDir::open(dir)?.skin_lut(path)
}

/// [`BakedDir::skin_luts`] of a bake directory opened for it alone.
pub fn load_skin_luts(
    dir: &Path,
    skin_lut: &str,
    transmittance: &str,
) -> Result<crate::runtime::skin::inputs::SkinLuts, LutError> {
    BakedDir::open(dir)?.skin_luts(skin_lut, transmittance)
}

/// [`BakedDir::hemoglobin_rig`] of a bake directory opened for it alone.
pub fn load_hemoglobin_rig(dir: &Path, path: &str) -> Result<BakedRig, LutError> {
    BakedDir::open(dir)?.hemoglobin_rig(path)
}
