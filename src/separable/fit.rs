//! Fitting the separable kernel's strength and falloff to the exact 2-D kernel of a diffusion profile
//! (thesis eq. 6.1–6.3).
//!
//! # The objective (eq. 6.3), made explicit
//!
//! The thesis minimises `Σ_{a ∈ A_s} Σ_c (S_c[a] − s_c[x]·s_c[y])²` over a sample set A_s "denser near 0" but does
//! not publish A_s, the weighting, nor how the delta of eq. 6.1 is discretised. Here every choice is a field of
//! [`ObjectiveSpec`] and is recorded in [`ObjectiveSpec::definition`]:
//!
//! - **Units.** Everything is in mm. The kernel's offsets are in kernel units; the shader maps one kernel unit to
//!   (2/3)·sssWidth world units (its step divides by 3 while the texture coordinate spans half the NDC range), and
//!   a world unit is `mm_per_world_unit` mm (default 125: a head 1 unit tall ≈ 1/8 m, the published demo's scale,
//!   where sssWidth 0.012 gives ≈ 1 mm per kernel unit). So k = (2/3)·width·mm_per_world_unit mm per kernel unit.
//! - **Model (eq. 6.1).** s_c(x) = t_c·P̂(x / (k·(0.001 + f_c))) + (1 − t_c)·δ(x), where P̂ is the kernel profile
//!   of [`super::kernel`] (d'Eon's red Gaussians without the narrowest, each exp(−u²/2v)/(2πv), evaluated along a
//!   line exactly as the shader does, so the 1-D weights are ∝ w/√v) normalised to unit integral over the line,
//!   so ∫ s = 1 and ∬ s⊗s = 1. The runtime kernel additionally truncates P at ±RANGE kernel units and
//!   renormalises over its N taps; the fit uses the untruncated model.
//!   Width and falloff only appear as the product k·(0.001 + f): **width is fixed**, strength and falloff are fitted.
//! - **Target.** S_c(x, y) = R_c(√(x² + y²)) / R̂_c(0): the target's radial profile R (any
//!   [`RadialProfile`]) on the plane, normalised to unit total per channel (d'Eon's convention: colour comes from
//!   the albedo; the kernel itself conserves energy).
//! - **The delta term.** δ(x) has no pointwise value, and a renderer never sees it: light that stays within a
//!   pixel. Both kernels are therefore compared after filtering with the same pixel filter g⊗g, a Gaussian of
//!   variance h²/12 (the variance of a box pixel of footprint h = `pixel_mm`). Because g⊗g is separable *and*
//!   radial, the filtered model stays exactly separable, (s⊗s)∗(g⊗g) = (s∗g)⊗(s∗g), and the filtered target stays
//!   radial. δ∗g = g; each Gaussian of P̂ just gains variance h²/12 (closed form); the filtered target is the
//!   radial convolution S∗G(ρ) = ∫₀^∞ S(r)·(r/σ²)·exp(−(ρ − r)²/2σ²)·I₀e(ρr/σ²) dr, integrated with composite
//!   Gauss–Legendre panels of width σ over ρ ± 10σ (I₀e: exponentially scaled Bessel function).
//! - **Sample set A_s.** The tensor grid {(x_i, x_j)} of 1-D nodes x_k = X·sign(τ_k)·|τ_k|^e,
//!   τ_k = −1 + 2k/(n − 1) (the shader's own offset law; default n = 41, X = 4 mm, e = 2: spacing 0.01 mm at the
//!   centre, 0.39 mm at the edge).
//! - **Weighting.** Default none beyond the sample density (eq. 6.3 is a plain sum): the objective is
//!   Σ_c Σ_{i,j} (S̃_c(x_i, x_j) − s̃_c(x_i)·s̃_c(x_j))² in mm⁻⁴, where ~ marks pixel-filtered densities.
//!   [`Weighting::Area`] multiplies each term by the trapezoid cell area a_i·a_j, approximating eq. 6.2's integral
//!   over [−X, X]² instead (mm⁻²).
//!
//! # Solver
//!
//! Once width is fixed the channels decouple: three independent problems in (t_c, f_c). Each is solved with
//! argmin's **Nelder–Mead** simplex in the variables (θ, φ) with t = sin²θ, f = φ², which maps the box
//! t ∈ [0, 1], f ≥ 0 onto the plane without making the bounds unreachable (fits of skin profiles push strength
//! to 1). Why Nelder–Mead: two unknowns, a cheap objective (n² products), an optimum that sits on or near a bound,
//! and no box-constrained quasi-Newton method in argmin; a derivative-free simplex needs no Jacobian of the
//! reparameterisation, which vanishes exactly at the bounds and would stall gradient methods there. The problem
//! is not convex, so the simplex starts from Table 6.1's value (moved to the fixed width, same k·(0.001 + f)), the
//! published preset and a grid of 20 points, and the best result is polished by restarts with a small simplex.
//! Starting from Table 6.1 guarantees the fit is never worse than Table 6.1 under this objective.
//!
//! # Separability
//!
//! [`separability`] returns σ₁²/Σσᵢ² (energy) and σ₁/Σσᵢ (share) of each channel's pixel-filtered target
//! kernel matrix K[i, j] = S̃(x_i, x_j) on a uniform grid of pixel footprint h over [−X, X]² (nalgebra SVD). The
//! thesis' Figure 6.2 reports ~80 % "energy" for skin; for d'Eon's profile at the default pixel the squared
//! energy is 97.8 / 99.2 / 99.7 % (R, G, B) while the share is 84 / 91 / 95 %: the thesis' figure is closer to
//! the share; both are reported.

