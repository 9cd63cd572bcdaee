//! KTX 2.0 writer (Khronos KTX File Format Specification 2.0, with a Khronos Data Format basic descriptor).
//!
//! Single level, single layer, optionally Zstandard-supercompressed (scheme 2, the form Bevy ships its SMAA
//! LUTs in), `KHR_DF_TRANSFER_LINEAR`, BT.709 primaries, RGBSDA colour model. Every file is validated by reading
//! it back with the `ktx2` crate (the reader Bevy uses) in the tests.
//!
//! Why a hand-written writer: the crates that write KTX2 today (`libktx-rs` bindings to the C libktx, or
//! encoders tied to Basis Universal) pull in a C++ toolchain or a transcoder for what is here ~150 lines of
//! header layout; the only codec needed, Zstandard, comes from the `zstd` crate. Zstandard at level 15
//! through the bundled libzstd gives the same bytes as `ktx create --zstd 15` (see the consumer tests). Formats: `R8_UNORM`, `R8G8_UNORM`, `R8G8B8A8_UNORM`,
//! `R16_SFLOAT`, `R16G16_SFLOAT`, `R16G16B16A16_SFLOAT`, `R32_SFLOAT`, `R32G32B32A32_SFLOAT`.

use super::{IoError, PixelFormat};
use crate::image_buf::Image;

/// VkFormat enum value.
pub fn vk_format(format: PixelFormat) -> u32 {
    match format {
        PixelFormat::R8Unorm => 9,
        PixelFormat::R8G8Unorm => 16,
        PixelFormat::R8G8B8A8Unorm => 37,
        PixelFormat::R16Sfloat => 76,
        PixelFormat::R16G16Sfloat => 83,
        PixelFormat::R16G16B16A16Sfloat => 97,
        PixelFormat::R32Sfloat => 100,
        PixelFormat::R32G32B32A32Sfloat => 109,
    }
}

const IDENTIFIER: [u8; 12] = [0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, b'\r', b'\n', 0x1A, b'\n'];
const WRITER: &str = concat!("rtbake ", env!("CARGO_PKG_VERSION"));

fn align(v: usize, a: usize) -> usize {
    v.div_ceil(a) * a
}

fn dfd(format: PixelFormat) -> Vec<u8> {
    let channels = format.channels();
    let bpt = format.bytes_per_texel();
    let comp_bytes = bpt / channels;
    let is_float = !format.is_unorm8();
    let block_size = 24 + 16 * channels;
    let mut b = Vec::new();
    b.extend_from_slice(&(4 + block_size).to_le_bytes()); // dfdTotalSize
    b.extend_from_slice(&0u32.to_le_bytes()); // vendorId = KHR, descriptorType = basic
    b.extend_from_slice(&2u16.to_le_bytes()); // versionNumber
    b.extend_from_slice(&(block_size as u16).to_le_bytes());
    b.extend_from_slice(&[1, 1, 1, 0]); // colorModel RGBSDA, primaries BT709, transfer LINEAR, flags straight alpha
    b.extend_from_slice(&[0, 0, 0, 0]); // texelBlockDimension 1x1x1x1 (stored minus one)
    let mut planes = [0u8; 8];
    planes[0] = bpt as u8;
    b.extend_from_slice(&planes);
    for c in 0..channels {
        let channel_id: u8 = if c == 3 { 15 } else { c as u8 };
        let flags: u8 = if is_float { 0x80 | 0x40 } else { 0 };
        b.extend_from_slice(&((c * comp_bytes * 8) as u16).to_le_bytes());
        b.push((comp_bytes * 8 - 1) as u8);
        b.push(channel_id | flags);
        b.extend_from_slice(&[0, 0, 0, 0]);
        let (lower, upper) = if is_float { (0xBF80_0000u32, 0x3F80_0000u32) } else { (0, 255) };
        b.extend_from_slice(&lower.to_le_bytes());
        b.extend_from_slice(&upper.to_le_bytes());
    }
    b
}

