//! Profile tables: radii on a grid, R(r) (and T(r)) per channel, totals R̂(0),
//! T̂(0), and the model options, as CSV text or a JSON value. Pure: callers write the bytes.

use super::RadialProfile;
use crate::error::InvalidInput;
use serde_json::{json, Value};

/// Default table grid: 200 radii log-spaced over [0.001, 100] mm.
pub const DEFAULT_R_MIN_MM: f64 = 1e-3;
pub const DEFAULT_R_MAX_MM: f64 = 100.0;
pub const DEFAULT_COUNT: usize = 200;

/// `count` radii log-spaced over [r_min, r_max] mm (inclusive).
pub fn log_radii(r_min_mm: f64, r_max_mm: f64, count: usize) -> Result<Vec<f64>, InvalidInput> {
    crate::error::check_positive("r_min_mm", r_min_mm, "mm")?;
    crate::error::check_range("r_max_mm", r_max_mm, f64::MIN_POSITIVE, MAX_RADIUS_MM, "mm")?;
    if r_max_mm <= r_min_mm {
        return Err(InvalidInput::new("r_max_mm", format!("must exceed r_min_mm = {r_min_mm}, got {r_max_mm}")));
    }
    crate::error::check_range("count", count, 2, 1_000_000, "radii")?;
    let (a, b) = (r_min_mm.ln(), r_max_mm.ln());
    Ok((0..count).map(|i| (a + (b - a) * i as f64 / (count - 1) as f64).exp()).collect())
}

/// Largest radius a table may ask for, mm (the layered quadrature's node count grows linearly with r).
pub const MAX_RADIUS_MM: f64 = 1000.0;

/// Radii must be non-empty, finite, in [0, [`MAX_RADIUS_MM`]] and sorted ascending.
pub fn check_radii(param: &str, radii_mm: &[f64]) -> Result<(), InvalidInput> {
    if radii_mm.is_empty() {
        return Err(InvalidInput::new(param, "must list at least one radius (mm)"));
    }
    for (i, &r) in radii_mm.iter().enumerate() {
        if !(r.is_finite() && (0.0..=MAX_RADIUS_MM).contains(&r)) {
            return Err(InvalidInput::new(
                param,
                format!("must be in 0..={MAX_RADIUS_MM} mm, got {r} at position {i}"),
            ));
        }
        if i > 0 && r < radii_mm[i - 1] {
            return Err(InvalidInput::new(
                param,
                format!("must be sorted ascending, got {} before {r} at position {i}", radii_mm[i - 1]),
            ));
        }
    }
    Ok(())
}

/// An evaluated profile.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileTable {
    pub r_mm: Vec<f64>,
    /// R(r) per radius, [r, g, b], mm⁻².
    pub reflectance_mm2: Vec<[f64; 3]>,
    /// T(r) per radius for slabs and stacks.
    pub transmittance_mm2: Option<Vec<[f64; 3]>>,
    pub total_reflectance: [f64; 3],
    pub total_transmittance: Option<[f64; 3]>,
    /// Model options (a JSON object) recorded with the table.
    pub provenance: Value,
    /// Negative R or T values set to 0: how many, and the largest magnitude (mm⁻²). A diffusion profile is
    /// non-negative; where the layered model's numerical inverse Hankel transform (absolute error ≈ 1e-12–1e-9 of
    /// the peak) falls below zero at large r, the table holds 0 and says so here (and in its JSON and CSV).
    pub clamped_negative: ClampReport,
}

/// What [`ProfileTable::compute`] clamped (see [`ProfileTable::clamped_negative`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClampReport {
    pub count: usize,
    pub max_abs_mm2: f64,
}

impl ClampReport {
    fn clamp(&mut self, col: &mut [[f64; 3]]) {
        for v in col.iter_mut().flatten() {
            if *v < 0.0 {
                self.count += 1;
                self.max_abs_mm2 = self.max_abs_mm2.max(-*v);
                *v = 0.0;
            }
        }
    }

    /// One sentence for people (CSV comment, stderr), or `None` when nothing was clamped.
    pub fn describe(&self) -> Option<String> {
        (self.count > 0).then(|| {
            format!(
                "{} negative R/T values (largest magnitude {:e} mm^-2, the numerical inverse Hankel transform's error \
                 floor) were set to 0",
                self.count, self.max_abs_mm2
            )
        })
    }
}