use crate::diffusion::RadialProfile;
use crate::error::{check_range, InvalidInput};
use argmin::core::{CostFunction, Error as ArgminError, Executor, State};
use argmin::solver::neldermead::NelderMead;
use nalgebra::{DMatrix, Vector2};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::f64::consts::PI;

use super::kernel::{kernel_profile, validate_params, FALLOFF_EPSILON};
use super::{SeparableParams, CHANNELS, TABLE_6_1, TABLE_6_1_WIDTH};

/// Errors of the separable fit.
#[derive(Debug, thiserror::Error)]
pub enum SeparableFitError {
    #[error("{0}")]
    Invalid(#[from] InvalidInput),
    #[error("separable fit: optimiser failed: {0}")]
    Solver(String),
}

/// Every choice that defines the objective (see the module docs). Serialised into reports.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectiveSpec {
    /// Fixed width (the shader's sssWidth, world units). Default: Table 6.1's 0.014.
    pub width: f64,
    /// mm per world unit (default 125: a head 1 unit tall).
    pub mm_per_world_unit: f64,
    /// Number of 1-D grid nodes n (odd).
    pub grid_nodes: usize,
    /// Grid half-extent X, mm.
    pub grid_extent_mm: f64,
    /// Exponent e of the node law x = X·sign(τ)|τ|^e (1 = uniform, larger = denser near 0).
    pub grid_exponent: f64,
    /// Pixel footprint h, mm; the pixel filter is a Gaussian of variance h²/12.
    pub pixel_mm: f64,
    /// How samples are weighted (default: plain sum, eq. 6.3).
    #[serde(default)]
    pub weighting: Weighting,
}

/// Weighting of the squared residuals over the sample set.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Weighting {
    /// Plain sum over the samples (eq. 6.3): the node density (higher near 0) weights the centre.
    #[default]
    Samples,
    /// Each sample weighted by its cell area a_i·a_j (trapezoid rule), approximating eq. 6.2's integral over the
    /// square [−X, X]² independently of how the nodes are spaced.
    Area,
}

impl Weighting {
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Samples => "samples",
            Self::Area => "area",
        }
    }
}

impl Default for ObjectiveSpec {
    fn default() -> Self {
        Self {
            width: TABLE_6_1_WIDTH,
            mm_per_world_unit: 125.0,
            grid_nodes: 41,
            grid_extent_mm: 4.0,
            grid_exponent: 2.0,
            // A 125 mm head filling a 720-pixel viewport (the thesis' α calibration: 20° FOV, 720 px).
            pixel_mm: 125.0 / 720.0,
            weighting: Weighting::Samples,
        }
    }
}

