//! The skin-colour table by Monte Carlo transport, on a coarse (Cm, Chd) grid, and its difference from the
//! published table.
//!
//! The published table (thesis §7.6, eq. 7.7, Fig. 7.9; [`super::two_layer`]) combines multipole slabs by the
//! adding method (Donner & Jensen 2005/2006), a diffusion model that over-estimates the total reflectance of these
//! low-albedo layers. Here the same two-layer skin (same σa(λ), σs′(λ), thicknesses and indices) is run through
//! the Monte Carlo transport (MCML, Wang, Jacques & Zheng 1995; Henyey–Greenstein g, σs = σs′/(1 − g)) per
//! wavelength at the nodes of an `nodes × nodes` grid uniform in the table's index u = ∛(Cm/0.5), v = ∛(Chd/0.32),
//! projected to linear sRGB under D65 with the table's colour weights (the spectral projection of
//! [`crate::spectral::skin_layers::SkinProjection::Spectral`] times the weights' white, so a node's colour is
//! the table's colour functional applied to the transport's spectrum). Between the nodes the per-channel ratio
//! transport / published is interpolated bilinearly in (u, v) and applied to the published colour
//! ([`difference_map`]); [`McColorGrid::interpolate`] interpolates the node colours themselves.
//!
//! The difference is CIELAB ΔE*ab (CIE 15:2004 §8.2.1) between the two linear-sRGB colours, converted to XYZ with
//! the inverse of the IEC 61966-2-1 matrix and referred to the white XYZ of a flat reflectance of 1 (D65).
//! ΔE*ab rather than ΔE2000: the differences are large (tens of units), where the two metrics rank alike and ΔE*ab
//! is the simpler formula to check by hand.

use super::two_layer::TwoLayerSkinModel;
use crate::diffusion::source::TransportModel;
use crate::error::InvalidInput;
use crate::spectral::colorimetry::{Illuminant, SpectralGrid, SRGB_FROM_XYZ};
use crate::spectral::skin_layers::{
    physiological_skin_source_dj05, spectral_weights, SkinPhysiology, SkinProjection, DERMAL_HEMOGLOBIN_FRACTION_MAX,
    MELANIN_FRACTION_MAX,
};
use serde::{Deserialize, Serialize};

/// Most grid nodes per axis.
pub const MAX_NODES: u32 = 17;

/// Parameters of the Monte Carlo table. JSON field names are the `skin-color` flag names with `_`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct McColorParams {
    /// Henyey–Greenstein anisotropy, open interval (−1, 1) (0.8, the profiles' tissue-like default).
    pub g: f64,
    /// Photons per wavelength at the lightest nodes (Cm = 0), ≥ 1; see [`Self::photons_at`].
    pub photons: u64,
    /// Seed of the first node; node k (row-major, Chd slowest) uses `seed + k`.
    pub seed: u64,
    /// Grid nodes per axis, 2..=[`MAX_NODES`].
    pub mc_nodes: u32,
    /// Wavelength step of the transport, nm (must divide 400).
    pub mc_step_nm: u32,
    /// Width and height of the difference map, texels (8..=256).
    pub map_size: u32,
}

impl Default for McColorParams {
    /// The baked map: 4 × 4 nodes, 40 nm, 120 photons per wavelength at Cm = 0 (up to 1920 at Cm = 0.5), g = 0.8.
    fn default() -> Self {
        Self { g: 0.8, photons: 120, seed: 1, mc_nodes: 4, mc_step_nm: 40, map_size: 32 }
    }
}

