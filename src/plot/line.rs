//! Minimal line plots as SVG text and as raster images (for PNG), without system fonts or a plotting crate.
//!
//! Why not `plotters`: its text needs system fonts or the `ab_glyph` feature plus a bundled TrueType font (and the
//! crate's compile time) for plots that are a few polylines on a linear or log₁₀ x axis. The SVG is written
//! directly (title, ticks, tick labels, axis labels with units, legend). The raster version draws the same axes,
//! ticks, grid, polylines, title, axis labels (the y label rotated) and legend names into an `Image<u8>` with the
//! public-domain X11 6×10 bitmap font that `embedded-graphics` embeds (ISO 8859-1: both cases, `µ`, `²`, `·`), so
//! both formats carry the same text and nothing depends on system fonts. The y axis may be log₁₀ too
//! (decade ticks; at most [`LOG_Y_DECADES`] decades below the largest value are shown). Several plots can be stacked
//! vertically into one document ([`panels_to_svg`], [`panels_to_image`]). Pure: returns text / pixels.

use crate::image_buf::Image;
use std::fmt::Write;

/// One polyline.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Legend name; an empty label draws the curve without a legend entry (e.g. error bars).
    pub label: String,
    /// sRGB colour.
    pub color: [u8; 3],
    pub dashed: bool,
    /// (x, y) points in data units; non-finite points (and x ≤ 0 on a log axis) are skipped.
    pub points: Vec<(f64, f64)>,
}

/// A line plot with one x and one y axis.
#[derive(Clone, Debug, PartialEq)]
pub struct LinePlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// log₁₀ x axis.
    pub log_x: bool,
    /// log₁₀ y axis (points with y ≤ 0 are skipped, as are points more than [`LOG_Y_DECADES`] decades below the
    /// largest value).
    pub log_y: bool,
    pub series: Vec<Curve>,
}

const MARGIN_L: f64 = 70.0;
const MARGIN_R: f64 = 20.0;
const MARGIN_T: f64 = 36.0;
const MARGIN_B: f64 = 50.0;

/// Decades a log₁₀ y axis spans at most, counted down from the decade above the largest value.
pub const LOG_Y_DECADES: f64 = 10.0;

/// Axis ranges and ticks in plot coordinates (x already log₁₀ when `log_x`).
struct Frame {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    x_ticks: Vec<(f64, String)>,
    y_ticks: Vec<(f64, String)>,
}

/// A linear axis from `lo` to `hi` widened to whole "nice" steps (about `target` of them), its ticks appended to
/// `ticks`; returns the widened range.
fn linear_ticks(lo: f64, hi: f64, target: usize, ticks: &mut Vec<(f64, String)>) -> (f64, f64) {
    let step = nice_step(hi - lo, target);
    let (lo, hi) = ((lo / step).floor() * step, (hi / step).ceil() * step);
    let mut t = lo;
    while t <= hi + 0.5 * step {
        ticks.push((t, fmt_tick(t, step)));
        t += step;
    }
    (lo, hi)
}