/// Supercompression of the level data (KTX2 `supercompressionScheme`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Supercompression {
    /// Scheme 0: level data stored as is.
    #[default]
    None,
    /// Scheme 2: Zstandard at this level (1..=22), no checksum, content size in the frame (as libktx writes).
    Zstd(i32),
}

/// The Zstandard level Bevy's SMAA LUTs were made with (`KTXwriterScParams` = `--zstd 15`).
pub const BEVY_ZSTD_LEVEL: i32 = 15;

impl Supercompression {
    /// Manifest name: `none` or `zstd-<level>`.
    pub fn label(self) -> String {
        match self {
            Self::None => "none".into(),
            Self::Zstd(l) => format!("zstd-{l}"),
        }
    }
}

fn kv_entry(key: &str, value: &str, out: &mut Vec<u8>) {
    let mut entry = key.as_bytes().to_vec();
    entry.push(0);
    entry.extend_from_slice(value.as_bytes());
    entry.push(0);
    out.extend_from_slice(&(entry.len() as u32).to_le_bytes());
    out.extend_from_slice(&entry);
    while !out.len().is_multiple_of(4) {
        out.push(0);
    }
}

fn kvd(sc: Supercompression) -> Vec<u8> {
    let mut b = Vec::new();
    kv_entry("KTXwriter", WRITER, &mut b);
    if let Supercompression::Zstd(level) = sc {
        kv_entry("KTXwriterScParams", &format!("--zstd {level}"), &mut b);
    }
    b
}

/// Assembles a KTX2 file from raw little-endian level-0 texels.
pub fn encode_raw(width: u32, height: u32, format: PixelFormat, payload: &[u8]) -> Result<Vec<u8>, IoError> {
    encode_raw_with(width, height, format, payload, Supercompression::None)
}

/// Zstandard-compresses `payload` as libktx does (`ZSTD_compressCCtx`: content size, no checksum).
pub fn zstd_compress(payload: &[u8], level: i32) -> Result<Vec<u8>, IoError> {
    if !(1..=22).contains(&level) {
        return Err(IoError::Unsupported { what: "ktx2", detail: format!("zstd level {level}, accepted 1..=22") });
    }
    zstd::bulk::compress(payload, level).map_err(|e| IoError::Unsupported { what: "ktx2", detail: e.to_string() })
}

/// Assembles a KTX2 file from raw little-endian level-0 texels with the given supercompression.
pub fn encode_raw_with(
    width: u32,
    height: u32,
    format: PixelFormat,
    payload: &[u8],
    sc: Supercompression,
) -> Result<Vec<u8>, IoError> {
    let expected = width as usize * height as usize * format.bytes_per_texel() as usize;
    if payload.len() != expected {
        return Err(IoError::Unsupported {
            what: "ktx2",
            detail: format!("payload {} bytes, expected {expected}", payload.len()),
        });
    }
    let type_size = if format.is_unorm8() { 1 } else { format.bytes_per_texel() / format.channels() };
    let dfd = dfd(format);
    let kvd = kvd(sc);
    let (scheme, level_bytes) = match sc {
        Supercompression::None => (0u32, payload.to_vec()),
        Supercompression::Zstd(level) => (2u32, zstd_compress(payload, level)?),
    };
    let header_len = 12 + 9 * 4 + 4 * 4 + 2 * 8; // identifier + header fields + index
    let level_index_len = 3 * 8;
    let dfd_off = header_len + level_index_len;
    let kvd_off = dfd_off + dfd.len();
    // Supercompressed level data needs no alignment (spec §3.9.7); plain data is aligned to lcm(4, texel size).
    let data_align = if scheme != 0 {
        1
    } else {
        let bpt = format.bytes_per_texel() as usize;
        // lcm(4, texel block size)
        let g = gcd(4, bpt);
        4 * bpt / g
    };
    let data_off = align(kvd_off + kvd.len(), data_align);

    let mut out = Vec::with_capacity(data_off + level_bytes.len());
    out.extend_from_slice(&IDENTIFIER);
    for v in [vk_format(format), type_size, width, height, 0, 0, 1, 1, scheme] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [dfd_off as u32, dfd.len() as u32, kvd_off as u32, kvd.len() as u32] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&0u64.to_le_bytes()); // sgdByteOffset
    out.extend_from_slice(&0u64.to_le_bytes()); // sgdByteLength
    for v in [data_off as u64, level_bytes.len() as u64, payload.len() as u64] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    out.resize(data_off, 0);
    out.extend_from_slice(&level_bytes);
    Ok(out)
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// 8-bit UNORM texture with 1, 2 or 4 channels.
pub fn encode_u8(img: &Image<u8>) -> Result<Vec<u8>, IoError> {
    encode_u8_with(img, Supercompression::None)
}

