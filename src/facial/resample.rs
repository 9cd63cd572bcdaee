//! Resampling of low-frequency maps: area-weighted (box-footprint) resampling for any size ratio, and the
//! bilinear reconstruction a GPU sampler applies when the stored maps are read back at full resolution.
//!
//! Thesis §7.4/7.6: the scale and bias textures are low-frequency and are stored at 256×256; ch. 8 stores
//! wrinkle maps at 256×256 and masks at 64×64. Point sampling would alias, so every output texel is the exact
//! area average of the input texels its footprint covers: along one axis, output texel `j` of `m` covers input
//! interval `[j·n/m, (j+1)·n/m)`; in units of `1/m` input texel `i` spans `[i·m, (i+1)·m)` and output texel `j`
//! spans `[j·n, (j+1)·n)`, so all overlaps are integers and the weights `overlap / n` are exact. The filter is
//! separable (the footprint is a rectangle). It preserves the mean for any ratio and returns a constant map
//! unchanged (bit-exact), because each output is formed as `v_ref + Σ (v_i − v_ref)·overlap_i / n`.
//!
//! Bilinear reconstruction uses texel centres at `(i + 0.5)/m` and clamp-to-edge addressing (D3D/Vulkan/wgpu
//! `ClampToEdge` + linear filter).

use rayon::prelude::*;

/// Integer-overlap weights of one axis: for each output texel, (first input index, overlaps in units of 1/m).
fn axis_weights(n: usize, m: usize) -> Vec<(usize, Vec<u64>)> {
    (0..m)
        .map(|j| {
            let (a, b) = ((j * n) as u64, ((j + 1) * n) as u64); // output span in 1/m units
            let first = (a / m as u64) as usize;
            let last = b.div_ceil(m as u64) as usize; // exclusive
            let overlaps = (first..last)
                .map(|i| {
                    let (ia, ib) = ((i * m) as u64, ((i + 1) * m) as u64);
                    ib.min(b) - ia.max(a)
                })
                .collect();
            (first, overlaps)
        })
        .collect()
}

#[inline]
fn weighted(values: impl Iterator<Item = f64>, overlaps: &[u64], n: usize) -> f64 {
    let mut it = values.zip(overlaps);
    let Some((v0, &o0)) = it.next() else { return 0.0 };
    let _ = o0;
    let mut acc = 0.0f64;
    for (v, &o) in it {
        acc += (v - v0) * o as f64;
    }
    v0 + acc / n as f64
}

/// Area-weighted resampling of an interleaved `width × height × channels` f64 image to `out_w × out_h`.
/// Sizes must be non-zero (callers validate).
pub fn resample_area(src: &[f64], width: u32, height: u32, channels: u32, out_w: u32, out_h: u32) -> Vec<f64> {
    let (w, h, c, ow, oh) = (width as usize, height as usize, channels as usize, out_w as usize, out_h as usize);
    assert_eq!(src.len(), w * h * c, "image data length");
    assert!(ow > 0 && oh > 0 && w > 0 && h > 0);
    let wx = axis_weights(w, ow);
    let wy = axis_weights(h, oh);
    // Horizontal pass: h × ow.
    let mut tmp = vec![0.0f64; h * ow * c];
    tmp.par_chunks_mut(ow * c).enumerate().for_each(|(y, out)| {
        let row = &src[y * w * c..(y + 1) * w * c];
        for (j, (first, ov)) in wx.iter().enumerate() {
            for ch in 0..c {
                let vals = (0..ov.len()).map(|k| row[(first + k) * c + ch]);
                out[j * c + ch] = weighted(vals, ov, w);
            }
        }
    });
    // Vertical pass: oh × ow.
    let mut out = vec![0.0f64; oh * ow * c];
    out.par_chunks_mut(ow * c).enumerate().for_each(|(j, orow)| {
        let (first, ov) = &wy[j];
        for (x, o) in orow.iter_mut().enumerate() {
            let vals = (0..ov.len()).map(|k| tmp[(first + k) * ow * c + x]);
            *o = weighted(vals, ov, h);
        }
    });
    out
}

