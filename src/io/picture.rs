//! An 8-bit picture (PNG or JPEG, e.g. a scanned head's albedo or normal map) decoded with its own channel count,
//! so that a caller can refuse a grey or grey+alpha map by name instead of silently expanding it to RGB. 16-bit
//! and float pictures are reduced to 8 bits per channel, keeping their channel count.

use crate::error::InvalidInput;
use crate::image_buf::ImageU8;

/// Decodes `bytes` (`origin` names the file in messages; `param` the flag) into 8-bit pixels, 1–4 channels.
pub fn decode_u8(param: &str, origin: &str, bytes: &[u8]) -> Result<ImageU8, InvalidInput> {
    use image::DynamicImage as D;
    let img = image::load_from_memory(bytes)
        .map_err(|e| InvalidInput::new(param, format!("{origin}: not a decodable PNG or JPEG picture: {e}")))?;
    let (w, h) = (img.width(), img.height());
    let (channels, data) = match img {
        D::ImageLuma8(i) => (1, i.into_raw()),
        D::ImageLumaA8(i) => (2, i.into_raw()),
        D::ImageRgb8(i) => (3, i.into_raw()),
        D::ImageRgba8(i) => (4, i.into_raw()),
        other => match other.color().channel_count() {
            1 => (1, other.to_luma8().into_raw()),
            2 => (2, other.to_luma_alpha8().into_raw()),
            3 => (3, other.to_rgb8().into_raw()),
            _ => (4, other.to_rgba8().into_raw()),
        },
    };
    Ok(ImageU8::from_vec(w, h, channels, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_counts_are_kept_and_garbage_is_refused_by_flag() {
        let mut png = Vec::new();
        let grey = image::GrayImage::from_raw(4, 4, vec![7u8; 16]).unwrap();
        grey.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
        let img = decode_u8("albedo_map", "grey.png", &png).unwrap();
        assert_eq!((img.width, img.height, img.channels, img.data[0]), (4, 4, 1, 7));
        let e = decode_u8("normal_map", "x.jpg", b"not a picture").unwrap_err();
        assert_eq!(e.param, "normal_map");
        assert!(e.message.contains("x.jpg"), "{e}");
    }
}
