//! `baked/manifest.json`: what every baked file is, how it was made, and its sha256.
//!
//! Written deterministically: stable key order, no timestamps, entries sorted by path. Re-baking with the same
//! rtbake sources and parameters changes no byte of any file, the manifest included.
//!
//! Provenance is rtbake's own, captured when rtbake was compiled (not the directory the bake runs in):
//! `tool_version` (the crate version), `source_tree` (the git tree id of rtbake's `src/`, equal to
//! `git rev-parse <commit>:src` for a clean checkout of that commit) and `cargo_lock` (the git blob id of the
//! `Cargo.lock` it was built with, which pins the encoders, or `absent`). A tree id rather than a commit id: a commit
//! that only re-bakes `baked/` or edits docs moves HEAD but not the tree, so re-baking the same sources keeps the
//! manifest byte-identical.

use crate::io::PixelFormat;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::path::Path;

pub const MANIFEST_NAME: &str = "manifest.json";
pub const SCHEMA: &str = crate::baked_layout::schema::MANIFEST;

/// Git tree id of the `src/` this rtbake was compiled from (computed by `build.rs` from the files, so it also
/// names uncommitted sources; `git rev-parse <commit>:src` prints the same id for a clean checkout).
pub const SOURCE_TREE: &str = env!("RTBAKE_SOURCE_TREE");
/// Git blob id of the `Cargo.lock` this rtbake was compiled with (`git rev-parse <commit>:Cargo.lock`), or `absent`
/// when built as a dependency without one.
pub const CARGO_LOCK: &str = env!("RTBAKE_CARGO_LOCK");

/// Metadata recorded in the manifest for one file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FileMeta {
    /// What the file is.
    pub kind: FileKind,
    /// Its container.
    pub format: FileFormat,
    /// GPU texel format of the payload where it has one.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub pixel_format: Option<PixelFormat>,
    pub width: u32,
    pub height: u32,
    pub channels: u32,
    /// The payload's sample type.
    pub sample_type: SampleType,
    /// `linear` for every data texture; `srgb` only for labelled viewing previews; `n/a` for text.
    pub color_space: ColorSpace,
    /// Texel / index convention (how a shader maps coordinates to parameters), in words and formulas.
    pub convention: String,
    /// Absolute tolerance used by `verify` for float payloads (None: must be byte-identical).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub verify_tolerance: Option<f64>,
    /// KTX2 supercompression of the level data (`zstd-<level>`); absent: stored uncompressed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub supercompression: Option<String>,
}

impl FileMeta {
    /// Metadata of a text file (sources, JSON, CSV).
    pub fn text(kind: FileKind, format: FileFormat, convention: &str) -> Self {
        Self {
            kind,
            format,
            pixel_format: None,
            width: 0,
            height: 0,
            channels: 0,
            sample_type: SampleType::Text,
            color_space: ColorSpace::NotApplicable,
            convention: convention.into(),
            verify_tolerance: None,
            supercompression: None,
        }
    }
}

/// Declares a closed vocabulary of the manifest: an enum serialised as the listed strings, with `as_str` and
/// `Display` giving the same string (messages print what the manifest holds).
macro_rules! vocabulary {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident = $text:literal,)+ }) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        pub enum $name {
            $($(#[$vdoc])* #[serde(rename = $text)] $variant,)+
        }

        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The string the manifest holds.
            pub fn as_str(self) -> &'static str {
                match self {
                    $($name::$variant => $text,)+
                }
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.as_str())
            }
        }
    };
}

vocabulary! {
    /// What a baked file is (the manifest's `kind`).
    FileKind {
        /// A data texture or table a shader samples.
        Lut = "lut",
        /// An sRGB-encoded picture of a table, for viewing only.
        Preview = "preview",
        /// A C header with a texture's bytes.
        CHeader = "c-header",
        /// A Rust source with a texture's bytes.
        RustSource = "rust-source",
        /// A shader include (HLSL, GLSL, WGSL).
        ShaderInclude = "shader-include",
        /// Bevy asset settings beside a texture.
        BevyMeta = "bevy-meta",
        /// A JSON description, report or parameter file.
        Json = "json",
        /// A CSV table.
        Csv = "csv",
        /// A plot (SVG or PNG).
        Plot = "plot",
        /// A sampling kernel's float payload.
        Kernel = "kernel",
        /// A float table that is not a texture.
        Table = "table",
        /// An input a command was given, kept beside its output.
        Input = "input",
        /// A map written by `rtbake maps`.
        Map = "map",
        /// A rendered frame (`rtbake run smaa --mode`).
        Frame = "frame",
    }
}