impl ObjectiveSpec {
    /// Checks every field, naming the `rtbake fit separable` flag.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        check_range("width", self.width, 1e-5, 1.0, "world units")?;
        check_range("mm_per_world_unit", self.mm_per_world_unit, 1e-3, 1e6, "mm")?;
        let n = self.grid_nodes;
        if !(5..=401).contains(&n) || n.is_multiple_of(2) {
            return Err(InvalidInput::new("grid_nodes", format!("must be an odd number in 5..=401, got {n}")));
        }
        check_range("grid_extent_mm", self.grid_extent_mm, 0.05, 100.0, "mm")?;
        check_range("grid_exponent", self.grid_exponent, 1.0, 4.0, "")?;
        check_range("pixel_mm", self.pixel_mm, 1e-3, 10.0, "mm")?;
        Ok(())
    }

    /// mm per kernel unit: (2/3)·width·mm_per_world_unit (the shader's fixed /3 against UV's half NDC range).
    pub fn mm_per_kernel_unit(&self) -> f64 {
        2.0 / 3.0 * self.width * self.mm_per_world_unit
    }

    /// Variance of the pixel filter, mm².
    pub fn pixel_variance_mm2(&self) -> f64 {
        self.pixel_mm * self.pixel_mm / 12.0
    }

    /// The 1-D nodes x_k of the sample set, mm, ascending and exactly symmetric.
    pub fn grid_nodes_mm(&self) -> Vec<f64> {
        let half = (self.grid_nodes - 1) / 2;
        let pos: Vec<f64> =
            (1..=half).map(|k| self.grid_extent_mm * (k as f64 / half as f64).powf(self.grid_exponent)).collect();
        let mut v: Vec<f64> = pos.iter().rev().map(|x| -x).collect();
        v.push(0.0);
        v.extend(pos);
        v
    }

    /// Per-node weights of the sum: 1 (samples) or the trapezoid cell width (area), mm.
    pub fn node_weights(&self, nodes: &[f64]) -> Vec<f64> {
        let n = nodes.len();
        (0..n)
            .map(|i| match self.weighting {
                Weighting::Samples => 1.0,
                Weighting::Area => {
                    let left = if i > 0 { nodes[i] - nodes[i - 1] } else { 0.0 };
                    let right = if i + 1 < n { nodes[i + 1] - nodes[i] } else { 0.0 };
                    0.5 * (left + right)
                }
            })
            .collect()
    }

    /// The recorded definition of the objective (for reports and provenance).
    pub fn definition(&self, target: &str) -> Value {
        let nodes = self.grid_nodes_mm();
        let half = nodes.len() / 2;
        json!({
            "formula": "sum over channels c and samples (x_i, x_j) of (S~_c(x_i, x_j) - s~_c(x_i) * s~_c(x_j))^2 \
                        (thesis eq. 6.3); ~ = filtered by the pixel filter",
            "units": "densities in mm^-2 (2-D) and mm^-1 (1-D); objective in mm^-4",
            "target": target,
            "target_normalisation": "R(r) / total reflectance per channel (unit integral over the plane)",
            "model": "s_c(x) = t_c * P(x / (k * (0.001 + f_c))) / (integral of P) + (1 - t_c) * delta(x), P = d'Eon \
                      red Gaussians without the narrowest, each exp(-u^2/2v)/(2 pi v), as in the shader",
            "width": self.width,
            "width_fixed": true,
            "mm_per_world_unit": self.mm_per_world_unit,
            "mm_per_kernel_unit": self.mm_per_kernel_unit(),
            "pixel_mm": self.pixel_mm,
            "pixel_filter": "Gaussian of variance pixel_mm^2 / 12 applied to both kernels (delta * g = g)",
            "grid": {
                "nodes": self.grid_nodes,
                "extent_mm": self.grid_extent_mm,
                "exponent": self.grid_exponent,
                "law": "x_k = extent * sign(tau) * |tau|^exponent, tau = -1 + 2k/(nodes - 1)",
                "samples": "tensor grid {(x_i, x_j)}: nodes^2 points per channel",
                "min_spacing_mm": nodes[half + 1] - nodes[half],
                "max_spacing_mm": nodes[nodes.len() - 1] - nodes[nodes.len() - 2],
            },
            "weighting": match self.weighting {
                Weighting::Samples => "samples: plain sum as eq. 6.3 (every sample weight 1); the node density, \
                    higher near 0, weights the centre",
                Weighting::Area => "area: each sample weighted by its trapezoid cell area a_i * a_j (mm^2), \
                    approximating eq. 6.2's integral over the square; objective in mm^-2",
            },
        })
    }
}

/// The pixel-filtered target on the tensor grid of an [`ObjectiveSpec`], per channel, row-major n×n.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetKernel {
    pub spec: ObjectiveSpec,
    pub nodes_mm: Vec<f64>,
    /// S̃_c(x_i, x_j) at index i·n + j, mm⁻².
    pub values: [Vec<f64>; 3],
    /// What the target is (recorded in reports).
    pub description: String,
}

impl TargetKernel {
    /// The exact 2-D kernel of a radial profile, normalised to unit total and pixel-filtered (module docs).
    pub fn from_profile(
        profile: &dyn RadialProfile,
        spec: &ObjectiveSpec,
        description: &str,
    ) -> Result<Self, SeparableFitError> {
        spec.validate()?;
        let nodes = spec.grid_nodes_mm();
        let values = radial_matrix(profile, &nodes, spec.pixel_variance_mm2())?;
        Ok(Self { spec: *spec, nodes_mm: nodes, values, description: description.into() })
    }

    /// A synthetic, exactly separable target s̃⊗s̃ made with known parameters (for validating the fitter).
    pub fn from_separable(params: &SeparableParams, spec: &ObjectiveSpec) -> Result<Self, SeparableFitError> {
        spec.validate()?;
        validate_params(params)?;
        let nodes = spec.grid_nodes_mm();
        let model = Model::new(spec);
        let n = nodes.len();
        let values = [0, 1, 2].map(|c| {
            let s = model.filtered(&nodes, params.strength[c], params.falloff[c]);
            let mut v = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    v[i * n + j] = s[i] * s[j];
                }
            }
            v
        });
        let description =
            format!("synthetic separable kernel, strength {:?}, falloff {:?}", params.strength, params.falloff);
        Ok(Self { spec: *spec, nodes_mm: nodes, values, description })
    }
}

