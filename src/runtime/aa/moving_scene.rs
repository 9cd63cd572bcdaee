//! A procedural moving scene with sub-pixel detail for the SMAA S2x/T2x/4x modes (thesis ch. 10, §10.4.3–10.4.4):
//! thin rotating lines (0.35, 0.6 and 1.0 px wide), a rotating square (long edges at every angle), and a fast disc
//! moving over a textured background (ghosting), all evaluable at any sample position and any (fractional) time.
//! Pure CPU maths, so the aliased frames, the jittered samples of every mode and the 16× supersampled truth are the
//! same function.
//!
//! Conventions: positions in pixels, y down, pixel (i, j) covers `[i, i+1) × [j, j+1)` (centre at `(i+0.5, j+0.5)`);
//! time `t` in frames. Velocity is the screen-space displacement of the surface point seen at `p` between frames
//! `t − 1` and `t`, in pixels per frame (`v = p(t) − p(t−1)`, the motion-blur convention of the SMAA shader, which
//! reprojects to `p − v`). For a rigid object with centre `c(t)` and angle `θ(t)`: `q = R(−θ(t))·(p − c(t))`,
//! `p(t−1) = c(t−1) + R(θ(t−1))·q`. Colours are linear RGB; frames are RGBA8 sRGB-encoded with alpha 255.

use crate::error::InvalidInput;
use crate::runtime::sampler::{linear_to_srgb, unorm8};
use rayon::prelude::*;

/// How the scene moves (per frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneMotion {
    /// Angular speed of the square and of the thin lines, radians per frame.
    pub rotation_rad_per_frame: f64,
    /// Horizontal speed of the fast disc, pixels per frame (0: it stands still).
    pub fast_px_per_frame: f64,
    /// Horizontal drift of the square and the lines, pixels per frame (sub-pixel motion of a static camera).
    pub drift_px_per_frame: f64,
}

impl SceneMotion {
    /// The default sequence: rotation 0.02 rad/frame, a disc at 6.5 px/frame, no drift.
    pub const DEFAULT: Self = Self { rotation_rad_per_frame: 0.02, fast_px_per_frame: 6.5, drift_px_per_frame: 0.0 };
    /// Static camera with sub-pixel motion only: 0.002 rad/frame (≤ 0.1 px/frame at the edges), drift 0.1 px/frame,
    /// the disc at rest.
    pub const SUBPIXEL: Self = Self { rotation_rad_per_frame: 0.002, fast_px_per_frame: 0.0, drift_px_per_frame: 0.1 };

    pub fn validate(&self) -> Result<(), InvalidInput> {
        for (name, v, max) in [
            ("rotation_rad_per_frame", self.rotation_rad_per_frame, 1.0),
            ("fast_px_per_frame", self.fast_px_per_frame, 64.0),
            ("drift_px_per_frame", self.drift_px_per_frame, 64.0),
        ] {
            if !(v.is_finite() && v.abs() <= max) {
                return Err(InvalidInput::new(name, format!("must be finite and within ±{max}, got {v}")));
            }
        }
        Ok(())
    }
}

impl Default for SceneMotion {
    fn default() -> Self {
        Self::DEFAULT
    }
}

#[derive(Clone, Copy)]
enum Kind {
    /// Half extents (x, y) of a rectangle in its local frame.
    Rect(f64, f64),
    /// Radius.
    Disc(f64),
}

#[derive(Clone, Copy)]
struct Object {
    kind: Kind,
    colour: [f64; 3],
    centre0: [f64; 2],
    /// Centre velocity, px/frame.
    centre_v: [f64; 2],
    angle0: f64,
    /// rad/frame.
    omega: f64,
}

impl Object {
    fn pose(&self, t: f64) -> ([f64; 2], f64) {
        ([self.centre0[0] + self.centre_v[0] * t, self.centre0[1] + self.centre_v[1] * t], self.angle0 + self.omega * t)
    }

    /// Local coordinates of `p` at time `t` if the object covers it.
    fn local(&self, p: [f64; 2], t: f64) -> Option<[f64; 2]> {
        let (c, a) = self.pose(t);
        let (s, co) = a.sin_cos();
        let d = [p[0] - c[0], p[1] - c[1]];
        let q = [co * d[0] + s * d[1], -s * d[0] + co * d[1]];
        let inside = match self.kind {
            Kind::Rect(hx, hy) => q[0].abs() <= hx && q[1].abs() <= hy,
            Kind::Disc(r) => q[0] * q[0] + q[1] * q[1] <= r * r,
        };
        inside.then_some(q)
    }

