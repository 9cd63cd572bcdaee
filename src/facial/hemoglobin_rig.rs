//! Hemoglobin appearance rig: approximate local histogram matching with Gaussian local statistics (thesis §7.4;
//! Jimenez et al., "A practical appearance model for dynamic facial color", ACM TOG 29(6), SIGGRAPH Asia 2010).
//!
//! With disk statistics μ, σ of radius r (eq. 7.1, [`super::disk_stats`]):
//!
//! ```text
//! H0 = Hn − μn                                   (eq. 7.4, mean-free base, full resolution)
//! bias_0 = μn, scale_0 = 1; bias_i = μi, scale_i = σi / σn     (eq. 7.5)
//! H = Σ wᵢ·bias_i + H0 · Σ wᵢ·scale_i, Σ wᵢ = 1   (eq. 7.6)
//! ```
//!
//! Storage (thesis §7.6): scale_i and bias_i are low-frequency and are stored at `rig_width × rig_height`
//! (default 256×256) after area-weighted downsampling ([`super::resample::resample_area`]); a renderer reads them
//! back with bilinear filtering. So that `w_neutral = 1` reproduces Hn (the spec requires it), H0 is taken against
//! the **stored** neutral bias as the renderer reconstructs it: `H0 = Hn − bilinear(bias_0 stored as f32)`. The
//! CPU evaluator [`evaluate`] reads every map the same way (texel centres, clamp to edge), so
//! `evaluate(w_neutral = 1) = bias_0 + (Hn − bias_0) = Hn` up to the f32 rounding of H0.
//!
//! σn can be 0 (flat regions): `scale_i = σi / max(σn, ε)` with a floor ε (`sigma_floor`, concentration units);
//! the number of full-resolution texels with σn < ε is reported.
//!
//! Global states (thesis §7.7): extreme anger / fear scale the whole hemoglobin map (×1.27 / ×0.81); the
//! evaluator takes that factor as `global_scale`.

use super::disk_stats::{self, Border};
use super::resample;
use crate::error::InvalidInput;
use rayon::prelude::*;

/// Name of the neutral basis map (index 0) in weights and in the rig description.
pub const NEUTRAL: &str = "neutral";

/// Global hemoglobin scale factors reported in the thesis (§7.7, Fig. 7.1): anger ×1.27, fear ×0.81.
pub const THESIS_GLOBAL_SCALES: [(&str, f64); 2] = [("anger", 1.27), ("fear", 0.81)];

/// Settings of a rig bake.
#[derive(Clone, Debug, PartialEq)]
pub struct RigSettings {
    /// Disk radius r in texels of the full-resolution maps (eq. 7.1).
    pub radius_texels: u32,
    pub border: Border,
    /// Floor ε of σn in `scale_i = σi / max(σn, ε)` (concentration units).
    pub sigma_floor: f64,
    /// Requested storage size of scale/bias maps (thesis: 256); clamped per axis to the input size.
    pub rig_size: u32,
}

impl Default for RigSettings {
    fn default() -> Self {
        Self { radius_texels: 32, border: Border::Clip, sigma_floor: 1e-4, rig_size: 256 }
    }
}

/// One basis map of the rig at storage resolution (index 0 is the neutral map with scale = 1).
#[derive(Clone, Debug, PartialEq)]
pub struct RigMap {
    pub name: String,
    pub scale: Vec<f32>,
    pub bias: Vec<f32>,
}

/// A baked rig.
#[derive(Clone, Debug, PartialEq)]
pub struct HemoglobinRig {
    pub width: u32,
    pub height: u32,
    pub rig_width: u32,
    pub rig_height: u32,
    pub settings: RigSettings,
    /// Mean-free base H0 at full resolution (eq. 7.4, against the stored neutral bias).
    pub h0: Vec<f32>,
    /// `maps[0]` is the neutral map, then the targets in input order.
    pub maps: Vec<RigMap>,
    /// Full-resolution texels where σn < ε.
    pub sigma_floored_texels: u64,
}

