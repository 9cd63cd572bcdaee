//! TAP 2009 Fig. 8 (thesis Fig. 4.9): "Results of our psychophysical experiments for varying light position (left)
//! and distance to the camera (right)". Each point is the proportion of trials in which TS was chosen over the
//! other shader, pooled over the conditions of the other factor: 1 means TS always won, 0.5 is chance (no
//! perceived difference). Pooling sums counts (Σ chosen / Σ total), so unequal totals weigh as the trials did.
//!
//! A configuration names its conditions as Table II does, `"TS - Far - 110°"`: a camera distance (zoom, near, far;
//! any case) and a light azimuth in degrees (a number followed by `°` or `deg`). Rows whose configuration names
//! neither are left out of the corresponding panel; [`Proportions::unparsed`] counts them.

use super::PreferenceCount;
use crate::mesh::framing::TapDistance;

/// One point of Fig. 8: a comparison (e.g. "TS vs SS Full") at one level of one factor.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Proportion {
    pub comparison: String,
    pub chosen: u64,
    pub total: u64,
    /// chosen / total.
    pub proportion: f64,
}

/// Fig. 8's two panels.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Proportions {
    /// Per light azimuth (degrees, ascending), pooled over the distances.
    pub by_light_azimuth_deg: Vec<(f64, Vec<Proportion>)>,
    /// Per camera distance (zoom, near, far), pooled over the light angles.
    pub by_distance: Vec<(TapDistance, Vec<Proportion>)>,
    /// Rows whose configuration names no distance and no angle.
    pub unparsed: usize,
}

/// The distance and light azimuth a configuration names (see the module doc).
pub fn conditions(configuration: &str) -> (Option<TapDistance>, Option<f64>) {
    let mut distance = None;
    let mut azimuth = None;
    for part in configuration.split(['-', ',', ';', '/']).map(str::trim) {
        if let Some(d) = TapDistance::parse(&part.to_ascii_lowercase()) {
            distance = Some(d);
        }
        let number = part.strip_suffix('°').or_else(|| part.strip_suffix("deg")).map(str::trim);
        if let Some(v) = number.and_then(|n| n.parse::<f64>().ok()).filter(|v| v.is_finite()) {
            azimuth = Some(v);
        }
    }
    (distance, azimuth)
}

/// Adds `c` into the group's per-comparison sums (kept in first-seen order).
fn add(group: &mut Vec<Proportion>, c: &PreferenceCount) {
    match group.iter_mut().find(|p| p.comparison == c.comparison) {
        Some(p) => {
            p.chosen += c.chosen;
            p.total += c.total;
        }
        None => group.push(Proportion {
            comparison: c.comparison.clone(),
            chosen: c.chosen,
            total: c.total,
            proportion: 0.0,
        }),
    }
}

/// Fig. 8's proportions of `counts`.
pub fn preference_proportions(counts: &[PreferenceCount]) -> Proportions {
    let mut out = Proportions::default();
    for c in counts {
        let (d, a) = conditions(&c.configuration);
        if d.is_none() && a.is_none() {
            out.unparsed += 1;
        }
        if let Some(a) = a {
            let i = match out.by_light_azimuth_deg.iter().position(|(x, _)| *x == a) {
                Some(i) => i,
                None => {
                    out.by_light_azimuth_deg.push((a, Vec::new()));
                    out.by_light_azimuth_deg.len() - 1
                }
            };
            add(&mut out.by_light_azimuth_deg[i].1, c);
        }
        if let Some(d) = d {
            let i = match out.by_distance.iter().position(|(x, _)| *x == d) {
                Some(i) => i,
                None => {
                    out.by_distance.push((d, Vec::new()));
                    out.by_distance.len() - 1
                }
            };
            add(&mut out.by_distance[i].1, c);
        }
    }
    out.by_light_azimuth_deg.sort_by(|a, b| a.0.total_cmp(&b.0));
    out.by_distance.sort_by(|a, b| a.0.tap_units().total_cmp(&b.0.tap_units()));
    for g in out.by_light_azimuth_deg.iter_mut().map(|g| &mut g.1).chain(out.by_distance.iter_mut().map(|g| &mut g.1)) {
        for p in g.iter_mut() {
            p.proportion = if p.total > 0 { p.chosen as f64 / p.total as f64 } else { f64::NAN };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::tap2009;

    #[test]
    fn conditions_are_read_from_table_ii_names() {
        assert_eq!(conditions("TS - Far - 110°"), (Some(TapDistance::Far), Some(110.0)));
        assert_eq!(conditions("zoom, 60deg"), (Some(TapDistance::Zoom), Some(60.0)));
        assert_eq!(conditions("session 3"), (None, None));
    }

    /// TAP 2009 Fig. 8 from Table II's implied counts: SS Full sits near chance at every angle and distance (TS
    /// chosen 16–22 of 32 per cell, so 0.5–0.69 pooled), No SSS near 1; each point pools 3 distances or 4 angles
    /// of 32 responses (16 participants, each pair twice).
    #[test]
    fn table_ii_gives_fig_8() {
        let p = preference_proportions(&tap2009::implied_counts());
        assert_eq!(p.unparsed, 0);
        let angles: Vec<f64> = p.by_light_azimuth_deg.iter().map(|g| g.0).collect();
        assert_eq!(angles, vec![0.0, 60.0, 110.0, 150.0]);
        let dists: Vec<TapDistance> = p.by_distance.iter().map(|g| g.0).collect();
        assert_eq!(dists, vec![TapDistance::Zoom, TapDistance::Near, TapDistance::Far]);
        let at =
            |g: &Vec<Proportion>, s: &str| g.iter().find(|x| x.comparison == format!("TS vs {s}")).unwrap().clone();
        // 0°: SS Full chosen 21 + 16 + 18 = 55 of 96; No SSS 29 + 32 + 31 = 92 of 96.
        let zero = &p.by_light_azimuth_deg[0].1;
        assert_eq!((at(zero, "SS Full").chosen, at(zero, "SS Full").total), (55, 96));
        assert_eq!(at(zero, "No SSS").chosen, 92);
        // Far: SS Full 21 + 21 + 17 + 16 = 75 of 128.
        let far = &p.by_distance[2].1;
        assert_eq!((at(far, "SS Full").chosen, at(far, "SS Full").total), (75, 128));
        for g in p.by_light_azimuth_deg.iter().map(|g| &g.1).chain(p.by_distance.iter().map(|g| &g.1)) {
            let (full, none, jit) = (at(g, "SS Full"), at(g, "No SSS"), at(g, "SS Jittered"));
            assert!(full.proportion >= 0.5 && full.proportion < 0.65, "{full:?}");
            assert!(none.proportion > 0.9 && jit.proportion > 0.8, "{none:?} {jit:?}");
            assert!(full.proportion < jit.proportion && jit.proportion <= none.proportion + 0.06);
        }
    }
}
