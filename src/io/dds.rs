//! DDS with the DX10 extended header (via `ddsfile`): real two-channel formats, unlike the 24-bit RGB files
//! upstream SMAA ships labelled as R8G8. Supported: `R8_UNORM`, `R8G8_UNORM`, `R8G8B8A8_UNORM`,
//! `R16G16B16A16_FLOAT`, `R32G32B32A32_FLOAT`. Data textures are non-sRGB.
//!
//! The legacy pixel-format block of a DX10 file says FourCC only (`dwFlags = DDPF_FOURCC`, bit count and masks
//! 0), as the DDS programming guide specifies: `ddsfile` also sets `DDPF_RGB` and a bit count there, and readers
//! that follow the flags (Pillow, ImageMagick) then decode the file as uncompressed RGB — black or garbage.
//!
//! Readers that know no DX10 header (ImageMagick 6, OpenImageIO 2.4, older engines) get a legacy-header copy where
//! an exact D3D9 format exists ([`encode_u8_legacy`], as upstream SMAA ships `AreaTexDX9.dds`): R8 as `D3DFMT_L8`,
//! R8G8 as `D3DFMT_A8L8` (R in luminance, G in alpha: a D3D9 shader reads `.ra`, SMAA's `SMAA_AREATEX_SELECT` for
//! D3D9), R8G8B8A8 as `D3DFMT_A8R8G8B8` (bytes B, G, R, A in memory). Layout of the DDS header and pixel format:
//! Microsoft, "DDS programming guide" / `DDS_HEADER`, `DDS_PIXELFORMAT`.

use super::{IoError, PixelFormat};
use crate::image_buf::Image;
use ddsfile::{AlphaMode, D3D10ResourceDimension, Dds, DxgiFormat, NewDxgiParams};

fn dxgi(format: PixelFormat) -> Result<DxgiFormat, IoError> {
    Ok(match format {
        PixelFormat::R8Unorm => DxgiFormat::R8_UNorm,
        PixelFormat::R8G8Unorm => DxgiFormat::R8G8_UNorm,
        PixelFormat::R8G8B8A8Unorm => DxgiFormat::R8G8B8A8_UNorm,
        PixelFormat::R16G16B16A16Sfloat => DxgiFormat::R16G16B16A16_Float,
        PixelFormat::R32G32B32A32Sfloat => DxgiFormat::R32G32B32A32_Float,
        other => return Err(IoError::Unsupported { what: "dds", detail: format!("{other:?}") }),
    })
}

fn build(width: u32, height: u32, format: PixelFormat, payload: Vec<u8>) -> Result<Vec<u8>, IoError> {
    let mut dds = Dds::new_dxgi(NewDxgiParams {
        height,
        width,
        depth: None,
        format: dxgi(format)?,
        mipmap_levels: None,
        array_layers: None,
        caps2: None,
        is_cubemap: false,
        resource_dimension: D3D10ResourceDimension::Texture2D,
        alpha_mode: AlphaMode::Unknown,
    })
    .map_err(|e| IoError::Unsupported { what: "dds", detail: e.to_string() })?;
    if dds.data.len() != payload.len() {
        return Err(IoError::Unsupported {
            what: "dds",
            detail: format!("payload {} != {}", payload.len(), dds.data.len()),
        });
    }
    dds.data = payload;
    let mut out = Vec::new();
    dds.write(&mut out).map_err(|e| IoError::Unsupported { what: "dds", detail: e.to_string() })?;
    fourcc_only_pixel_format(&mut out);
    Ok(out)
}

/// File offsets of the DDS_PIXELFORMAT fields (after the 4-byte magic and 72 header bytes).
const PF_FLAGS: usize = 4 + 72 + 4;
const PF_FOURCC: usize = PF_FLAGS + 4;
const PF_BITCOUNT_AND_MASKS: std::ops::Range<usize> = PF_FOURCC + 4..PF_FOURCC + 24;
const DDPF_FOURCC: u32 = 0x4;

