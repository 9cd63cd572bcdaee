//! The sRGB transfer curve, IEC 61966-2-1:1999 §5.2 (piecewise: 12.92·v below 0.0031308, else
//! 1.055·v^(1/2.4) − 0.055).

/// sRGB encoding of a linear value, clamped to [0, 1] first.
pub fn encode(linear: f64) -> f64 {
    let v = linear.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear value of an sRGB-encoded one in [0, 1] (the inverse of [`encode`]: v/12.92 up to 0.04045, else
/// ((v + 0.055)/1.055)^2.4).
pub fn decode(encoded: f64) -> f64 {
    let v = encoded.clamp(0.0, 1.0);
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn decode_inverts_encode() {
        for i in 0..=255 {
            let v = i as f64 / 255.0;
            assert!((super::encode(super::decode(v)) - v).abs() < 1e-12, "{v}");
        }
        assert!((super::decode(0.461_356_1) - 0.18).abs() < 1e-6);
    }

    #[test]
    fn mid_grey_and_ends() {
        assert_eq!(super::encode(0.0), 0.0);
        assert!((super::encode(1.0) - 1.0).abs() < 1e-12);
        // 18 % grey encodes to 0.4614; the linear segment ends at 0.0031308 -> 0.04045.
        assert!((super::encode(0.18) - 0.461_356_1).abs() < 1e-6);
        assert!((super::encode(0.003_130_8) - 0.040_449_9).abs() < 1e-6);
        assert!((super::encode(0.5) - 0.735_356_6).abs() < 1e-6);
        assert_eq!(super::encode(2.0), super::encode(1.0));
    }
}
