//! Plots of a [`ProfileTable`]: two panels stacked in one image or SVG document,
//! both over a log₁₀ r axis (mm) and drawn at exactly the tabulated radii (radii ≤ 0 are skipped):
//!
//! 1. r·R(r) (mm⁻¹) on a linear y axis — the energy per unit log r, where the area under the curve in ln r is
//!    R̂(0)/2π, so the shape of the whole profile is visible at once;
//! 2. R(r) (mm⁻²) on a log₁₀ y axis (log–log), at most [`crate::plot::LOG_Y_DECADES`] decades deep, which shows the
//!    near-field peak and the far exponential tail.
//!
//! Every channel is a solid line in [`CHANNEL_COLORS`]; T(r) (slabs and layer stacks) is dashed in
//! a lighter shade of the channel colour; an optional sum-of-Gaussians overlay is dashed in a darker shade. Pure:
//! returns a [`LinePlot`] pair, text or PNG bytes; callers write the files.

use crate::diffusion::sum_of_gaussians::RgbGaussians;
use crate::diffusion::table::ProfileTable;
use crate::diffusion::RadialProfile;
use crate::error::InvalidInput;
use crate::plot::{panels_to_image, panels_to_svg, Curve, LinePlot};
use serde_json::Value;
use std::path::Path;

/// Width of a profile plot, pixels / SVG user units.
pub const PLOT_WIDTH: u32 = 720;
/// Height of each of the two panels, pixels / SVG user units (the document is twice as tall).
pub const PANEL_HEIGHT: u32 = 400;

/// File format of a plot, chosen by the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotFormat {
    Png,
    Svg,
}

impl PlotFormat {
    /// `.png` or `.svg` (case-insensitive); anything else is an error naming `param`.
    pub fn from_path(param: &str, path: &Path) -> Result<Self, InvalidInput> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png") => Ok(PlotFormat::Png),
            Some("svg") => Ok(PlotFormat::Svg),
            _ => Err(InvalidInput::new(
                param,
                format!("must name a .png or .svg file (format is chosen by extension), got '{}'", path.display()),
            )),
        }
    }

    pub fn extension(self) -> &'static str {
        match self {
            PlotFormat::Png => "png",
            PlotFormat::Svg => "svg",
        }
    }
}

const CHANNEL_NAMES: [&str; 3] = ["R", "G", "B"];

fn lighter(c: [u8; 3]) -> [u8; 3] {
    c.map(|v| ((v as u16 + 255) / 2) as u8)
}

fn darker(c: [u8; 3]) -> [u8; 3] {
    c.map(|v| v / 2)
}

/// The two panels of `table` (r·R(r) over log r; R(r) log–log), with T(r) when tabulated and `fit` overlaid when
/// given (evaluated at the same radii). `title` heads both panels.
pub fn profile_panels(table: &ProfileTable, fit: Option<&RgbGaussians>, title: &str) -> [LinePlot; 2] {
    let fit_values: Option<Vec<[f64; 3]>> = fit.map(|f| table.r_mm.iter().map(|&r| f.reflectance_mm2(r)).collect());
    let panel = |weighted: bool| {
        let y = |r: f64, v: f64| if weighted { r * v } else { v };
        let points = |vals: &[[f64; 3]], c: usize| -> Vec<(f64, f64)> {
            table.r_mm.iter().zip(vals).map(|(&r, v)| (r, y(r, v[c]))).collect()
        };
        let mut series = Vec::new();
        for c in 0..3 {
            series.push(Curve {
                label: format!("R {}", CHANNEL_NAMES[c]),
                color: CHANNEL_COLORS[c],
                dashed: false,
                points: points(&table.reflectance_mm2, c),
            });
        }
        if let Some(t) = &table.transmittance_mm2 {
            for c in 0..3 {
                series.push(Curve {
                    label: format!("T {}", CHANNEL_NAMES[c]),
                    color: lighter(CHANNEL_COLORS[c]),
                    dashed: true,
                    points: points(t, c),
                });
            }
        }
        if let (Some(f), Some(vals)) = (fit, &fit_values) {
            for c in 0..3 {
                series.push(Curve {
                    label: format!("{}-Gaussian fit {}", f.count(), CHANNEL_NAMES[c]),
                    color: darker(CHANNEL_COLORS[c]),
                    dashed: true,
                    points: points(vals, c),
                });
            }
        }
        let (sub, y_label) = if weighted {
            (
                "r R(r), log r axis",
                if table.transmittance_mm2.is_some() { "r R(r), r T(r) (1/mm)" } else { "r R(r) (1/mm)" },
            )
        } else {
            ("R(r), log-log", if table.transmittance_mm2.is_some() { "R(r), T(r) (1/mm^2)" } else { "R(r) (1/mm^2)" })
        };
        LinePlot {
            title: format!("{title}: {sub}"),
            x_label: "r (mm)".into(),
            y_label: y_label.into(),
            log_x: true,
            log_y: !weighted,
            series,
        }
    };
    [panel(true), panel(false)]
}

/// The panels rendered as a file in `format`: SVG text, or an RGB PNG ([`PLOT_WIDTH`] × 2·[`PANEL_HEIGHT`]).
/// The SVG records `provenance` (the model options, as JSON) in its `<desc>` element; a PNG carries pixels only.
pub fn render(panels: &[LinePlot], format: PlotFormat, provenance: &Value) -> Result<Vec<u8>, crate::io::IoError> {
    match format {
        PlotFormat::Svg => {
            let svg = panels_to_svg(panels, PLOT_WIDTH, PANEL_HEIGHT);
            let desc = provenance.to_string().replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
            // After the opening `<svg …>` line.
            let (head, body) = svg.split_once('\n').unwrap_or((&svg, ""));
            Ok(format!("{head}\n<desc>rtbake profile: {desc}</desc>\n{body}").into_bytes())
        }
        PlotFormat::Png => crate::io::png::encode_u8_as(
            &panels_to_image(panels, PLOT_WIDTH, PANEL_HEIGHT),
            crate::io::png::PngColor::Srgb,
        ),
    }
}

