//! PNG encoding (via the `png` crate, for the colour chunks) and decoding (via the `image` crate).
//!
//! Channel mapping for what engines load (Bevy, three.js, browsers, Unity): 1 channel → gray, **2 channels (RG) →
//! RGB with R, G in red and green and B = 0** (gray + alpha would be expanded to (R, R, R, G) and put G in `.a`),
//! 3 → RGB, 4 → RGBA. Every PNG says its colour space so colour-managed readers (OIIO, browsers) do not guess
//! (PNG Third Edition §11.3.2): data is tagged [`PngColor::Linear`] (`gAMA` 1.0 and `cICP` BT.709 / linear /
//! full range), viewing images [`PngColor::Srgb`] (`sRGB` chunk with its `gAMA`/`cHRM` fallbacks and `cICP`
//! BT.709 / IEC 61966-2-1 / full range).

use super::IoError;
use crate::image_buf::{Image, ImageF32};

/// Colour space a PNG declares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PngColor {
    /// Linear data (LUTs, maps): `gAMA` = 100000 (γ 1.0), `cICP` 1/8/0/1.
    Linear,
    /// sRGB-encoded image for viewing: `sRGB` (perceptual), `gAMA` 45455, `cHRM` BT.709, `cICP` 1/13/0/1.
    Srgb,
}

/// ITU-T H.273 transfer characteristics: 8 = linear, 13 = IEC 61966-2-1 (sRGB).
const CICP_TRANSFER_LINEAR: u8 = 8;
const CICP_TRANSFER_SRGB: u8 = 13;

fn color_type(channels: u32) -> Result<png::ColorType, IoError> {
    Ok(match channels {
        1 => png::ColorType::Grayscale,
        3 => png::ColorType::Rgb,
        4 => png::ColorType::Rgba,
        _ => return Err(IoError::Unsupported { what: "png", detail: format!("{channels} channels") }),
    })
}

/// Samples of a 2-channel image widened to RGB with B = 0 (`zero` is the zero sample).
fn rg_to_rgb<T: Copy>(data: &[T], zero: T) -> Vec<T> {
    data.chunks_exact(2).flat_map(|rg| [rg[0], rg[1], zero]).collect()
}

fn encode(bytes: &[u8], w: u32, h: u32, channels: u32, sixteen: bool, color: PngColor) -> Result<Vec<u8>, IoError> {
    encode_with(bytes, w, h, channels, sixteen, color, png::Compression::High)
}

fn encode_with(
    bytes: &[u8],
    w: u32,
    h: u32,
    channels: u32,
    sixteen: bool,
    color: PngColor,
    compression: png::Compression,
) -> Result<Vec<u8>, IoError> {
    let err = |e: png::EncodingError| IoError::Unsupported { what: "png", detail: e.to_string() };
    let mut info = png::Info::with_size(w, h);
    info.color_type = color_type(channels)?;
    info.bit_depth = if sixteen { png::BitDepth::Sixteen } else { png::BitDepth::Eight };
    let transfer = match color {
        PngColor::Linear => {
            info.source_gamma = Some(png::ScaledFloat::from_scaled(100_000));
            CICP_TRANSFER_LINEAR
        }
        PngColor::Srgb => {
            info.srgb = Some(png::SrgbRenderingIntent::Perceptual);
            info.source_gamma = Some(png::ScaledFloat::from_scaled(45_455));
            info.source_chromaticities =
                Some(png::SourceChromaticities::new((0.3127, 0.3290), (0.64, 0.33), (0.30, 0.60), (0.15, 0.06)));
            CICP_TRANSFER_SRGB
        }
    };
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::with_info(&mut out, info).map_err(err)?;
        enc.set_compression(compression);
        let mut writer = enc.write_header().map_err(err)?;
        // cICP (PNG Third Edition §11.3.2.6): BT.709 primaries, transfer, RGB (matrix 0), full range. The
        // encoder does not write `Info::coding_independent_code_points`, so the chunk is written here, before IDAT.
        writer.write_chunk(png::chunk::cICP, &[1, transfer, 0, 1]).map_err(err)?;
        writer.write_image_data(bytes).map_err(err)?;
        writer.finish().map_err(err)?;
    }
    Ok(out)
}

/// 8-bit PNG of linear data: the bytes of `img` unchanged (RG widened to RGB with B = 0), tagged linear.
pub fn encode_u8(img: &Image<u8>) -> Result<Vec<u8>, IoError> {
    encode_u8_as(img, PngColor::Linear)
}

/// 8-bit PNG holding the bytes of `img` (RG widened to RGB with B = 0) with the given colour tag.
pub fn encode_u8_as(img: &Image<u8>, color: PngColor) -> Result<Vec<u8>, IoError> {
    if img.channels == 2 {
        return encode(&rg_to_rgb(&img.data, 0), img.width, img.height, 3, false, color);
    }
    encode(&img.data, img.width, img.height, img.channels, false, color)
}