/// Checks a target name: `[a-z0-9_-]`, 1..=64 characters, not `neutral`.
pub fn check_target_name(param: &str, name: &str) -> Result<(), InvalidInput> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-');
    if !ok {
        return Err(InvalidInput::new(
            param,
            format!("target name must be 1..=64 characters of [a-z0-9_-], got '{name}'"),
        ));
    }
    if name == NEUTRAL {
        return Err(InvalidInput::new(param, "target name 'neutral' is reserved for the neutral map (`neutral`)"));
    }
    Ok(())
}

/// Storage size for a `width × height` input and a requested `rig_size` (clamped per axis).
pub fn rig_dims(width: u32, height: u32, rig_size: u32) -> (u32, u32) {
    (rig_size.min(width), rig_size.min(height))
}

/// Validates the settings against the map size.
pub fn check_settings(settings: &RigSettings, width: u32, height: u32) -> Result<(), InvalidInput> {
    disk_stats::check_radius("radius_texels", settings.radius_texels, width, height)?;
    if !(settings.sigma_floor.is_finite() && settings.sigma_floor > 0.0) {
        return Err(InvalidInput::new(
            "sigma_floor",
            format!("must be a finite number > 0 (concentration units), got {}", settings.sigma_floor),
        ));
    }
    crate::error::check_range("rig_size", settings.rig_size, 1, crate::error::MAX_TEXTURE_EDGE, "texels")?;
    Ok(())
}

/// Builds the rig from the neutral map and named targets (single-channel, same size, finite).
pub fn build_rig(
    neutral: &[f32],
    width: u32,
    height: u32,
    targets: &[(String, &[f32])],
    settings: &RigSettings,
) -> Result<HemoglobinRig, InvalidInput> {
    build_rig_with_progress(neutral, width, height, targets, settings, &|_| {})
}

