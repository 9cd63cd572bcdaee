//! Plots, in one place: [`line`](mod@line) draws line plots as SVG and as raster images (for PNG) with a built-in font;
//! [`profile`] turns a diffusion-profile table into its two-panel plot; [`transport`] a Monte Carlo result against
//! a diffusion profile; [`preview`] frames a lookup table's pixels with a title, axis names and ticks;
//! [`preference`] TAP 2009 Fig. 8's preference proportions; [`sheet`] contact sheets and difference images. Pure: text or pixels; callers write files.

pub mod line;
pub mod preference;
pub mod preview;
pub mod profile;
pub mod separable;
pub mod sheet;
pub mod transport;

pub use line::{panels_to_image, panels_to_svg, Curve, LinePlot, LOG_Y_DECADES};
