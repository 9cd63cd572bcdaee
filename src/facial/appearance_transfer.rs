//! Appearance transfer between characters (thesis §7.4.2; Jimenez et al., "A practical appearance model for dynamic
//! facial color", ACM TOG 29(6), 2010): "it becomes possible to apply relative changes derived from an existing
//! subject's native hemoglobin map to other (for instance hand-painted) maps".
//!
//! A rig built from subject A (neutral Hn^A, targets H_i^A) stores, per target, the local statistics of eq. 7.5:
//! bias_i = μ_i^A and scale_i = σ_i^A / σ_n^A. The *relative* change of target i is the shift of the local mean
//! Δμ_i = μ_i^A − μ_n^A and the ratio of the local spreads scale_i. Applied to another character B with neutral
//! map Hn^B (local statistics μ_n^B, σ_n^B of the same disk, eq. 7.1):
//!
//! ```text
//! bias_0^B = μ_n^B,  H0^B = Hn^B − μ_n^B                         (eq. 7.4–7.5 for B)
//! bias_i^B = μ_n^B + (μ_i^A − μ_n^A),  scale_i^B = σ_i^A / σ_n^A   (A's relative change)
//! ```
//!
//! so eq. 7.6 with target i alone gives H = bias_i^B + scale_i^B·H0^B: by eq. 7.3 a map whose local mean is
//! B's shifted by A's Δμ_i and whose local spread is B's scaled by A's ratio, while B's own vessels and detail
//! (H0^B) stay where B has them. The mean change is additive (blood added to or drained from the dermis, in volume
//! fraction); the neutral weight reproduces Hn^B as [`super::hemoglobin_rig`] reproduces Hn^A. All maps are kept
//! at the rig's storage resolution, as the rig itself is (thesis §7.6).

use super::hemoglobin_rig::{build_rig, HemoglobinRig, RigMap};
use crate::error::InvalidInput;