/// [`build_rig`] calling `progress(k)` after the k-th of `1 + targets.len()` maps has been analysed.
pub fn build_rig_with_progress(
    neutral: &[f32],
    width: u32,
    height: u32,
    targets: &[(String, &[f32])],
    settings: &RigSettings,
    progress: &dyn Fn(usize),
) -> Result<HemoglobinRig, InvalidInput> {
    check_settings(settings, width, height)?;
    let n = width as usize * height as usize;
    if neutral.len() != n {
        return Err(InvalidInput::new("neutral", format!("expected {n} texels, got {}", neutral.len())));
    }
    for (i, (name, t)) in targets.iter().enumerate() {
        check_target_name("target", name)?;
        if targets[..i].iter().any(|(o, _)| o == name) {
            return Err(InvalidInput::new("target", format!("target '{name}' is given twice")));
        }
        if t.len() != n {
            return Err(InvalidInput::new(format!("target {name}"), format!("expected {n} texels, got {}", t.len())));
        }
    }
    let (rw, rh) = rig_dims(width, height, settings.rig_size);
    let r = settings.radius_texels;
    let eps = settings.sigma_floor;

    // One fused pass per map (eq. 7.1 band by band): each band's μ and σ rows go straight into the horizontal
    // half of the area downsampling, so no full-size μ, σ or scale map is stored except the floored σn that every
    // target divides by; the buffers are allocated once for all maps. The values are those of `disk_stats` +
    // `resample_area`, bit for bit.
    let (w, h) = (width as usize, height as usize);
    let res = resample::AreaResampler::new(width, height, rw, rh);
    let down = |tmp: &[f64]| -> Vec<f32> { res.vertical(tmp).into_iter().map(|x| x as f32).collect() };
    let (band_full, band_rw) = (disk_stats::BAND_ROWS * w, disk_stats::BAND_ROWS * rw as usize);
    let mut tmp_mean = vec![0.0f64; h * rw as usize];
    let mut tmp_scale = vec![0.0f64; h * rw as usize];
    let mut sigma_n_floored = vec![0.0f64; n];
    let floored = std::sync::atomic::AtomicU64::new(0);
    let outputs = sigma_n_floored.par_chunks_mut(band_full).zip(tmp_mean.par_chunks_mut(band_rw));
    disk_stats::disk_stats_bands(neutral, width, height, r, settings.border, outputs, |(sn, tm), _, mean, sigma| {
        for (row, out) in mean.chunks_exact(w).zip(tm.chunks_exact_mut(rw as usize)) {
            res.horizontal_row(row, out); // eq. 7.5, i = 0: bias_0 = μn
        }
        let mut count = 0u64;
        for (o, &s) in sn.iter_mut().zip(sigma) {
            count += (s < eps) as u64;
            *o = s.max(eps);
        }
        floored.fetch_add(count, std::sync::atomic::Ordering::Relaxed);
    })?;
    let sigma_floored_texels = floored.into_inner();
    let mut maps = vec![RigMap { name: NEUTRAL.into(), scale: vec![1.0; (rw * rh) as usize], bias: down(&tmp_mean) }];
    progress(1);

    for (name, t) in targets {
        let outputs = tmp_mean
            .par_chunks_mut(band_rw)
            .zip(tmp_scale.par_chunks_mut(band_rw))
            .zip(sigma_n_floored.par_chunks(band_full));
        disk_stats::disk_stats_bands(
            t,
            width,
            height,
            r,
            settings.border,
            outputs,
            |((tm, ts), sn), _, mean, sigma| {
                let mut scale_row = vec![0.0f64; w];
                let rows = mean.chunks_exact(w).zip(sigma.chunks_exact(w)).zip(sn.chunks_exact(w));
                for (((m_row, s_row), sn_row), (tm_row, ts_row)) in
                    rows.zip(tm.chunks_exact_mut(rw as usize).zip(ts.chunks_exact_mut(rw as usize)))
                {
                    res.horizontal_row(m_row, tm_row); // eq. 7.5: bias_i = μi
                    for ((o, &si), &sn) in scale_row.iter_mut().zip(s_row).zip(sn_row) {
                        *o = si / sn; // eq. 7.5: scale_i = σi / max(σn, ε)
                    }
                    res.horizontal_row(&scale_row, ts_row);
                }
            },
        )?;
        maps.push(RigMap { name: name.clone(), scale: down(&tmp_scale), bias: down(&tmp_mean) });
        progress(maps.len());
    }
    drop(sigma_n_floored);

    // eq. 7.4 against the stored neutral bias (see module docs), read bilinearly as `upsample_bilinear` does.
    let (ax, ay) = (resample::bilinear_axis(w, rw as usize), resample::bilinear_axis(h, rh as usize));
    let mut h0 = vec![0.0f32; n];
    h0.par_chunks_mut(w).zip(neutral.par_chunks(w)).enumerate().for_each(|(y, (out, hn))| {
        for (x, (o, &hn)) in out.iter_mut().zip(hn).enumerate() {
            *o = (hn as f64 - resample::bilinear_at(&maps[0].bias, rw as usize, ax[x], ay[y])) as f32;
        }
    });
    Ok(HemoglobinRig {
        width,
        height,
        rig_width: rw,
        rig_height: rh,
        settings: settings.clone(),
        h0,
        maps,
        sigma_floored_texels,
    })
}

/// Turns `name=weight` pairs into one weight per rig map (in rig order; unnamed maps get 0). Weights must be
/// finite and sum to 1 within 1e-6, unless `normalize` (then they are divided by their sum, which must not be 0).
/// The largest magnitude of one target's blend weight in eq. 7.6. The weights sum to 1; a pose may extrapolate
/// beyond a target (a weight above 1 or below 0), but beyond ±1000 the blended maps lose every digit of the
/// neutral map, and ±1e308 overflows (to a NaN pose) when the runtime sums them in f32.
pub const MAX_TARGET_WEIGHT: f64 = 1000.0;

