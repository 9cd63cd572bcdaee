//! The scalar reference engine (tests only): MCML's photon loop one packet at a time, with the draws the module
//! docs of [`super::mc`] describe for it (ziggurat steps, [`super::ziggurat`]; the azimuth from a point uniform in
//! the unit disk, [`super::rng::PhotonRng::azimuth_cos_sin`]). The lane engine ([`super::lanes`]) is checked
//! against it statistically (`mc::tests`); its histories differ, its results agree within the standard errors.

use super::mc::{Channel, HenyeyGreenstein, Tally, ROULETTE_CHANCE, ROULETTE_THRESHOLD};
use super::rng::PhotonRng;
use super::ziggurat::ExponentialZiggurat;

impl HenyeyGreenstein {
    /// cos θ from a uniform ξ.
    #[inline]
    fn cos_theta(&self, xi: f64) -> f64 {
        if self.isotropic {
            return 2.0 * xi - 1.0;
        }
        let f = self.one_minus_g2 / (self.one_minus_g + self.two_g * xi);
        ((self.one_plus_g2 - f * f) * self.inv_two_g).clamp(-1.0, 1.0)
    }
}

/// Unpolarised Fresnel reflectance from index `n_i` into `n_t` at incidence cosine `cos_i` ∈ `[0, 1]`, and the cosine of
/// the refracted ray (MCML eq. 3.36–3.38 in the cosine form; 1 and 0 past the critical angle).
fn fresnel(n_i: f64, n_t: f64, cos_i: f64) -> (f64, f64) {
    if n_i == n_t {
        return (0.0, cos_i);
    }
    let sin_t2 = (n_i / n_t).powi(2) * (1.0 - cos_i * cos_i).max(0.0);
    if sin_t2 >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_i * cos_t - n_t * cos_i) / (n_i * cos_t + n_t * cos_i);
    (0.5 * (rs * rs + rp * rp), cos_t)
}

/// Rotates direction `u` by polar cos θ and the azimuth (cos φ, sin φ) (MCML eq. 3.30–3.31). sin θ/√(1 − uz²) is
/// taken as one square root of a quotient, and sin θ·√(1 − uz²) as that times 1 − uz² (the same expressions as
/// MCML's `Spin`, one square root fewer).
#[inline]
fn spin(u: [f64; 3], cos_t: f64, cos_p: f64, sin_p: f64) -> [f64; 3] {
    let sin2_t = (1.0 - cos_t * cos_t).max(0.0);
    let [ux, uy, uz] = u;
    if uz.abs() > 0.99999 {
        let sin_t = sin2_t.sqrt();
        [sin_t * cos_p, sin_t * sin_p, cos_t * uz.signum()]
    } else {
        let one_minus_uz2 = 1.0 - uz * uz;
        // sin θ / √(1 − uz²)
        let a = (sin2_t / one_minus_uz2).sqrt();
        [
            a * (ux * uz * cos_p - uy * sin_p) + ux * cos_t,
            a * (uy * uz * cos_p + ux * sin_p) + uy * cos_t,
            -a * one_minus_uz2 * cos_p + uz * cos_t,
        ]
    }
}

/// One photon packet in flight (the scalar reference engine).
struct Photon {
    x: f64,
    y: f64,
    z: f64,
    u: [f64; 3],
    w: f64,
    /// Optical depth left of the current step (0: draw a new one).
    s_left: f64,
    layer: usize,
    rng: PhotonRng,
}

