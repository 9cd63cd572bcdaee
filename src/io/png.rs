//! PNG encoding/decoding (via the `image` crate).
//!
//! Channel mapping: 1 channel → gray, **2 channels (RG) → gray + alpha** (R in gray, G in alpha),
//! 3 → RGB, 4 → RGBA. 8-bit PNGs of data textures hold the raw bytes (linear data, no gamma chunk);
//! previews of float data are sRGB-encoded and labelled as such in the manifest.

use super::IoError;
use crate::image_buf::{Image, ImageF32};
use image::{ExtendedColorType, ImageEncoder};

fn color_type(channels: u32, sixteen: bool) -> Result<ExtendedColorType, IoError> {
    Ok(match (channels, sixteen) {
        (1, false) => ExtendedColorType::L8,
        (2, false) => ExtendedColorType::La8,
        (3, false) => ExtendedColorType::Rgb8,
        (4, false) => ExtendedColorType::Rgba8,
        (1, true) => ExtendedColorType::L16,
        (2, true) => ExtendedColorType::La16,
        (3, true) => ExtendedColorType::Rgb16,
        (4, true) => ExtendedColorType::Rgba16,
        _ => return Err(IoError::Unsupported { what: "png", detail: format!("{channels} channels") }),
    })
}

fn encode(bytes: &[u8], w: u32, h: u32, ct: ExtendedColorType) -> Result<Vec<u8>, IoError> {
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut out,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    )
    .write_image(bytes, w, h, ct)
    .map_err(|e| IoError::Unsupported { what: "png", detail: e.to_string() })?;
    Ok(out)
}

/// 8-bit PNG holding the bytes of `img` unchanged.
pub fn encode_u8(img: &Image<u8>) -> Result<Vec<u8>, IoError> {
    encode(&img.data, img.width, img.height, color_type(img.channels, false)?)
}

/// 16-bit PNG holding the samples of `img` unchanged.
pub fn encode_u16(img: &Image<u16>) -> Result<Vec<u8>, IoError> {
    // The encoder takes native-endian samples and writes big-endian PNG.
    encode(bytemuck::cast_slice(&img.data), img.width, img.height, color_type(img.channels, true)?)
}

/// Linear float → 16-bit linear PNG: value v in [0, 1] stored as round(65535·v) (clamped).
pub fn encode_linear16(img: &ImageF32) -> Result<Vec<u8>, IoError> {
    let data = img.data.iter().map(|&v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16).collect();
    encode_u16(&Image::from_vec(img.width, img.height, img.channels, data))
}

/// IEC 61966-2-1 sRGB encoding of a linear value in [0, 1].
pub fn srgb_encode(linear: f64) -> f64 {
    let v = linear.clamp(0.0, 1.0);
    if v <= 0.0031308 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear float → 8-bit **sRGB-encoded** preview (for viewing only; alpha, if any, stays linear).
pub fn encode_srgb_preview(img: &ImageF32) -> Result<Vec<u8>, IoError> {
    let ch = img.channels;
    let data: Vec<u8> = img
        .data
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let c = i as u32 % ch;
            let e = if ch == 4 && c == 3 { (v as f64).clamp(0.0, 1.0) } else { srgb_encode(v as f64) };
            (e * 255.0).round() as u8
        })
        .collect();
    encode_u8(&Image::from_vec(img.width, img.height, ch, data))
}

/// A decoded PNG: 8- or 16-bit samples.
pub enum DecodedPng {
    U8(Image<u8>),
    U16(Image<u16>),
}

/// Decodes a PNG keeping its channel count and bit depth.
pub fn decode(bytes: &[u8], path: &str) -> Result<DecodedPng, IoError> {
    let err = |e: image::ImageError| IoError::Decode { path: path.to_string(), detail: e.to_string() };
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png).map_err(err)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rg8_round_trips_as_gray_alpha() {
        let img = Image::from_vec(3, 2, 2, (0..12u8).map(|v| v * 20).collect());
        let bytes = encode_u8(&img).unwrap();
        match decode(&bytes, "t").unwrap() {
            DecodedPng::U8(back) => assert_eq!(back, img),
            _ => panic!("expected 8-bit"),
        }
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