/// One target weight of a pose (`param` names the flag or field): finite and within ±[`MAX_TARGET_WEIGHT`].
pub fn check_target_weight(param: &str, target: &str, w: f64) -> Result<f64, InvalidInput> {
    if !(w.is_finite() && w.abs() <= MAX_TARGET_WEIGHT) {
        return Err(InvalidInput::new(
            param,
            format!(
                "weight of '{target}' must be in -{MAX_TARGET_WEIGHT}..={MAX_TARGET_WEIGHT} (the weights sum to 1, \
                 eq. 7.6), got {w:e}"
            ),
        ));
    }
    Ok(w)
}

/// Checks the target weights of a pose object `{"target": weight, …, "global": {…}}` (`--rig-weights`) before a
/// renderer sums them: every number outside `"global"` through [`check_target_weight`].
pub fn check_pose_json(param: &str, json: &serde_json::Value) -> Result<(), InvalidInput> {
    if let Some(obj) = json.as_object() {
        for (key, v) in obj.iter().filter(|(k, _)| k.as_str() != "global") {
            if let Some(w) = v.as_f64() {
                check_target_weight(param, key, w)?;
            }
        }
    }
    Ok(())
}

pub fn rig_weights(map_names: &[String], pairs: &[(String, f64)], normalize: bool) -> Result<Vec<f64>, InvalidInput> {
    let mut w = vec![0.0f64; map_names.len()];
    let mut seen = vec![false; map_names.len()];
    for (name, v) in pairs {
        let Some(i) = map_names.iter().position(|m| m == name) else {
            return Err(InvalidInput::new(
                "weights",
                format!("unknown target '{name}'; the rig has: {}", map_names.join(", ")),
            ));
        };
        if seen[i] {
            return Err(InvalidInput::new("weights", format!("target '{name}' is given twice")));
        }
        check_target_weight("weights", name, *v)?;
        seen[i] = true;
        w[i] = *v;
    }
    let sum: f64 = w.iter().sum();
    if normalize {
        if sum.abs() < 1e-12 {
            return Err(InvalidInput::new("weights", "cannot normalise weights that sum to 0"));
        }
        w.iter_mut().for_each(|x| *x /= sum);
    } else if (sum - 1.0).abs() > 1e-6 {
        return Err(InvalidInput::new(
            "weights",
            format!("must sum to 1 (eq. 7.6), got {sum}; pass `normalize_weights` to divide by the sum"),
        ));
    }
    Ok(w)
}

