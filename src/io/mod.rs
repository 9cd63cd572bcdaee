//! File formats: the only module that knows how bytes are laid out on disk.
//!
//! Every encoder takes a typed buffer (`crate::image_buf::Image`) and returns the file bytes; writing is done
//! by [`atomic`] (temp file in the same directory, fsync, rename) so an interrupted bake never leaves a
//! truncated file. Decoders exist for every format we write (read-back tests, `verify`) and for user inputs.

pub mod atomic;
pub mod bevy_meta;
pub mod dds;
pub mod exr;
pub mod file_set;
pub mod frame_sequence;
pub mod ktx2;
pub mod picture;
pub mod png;
pub mod source;

/// GPU texel formats rtbake writes. Data textures are always linear (never sRGB).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum PixelFormat {
    R8Unorm,
    R8G8Unorm,
    R8G8B8A8Unorm,
    R16Sfloat,
    R16G16Sfloat,
    R16G16B16A16Sfloat,
    R32Sfloat,
    R32G32B32A32Sfloat,
}

impl PixelFormat {
    pub fn channels(self) -> u32 {
        match self {
            Self::R8Unorm | Self::R16Sfloat | Self::R32Sfloat => 1,
            Self::R8G8Unorm | Self::R16G16Sfloat => 2,
            Self::R8G8B8A8Unorm | Self::R16G16B16A16Sfloat | Self::R32G32B32A32Sfloat => 4,
        }
    }
    pub fn bytes_per_texel(self) -> u32 {
        match self {
            Self::R8Unorm => 1,
            Self::R8G8Unorm | Self::R16Sfloat => 2,
            Self::R8G8B8A8Unorm | Self::R16G16Sfloat | Self::R32Sfloat => 4,
            Self::R16G16B16A16Sfloat => 8,
            Self::R32G32B32A32Sfloat => 16,
        }
    }
    /// 8-bit unsigned-normalised formats.
    pub fn is_unorm8(self) -> bool {
        matches!(self, Self::R8Unorm | Self::R8G8Unorm | Self::R8G8B8A8Unorm)
    }
    /// The 8-bit format holding `channels` channels (1, 2 or 4).
    pub fn unorm8_for(channels: u32) -> Option<Self> {
        match channels {
            1 => Some(Self::R8Unorm),
            2 => Some(Self::R8G8Unorm),
            4 => Some(Self::R8G8B8A8Unorm),
            _ => None,
        }
    }
    /// The half-float format holding `channels` channels (3 is padded to 4).
    pub fn f16_for(channels: u32) -> Option<Self> {
        match channels {
            1 => Some(Self::R16Sfloat),
            2 => Some(Self::R16G16Sfloat),
            3 | 4 => Some(Self::R16G16B16A16Sfloat),
            _ => None,
        }
    }
}

/// Errors of the encoders/decoders.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{what}: unsupported layout ({detail})")]
    Unsupported { what: &'static str, detail: String },
    #[error("{path}: cannot decode: {detail}")]
    Decode { path: String, detail: String },
}

impl IoError {
    pub fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        Self::Io { path: path.display().to_string(), source }
    }
}