    /// Velocity (px/frame) of the surface point `q` (local) seen at `p` at time `t`.
    fn velocity(&self, p: [f64; 2], q: [f64; 2], t: f64) -> [f64; 2] {
        let (c, a) = self.pose(t - 1.0);
        let (s, co) = a.sin_cos();
        let prev = [c[0] + co * q[0] - s * q[1], c[1] + s * q[0] + co * q[1]];
        [p[0] - prev[0], p[1] - prev[1]]
    }
}

/// The moving scene for one frame size.
#[derive(Clone)]
pub struct MovingScene {
    width: u32,
    height: u32,
    motion: SceneMotion,
    /// Back to front.
    objects: Vec<Object>,
    /// Checker cell of the background texture, px.
    cell_px: f64,
}

impl MovingScene {
    pub fn new(width: u32, height: u32, motion: SceneMotion) -> Result<Self, InvalidInput> {
        crate::error::check_size("width/height", width as u64, height as u64)?;
        motion.validate()?;
        let (fw, fh) = (width as f64, height as f64);
        let s = fw.min(fh);
        let drift = [motion.drift_px_per_frame, 0.0];
        let w = motion.rotation_rad_per_frame;
        let mut objects = vec![Object {
            kind: Kind::Rect(0.17 * s, 0.17 * s),
            colour: [0.85, 0.25, 0.10],
            centre0: [0.32 * fw, 0.36 * fh],
            centre_v: drift,
            angle0: 0.31,
            omega: w,
        }];
        for (i, width_px) in [0.35, 0.6, 1.0].into_iter().enumerate() {
            objects.push(Object {
                kind: Kind::Rect(0.2 * s, 0.5 * width_px),
                colour: [0.95, 0.95, 0.85],
                centre0: [0.70 * fw, 0.34 * fh],
                centre_v: drift,
                angle0: 0.12 + 1.05 * i as f64,
                omega: 0.5 * w,
            });
        }
        objects.push(Object {
            kind: Kind::Disc(0.09 * s),
            colour: [0.10, 0.55, 0.95],
            centre0: [0.15 * fw, 0.76 * fh],
            centre_v: [motion.fast_px_per_frame, 0.0],
            angle0: 0.0,
            omega: 0.0,
        });
        Ok(Self { width, height, motion, objects, cell_px: (s / 40.0).max(3.0) })
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    pub fn motion(&self) -> SceneMotion {
        self.motion
    }

    /// Linear RGB of the static textured background (a checker of two greys modulated by a smooth ramp).
    fn background(&self, p: [f64; 2]) -> [f64; 3] {
        let cx = (p[0] / self.cell_px).floor() as i64;
        let cy = (p[1] / self.cell_px).floor() as i64;
        let k = if (cx + cy).rem_euclid(2) == 0 { 0.35 } else { 0.12 };
        let ramp = 0.7 + 0.3 * (p[0] / self.width as f64);
        [k * ramp, k * 0.9, k * (1.3 - 0.3 * ramp)]
    }

    /// Linear colour and velocity (px/frame) of the surface seen at `p` (pixels, y down) at time `t` (frames).
    pub fn sample(&self, p: [f64; 2], t: f64) -> ([f64; 3], [f64; 2]) {
        for o in self.objects.iter().rev() {
            if let Some(q) = o.local(p, t) {
                return (o.colour, o.velocity(p, q, t));
            }
        }
        (self.background(p), [0.0, 0.0])
    }

    /// One sample per pixel at `centre + offset_px` (y down): RGBA8 sRGB-encoded, alpha 255, top row first.
    pub fn render(&self, t: f64, offset_px: [f64; 2]) -> Vec<u8> {
        self.render_grid(t, 1, offset_px)
    }

    /// The `n × n`-sample supersampled frame at time `t` (regular grid, averaged in linear light); n = 4 is the
    /// 16× ground truth of the quality measurements.
    pub fn truth(&self, t: f64, n: u32) -> Vec<u8> {
        self.render_grid(t, n.max(1), [0.0, 0.0])
    }

    fn render_grid(&self, t: f64, n: u32, offset_px: [f64; 2]) -> Vec<u8> {
        let w = self.width as usize;
        let mut out = vec![0u8; w * self.height as usize * 4];
        out.par_chunks_mut(w * 4).enumerate().for_each(|(y, row)| {
            for x in 0..w {
                let mut acc = [0.0f64; 3];
                for j in 0..n {
                    for i in 0..n {
                        let sx = x as f64 + (i as f64 + 0.5) / n as f64 + offset_px[0];
                        let sy = y as f64 + (j as f64 + 0.5) / n as f64 + offset_px[1];
                        let c = self.sample([sx, sy], t).0;
                        (0..3).for_each(|k| acc[k] += c[k]);
                    }
                }
                let inv = 1.0 / (n * n) as f64;
                for k in 0..3 {
                    row[x * 4 + k] = unorm8(linear_to_srgb((acc[k] * inv) as f32));
                }
                row[x * 4 + 3] = 255;
            }
        });
        out
    }

    /// The velocity buffer of frame `t` at the pixel centres: RG f32, pixels per frame, top row first.
    pub fn velocity(&self, t: f64) -> Vec<f32> {
        let w = self.width as usize;
        let mut out = vec![0.0f32; w * self.height as usize * 2];
        out.par_chunks_mut(w * 2).enumerate().for_each(|(y, row)| {
            for x in 0..w {
                let v = self.sample([x as f64 + 0.5, y as f64 + 0.5], t).1;
                row[2 * x] = v[0] as f32;
                row[2 * x + 1] = v[1] as f32;
            }
        });
        out
    }

    /// Pixels whose centre the fast disc covered at frame `t − 1` but covers no longer at `t` (where a resolve that
    /// ignores motion leaves its ghost).
    pub fn disoccluded_mask(&self, t: f64) -> Vec<bool> {
        let disc = self.objects.last().expect("the disc");
        let (w, h) = (self.width as usize, self.height as usize);
        (0..w * h)
            .map(|i| {
                let p = [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
                disc.local(p, t - 1.0).is_some() && disc.local(p, t).is_none()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_points_back_to_the_previous_position_of_the_same_surface_point() {
        let scene = MovingScene::new(200, 120, SceneMotion::DEFAULT).unwrap();
        let t = 3.0;
        let mut checked = 0;
        for o in &scene.objects {
            let (c, _) = o.pose(t);
            let p = [c[0] + 0.1, c[1] - 0.05];
            let q = o.local(p, t).unwrap();
            let v = o.velocity(p, q, t);
            // The same local point one frame earlier is at p − v.
            let back = o.local([p[0] - v[0], p[1] - v[1]], t - 1.0).unwrap();
            assert!((back[0] - q[0]).abs() < 1e-9 && (back[1] - q[1]).abs() < 1e-9);
            checked += 1;
        }
        assert_eq!(checked, 5);
        // The disc moves at exactly the configured speed; the background is static.
        let disc = scene.objects.last().unwrap();
        let (c, _) = disc.pose(t);
        assert_eq!(scene.sample(c, t).1, [6.5, 0.0]);
        assert_eq!(scene.sample([0.5, 119.5], t).1, [0.0, 0.0]);
    }

    #[test]
    fn truth_averages_the_aliased_samples_it_is_made_of() {
        // A 1×1-sample truth is the aliased frame; a 16× truth differs from it only at edges, and thin lines are
        // visible in the truth as partial coverage.
        let scene = MovingScene::new(160, 96, SceneMotion::DEFAULT).unwrap();
        assert_eq!(scene.truth(2.0, 1), scene.render(2.0, [0.0, 0.0]));
        let truth = scene.truth(2.0, 4);
        let aliased = scene.render(2.0, [0.0, 0.0]);
        let differ = truth.chunks(4).zip(aliased.chunks(4)).filter(|(a, b)| a != b).count();
        assert!(differ > 100 && differ < 160 * 96 / 3, "{differ} pixels differ");
    }

    #[test]
    fn bad_motion_is_refused_naming_the_field() {
        let m = SceneMotion { fast_px_per_frame: f64::NAN, ..SceneMotion::DEFAULT };
        assert_eq!(MovingScene::new(8, 8, m).err().unwrap().param, "fast_px_per_frame");
    }
}
