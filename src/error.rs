//! Input validation shared by every user-facing path.
//!
//! Library modules define one `thiserror` enum per operation; the checks here produce the common
//! [`InvalidInput`] they wrap, named after the parameter's field (struct field / JSON key) so a user can fix the
//! call ("radius_texels must be in 1..=512 texels, got 0"); the CLI prints each field as its flag.

use std::fmt::Display;

/// A parameter or input file that is out of its accepted range or malformed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{param} {message}")]
pub struct InvalidInput {
    /// The field, e.g. `max_distance`, `layers[1].thickness_mm`, a pair `width/height` or a field and the value
    /// it concerns (`target cheek`). A message names another setting as its field between backticks
    /// (`` `cpu` ``); the CLI turns both into flags (`bin/rtbake/flags.rs`).
    pub param: String,
    /// What is wrong and what is accepted.
    pub message: String,
}

impl InvalidInput {
    pub fn new(param: impl Into<String>, message: impl Into<String>) -> Self {
        Self { param: param.into(), message: message.into() }
    }
}

/// `value` must be finite and within `min..=max` (`unit` is printed after the range).
pub fn check_range<T: PartialOrd + Display + Copy>(
    param: &str,
    value: T,
    min: T,
    max: T,
    unit: &str,
) -> Result<T, InvalidInput> {
    // `!(a <= b)` also rejects NaN for floats.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(min <= value && value <= max) {
        let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
        return Err(InvalidInput::new(param, format!("must be in {min}..={max}{unit}, got {value}")));
    }
    Ok(value)
}

/// `value` must be finite and `> 0`.
pub fn check_positive(param: &str, value: f64, unit: &str) -> Result<f64, InvalidInput> {
    if !(value.is_finite() && value > 0.0) {
        let unit = if unit.is_empty() { String::new() } else { format!(" ({unit})") };
        return Err(InvalidInput::new(param, format!("must be a finite number > 0{unit}, got {value}")));
    }
    Ok(value)
}

/// `value` must be finite and `>= 0`.
pub fn check_non_negative(param: &str, value: f64, unit: &str) -> Result<f64, InvalidInput> {
    if !(value.is_finite() && value >= 0.0) {
        let unit = if unit.is_empty() { String::new() } else { format!(" ({unit})") };
        return Err(InvalidInput::new(param, format!("must be a finite number >= 0{unit}, got {value}")));
    }
    Ok(value)
}

/// Largest texture edge any baker accepts; requests above are refused before allocating.
pub const MAX_TEXTURE_EDGE: u32 = 16384;

/// Image/LUT dimensions must be in `1..=MAX_TEXTURE_EDGE` each.
pub fn check_size(param: &str, width: u64, height: u64) -> Result<(u32, u32), InvalidInput> {
    let max = MAX_TEXTURE_EDGE as u64;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(InvalidInput::new(
            param,
            format!("must be between 1x1 and {max}x{max} texels, got {width}x{height}"),
        ));
    }
    Ok((width as u32, height as u32))
}
