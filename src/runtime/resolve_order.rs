//! MLAA before or after the MSAA resolve (thesis §10.5, Figs. 10.15–10.16: a post-process antialiaser combined
//! with MSAA can run on the resolved image, or on each sample's image before the resolve). On the procedural
//! shapes scene ([`crate::runtime::aa::scene`]) with the standard 4× sample pattern:
//!
//! - **aliased**: one sample at each pixel centre;
//! - **resolve**: the four sample images averaged in linear light (the hardware resolve);
//! - **after**: MLAA on the resolved image;
//! - **before**: MLAA on each sample image, then the resolve;
//!
//! each scored by its mean absolute error against 16× supersampling (a 4×4 grid averaged in linear light) over the
//! edge pixels — those whose supersampled value differs from the aliased one — in sRGB-encoded 0..=1 units
//! (mean over R, G, B). Pure orchestration of [`crate::runtime::chain::antialias`] (GPU or CPU twin).

use crate::image_buf::Image;
use crate::runtime::aa::mlaa::MlaaAreaMap;
use crate::runtime::aa::scene::{render_shapes, render_shapes_at};
use crate::runtime::backend::Backend;
use crate::runtime::chain::{antialias, Antialiasing};
use crate::runtime::sampler::{linear_to_srgb, srgb_to_linear, unorm8};
use crate::runtime::skin::mesh_raster_cpu::STANDARD_4X;
use crate::runtime::RuntimeError;

/// Edge errors of the four images (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ResolveOrderErrors {
    pub width: u32,
    pub height: u32,
    /// Pixels scored: supersampled value ≠ aliased value.
    pub edge_pixels: usize,
    pub aliased: f64,
    pub resolve: f64,
    pub mlaa_after_resolve: f64,
    pub mlaa_before_resolve: f64,
}

/// The linear-light mean of RGBA8 sRGB images, re-encoded (alpha 255).
fn resolve(images: &[Vec<u8>]) -> Vec<u8> {
    let n = images[0].len();
    (0..n)
        .map(|i| {
            if i % 4 == 3 {
                return 255;
            }
            let sum: f32 = images.iter().map(|im| srgb_to_linear(im[i] as f32 / 255.0)).sum();
            unorm8(linear_to_srgb(sum / images.len() as f32))
        })
        .collect()
}

fn edge_error(img: &[u8], truth: &[u8], edges: &[usize]) -> f64 {
    let sum: f64 = edges
        .iter()
        .map(|&p| (0..3).map(|c| (img[4 * p + c] as f64 - truth[4 * p + c] as f64).abs()).sum::<f64>() / 3.0)
        .sum();
    sum / 255.0 / edges.len().max(1) as f64
}

/// Renders and scores the four images at `w`×`h` with MLAA's area map `map`.
pub fn compare<'g>(
    gpu: impl Into<Backend<'g>>,
    w: u32,
    h: u32,
    map: &MlaaAreaMap,
) -> Result<ResolveOrderErrors, RuntimeError> {
    let gpu: Backend = gpu.into();
    crate::error::check_size("width/height", w as u64, h as u64)?;
    let aa = Antialiasing::Mlaa(map.clone());
    let mlaa = |rgba: Vec<u8>| -> Result<Vec<u8>, RuntimeError> {
        Ok(antialias(gpu, &Image::from_vec(w, h, 4, rgba), &aa)?.data)
    };
    let truth = render_shapes(w, h, 4);
    let aliased = render_shapes(w, h, 1);
    let samples: Vec<Vec<u8>> =
        STANDARD_4X.iter().map(|o| render_shapes_at(w, h, [o[0] as f64, o[1] as f64])).collect();
    let resolved = resolve(&samples);
    let after = mlaa(resolved.clone())?;
    let per_sample: Vec<Vec<u8>> = samples.into_iter().map(&mlaa).collect::<Result<_, _>>()?;
    let before = resolve(&per_sample);
    let edges: Vec<usize> =
        (0..(w * h) as usize).filter(|&p| truth[4 * p..4 * p + 3] != aliased[4 * p..4 * p + 3]).collect();
    Ok(ResolveOrderErrors {
        width: w,
        height: h,
        edge_pixels: edges.len(),
        aliased: edge_error(&aliased, &truth, &edges),
        resolve: edge_error(&resolved, &truth, &edges),
        mlaa_after_resolve: edge_error(&after, &truth, &edges),
        mlaa_before_resolve: edge_error(&before, &truth, &edges),
    })
}