impl Photon {
    /// Photon `k` of the channel at the origin, heading down with weight 1 − Rsp.
    fn launch(ch: &Channel<'_>, k: u64) -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            u: [0.0, 0.0, 1.0],
            w: ch.start_weight,
            s_left: 0.0,
            layer: 0,
            rng: PhotonRng::new(ch.seed, k, ch.index),
        }
    }

    /// One event: an interaction inside the layer or the arrival at a face. Returns false when the packet has
    /// ended (left the stack, lost the roulette, or glides in a clear layer forever).
    ///
    /// The common case — an interaction inside the layer — is decided without a division: the new depth
    /// z + uz·s/σt is compared with the face the packet heads for; only a packet that reaches it computes the
    /// distance to the face (and then stops there exactly, as MCML's `PathToBoundary` and `CrossOrNot`).
    #[inline(always)]
    fn event(
        &mut self,
        ch: &Channel<'_>,
        exponential: &ExponentialZiggurat,
        bins: usize,
        inv_bin: f64,
        tally: &mut Tally,
    ) -> bool {
        let media = ch.media;
        let m = &media[self.layer];
        let rng = &mut self.rng;
        if self.s_left == 0.0 {
            self.s_left = exponential.sample(rng);
        }
        let u = self.u;
        let down = u[2] > 0.0;
        let face_z = if down { m.z_bottom_mm } else { m.z_top_mm };
        if m.sigma_t > 0.0 {
            let d_step = self.s_left * m.inv_sigma_t;
            let z_new = self.z + u[2] * d_step;
            // Strictly short of the face it heads for (always for uz = 0, which meets no face).
            if u[2] == 0.0 || (z_new - face_z) * u[2] < 0.0 {
                self.x += u[0] * d_step;
                self.y += u[1] * d_step;
                self.z = z_new;
                self.s_left = 0.0;
                tally.interactions += 1;
                let dw = self.w * m.absorb_fraction;
                tally.absorbed[self.layer] += dw;
                self.w -= dw;
                let cos_t = m.hg.cos_theta(rng.uniform());
                let (cos_p, sin_p) = rng.azimuth_cos_sin();
                self.u = spin(u, cos_t, cos_p, sin_p);
                if self.w < ROULETTE_THRESHOLD {
                    if self.w == 0.0 {
                        return false;
                    }
                    if rng.uniform() <= 1.0 / ROULETTE_CHANCE {
                        self.w *= ROULETTE_CHANCE;
                    } else {
                        return false;
                    }
                }
                return true;
            }
        }
        let d_face = if u[2] != 0.0 { (face_z - self.z) / u[2] } else { f64::INFINITY };
        if d_face.is_infinite() {
            // Gliding parallel to the faces of a clear layer (or down a clear semi-infinite one): it never leaves;
            // score it as absorbed there.
            tally.absorbed[self.layer] += self.w;
            return false;
        }
        // Move to the face, keep the rest of the optical depth.
        self.x += u[0] * d_face;
        self.y += u[1] * d_face;
        self.z = face_z;
        if m.sigma_t > 0.0 {
            self.s_left = (self.s_left - d_face * m.sigma_t).max(0.0);
        }
        let last = media.len() - 1;
        let n_t = match (down, self.layer) {
            (false, 0) => ch.eta_above,
            (false, j) => media[j - 1].eta,
            (true, j) if j == last => ch.eta_below,
            (true, j) => media[j + 1].eta,
        };
        let (refl, cos_t) = fresnel(m.eta, n_t, u[2].abs());
        if refl > 0.0 && (refl >= 1.0 || rng.uniform() <= refl) {
            self.u[2] = -u[2];
            return true;
        }
        let ratio = m.eta / n_t;
        self.u = [u[0] * ratio, u[1] * ratio, if down { cos_t } else { -cos_t }];
        let exit = match (down, self.layer) {
            (false, 0) => {
                tally.rd += self.w;
                &mut tally.r
            }
            (true, j) if j == last => {
                tally.td += self.w;
                &mut tally.t
            }
            (false, _) => {
                self.layer -= 1;
                return true;
            }
            (true, _) => {
                self.layer += 1;
                return true;
            }
        };
        let bin = ((self.x * self.x + self.y * self.y).sqrt() * inv_bin) as usize;
        if bin < bins {
            exit[bin] += self.w;
        }
        false
    }
}

/// The scalar reference engine: traces photons `first..first + count` of channel `ch` into `tally`, one after the
/// other, with the draws of the module docs' last paragraph but one (ziggurat steps, disk azimuths). The lane
/// engine ([`super::lanes`]) is checked against it statistically.
pub(super) fn trace_chunk_scalar(ch: &Channel<'_>, bin_mm: f64, first: u64, count: u64, tally: &mut Tally) {
    let exponential = ExponentialZiggurat::new();
    let inv_bin = 1.0 / bin_mm;
    for k in first..first + count {
        let mut p = Photon::launch(ch, k);
        while p.event(ch, &exponential, tally.r.len(), inv_bin, tally) {}
    }
}
