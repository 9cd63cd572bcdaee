//! Decoding of user maps for the facial tools, from bytes (the caller reads the files), with the value mapping
//! stated explicitly. Every error is an [`InvalidInput`] naming the flag and the file.
//!
//! Hemoglobin concentration maps (single channel; values are dermal hemoglobin volume fractions, thesis
//! Table 7.1 range 0–0.32, but any non-negative unit works as long as all maps share it):
//!
//! | file | concentration |
//! | --- | --- |
//! | EXR f16/f32 (one channel) | the stored value |
//! | 16-bit PNG (gray) | `min + (max − min)·s/65535`, default range `[0, 1]` (so `s/65535`) |
//! | 8-bit PNG (gray) | `min + (max − min)·s/255`, **only** with a declared range (`--value-range MIN,MAX`) |
//!
//! Normal maps (RGB or RGBA, alpha ignored): 8/16-bit PNG or EXR, every channel encoded `n = 2·v − 1` with
//! `v ∈ [0, 1]` (`v = s/255` or `s/65535` for PNG, the stored value for EXR).
//! Zone masks (single channel): 8/16-bit PNG (`s/255`, `s/65535`) or EXR with values in [0, 1].

use crate::error::{check_size, InvalidInput};
use crate::image_buf::Image;
use crate::io::{self, png::DecodedPng};

/// Container of an input file, detected from its first bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputFormat {
    Png,
    Exr,
}

/// Detects PNG or OpenEXR from the magic number.
pub fn detect_format(bytes: &[u8]) -> Option<InputFormat> {
    if bytes.starts_with(&[0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n']) {
        Some(InputFormat::Png)
    } else if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        Some(InputFormat::Exr)
    } else {
        None
    }
}

/// Declared mapping of integer samples to concentration: `min + (max − min)·s/smax`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ValueRange {
    pub min: f64,
    pub max: f64,
}

impl ValueRange {
    /// Validates a declared range (finite, 0 ≤ min < max).
    pub fn new(param: &str, min: f64, max: f64) -> Result<Self, InvalidInput> {
        if !(min.is_finite() && max.is_finite() && min >= 0.0 && min < max) {
            return Err(InvalidInput::new(
                param,
                format!("must be MIN,MAX with finite 0 <= MIN < MAX (concentration units), got {min},{max}"),
            ));
        }
        Ok(Self { min, max })
    }
}

/// A decoded concentration map with a description of how its samples were mapped.
#[derive(Clone, Debug, PartialEq)]
pub struct ConcentrationMap {
    pub image: Image<f32>,
    /// `exr-f32`, `exr-f16`, `png16` or `png8`.
    pub source_format: &'static str,
    /// The mapping in words, e.g. `concentration = 0 + (1 - 0) * s / 65535`.
    pub mapping: String,
}

fn bad(param: &str, path: &str, msg: impl std::fmt::Display) -> InvalidInput {
    InvalidInput::new(param, format!("{path}: {msg}"))
}

fn decode_err(param: &str, path: &str, e: io::IoError) -> InvalidInput {
    let msg = e.to_string();
    let msg = msg.strip_prefix(&format!("{path}: ")).unwrap_or(&msg).to_string();
    bad(param, path, format!("corrupt or unsupported image: {msg}"))
}

fn check_dims(param: &str, path: &str, w: u32, h: u32) -> Result<(), InvalidInput> {
    check_size(param, w as u64, h as u64).map(|_| ()).map_err(|e| bad(param, path, e.message))
}

fn format_of(param: &str, path: &str, bytes: &[u8]) -> Result<InputFormat, InvalidInput> {
    if bytes.is_empty() {
        return Err(bad(param, path, "file is empty"));
    }
    detect_format(bytes).ok_or_else(|| bad(param, path, "not a PNG or OpenEXR file"))
}