/// A rendered 8-bit **sRGB-encoded** frame (`rtbake run` outputs) tagged sRGB, with fast compression: frames are
/// looked at, not archived, and at 1080p the default compression cost more than the pass itself.
pub fn encode_u8_frame(img: &Image<u8>) -> Result<Vec<u8>, IoError> {
    if img.channels == 2 {
        return Err(IoError::Unsupported { what: "png", detail: "a frame has 1, 3 or 4 channels".into() });
    }
    encode_with(&img.data, img.width, img.height, img.channels, false, PngColor::Srgb, png::Compression::Fast)
}

/// 16-bit PNG of linear data: the samples of `img` unchanged (RG widened to RGB with B = 0), tagged linear.
pub fn encode_u16(img: &Image<u16>) -> Result<Vec<u8>, IoError> {
    let (data, channels) =
        if img.channels == 2 { (rg_to_rgb(&img.data, 0), 3) } else { (img.data.clone(), img.channels) };
    let be: Vec<u8> = data.iter().flat_map(|v| v.to_be_bytes()).collect();
    encode(&be, img.width, img.height, channels, true, PngColor::Linear)
}

/// Linear float → 16-bit linear PNG: value v in [0, 1] stored as round(65535·v) (clamped).
pub fn encode_linear16(img: &ImageF32) -> Result<Vec<u8>, IoError> {
    let data = img.data.iter().map(|&v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16).collect();
    encode_u16(&Image::from_vec(img.width, img.height, img.channels, data))
}

/// The RGB colours of a float table (1–4 channels; missing colour channels 0, alpha dropped) sRGB-encoded to 8 bits,
/// for labelled previews (`crate::plot::preview`).
pub fn srgb_preview_pixels(img: &ImageF32) -> Image<u8> {
    let ch = img.channels as usize;
    let mut data = Vec::with_capacity(img.data.len() / ch * 3);
    for px in img.data.chunks_exact(ch) {
        for c in 0..3 {
            // One channel is shown grey; two are R, G with B = 0.
            let v = if ch == 1 {
                px[0] as f64
            } else if c < ch.min(3) {
                px[c] as f64
            } else {
                0.0
            };
            data.push((crate::color::srgb::encode(v) * 255.0).round() as u8);
        }
    }
    Image::from_vec(img.width, img.height, 3, data)
}

/// Linear float → 8-bit **sRGB-encoded** preview tagged sRGB (for viewing only; alpha, if any, stays linear).
pub fn encode_srgb_preview(img: &ImageF32) -> Result<Vec<u8>, IoError> {
    let ch = img.channels;
    let data: Vec<u8> = img
        .data
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let c = i as u32 % ch;
            let e = if ch == 4 && c == 3 { (v as f64).clamp(0.0, 1.0) } else { crate::color::srgb::encode(v as f64) };
            (e * 255.0).round() as u8
        })
        .collect();
    encode_u8_as(&Image::from_vec(img.width, img.height, ch, data), PngColor::Srgb)
}

/// The chunk types of a PNG file in order (`IHDR`, `gAMA`, …), for tests and checks.
pub fn chunk_types(bytes: &[u8]) -> Vec<[u8; 4]> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 8 <= bytes.len() {
        let len = u32::from_be_bytes(bytes[at..at + 4].try_into().expect("4 bytes")) as usize;
        out.push(bytes[at + 4..at + 8].try_into().expect("4 bytes"));
        at += 12 + len;
    }
    out
}

/// A decoded PNG: 8- or 16-bit samples.
pub enum DecodedPng {
    U8(Image<u8>),
    U16(Image<u16>),
}

/// Decodes a PNG keeping its channel count and bit depth.
pub fn decode(bytes: &[u8], path: &str) -> Result<DecodedPng, IoError> {
    let edge = crate::error::MAX_TEXTURE_EDGE;
    let err = |e: image::ImageError| {
        let detail = match &e {
            image::ImageError::Limits(_) => {
                format!("{e} (accepted: width and height up to {edge} texels, 8 or 16 bits, 1 to 4 channels)")
            }
            _ => e.to_string(),
        };
        IoError::Decode { path: path.to_string(), detail }
    };
    // rtbake's own size range, not the decoder's default 512 MiB allocation cap (which refused 16384² RGBA8 inputs
    // that --help allows); the commands then check their memory budget against the decoded size.
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(edge);
    limits.max_image_height = Some(edge);
    limits.max_alloc = Some(edge as u64 * edge as u64 * 8 + (64 << 20));
    let mut reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
    reader.limits(limits);
    let img = reader.decode().map_err(err)?;
    let (w, h) = (img.width(), img.height());
    use image::DynamicImage as D;
    Ok(match img {
        D::ImageLuma8(b) => DecodedPng::U8(Image::from_vec(w, h, 1, b.into_raw())),
        D::ImageLumaA8(b) => DecodedPng::U8(Image::from_vec(w, h, 2, b.into_raw())),
        D::ImageRgb8(b) => DecodedPng::U8(Image::from_vec(w, h, 3, b.into_raw())),
        D::ImageRgba8(b) => DecodedPng::U8(Image::from_vec(w, h, 4, b.into_raw())),
        D::ImageLuma16(b) => DecodedPng::U16(Image::from_vec(w, h, 1, b.into_raw())),
        D::ImageLumaA16(b) => DecodedPng::U16(Image::from_vec(w, h, 2, b.into_raw())),
        D::ImageRgb16(b) => DecodedPng::U16(Image::from_vec(w, h, 3, b.into_raw())),
        D::ImageRgba16(b) => DecodedPng::U16(Image::from_vec(w, h, 4, b.into_raw())),
        other => {
            return Err(IoError::Decode {
                path: path.to_string(),
                detail: format!("unsupported PNG layout {:?}", other.color()),
            })
        }
    })
}