/// 8-bit UNORM texture with 1, 2 or 4 channels and the given supercompression.
pub fn encode_u8_with(img: &Image<u8>, sc: Supercompression) -> Result<Vec<u8>, IoError> {
    let format = PixelFormat::unorm8_for(img.channels)
        .ok_or(IoError::Unsupported { what: "ktx2", detail: format!("{} channels of u8", img.channels) })?;
    encode_raw_with(img.width, img.height, format, &img.data, sc)
}

/// Float texture stored as half floats: 1 → R16, 2 → RG16, 3 or 4 → RGBA16 (3 padded with alpha 1).
pub fn encode_f16(img: &Image<f32>) -> Result<Vec<u8>, IoError> {
    encode_f16_with(img, Supercompression::None)
}

/// [`encode_f16`] with the given supercompression.
pub fn encode_f16_with(img: &Image<f32>, sc: Supercompression) -> Result<Vec<u8>, IoError> {
    let format = PixelFormat::f16_for(img.channels)
        .ok_or(IoError::Unsupported { what: "ktx2", detail: format!("{} channels", img.channels) })?;
    let samples: Vec<f32> = if img.channels == 3 { super::dds::to_rgba(img) } else { img.data.clone() };
    let h: Vec<half::f16> = samples.iter().map(|&v| half::f16::from_f32(v)).collect();
    encode_raw_with(img.width, img.height, format, bytemuck::cast_slice(&h), sc)
}

/// The [`PixelFormat`] of a VkFormat value rtbake writes.
pub fn pixel_format_of_vk(vk: u32) -> Option<PixelFormat> {
    use PixelFormat as P;
    [
        P::R8Unorm,
        P::R8G8Unorm,
        P::R8G8B8A8Unorm,
        P::R16Sfloat,
        P::R16G16Sfloat,
        P::R16G16B16A16Sfloat,
        P::R32Sfloat,
        P::R32G32B32A32Sfloat,
    ]
    .into_iter()
    .find(|&p| vk_format(p) == vk)
}

/// Re-encodes a single-level KTX2 file written by rtbake with Zstandard supercompression at `level`.
pub fn supercompress(bytes: &[u8], path: &str, level: i32) -> Result<Vec<u8>, IoError> {
    let (vk, width, height, payload, _) = decode(bytes, path)?;
    let format = pixel_format_of_vk(vk).ok_or_else(|| IoError::Decode {
        path: path.to_string(),
        detail: format!("VkFormat {vk} not written by rtbake"),
    })?;
    encode_raw_with(width, height, format, &payload, Supercompression::Zstd(level))
}