/// Rewrites the pixel-format block of a DX10 file to `DDPF_FOURCC` with zero bit count and masks.
fn fourcc_only_pixel_format(file: &mut [u8]) {
    debug_assert_eq!(&file[PF_FOURCC..PF_FOURCC + 4], b"DX10");
    file[PF_FLAGS..PF_FLAGS + 4].copy_from_slice(&DDPF_FOURCC.to_le_bytes());
    file[PF_BITCOUNT_AND_MASKS].fill(0);
}

/// 8-bit UNORM texture with 1, 2 or 4 channels.
pub fn encode_u8(img: &Image<u8>) -> Result<Vec<u8>, IoError> {
    let format = PixelFormat::unorm8_for(img.channels)
        .ok_or(IoError::Unsupported { what: "dds", detail: format!("{} channels of u8", img.channels) })?;
    build(img.width, img.height, format, img.data.clone())
}

/// `DDS_PIXELFORMAT.dwFlags` bits (ddraw.h).
const DDPF_ALPHAPIXELS: u32 = 0x1;
const DDPF_RGB: u32 = 0x40;
const DDPF_LUMINANCE: u32 = 0x2_0000;
/// `DDS_HEADER.dwFlags`: CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT.
const DDSD_UNCOMPRESSED: u32 = 0x1 | 0x2 | 0x4 | 0x8 | 0x1000;
const DDSCAPS_TEXTURE: u32 = 0x1000;

/// The legacy (D3D9) format of an 8-bit texture with `channels` channels: (name, flags, bits per texel, R, G, B,
/// A masks).
pub fn legacy_format(channels: u32) -> Option<(&'static str, u32, u32, [u32; 4])> {
    match channels {
        1 => Some(("D3DFMT_L8", DDPF_LUMINANCE, 8, [0xff, 0, 0, 0])),
        2 => Some(("D3DFMT_A8L8", DDPF_LUMINANCE | DDPF_ALPHAPIXELS, 16, [0xff, 0, 0, 0xff00])),
        4 => Some((
            "D3DFMT_A8R8G8B8",
            DDPF_RGB | DDPF_ALPHAPIXELS,
            32,
            [0x00ff_0000, 0x0000_ff00, 0x0000_00ff, 0xff00_0000],
        )),
        _ => None,
    }
}

/// 8-bit UNORM texture (1, 2 or 4 channels) with the legacy header and no DX10 extension: `D3DFMT_L8`, `D3DFMT_A8L8`
/// (R → L, G → A) or `D3DFMT_A8R8G8B8` (texels stored B, G, R, A), see the module docs.
pub fn encode_u8_legacy(img: &Image<u8>) -> Result<Vec<u8>, IoError> {
    let (_, pf_flags, bits, masks) = legacy_format(img.channels)
        .ok_or(IoError::Unsupported { what: "legacy dds", detail: format!("{} channels of u8", img.channels) })?;
    let mut out = Vec::with_capacity(128 + img.data.len());
    let mut put = |v: u32| out.extend_from_slice(&v.to_le_bytes());
    put(u32::from_le_bytes(*b"DDS "));
    put(124); // dwSize
    put(DDSD_UNCOMPRESSED);
    put(img.height);
    put(img.width);
    put(img.width * bits / 8); // dwPitchOrLinearSize: bytes per row
    put(0); // dwDepth
    put(0); // dwMipMapCount
    for _ in 0..11 {
        put(0); // dwReserved1
    }
    put(32); // DDS_PIXELFORMAT.dwSize
    put(pf_flags);
    put(0); // dwFourCC
    put(bits);
    for m in masks {
        put(m);
    }
    put(DDSCAPS_TEXTURE);
    for _ in 0..4 {
        put(0); // dwCaps2..4, dwReserved2
    }
    if img.channels == 4 {
        for px in img.data.chunks_exact(4) {
            out.extend_from_slice(&[px[2], px[1], px[0], px[3]]);
        }
    } else {
        out.extend_from_slice(&img.data);
    }
    Ok(out)
}

