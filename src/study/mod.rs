//! Psychophysics of the TAP 2009 skin study (Jimenez, Sundstedt & Gutierrez, *Screen-Space Perceptual Rendering of
//! Human Skin*, ACM TAP 6(4), 2009, §6): the one-sample χ² test of a two-alternative forced-choice (2AFC)
//! experiment, and the preference counts that the paper's Table II implies.
//!
//! - [`chi_square`]: χ² = Σ (O − E)² / E over the two choices with E = n/2, df = 1, its p-value
//!   p = erfc(√(χ²/2)), and the significance at a level α.
//! - [`tap2009`]: the 36 comparisons of Table II (12 configurations × 3 shaders against TS) as counts of 32
//!   responses each (16 participants, each pair shown twice, §5.2), with the χ² and p the paper prints, so
//!   `rtbake report chi2 --counts tap2009` reproduces the table.
//! - [`proportions`]: Fig. 8's proportions of TS chosen per light angle and per camera distance.

pub mod chi_square;
pub mod proportions;
pub mod tap2009;

pub use chi_square::{chi_square_2afc, parse_counts_csv, ChiSquare, PreferenceCount};
