//! The separable-SSS fit as a plot (thesis ch. 6, eq. 6.1): the pixel-filtered target kernel S̃(x, 0) beside the
//! separable model s̃(x)·s̃(0) along the x axis, per channel, on a log y axis (`rtbake evaluate --candidate-separable
//! … --plot`). The rows come from [`crate::separable::fit::axis_rows`].

use super::line::{Curve, LinePlot};
use super::profile::CHANNEL_COLORS;
use crate::separable::fit::{axis_rows, TargetKernel};
use crate::separable::SeparableParams;

/// Target (solid) and separable model (dashed, half brightness) per channel; `label` names the target.
pub fn separable_kernel_plot(target: &TargetKernel, params: &SeparableParams, label: &str) -> LinePlot {
    let names = ["R", "G", "B"];
    let mut series = Vec::new();
    for (c, rows) in axis_rows(target, params).into_iter().enumerate() {
        series.push(Curve {
            label: format!("target {}", names[c]),
            color: CHANNEL_COLORS[c],
            dashed: false,
            points: rows.target,
        });
        series.push(Curve {
            label: format!("separable {}", names[c]),
            color: CHANNEL_COLORS[c].map(|v| v / 2),
            dashed: true,
            points: rows.model,
        });
    }
    LinePlot {
        title: format!("separable kernel vs {label} (pixel-filtered, y = 0)"),
        x_label: "x (mm)".into(),
        y_label: "kernel (1/mm^2)".into(),
        log_x: false,
        log_y: true,
        series,
    }
}