/// Pixel-filtered, normalised target at every (x_i, x_j) of `nodes` (symmetric), per channel.
fn radial_matrix(profile: &dyn RadialProfile, nodes: &[f64], sigma2: f64) -> Result<[Vec<f64>; 3], SeparableFitError> {
    let totals = profile.total_reflectance();
    for (c, t) in totals.iter().enumerate() {
        if !(t.is_finite() && *t > 0.0) {
            return Err(InvalidInput::new(
                "target profile",
                format!("({}) total reflectance must be finite and > 0, got {t}", CHANNELS[c]),
            )
            .into());
        }
    }
    let n = nodes.len();
    let half = n / 2;
    // Distinct radii: pairs (a, b) of non-negative node indices with a <= b.
    let pairs: Vec<(usize, usize)> = (0..=half).flat_map(|a| (a..=half).map(move |b| (a, b))).collect();
    let filtered: Vec<[f64; 3]> = pairs
        .par_iter()
        .map(|&(a, b)| {
            let (xa, xb) = (nodes[half + a], nodes[half + b]);
            filtered_radial(profile, (xa * xa + xb * xb).sqrt(), sigma2)
        })
        .collect();
    let mut index = vec![0usize; (half + 1) * (half + 1)];
    for (k, &(a, b)) in pairs.iter().enumerate() {
        index[a * (half + 1) + b] = k;
        index[b * (half + 1) + a] = k;
    }
    let mut out = [vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]];
    for i in 0..n {
        for j in 0..n {
            let a = i.abs_diff(half);
            let b = j.abs_diff(half);
            let v = filtered[index[a * (half + 1) + b]];
            for c in 0..3 {
                let value = v[c] / totals[c];
                if !value.is_finite() {
                    return Err(InvalidInput::new(
                        "target profile",
                        format!("({}) is not finite near r = {} mm", CHANNELS[c], (nodes[i].hypot(nodes[j]))),
                    )
                    .into());
                }
                out[c][i * n + j] = value;
            }
        }
    }
    Ok(out)
}

/// (R ∗ G_σ)(ρ) for a radial R and a normalised 2-D Gaussian of variance σ²:
/// ∫₀^∞ R(r)·(r/σ²)·exp(−(ρ − r)²/(2σ²))·I₀e(ρr/σ²) dr, composite 8-point Gauss–Legendre on panels of width σ
/// over [max(0, ρ − 10σ), ρ + 10σ] (the Gaussian window is below e⁻⁵⁰ outside).
fn filtered_radial(profile: &dyn RadialProfile, rho: f64, sigma2: f64) -> [f64; 3] {
    let sigma = sigma2.sqrt();
    let lo = (rho - 10.0 * sigma).max(0.0);
    let hi = rho + 10.0 * sigma;
    let panels = ((hi - lo) / sigma).ceil().max(1.0) as usize;
    let width = (hi - lo) / panels as f64;
    let mut acc = [0.0; 3];
    for p in 0..panels {
        let a = lo + p as f64 * width;
        for (x, w) in GL8_NODES.iter().zip(GL8_WEIGHTS) {
            let r = a + 0.5 * width * (1.0 + x);
            let window = r / sigma2 * (-(rho - r) * (rho - r) / (2.0 * sigma2)).exp() * bessel_i0e(rho * r / sigma2);
            let prof = profile.reflectance_mm2(r);
            for c in 0..3 {
                acc[c] += 0.5 * width * w * window * prof[c];
            }
        }
    }
    acc
}