fn nice_step(range: f64, target: usize) -> f64 {
    let raw = range / target as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let m = if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

fn fmt_tick(v: f64, step: f64) -> String {
    let decimals = if step >= 1.0 { 0 } else { (-step.log10().floor()) as usize };
    let s = format!("{v:.decimals$}");
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

fn fmt_decade(e: i32) -> String {
    if e >= 0 {
        format!("{}", 10f64.powi(e))
    } else {
        format!("{:.*}", (-e) as usize, 10f64.powi(e))
    }
}

/// Decade label for a log y axis: plain decimals for 1e-3..1e3, else `1e-5`.
fn fmt_log_tick(e: i32) -> String {
    if (-3..=3).contains(&e) {
        fmt_decade(e)
    } else {
        format!("1e{e}")
    }
}

impl LinePlot {
    fn data_points(&self, s: &Curve) -> Vec<(f64, f64)> {
        s.points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite() && (!self.log_x || *x > 0.0) && (!self.log_y || *y > 0.0))
            .map(|&(x, y)| (if self.log_x { x.log10() } else { x }, if self.log_y { y.log10() } else { y }))
            .collect()
    }

    /// Plot-space points of `s` that lie inside the frame's y range (only a log y axis cuts any off).
    fn visible_points(&self, s: &Curve, f: &Frame) -> Vec<(f64, f64)> {
        self.data_points(s).into_iter().filter(|&(_, y)| y >= f.y0).collect()
    }

    fn frame(&self) -> Frame {
        let pts: Vec<(f64, f64)> = self.series.iter().flat_map(|s| self.data_points(s)).collect();
        // A linear y axis always includes 0; a log one starts at the smallest value.
        let y_start = if self.log_y { f64::INFINITY } else { 0.0f64 };
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, y_start, f64::NEG_INFINITY);
        for &(x, y) in &pts {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if !(x0.is_finite() && x1 > x0) {
            (x0, x1) = (0.0, 1.0);
        }
        if !y0.is_finite() {
            y0 = 0.0;
        }
        if !(y1.is_finite() && y1 > y0) {
            y1 = y0 + 1.0;
        }
        // Round-off below a zero baseline (e.g. −1e−18 from a numerical transform) does not add a negative tick row.
        if !self.log_y && y0 < 0.0 && -y0 < 1e-6 * y1.abs() {
            y0 = 0.0;
        }
        let mut y_ticks = Vec::new();
        if self.log_y {
            y1 = y1.ceil();
            y0 = y0.floor().max(y1 - LOG_Y_DECADES);
            let every = if y1 - y0 > 6.0 { 2 } else { 1 };
            for e in (y0 as i32..=y1 as i32).filter(|e| (y1 as i32 - e) % every == 0) {
                y_ticks.push((e as f64, fmt_log_tick(e)));
            }
        } else {
            (y0, y1) = linear_ticks(y0, y1, 5, &mut y_ticks);
        }
        let mut x_ticks = Vec::new();
        if self.log_x {
            x0 = x0.floor();
            x1 = x1.ceil();
            for e in x0 as i32..=x1 as i32 {
                x_ticks.push((e as f64, fmt_decade(e)));
            }
        } else {
            (x0, x1) = linear_ticks(x0, x1, 6, &mut x_ticks);
        }
        Frame { x0, x1, y0, y1, x_ticks, y_ticks }
    }

    fn mapper(f: &Frame, w: f64, h: f64) -> impl Fn(f64, f64) -> (f64, f64) + '_ {
        move |x, y| {
            let px = MARGIN_L + (x - f.x0) / (f.x1 - f.x0) * (w - MARGIN_L - MARGIN_R);
            let py = h - MARGIN_B - (y - f.y0) / (f.y1 - f.y0) * (h - MARGIN_T - MARGIN_B);
            (px, py)
        }
    }

    /// SVG document of `width × height` user units.
    pub fn to_svg(&self, width: u32, height: u32) -> String {
        panels_to_svg(std::slice::from_ref(self), width, height)
    }

    /// The plot's SVG elements (no `<svg>` wrapper) in a `width × height` box at the origin.
    fn svg_elements(&self, width: u32, height: u32) -> String {
        let (w, h) = (width as f64, height as f64);
        let f = self.frame();
        let map = Self::mapper(&f, w, h);
        let esc = |s: &str| s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
        let mut s = String::new();
        let (ax0, ay0) = map(f.x0, f.y0);
        let (ax1, ay1) = map(f.x1, f.y1);
        for (x, label) in &f.x_ticks {
            let (px, _) = map(*x, f.y0);
            let _ = writeln!(s, r##"<line x1="{px:.2}" y1="{ay1:.2}" x2="{px:.2}" y2="{ay0:.2}" stroke="#e0e0e0"/>"##);
            let _ = writeln!(
                s,
                r##"<line x1="{px:.2}" y1="{ay0:.2}" x2="{px:.2}" y2="{:.2}" stroke="black"/><text x="{px:.2}" y="{:.2}" text-anchor="middle">{}</text>"##,
                ay0 + 5.0,
                ay0 + 18.0,
                esc(label)
            );
        }
        for (y, label) in &f.y_ticks {
            let (_, py) = map(f.x0, *y);
            let _ = writeln!(s, r##"<line x1="{ax0:.2}" y1="{py:.2}" x2="{ax1:.2}" y2="{py:.2}" stroke="#e0e0e0"/>"##);
            let _ = writeln!(
                s,
                r##"<line x1="{:.2}" y1="{py:.2}" x2="{ax0:.2}" y2="{py:.2}" stroke="black"/><text x="{:.2}" y="{:.2}" text-anchor="end">{}</text>"##,
                ax0 - 5.0,
                ax0 - 8.0,
                py + 4.0,
                esc(label)
            );
        }
        let _ = writeln!(
            s,
            r#"<rect x="{ax0:.2}" y="{ay1:.2}" width="{:.2}" height="{:.2}" fill="none" stroke="black"/>"#,
            ax1 - ax0,
            ay0 - ay1
        );
        for series in &self.series {
            let pts: Vec<String> = self
                .visible_points(series, &f)
                .iter()
                .map(|&(x, y)| {
                    let (px, py) = map(x, y);
                    format!("{px:.2},{py:.2}")
                })
                .collect();
            // A polyline needs at least two points (ImageMagick refuses an empty `points`); a series with nothing
            // in the visible range keeps only its legend entry.
            if pts.len() < 2 {
                continue;
            }
            let [r, g, b] = series.color;
            let dash = if series.dashed { r#" stroke-dasharray="6,4""# } else { "" };
            let _ = writeln!(
                s,
                r##"<polyline fill="none" stroke="#{r:02x}{g:02x}{b:02x}" stroke-width="1.5"{dash} points="{}"/>"##,
                pts.join(" ")
            );
        }
        for (i, series) in self.series.iter().filter(|s| !s.label.is_empty()).enumerate() {
            let [r, g, b] = series.color;
            let y = MARGIN_T + 12.0 + 14.0 * i as f64;
            let x = w - MARGIN_R - 150.0;
            let dash = if series.dashed { r#" stroke-dasharray="6,4""# } else { "" };
            let _ = writeln!(
                s,
                r##"<line x1="{x:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#{r:02x}{g:02x}{b:02x}" stroke-width="1.5"{dash}/><text x="{:.2}" y="{y:.2}">{}</text>"##,
                y - 4.0,
                x + 24.0,
                y - 4.0,
                x + 30.0,
                esc(&series.label)
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.2}" y="{:.2}" text-anchor="middle" font-size="13">{}</text>"#,
            w / 2.0,
            MARGIN_T - 14.0,
            esc(&self.title)
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.2}" y="{:.2}" text-anchor="middle">{}</text>"#,
            (ax0 + ax1) / 2.0,
            h - 10.0,
            esc(&self.x_label)
        );
        let _ = writeln!(
            s,
            r#"<text transform="translate(14,{:.2}) rotate(-90)" text-anchor="middle">{}</text>"#,
            (ay0 + ay1) / 2.0,
            esc(&self.y_label)
        );
        s
    }

    /// RGB raster of the plot (white background), for PNG encoding.
    pub fn to_image(&self, width: u32, height: u32) -> Image<u8> {
        let (w, h) = (width as f64, height as f64);
        let f = self.frame();
        let map = Self::mapper(&f, w, h);
        let mut c = Canvas { img: Image::from_vec(width, height, 3, vec![255; (width * height * 3) as usize]) };
        let (ax0, ay0) = map(f.x0, f.y0);
        let (ax1, ay1) = map(f.x1, f.y1);
        let grid = [224, 224, 224];
        let black = [0, 0, 0];
        for (x, label) in &f.x_ticks {
            let (px, _) = map(*x, f.y0);
            c.line(px, ay1, px, ay0, grid, false);
            c.line(px, ay0, px, ay0 + 5.0, black, false);
            c.text(label, px, ay0 + 9.0, true, black);
        }
        for (y, label) in &f.y_ticks {
            let (_, py) = map(f.x0, *y);
            c.line(ax0, py, ax1, py, grid, false);
            c.line(ax0 - 5.0, py, ax0, py, black, false);
            let tw = text_width(label);
            c.text(label, ax0 - 8.0 - tw / 2.0, py - 5.0, true, black);
        }
        c.line(ax0, ay0, ax1, ay0, black, false);
        c.line(ax0, ay1, ax1, ay1, black, false);
        c.line(ax0, ay0, ax0, ay1, black, false);
        c.line(ax1, ay0, ax1, ay1, black, false);
        for series in &self.series {
            let pts: Vec<(f64, f64)> = self.visible_points(series, &f).iter().map(|&(x, y)| map(x, y)).collect();
            // The dash pattern runs along the whole polyline (segments are often shorter than one dash).
            let mut phase = 0.0;
            for p in pts.windows(2) {
                c.dashed_line(p[0].0, p[0].1, p[1].0, p[1].1, series.color, series.dashed, phase);
                phase += ((p[1].0 - p[0].0).powi(2) + (p[1].1 - p[0].1).powi(2)).sqrt();
            }
        }
        // Legend: swatch and name, right-aligned inside the frame's top-right corner.
        let widest = self.series.iter().map(|s| text_width(&s.label)).fold(0.0, f64::max);
        for (i, series) in self.series.iter().filter(|s| !s.label.is_empty()).enumerate() {
            let y = MARGIN_T + 8.0 + 14.0 * i as f64;
            let x = w - MARGIN_R - 40.0 - widest;
            c.line(x, y, x + 24.0, y, series.color, series.dashed);
            c.text(&series.label, x + 30.0, y - 5.0, false, black);
        }
        c.text(&self.title, w / 2.0, MARGIN_T - 24.0, true, black);
        c.text(&self.x_label, (ax0 + ax1) / 2.0, h - 16.0, true, black);
        c.text_vertical(&self.y_label, 6.0, (ay0 + ay1) / 2.0, black);
        c.img
    }
}

/// One SVG document with `panels` stacked top to bottom, each `width × panel_height` user units.
pub fn panels_to_svg(panels: &[LinePlot], width: u32, panel_height: u32) -> String {
    let height = panel_height * panels.len().max(1) as u32;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (i, p) in panels.iter().enumerate() {
        if i == 0 {
            s.push_str(&p.svg_elements(width, panel_height));
        } else {
            let _ = writeln!(s, r#"<g transform="translate(0,{})">"#, i as u32 * panel_height);
            s.push_str(&p.svg_elements(width, panel_height));
            s.push_str("</g>\n");
        }
    }
    s.push_str("</svg>\n");
    s
}

/// One RGB raster with `panels` stacked top to bottom, each `width × panel_height` pixels.
pub fn panels_to_image(panels: &[LinePlot], width: u32, panel_height: u32) -> Image<u8> {
    let mut data = Vec::with_capacity((width * panel_height * 3) as usize * panels.len());
    for p in panels {
        data.extend_from_slice(&p.to_image(width, panel_height).data);
    }
    Image::from_vec(width, panel_height * panels.len() as u32, 3, data)
}

/// The character drawn for `ch`: the font's ISO 8859-1 repertoire as it is, the few other symbols plot labels use
/// folded onto it (Greek μ → micro sign µ, superscript/typographic minus → `-`, subscript digits → digits).
fn normalize(ch: char) -> char {
    match ch {
        'μ' => 'µ',
        '⁻' | '−' | '–' => '-',
        '₀'..='₉' => char::from(b'0' + (ch as u32 - '₀' as u32) as u8),
        '′' => '\'',
        c => c,
    }
}

/// The raster font: X11's 6×10 "fixed" (public domain) as embedded in `embedded-graphics`, ISO 8859-1 (upper and
/// lower case, `µ`, `²`, `³`, `·`, `×`); unknown characters draw as `?`.
const FONT: embedded_graphics::mono_font::MonoFont<'static> = embedded_graphics::mono_font::iso_8859_1::FONT_6X10;

/// Advance of one character in pixels.
fn char_advance() -> f64 {
    (FONT.character_size.width + FONT.character_spacing) as f64
}

pub(super) fn text_width(s: &str) -> f64 {
    s.chars().count() as f64 * char_advance() - FONT.character_spacing as f64
}

/// Receives the font's lit pixels (in text coordinates: x along the text, y down, origin at the top-left of the
/// first glyph cell) and puts them on the canvas, horizontally or rotated 90° counter-clockwise.
struct GlyphSink<'a> {
    canvas: &'a mut Canvas,
    origin: (i64, i64),
    vertical: bool,
    color: [u8; 3],
}

impl embedded_graphics::geometry::OriginDimensions for GlyphSink<'_> {
    fn size(&self) -> embedded_graphics::geometry::Size {
        embedded_graphics::geometry::Size::new(u32::MAX / 2, u32::MAX / 2)
    }
}

impl embedded_graphics::draw_target::DrawTarget for GlyphSink<'_> {
    type Color = embedded_graphics::pixelcolor::BinaryColor;
    type Error = std::convert::Infallible;

    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Self::Error>
    where
        I: IntoIterator<Item = embedded_graphics::Pixel<Self::Color>>,
    {
        for embedded_graphics::Pixel(p, c) in pixels {
            if c == embedded_graphics::pixelcolor::BinaryColor::On {
                let (tx, ty) = (p.x as i64, p.y as i64);
                let (x, y) = if self.vertical {
                    (self.origin.0 + ty, self.origin.1 - tx)
                } else {
                    (self.origin.0 + tx, self.origin.1 + ty)
                };
                self.canvas.put(x, y, self.color);
            }
        }
        Ok(())
    }
}

pub(super) struct Canvas {
    pub(super) img: Image<u8>,
}

impl Canvas {
    pub(super) fn put(&mut self, x: i64, y: i64, color: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.img.width && (y as u32) < self.img.height {
            for (ch, v) in color.iter().enumerate() {
                self.img.set(x as u32, y as u32, ch as u32, *v);
            }
        }
    }

    /// A 2-pixel-wide line (1 pixel for axis-aligned lines); dashed lines alternate 6 px on, 4 px off.
    pub(super) fn line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, color: [u8; 3], dashed: bool) {
        self.dashed_line(x0, y0, x1, y1, color, dashed, 0.0);
    }

    /// [`Canvas::line`] whose dash pattern starts `phase` pixels into the pattern.
    #[allow(clippy::too_many_arguments)]
    fn dashed_line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, color: [u8; 3], dashed: bool, phase: f64) {
        let len = ((x1 - x0).powi(2) + (y1 - y0).powi(2)).sqrt();
        let steps = (len * 2.0).ceil().max(1.0) as usize;
        let thick = (x1 - x0).abs() > 0.5 && (y1 - y0).abs() > 0.5 || color != [0, 0, 0] && color != [224, 224, 224];
        for i in 0..=steps {
            let t = i as f64 / steps as f64;
            if dashed && (phase + t * len) % 10.0 >= 6.0 {
                continue;
            }
            let (x, y) = (x0 + t * (x1 - x0), y0 + t * (y1 - y0));
            let (xi, yi) = (x.round() as i64, y.round() as i64);
            self.put(xi, yi, color);
            if thick {
                self.put(xi + 1, yi, color);
                self.put(xi, yi + 1, color);
            }
        }
    }

    /// Draws `s` rotated 90° counter-clockwise (reading bottom to top), centred vertically on `y`, left edge at `x`.
    pub(super) fn text_vertical(&mut self, s: &str, x: f64, y: f64, color: [u8; 3]) {
        let origin = (x.round() as i64, (y + text_width(s) / 2.0).round() as i64);
        self.glyphs(s, origin, true, color);
    }

    /// Draws `s` with the raster font; (x, y) is the top-left corner, or the top-centre when `centered`.
    pub(super) fn text(&mut self, s: &str, x: f64, y: f64, centered: bool, color: [u8; 3]) {
        let x = if centered { x - text_width(s) / 2.0 } else { x };
        self.glyphs(s, (x.round() as i64, y.round() as i64), false, color);
    }

    fn glyphs(&mut self, s: &str, origin: (i64, i64), vertical: bool, color: [u8; 3]) {
        use embedded_graphics::{mono_font::MonoTextStyle, pixelcolor::BinaryColor, prelude::*, text};
        let folded: String = s.chars().map(normalize).collect();
        let style = MonoTextStyle::new(&FONT, BinaryColor::On);
        let mut sink = GlyphSink { canvas: self, origin, vertical, color };
        let _ = text::Text::with_baseline(&folded, Point::zero(), style, text::Baseline::Top).draw(&mut sink);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> LinePlot {
        LinePlot {
            title: "t".into(),
            x_label: "r (mm)".into(),
            y_label: "r R(r)".into(),
            log_x: true,
            log_y: false,
            series: vec![Curve {
                label: "a<b".into(),
                color: [255, 0, 0],
                dashed: false,
                points: (1..100).map(|i| (0.01 * i as f64, (i as f64).sqrt())).collect(),
            }],
        }
    }

    #[test]
    fn svg_has_decade_ticks_labels_and_escaped_legend() {
        let svg = sample().to_svg(640, 400);
        assert!(svg.starts_with("<svg"));
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains(">0.01</text>") && svg.contains(">0.1</text>") && svg.contains(">1</text>"));
        assert!(svg.contains("a&lt;b"));
        assert_eq!(svg.matches("<polyline").count(), 1);
    }

    #[test]
    fn log_y_axis_has_decade_ticks_and_cuts_the_deep_tail() {
        let mut p = sample();
        p.log_y = true;
        // y from 1 down to 1e-20 and one non-positive value: the axis spans 10 decades below the top decade.
        p.series[0].points = (0..=20).map(|i| (10f64.powi(i - 10), 10f64.powi(-i))).collect();
        p.series[0].points.push((1e20, 0.0));
        let f = p.frame();
        assert_eq!((f.y0, f.y1), (-LOG_Y_DECADES, 0.0));
        assert!(f.y_ticks.iter().any(|(_, l)| l == "1") && f.y_ticks.iter().any(|(_, l)| l == "1e-10"));
        let visible = p.visible_points(&p.series[0], &f);
        assert_eq!(visible.len(), 11);
        assert!(visible.iter().all(|&(_, y)| (-LOG_Y_DECADES..=0.0).contains(&y)));
        let svg = p.to_svg(640, 400);
        assert!(svg.contains(">1e-10</text>"));
    }

    #[test]
    fn linear_axis_ignores_round_off_below_zero() {
        let mut p = sample();
        p.series[0].points.push((2.0, -1e-18));
        assert_eq!(p.frame().y0, 0.0);
        p.series[0].points.push((3.0, -1.0));
        assert!(p.frame().y0 <= -1.0);
    }

    #[test]
    fn panels_stack_vertically() {
        let (a, b) = (sample(), sample());
        let svg = panels_to_svg(&[a.clone(), b.clone()], 300, 200);
        assert!(svg.contains(r#"height="400""#) && svg.contains(r#"<g transform="translate(0,200)">"#));
        assert_eq!(svg.matches("<polyline").count(), 2);
        let img = panels_to_image(&[a.clone(), b], 300, 200);
        assert_eq!((img.width, img.height), (300, 400));
        assert_eq!(img.data[..img.data.len() / 2], a.to_image(300, 200).data[..]);
    }

    #[test]
    fn dashes_run_across_short_segments() {
        // 400 points: every segment is ~1 px, far shorter than a dash.
        let mut p = sample();
        p.series[0].points = (0..400).map(|i| (1.0 + i as f64, 1.0)).collect();
        p.log_x = false;
        let count = |p: &LinePlot| p.to_image(640, 200).data.chunks(3).filter(|px| px == &[255, 0, 0]).count();
        let solid = count(&p);
        p.series[0].dashed = true;
        let dashed = count(&p);
        assert!((dashed as f64) < 0.75 * solid as f64 && dashed as f64 > 0.45 * solid as f64, "{dashed} vs {solid}");
    }

    #[test]
    fn raster_draws_title_axis_labels_and_legend_names() {
        let (w, h) = (400u32, 240u32);
        let dark = |img: &Image<u8>, x0: u32, x1: u32, y0: u32, y1: u32| {
            (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y))).filter(|&(x, y)| img.get(x, y, 0) < 64).count()
        };
        let mut titled = sample();
        titled.title = "Title".into();
        let with = titled.to_image(w, h);
        let mut blank = sample();
        blank.title.clear();
        blank.x_label.clear();
        blank.y_label.clear();
        for s in &mut blank.series {
            s.label.clear();
        }
        let without = blank.to_image(w, h);
        // Title band above the frame, x-label band below the tick labels, y-label band left of the tick labels.
        for (x0, x1, y0, y1, what) in
            [(0, w, 0, 20, "title"), (60, w, h - 18, h, "x label"), (0, 18, 40, h - 60, "y label")]
        {
            assert!(dark(&with, x0, x1, y0, y1) > 10, "{what} not drawn");
            assert_eq!(dark(&without, x0, x1, y0, y1), 0, "{what} band not empty without text");
        }
    }

    #[test]
    fn series_without_visible_points_write_no_empty_polyline() {
        let mut p = sample();
        p.series[0].points = vec![(-1.0, 1.0), (0.0, 2.0)];
        let svg = p.to_svg(400, 240);
        assert!(!svg.contains(r#"points="""#), "{svg}");
    }

    #[test]
    fn raster_draws_series_colour_inside_the_frame() {
        let img = sample().to_image(320, 200);
        let red = img.data.chunks(3).filter(|p| p == &[255, 0, 0]).count();
        assert!(red > 100, "{red}");
        assert!(img.data.chunks(3).any(|p| p == [0, 0, 0]));
    }
}