/// [`resample_area`] of single-channel maps in two steps, so that a producer of rows can downsample each row as it
/// is computed (no full-size buffer): [`Self::horizontal_row`] per input row into an `height × out_w` intermediate,
/// then [`Self::vertical`]. The values are those of `resample_area(…, 1, out_w, out_h)`, bit for bit.
#[derive(Clone, Debug)]
pub struct AreaResampler {
    width: usize,
    height: usize,
    out_w: usize,
    out_h: usize,
    wx: Vec<(usize, Vec<u64>)>,
    wy: Vec<(usize, Vec<u64>)>,
}

impl AreaResampler {
    /// Sizes must be non-zero (callers validate).
    pub fn new(width: u32, height: u32, out_w: u32, out_h: u32) -> Self {
        let (w, h, ow, oh) = (width as usize, height as usize, out_w as usize, out_h as usize);
        assert!(ow > 0 && oh > 0 && w > 0 && h > 0);
        Self { width: w, height: h, out_w: ow, out_h: oh, wx: axis_weights(w, ow), wy: axis_weights(h, oh) }
    }

    /// The horizontal pass of one input row (`width` values) into `out` (`out_w` values).
    pub fn horizontal_row(&self, row: &[f64], out: &mut [f64]) {
        assert_eq!((row.len(), out.len()), (self.width, self.out_w), "row lengths");
        for ((first, ov), o) in self.wx.iter().zip(out) {
            *o = weighted(row[*first..*first + ov.len()].iter().copied(), ov, self.width);
        }
    }

    /// The vertical pass over the `height × out_w` rows of [`Self::horizontal_row`]: the `out_w × out_h` result.
    pub fn vertical(&self, tmp: &[f64]) -> Vec<f64> {
        let (ow, h) = (self.out_w, self.height);
        assert_eq!(tmp.len(), h * ow, "intermediate size");
        let mut out = vec![0.0f64; self.out_h * ow];
        out.par_chunks_mut(ow).enumerate().for_each(|(j, orow)| {
            let (first, ov) = &self.wy[j];
            for (x, o) in orow.iter_mut().enumerate() {
                let vals = (0..ov.len()).map(|k| tmp[(first + k) * ow + x]);
                *o = weighted(vals, ov, h);
            }
        });
        out
    }
}

/// Sample position of full-resolution texel `x` (of `full`) in a map of `stored` texels: (i0, i1, t).
#[inline]
pub fn bilinear_coord(x: usize, full: usize, stored: usize) -> (usize, usize, f64) {
    // s = (x + 0.5)·stored/full − 0.5, formed exactly as a ratio of integers.
    let s = ((2 * x + 1) * stored) as f64 / (2 * full) as f64 - 0.5;
    if s <= 0.0 {
        return (0, 0, 0.0);
    }
    let i0 = s.floor() as usize;
    if i0 + 1 >= stored {
        return (stored - 1, stored - 1, 0.0);
    }
    (i0, i0 + 1, s - i0 as f64)
}

/// Precomputed bilinear coordinates of one axis.
pub fn bilinear_axis(full: usize, stored: usize) -> Vec<(usize, usize, f64)> {
    (0..full).map(|x| bilinear_coord(x, full, stored)).collect()
}

/// Bilinear value of a single-channel `sw × _` map at precomputed axis coordinates.
#[inline]
pub fn bilinear_at(map: &[f32], sw: usize, cx: (usize, usize, f64), cy: (usize, usize, f64)) -> f64 {
    let (x0, x1, tx) = cx;
    let (y0, y1, ty) = cy;
    let a = map[y0 * sw + x0] as f64;
    let b = map[y0 * sw + x1] as f64;
    let c = map[y1 * sw + x0] as f64;
    let d = map[y1 * sw + x1] as f64;
    let top = a + (b - a) * tx;
    let bot = c + (d - c) * tx;
    top + (bot - top) * ty
}