/// 8-point Gauss–Legendre nodes on [−1, 1] (Abramowitz & Stegun, Table 25.4).
const GL8_NODES: [f64; 8] = [
    -0.960_289_856_497_536_3,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL8_WEIGHTS: [f64; 8] = [
    0.101_228_536_290_376_3,
    0.222_381_034_453_374_5,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// Exponentially scaled modified Bessel function I₀e(z) = e^(−z)·I₀(z), z >= 0: power series
/// Σ (z²/4)^k/(k!)² for z <= 25, else the asymptotic series e^z/√(2πz)·Σ ((2k−1)!!)²/(k!·(8z)^k)
/// (Abramowitz & Stegun 9.6.12 and 9.7.1), both to ~1e−15 relative.
pub fn bessel_i0e(z: f64) -> f64 {
    if z <= 25.0 {
        let q = 0.25 * z * z;
        let mut term = 1.0;
        let mut sum = 1.0;
        let mut k = 1.0;
        while term > 1e-17 * sum {
            term *= q / (k * k);
            sum += term;
            k += 1.0;
        }
        sum * (-z).exp()
    } else {
        let mut term = 1.0;
        let mut sum = 1.0;
        for k in 1..60 {
            let kf = k as f64;
            let next = term * (2.0 * kf - 1.0) * (2.0 * kf - 1.0) / (8.0 * kf * z);
            if next > term || next < 1e-17 * sum {
                break;
            }
            term = next;
            sum += term;
        }
        sum / (2.0 * PI * z).sqrt()
    }
}

/// The pixel-filtered 1-D model s̃(x) (closed form).
struct Model {
    /// 1-D mixture weights m_i ∝ w_i/√v_i (the 2-D-normalised Gaussians of the shader, integrated along a line).
    mix: Vec<f64>,
    /// Variances of the profile's Gaussians in kernel units² (mm² of d'Eon's profile).
    variances: Vec<f64>,
    mm_per_kernel_unit: f64,
    sigma2: f64,
}

impl Model {
    fn new(spec: &ObjectiveSpec) -> Self {
        let prof = kernel_profile();
        let raw: Vec<f64> = prof.iter().map(|(v, w)| w / v.sqrt()).collect();
        let total: f64 = raw.iter().sum();
        Self {
            mix: raw.iter().map(|m| m / total).collect(),
            variances: prof.iter().map(|(v, _)| *v).collect(),
            mm_per_kernel_unit: spec.mm_per_kernel_unit(),
            sigma2: spec.pixel_variance_mm2(),
        }
    }

    /// s̃(x) = t·Σ m_i g(x; v_i·(k(0.001 + f))² + σ²) + (1 − t)·g(x; σ²) at every node, mm⁻¹ (eq. 6.1 ∗ pixel).
    fn filtered(&self, nodes: &[f64], strength: f64, falloff: f64) -> Vec<f64> {
        let scale = self.mm_per_kernel_unit * (FALLOFF_EPSILON + falloff);
        let vars: Vec<f64> = self.variances.iter().map(|v| v * scale * scale + self.sigma2).collect();
        nodes
            .iter()
            .map(|&x| {
                let p: f64 = self.mix.iter().zip(&vars).map(|(m, v)| m * gauss_1d(*v, x)).sum();
                strength * p + (1.0 - strength) * gauss_1d(self.sigma2, x)
            })
            .collect()
    }
}

/// Normalised 1-D Gaussian of variance v (mm²), mm⁻¹.
#[inline]
fn gauss_1d(variance: f64, x: f64) -> f64 {
    (-x * x / (2.0 * variance)).exp() / (2.0 * PI * variance).sqrt()
}

/// Σ_{i,j} w_i·w_j·(T[i,j] − s_i s_j)² for one channel.
fn channel_objective(target: &[f64], s: &[f64], weights: &[f64]) -> f64 {
    let n = s.len();
    let mut acc = 0.0;
    for i in 0..n {
        let row = &target[i * n..(i + 1) * n];
        let mut acc_row = 0.0;
        for j in 0..n {
            let d = row[j] - s[i] * s[j];
            acc_row += weights[j] * d * d;
        }
        acc += weights[i] * acc_row;
    }
    acc
}

/// Objective value per channel (eq. 6.3 as defined in the module docs) of `params` against `target`.
pub fn objective(target: &TargetKernel, params: &SeparableParams) -> [f64; 3] {
    objective_at_width(target, params, target.spec.width)
}

/// Objective per channel of `params` used with another width (same target, grid and pixel filter): how Table 6.1
/// (made for width 0.014) scores when the fit's fixed width differs.
pub fn objective_at_width(target: &TargetKernel, params: &SeparableParams, width: f64) -> [f64; 3] {
    let model = Model::new(&ObjectiveSpec { width, ..target.spec });
    let weights = target.spec.node_weights(&target.nodes_mm);
    [0, 1, 2].map(|c| {
        let s = model.filtered(&target.nodes_mm, params.strength[c], params.falloff[c]);
        channel_objective(&target.values[c], &s, &weights)
    })
}

/// Relative errors of the separable model s̃⊗s̃ with `params` against the pixel-filtered target kernel S̃ on the
/// fit's tensor grid, per channel, percent (`rtbake evaluate --separable`): the relative L2
/// √(Σ (S̃ − s̃⊗s̃)² / Σ S̃²) over the grid (the plain sum of eq. 6.3 as [`objective`] uses it, relative to the
/// target) and the max |S̃ − s̃⊗s̃| / max S̃. Both kernels have unit total by construction (module docs).
pub fn kernel_errors(target: &TargetKernel, params: &SeparableParams) -> ([f64; 3], [f64; 3]) {
    let model = Model::new(&target.spec);
    let n = target.nodes_mm.len();
    let mut l2 = [0.0; 3];
    let mut max = [0.0; 3];
    for c in 0..3 {
        let s = model.filtered(&target.nodes_mm, params.strength[c], params.falloff[c]);
        let (mut num, mut den, mut worst, mut peak) = (0.0, 0.0, 0.0f64, 0.0f64);
        for i in 0..n {
            for j in 0..n {
                let t = target.values[c][i * n + j];
                let d = t - s[i] * s[j];
                num += d * d;
                den += t * t;
                worst = worst.max(d.abs());
                peak = peak.max(t.abs());
            }
        }
        l2[c] = 100.0 * (num / den).sqrt();
        max[c] = 100.0 * worst / peak;
    }
    (l2, max)
}

/// One channel of the target and the model along the x axis (y = 0) from the centre outwards: the pixel-filtered
/// target kernel S̃(x, 0) and the separable model's s̃(x)·s̃(0) (eq. 6.1), as `(x mm, value mm⁻²)` points.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisRows {
    pub target: Vec<(f64, f64)>,
    pub model: Vec<(f64, f64)>,
}

/// [`AxisRows`] of each channel of `target` for the separable parameters `params`.
pub fn axis_rows(target: &TargetKernel, params: &SeparableParams) -> [AxisRows; 3] {
    let n = target.nodes_mm.len();
    let half = n / 2;
    std::array::from_fn(|c| {
        let s = model_row(&target.spec, params, c, &target.nodes_mm);
        AxisRows {
            target: (half..n).map(|i| (target.nodes_mm[i], target.values[c][i * n + half])).collect(),
            model: (half..n).map(|i| (target.nodes_mm[i], s[i] * s[half])).collect(),
        }
    })
}

/// The separable model's pixel-filtered 1-D kernel s̃(x) at `nodes_mm` (for plots next to the target's row).
pub fn model_row(spec: &ObjectiveSpec, params: &SeparableParams, channel: usize, nodes_mm: &[f64]) -> Vec<f64> {
    Model::new(spec).filtered(nodes_mm, params.strength[channel], params.falloff[channel])
}

/// One channel's problem in the reparameterised variables (θ, φ): t = sin²θ, f = φ².
struct ChannelProblem<'a> {
    model: &'a Model,
    nodes: &'a [f64],
    weights: &'a [f64],
    target: &'a [f64],
}

