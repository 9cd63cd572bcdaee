//! The procedural demo frame: skin-shaded spheres (a "head" and two smaller ones) in front of hard-edged shapes,
//! through the whole chain — skin inputs (rig → hemoglobin → albedo LUT, T(s)·E) → diffuse lighting →
//! separable SSS → + transmittance → sRGB encode → SMAA / MLAA. Every stage runs on the GPU passes, or on their
//! CPU references when no device is given. No input files.
//!
//! Stand-ins until the baked assets are wired: the albedo LUT is a smooth analytic melanin/hemoglobin tint
//! ([`standin_skin_luts`]), T(s) is eq. 5.12 evaluated on d'Eon's 6-Gaussian fit, and the kernel is
//! [`standin_kernel`] (per-channel Gaussians). Each can be replaced by the baked table without touching the chain.

use super::chain::{self, Antialiasing};
use super::cpu;
use super::device::Gpu;
use super::separable_sss::{SeparableSss, SssKernel, SssParams};
use super::skin_inputs::{HemoglobinRig, SkinFrame, SkinInputs, SkinLuts};
use super::RuntimeError;
use crate::diffusion::sum_of_gaussians::deon6;
use crate::image_buf::Image;

/// Stand-in skin LUTs: albedo tinted by melanin (absorbs blue most) and hemoglobin (absorbs green/blue), and
/// T(s) = Σ wᵢ exp(−s²/vᵢ) (thesis eq. 5.12, published form) from d'Eon's 6 Gaussians on s ∈ [0, 8] mm.
pub fn standin_skin_luts() -> SkinLuts {
    let (w, h) = (32u32, 32u32);
    let mut albedo = Vec::with_capacity((w * h) as usize);
    for j in 0..h {
        for i in 0..w {
            let cm = 0.5 * (i as f32 / (w - 1) as f32).powi(3);
            let chd = 0.32 * (j as f32 / (h - 1) as f32).powi(3);
            let m = [(-2.0 * cm).exp(), (-3.5 * cm).exp(), (-5.5 * cm).exp()];
            let hb = [(-0.6 * chd).exp(), (-4.0 * chd).exp(), (-3.0 * chd).exp()];
            albedo.push([0.85 * m[0] * hb[0], 0.70 * m[1] * hb[1], 0.62 * m[2] * hb[2]]);
        }
    }
    let fit = deon6();
    let n = 64;
    let transmittance = (0..n)
        .map(|i| {
            let s = 8.0 * i as f64 / (n - 1) as f64;
            let mut t = [0.0f32; 3];
            for (v, wt) in fit.variances_mm2.iter().zip(&fit.weights) {
                for c in 0..3 {
                    t[c] += (wt[c] * (-s * s / v).exp()) as f32; // eq. 5.12
                }
            }
            t
        })
        .collect();
    SkinLuts { albedo_size: (w, h), albedo, transmittance, s_max_mm: 8.0 }
}

/// Stand-in 17-tap separable kernel: per-channel Gaussians (σ = 1.0, 0.45, 0.3 kernel units) on offsets in
/// [−3, 3], normalised per channel, centre first.
pub fn standin_kernel() -> SssKernel {
    let n = 17;
    let sig = [1.0f32, 0.45, 0.3];
    let mut taps: Vec<[f32; 4]> = (0..n)
        .map(|i| {
            let o = -3.0 + 6.0 * i as f32 / (n - 1) as f32;
            let mut t = [0.0, 0.0, 0.0, o];
            for c in 0..3 {
                t[c] = (-o * o / (2.0 * sig[c] * sig[c])).exp();
            }
            t
        })
        .collect();
    for c in 0..3 {
        let s: f32 = taps.iter().map(|t| t[c]).sum();
        taps.iter_mut().for_each(|t| t[c] /= s);
    }
    let centre = taps.remove(n / 2);
    taps.insert(0, centre);
    SssKernel { taps }
}

/// A two-target rig (neutral, blush) at 16×16.
fn standin_rig() -> HemoglobinRig {
    let s = 16u32;
    let neutral = vec![[1.0f32, 0.06]; (s * s) as usize];
    let blush = (0..s * s)
        .map(|i| {
            let (x, y) = ((i % s) as f32 / s as f32 - 0.5, (i / s) as f32 / s as f32 - 0.55);
            let cheeks = (-((x.abs() - 0.2).powi(2) + y * y) / 0.02).exp();
            [1.0 + 0.8 * cheeks, 0.06 + 0.12 * cheeks]
        })
        .collect();
    HemoglobinRig { width: s, height: s, targets: vec![neutral, blush] }
}

struct Geometry {
    frame: SkinFrame,
    depth: Vec<f32>,
    skin: Vec<bool>,
}

