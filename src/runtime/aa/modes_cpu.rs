//! CPU reference of SMAA S2x / T2x / 4x — the twin of [`crate::runtime::aa::modes`] and
//! `aa/modes.wgsl` (thesis ch. 10, eq. 10.6–10.7; see those for the algorithm and the sample tables):
//! SMAA 1x per sample through [`crate::runtime::aa::smaa_cpu::smaa_with_subsample`], the S2x mean in linear light, and the temporal
//! resolve with nearest-texel reprojection to `p − v` and the velocity weight of eq. 10.6.

use crate::error::InvalidInput;
use crate::runtime::aa::modes::{with_velocity_alpha, ModeFrame, SmaaMode, TemporalResolve};
use crate::runtime::aa::smaa::SmaaTextures;
use crate::runtime::sampler::{linear_to_srgb, srgb_to_linear, unorm8, FilterPrecision, Tex8};
use rayon::prelude::*;

/// `srgb_to_linear(v / 255)` for every byte: the same f32 values as decoding each fetch, computed once.
fn decode_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

/// The shader's `lin(textureLoad(…))`: clamp-to-edge load, RGB decoded to linear, alpha as stored.
fn lin(t: &Tex8, x: i32, y: i32) -> [f32; 4] {
    let x = x.clamp(0, t.w as i32 - 1) as usize;
    let y = y.clamp(0, t.h as i32 - 1) as usize;
    let i = (y * t.w as usize + x) * 4;
    let d = decode_table();
    let p = &t.data[i..i + 4];
    [d[p[0] as usize], d[p[1] as usize], d[p[2] as usize], p[3] as f32 / 255.0]
}

/// The shader's `blend`: linear-light lerp of two sRGB-encoded colours (alpha linear), re-encoded.
fn blend(cur: [f32; 4], prev: [f32; 4], w: f32, out: &mut [u8]) {
    for k in 0..4 {
        let c = cur[k] + (prev[k] - cur[k]) * w;
        out[k] = unorm8(if k < 3 { linear_to_srgb(c) } else { c });
    }
}

/// `fs_average`: the S2x resolve of two per-sample SMAA outputs (RGBA8, sRGB-encoded).
pub fn average(a: &[u8], b: &[u8], w: u32, h: u32) -> Vec<u8> {
    let (ta, tb) = (Tex8::new(w, h, 4, a), Tex8::new(w, h, 4, b));
    let mut out = vec![0u8; a.len()];
    out.par_chunks_mut(w as usize * 4).enumerate().for_each(|(y, row)| {
        for x in 0..w as usize {
            let (xi, yi) = (x as i32, y as i32);
            blend(lin(&ta, xi, yi), lin(&tb, xi, yi), 0.5, &mut row[4 * x..4 * x + 4]);
        }
    });
    out
}

/// `fs_resolve`: eq. 10.6–10.7 (or the plain 50/50 blend) of the current and the previous SMAA'd frames;
/// `previous = None` passes the current frame through (first frame).
pub fn temporal_resolve(
    current: &[u8],
    previous: Option<&[u8]>,
    velocity_px: &[f32],
    (w, h): (u32, u32),
    resolve: TemporalResolve,
) -> Vec<u8> {
    let Some(previous) = previous else {
        return current.to_vec();
    };
    let (k, plain) = resolve.uniform();
    let (tc, tp) = (Tex8::new(w, h, 4, current), Tex8::new(w, h, 4, previous));
    let mut out = vec![0u8; current.len()];
    out.par_chunks_mut(w as usize * 4).enumerate().for_each(|(y, row)| {
        for x in 0..w as usize {
            let (xi, yi) = (x as i32, y as i32);
            let cur = lin(&tc, xi, yi);
            let o = &mut row[4 * x..4 * x + 4];
            if plain > 0.5 {
                blend(cur, lin(&tp, xi, yi), 0.5, o);
                continue;
            }
            let i = 2 * (y * w as usize + x);
            let (vx, vy) = (velocity_px[i], velocity_px[i + 1]);
            // floor(pos − v) with pos the pixel centre, in f32 as on the GPU; Tex8 clamps to the edge.
            let qx = (x as f32 + 0.5 - vx).floor() as i32;
            let qy = (y as f32 + 0.5 - vy).floor() as i32;
            let prev = lin(&tp, qx, qy);
            let delta = (cur[3] * cur[3] - prev[3] * prev[3]).abs() / 5.0;
            let wgt = 0.5 * (1.0 - k * delta.sqrt()).clamp(0.0, 1.0);
            blend(cur, prev, wgt, o);
        }
    });
    out
}