/// A's rig with its relative changes carried onto `other_neutral` (B's neutral map, the rig's full size, finite);
/// `param` names the flag in errors. The targets keep their names and order.
pub fn transfer_rig(rig: &HemoglobinRig, other_neutral: &[f32], param: &str) -> Result<HemoglobinRig, InvalidInput> {
    let n = rig.width as usize * rig.height as usize;
    if other_neutral.len() != n {
        return Err(InvalidInput::new(
            param,
            format!(
                "has {} texels; the rig was built from {}x{} maps, so the other character's neutral map must be {}x{}",
                other_neutral.len(),
                rig.width,
                rig.height,
                rig.width,
                rig.height
            ),
        ));
    }
    if let Some(i) = other_neutral.iter().position(|v| !v.is_finite()) {
        return Err(InvalidInput::new(param, format!("texel {i} is not finite")));
    }
    // B's own neutral statistics (bias_0^B, H0^B) with the rig's radius, border and storage size.
    let base = build_rig(other_neutral, rig.width, rig.height, &[], &rig.settings)?;
    let (a0, b0) = (&rig.maps[0].bias, &base.maps[0].bias);
    let mut maps = vec![base.maps[0].clone()];
    for m in &rig.maps[1..] {
        let bias = m.bias.iter().zip(a0).zip(b0).map(|((&mi, &mn_a), &mn_b)| mn_b + (mi - mn_a)).collect();
        maps.push(RigMap { name: m.name.clone(), scale: m.scale.clone(), bias });
    }
    Ok(HemoglobinRig { maps, ..base })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facial::disk_stats::disk_stats;
    use crate::facial::hemoglobin_rig::{evaluate, RigSettings};
    use crate::facial::synthetic::{expression, hemoglobin_map};

    const SIZE: u32 = 128;

    fn map(seed: u32, expr: Option<&str>) -> Vec<f32> {
        hemoglobin_map(SIZE, seed, expr.map(|e| expression(e).unwrap())).into_iter().map(|v| v as f32).collect()
    }

    fn median(mut v: Vec<f64>) -> f64 {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }

    /// Subject A (seed 1) smiles; the rig is transferred to character B (seed 7, other vessels, other levels).
    /// B's neutral weight gives B's map back; B's "joy" has, away from the border, the local statistics of eq.
    /// 7.3: mean = B's mean + A's shift, spread = B's spread × A's ratio — and differs from A's own joy map.
    #[test]
    fn the_transferred_rig_keeps_the_other_characters_detail_with_the_subjects_changes() {
        let settings = RigSettings { radius_texels: 8, rig_size: SIZE, ..RigSettings::default() };
        let (na, joy_a, nb) = (map(1, None), map(1, Some("joy")), map(7, None));
        let rig_a = build_rig(&na, SIZE, SIZE, &[("joy".into(), &joy_a)], &settings).unwrap();
        let rig_b = transfer_rig(&rig_a, &nb, "neutral").unwrap();
        assert_eq!(rig_b.maps.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(), vec!["neutral", "joy"]);
        let neutral_b = evaluate(&rig_b, &[1.0, 0.0], 1.0);
        let worst = neutral_b.iter().zip(&nb).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-6, "neutral weight reproduces B: {worst}");

        let joy_b = evaluate(&rig_b, &[0.0, 1.0], 1.0);
        let joy_a_rig = evaluate(&rig_a, &[0.0, 1.0], 1.0);
        let r = settings.radius_texels;
        let stats = |m: &[f32]| disk_stats(m, SIZE, SIZE, r, settings.border).unwrap();
        let (sa_n, sa_j, sb_n) = (stats(&na), stats(&joy_a), stats(&nb));
        // The local statistics eq. 7.3 asks of a rig's output, for A's rig on A and the transferred rig on B,
        // and how far each output is from them (median over the interior, mean error relative to the local
        // spread).
        let error = |out: &[f32], base: &crate::facial::disk_stats::LocalStats| -> (f64, f64) {
            let so = stats(out);
            let (mut me, mut se) = (Vec::new(), Vec::new());
            let w = SIZE as usize;
            for y in 2 * r as usize..w - 2 * r as usize {
                for x in 2 * r as usize..w - 2 * r as usize {
                    let i = y * w + x;
                    let ratio = sa_j.sigma[i] / sa_n.sigma[i].max(settings.sigma_floor);
                    let want_mean = base.mean[i] + (sa_j.mean[i] - sa_n.mean[i]);
                    let want_sigma = base.sigma[i] * ratio;
                    me.push((so.mean[i] - want_mean).abs() / want_sigma);
                    se.push((so.sigma[i] - want_sigma).abs() / want_sigma);
                }
            }
            (median(me), median(se))
        };
        let (own_mean, own_sigma) = error(&joy_a_rig, &sa_n);
        let (b_mean, b_sigma) = error(&joy_b, &sb_n);
        // The transfer keeps the statistics about as well as the rig keeps its own subject's (both to about 0.2 %
        // of the local spread here), and both well.
        assert!(b_mean < 0.01 && b_sigma < 0.01, "{b_mean} {b_sigma}");
        assert!(b_mean < 2.0 * own_mean + 0.01 && b_sigma < 2.0 * own_sigma + 0.01);
        // B's joy is not A's joy: B's own detail stays.
        let diff = joy_b.iter().zip(&joy_a).map(|(a, b)| (a - b).abs() as f64).sum::<f64>() / joy_b.len() as f64;
        assert!(diff > 5e-3, "{diff}");
    }

    #[test]
    fn a_neutral_map_of_the_wrong_size_or_with_nan_is_named() {
        let settings = RigSettings { radius_texels: 4, rig_size: 16, ..RigSettings::default() };
        let na = map(1, None);
        let rig = build_rig(&na, SIZE, SIZE, &[], &settings).unwrap();
        let e = transfer_rig(&rig, &na[..100], "neutral").unwrap_err();
        assert_eq!(e.param, "neutral");
        assert!(e.message.contains("must be 128x128"), "{e}");
        let mut bad = na.clone();
        bad[5] = f32::NAN;
        assert!(transfer_rig(&rig, &bad, "neutral").unwrap_err().message.contains("texel 5"));
    }
}