/// Decodes a hemoglobin concentration map (see the module table). `range` applies to PNG inputs only.
pub fn decode_concentration(
    param: &str,
    path: &str,
    bytes: &[u8],
    range: Option<ValueRange>,
) -> Result<ConcentrationMap, InvalidInput> {
    let (image, source_format, mapping) = match format_of(param, path, bytes)? {
        InputFormat::Exr => {
            let (img, prec) = io::exr::decode(bytes, path).map_err(|e| decode_err(param, path, e))?;
            let fmt = match prec {
                io::exr::ExrPrecision::F16 => "exr-f16",
                io::exr::ExrPrecision::F32 => "exr-f32",
            };
            (img, fmt, "concentration = stored value".to_string())
        }
        InputFormat::Png => {
            let decoded = io::png::decode(bytes, path).map_err(|e| decode_err(param, path, e))?;
            let (w, h, ch, samples, smax, fmt): (u32, u32, u32, Vec<f64>, f64, &'static str) = match decoded {
                DecodedPng::U8(i) => {
                    (i.width, i.height, i.channels, i.data.iter().map(|&s| s as f64).collect(), 255.0, "png8")
                }
                DecodedPng::U16(i) => {
                    (i.width, i.height, i.channels, i.data.iter().map(|&s| s as f64).collect(), 65535.0, "png16")
                }
            };
            if ch != 1 {
                return Err(bad(param, path, format!("expected a single-channel (gray) map, got {ch} channels")));
            }
            let r = match (range, fmt) {
                (Some(r), _) => r,
                (None, "png16") => ValueRange { min: 0.0, max: 1.0 },
                (None, _) => {
                    return Err(bad(
                        param,
                        path,
                        "8-bit PNG maps need a declared value range: --value-range MIN,MAX maps samples 0..255 \
                         linearly to concentrations MIN..MAX",
                    ))
                }
            };
            let data = samples.iter().map(|&s| (r.min + (r.max - r.min) * s / smax) as f32).collect();
            let mapping = format!("concentration = {} + ({} - {}) * s / {}", r.min, r.max, r.min, smax);
            (Image::from_vec(w, h, 1, data), fmt, mapping)
        }
    };
    check_dims(param, path, image.width, image.height)?;
    if image.channels != 1 {
        return Err(bad(param, path, format!("expected a single-channel map, got {} channels", image.channels)));
    }
    if let Some(i) = image.data.iter().position(|v| !v.is_finite() || *v < 0.0) {
        let (x, y) = (i as u32 % image.width, i as u32 / image.width);
        return Err(bad(
            param,
            path,
            format!("texel ({x}, {y}) is {}; concentrations must be finite and >= 0", image.data[i]),
        ));
    }
    Ok(ConcentrationMap { image, source_format, mapping })
}

/// Decodes an encoded normal map to `n = 2·v − 1` per channel (3 channels, alpha dropped; not normalised).
pub fn decode_normal_map(param: &str, path: &str, bytes: &[u8]) -> Result<Image<f32>, InvalidInput> {
    let (w, h, ch, values): (u32, u32, u32, Vec<f64>) = match format_of(param, path, bytes)? {
        InputFormat::Exr => {
            let (img, _) = io::exr::decode(bytes, path).map_err(|e| decode_err(param, path, e))?;
            (img.width, img.height, img.channels, img.data.iter().map(|&v| v as f64).collect())
        }
        InputFormat::Png => match io::png::decode(bytes, path).map_err(|e| decode_err(param, path, e))? {
            DecodedPng::U8(i) => (i.width, i.height, i.channels, i.data.iter().map(|&s| s as f64 / 255.0).collect()),
            DecodedPng::U16(i) => (i.width, i.height, i.channels, i.data.iter().map(|&s| s as f64 / 65535.0).collect()),
        },
    };
    check_dims(param, path, w, h)?;
    if ch != 3 && ch != 4 {
        return Err(bad(param, path, format!("a normal map needs 3 (RGB) or 4 (RGBA) channels, got {ch}")));
    }
    let mut data = Vec::with_capacity((w * h * 3) as usize);
    for (i, px) in values.chunks_exact(ch as usize).enumerate() {
        for &v in &px[..3] {
            if !v.is_finite() {
                let (x, y) = (i as u32 % w, i as u32 / w);
                return Err(bad(param, path, format!("texel ({x}, {y}) is not finite")));
            }
            data.push((2.0 * v - 1.0) as f32);
        }
    }
    Ok(Image::from_vec(w, h, 3, data))
}

/// Decodes a zone mask (single channel, values in [0, 1]).
pub fn decode_mask(param: &str, path: &str, bytes: &[u8]) -> Result<Image<f32>, InvalidInput> {
    let img: Image<f32> = match format_of(param, path, bytes)? {
        InputFormat::Exr => io::exr::decode(bytes, path).map_err(|e| decode_err(param, path, e))?.0,
        InputFormat::Png => match io::png::decode(bytes, path).map_err(|e| decode_err(param, path, e))? {
            DecodedPng::U8(i) => {
                Image::from_vec(i.width, i.height, i.channels, i.data.iter().map(|&s| s as f32 / 255.0).collect())
            }
            DecodedPng::U16(i) => Image::from_vec(
                i.width,
                i.height,
                i.channels,
                i.data.iter().map(|&s| (s as f64 / 65535.0) as f32).collect(),
            ),
        },
    };
    check_dims(param, path, img.width, img.height)?;
    if img.channels != 1 {
        return Err(bad(
            param,
            path,
            format!("a zone mask must be single-channel (gray), got {} channels", img.channels),
        ));
    }
    if let Some(i) = img.data.iter().position(|v| !(0.0..=1.0).contains(v)) {
        let (x, y) = (i as u32 % img.width, i as u32 / img.width);
        return Err(bad(param, path, format!("texel ({x}, {y}) is {}; mask values must be in 0..=1", img.data[i])));
    }
    Ok(img)
}
