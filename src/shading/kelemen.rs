//! Kelemen & Szirmay-Kalos, *A Microfacet Based Coupled Specular-Matte BRDF Model with Importance Sampling*
//! (Eurographics 2001 short paper): the specular term with the unnormalised half vector h = L + V,
//!
//! f_s · (N·L) = ρ_s · (N·L) · P_H(N·H) · F(H·V) / (h·h),
//!
//! P_H the Beckmann distribution exp(−tan²θ_h / m²) / (m² cos⁴θ_h) and F Schlick's approximation
//! F0 + (1 − F0)(1 − H·V)⁵. The skin constants are those TAP 2009 §4 and thesis ch. 4 take over from d'Eon &
//! Luebke (GPU Gems 3, ch. 14, 2007): roughness m = 0.3, ρ_s = 0.18, F0 = 0.028 (skin's index of refraction 1.4).
//! Directions are unit vectors in any common frame, L and V pointing away from the surface.

/// Beckmann roughness m of skin.
pub const SKIN_ROUGHNESS: f32 = 0.3;
/// Specular intensity ρ_s of skin.
pub const SKIN_RHO_S: f32 = 0.18;
/// Fresnel reflectance at normal incidence of skin (n ≈ 1.4).
pub const SKIN_F0: f32 = 0.028;

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Schlick's Fresnel reflectance for the cosine `h_dot_v` between the half vector and the view direction.
pub fn schlick_fresnel(h_dot_v: f32, f0: f32) -> f32 {
    let base = (1.0 - h_dot_v.clamp(0.0, 1.0)).powi(5);
    f0 + (1.0 - f0) * base
}

/// The Beckmann distribution P_H for the cosine `n_dot_h`, roughness `m` (0 when n·h ≤ 0).
pub fn beckmann(n_dot_h: f32, m: f32) -> f32 {
    if n_dot_h <= 0.0 {
        return 0.0;
    }
    let c2 = n_dot_h * n_dot_h;
    let tan2 = (1.0 - c2) / c2;
    (-tan2 / (m * m)).exp() / (m * m * c2 * c2)
}

/// Reflected specular radiance per unit irradiance-normal light, f_s · (N·L) (0 when N·L ≤ 0).
pub fn specular(n: [f32; 3], l: [f32; 3], v: [f32; 3], m: f32, rho_s: f32, f0: f32) -> f32 {
    let n_dot_l = dot(n, l);
    if n_dot_l <= 0.0 {
        return 0.0;
    }
    let h = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
    let hh = dot(h, h);
    if hh <= 1e-12 {
        return 0.0;
    }
    let inv = 1.0 / hh.sqrt();
    let hn = [h[0] * inv, h[1] * inv, h[2] * inv];
    let value = rho_s * n_dot_l * beckmann(dot(n, hn), m) * schlick_fresnel(dot(hn, v), f0) / hh;
    value.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(v: [f32; 3]) -> [f32; 3] {
        let l = dot(v, v).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    }

    #[test]
    fn fresnel_and_beckmann_limits() {
        assert_eq!(schlick_fresnel(1.0, SKIN_F0), SKIN_F0);
        assert_eq!(schlick_fresnel(0.0, SKIN_F0), 1.0);
        // Beckmann at the peak is 1/m² and its projected integral ∫ P_H cos θ dω over the hemisphere is π
        // (this normalisation has no 1/π).
        assert!((beckmann(1.0, 0.3) - 1.0 / 0.09).abs() < 1e-4);
        let n = 20000;
        let mut integral = 0.0f64;
        for i in 0..n {
            let theta = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
            let p = beckmann(theta.cos() as f32, 0.3) as f64;
            integral +=
                p * theta.cos() * theta.sin() * 2.0 * std::f64::consts::PI * std::f64::consts::FRAC_PI_2 / n as f64;
        }
        assert!((integral - std::f64::consts::PI).abs() < 1e-3 * std::f64::consts::PI, "{integral}");
    }

    #[test]
    fn reciprocal_peaked_at_the_mirror_direction_and_zero_below_the_horizon() {
        let n = [0.0, 0.0, 1.0];
        let l = unit([0.3, 0.1, 0.9]);
        let v = unit([-0.5, 0.2, 0.7]);
        let f = |l, v| specular(n, l, v, SKIN_ROUGHNESS, SKIN_RHO_S, SKIN_F0) / dot(n, l);
        assert!((f(l, v) - f(v, l)).abs() < 1e-6 * f(l, v), "reciprocity");
        let mirror = [-l[0], -l[1], l[2]];
        let off = unit([-l[0] + 0.3, -l[1], l[2]]);
        assert!(f(l, mirror) > f(l, off));
        assert_eq!(specular(n, unit([0.0, 1.0, -0.1]), v, 0.3, 0.18, 0.028), 0.0);
    }
}