/// Evaluates eq. 7.6 at full resolution: `H = g·(Σ wᵢ·bias_i + H0·Σ wᵢ·scale_i)` with stored maps read
/// bilinearly. `weights` has one entry per `rig.maps` (see [`rig_weights`]); `global_scale` g is 1 for none.
pub fn evaluate(rig: &HemoglobinRig, weights: &[f64], global_scale: f64) -> Vec<f32> {
    assert_eq!(weights.len(), rig.maps.len(), "one weight per rig map");
    let (w, h, rw, rh) = (rig.width as usize, rig.height as usize, rig.rig_width as usize, rig.rig_height as usize);
    // Blend the stored maps first (bilinear filtering is linear, so this equals blending the samples).
    let mut bias = vec![0.0f64; rw * rh];
    let mut scale = vec![0.0f64; rw * rh];
    for (m, &wi) in rig.maps.iter().zip(weights) {
        if wi == 0.0 {
            continue;
        }
        for k in 0..rw * rh {
            bias[k] += wi * m.bias[k] as f64;
            scale[k] += wi * m.scale[k] as f64;
        }
    }
    let ax = resample::bilinear_axis(w, rw);
    let ay = resample::bilinear_axis(h, rh);
    let lerp = |map: &[f64], cx: (usize, usize, f64), cy: (usize, usize, f64)| {
        let a = map[cy.0 * rw + cx.0];
        let b = map[cy.0 * rw + cx.1];
        let c = map[cy.1 * rw + cx.0];
        let d = map[cy.1 * rw + cx.1];
        let top = a + (b - a) * cx.2;
        let bot = c + (d - c) * cx.2;
        top + (bot - top) * cy.2
    };
    let single = weights.iter().filter(|&&x| x != 0.0).count() == 1;
    let mut out = vec![0.0f32; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let (b, s) = if single {
                // One map with weight wi: read the stored f32 maps directly (bit-identical to the H0 reference).
                let i = weights.iter().position(|&x| x != 0.0).unwrap();
                let m = &rig.maps[i];
                (
                    weights[i] * resample::bilinear_at(&m.bias, rw, ax[x], ay[y]),
                    weights[i] * resample::bilinear_at(&m.scale, rw, ax[x], ay[y]),
                )
            } else {
                (lerp(&bias, ax[x], ay[y]), lerp(&scale, ax[x], ay[y]))
            };
            let v = b + rig.h0[y * w + x] as f64 * s; // eq. 7.6
            *o = (global_scale * v) as f32;
        }
    });
    out
}
/// Wall time of [`build_rig`] on `maps` maps (neutral + targets) of `width`×`height` at disk radius `radius`
/// (the budget check): 1.5 ns per texel, map and chord row (2r + 1 rows per disk) on one thread, divided by
/// `threads`. Measured with the release build on the project's 2-core machine: 4096², 9 maps, r = 32: 6.4 s on 2
/// threads with the earlier, unfused build (1.3 ns), 3.3 s of CPU with the fused band-wise one (0.33 ns; `examples/bench_facial.rs`); the estimate
/// keeps the older, larger figure, so it only ever over-estimates.
pub fn time_estimate_seconds(width: u32, height: u32, maps: usize, radius: u32, threads: usize) -> f64 {
    1.5e-9 * width as f64 * height as f64 * maps as f64 * (2 * radius as u64 + 1) as f64 / threads.max(1) as f64
}

/// Wall time of [`evaluate`] at full resolution `width`×`height` with its EXR encoding (`maps rig-eval`; the
/// budget check): 0.25 µs per output texel + 0.5 s. Measured with the release build on the project's 2-core machine:
/// 4096², 5 maps, f32 output: 2.0 s (0.12 µs per texel); the estimate doubles it.
pub fn evaluate_time_estimate_seconds(width: u32, height: u32) -> f64 {
    0.5 + 0.25e-6 * width as f64 * height as f64
}

/// Peak memory of [`evaluate`] with its EXR encoding, in bytes: the f32 output, the encoder's copy and the encoded
/// bytes (16 bytes per texel measured at 4096²: 267 MB), rounded up to 24, plus the stored rig maps (scale and
/// bias, f32, of `rig_width`×`rig_height`, `maps` of them) and 32 MiB.
pub fn evaluate_memory_estimate_bytes(width: u32, height: u32, rig_width: u32, rig_height: u32, maps: usize) -> u64 {
    24 * width as u64 * height as u64 + 8 * maps as u64 * rig_width as u64 * rig_height as u64 + (32 << 20)
}

/// Peak memory of [`build_rig`] with its files, in bytes: the decoded maps (f32) and, counted from the buffers of
/// the unfused build (full-size mean and σ of the neutral and of one target, f64, the full-size scale and bias,
/// the encoded outputs), 72 bytes per texel, plus 32 MiB. The fused build keeps only the floored σn (f64)
/// and H0 (f32) at full size, so this over-estimates.
pub fn memory_estimate_bytes(width: u32, height: u32, maps: usize) -> u64 {
    let texels = width as u64 * height as u64;
    texels * (4 * maps as u64 + 72) + (32 << 20)
}
