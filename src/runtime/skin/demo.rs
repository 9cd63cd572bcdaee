//! The procedural demo frame (`rtbake run demo`, no input images): skin-shaded spheres (a "head" and two smaller
//! ones) in front of hard-edged shapes, through the shared lighting and compositing of
//! [`crate::runtime::skin::lighting`]. The baked rig and H0 cover the frame (screen uv ∈ [0, 1]², as the
//! skin-inputs pass samples them); the weights blend neutral with joy.

use crate::error::InvalidInput;
use crate::image_buf::Image;
use crate::runtime::backend::Backend;
use crate::runtime::chain::Antialiasing;
use crate::runtime::loader;
use crate::runtime::skin::inputs::SkinFrame;
use crate::runtime::skin::lighting::{lit_geometry, DemoAssets, Geometry, Lit, SssMethod};
use crate::runtime::skin::shade_frame::render_geometry;
use crate::runtime::RuntimeError;

/// Spheres as (centre x, centre y in units of the frame height, radius, depth of the centre).
const SPHERES: [(f32, f32, f32, f32); 3] = [(0.5, 0.5, 0.32, 4.0), (0.16, 0.72, 0.12, 5.0), (0.84, 0.3, 0.1, 3.5)];

fn geometry(w: u32, h: u32, rig: Option<&loader::BakedRig>) -> Geometry {
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
        specular: None,
        albedo: None,
        rig_at_uv: None,
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
                    // Fair, dark and medium skin (the LUT darkens quickly: Cm = 0.035 is already tanned).
                    g.frame.melanin[i] = [0.008, 0.12, 0.035][k];
                    // Mean-free neutral hemoglobin: the baked H0 at the screen uv, else a pore-scale pattern.
                    g.frame.h0[i] = match rig {
                        Some(r) => r.h0_at((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / hf),
                        None => 0.006 * ((x as f32 * 0.9).sin() * (y as f32 * 0.7).cos()),
                    };
                    // Thin at the rim (ears, nose in a head), thick in the middle.
                    g.frame.thickness_mm[i] = 0.3 + 6.0 * z;
                }
            }
        }
    }
    g
}

/// Peak host memory of [`render`] at `w`×`h`, in bytes: 120 bytes per pixel + 64 MiB, from peak RSS of the CPU
/// path measured at 512² and 1024² (115 B/pixel). The GPU path keeps the same host-side buffers.
pub fn memory_estimate_bytes(w: u32, h: u32) -> u64 {
    120 * w as u64 * h as u64 + (64 << 20)
}

fn lit(gpu: Backend<'_>, w: u32, h: u32, assets: &DemoAssets) -> Result<Lit, RuntimeError> {
    crate::error::check_size("width/height", w as u64, h as u64)?;
    lit_geometry(gpu, geometry(w, h, assets.baked_rig.as_ref()), assets)
}

/// The inputs the demo hands its SSS pass, as `rtbake run sss` reads them: linear diffuse light, albedo ·
/// (irradiance + back-lit T(s)·E) (RGBA, alpha = SSS strength, 1 on skin and 0 elsewhere) and linear view-space depth (one channel, > 0, in the
/// world units of the kernel's `sss_width`: the skin spheres sit 3.5–5 units away, the background at 50).
pub struct SssInputs {
    pub width: u32,
    pub height: u32,
    pub irradiance_rgba: Vec<f32>,
    pub depth: Vec<f32>,
}

/// The demo scene's SSS inputs (see [`SssInputs`]).
pub fn sss_inputs<'g>(
    gpu: impl Into<Backend<'g>>,
    w: u32,
    h: u32,
    assets: &DemoAssets,
) -> Result<SssInputs, RuntimeError> {
    let gpu: Backend = gpu.into();
    let Lit { geo, diffuse, .. } = lit(gpu, w, h, assets)?;
    Ok(SssInputs { width: w, height: h, irradiance_rgba: diffuse, depth: geo.depth })
}

/// Renders the demo frame (RGBA8, sRGB-encoded) with `assets`. `aa` None leaves it aliased. On a device the shading
/// (skin inputs, lit layer, SSS, composite, tone map) and the antialiasing are recorded into one command encoder and
/// read back once ([`crate::runtime::skin::shade_frame`], [`crate::runtime::chain::record_antialias`]), or each pass
/// runs on its own with its `set_shading_in_one_encoder` off (the antialiasing with its own submissions).
pub fn render<'g>(
    gpu: impl Into<Backend<'g>>,
    w: u32,
    h: u32,
    assets: &DemoAssets,
    method: SssMethod,
    aa: Option<&Antialiasing>,
) -> Result<Image<u8>, RuntimeError> {
    let gpu: Backend = gpu.into();
    crate::error::check_size("width/height", w as u64, h as u64)?;
    let geo = geometry(w, h, assets.baked_rig.as_ref());
    let background = crate::runtime::aa::scene::render_shapes(w, h, 1);
    render_geometry(gpu, geo, assets, Some(method), background, aa)
}

