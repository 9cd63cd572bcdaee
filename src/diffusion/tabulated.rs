//! A user's own profile: R(r) tabulated in a CSV (measured, or from `rtbake profile --csv` / `rtbake transport
//! --csv`), read with row-numbered validation and interpolated for the fits.
//!
//! Layout (the one `rtbake profile --csv` writes, `DiffusionTable::to_csv`): `#` comment lines, a header whose first
//! column is `r_mm` followed by `R_r,R_g,R_b` (more columns, e.g. `T_*`, are ignored) or by a single `R` (one channel,
//! used for R, G and B), then one row per radius: r in mm, strictly increasing, any spacing; R in mm⁻², finite and
//! non-negative; at least two rows. Between rows R is interpolated linearly in log r (the profiles' natural
//! variable; linear in r where a row is at r = 0); below the first radius it is held at the first row's value, above
//! the last it is 0. The totals ∫ 2πr R(r) dr are integrated exactly for that interpolant by adaptive Simpson on each
//! interval.

use super::RadialProfile;
use crate::error::InvalidInput;
use std::f64::consts::PI;

/// The headers a profile CSV may start with, for messages.
pub const EXPECTED_HEADERS: &str = "r_mm,R_r,R_g,R_b (also r_mm,R,G,B or r_mm,red,green,blue; more columns after \
     the three, e.g. T_r,T_g,T_b, are ignored) or exactly r_mm,R for one channel";

/// The number of reflectance channels a header declares (3 or 1), or `None` when it is not one of
/// [`EXPECTED_HEADERS`]. A single `R` column is accepted only alone, so no channel column is ever silently dropped.
fn header_channels(cols: &[&str]) -> Option<usize> {
    let lower: Vec<String> = cols.iter().map(|c| c.to_ascii_lowercase().replace([' ', '(', ')'], "")).collect();
    if !matches!(lower.first().map(String::as_str), Some("r_mm" | "rmm")) {
        return None;
    }
    let rgb = |a: &str, b: &str, c: &str| lower.len() >= 4 && lower[1] == a && lower[2] == b && lower[3] == c;
    if rgb("r_r", "r_g", "r_b")
        || rgb("r", "g", "b")
        || rgb("red", "green", "blue")
        || rgb("r_red", "r_green", "r_blue")
    {
        return Some(3);
    }
    (lower.len() == 2 && lower[1] == "r").then_some(1)
}

/// R(r) per channel at tabulated radii.
#[derive(Clone, Debug, PartialEq)]
pub struct TabulatedProfile {
    pub r_mm: Vec<f64>,
    pub reflectance_mm2: Vec<[f64; 3]>,
    totals: [f64; 3],
}

impl TabulatedProfile {
    /// Parses and validates a CSV; errors name `source` and the offending (1-based) line.
    pub fn from_csv_str(text: &str, source: &str) -> Result<Self, InvalidInput> {
        let err = |line: usize, msg: String| InvalidInput::new(format!("{source} row {line}"), msg);
        // Spreadsheet programs start a UTF-8 CSV with a byte-order mark.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut lines =
            text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((hl, header)) = lines.next() else {
            return Err(InvalidInput::new(source, format!("is empty: expected a header {EXPECTED_HEADERS} and rows")));
        };
        let cols: Vec<&str> = header.split(',').map(|c| c.trim().trim_matches('"')).collect();
        let channels = header_channels(&cols).ok_or_else(|| {
            err(
                hl + 1,
                format!("header must be {EXPECTED_HEADERS}, got '{}'", header.trim().trim_start_matches('\u{feff}')),
            )
        })?;
        let (mut r_mm, mut refl) = (Vec::new(), Vec::new());
        for (i, line) in lines {
            let n = i + 1;
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() < 1 + channels {
                return Err(err(n, format!("expected {} values, got {}", 1 + channels, fields.len())));
            }
            if fields.len() > cols.len() {
                return Err(err(
                    n,
                    format!(
                        "has {} values but the header names {} columns; no value is dropped",
                        fields.len(),
                        cols.len()
                    ),
                ));
            }
            let mut vals = [0.0f64; 4];
            for (k, f) in fields[..1 + channels].iter().enumerate() {
                let v: f64 = f.parse().map_err(|_| err(n, format!("'{f}' is not a number")))?;
                if !v.is_finite() {
                    return Err(err(n, format!("{} is not finite", cols[k])));
                }
                if v < 0.0 {
                    return Err(err(n, format!("{} = {v} is negative", cols[k])));
                }
                vals[k] = v;
            }
            if let Some(&prev) = r_mm.last() {
                if vals[0] <= prev {
                    return Err(err(n, format!("r_mm = {} does not increase (previous row {prev})", vals[0])));
                }
            }
            r_mm.push(vals[0]);
            refl.push(if channels == 3 { [vals[1], vals[2], vals[3]] } else { [vals[1]; 3] });
        }
        if r_mm.len() < 2 {
            return Err(InvalidInput::new(source, format!("needs at least 2 rows, has {}", r_mm.len())));
        }
        let mut p = Self { r_mm, reflectance_mm2: refl, totals: [0.0; 3] };
        p.totals = p.integrate_totals();
        Ok(p)
    }