impl McColorParams {
    /// Validates every field (errors name the field).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        TransportModel::monte_carlo(self.g, self.photons, self.seed)?;
        if !(2..=MAX_NODES).contains(&self.mc_nodes) {
            return Err(InvalidInput::new("mc_nodes", format!("must be 2..={MAX_NODES}, got {}", self.mc_nodes)));
        }
        SpectralGrid::new(self.mc_step_nm).map_err(|e| InvalidInput::new("mc_step_nm", e.message))?;
        if !(8..=256).contains(&self.map_size) {
            return Err(InvalidInput::new("map_size", format!("must be 8..=256 texels, got {}", self.map_size)));
        }
        Ok(())
    }

    /// (Cm, Chd) of node (i, j): the table's cube-root index, uniform.
    pub fn node(&self, i: u32, j: u32) -> (f64, f64) {
        let t = |k: u32| (k as f64 / (self.mc_nodes - 1) as f64).powi(3);
        (MELANIN_FRACTION_MAX * t(i), DERMAL_HEMOGLOBIN_FRACTION_MAX * t(j))
    }

    /// Photons per wavelength at melanin node `i`: `photons · (1 + 3u)²` with u = i/(nodes − 1), so the darker
    /// nodes (less light returns, but their photons are absorbed sooner and cost less) reach a relative standard
    /// error closer to the light ones' (16 × at Cm = 0.5).
    pub fn photons_at(&self, i: u32) -> u64 {
        let u = i as f64 / (self.mc_nodes - 1) as f64;
        (self.photons as f64 * (1.0 + 3.0 * u).powi(2)).round() as u64
    }

    fn source(
        &self,
        physiology: &SkinPhysiology,
        k: u32,
    ) -> Result<crate::diffusion::source::ProfileSource, InvalidInput> {
        let (i, j) = (k % self.mc_nodes, k / self.mc_nodes);
        let (cm, chd) = self.node(i, j);
        let transport = TransportModel::monte_carlo(self.g, self.photons_at(i), self.seed.wrapping_add(k as u64))?;
        let projection = SkinProjection::Spectral { illuminant: Illuminant::D65, step_nm: self.mc_step_nm };
        physiological_skin_source_dj05(physiology, &projection, cm, chd, transport)
    }

    /// Upper estimate of the wall time of [`McColorGrid::simulate`] on `threads` threads, seconds.
    pub fn time_estimate_seconds(&self, physiology: &SkinPhysiology, threads: usize) -> Result<f64, InvalidInput> {
        self.validate()?;
        let mut t = 0.0;
        for k in 0..self.mc_nodes * self.mc_nodes {
            t += self.source(physiology, k)?.time_estimate_seconds(0, threads);
        }
        Ok(t)
    }
}

/// The Monte Carlo colours at the grid nodes (row-major, Chd slowest) and their standard errors.
#[derive(Clone, Debug, PartialEq)]
pub struct McColorGrid {
    pub params: McColorParams,
    pub linear_rgb: Vec<[f64; 3]>,
    pub linear_rgb_se: Vec<[f64; 3]>,
}

impl McColorGrid {
    /// Runs the transport at every node (errors name a [`McColorParams`] field or a physiology field).
    pub fn simulate(params: &McColorParams, physiology: &SkinPhysiology) -> Result<Self, InvalidInput> {
        params.validate()?;
        let (_, white) = spectral_weights(SpectralGrid::new(params.mc_step_nm)?, Illuminant::D65);
        use rayon::prelude::*;
        // Nodes in parallel (each node's photons are few); each node has its own seed, results kept in node order.
        let nodes: Vec<([f64; 3], [f64; 3])> = (0..params.mc_nodes * params.mc_nodes)
            .into_par_iter()
            .map(|k| {
                let profile = params.source(physiology, k)?.build()?;
                let total = profile.total_reflectance();
                let se = profile.total_reflectance_se().unwrap_or([0.0; 3]);
                Ok(([0, 1, 2].map(|c| total[c] * white[c]), [0, 1, 2].map(|c| se[c] * white[c])))
            })
            .collect::<Result<_, InvalidInput>>()?;
        let (linear_rgb, linear_rgb_se) = nodes.into_iter().unzip();
        Ok(Self { params: params.clone(), linear_rgb, linear_rgb_se })
    }

