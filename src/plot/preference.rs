//! TAP 2009 Fig. 8 (thesis Fig. 4.9) as two line-plot panels: the proportion of trials in which TS was chosen over
//! each other shader, per light azimuth (degrees) and per camera distance (TAP's distance units, head 27 units
//! tall), with chance (0.5) dashed. The numbers come from [`crate::study::proportions`].

use crate::plot::{panels_to_image, panels_to_svg, Curve, LinePlot};
use crate::study::proportions::{Proportion, Proportions};

/// Width and per-panel height of the figure, pixels.
pub const WIDTH: u32 = 760;
pub const PANEL_HEIGHT: u32 = 360;

/// Colours of the comparisons, in first-seen order (No SSS, SS Jittered, SS Full for Table II), then repeated.
const COLORS: [[u8; 3]; 6] =
    [[200, 30, 30], [230, 140, 20], [30, 60, 210], [20, 140, 40], [130, 40, 160], [90, 90, 90]];

fn panel<K>(title: &str, x_label: &str, groups: &[(K, Vec<Proportion>)], x: impl Fn(&K) -> f64) -> LinePlot {
    let mut comparisons: Vec<String> = Vec::new();
    for (_, g) in groups {
        for p in g {
            if !comparisons.contains(&p.comparison) {
                comparisons.push(p.comparison.clone());
            }
        }
    }
    let mut series: Vec<Curve> = comparisons
        .iter()
        .enumerate()
        .map(|(i, c)| Curve {
            label: c.clone(),
            color: COLORS[i % COLORS.len()],
            dashed: false,
            points: groups
                .iter()
                .filter_map(|(k, g)| g.iter().find(|p| &p.comparison == c).map(|p| (x(k), p.proportion)))
                .collect(),
        })
        .collect();
    let xs: Vec<f64> = groups.iter().map(|(k, _)| x(k)).collect();
    let (lo, hi) = xs.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    if lo <= hi {
        series.push(Curve {
            label: "chance (0.5)".into(),
            color: [120, 120, 120],
            dashed: true,
            points: vec![(lo, 0.5), (hi, 0.5)],
        });
    }
    // An invisible anchor keeps the y axis from 0 to 1, as in the paper.
    series.push(Curve {
        label: String::new(),
        color: [255, 255, 255],
        dashed: false,
        points: vec![(lo, 0.0), (lo, 1.0)],
    });
    LinePlot {
        title: title.into(),
        x_label: x_label.into(),
        y_label: "proportion of trials TS chosen".into(),
        log_x: false,
        log_y: false,
        series,
    }
}

/// The two panels of Fig. 8: by light azimuth, by camera distance.
pub fn fig8_panels(p: &Proportions) -> Vec<LinePlot> {
    let mut out = Vec::new();
    if !p.by_light_azimuth_deg.is_empty() {
        out.push(panel(
            "TS chosen over each shader, per light angle (TAP 2009 Fig. 8 left)",
            "light azimuth (degrees; 0 = in front of the head)",
            &p.by_light_azimuth_deg,
            |a| *a,
        ));
    }
    if !p.by_distance.is_empty() {
        out.push(panel(
            "TS chosen over each shader, per camera distance (TAP 2009 Fig. 8 right)",
            "camera distance (TAP units, head 27 tall: zoom 28, near 50, far 132)",
            &p.by_distance,
            |d| d.tap_units() as f64,
        ));
    }
    out
}

/// The figure as SVG text.
pub fn fig8_svg(p: &Proportions) -> String {
    panels_to_svg(&fig8_panels(p), WIDTH, PANEL_HEIGHT)
}

/// The figure as RGB pixels.
pub fn fig8_image(p: &Proportions) -> crate::image_buf::Image<u8> {
    panels_to_image(&fig8_panels(p), WIDTH, PANEL_HEIGHT)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{proportions::preference_proportions, tap2009};

    #[test]
    fn fig8_has_both_panels_with_titles_axes_and_a_legend() {
        let p = preference_proportions(&tap2009::implied_counts());
        let panels = fig8_panels(&p);
        assert_eq!(panels.len(), 2);
        for pl in &panels {
            assert!(pl.title.contains("Fig. 8") && !pl.x_label.is_empty() && !pl.y_label.is_empty());
            let labels: Vec<&str> = pl.series.iter().map(|c| c.label.as_str()).filter(|l| !l.is_empty()).collect();
            assert_eq!(labels, vec!["TS vs No SSS", "TS vs SS Jittered", "TS vs SS Full", "chance (0.5)"]);
        }
        assert_eq!(panels[0].series[2].points.len(), 4);
        assert_eq!(panels[1].series[2].points.iter().map(|p| p.0).collect::<Vec<_>>(), vec![28.0, 50.0, 132.0]);
        let svg = fig8_svg(&p);
        assert!(svg.contains("TS vs SS Full") && svg.contains("light azimuth"));
        let img = fig8_image(&p);
        assert_eq!((img.width, img.height), (WIDTH, 2 * PANEL_HEIGHT));
    }
}
