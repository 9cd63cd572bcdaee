//! Contact sheets and difference images for comparing renders (TAP 2009 Figs. 4, 6 and 9: stimuli side by side,
//! difference images against the TS shader): pixels only, labelled with the plots' built-in bitmap font
//! ([`super::line`]); callers encode and write them.

use super::line::{text_width, Canvas};
use crate::image_buf::Image;

/// Background and text colours of a sheet (RGB).
const SHEET_BACKGROUND: [u8; 3] = [255, 255, 255];
const SHEET_TEXT: [u8; 3] = [0, 0, 0];
/// Height of a text line of the font, pixels, with its spacing.
const LINE_PX: u32 = 12;

/// The colour of a difference `t` in 0..=1 on a black → red → yellow → white ramp.
pub fn difference_colour(t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0) * 3.0;
    let c = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    [c(t), c(t - 1.0), c(t - 2.0)]
}

/// The largest per-channel difference |a − b| of each pixel (RGB of two RGBA or RGB 8-bit images of one size, in
/// 0..=1), multiplied by `scale` and shown on [`difference_colour`]'s ramp, with a legend strip over the bottom
/// rows: the ramp from 0 to 1/`scale` and its label (`|Δ| 0 … 1/scale`). RGB.
pub fn difference_image(a: &Image<u8>, b: &Image<u8>, scale: f32) -> Image<u8> {
    assert_eq!((a.width, a.height, a.channels), (b.width, b.height, b.channels), "difference of unequal images");
    let (w, h, ch) = (a.width, a.height, a.channels as usize);
    let mut out = Image::from_vec(w, h, 3, vec![0u8; (3 * w * h) as usize]);
    for i in 0..(w * h) as usize {
        let d = (0..3).map(|c| a.data[ch * i + c].abs_diff(b.data[ch * i + c])).max().unwrap_or(0);
        out.data[3 * i..3 * i + 3].copy_from_slice(&difference_colour(d as f32 / 255.0 * scale));
    }
    let mut canvas = Canvas { img: out };
    let label = format!("|d| 0-{:.3}", 1.0 / scale);
    let bar_w = (w as f64 * 0.3).clamp(8.0, 64.0) as u32;
    if h > LINE_PX + 2 && w > bar_w + text_width(&label) as u32 + 6 {
        let y0 = h - LINE_PX;
        for y in y0..h {
            for x in 0..w {
                canvas.put(x as i64, y as i64, [32, 32, 32]);
            }
        }
        for x in 0..bar_w {
            for y in y0 + 2..h - 2 {
                canvas.put(2 + x as i64, y as i64, difference_colour(x as f32 / (bar_w - 1) as f32));
            }
        }
        canvas.text(&label, (bar_w + 5) as f64, y0 as f64 + 1.0, false, [255, 255, 255]);
    }
    canvas.img
}

/// Frames in a grid with a title, a label above each column and one left of each row (RGB). `cells` are row-major,
/// `rows.len()` × `columns.len()`, each RGB or RGBA and at most `cell_w`×`cell_h` (smaller ones are placed at their
/// cell's top-left corner); a missing cell stays blank.
pub fn contact_sheet(
    title: &str,
    rows: &[String],
    columns: &[String],
    cells: &[Option<&Image<u8>>],
    cell_w: u32,
    cell_h: u32,
) -> Image<u8> {
    assert_eq!(cells.len(), rows.len() * columns.len(), "one cell per row and column");
    let gap = 4u32;
    let label_w = rows.iter().map(|r| text_width(r) as u32).max().unwrap_or(0) + 2 * gap;
    let col_label_lines = 1;
    let top = LINE_PX + gap + col_label_lines * LINE_PX + gap;
    let width = label_w + columns.len() as u32 * (cell_w + gap) + gap;
    let width = width.max(text_width(title) as u32 + 2 * gap);
    let height = top + rows.len() as u32 * (cell_h + gap) + gap;
    let mut canvas =
        Canvas { img: Image::from_vec(width, height, 3, SHEET_BACKGROUND.repeat((width * height) as usize)) };
    canvas.text(title, gap as f64, gap as f64 / 2.0, false, SHEET_TEXT);
    for (c, name) in columns.iter().enumerate() {
        let x = label_w + c as u32 * (cell_w + gap) + cell_w / 2;
        canvas.text(name, x as f64, (LINE_PX + gap) as f64, true, SHEET_TEXT);
    }
    for (r, name) in rows.iter().enumerate() {
        let y = top + r as u32 * (cell_h + gap);
        canvas.text(name, gap as f64, (y + cell_h / 2) as f64 - 5.0, false, SHEET_TEXT);
        for c in 0..columns.len() {
            let Some(img) = cells[r * columns.len() + c] else { continue };
            let x0 = label_w + c as u32 * (cell_w + gap);
            let ch = img.channels as usize;
            for y in 0..img.height.min(cell_h) {
                for x in 0..img.width.min(cell_w) {
                    let i = (y * img.width + x) as usize * ch;
                    let px = [img.data[i], img.data[i + 1], img.data[i + 2]];
                    canvas.put((x0 + x) as i64, (top + r as u32 * (cell_h + gap) + y) as i64, px);
                }
            }
        }
    }
    canvas.img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_ramp_and_legend() {
        assert_eq!(difference_colour(0.0), [0, 0, 0]);
        assert_eq!(difference_colour(1.0), [255, 255, 255]);
        assert_eq!(difference_colour(1.0 / 3.0), [255, 0, 0]);
        let a = Image::from_vec(160, 48, 4, [100u8, 100, 100, 255].repeat(160 * 48));
        let mut b = a.clone();
        b.data[0] = 108; // pixel (0, 0): |d| = 8/255, ×8 → 0.25 of the ramp
        let d = difference_image(&a, &b, 8.0);
        assert_eq!((d.width, d.height, d.channels), (160, 48, 3));
        assert_eq!(&d.data[..3], &difference_colour(64.0 / 255.0));
        assert_eq!(&d.data[3..6], &[0, 0, 0]);
        // The legend strip at the bottom holds the ramp's white end and label text; too narrow a frame has none.
        let narrow = Image::from_vec(32, 48, 4, [100u8, 100, 100, 255].repeat(32 * 48));
        assert!(difference_image(&narrow, &narrow, 8.0).data.iter().all(|&v| v == 0));
        let bottom = &d.data[(3 * 160 * 40) as usize..];
        assert!(bottom.chunks(3).any(|p| p == [255, 255, 255]));
    }

    #[test]
    fn a_sheet_places_cells_under_their_labels() {
        let red = Image::from_vec(10, 8, 3, [255u8, 0, 0].repeat(80));
        let blue = Image::from_vec(10, 8, 4, [0u8, 0, 255, 255].repeat(80));
        let rows = vec!["A".to_string(), "B".to_string()];
        let cols = vec!["x".to_string(), "y".to_string()];
        let s = contact_sheet("T", &rows, &cols, &[Some(&red), None, None, Some(&blue)], 10, 8);
        let count = |c: [u8; 3]| s.data.chunks(3).filter(|p| *p == c).count();
        assert_eq!(count([255, 0, 0]), 80);
        assert_eq!(count([0, 0, 255]), 80);
        // Text was drawn (black pixels) for the title and labels.
        assert!(count([0, 0, 0]) > 20);
    }
}