    /// Bilinear interpolation in the table's index (u, v) ∈ [0, 1]².
    pub fn interpolate(&self, u: f64, v: f64) -> [f64; 3] {
        let n = self.params.mc_nodes as usize;
        let (x, y) = (u.clamp(0.0, 1.0) * (n - 1) as f64, v.clamp(0.0, 1.0) * (n - 1) as f64);
        let (i0, j0) = ((x.floor() as usize).min(n - 2), (y.floor() as usize).min(n - 2));
        let (fx, fy) = (x - i0 as f64, y - j0 as f64);
        let at = |i: usize, j: usize| self.linear_rgb[j * n + i];
        [0, 1, 2].map(|c| {
            let a = at(i0, j0)[c] * (1.0 - fx) + at(i0 + 1, j0)[c] * fx;
            let b = at(i0, j0 + 1)[c] * (1.0 - fx) + at(i0 + 1, j0 + 1)[c] * fx;
            a * (1.0 - fy) + b * fy
        })
    }

    /// The per-channel ratio transport / `published` at the nodes, as a grid (its standard errors relative).
    /// The colour falls steeply between the coarse nodes (a factor 6 between adjacent melanin nodes); the ratio
    /// varies slowly, so the ratio is what is interpolated.
    pub fn ratio_to(&self, published: &TwoLayerSkinModel) -> Result<Self, InvalidInput> {
        let mut ratios = self.clone();
        for (k, (r, se)) in ratios.linear_rgb.iter_mut().zip(ratios.linear_rgb_se.iter_mut()).enumerate() {
            let (i, j) = (k as u32 % self.params.mc_nodes, k as u32 / self.params.mc_nodes);
            let (cm, chd) = self.params.node(i, j);
            let p = published
                .evaluate(cm, chd, false)
                .map_err(|super::two_layer::SkinColorError::Invalid(e)| e)?
                .linear_rgb;
            *r = [0, 1, 2].map(|c| r[c] / p[c]);
            *se = [0, 1, 2].map(|c| se[c] / p[c]);
        }
        Ok(ratios)
    }

    /// The colour at (Cm, Chd) in Table 7.1's ranges.
    pub fn colour_at(&self, cm: f64, chd: f64) -> [f64; 3] {
        self.interpolate((cm / MELANIN_FRACTION_MAX).cbrt(), (chd / DERMAL_HEMOGLOBIN_FRACTION_MAX).cbrt())
    }
}

/// One texel of the difference map.
#[derive(Clone, Debug, PartialEq)]
pub struct DifferenceTexel {
    pub melanin: f64,
    pub hemoglobin: f64,
    pub published_linear_rgb: [f64; 3],
    pub monte_carlo_linear_rgb: [f64; 3],
    pub delta_e_ab: f64,
    /// Relative luminance difference (Y_mc − Y_published) / Y_published.
    pub relative_luminance: f64,
}

/// The published table against the Monte Carlo grid on a `map_size`² map of texel centres, row 0 = Chd 0
/// (the table's own convention), Cm along x. The Monte Carlo colour of a texel is the published colour times the
/// bilinear interpolation (in u, v) of the per-channel ratio transport / published at the nodes.
pub fn difference_map(published: &TwoLayerSkinModel, grid: &McColorGrid) -> Result<Vec<DifferenceTexel>, InvalidInput> {
    let n = grid.params.map_size;
    let ratios = grid.ratio_to(published)?;
    let mut out = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let (cm, chd) = (MELANIN_FRACTION_MAX * u.powi(3), DERMAL_HEMOGLOBIN_FRACTION_MAX * v.powi(3));
            let p = published
                .evaluate(cm, chd, false)
                .map_err(|super::two_layer::SkinColorError::Invalid(e)| e)?
                .linear_rgb;
            let ratio = ratios.interpolate(u, v);
            let m = [0, 1, 2].map(|c| p[c] * ratio[c]);
            let (yp, ym) = (xyz_of_linear_srgb(p)[1], xyz_of_linear_srgb(m)[1]);
            out.push(DifferenceTexel {
                melanin: cm,
                hemoglobin: chd,
                published_linear_rgb: p,
                monte_carlo_linear_rgb: m,
                delta_e_ab: delta_e_ab(p, m),
                relative_luminance: (ym - yp) / yp,
            });
        }
    }
    Ok(out)
}

