//! The one-sample χ² test of a two-alternative forced-choice experiment (TAP 2009 §6, Table II: "df = 1, 0.05
//! level of significance"; the frequencies are "compared to an expected 16/16 result").
//!
//! With `chosen` of `total` participants picking the first alternative, the expected count of each alternative is
//! E = total/2 and
//!
//! χ² = (chosen − E)²/E + (total − chosen − E)²/E = (2·chosen − total)² / total,
//!
//! with one degree of freedom and no continuity correction (Table II's 4.5 for 22 of 32 is (44 − 32)²/32). The
//! p-value is the χ²₁ survival function, P(X ≥ χ²) = erfc(√(χ²/2)); the choice is significant at level α when
//! p < α (for α = 0.05 that is χ² > 3.841).

use crate::error::InvalidInput;

/// One comparison of a 2AFC study: how many of `total` participants chose the first alternative.
#[derive(Clone, Debug, PartialEq)]
pub struct PreferenceCount {
    /// What was shown (e.g. "TS - Far - 0°").
    pub configuration: String,
    /// The pair compared (e.g. "TS vs SS Full").
    pub comparison: String,
    pub chosen: u64,
    pub total: u64,
}

/// The test's result for one comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquare {
    pub chi2: f64,
    /// P(χ²₁ ≥ chi2).
    pub p_value: f64,
    /// p < α.
    pub significant: bool,
}

/// Largest number of participants accepted per comparison (the counts stay exact in f64 far beyond it).
pub const MAX_PARTICIPANTS: u64 = 1 << 40;

/// χ² (df = 1) of `chosen` of `total` against the 50/50 expectation, its p-value and significance at `alpha`.
pub fn chi_square_2afc(chosen: u64, total: u64, alpha: f64) -> Result<ChiSquare, InvalidInput> {
    if total == 0 || total > MAX_PARTICIPANTS {
        return Err(InvalidInput::new("total", format!("{total} is outside 1..={MAX_PARTICIPANTS}")));
    }
    if chosen > total {
        return Err(InvalidInput::new("chosen", format!("{chosen} exceeds total {total}; accepted 0..={total}")));
    }
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(InvalidInput::new("alpha", format!("{alpha} is outside the open interval (0, 1)")));
    }
    let d = 2.0 * chosen as f64 - total as f64;
    let chi2 = d * d / total as f64;
    let p_value = erfc((chi2 / 2.0).sqrt());
    Ok(ChiSquare { chi2, p_value, significant: p_value < alpha })
}

/// Parses a counts CSV: a header `configuration,comparison,chosen,total`, then one row per comparison with
/// non-negative integer counts, chosen ≤ total. Errors name the line and the column.
pub fn parse_counts_csv(text: &str) -> Result<Vec<PreferenceCount>, InvalidInput> {
    const HEADER: &str = "configuration,comparison,chosen,total";
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    match lines.next() {
        Some((_, h)) if h.split(',').map(str::trim).eq(HEADER.split(',')) => {}
        Some((i, h)) => {
            return Err(InvalidInput::new(format!("line {}", i + 1), format!("header is {h:?}; expected {HEADER:?}")))
        }
        None => return Err(InvalidInput::new("counts", format!("empty; expected the header {HEADER:?} and rows"))),
    }
    let mut rows = Vec::new();
    for (i, line) in lines {
        let at = |col: &str| format!("line {} column {col}", i + 1);
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 4 {
            return Err(InvalidInput::new(
                format!("line {}", i + 1),
                format!("has {} fields; expected 4 ({HEADER})", fields.len()),
            ));
        }
        let count = |col: &str, s: &str| -> Result<u64, InvalidInput> {
            s.parse::<u64>()
                .map_err(|_| InvalidInput::new(at(col), format!("{s:?} is not a non-negative integer count")))
        };
        let chosen = count("chosen", fields[2])?;
        let total = count("total", fields[3])?;
        if total == 0 || total > MAX_PARTICIPANTS {
            return Err(InvalidInput::new(at("total"), format!("{total} is outside 1..={MAX_PARTICIPANTS}")));
        }
        if chosen > total {
            return Err(InvalidInput::new(at("chosen"), format!("{chosen} exceeds total {total}")));
        }
        rows.push(PreferenceCount {
            configuration: fields[0].to_string(),
            comparison: fields[1].to_string(),
            chosen,
            total,
        });
    }
    if rows.is_empty() {
        return Err(InvalidInput::new("counts", "has a header but no rows"));
    }
    Ok(rows)
}