fn to_params(p: &Vector2<f64>) -> (f64, f64) {
    let s = p[0].sin();
    (s * s, p[1] * p[1])
}

fn from_params(t: f64, f: f64) -> Vector2<f64> {
    Vector2::new(t.clamp(0.0, 1.0).sqrt().asin(), f.max(0.0).sqrt())
}

impl CostFunction for ChannelProblem<'_> {
    type Param = Vector2<f64>;
    type Output = f64;
    fn cost(&self, p: &Self::Param) -> Result<f64, ArgminError> {
        let (t, f) = to_params(p);
        Ok(channel_objective(self.target, &self.model.filtered(self.nodes, t, f), self.weights))
    }
}

/// Runs Nelder–Mead from `start` with simplex edge `step`; returns (best point, best cost, iterations).
fn nelder_mead(
    problem: ChannelProblem<'_>,
    start: Vector2<f64>,
    step: f64,
) -> Result<(Vector2<f64>, f64, u64), SeparableFitError> {
    let f0 = problem.cost(&start).map_err(|e| SeparableFitError::Solver(e.to_string()))?;
    let simplex = vec![start, start + Vector2::new(step, 0.0), start + Vector2::new(0.0, step)];
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-15 * f0.max(1e-300))
        .map_err(|e| SeparableFitError::Solver(e.to_string()))?;
    let res = Executor::new(problem, solver)
        .configure(|state| state.max_iters(2000))
        .run()
        .map_err(|e| SeparableFitError::Solver(e.to_string()))?;
    let state = res.state();
    let best = *state.get_best_param().ok_or_else(|| SeparableFitError::Solver("no best parameter".into()))?;
    Ok((best, state.get_best_cost(), state.get_iter()))
}

/// The falloff that gives the same kernel at `to_width` as `falloff` at `from_width` (only width·(0.001 + f)
/// matters), clamped at 0.
pub fn falloff_at_width(falloff: f64, from_width: f64, to_width: f64) -> f64 {
    (from_width / to_width * (FALLOFF_EPSILON + falloff) - FALLOFF_EPSILON).max(0.0)
}

/// Fit of one target: parameters, objective values and what they were measured under.
#[derive(Clone, Debug, PartialEq)]
pub struct FitResult {
    pub params: SeparableParams,
    pub width: f64,
    /// Objective of the fitted parameters, per channel (sum = [`FitResult::objective`]).
    pub objective_per_channel: [f64; 3],
    /// Objective of thesis Table 6.1's parameters (at its width 0.014) under the same objective, per channel.
    pub table_6_1_per_channel: [f64; 3],
    /// Nelder–Mead iterations over all starts and channels.
    pub iterations: u64,
}

impl FitResult {
    pub fn objective(&self) -> f64 {
        self.objective_per_channel.iter().sum()
    }
    pub fn objective_table_6_1(&self) -> f64 {
        self.table_6_1_per_channel.iter().sum()
    }
}

/// Fits strength and falloff per channel (width fixed at `target.spec.width`) by Nelder–Mead with multiple
/// starts (module docs). Deterministic.
pub fn fit(target: &TargetKernel) -> Result<FitResult, SeparableFitError> {
    let spec = target.spec;
    spec.validate()?;
    let model = Model::new(&spec);
    let weights = spec.node_weights(&target.nodes_mm);
    let mut params = SeparableParams { strength: [0.0; 3], falloff: [0.0; 3] };
    let mut iterations = 0;
    for c in 0..3 {
        let problem =
            || ChannelProblem { model: &model, nodes: &target.nodes_mm, weights: &weights, target: &target.values[c] };
        let mut starts = vec![
            // Table 6.1 at its own width, moved to the fixed width (same k·(0.001 + f)), so the fit can never be
            // worse than Table 6.1 whenever that falloff is >= 0.
            (TABLE_6_1.strength[c], falloff_at_width(TABLE_6_1.falloff[c], TABLE_6_1_WIDTH, spec.width)),
            (super::PUBLISHED.strength[c], super::PUBLISHED.falloff[c]),
        ];
        for t in [0.3, 0.6, 0.9, 0.99] {
            for f in [0.02, 0.1, 0.3, 0.6, 1.0] {
                starts.push((t, f));
            }
        }
        let mut best: Option<(Vector2<f64>, f64)> = None;
        for (t, f) in starts {
            let (p, cost, it) = nelder_mead(problem(), from_params(t, f), 0.1)?;
            iterations += it;
            if best.is_none_or(|(_, b)| cost < b) {
                best = Some((p, cost));
            }
        }
        let (mut p, mut cost) = best.expect("at least one start");
        // Polish: restart with a small simplex until it stops improving.
        for _ in 0..5 {
            let (q, qcost, it) = nelder_mead(problem(), p, 1e-3)?;
            iterations += it;
            let improved = qcost < cost * (1.0 - 1e-12);
            if qcost < cost {
                p = q;
                cost = qcost;
            }
            if !improved {
                break;
            }
        }
        let (t, f) = to_params(&p);
        params.strength[c] = t;
        params.falloff[c] = f;
    }
    // Report the exact objective of the returned numbers.
    let objective_per_channel = objective(target, &params);
    let table_6_1_per_channel = objective_at_width(target, &TABLE_6_1, TABLE_6_1_WIDTH);
    Ok(FitResult { params, width: spec.width, objective_per_channel, table_6_1_per_channel, iterations })
}