/// XYZ of a linear-sRGB colour (inverse of [`SRGB_FROM_XYZ`], by Cramer's rule).
pub fn xyz_of_linear_srgb(rgb: [f64; 3]) -> [f64; 3] {
    let m = SRGB_FROM_XYZ;
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(m);
    [0, 1, 2].map(|k| {
        let mut a = m;
        for r in 0..3 {
            a[r][k] = rgb[r];
        }
        det(a) / d
    })
}

/// CIELAB of a linear-sRGB colour, white = the XYZ of linear sRGB (1, 1, 1) (D65).
pub fn lab_of_linear_srgb(rgb: [f64; 3]) -> [f64; 3] {
    let xyz = xyz_of_linear_srgb(rgb);
    let white = xyz_of_linear_srgb([1.0; 3]);
    let f = |t: f64| {
        let d = 6.0 / 29.0;
        if t > d * d * d {
            t.cbrt()
        } else {
            t / (3.0 * d * d) + 4.0 / 29.0
        }
    };
    let [fx, fy, fz] = [0, 1, 2].map(|c| f(xyz[c] / white[c]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIELAB ΔE*ab between two linear-sRGB colours.
pub fn delta_e_ab(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (la, lb) = (lab_of_linear_srgb(a), lab_of_linear_srgb(b));
    ((la[0] - lb[0]).powi(2) + (la[1] - lb[1]).powi(2) + (la[2] - lb[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// White is L* = 100, a* = b* = 0; 18 % grey is L* ≈ 49.5; ΔE of a colour with itself is 0.
    #[test]
    fn cielab_of_white_and_grey() {
        let w = lab_of_linear_srgb([1.0; 3]);
        assert!((w[0] - 100.0).abs() < 1e-9 && w[1].abs() < 1e-9 && w[2].abs() < 1e-9, "{w:?}");
        let g = lab_of_linear_srgb([0.18; 3]);
        assert!((g[0] - 49.496).abs() < 1e-2, "{g:?}");
        assert_eq!(delta_e_ab([0.3, 0.2, 0.1], [0.3, 0.2, 0.1]), 0.0);
        // The inverse matrix inverts: sRGB(XYZ(rgb)) = rgb.
        let rgb = [0.3, 0.2, 0.1];
        let back = crate::spectral::colorimetry::mat3_mul(&SRGB_FROM_XYZ, xyz_of_linear_srgb(rgb));
        assert!((0..3).all(|c| (back[c] - rgb[c]).abs() < 1e-12), "{back:?}");
    }

    /// Bilinear interpolation reproduces the nodes and is linear between them.
    #[test]
    fn interpolation_hits_the_nodes() {
        let params = McColorParams { mc_nodes: 3, ..Default::default() };
        let linear_rgb: Vec<[f64; 3]> = (0..9).map(|k| [k as f64, 2.0 * k as f64, (k % 3) as f64]).collect();
        let grid = McColorGrid { params, linear_rgb: linear_rgb.clone(), linear_rgb_se: vec![[0.0; 3]; 9] };
        for j in 0..3 {
            for i in 0..3 {
                assert_eq!(grid.interpolate(i as f64 / 2.0, j as f64 / 2.0), linear_rgb[j * 3 + i]);
            }
        }
        let mid = grid.interpolate(0.25, 0.25);
        let expect =
            [0, 1, 2].map(|c| (linear_rgb[0][c] + linear_rgb[1][c] + linear_rgb[3][c] + linear_rgb[4][c]) / 4.0);
        assert!((0..3).all(|c| (mid[c] - expect[c]).abs() < 1e-12), "{mid:?} {expect:?}");
    }

    /// Each field is validated by name.
    #[test]
    fn bad_parameters_name_their_field() {
        let bad = |p: McColorParams| p.validate().unwrap_err().param;
        assert_eq!(bad(McColorParams { g: 1.0, ..Default::default() }), "g");
        assert_eq!(bad(McColorParams { photons: 0, ..Default::default() }), "photons");
        assert_eq!(bad(McColorParams { mc_nodes: 1, ..Default::default() }), "mc_nodes");
        assert_eq!(bad(McColorParams { mc_step_nm: 7, ..Default::default() }), "mc_step_nm");
        assert_eq!(bad(McColorParams { map_size: 4, ..Default::default() }), "map_size");
    }
}
