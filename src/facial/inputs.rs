//! Decoding of user maps for the facial tools, from bytes (the caller reads the files), with the value mapping
//! stated explicitly. Every error is an [`InvalidInput`] naming the flag and the file.
//!
//! Hemoglobin concentration maps (values are dermal hemoglobin volume fractions, thesis Table 7.1 range 0–0.32,
//! but any non-negative unit works as long as all maps share it):
//!
//! | file | concentration |
//! | --- | --- |
//! | EXR f16/f32 | the stored value |
//! | 16-bit PNG | `min + (max − min)·s/65535`, default range `[0, 1]` (so `s/65535`) |
//! | 8-bit PNG | `min + (max − min)·s/255`, **only** with a declared range (`--value-range MIN,MAX`) |
//!
//! A single-channel map (EXR `Y`, gray PNG) is read as is. A map with several channels (EXR `R,G[,B[,A]]`, PNG
//! gray+alpha, RGB, RGBA — what most painting tools write) needs a [`ChannelSelect`] (`--channel`): one stored
//! channel, or `luminance` = 0.2126·R + 0.7152·G + 0.0722·B (Rec. 709 / linear-sRGB weights, applied to the
//! mapped values, alpha ignored).
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

/// Which channel of a multi-channel concentration map holds the concentration (`--channel`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ChannelSelect {
    R,
    G,
    B,
    A,
    /// The gray channel: a single-channel map, or the gray of a gray+alpha PNG.
    Y,
    /// 0.2126·R + 0.7152·G + 0.0722·B of an RGB(A) map (gray of a gray map).
    Luminance,
}

/// Accepted spellings of [`ChannelSelect`].
pub const CHANNEL_NAMES: [&str; 6] = ["R", "G", "B", "A", "Y", "luminance"];

impl ChannelSelect {
    /// Parses `R|G|B|A|Y|luminance` (case-insensitive), naming `param` on error.
    pub fn parse(param: &str, s: &str) -> Result<Self, InvalidInput> {
        Ok(match s.to_ascii_lowercase().as_str() {
            "r" => Self::R,
            "g" => Self::G,
            "b" => Self::B,
            "a" => Self::A,
            "y" => Self::Y,
            "luminance" => Self::Luminance,
            _ => {
                return Err(InvalidInput::new(param, format!("must be one of {}, got {s:?}", CHANNEL_NAMES.join(", "))))
            }
        })
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Self::R => "R",
            Self::G => "G",
            Self::B => "B",
            Self::A => "A",
            Self::Y => "Y",
            Self::Luminance => "luminance",
        }
    }
}

/// Channel names of a decoded map, in storage order.
fn stored_channel_names(format: InputFormat, channels: u32) -> &'static [&'static str] {
    match (format, channels) {
        (_, 1) => &["Y"],
        (InputFormat::Png, 2) => &["Y", "A"],
        (InputFormat::Exr, 2) => &["R", "G"],
        (_, 3) => &["R", "G", "B"],
        _ => &["R", "G", "B", "A"],
    }
}