impl ProfileTable {
    /// Evaluates `profile` at `radii_mm` (checked with [`check_radii`], errors name `radii`).
    pub fn compute(profile: &dyn RadialProfile, radii_mm: &[f64], provenance: Value) -> Result<Self, InvalidInput> {
        check_radii("radii", radii_mm)?;
        let (mut reflectance_mm2, mut transmittance_mm2) = profile.profile_many(radii_mm);
        let (total_reflectance, total_transmittance) = (profile.total_reflectance(), profile.total_transmittance());
        // Nothing non-finite is ever written: huge but finite coefficients or thicknesses can overflow the model.
        let columns = [("R", Some(&reflectance_mm2)), ("T", transmittance_mm2.as_ref())];
        for (name, col) in columns {
            for (r, v) in radii_mm.iter().zip(col.into_iter().flatten()) {
                if let Some(c) = v.iter().position(|x| !x.is_finite()) {
                    return Err(InvalidInput::new(
                        "profile",
                        format!(
                            "{name}(r) is not finite ({}) at r = {r} mm, channel {}: the model's inputs (coefficients, \
                             thicknesses) are beyond what it evaluates in double precision; nothing was written",
                            v[c],
                            ["r", "g", "b"][c]
                        ),
                    ));
                }
            }
        }
        let totals = [("total R", Some(total_reflectance)), ("total T", total_transmittance)];
        for (name, t) in totals {
            if let Some(t) = t.filter(|t| t.iter().any(|x| !x.is_finite())) {
                return Err(InvalidInput::new(
                    "profile",
                    format!("{name} is not finite ({t:?}): the model's inputs are beyond what it evaluates; nothing was written"),
                ));
            }
        }
        let mut clamped_negative = ClampReport::default();
        clamped_negative.clamp(&mut reflectance_mm2);
        if let Some(t) = transmittance_mm2.as_mut() {
            clamped_negative.clamp(t);
        }
        Ok(Self {
            r_mm: radii_mm.to_vec(),
            reflectance_mm2,
            transmittance_mm2,
            total_reflectance,
            total_transmittance,
            provenance,
            clamped_negative,
        })
    }

    /// `{"r_mm": [...], "R": [[r,g,b], ...], "total_R": [r,g,b], ("T", "total_T",) + provenance keys}`.
    pub fn to_json(&self) -> Value {
        let mut v = json!({
            "r_mm": self.r_mm,
            "R": self.reflectance_mm2,
            "total_R": self.total_reflectance,
        });
        if let Some(t) = &self.transmittance_mm2 {
            v["T"] = json!(t);
        }
        if let Some(t) = &self.total_transmittance {
            v["total_T"] = json!(t);
        }
        if self.clamped_negative.count > 0 {
            v["clamped_negative"] = json!({
                "count": self.clamped_negative.count,
                "max_abs_mm2": self.clamped_negative.max_abs_mm2,
                "reason": "a diffusion profile is non-negative; values below 0 are the numerical inverse Hankel \
                           transform's error floor and were set to 0",
            });
        }
        if let Value::Object(p) = &self.provenance {
            for (k, val) in p {
                if v.get(k).is_none() {
                    v[k] = val.clone();
                }
            }
        }
        v
    }

    /// CSV: a header row, one row per radius, nothing else (no comment lines: pandas, numpy and spreadsheets
    /// read it with their defaults). The provenance, the totals and any clamping note are in [`Self::to_json`].
    pub fn to_csv(&self) -> String {
        let mut s = String::new();
        let t3 = |t: &[f64; 3]| format!("{:e},{:e},{:e}", t[0], t[1], t[2]);
        s.push_str("r_mm,R_r,R_g,R_b");
        if self.transmittance_mm2.is_some() {
            s.push_str(",T_r,T_g,T_b");
        }
        s.push('\n');
        for (i, r) in self.r_mm.iter().enumerate() {
            s.push_str(&format!("{r:e},{}", t3(&self.reflectance_mm2[i])));
            if let Some(t) = &self.transmittance_mm2 {
                s.push_str(&format!(",{}", t3(&t[i])));
            }
            s.push('\n');
        }
        s
    }
}
