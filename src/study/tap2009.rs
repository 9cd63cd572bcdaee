//! TAP 2009 Table II (Jimenez, Sundstedt & Gutierrez 2009, §6): "Output for the Chi-Square Analysis (df = 1, 0.05
//! Level of Significance)" of the 2AFC study, 32 responses per comparison (16 participants, each pair shown twice, §5.2), TS (texture-space diffusion) against
//! No SSS, SS Jittered and SS Full at three camera distances (Far, Near, Zoom) and four light angles.
//!
//! The paper prints χ² and p only. The counts are the ones those χ² imply: χ² = (2c − 32)²/32 has the two roots
//! c = 16 ± √(8χ²), and the larger one is taken because the paper reports that TS was chosen at or above chance in
//! every comparison (§6, Fig. 8: "TS was chosen over SS Full slightly above chance"). E.g. 22 of 32 ↔ χ² 4.5.
//! [`published`] keeps the printed χ² and p beside each count so the reproduction can be checked.

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

/// Table II as printed, one comparison a row (`tap2009_table2.csv`: configuration, shader, TS chosen, χ², p), in
/// the paper's order: configurations by distance and angle, shaders No SSS, SS Jittered, SS Full.
pub const TABLE_II_CSV: &str = include_str!("tap2009_table2.csv");

/// The 36 rows of [`TABLE_II_CSV`], parsed once. The file is compiled in, so a malformed row is a bug of the crate
/// (a panic naming the line), caught by the tests.
pub fn published() -> &'static [PublishedRow] {
    static ROWS: std::sync::OnceLock<Vec<PublishedRow>> = std::sync::OnceLock::new();
    ROWS.get_or_init(|| {
        let rows: Vec<PublishedRow> = TABLE_II_CSV
            .lines()
            .filter(|l| !l.starts_with('#') && !l.starts_with("configuration,"))
            .map(|l| {
                let f: Vec<&'static str> = l.split(',').collect();
                let num = |i: usize| {
                    f.get(i).and_then(|t| t.parse::<f64>().ok()).unwrap_or_else(|| panic!("tap2009_table2.csv: {l:?}"))
                };
                PublishedRow {
                    configuration: f[0],
                    shader: f[1],
                    ts_chosen: num(2) as u64,
                    chi2: num(3),
                    p_value: num(4),
                }
            })
            .collect();
        assert_eq!(rows.len(), 36, "tap2009_table2.csv: Table II has 36 comparisons");
        rows
    })
}

/// The implied counts as the input of [`super::chi_square_2afc`]: comparison "TS vs SHADER", TS chosen of 32 responses.
pub fn implied_counts() -> Vec<PreferenceCount> {
    published()
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
        for (c, r) in counts.iter().zip(published().iter()) {
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