/// How much of each channel's target kernel matrix its first singular value holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separability {
    /// σ₁²/Σσᵢ² (fraction of the Frobenius energy; 1 for a separable kernel).
    pub energy: [f64; 3],
    /// σ₁/Σσᵢ (share of the singular-value sum, the reading under which the thesis' ~80 % fits best).
    pub share: [f64; 3],
}

/// Singular values of each channel's pixel-filtered, normalised target kernel matrix K[i, j] = S̃(x_i, x_j) on a
/// uniform grid of pixel footprint `spec.pixel_mm` over [−X, X]² (nalgebra SVD).
pub fn separability(profile: &dyn RadialProfile, spec: &ObjectiveSpec) -> Result<Separability, SeparableFitError> {
    spec.validate()?;
    let half = (spec.grid_extent_mm / spec.pixel_mm).floor() as usize;
    let nodes: Vec<f64> = (0..=2 * half).map(|i| (i as f64 - half as f64) * spec.pixel_mm).collect();
    let m = radial_matrix(profile, &nodes, spec.pixel_variance_mm2())?;
    let fractions = m.map(|values| singular_value_fractions(nodes.len(), &values));
    Ok(Separability { energy: fractions.map(|f| f.0), share: fractions.map(|f| f.1) })
}

/// Shorthand for [`separability`]`.energy`.
pub fn first_singular_value_energy(
    profile: &dyn RadialProfile,
    spec: &ObjectiveSpec,
) -> Result<[f64; 3], SeparableFitError> {
    Ok(separability(profile, spec)?.energy)
}

/// (σ₁²/Σσᵢ², σ₁/Σσᵢ) of an n×n row-major matrix.
pub fn singular_value_fractions(n: usize, values: &[f64]) -> (f64, f64) {
    let sv = DMatrix::from_row_slice(n, n, values).singular_values();
    let total2: f64 = sv.iter().map(|s| s * s).sum();
    let total: f64 = sv.iter().sum();
    let first = sv.iter().cloned().fold(0.0, f64::max);
    if total > 0.0 {
        (first * first / total2, first / total)
    } else {
        (0.0, 0.0)
    }
}