vocabulary! {
    /// A baked file's container (the manifest's `format`).
    FileFormat {
        Raw = "raw",
        Dds = "dds",
        Ktx2 = "ktx2",
        Png = "png",
        Exr = "exr",
        C = "c",
        Rust = "rust",
        Hlsl = "hlsl",
        Glsl = "glsl",
        Wgsl = "wgsl",
        Json = "json",
        Csv = "csv",
        Svg = "svg",
        Ron = "ron",
        /// A Markdown text (a report's summary table).
        Md = "md",
    }
}

vocabulary! {
    /// The type of a payload's samples (the manifest's `sample_type`).
    SampleType {
        U8 = "u8",
        U16 = "u16",
        F16 = "f16",
        F32 = "f32",
        /// Not a sampled payload.
        Text = "text",
    }
}

vocabulary! {
    /// How a payload's values are encoded (the manifest's `color_space`).
    ColorSpace {
        /// Linear data: every data texture.
        Linear = "linear",
        /// sRGB-encoded: labelled viewing previews only.
        Srgb = "srgb",
        /// Text.
        NotApplicable = "n/a",
    }
}

impl From<crate::io::source::ShaderLang> for FileFormat {
    fn from(lang: crate::io::source::ShaderLang) -> Self {
        use crate::io::source::ShaderLang;
        match lang {
            ShaderLang::Hlsl => Self::Hlsl,
            ShaderLang::Glsl => Self::Glsl,
            ShaderLang::Wgsl => Self::Wgsl,
        }
    }
}

/// One output file: path relative to the bake directory, its bytes and its metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedFile {
    pub path: String,
    pub bytes: Vec<u8>,
    pub meta: FileMeta,
}

/// One file of the bake.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// Path relative to the bake directory, `/`-separated.
    pub path: String,
    /// Asset that produced it (`rtbake assets`).
    pub asset: String,
    #[serde(flatten)]
    pub meta: FileMeta,
    pub size_bytes: u64,
    pub sha256: String,
}

/// Parameters and model options of one asset, shared by all its files.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AssetRecord {
    pub name: String,
    pub params: Value,
}

/// The whole manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub schema: String,
    pub tool: String,
    pub tool_version: String,
    /// [`SOURCE_TREE`] of the rtbake that baked it (manifests written before 0.1.0's provenance fix stored the
    /// working directory's commit here under the name `git_revision`).
    #[serde(alias = "git_revision")]
    pub source_tree: String,
    /// [`CARGO_LOCK`] of the rtbake that baked it.
    #[serde(default)]
    pub cargo_lock: String,
    pub conventions: Value,
    pub assets: Vec<AssetRecord>,
    pub files: Vec<Entry>,
}

/// Errors reading a manifest.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("{path}: cannot read manifest: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("{path}: corrupted or hand-edited manifest: {detail}")]
    Parse { path: String, detail: String },
}

/// Lower-case hex sha256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// The project-wide conventions recorded in every manifest.
pub fn conventions() -> Value {
    serde_json::json!({
        "row_order": "top row first (texcoord v = 0 is the first stored row, D3D convention)",
        "units": "lengths in mm, coefficients in mm^-1, radial profiles in mm^-2",
        "color_space": "data textures are linear; only files with color_space = srgb are sRGB-encoded previews",
        "determinism": "same bytes for any thread count and across runs",
    })
}

impl Default for Manifest {
    fn default() -> Self {
        Self::new()
    }
}

impl Manifest {
    /// An empty manifest stamped with this build's provenance.
    pub fn new() -> Self {
        Self {
            schema: SCHEMA.into(),
            tool: "rtbake".into(),
            tool_version: env!("CARGO_PKG_VERSION").into(),
            source_tree: SOURCE_TREE.into(),
            cargo_lock: CARGO_LOCK.into(),
            conventions: conventions(),
            assets: Vec::new(),
            files: Vec::new(),
        }
    }

