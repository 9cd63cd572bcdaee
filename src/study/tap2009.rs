//! TAP 2009 Table II (Jimenez, Sundstedt & Gutierrez 2009, §6): "Output for the Chi-Square Analysis (df = 1, 0.05
//! Level of Significance)" of the 2AFC study, 32 responses per comparison (16 participants, each pair shown twice, §5.2), TS (texture-space diffusion) against
//! No SSS, SS Jittered and SS Full at three camera distances (Far, Near, Zoom) and four light angles.
//!
//! The paper prints χ² and p only. The counts are the ones those χ² imply: χ² = (2c − 32)²/32 has the two roots
//! c = 16 ± √(8χ²), and the larger one is taken because the paper reports that TS was chosen at or above chance in
//! every comparison (§6, Fig. 8: "TS was chosen over SS Full slightly above chance"). E.g. 22 of 32 ↔ χ² 4.5.
//! [`PUBLISHED`] keeps the printed χ² and p beside each count so the reproduction can be checked.

use super::PreferenceCount;

/// One row of Table II: configuration, shader compared with TS, TS chosen of 32, printed χ², printed p.
pub struct PublishedRow {
    pub configuration: &'static str,
    pub shader: &'static str,
    pub ts_chosen: u64,
    pub chi2: f64,
    pub p_value: f64,
}

/// Responses per comparison ("an expected 16/16 (32 for each comparison)"): 16 participants, each of whom saw
/// every pair twice (§5.2, counterbalanced order).
pub const RESPONSES_PER_COMPARISON: u64 = 32;
/// Participants of the study (§5.2); each answered every comparison twice.
pub const PARTICIPANTS: u64 = 16;

const fn row(
    configuration: &'static str,
    shader: &'static str,
    ts_chosen: u64,
    chi2: f64,
    p_value: f64,
) -> PublishedRow {
    PublishedRow { configuration, shader, ts_chosen, chi2, p_value }
}

/// Table II, row by row (configuration) and column by column (No SSS, SS Jittered, SS Full).
#[rustfmt::skip]
pub const PUBLISHED: [PublishedRow; 36] = [
    row("TS - Far - 0°", "No SSS", 29, 21.125, 0.000), row("TS - Far - 0°", "SS Jittered", 29, 21.125, 0.000), row("TS - Far - 0°", "SS Full", 21, 3.125, 0.077),
    row("TS - Far - 60°", "No SSS", 31, 28.125, 0.000), row("TS - Far - 60°", "SS Jittered", 28, 18.0, 0.000), row("TS - Far - 60°", "SS Full", 21, 3.125, 0.077),
    row("TS - Far - 110°", "No SSS", 30, 24.5, 0.000), row("TS - Far - 110°", "SS Jittered", 27, 15.125, 0.000), row("TS - Far - 110°", "SS Full", 17, 0.125, 0.724),
    row("TS - Far - 150°", "No SSS", 32, 32.0, 0.000), row("TS - Far - 150°", "SS Jittered", 27, 15.125, 0.000), row("TS - Far - 150°", "SS Full", 16, 0.0, 1.0),
    row("TS - Near - 0°", "No SSS", 32, 32.0, 0.000), row("TS - Near - 0°", "SS Jittered", 31, 28.125, 0.000), row("TS - Near - 0°", "SS Full", 16, 0.0, 1.0),
    row("TS - Near - 60°", "No SSS", 32, 32.0, 0.000), row("TS - Near - 60°", "SS Jittered", 31, 28.125, 0.000), row("TS - Near - 60°", "SS Full", 17, 0.125, 0.724),
    row("TS - Near - 110°", "No SSS", 30, 24.5, 0.000), row("TS - Near - 110°", "SS Jittered", 31, 28.125, 0.000), row("TS - Near - 110°", "SS Full", 19, 1.125, 0.289),
    row("TS - Near - 150°", "No SSS", 32, 32.0, 0.000), row("TS - Near - 150°", "SS Jittered", 29, 21.125, 0.000), row("TS - Near - 150°", "SS Full", 17, 0.125, 0.724),
    row("TS - Zoom - 0°", "No SSS", 31, 28.125, 0.000), row("TS - Zoom - 0°", "SS Jittered", 31, 28.125, 0.000), row("TS - Zoom - 0°", "SS Full", 18, 0.5, 0.480),
    row("TS - Zoom - 60°", "No SSS", 31, 28.125, 0.000), row("TS - Zoom - 60°", "SS Jittered", 28, 18.0, 0.000), row("TS - Zoom - 60°", "SS Full", 20, 2.0, 0.157),
    row("TS - Zoom - 110°", "No SSS", 32, 32.0, 0.000), row("TS - Zoom - 110°", "SS Jittered", 27, 15.125, 0.000), row("TS - Zoom - 110°", "SS Full", 22, 4.5, 0.034),
    row("TS - Zoom - 150°", "No SSS", 32, 32.0, 0.000), row("TS - Zoom - 150°", "SS Jittered", 28, 18.0, 0.000), row("TS - Zoom - 150°", "SS Full", 18, 0.5, 0.480),
];

/// The implied counts as the input of [`super::chi_square_2afc`]: comparison "TS vs SHADER", TS chosen of 32 responses.
pub fn implied_counts() -> Vec<PreferenceCount> {
    PUBLISHED
        .iter()
        .map(|r| PreferenceCount {
            configuration: r.configuration.to_string(),
            comparison: format!("TS vs {}", r.shader),
            chosen: r.ts_chosen,
            total: RESPONSES_PER_COMPARISON,
        })
        .collect()
}

/// The implied counts as the counts CSV `rtbake report chi2 --counts` reads.
pub fn implied_counts_csv() -> String {
    let mut s = String::from("configuration,comparison,chosen,total\n");
    for c in implied_counts() {
        s.push_str(&format!("{},{},{},{}\n", c.configuration, c.comparison, c.chosen, c.total));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{chi_square_2afc, parse_counts_csv};

    /// Every χ² and p of Table II, to the printed precision, and the paper's reading of significance: No SSS and
    /// SS Jittered always differ from TS; SS Full differs only at Zoom 110°.
    #[test]
    fn reproduces_table_ii() {
        let counts = parse_counts_csv(&implied_counts_csv()).unwrap();
        assert_eq!(counts, implied_counts());
        for (c, r) in counts.iter().zip(PUBLISHED.iter()) {
            let t = chi_square_2afc(c.chosen, c.total, 0.05).unwrap();
            assert_eq!(t.chi2, r.chi2, "{} {}", r.configuration, r.shader);
            assert!(
                (t.p_value - r.p_value).abs() <= 0.0005,
                "{} {}: p {} vs {}",
                r.configuration,
                r.shader,
                t.p_value,
                r.p_value
            );
            let expect_significant = r.shader != "SS Full" || r.configuration == "TS - Zoom - 110°";
            assert_eq!(t.significant, expect_significant, "{} {}", r.configuration, r.shader);
        }
    }
}
