//! Labelled previews of lookup tables: the table's pixels (already encoded for viewing) scaled up with nearest-neighbour
//! sampling inside a frame with a title, axis names with units and tick labels, so a 256×1 table is a readable band
//! and a 2-D table says which parameter runs along which axis. Pure: pixels in, pixels out.

use super::line::{text_width, Canvas};
use crate::image_buf::Image;

/// What the axes of a table mean. Tick positions are fractions of the table's extent: x from the left edge of the
/// first column (0) to the right edge of the last (1), y from the top edge of the first row (0) down to the bottom
/// edge of the last (1).
#[derive(Clone, Debug, PartialEq)]
pub struct PreviewAxes {
    pub title: String,
    pub x_label: String,
    pub x_ticks: Vec<(f64, String)>,
    /// Empty for a one-row table (a band: no y axis).
    pub y_label: String,
    pub y_ticks: Vec<(f64, String)>,
}

impl PreviewAxes {
    /// Texel-index axes, for tables without a better description.
    pub fn texels(title: &str, width: u32, height: u32) -> Self {
        let ticks = |n: u32| vec![(0.5 / n as f64, "0".to_string()), (1.0 - 0.5 / n as f64, (n - 1).to_string())];
        Self {
            title: title.into(),
            x_label: "texel column".into(),
            x_ticks: ticks(width),
            y_label: if height > 1 { "texel row".into() } else { String::new() },
            y_ticks: if height > 1 { ticks(height) } else { Vec::new() },
        }
    }

    /// Ticks for a linear axis from `lo` at the centre of the first texel to `hi` at the centre of the last of `n`
    /// (node-inclusive tables), at `values`.
    pub fn node_ticks(lo: f64, hi: f64, n: u32, values: &[f64], unit: &str) -> Vec<(f64, String)> {
        values
            .iter()
            .map(|&v| {
                let i = (v - lo) / (hi - lo) * (n - 1) as f64;
                ((i + 0.5) / n as f64, format!("{v}{unit}"))
            })
            .collect()
    }
}

const MARGIN_L: f64 = 64.0;
const MARGIN_R: f64 = 24.0;
const MARGIN_T: f64 = 30.0;
const MARGIN_B: f64 = 44.0;
/// Minimum drawn size of the table inside the frame (pixels): one-row tables become bands this high.
const MIN_WIDTH: u32 = 512;
const BAND_HEIGHT: u32 = 48;

/// The labelled preview of `pixels` (RGB, 3 channels, 8-bit): see the module docs. Every table pixel becomes a
/// `sx × sy` block; the result is white around the frame.
pub fn labelled_preview(pixels: &Image<u8>, axes: &PreviewAxes) -> Image<u8> {
    assert_eq!(pixels.channels, 3, "previews are RGB");
    let sx = MIN_WIDTH.div_ceil(pixels.width).max(1);
    let sy = if pixels.height == 1 { BAND_HEIGHT } else { sx };
    let (tw, th) = (pixels.width * sx, pixels.height * sy);
    let title_w = text_width(&axes.title) as u32 + 16;
    let width = (MARGIN_L as u32 + tw + MARGIN_R as u32).max(title_w);
    let height = MARGIN_T as u32 + th + MARGIN_B as u32;
    let mut c = Canvas { img: Image::from_vec(width, height, 3, vec![255; (width * height * 3) as usize]) };
    let (x0, y0) = (MARGIN_L, MARGIN_T);
    for y in 0..th {
        for x in 0..tw {
            for ch in 0..3 {
                c.img.set(x0 as u32 + x, y0 as u32 + y, ch, pixels.get(x / sx, y / sy, ch));
            }
        }
    }
    let black = [0, 0, 0];
    let (x1, y1) = (x0 + tw as f64, y0 + th as f64);
    c.line(x0 - 1.0, y0 - 1.0, x1, y0 - 1.0, black, false);
    c.line(x0 - 1.0, y1, x1, y1, black, false);
    c.line(x0 - 1.0, y0 - 1.0, x0 - 1.0, y1, black, false);
    c.line(x1, y0 - 1.0, x1, y1, black, false);
    for (f, label) in &axes.x_ticks {
        let px = x0 + f * tw as f64;
        c.line(px, y1, px, y1 + 5.0, black, false);
        c.text(label, px, y1 + 8.0, true, black);
    }
    for (f, label) in &axes.y_ticks {
        let py = y0 + f * th as f64;
        c.line(x0 - 6.0, py, x0 - 1.0, py, black, false);
        c.text(label, x0 - 9.0 - text_width(label), py - 5.0, false, black);
    }
    c.text(&axes.title, width as f64 / 2.0, 9.0, true, black);
    c.text(&axes.x_label, (x0 + x1) / 2.0, height as f64 - 16.0, true, black);
    if !axes.y_label.is_empty() {
        c.text_vertical(&axes.y_label, 4.0, (y0 + y1) / 2.0, black);
    }
    c.img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_one_row_table_becomes_a_framed_band_with_its_texels_in_order() {
        let row = Image::from_vec(4, 1, 3, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30]);
        let axes = PreviewAxes {
            title: "T(s)".into(),
            x_label: "thickness s (mm)".into(),
            x_ticks: PreviewAxes::node_ticks(0.0, 3.0, 4, &[0.0, 3.0], ""),
            y_label: String::new(),
            y_ticks: Vec::new(),
        };
        let img = labelled_preview(&row, &axes);
        assert!(img.height >= BAND_HEIGHT + 60 && img.width >= MIN_WIDTH, "{}x{}", img.width, img.height);
        // Column blocks of 128 px: the middle of each block holds that texel's colour, on every band row.
        for y in [MARGIN_T as u32 + 1, MARGIN_T as u32 + BAND_HEIGHT - 2] {
            for (i, px) in row.data.chunks_exact(3).enumerate() {
                let x = MARGIN_L as u32 + 128 * i as u32 + 64;
                assert_eq!([img.get(x, y, 0), img.get(x, y, 1), img.get(x, y, 2)], [px[0], px[1], px[2]]);
            }
        }
        // Text was drawn above and below the band (title, tick labels, axis name).
        let dark =
            |y0: u32, y1: u32| (y0..y1).any(|y| (0..img.width).any(|x| img.get(x, y, 0) < 64 && img.get(x, y, 1) < 64));
        assert!(dark(0, MARGIN_T as u32 - 2), "title");
        assert!(dark(MARGIN_T as u32 + BAND_HEIGHT + 7, img.height), "x ticks and label");
    }

    #[test]
    fn node_ticks_sit_on_texel_centres() {
        let t = PreviewAxes::node_ticks(0.0, 1.0, 5, &[0.0, 0.5, 1.0], " mm");
        assert_eq!(t[0], (0.1, "0 mm".to_string()));
        assert_eq!(t[1], (0.5, "0.5 mm".to_string()));
        assert!((t[2].0 - 0.9).abs() < 1e-12);
    }
}
