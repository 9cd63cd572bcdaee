//! OpenEXR (via the `exr` crate): scan lines, ZIP compression, f16 or f32 samples, linear data.
//!
//! Channel names: 1 channel → `Y`, 2 → `R`,`G`, 3 → `R`,`G`,`B`, 4 → `R`,`G`,`B`,`A`. Reading accepts any of
//! those layouts and returns the channels in that order.

use super::IoError;
use crate::image_buf::Image;
use exr::prelude::*;

/// Sample precision of an EXR file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExrPrecision {
    F16,
    F32,
}

fn channel_names(channels: u32) -> std::result::Result<&'static [&'static str], IoError> {
    Ok(match channels {
        1 => &["Y"],
        2 => &["R", "G"],
        3 => &["R", "G", "B"],
        4 => &["R", "G", "B", "A"],
        n => return Err(IoError::Unsupported { what: "exr", detail: format!("{n} channels") }),
    })
}

/// Encodes `img` (top row first) as a single-layer EXR.
pub fn encode(img: &Image<f32>, precision: ExrPrecision) -> std::result::Result<Vec<u8>, IoError> {
    let names = channel_names(img.channels)?;
    let n = img.channels as usize;
    let list: smallvec::SmallVec<[AnyChannel<FlatSamples>; 4]> = names
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let plane = img.data.iter().skip(c).step_by(n).copied();
            let samples = match precision {
                ExrPrecision::F32 => FlatSamples::F32(plane.collect()),
                ExrPrecision::F16 => FlatSamples::F16(plane.map(f16::from_f32).collect()),
            };
            AnyChannel::new(*name, samples)
        })
        .collect();
    let encoding =
        Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
    let layer = Layer::new(
        (img.width as usize, img.height as usize),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(list),
    );
    let image = exr::image::Image::from_layer(layer);
    let mut cursor = std::io::Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut cursor)
        .map_err(|e| IoError::Unsupported { what: "exr", detail: e.to_string() })?;
    Ok(cursor.into_inner())
}

/// Decodes the first layer of an EXR into f32 samples; also returns whether the file stored f16.
pub fn decode(bytes: &[u8], path: &str) -> std::result::Result<(Image<f32>, ExrPrecision), IoError> {
    let err = |d: String| IoError::Decode { path: path.to_string(), detail: d };
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| err(e.to_string()))?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let chans = &layer.channel_data.list;
    let find = |name: &str| chans.iter().find(|c| c.name.eq(name));
    let order: Vec<&AnyChannel<FlatSamples>> = if chans.len() == 1 {
        vec![&chans[0]]
    } else {
        let names = channel_names(chans.len() as u32).map_err(|e| err(e.to_string()))?;
        names
            .iter()
            .map(|n| find(n).ok_or_else(|| err(format!("missing channel {n}"))))
            .collect::<std::result::Result<_, _>>()?
    };
    let precision =
        if matches!(order[0].sample_data, FlatSamples::F16(_)) { ExrPrecision::F16 } else { ExrPrecision::F32 };
    let planes: Vec<Vec<f32>> = order.iter().map(|c| c.sample_data.values_as_f32().collect()).collect();
    let n = planes.len();
    let mut data = Vec::with_capacity(w * h * n);
    for i in 0..w * h {
        for p in &planes {
            data.push(p[i]);
        }
    }
    Ok((Image::from_vec(w as u32, h as u32, n as u32, data), precision))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_round_trips_exactly_and_f16_within_half_precision() {
        let data: Vec<f32> = (0..2 * 3 * 3).map(|i| i as f32 * 0.137 - 0.5).collect();
        let img = Image::from_vec(2, 3, 3, data);
        let (back, p) = decode(&encode(&img, ExrPrecision::F32).unwrap(), "t").unwrap();
        assert_eq!(p, ExrPrecision::F32);
        assert_eq!(back, img);
        let (back, p) = decode(&encode(&img, ExrPrecision::F16).unwrap(), "t").unwrap();
        assert_eq!(p, ExrPrecision::F16);
        for (a, b) in back.data.iter().zip(&img.data) {
            assert!((a - b).abs() <= b.abs() * 1e-3 + 1e-4);
        }
    }

    #[test]
    fn one_and_two_channel_layouts() {
        for ch in [1u32, 2, 4] {
            let img = Image::from_vec(4, 2, ch, (0..8 * ch).map(|i| i as f32).collect());
            let (back, _) = decode(&encode(&img, ExrPrecision::F32).unwrap(), "t").unwrap();
            assert_eq!(back, img);
        }
    }

    #[test]
    fn encoding_is_deterministic() {
        let img = Image::from_vec(16, 16, 3, (0..768).map(|i| (i as f32).sin()).collect());
        assert_eq!(encode(&img, ExrPrecision::F16).unwrap(), encode(&img, ExrPrecision::F16).unwrap());
    }
}