/// The report `rtbake fit separable --json` prints: `strength`, `falloff`, `width`, `objective`,
/// `objective_table_6_1`, plus `objective_definition`, `first_singular_value_energy` and per-channel details.
pub fn report_json(target: &TargetKernel, result: &FitResult, sep: Option<&Separability>) -> Value {
    let ratio =
        if result.objective_table_6_1() > 0.0 { result.objective() / result.objective_table_6_1() } else { 0.0 };
    json!({
        "strength": result.params.strength,
        "falloff": result.params.falloff,
        "width": result.width,
        "objective": result.objective(),
        "objective_table_6_1": result.objective_table_6_1(),
        "objective_ratio_to_table_6_1": ratio,
        "objective_per_channel": result.objective_per_channel,
        "objective_table_6_1_per_channel": result.table_6_1_per_channel,
        "table_6_1": {"width": TABLE_6_1_WIDTH, "strength": TABLE_6_1.strength, "falloff": TABLE_6_1.falloff},
        "first_singular_value_energy": sep.map(|s| s.energy),
        "first_singular_value_share": sep.map(|s| s.share),
        "first_singular_value_definition": "singular values sigma_i of the pixel-filtered, normalised target kernel \
            matrix K[i, j] = S~(x_i, x_j) on a uniform grid of pixel_mm spacing over [-extent_mm, extent_mm]^2, per \
            channel; energy = sigma_1^2 / sum sigma_i^2, share = sigma_1 / sum sigma_i (thesis Figure 6.2: ~80 %)",
        "solver": "argmin Nelder-Mead per channel in (theta, phi), t = sin^2 theta, f = phi^2; 22 starts \
            (Table 6.1, published preset, 4x5 grid) + small-simplex restarts",
        "iterations": result.iterations,
        "objective_definition": target.spec.definition(&target.description),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::sum_of_gaussians::{deon6, gaussian_mm2};

    #[test]
    fn bessel_i0e_matches_known_values() {
        // I0(1) = 1.2660658777520082, I0(10) = 2815.716628466254, I0(30) = 7.816722978239774e11.
        assert!((bessel_i0e(0.0) - 1.0).abs() < 1e-16);
        assert!((bessel_i0e(1.0) - 1.266_065_877_752_008_2 * (-1.0f64).exp()).abs() < 1e-15);
        assert!((bessel_i0e(10.0) / (2_815.716_628_466_254 * (-10.0f64).exp()) - 1.0).abs() < 1e-13);
        assert!((bessel_i0e(30.0) / (7.816_722_978_239_774e11 * (-30.0f64).exp()) - 1.0).abs() < 1e-12);
        // Both sides of the switch between power series and asymptotic expansion (mpmath values).
        for (z, v) in
            [(24.9, 0.080_359_332_611_532_2), (25.0, 0.080_196_773_547_436_7), (25.1, 0.080_035_197_254_296_2)]
        {
            assert!((bessel_i0e(z) / v - 1.0).abs() < 1e-13, "{z}: {}", bessel_i0e(z));
        }
        assert!((bessel_i0e(100.0) / 0.039_944_379_299_096_7 - 1.0).abs() < 1e-13);
    }

    #[test]
    fn radial_filter_of_a_gaussian_sum_adds_the_pixel_variance() {
        // G(v) ∗ G(σ²) = G(v + σ²): the numerical radial convolution must reproduce it.
        let p = deon6();
        let sigma2 = 0.05f64.powi(2);
        for rho in [0.0, 0.01, 0.1, 0.37, 1.0, 2.5, 5.6] {
            let got = filtered_radial(&p, rho, sigma2);
            for c in 0..3 {
                let exact: f64 =
                    p.variances_mm2.iter().zip(&p.weights).map(|(v, w)| w[c] * gaussian_mm2(v + sigma2, rho)).sum();
                assert!((got[c] - exact).abs() <= 1e-10 * exact.max(1e-6), "rho {rho} c {c}: {} vs {exact}", got[c]);
            }
        }
    }

    #[test]
    fn model_integrates_to_one_and_matches_the_shader_profile_shape() {
        let spec = ObjectiveSpec::default();
        let model = Model::new(&spec);
        let xs: Vec<f64> = (-20000..=20000).map(|i| i as f64 * 1e-3).collect();
        for (t, f) in [(0.78, 0.57), (0.3, 0.05), (1.0, 1.0)] {
            let s = model.filtered(&xs, t, f);
            let integral: f64 = s.iter().sum::<f64>() * 1e-3;
            assert!((integral - 1.0).abs() < 1e-9, "{integral}");
        }
        // Unfiltered shape: proportional to the shader's profile P(x/(k(0.001+f))).
        let spec0 = ObjectiveSpec { pixel_mm: 1e-3, ..spec };
        let m0 = Model::new(&spec0);
        let k = spec0.mm_per_kernel_unit() * (0.001 + 0.4);
        let shader = |x: f64| -> f64 {
            let u = x / k;
            kernel_profile().iter().map(|(v, w)| w * (-u * u / (2.0 * v)).exp() / (2.0 * PI * v)).sum()
        };
        let xs = [0.3, 0.7, 1.5, 3.0];
        let s = m0.filtered(&xs, 1.0, 0.4);
        let ratios: Vec<f64> = xs.iter().zip(&s).map(|(x, s)| s / shader(*x)).collect();
        for r in &ratios {
            assert!((r / ratios[0] - 1.0).abs() < 1e-5, "{ratios:?}");
        }
    }

    #[test]
    fn grid_is_symmetric_and_denser_near_zero() {
        let nodes = ObjectiveSpec::default().grid_nodes_mm();
        assert_eq!(nodes.len(), 41);
        assert_eq!(nodes[20], 0.0);
        for i in 0..41 {
            assert_eq!(nodes[i], -nodes[40 - i]);
        }
        let d: Vec<f64> = nodes.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(d[20] < d[30] && d[30] < d[39]);
        assert!((nodes[40] - 4.0).abs() < 1e-15);
    }

    #[test]
    fn separable_target_has_rank_one() {
        let spec = ObjectiveSpec::default();
        let t = TargetKernel::from_separable(&TABLE_6_1, &spec).unwrap();
        for c in 0..3 {
            let (e, share) = singular_value_fractions(spec.grid_nodes, &t.values[c]);
            assert!((e - 1.0).abs() < 1e-12 && (share - 1.0).abs() < 1e-6, "{e} {share}");
        }
        assert!(objective(&t, &TABLE_6_1).iter().all(|v| *v == 0.0));
    }

    /// For a target that is itself separable, the plotted x-axis rows of target and model coincide, start at the
    /// centre and cover the positive half of the grid.
    #[test]
    fn axis_rows_of_a_separable_target_coincide() {
        let spec = ObjectiveSpec::default();
        let t = TargetKernel::from_separable(&TABLE_6_1, &spec).unwrap();
        for rows in axis_rows(&t, &TABLE_6_1) {
            assert_eq!(rows.target.len(), t.nodes_mm.len() - t.nodes_mm.len() / 2);
            assert_eq!(rows.target[0].0, 0.0);
            for (a, b) in rows.target.iter().zip(&rows.model) {
                assert_eq!(a.0, b.0);
                assert!((a.1 - b.1).abs() <= 1e-12 * a.1.abs().max(1e-300), "{a:?} {b:?}");
            }
        }
    }
}