/// Bilinear reconstruction of a single-channel `sw × sh` map at `width × height` (texel centres, clamp to edge).
pub fn upsample_bilinear(map: &[f32], sw: u32, sh: u32, width: u32, height: u32) -> Vec<f64> {
    let (sw, sh, w, h) = (sw as usize, sh as usize, width as usize, height as usize);
    let ax = bilinear_axis(w, sw);
    let ay = bilinear_axis(h, sh);
    let mut out = vec![0.0f64; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            *o = bilinear_at(map, sw, ax[x], ay[y]);
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: usize, h: usize) -> Vec<f64> {
        (0..w * h).map(|i| ((i * 7919) % 1000) as f64 / 997.0 + (i % w) as f64 * 0.01).collect()
    }

    #[test]
    fn weights_sum_to_the_ratio() {
        for (n, m) in [(10usize, 3usize), (4096, 256), (100, 7), (3, 10), (5, 5)] {
            for (_, ov) in axis_weights(n, m) {
                assert_eq!(ov.iter().sum::<u64>(), n as u64);
            }
        }
    }

    #[test]
    fn preserves_the_mean_for_any_ratio() {
        for &(w, h, ow, oh) in &[(37u32, 23u32, 5u32, 7u32), (64, 64, 16, 16), (50, 30, 256, 17), (13, 11, 13, 11)] {
            let src = ramp(w as usize, h as usize);
            let out = resample_area(&src, w, h, 1, ow, oh);
            let m_in = src.iter().sum::<f64>() / src.len() as f64;
            let m_out = out.iter().sum::<f64>() / out.len() as f64;
            assert!((m_in - m_out).abs() < 1e-12, "{w}x{h}->{ow}x{oh}: {m_in} vs {m_out}");
        }
    }

    #[test]
    fn constant_maps_stay_exact() {
        for &c in &[0.1f64, 1.0 / 3.0, 12345.678, -2.5e-7] {
            for &(w, h, ow, oh) in &[(64u32, 48u32, 16u32, 12u32), (96, 96, 32, 32), (100, 37, 9, 5)] {
                let out = resample_area(&vec![c; (w * h * 2) as usize], w, h, 2, ow, oh);
                assert!(out.iter().all(|&v| v == c), "{c} {w}x{h}->{ow}x{oh}");
            }
        }
    }

    #[test]
    fn integer_ratio_is_the_block_average() {
        let src = ramp(8, 6);
        let out = resample_area(&src, 8, 6, 1, 4, 3);
        for j in 0..3 {
            for i in 0..4 {
                let avg = (src[2 * j * 8 + 2 * i]
                    + src[2 * j * 8 + 2 * i + 1]
                    + src[(2 * j + 1) * 8 + 2 * i]
                    + src[(2 * j + 1) * 8 + 2 * i + 1])
                    / 4.0;
                assert!((out[j * 4 + i] - avg).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn bilinear_reproduces_linear_ramps_inside_and_clamps_outside() {
        // A 4-texel ramp v = i stored; upsample to 16: interior texels follow s = (x+0.5)/4 − 0.5.
        let map = [0.0f32, 1.0, 2.0, 3.0];
        let up = upsample_bilinear(&map, 4, 1, 16, 1);
        for (x, &v) in up.iter().enumerate() {
            let s = ((x as f64 + 0.5) / 4.0 - 0.5).clamp(0.0, 3.0);
            assert!((v - s).abs() < 1e-12, "{x}: {v} vs {s}");
        }
        // Same size: identity.
        let up = upsample_bilinear(&map, 4, 1, 4, 1);
        assert_eq!(up, vec![0.0, 1.0, 2.0, 3.0]);
    }
}