    fn interpolate(&self, r: f64) -> [f64; 3] {
        let (rs, vs) = (&self.r_mm, &self.reflectance_mm2);
        if r <= rs[0] {
            return vs[0];
        }
        if r > rs[rs.len() - 1] {
            return [0.0; 3];
        }
        let k = rs.partition_point(|&x| x < r).clamp(1, rs.len() - 1);
        let (r0, r1) = (rs[k - 1], rs[k]);
        let t = if r0 > 0.0 { (r / r0).ln() / (r1 / r0).ln() } else { (r - r0) / (r1 - r0) };
        let (a, b) = (vs[k - 1], vs[k]);
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])]
    }

    /// ∫ 2πr R dr of the interpolant: πr₀²R₀ for the held part, then Simpson on every interval (64 panels).
    fn integrate_totals(&self) -> [f64; 3] {
        let mut tot = self.reflectance_mm2[0].map(|v| PI * self.r_mm[0] * self.r_mm[0] * v);
        for w in self.r_mm.windows(2) {
            let (a, b) = (w[0], w[1]);
            let n = 64;
            let h = (b - a) / n as f64;
            for k in 0..=n {
                let r = a + k as f64 * h;
                let wt = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let v = self.interpolate(r);
                for c in 0..3 {
                    tot[c] += wt * h / 3.0 * 2.0 * PI * r * v[c];
                }
            }
        }
        tot
    }
}

impl RadialProfile for TabulatedProfile {
    fn reflectance_mm2(&self, r_mm: f64) -> [f64; 3] {
        self.interpolate(r_mm)
    }

    fn total_reflectance(&self) -> [f64; 3] {
        self.totals
    }

    fn support_mm(&self) -> Option<(f64, f64)> {
        Some((self.r_mm[0], *self.r_mm.last().expect(">= 2 rows")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_profile_csv_layout_and_interpolates_between_rows() {
        let csv = "# rtbake profile: {}\n# total_R (r,g,b): 1,1,1\nr_mm,R_r,R_g,R_b,T_r,T_g,T_b\n0.1,4,2,1,0,0,0\n1,2,1,0.5,0,0,0\n10,0,0,0,0,0,0\n";
        let p = TabulatedProfile::from_csv_str(csv, "p.csv").unwrap();
        assert_eq!(p.r_mm, vec![0.1, 1.0, 10.0]);
        assert_eq!(p.reflectance_mm2(0.05), [4.0, 2.0, 1.0]);
        assert_eq!(p.reflectance_mm2(1.0), [2.0, 1.0, 0.5]);
        // Halfway in log r between 0.1 and 1 (r = 0.316…): halfway in R.
        let mid = p.reflectance_mm2(0.1f64.sqrt());
        assert!((mid[0] - 3.0).abs() < 1e-12, "{mid:?}");
        assert_eq!(p.reflectance_mm2(11.0), [0.0; 3]);
        let one = TabulatedProfile::from_csv_str("r_mm,R\n0,1\n1,1\n", "one.csv").unwrap();
        // Constant R = 1 over [0, 1] (linear in r from a row at 0): total π.
        assert!((one.total_reflectance()[1] - PI).abs() < 1e-12, "{:?}", one.total_reflectance());
    }

    #[test]
    fn spreadsheet_headers_keep_all_three_channels() {
        let want = [[4.0, 2.0, 1.0], [2.0, 1.0, 0.5]];
        for header in ["\u{feff}r_mm,R_r,R_g,R_b", "r_mm,R,G,B", "R_MM,r,g,b", "\"r_mm\",\"red\",\"green\",\"blue\""] {
            let csv = format!("{header}\n0.1,4,2,1\n1,2,1,0.5\n");
            let p = TabulatedProfile::from_csv_str(&csv, "s.csv").unwrap_or_else(|e| panic!("{header}: {e}"));
            assert_eq!(p.reflectance_mm2, want, "{header}");
        }
    }

    #[test]
    fn bad_csvs_name_the_row() {
        for (text, needle) in [
            ("", "is empty"),
            ("# only a comment\n", "is empty"),
            ("x,y\n1,2\n", "row 1"),
            ("r_mm,R\n0.1,1\n", "at least 2 rows"),
            ("r_mm,R\n0.1,1\n0.2,NaN\n", "row 3"),
            ("r_mm,R\n0.1,1\n0.05,1\n", "row 3"),
            ("r_mm,R\n0.1,1\n0.2,-1\n", "row 3"),
            ("r_mm,R_r,R_g,R_b\n0.1,1,1\n", "row 2"),
            ("r_mm,R\n0.1,abc\n0.2,1\n", "row 2"),
            // A third column beside a single R would be dropped: refused, naming the headers accepted.
            ("r_mm,R,X\n0.1,1,1\n0.2,1,1\n", "r_mm,R_r,R_g,R_b"),
            ("r_mm,R\n0.1,1,2\n0.2,1,2\n", "no value is dropped"),
        ] {
            let e = TabulatedProfile::from_csv_str(text, "f.csv").unwrap_err();
            assert!(e.to_string().contains("f.csv") && e.to_string().contains(needle), "{text:?}: {e}");
        }
    }
}