/// Bytes per pixel of the demo frame's largest GPU image: the skin-inputs pass reads back albedo and T(s)·E as
/// RGBA f32 (16 bytes); the SSS passes' images (8) and the antialiasing's (4) are smaller, and there is no bloom.
pub const LARGEST_BYTES_PER_PIXEL: u32 = 16;

/// Checks the demo frame `w`×`h` against the adapter's `limits` before any work (the geometry, the lighting and
/// every pass after it), so an over-limit frame is refused at once instead of after the passes before the one that
/// does not fit: the 2-D texture edge and the largest read-back ([`LARGEST_BYTES_PER_PIXEL`]). The message names
/// `--width/--height`, the largest frame of the same aspect that fits and `--cpu` (the CPU twins have no limit).
pub fn check_frame_fits(limits: &wgpu::Limits, w: u32, h: u32) -> Result<(), InvalidInput> {
    let edge = limits.max_texture_dimension_2d;
    let fits = |w: u32, h: u32| {
        w <= edge
            && h <= edge
            && crate::runtime::device::readback_bytes(w, h, LARGEST_BYTES_PER_PIXEL) <= limits.max_buffer_size
    };
    if fits(w, h) {
        return Ok(());
    }
    let largest = match crate::runtime::skin::frame::largest_fitting(w, h, fits) {
        Some((fw, fh)) => format!("`width` {fw} `height` {fh} is the largest frame of this aspect that fits"),
        None => "no frame of this aspect fits".to_string(),
    };
    Err(InvalidInput::new(
        "width/height",
        format!(
            "{w}x{h}: the skin-inputs pass needs {LARGEST_BYTES_PER_PIXEL} bytes per pixel (a {}-byte read-back), \
             over this GPU's limits (max_texture_dimension_2d {edge}, max_buffer_size {}); {largest}; or `cpu` \
             (the CPU twins have no such limit)",
            crate::runtime::device::readback_bytes(w, h, LARGEST_BYTES_PER_PIXEL),
            limits.max_buffer_size
        ),
    ))
}

/// Wall time of [`render`] at `w`×`h` plus the PNG encoding (the budget check): 1 µs per pixel on the CPU
/// path (0.94 s at 1024² on the project's 2-core machine, release), a tenth of it with a GPU, plus 0.5 s start-up.
pub fn time_estimate_seconds(w: u32, h: u32, cpu: bool) -> f64 {
    let per_pixel = if cpu { 1.0e-6 } else { 0.1e-6 };
    0.5 + per_pixel * w as f64 * h as f64
}

/// Wall time of `run demo` at `w`×`h` on a software adapter (lavapipe, llvmpipe), an upper bound of what was
/// measured with the debug build on the project's 2-core machine (lavapipe: llvmpipe 15 through Vulkan): 0.83 s at
/// 512², 1.13 s at 1024² (and 45 s reported at 8192²); 1 s of start-up plus 0.8 µs per pixel.
pub fn software_adapter_time_estimate_seconds(w: u32, h: u32) -> f64 {
    1.0 + 0.8e-6 * w as f64 * h as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_demo_frame_over_the_limits_is_refused_before_any_work_naming_the_largest_that_fits() {
        // 256 MiB buffers and 16384-texel textures (wgpu's defaults for the downlevel tiers are smaller).
        let l = wgpu::Limits { max_buffer_size: 1 << 28, max_texture_dimension_2d: 16384, ..Default::default() };
        assert_eq!(check_frame_fits(&l, 1920, 1080), Ok(()));
        // 8192² needs a 1 GiB read-back of RGBA f32.
        let err = check_frame_fits(&l, 8192, 8192).unwrap_err();
        assert_eq!(err.param, "width/height");
        for part in ["1073741824", "268435456", "`cpu`", "max_buffer_size"] {
            assert!(err.message.contains(part), "{part}: {err}");
        }
        let rest = &err.message[err.message.find("`width` ").expect("a suggestion") + 8..];
        let w: u32 = rest.split_whitespace().next().unwrap().parse().unwrap();
        assert_eq!(check_frame_fits(&l, w, w), Ok(()), "the suggested {w}² fits");
        assert!(check_frame_fits(&l, w + 1, w + 1).is_err(), "{w}² is not the largest");
        // The texture edge alone.
        let small = wgpu::Limits { max_texture_dimension_2d: 2048, ..l };
        let err = check_frame_fits(&small, 4096, 1024).unwrap_err();
        assert!(err.message.contains("`width` 2048 `height` 512"), "{err}");
    }
}