/// Reduces `image` to one channel by `select` (None: the map must have one channel). Returns the image and the
/// words recorded in the mapping (`""` for a single-channel map read as is).
fn select_channel(
    param: &str,
    path: &str,
    format: InputFormat,
    image: Image<f32>,
    select: Option<ChannelSelect>,
) -> Result<(Image<f32>, String), InvalidInput> {
    let names = stored_channel_names(format, image.channels);
    let n = image.channels as usize;
    let pick = |c: usize| -> Image<f32> {
        let data = image.data.chunks_exact(n).map(|px| px[c]).collect();
        Image::from_vec(image.width, image.height, 1, data)
    };
    let index = |name: &str| names.iter().position(|x| *x == name);
    match select {
        None if n == 1 => Ok((image, String::new())),
        None => Err(bad(
            param,
            path,
            format!(
                "expected a single-channel map, got {n} channels ({}); choose one with `channel` {}",
                names.join(", "),
                CHANNEL_NAMES.join("|")
            ),
        )),
        Some(ChannelSelect::Luminance) => {
            if n == 1 || names == ["Y", "A"] {
                return Ok((pick(0), " (luminance of a gray map = its gray channel Y)".into()));
            }
            let (r, g, b) = match (index("R"), index("G"), index("B")) {
                (Some(r), Some(g), Some(b)) => (r, g, b),
                _ => {
                    return Err(bad(
                        param,
                        path,
                        format!("`channel` luminance needs R, G and B channels; the map has {}", names.join(", ")),
                    ))
                }
            };
            let data = image
                .data
                .chunks_exact(n)
                .map(|px| (0.2126 * px[r] as f64 + 0.7152 * px[g] as f64 + 0.0722 * px[b] as f64) as f32)
                .collect();
            Ok((
                Image::from_vec(image.width, image.height, 1, data),
                " (luminance 0.2126 R + 0.7152 G + 0.0722 B)".into(),
            ))
        }
        Some(sel) => match index(sel.as_str()) {
            Some(c) => Ok((pick(c), format!(" (channel {})", sel.as_str()))),
            None => {
                Err(bad(param, path, format!("`channel` {}: the map has channels {}", sel.as_str(), names.join(", "))))
            }
        },
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

/// Decodes a single-channel hemoglobin concentration map (see the module table). `range` applies to PNG inputs
/// only.
pub fn decode_concentration(
    param: &str,
    path: &str,
    bytes: &[u8],
    range: Option<ValueRange>,
) -> Result<ConcentrationMap, InvalidInput> {
    decode_concentration_channel(param, path, bytes, range, None)
}

/// Decodes a hemoglobin concentration map, reducing a multi-channel map to one channel by `channel` (see the
/// module docs; `None` requires a single-channel map).
pub fn decode_concentration_channel(
    param: &str,
    path: &str,
    bytes: &[u8],
    range: Option<ValueRange>,
    channel: Option<ChannelSelect>,
) -> Result<ConcentrationMap, InvalidInput> {
    let format = format_of(param, path, bytes)?;
    let (image, source_format, mapping) = match format {
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
            let r = match (range, fmt) {
                (Some(r), _) => r,
                (None, "png16") => ValueRange { min: 0.0, max: 1.0 },
                (None, _) => {
                    return Err(bad(
                        param,
                        path,
                        "8-bit PNG maps need a declared value range: `value_range` MIN,MAX maps samples 0..255 \
                         linearly to concentrations MIN..MAX",
                    ))
                }
            };
            let data = samples.iter().map(|&s| (r.min + (r.max - r.min) * s / smax) as f32).collect();
            let mapping = format!("concentration = {} + ({} - {}) * s / {}", r.min, r.max, r.min, smax);
            (Image::from_vec(w, h, ch, data), fmt, mapping)
        }
    };
    check_dims(param, path, image.width, image.height)?;
    let (image, channel_words) = select_channel(param, path, format, image, channel)?;
    let mapping = format!("{mapping}{channel_words}");
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::exr::{encode, ExrPrecision};

    /// 3 × 2 RGB(A) EXR with R = i/10, G = 2·R, B = 0.05, A = 1.
    fn exr(channels: u32) -> Vec<u8> {
        let mut data = Vec::new();
        for i in 0..6 {
            let r = i as f32 / 10.0;
            data.extend_from_slice(&[r, 2.0 * r, 0.05, 1.0][..channels as usize]);
        }
        encode(&Image::from_vec(3, 2, channels, data), ExrPrecision::F32).unwrap()
    }

    fn decode(bytes: &[u8], sel: Option<ChannelSelect>) -> Result<ConcentrationMap, InvalidInput> {
        decode_concentration_channel("neutral", "n.exr", bytes, None, sel)
    }

    #[test]
    fn rgb_exr_needs_a_channel_and_reads_the_chosen_one() {
        for ch in [3, 4] {
            let bytes = exr(ch);
            let e = decode(&bytes, None).unwrap_err();
            assert_eq!(e.param, "neutral");
            assert!(e.message.contains("n.exr") && e.message.contains("`channel` R|G|B|A|Y|luminance"), "{e}");
            let r = decode(&bytes, Some(ChannelSelect::R)).unwrap();
            assert_eq!(r.image.channels, 1);
            assert_eq!(r.image.data, (0..6).map(|i| i as f32 / 10.0).collect::<Vec<_>>());
            assert!(r.mapping.ends_with("(channel R)"), "{}", r.mapping);
            let g = decode(&bytes, Some(ChannelSelect::G)).unwrap();
            assert_eq!(g.image.data, (0..6).map(|i| 2.0 * (i as f32 / 10.0)).collect::<Vec<_>>());
            let y = decode(&bytes, Some(ChannelSelect::Luminance)).unwrap();
            for (i, v) in y.image.data.iter().enumerate() {
                let r = i as f64 / 10.0;
                let want = 0.2126 * r + 0.7152 * 2.0 * r + 0.0722 * 0.05;
                assert!((*v as f64 - want).abs() < 1e-6, "texel {i}: {v} vs {want}");
            }
        }
        let e = decode(&exr(3), Some(ChannelSelect::A)).unwrap_err();
        assert!(e.message.contains("`channel` A") && e.message.contains("R, G, B"), "{e}");
        assert_eq!(decode(&exr(4), Some(ChannelSelect::A)).unwrap().image.data, vec![1.0; 6]);
    }

    #[test]
    fn single_channel_maps_are_read_as_is_and_y_selects_them() {
        let bytes = encode(&Image::from_vec(2, 1, 1, vec![0.1, 0.2]), ExrPrecision::F32).unwrap();
        assert_eq!(decode(&bytes, None).unwrap().image.data, vec![0.1, 0.2]);
        assert_eq!(decode(&bytes, Some(ChannelSelect::Y)).unwrap().image.data, vec![0.1, 0.2]);
        assert_eq!(decode(&bytes, Some(ChannelSelect::Luminance)).unwrap().image.data, vec![0.1, 0.2]);
        assert!(decode(&bytes, Some(ChannelSelect::G)).unwrap_err().message.contains("channels Y"));
    }

    #[test]
    fn channel_names_parse_case_insensitively_and_bad_ones_name_the_flag() {
        assert_eq!(ChannelSelect::parse("channel", "r").unwrap(), ChannelSelect::R);
        assert_eq!(ChannelSelect::parse("channel", "Luminance").unwrap(), ChannelSelect::Luminance);
        let e = ChannelSelect::parse("channel", "X").unwrap_err();
        assert_eq!(e.param, "channel");
        assert!(e.message.contains("R, G, B, A, Y, luminance"));
    }

    #[test]
    fn negative_selected_channel_is_refused_with_its_texel() {
        let bytes = encode(&Image::from_vec(1, 1, 3, vec![0.1, -0.5, 0.0]), ExrPrecision::F32).unwrap();
        assert!(decode(&bytes, Some(ChannelSelect::R)).is_ok());
        assert!(decode(&bytes, Some(ChannelSelect::G)).unwrap_err().message.contains("texel (0, 0)"));
    }
}