/// One SMAA mode with its history, on the CPU.
pub struct SmaaModesCpu {
    mode: SmaaMode,
    resolve: TemporalResolve,
    width: u32,
    height: u32,
    luts: SmaaTextures,
    prec: FilterPrecision,
    frame: u64,
    history: Option<Vec<u8>>,
}

impl SmaaModesCpu {
    pub fn new(
        width: u32,
        height: u32,
        luts: &SmaaTextures,
        prec: FilterPrecision,
        mode: SmaaMode,
        resolve: TemporalResolve,
    ) -> Result<Self, InvalidInput> {
        crate::error::check_size("image", width as u64, height as u64)?;
        resolve.validate()?;
        Ok(Self { mode, resolve, width, height, luts: luts.clone(), prec, frame: 0, history: None })
    }

    /// Runs one frame (the twin of `SmaaModes::run_frame`) and advances.
    pub fn run_frame(&mut self, frame: &ModeFrame<'_>) -> Result<Vec<u8>, InvalidInput> {
        let (w, h) = (self.width, self.height);
        frame.check(self.mode, w, h)?;
        let outs: Vec<Vec<u8>> = self
            .mode
            .samples(self.frame)
            .iter()
            .zip(frame.samples)
            .map(|(s, rgba)| {
                let input = with_velocity_alpha(rgba, frame.velocity_px, w, h);
                crate::runtime::aa::smaa_cpu::smaa_with_subsample(&input, w, h, &self.luts, self.prec, s.subsample)
                    .output
            })
            .collect();
        let result = match outs.as_slice() {
            [one] => one.clone(),
            [a, b] => average(a, b, w, h),
            _ => unreachable!("one or two samples per frame"),
        };
        let out = if self.mode.is_temporal() {
            let out = temporal_resolve(&result, self.history.as_deref(), frame.velocity_px, (w, h), self.resolve);
            self.history = Some(result);
            out
        } else {
            result
        };
        self.frame += 1;
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_table_equals_decoding_each_fetch() {
        for v in 0..=255u8 {
            let data = [v, v, v, v];
            let t = Tex8::new(1, 1, 4, &data);
            assert_eq!(lin(&t, 0, 0)[0], srgb_to_linear(t.load(0, 0, 0)));
            assert_eq!(lin(&t, 3, -2)[3], t.load(0, 0, 3));
        }
    }

    #[test]
    fn resolve_weights_follow_eq_10_6() {
        // 2×1 frames; current pixel alpha a_c, previous a_p: w = 0.5·max(0, 1 − K·sqrt(|a_c² − a_p²|/5)).
        let cur = [255u8, 255, 255, 0, 0, 0, 0, 0];
        let prev = [0u8, 0, 0, 0, 0, 0, 0, 0];
        let v = [0.0f32; 4];
        let r = |k: f32| temporal_resolve(&cur, Some(&prev), &v, (2, 1), TemporalResolve::Reprojected { k })[0];
        // Equal velocities: w = 0.5 → half of linear white, sRGB-encoded (188).
        assert_eq!(r(30.0), 188);
        assert_eq!(temporal_resolve(&cur, Some(&prev), &v, (2, 1), TemporalResolve::Plain)[0], 188);
        // Different velocity (current alpha 1, previous 0): sqrt(1/5)·30 > 1 → w = 0, the current pixel only.
        let cur_moving = [255u8, 255, 255, 255, 0, 0, 0, 0];
        let out = temporal_resolve(&cur_moving, Some(&prev), &v, (2, 1), TemporalResolve::default());
        assert_eq!(out[..4], [255, 255, 255, 255]);
        // …but K = 0 (reprojection without weighting) blends half.
        let out = temporal_resolve(&cur_moving, Some(&prev), &v, (2, 1), TemporalResolve::Reprojected { k: 0.0 });
        assert_eq!(out[0], 188);
        // No history: pass-through.
        assert_eq!(temporal_resolve(&cur, None, &v, (2, 1), TemporalResolve::default()), cur);
    }

    #[test]
    fn reprojection_fetches_the_previous_frame_at_p_minus_v() {
        // Previous frame: a white pixel at x = 1; current velocity (+1, 0) everywhere, so pixel 2 fetches x = 1.
        let (w, h) = (4u32, 1u32);
        let mut prev = vec![0u8; 16];
        prev[4..8].copy_from_slice(&[255, 255, 255, 0]);
        let cur = vec![0u8; 16];
        let v = vec![1.0f32, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0];
        let out = temporal_resolve(&cur, Some(&prev), &v, (w, h), TemporalResolve::default());
        let reds: Vec<u8> = out.chunks(4).map(|p| p[0]).collect();
        assert_eq!(reds, [0, 0, 188, 0]);
    }
}