/// Reads a KTX2 back with the `ktx2` crate: (vkFormat, width, height, level-0 bytes, transfer is linear).
/// Zstandard-supercompressed level data is decompressed (as Bevy's loader does).
pub fn decode(bytes: &[u8], path: &str) -> Result<(u32, u32, u32, Vec<u8>, bool), IoError> {
    let err = |d: String| IoError::Decode { path: path.to_string(), detail: d };
    let reader = ktx2::Reader::new(bytes).map_err(|e| err(e.to_string()))?;
    let header = reader.header();
    let format = header.format.map(|f| f.value()).unwrap_or(0);
    let level = reader.levels().next().ok_or_else(|| err("no mip level".into()))?;
    let linear = reader.transfer_function() == Some(ktx2::TransferFunction::Linear);
    let data = match header.supercompression_scheme {
        None => level.data.to_vec(),
        Some(ktx2::SupercompressionScheme::Zstandard) => {
            let want = level.uncompressed_byte_length as usize;
            let out = zstd::bulk::decompress(level.data, want).map_err(|e| err(format!("zstd: {e}")))?;
            if out.len() != want {
                return Err(err(format!("zstd level data: {} bytes, header says {want}", out.len())));
            }
            out
        }
        Some(other) => return Err(err(format!("unsupported supercompression {other:?}"))),
    };
    Ok((format, header.pixel_width, header.pixel_height, data, linear))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rg8_reads_back_with_ktx2_crate() {
        let img = Image::from_vec(5, 3, 2, (0..30u8).collect());
        let bytes = encode_u8(&img).unwrap();
        let reader = ktx2::Reader::new(&bytes[..]).unwrap();
        let h = reader.header();
        assert_eq!(h.format, Some(ktx2::Format::R8G8_UNORM));
        assert_eq!((h.pixel_width, h.pixel_height, h.type_size), (5, 3, 1));
        assert_eq!(reader.transfer_function(), Some(ktx2::TransferFunction::Linear));
        assert_eq!(reader.color_model(), Some(ktx2::ColorModel::RGBSDA));
        assert_eq!(reader.writer().map(|w| w.trim_end_matches(char::from(0))), Some(WRITER));
        assert_eq!(reader.levels().next().unwrap().data, &img.data[..]);
        let basic = reader.basic_dfd().unwrap();
        assert_eq!(basic.sample_information.len(), 2);
    }

    #[test]
    fn rgba16f_reads_back_and_is_aligned() {
        let img = Image::from_vec(2, 2, 3, vec![0.5f32, 1.0, 2.0, 0.0, 0.25, 8.0, 1.0, 1.0, 1.0, 0.125, 0.0, 3.0]);
        let bytes = encode_f16(&img).unwrap();
        let (fmt, w, h, data, linear) = decode(&bytes, "t").unwrap();
        assert_eq!((fmt, w, h, linear), (97, 2, 2, true));
        let back: Vec<f32> = data.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect();
        assert_eq!(&back[0..4], &[0.5, 1.0, 2.0, 1.0]);
        assert_eq!(back.len(), 16);
        let reader = ktx2::Reader::new(&bytes[..]).unwrap();
        assert_eq!(reader.header().type_size, 2);
        let sample = reader.basic_dfd().unwrap().sample_information[0];
        assert_eq!(sample.bit_length.get(), 16);
    }

    #[test]
    fn zstd_supercompressed_reads_back_with_ktx2_crate() {
        let img = Image::from_vec(16, 8, 2, (0..256u32).map(|v| (v % 7) as u8).collect());
        let bytes = encode_u8_with(&img, Supercompression::Zstd(BEVY_ZSTD_LEVEL)).unwrap();
        let reader = ktx2::Reader::new(&bytes[..]).unwrap();
        assert_eq!(reader.header().supercompression_scheme, Some(ktx2::SupercompressionScheme::Zstandard));
        let level = reader.levels().next().unwrap();
        assert_eq!(level.uncompressed_byte_length, 256);
        assert!(level.data.len() < 256);
        assert_eq!(decode(&bytes, "t").unwrap().3, img.data);
        assert!(zstd_compress(&img.data, 0).is_err() && zstd_compress(&img.data, 23).is_err());
    }

    #[test]
    fn r8_reads_back() {
        let img = Image::from_vec(2, 2, 1, vec![9u8, 8, 7, 6]);
        let (fmt, _, _, data, _) = decode(&encode_u8(&img).unwrap(), "t").unwrap();
        assert_eq!((fmt, data), (9, img.data));
    }
}
