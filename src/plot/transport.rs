//! Plots of a Monte Carlo transport result ([`crate::transport::McResult`]) against a diffusion profile: two
//! panels over a linear r axis (mm), r·R(r) (mm⁻¹, linear y) above and R(r) (mm⁻², log y) below. Monte Carlo is a
//! solid line per channel through the bin centres with ±1 standard-error bars (vertical segments, no legend
//! entry); the diffusion profile, averaged over the same annuli, is dashed in a darker shade. Pure: returns
//! [`LinePlot`]s; [`crate::plot::profile::render`] turns them into SVG or PNG bytes.

use crate::plot::profile::CHANNEL_COLORS;
use crate::plot::{Curve, LinePlot};
use crate::transport::McResult;

const NAMES: [&str; 3] = ["R", "G", "B"];

/// The two panels; `diffusion` holds the profile's annulus means per bin (`transport::compare::bin_averaged`) and
/// `diffusion_name` its legend name.
pub fn transport_panels(result: &McResult, diffusion: Option<(&[[f64; 3]], &str)>, title: &str) -> [LinePlot; 2] {
    let radii = result.settings.radii_mm();
    let panel = |weighted: bool| {
        let k = |r: f64| if weighted { r } else { 1.0 };
        let mut series = Vec::new();
        for c in 0..3 {
            let est = &result.channels[c].reflectance_mm2;
            series.push(Curve {
                label: format!("Monte Carlo {}", NAMES[c]),
                color: CHANNEL_COLORS[c],
                dashed: false,
                points: radii.iter().zip(est).map(|(&r, e)| (r, k(r) * e.mean)).collect(),
            });
            for (&r, e) in radii.iter().zip(est) {
                if e.se > 0.0 {
                    // On the log axis a bar reaching zero is cut at 1 % of the value.
                    let lo = if weighted { e.mean - e.se } else { (e.mean - e.se).max(0.01 * e.mean) };
                    series.push(Curve {
                        label: String::new(),
                        color: CHANNEL_COLORS[c],
                        dashed: false,
                        points: vec![(r, k(r) * lo), (r, k(r) * (e.mean + e.se))],
                    });
                }
            }
        }
        if let Some((values, name)) = diffusion {
            for c in 0..3 {
                series.push(Curve {
                    label: format!("{name} {}", NAMES[c]),
                    color: CHANNEL_COLORS[c].map(|v| v / 2),
                    dashed: true,
                    points: radii.iter().zip(values).map(|(&r, v)| (r, k(r) * v[c])).collect(),
                });
            }
        }
        profile_panel(title, weighted, series)
    };
    [panel(true), panel(false)]
}

/// One panel of radial profiles: r·R(r) on linear axes when `weighted`, else R(r) on a log y axis.
fn profile_panel(title: &str, weighted: bool, series: Vec<Curve>) -> LinePlot {
    LinePlot {
        title: format!("{title}: {}", if weighted { "r R(r)" } else { "R(r), log y" }),
        x_label: "r (mm)".into(),
        y_label: if weighted { "r R(r) (1/mm)".into() } else { "R(r) (1/mm^2)".into() },
        log_x: false,
        log_y: !weighted,
        series,
    }
}

/// The same two panels for a reference already on bins ([`crate::transport::compare::BinnedReference`]: a Monte
/// Carlo profile per entering flux, or a spectral projection of several), with any number of models' annulus means
/// (`models`: values per bin and legend name; the first dashed in a darker shade, the next dotted-dark further).
pub fn reference_panels(
    reference: &crate::transport::compare::BinnedReference,
    models: &[(&[[f64; 3]], &str)],
    title: &str,
) -> [LinePlot; 2] {
    let radii: Vec<f64> = (0..reference.r_mm2.len()).map(|i| (i as f64 + 0.5) * reference.bin_mm).collect();
    let panel = |weighted: bool| {
        let k = |r: f64| if weighted { r } else { 1.0 };
        let mut series = Vec::new();
        for c in 0..3 {
            let means = reference.r_mm2.iter().map(|v| v[c]);
            series.push(Curve {
                label: format!("Monte Carlo {}", NAMES[c]),
                color: CHANNEL_COLORS[c],
                dashed: false,
                points: radii.iter().zip(means).map(|(&r, m)| (r, k(r) * m)).collect(),
            });
            for (i, &r) in radii.iter().enumerate() {
                let (m, se) = (reference.r_mm2[i][c], reference.r_se_mm2[i][c]);
                if se > 0.0 && m > 0.0 {
                    let lo = if weighted { m - se } else { (m - se).max(0.01 * m) };
                    series.push(Curve {
                        label: String::new(),
                        color: CHANNEL_COLORS[c],
                        dashed: false,
                        points: vec![(r, k(r) * lo), (r, k(r) * (m + se))],
                    });
                }
            }
        }
        for (j, (values, name)) in models.iter().enumerate() {
            for c in 0..3 {
                series.push(Curve {
                    label: format!("{name} {}", NAMES[c]),
                    color: CHANNEL_COLORS[c].map(|v| v / (2 + j as u8)),
                    dashed: true,
                    points: radii.iter().zip(values.iter()).map(|(&r, v)| (r, k(r) * v[c])).collect(),
                });
            }
        }
        profile_panel(title, weighted, series)
    };
    [panel(true), panel(false)]
}
