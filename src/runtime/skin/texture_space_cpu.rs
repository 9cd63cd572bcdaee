//! CPU twin of the texture-space diffusion pass (`skin/texture_space.wgsl`; algorithm and sources in
//! [`crate::runtime::skin::texture_space`]): the same chained u/v blurs with the same f32 arithmetic (hand-written
//! bilinear filtering, clamp to edge, normalised by alpha), the weighted sum of blurs, and the gather at pixel uvs.
//! Meant for small maps (its cost is 12 passes × 7 taps × 4 loads per texel).

use crate::shading::texture_space::TAP_WEIGHTS;
use rayon::prelude::*;

fn load(map: &[[f32; 4]], n: i32, x: i32, y: i32) -> [f32; 4] {
    map[(y.clamp(0, n - 1) * n + x.clamp(0, n - 1)) as usize]
}

fn lerp4(a: [f32; 4], b: [f32; 4], f: f32) -> [f32; 4] {
    std::array::from_fn(|c| a[c] * (1.0 - f) + b[c] * f)
}

/// Bilinear sample of a `n`×`n` map at texel-space (px, py), texel centres at +0.5.
fn bilinear(map: &[[f32; 4]], n: i32, px: f32, py: f32) -> [f32; 4] {
    let (x, y) = (px - 0.5, py - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (ix, iy) = (x0 as i32, y0 as i32);
    let top = lerp4(load(map, n, ix, iy), load(map, n, ix + 1, iy), fx);
    let bottom = lerp4(load(map, n, ix, iy + 1), load(map, n, ix + 1, iy + 1), fx);
    lerp4(top, bottom, fy)
}

fn blur_pass(src: &[[f32; 4]], stretch: &[[f32; 2]], size: u32, dir: usize, sigma_mm: f32) -> Vec<[f32; 4]> {
    let n = size as i32;
    (0..(size * size) as usize)
        .into_par_iter()
        .map(|i| {
            let c = src[i];
            if c[3] <= 0.0 {
                return [0.0; 4];
            }
            let (x, y) = ((i as u32 % size) as f32, (i as u32 / size) as f32);
            let step = sigma_mm / stretch[i][dir];
            let d = if dir == 0 { [1.0, 0.0] } else { [0.0, 1.0] };
            let mut sum = [0.0f32; 4];
            for (k, w) in TAP_WEIGHTS.iter().enumerate() {
                let o = (k as i32 - 3) as f32 * step;
                let s = bilinear(src, n, x + 0.5 + d[0] * o, y + 0.5 + d[1] * o);
                for c in 0..4 {
                    sum[c] += w * s[c];
                }
            }
            if sum[3] > 0.0 {
                [sum[0] / sum[3], sum[1] / sum[3], sum[2] / sum[3], 1.0]
            } else {
                c
            }
        })
        .collect()
}

/// The weighted sum Σᵢ wᵢ · blurᵢ of the chained blurs of `irradiance` (premultiplied RGBA, `size`×`size`):
/// Gaussian i blurs the result of Gaussian i − 1 by `incremental_sigma_mm[i]` along u then v.
pub fn blur_sum(
    irradiance: &[[f32; 4]],
    stretch_mm_per_texel: &[[f32; 2]],
    size: u32,
    incremental_sigma_mm: &[f32],
    weights: &[[f32; 3]],
) -> Vec<[f32; 4]> {
    let mut cur = irradiance.to_vec();
    let mut acc = vec![[0.0f32; 4]; cur.len()];
    for (sigma, w) in incremental_sigma_mm.iter().zip(weights) {
        let h = blur_pass(&cur, stretch_mm_per_texel, size, 0, *sigma);
        cur = blur_pass(&h, stretch_mm_per_texel, size, 1, *sigma);
        acc.par_iter_mut().zip(&cur).for_each(|(a, o)| {
            *a = [a[0] + w[0] * o[0], a[1] + w[1] * o[1], a[2] + w[2] * o[2], o[3]];
        });
    }
    acc
}

/// The sum map at each of `uvs` (bilinear, normalised by alpha): (rgb, 1), or zeros where no covered texel is in
/// reach.
pub fn gather(sum_map: &[[f32; 4]], size: u32, uvs: &[[f32; 2]]) -> Vec<[f32; 4]> {
    uvs.par_iter()
        .map(|uv| {
            let s = bilinear(sum_map, size as i32, uv[0] * size as f32, uv[1] * size as f32);
            if s[3] > 0.0 {
                [s[0] / s[3], s[1] / s[3], s[2] / s[3], 1.0]
            } else {
                [0.0; 4]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A uniform covered map stays uniform (the kernel is normalised), and an uncovered border does not darken
    /// the covered texels next to it.
    #[test]
    fn uniform_irradiance_is_unchanged_and_uncovered_texels_do_not_bleed() {
        let size = 32u32;
        let irr: Vec<[f32; 4]> =
            (0..size * size).map(|i| if (i % size) < 16 { [0.5, 0.25, 0.125, 1.0] } else { [0.0; 4] }).collect();
        let stretch = vec![[0.5f32, 0.5]; irr.len()];
        let w = [[0.2f32, 0.3, 0.5], [0.8, 0.7, 0.5]];
        let out = blur_sum(&irr, &stretch, size, &[1.0, 2.0], &w);
        for (i, o) in out.iter().enumerate() {
            if irr[i][3] > 0.0 {
                for c in 0..3 {
                    assert!((o[c] - irr[i][c]).abs() < 1e-5, "texel {i}: {o:?}");
                }
            } else {
                assert_eq!(*o, [0.0; 4]);
            }
        }
        let g = gather(&out, size, &[[0.25, 0.5], [0.9, 0.5]]);
        assert!((g[0][0] - 0.5).abs() < 1e-5 && g[0][3] == 1.0);
        assert_eq!(g[1], [0.0; 4]);
    }

    /// A single bright texel spreads into a Gaussian whose variance along u is the sum of the incremental
    /// variances (in texels²: (σ/stretch)²) times the 7-tap kernel's own variance in σ² (Σ wₖ k² = 1.08).
    #[test]
    fn chained_blurs_add_their_variances() {
        let size = 129u32;
        let mut irr = vec![[0.0f32, 0.0, 0.0, 1.0]; (size * size) as usize];
        let c = (64 * size + 64) as usize;
        irr[c] = [1.0, 1.0, 1.0, 1.0];
        let stretch = vec![[0.25f32, 0.25]; irr.len()];
        // σ = 0.5 and then sqrt(1.75) mm: total variance 2 mm² = 32 texels².
        let out = blur_sum(&irr, &stretch, size, &[0.5, 1.75f32.sqrt()], &[[0.0; 3], [1.0; 3]]);
        let row = &out[(64 * size) as usize..(65 * size) as usize];
        let total: f32 = row.iter().map(|p| p[0]).sum();
        let var: f32 = row.iter().enumerate().map(|(x, p)| p[0] * (x as f32 - 64.0).powi(2)).sum::<f32>() / total;
        let kernel: f32 = TAP_WEIGHTS.iter().enumerate().map(|(k, w)| w * (k as f32 - 3.0).powi(2)).sum();
        let expect = kernel * 32.0;
        assert!((var - expect).abs() < 0.05 * expect, "variance {var} texels², expected {expect}");
    }
}