/// Spheres as (centre x, centre y in units of the frame height, radius, depth of the centre).
const SPHERES: [(f32, f32, f32, f32); 3] = [(0.5, 0.5, 0.32, 4.0), (0.16, 0.72, 0.12, 5.0), (0.84, 0.3, 0.1, 3.5)];

fn geometry(w: u32, h: u32) -> Geometry {
    let n = (w * h) as usize;
    let mut g = Geometry {
        frame: SkinFrame {
            width: w,
            height: h,
            melanin: vec![0.0; n],
            h0: vec![0.0; n],
            thickness_mm: vec![8.0; n],
            normals: vec![[0.0, 0.0, 1.0]; n],
        },
        depth: vec![50.0; n],
        skin: vec![false; n],
    };
    let hf = h as f32;
    let aspect = w as f32 / hf;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (px, py) = ((x as f32 + 0.5) / hf, (y as f32 + 0.5) / hf);
            for (k, &(cx, cy, r, d0)) in SPHERES.iter().enumerate() {
                let (dx, dy) = (px - cx * aspect, py - cy);
                let d2 = dx * dx + dy * dy;
                let depth = d0 - (r * r - d2).max(0.0).sqrt();
                if d2 < r * r && depth < g.depth[i] {
                    let z = (r * r - d2).sqrt() / r;
                    g.depth[i] = depth;
                    g.skin[i] = true;
                    g.frame.normals[i] = [dx / r, -dy / r, z];
                    g.frame.melanin[i] = [0.04, 0.25, 0.12][k];
                    // Pore-scale variation of the mean-free neutral hemoglobin.
                    g.frame.h0[i] = 0.015 * ((x as f32 * 0.9).sin() * (y as f32 * 0.7).cos());
                    // Thin at the rim (ears, nose in a head), thick in the middle.
                    g.frame.thickness_mm[i] = 0.3 + 6.0 * z;
                }
            }
        }
    }
    g
}

/// Renders the demo frame (RGBA8, sRGB-encoded). `aa` None leaves it aliased.
pub fn render(gpu: Option<&Gpu>, w: u32, h: u32, aa: Option<&Antialiasing>) -> Result<Image<u8>, RuntimeError> {
    crate::error::check_size("--width/--height", w as u64, h as u64)?;
    let geo = geometry(w, h);
    let (luts, rig, kernel, params) = (standin_skin_luts(), standin_rig(), standin_kernel(), SssParams::default());
    let weights = [0.4f32, 0.6];
    let key = normalise([-0.5, 0.6, 0.62]);
    let back = normalise([0.3, 0.2, -0.93]);
    let (albedo, transmitted) = match gpu {
        Some(g) => SkinInputs::new(&g.device, &g.queue, w, h, &luts, &rig)?
            .run(&g.device, &g.queue, &geo.frame, &weights, back)?,
        None => cpu::skin_inputs::skin_inputs(&geo.frame, &luts, &rig, &weights, back),
    };
    // Diffuse irradiance · albedo (Lambert key light + ambient), alpha = SSS strength (1 on skin, 0 elsewhere).
    let n = (w * h) as usize;
    let mut diffuse = vec![0.0f32; 4 * n];
    for i in 0..n {
        if !geo.skin[i] {
            continue;
        }
        let nn = geo.frame.normals[i];
        let lambert = (nn[0] * key[0] + nn[1] * key[1] + nn[2] * key[2]).max(0.0);
        let e = 2.2 * lambert + 0.08;
        for c in 0..3 {
            diffuse[4 * i + c] = albedo[4 * i + c] * e;
        }
        diffuse[4 * i + 3] = 1.0;
    }
    let blurred = match gpu {
        Some(g) => {
            SeparableSss::new(&g.device, w, h, &kernel, &params)?.run(&g.device, &g.queue, &diffuse, &geo.depth)?
        }
        None => cpu::separable_sss::separable_sss(&diffuse, &geo.depth, w, h, &kernel, &params),
    };
    // Composite over the hard-edged background shapes; add back-lit transmittance; encode sRGB.
    let mut rgba = super::scene::render_shapes(w, h, 1);
    for i in 0..n {
        if !geo.skin[i] {
            continue;
        }
        for c in 0..3 {
            let v = blurred[4 * i + c] + 1.5 * albedo[4 * i + c] * transmitted[4 * i + c];
            let tonemapped = v / (1.0 + v);
            rgba[4 * i + c] = cpu::unorm8(cpu::linear_to_srgb(tonemapped));
        }
        rgba[4 * i + 3] = 255;
    }
    let frame = Image::from_vec(w, h, 4, rgba);
    match aa {
        Some(aa) => chain::antialias(gpu, &frame, aa),
        None => Ok(frame),
    }
}

fn normalise(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}