/// The complementary error function erfc(x) for x ≥ 0, to about 1e-15 relative: the Maclaurin series of erf below
/// x = 2.5, the continued fraction erfc(x) = e^(−x²)/√π · 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + …)))) above it
/// (Abramowitz & Stegun 7.1.5 and 7.1.14), evaluated by the modified Lentz method.
pub fn erfc(x: f64) -> f64 {
    debug_assert!(x >= 0.0 || x.is_nan());
    if x.is_nan() {
        return f64::NAN;
    }
    const FRAC_2_SQRT_PI: f64 = std::f64::consts::FRAC_2_SQRT_PI;
    if x < 2.5 {
        // erf(x) = 2/√π Σ (−1)ⁿ x^(2n+1) / (n! (2n+1))
        let x2 = x * x;
        let (mut term, mut sum, mut n) = (x, x, 0.0f64);
        loop {
            n += 1.0;
            term *= -x2 / n;
            let add = term / (2.0 * n + 1.0);
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() {
                break;
            }
        }
        return 1.0 - FRAC_2_SQRT_PI * sum;
    }
    // Continued fraction b0 + a1/(b1 + a2/(b2 + …)) with b_k = x, a_k = k/2.
    let tiny = 1e-300;
    let mut f = x;
    let (mut c, mut d) = (x, 0.0f64);
    for k in 1..500 {
        let a = k as f64 / 2.0;
        d = x + a * d;
        d = if d.abs() < tiny { tiny } else { d };
        c = x + a / c;
        c = if c.abs() < tiny { tiny } else { c };
        d = 1.0 / d;
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x * x).exp() / (std::f64::consts::PI.sqrt() * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfc_matches_tabulated_values() {
        // Abramowitz & Stegun Table 7.1 / high-precision values.
        for (x, want) in [
            (0.0, 1.0),
            (0.5, 0.479_500_122_186_953_5),
            (1.0, 0.157_299_207_050_285_1),
            (2.0, 0.004_677_734_981_047_266),
            (2.5, 0.000_406_952_017_444_959),
            (3.0, 2.209_049_699_858_544e-5),
            (5.0, 1.537_459_794_428_035e-12),
        ] {
            let got = erfc(x);
            assert!(((got - want) / want).abs() < 1e-12, "erfc({x}) = {got}, want {want}");
        }
    }

    #[test]
    fn critical_value_at_five_percent() {
        // χ²₁ quantile 0.95 = 3.841458820694124.
        let p = erfc((3.841_458_820_694_124f64 / 2.0).sqrt());
        assert!((p - 0.05).abs() < 1e-12, "{p}");
    }

    #[test]
    fn the_papers_example_and_the_symmetry() {
        let r = chi_square_2afc(22, 32, 0.05).unwrap();
        assert_eq!(r.chi2, 4.5);
        assert!((r.p_value - 0.0339).abs() < 1e-4 && r.significant);
        assert_eq!(chi_square_2afc(10, 32, 0.05).unwrap(), r);
        let even = chi_square_2afc(16, 32, 0.05).unwrap();
        assert_eq!((even.chi2, even.p_value, even.significant), (0.0, 1.0, false));
    }

    #[test]
    fn bad_counts_are_refused_naming_the_field() {
        assert_eq!(chi_square_2afc(33, 32, 0.05).unwrap_err().param, "chosen");
        assert_eq!(chi_square_2afc(0, 0, 0.05).unwrap_err().param, "total");
        assert_eq!(chi_square_2afc(1, 2, 1.0).unwrap_err().param, "alpha");
        let bad = |body: &str| parse_counts_csv(body).unwrap_err().param;
        let h = "configuration,comparison,chosen,total\n";
        assert_eq!(bad(&format!("{h}a,b,-3,32\n")), "line 2 column chosen");
        assert_eq!(bad(&format!("{h}a,b,2.5,32\n")), "line 2 column chosen");
        assert_eq!(bad(&format!("{h}a,b,3,x\n")), "line 2 column total");
        assert_eq!(bad(&format!("{h}a,b,40,32\n")), "line 2 column chosen");
        assert_eq!(bad(&format!("{h}a,b,3\n")), "line 2");
        assert_eq!(bad("x,y\n"), "line 1");
        assert_eq!(bad(h), "counts");
        assert_eq!(bad(""), "counts");
    }
}