impl DecodedPng {
    /// The 8-bit samples as `channels` channels: an RG texture stored as RGB (B = 0) comes back as RG.
    /// `None` if the file is 16-bit or its layout does not hold `channels` channels that way.
    pub fn into_u8_channels(self, channels: u32) -> Option<Image<u8>> {
        match self {
            DecodedPng::U8(img) if img.channels == channels => Some(img),
            DecodedPng::U8(img) if channels == 2 && img.channels == 3 => {
                let rg = img.data.chunks_exact(3).flat_map(|p| [p[0], p[1]]).collect();
                Some(Image::from_vec(img.width, img.height, 2, rg))
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn decode_accepts_rtbakes_size_range_and_names_it_beyond() {
        // 16385 × 1 is beyond the edge range: refused by the decoder's limits, with the accepted range named.
        let wide = Image::from_vec(16385, 1, 1, vec![7u8; 16385]);
        let Err(e) = decode(&encode_u8(&wide).unwrap(), "wide.png") else { panic!("16385 wide decoded") };
        let e = e.to_string();
        assert!(e.contains("wide.png") && e.contains("up to 16384"), "{e}");
        let ok = Image::from_vec(16384, 2, 4, vec![9u8; 16384 * 2 * 4]);
        let decoded = decode(&encode_u8(&ok).unwrap(), "ok.png");
        assert!(matches!(decoded, Ok(DecodedPng::U8(ref i)) if i.width == 16384));
    }

    use super::*;

    #[test]
    fn rg8_is_stored_as_rgb_with_zero_blue_and_tagged_linear() {
        let img = Image::from_vec(3, 2, 2, (0..12u8).map(|v| v * 20 + 1).collect());
        let bytes = encode_u8(&img).unwrap();
        // IHDR colour type 2 (truecolour), bit depth 8.
        assert_eq!((bytes[24], bytes[25]), (8, 2));
        match decode(&bytes, "t").unwrap() {
            DecodedPng::U8(rgb) => {
                assert_eq!(rgb.channels, 3);
                assert!(rgb.data.chunks_exact(3).all(|p| p[2] == 0));
                assert_eq!(DecodedPng::U8(rgb).into_u8_channels(2).unwrap(), img);
            }
            _ => panic!("expected 8-bit"),
        }
        let chunks = chunk_types(&bytes);
        assert!(chunks.contains(b"gAMA") && chunks.contains(b"cICP") && !chunks.contains(b"sRGB"), "{chunks:?}");
        let at = bytes.windows(4).position(|w| w == b"gAMA").unwrap();
        assert_eq!(u32::from_be_bytes(bytes[at + 4..at + 8].try_into().unwrap()), 100_000);
        let at = bytes.windows(4).position(|w| w == b"cICP").unwrap();
        assert_eq!(&bytes[at + 4..at + 8], &[1, 8, 0, 1]);
    }

    #[test]
    fn previews_are_tagged_srgb() {
        let img = Image::from_vec(1, 1, 3, vec![0.5f32; 3]);
        let bytes = encode_srgb_preview(&img).unwrap();
        let chunks = chunk_types(&bytes);
        assert!(chunks.contains(b"sRGB") && chunks.contains(b"cICP"), "{chunks:?}");
        let at = bytes.windows(4).position(|w| w == b"cICP").unwrap();
        assert_eq!(&bytes[at + 4..at + 8], &[1, 13, 0, 1]);
    }

    #[test]
    fn u16_round_trips() {
        let img = Image::from_vec(2, 2, 1, vec![0u16, 1, 40000, 65535]);
        match decode(&encode_u16(&img).unwrap(), "t").unwrap() {
            DecodedPng::U16(back) => assert_eq!(back, img),
            _ => panic!("expected 16-bit"),
        }
    }

    #[test]
    fn srgb_preview_encodes_mid_grey() {
        let img = Image::from_vec(1, 1, 3, vec![0.214_041_14f32; 3]);
        match decode(&encode_srgb_preview(&img).unwrap(), "t").unwrap() {
            DecodedPng::U8(back) => assert_eq!(back.data, vec![128, 128, 128]),
            _ => panic!(),
        }
    }
}