    /// Stamps this build's provenance (`tool_version`, `source_tree`, `cargo_lock`) over what was recorded.
    pub fn stamp_provenance(&mut self) {
        let fresh = Self::new();
        self.tool_version = fresh.tool_version;
        self.source_tree = fresh.source_tree;
        self.cargo_lock = fresh.cargo_lock;
    }

    /// Replaces (or adds) an asset and its files; keeps assets and files sorted.
    pub fn set_asset(&mut self, name: &str, params: Value, files: &[BakedFile]) {
        let digests: Vec<String> = files.iter().map(|f| sha256_hex(&f.bytes)).collect();
        self.set_asset_with_digests(name, params, files, &digests);
    }

    /// [`Self::set_asset`] with the files' [`sha256_hex`] digests computed by the caller (`digests[i]` of
    /// `files[i]`; a bake hashes each asset's files as soon as the asset is done, beside the other assets).
    pub fn set_asset_with_digests(&mut self, name: &str, params: Value, files: &[BakedFile], digests: &[String]) {
        assert_eq!(files.len(), digests.len(), "one digest per file");
        self.assets.retain(|a| a.name != name);
        self.files.retain(|f| f.asset != name);
        self.assets.push(AssetRecord { name: name.into(), params });
        for (f, sha256) in files.iter().zip(digests) {
            self.files.push(Entry {
                path: f.path.clone(),
                asset: name.into(),
                meta: f.meta.clone(),
                size_bytes: f.bytes.len() as u64,
                sha256: sha256.clone(),
            });
        }
        self.assets.sort_by(|a, b| a.name.cmp(&b.name));
        self.files.sort_by(|a, b| a.path.cmp(&b.path));
    }

    /// Deterministic text (pretty JSON, trailing newline).
    pub fn to_text(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("manifest serialises");
        s.push('\n');
        s
    }

    pub fn parse(text: &str, path: &str) -> Result<Self, ManifestError> {
        let m: Manifest = serde_json::from_str(text)
            .map_err(|e| ManifestError::Parse { path: path.into(), detail: e.to_string() })?;
        if m.schema != SCHEMA {
            return Err(ManifestError::Parse {
                path: path.into(),
                detail: format!("schema {:?}, expected {SCHEMA:?}", m.schema),
            });
        }
        Ok(m)
    }

    /// Reads `dir/manifest.json`.
    pub fn load(dir: &Path) -> Result<Self, ManifestError> {
        let path = dir.join(MANIFEST_NAME);
        let p = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| ManifestError::Read { path: p.clone(), source: e })?;
        Self::parse(&text, &p)
    }

    pub fn entry(&self, path: &str) -> Option<&Entry> {
        self.files.iter().find(|f| f.path == path)
    }

    pub fn asset_params(&self, name: &str) -> Option<&Value> {
        self.assets.iter().find(|a| a.name == name).map(|a| &a.params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each closed vocabulary serialises as the string `as_str` names, reads it back, and refuses a word outside it
    /// (the manifest's bytes depend on these strings).
    #[test]
    fn vocabularies_serialise_as_their_manifest_strings() {
        fn check<T: Copy + PartialEq + std::fmt::Debug + Serialize + serde::de::DeserializeOwned>(
            all: &[T],
            as_str: fn(T) -> &'static str,
        ) {
            for &v in all {
                let json = serde_json::to_string(&v).unwrap();
                assert_eq!(json, format!("\"{}\"", as_str(v)));
                assert_eq!(serde_json::from_str::<T>(&json).unwrap(), v);
            }
            assert!(serde_json::from_str::<T>("\"not-a-word\"").is_err());
        }
        check(FileKind::ALL, FileKind::as_str);
        check(FileFormat::ALL, FileFormat::as_str);
        check(SampleType::ALL, SampleType::as_str);
        check(ColorSpace::ALL, ColorSpace::as_str);
        assert_eq!(ColorSpace::NotApplicable.to_string(), "n/a");
        assert_eq!(FileKind::ShaderInclude.as_str(), "shader-include");
    }
}