/// Pads 1–4 channels to RGBA (missing colour channels 0, alpha 1).
pub fn to_rgba(img: &Image<f32>) -> Vec<f32> {
    let c = img.channels as usize;
    let mut out = Vec::with_capacity(img.data.len() / c * 4);
    for px in img.data.chunks_exact(c) {
        let mut texel = [0.0, 0.0, 0.0, 1.0];
        texel[..c].copy_from_slice(px);
        out.extend_from_slice(&texel);
    }
    out
}

/// Float texture as `R16G16B16A16_FLOAT` (`half = true`) or `R32G32B32A32_FLOAT`; 1–3 channels are padded
/// to RGBA (missing colour channels 0, alpha 1).
pub fn encode_f32(img: &Image<f32>, half: bool) -> Result<Vec<u8>, IoError> {
    let rgba = to_rgba(img);
    if half {
        let h: Vec<half::f16> = rgba.iter().map(|&v| half::f16::from_f32(v)).collect();
        build(img.width, img.height, PixelFormat::R16G16B16A16Sfloat, bytemuck::cast_slice(&h).to_vec())
    } else {
        build(img.width, img.height, PixelFormat::R32G32B32A32Sfloat, bytemuck::cast_slice(&rgba).to_vec())
    }
}

/// Reads a DDS back: (format, width, height, payload bytes).
pub fn decode(bytes: &[u8], path: &str) -> Result<(PixelFormat, u32, u32, Vec<u8>), IoError> {
    let err = |d: String| IoError::Decode { path: path.to_string(), detail: d };
    let dds = Dds::read(bytes).map_err(|e| err(e.to_string()))?;
    if dds.get_dxgi_format().is_none() {
        return decode_legacy(&dds, bytes).map_err(err);
    }
    let format = match dds.get_dxgi_format() {
        Some(DxgiFormat::R8_UNorm) => PixelFormat::R8Unorm,
        Some(DxgiFormat::R8G8_UNorm) => PixelFormat::R8G8Unorm,
        Some(DxgiFormat::R8G8B8A8_UNorm) => PixelFormat::R8G8B8A8Unorm,
        Some(DxgiFormat::R16G16B16A16_Float) => PixelFormat::R16G16B16A16Sfloat,
        Some(DxgiFormat::R32G32B32A32_Float) => PixelFormat::R32G32B32A32Sfloat,
        other => return Err(err(format!("unsupported DXGI format {other:?}"))),
    };
    let data = dds.get_data(0).map_err(|e| err(e.to_string()))?.to_vec();
    Ok((format, dds.get_width(), dds.get_height(), data))
}