/// Plot colours of the R, G, B channels.
pub const CHANNEL_COLORS: [[u8; 3]; 3] = [[200, 30, 30], [20, 140, 40], [30, 60, 210]];

/// The y-axis name of an [`overlay_plot`] of profiles normalised to total reflectance 1 (R(r)/R_total): the same
/// units as r·R(r) but a different scale (skin1's red peaks near 0.16 instead of 0.022), so the label says so.
pub const NORMALIZED_Y_LABEL: &str = "r R(r) / R_total (1/mm; each channel normalised to total 1)";

/// `plot` relabelled for profiles normalised to total 1 ([`NORMALIZED_Y_LABEL`]).
pub fn normalized(mut plot: LinePlot) -> LinePlot {
    plot.y_label = NORMALIZED_Y_LABEL.into();
    plot
}

/// r·R(r) (mm⁻¹) on a log r axis per channel, with an optional fitted sum overlaid (dashed). The r range spans the
/// profile's 0.1 %–99.9 % energy quantiles, widened by 3× on both sides; 240 log-spaced points.
pub fn fit_overlay_plot(profile: &dyn RadialProfile, fit: Option<&RgbGaussians>, title: &str) -> LinePlot {
    overlay_plot(profile, "profile", fit.map(|f| (f as &dyn RadialProfile, "fit")), title)
}

/// r·R(r) (mm⁻¹) of `profile` (solid, legend `name R/G/B`) with any other profile overlaid (dashed, legend
/// `label R/G/B`), over the range of [`fit_overlay_plot`] (`rtbake evaluate` plots a candidate on its target).
pub fn overlay_plot(
    profile: &dyn RadialProfile,
    name: &str,
    overlay: Option<(&dyn RadialProfile, &str)>,
    title: &str,
) -> LinePlot {
    use crate::fitting::quadrature;
    use crate::fitting::sum_of_gaussians_fit;
    let grid = quadrature::RadialGrid::standard();
    let samples: Vec<[f64; 3]> = grid.r_mm.iter().map(|&r| profile.reflectance_mm2(r)).collect();
    let targets: Vec<Vec<f64>> = (0..3).map(|c| samples.iter().map(|s| s[c]).collect()).collect();
    let lo = (sum_of_gaussians_fit::quantile_radius(&grid, &targets, 0.001) / 3.0).max(quadrature::R_MIN_MM);
    let hi = (sum_of_gaussians_fit::quantile_radius(&grid, &targets, 0.999) * 3.0).min(quadrature::R_MAX_MM);
    let n = 240;
    let rs: Vec<f64> = (0..n).map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64)).collect();
    let names = ["R", "G", "B"];
    let mut series = Vec::new();
    for c in 0..3 {
        series.push(Curve {
            label: format!("{name} {}", names[c]),
            color: CHANNEL_COLORS[c],
            dashed: false,
            points: rs.iter().map(|&r| (r, r * profile.reflectance_mm2(r)[c])).collect(),
        });
    }
    if let Some((f, label)) = overlay {
        for c in 0..3 {
            series.push(Curve {
                label: format!("{label} {}", names[c]),
                color: CHANNEL_COLORS[c].map(|v| v / 2),
                dashed: true,
                points: rs.iter().map(|&r| (r, r * f.reflectance_mm2(r)[c])).collect(),
            });
        }
    }
    LinePlot {
        title: title.into(),
        x_label: "r (mm)".into(),
        y_label: "r R(r) (1/mm)".into(),
        log_x: true,
        log_y: false,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::materials;
    use crate::diffusion::table::log_radii;
    use crate::diffusion::FdrForm;

    #[test]
    fn format_by_extension() {
        assert_eq!(PlotFormat::from_path("plot", Path::new("a/b.PNG")).unwrap(), PlotFormat::Png);
        assert_eq!(PlotFormat::from_path("plot", Path::new("b.svg")).unwrap(), PlotFormat::Svg);
        for bad in ["b.jpg", "b", "png"] {
            assert_eq!(PlotFormat::from_path("plot", Path::new(bad)).unwrap_err().param, "plot");
        }
    }

    #[test]
    fn panels_carry_one_series_per_channel_and_weighting() {
        let profile = materials::find("skin1").unwrap().dipole(FdrForm::Dj05);
        let radii = log_radii(0.01, 10.0, 50).unwrap();
        let table = ProfileTable::compute(&profile, &radii, serde_json::json!({})).unwrap();
        let [top, bottom] = profile_panels(&table, None, "skin1");
        assert_eq!(top.series.len(), 3);
        assert!(top.log_x && !top.log_y && bottom.log_x && bottom.log_y);
        for c in 0..3 {
            let (r, v) = top.series[c].points[7];
            assert_eq!(v, r * table.reflectance_mm2[7][c]);
            assert_eq!(bottom.series[c].points[7].1, table.reflectance_mm2[7][c]);
        }
        let prov = serde_json::json!({"material": "skin1", "note": "a<b"});
        let svg = String::from_utf8(render(&[top, bottom], PlotFormat::Svg, &prov).unwrap()).unwrap();
        assert_eq!(svg.matches("<polyline").count(), 6);
        assert!(
            svg.starts_with("<svg")
                && svg.contains(r#"<desc>rtbake profile: {"material":"skin1","note":"a&lt;b"}</desc>"#)
        );
    }
}
