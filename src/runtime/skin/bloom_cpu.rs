//! CPU twin of [`crate::runtime::skin::bloom`] (`skin/bloom.wgsl`): the same bright pass, taps, zero padding and f32
//! sums in the same order.

use crate::error::InvalidInput;
use crate::runtime::skin::bloom::BloomParams;
use rayon::prelude::*;

/// Blooms a `width`×`height` linear HDR frame (RGBA, alpha passed through).
pub fn bloom(width: u32, height: u32, hdr_rgba: &[f32], p: &BloomParams) -> Result<Vec<f32>, InvalidInput> {
    p.validate()?;
    let (w, h) = (width as usize, height as usize);
    let n = w * h;
    if hdr_rgba.len() != 4 * n {
        return Err(InvalidInput::new("bloom input", format!("needs {width}x{height} RGBA values")));
    }
    let bright = |i: usize| -> [f32; 3] { std::array::from_fn(|c| (hdr_rgba[4 * i + c] - p.threshold).max(0.0)) };
    let kernels = p.kernels(height);
    // Horizontal blurs of B, one image per kernel.
    let tmp: Vec<Vec<[f32; 3]>> = kernels
        .iter()
        .map(|taps| {
            let r = ((taps.len() - 1) / 2) as i64;
            let mut out = vec![[0.0f32; 3]; n];
            out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                for (x, o) in row.iter_mut().enumerate() {
                    let mut s = [0.0f32; 3];
                    for j in -r..=r {
                        let xx = x as i64 + j;
                        if (0..w as i64).contains(&xx) {
                            let b = bright(y * w + xx as usize);
                            let t = taps[(j + r) as usize];
                            s = std::array::from_fn(|c| s[c] + t * b[c]);
                        }
                    }
                    *o = s;
                }
            });
            out
        })
        .collect();
    let mut out = vec![0.0f32; 4 * n];
    out.par_chunks_mut(4 * w).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            let mut kb = [0.0f32; 3];
            for (k, taps) in kernels.iter().enumerate() {
                let r = ((taps.len() - 1) / 2) as i64;
                let mut s = [0.0f32; 3];
                for j in -r..=r {
                    let yy = y as i64 + j;
                    if (0..h as i64).contains(&yy) {
                        let v = tmp[k][yy as usize * w + x];
                        let t = taps[(j + r) as usize];
                        s = std::array::from_fn(|c| s[c] + t * v[c]);
                    }
                }
                kb = std::array::from_fn(|c| kb[c] + p.mix[k] * s[c]);
            }
            let i = y * w + x;
            let b = bright(i);
            for c in 0..3 {
                row[4 * x + c] = hdr_rgba[4 * i + c] + p.weight * (kb[c] - b[c]);
            }
            row[4 * x + 3] = hdr_rgba[4 * i + 3];
        }
    });
    Ok(out)
}