/// The legacy 8-bit files [`encode_u8_legacy`] writes, back to (format, width, height, R[G[BA]] bytes): the
/// pixel-format block must be exactly one of [`legacy_format`]'s.
fn decode_legacy(dds: &Dds, file: &[u8]) -> Result<(PixelFormat, u32, u32, Vec<u8>), String> {
    let word = |at: usize| file.get(at..at + 4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")));
    let field = |at: usize| word(at).ok_or_else(|| "truncated header".to_string());
    let (flags, bits) = (field(PF_FLAGS)?, field(PF_FLAGS + 8)?);
    let masks = [field(PF_FLAGS + 12)?, field(PF_FLAGS + 16)?, field(PF_FLAGS + 20)?, field(PF_FLAGS + 24)?];
    let channels = [1, 2, 4]
        .into_iter()
        .find(|&c| legacy_format(c).is_some_and(|(_, f, b, m)| (f, b, m) == (flags, bits, masks)))
        .ok_or_else(|| format!("unsupported legacy pixel format (flags {flags:#x}, {bits} bits, masks {masks:x?})"))?;
    let (w, h) = (dds.get_width() as usize, dds.get_height() as usize);
    // The top mip level follows the 128-byte header.
    let data = file.get(128..128 + w * h * channels as usize).ok_or("truncated payload")?;
    let data = if channels == 4 {
        data.chunks_exact(4).flat_map(|p| [p[2], p[1], p[0], p[3]]).collect()
    } else {
        data.to_vec()
    };
    let format = PixelFormat::unorm8_for(channels).expect("1, 2 or 4 channels");
    Ok((format, dds.get_width(), dds.get_height(), data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rg8_round_trips_with_dx10_header() {
        let img = Image::from_vec(4, 3, 2, (0..24u8).collect());
        let bytes = encode_u8(&img).unwrap();
        assert_eq!(&bytes[84..88], b"DX10");
        // Pixel-format flags: FourCC only; bit count and masks zero.
        assert_eq!(u32::from_le_bytes(bytes[80..84].try_into().unwrap()), DDPF_FOURCC);
        assert!(bytes[88..108].iter().all(|&b| b == 0));
        let (f, w, h, data) = decode(&bytes, "t").unwrap();
        assert_eq!((f, w, h), (PixelFormat::R8G8Unorm, 4, 3));
        assert_eq!(data, img.data);
        // DXGI_FORMAT_R8G8_UNORM = 49 right after the pixel-format block.
        assert_eq!(u32::from_le_bytes(bytes[128..132].try_into().unwrap()), 49);
    }

    #[test]
    fn r8_and_float_formats_round_trip() {
        let img = Image::from_vec(2, 2, 1, vec![1u8, 2, 3, 4]);
        assert_eq!(decode(&encode_u8(&img).unwrap(), "t").unwrap().0, PixelFormat::R8Unorm);
        let f = Image::from_vec(2, 1, 3, vec![0.5f32, 0.25, 2.0, -1.0, 0.0, 7.5]);
        let (fmt, _, _, data) = decode(&encode_f32(&f, false).unwrap(), "t").unwrap();
        assert_eq!(fmt, PixelFormat::R32G32B32A32Sfloat);
        let back: &[f32] = bytemuck::cast_slice(&data);
        assert_eq!(back, &[0.5, 0.25, 2.0, 1.0, -1.0, 0.0, 7.5, 1.0]);
        let (fmt, _, _, data) = decode(&encode_f32(&f, true).unwrap(), "t").unwrap();
        assert_eq!(fmt, PixelFormat::R16G16B16A16Sfloat);
        let back: Vec<f32> = data.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect();
        assert_eq!(back, vec![0.5, 0.25, 2.0, 1.0, -1.0, 0.0, 7.5, 1.0]);
    }

    #[test]
    fn legacy_copies_have_exact_d3d9_masks_and_round_trip() {
        let word = |b: &[u8], at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
        for (channels, flags, bits, masks) in [
            (1u32, 0x2_0000u32, 8u32, [0xffu32, 0, 0, 0]),
            (2, 0x2_0001, 16, [0xff, 0, 0, 0xff00]),
            (4, 0x41, 32, [0xff_0000, 0xff00, 0xff, 0xff00_0000]),
        ] {
            let img = Image::from_vec(3, 2, channels, (0..6 * channels as u8).map(|v| v * 7 + 1).collect());
            let b = encode_u8_legacy(&img).unwrap();
            assert_eq!(b.len(), 128 + img.data.len());
            assert_eq!(
                (word(&b, 4), word(&b, 76), word(&b, 80), word(&b, 84), word(&b, 88)),
                (124, 32, flags, 0, bits)
            );
            assert_eq!([word(&b, 92), word(&b, 96), word(&b, 100), word(&b, 104)], masks);
            assert_eq!(word(&b, 20), 3 * bits / 8, "pitch");
            assert_eq!(word(&b, 108), 0x1000, "DDSCAPS_TEXTURE");
            let (f, w, h, data) = decode(&b, "t").unwrap();
            assert_eq!((f, w, h), (PixelFormat::unorm8_for(channels).unwrap(), 3, 2));
            assert_eq!(data, img.data);
        }
        // A8R8G8B8 stores B, G, R, A.
        let b = encode_u8_legacy(&Image::from_vec(1, 1, 4, vec![10, 20, 30, 40])).unwrap();
        assert_eq!(&b[128..], &[30, 20, 10, 40]);
        assert!(encode_u8_legacy(&Image::from_vec(1, 1, 3, vec![1, 2, 3])).is_err());
    }
}
