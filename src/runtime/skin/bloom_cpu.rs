//! CPU twin of [`crate::runtime::skin::bloom`] (`skin/bloom.wgsl`): the same bright part, 13-tap downsample, tent
//! upsample, zero padding and f32 sums in the same order.

use crate::error::InvalidInput;
use crate::runtime::skin::bloom::{level_sizes, BloomParams};
use rayon::prelude::*;

type Rgb = [f32; 3];

fn add(a: Rgb, b: Rgb) -> Rgb {
    std::array::from_fn(|c| a[c] + b[c])
}

fn scale(k: f32, a: Rgb) -> Rgb {
    std::array::from_fn(|c| k * a[c])
}

/// One level of the pyramid: size and texels, read as 0 outside.
struct Level {
    w: usize,
    h: usize,
    px: Vec<Rgb>,
}

impl Level {
    fn at(&self, x: i64, y: i64) -> Rgb {
        if x < 0 || y < 0 || x >= self.w as i64 || y >= self.h as i64 {
            return [0.0; 3];
        }
        self.px[y as usize * self.w + x as usize]
    }

    fn from_fn(w: usize, h: usize, f: impl Fn(usize, usize) -> Rgb + Sync) -> Level {
        let mut px = vec![[0.0f32; 3]; w * h];
        px.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                *o = f(x, y);
            }
        });
        Level { w, h, px }
    }

    /// The 2×2 box anchored at (x, y).
    fn quad(&self, x: i64, y: i64) -> Rgb {
        scale(0.25, add(add(add(self.at(x, y), self.at(x + 1, y)), self.at(x, y + 1)), self.at(x + 1, y + 1)))
    }

    /// Jimenez's 13-tap downsample at texel (x, y) of the level below this one.
    fn down(&self, x: usize, y: usize) -> Rgb {
        let (x, y) = (2 * x as i64, 2 * y as i64);
        let b = |dx: i64, dy: i64| self.quad(x + dx, y + dy);
        let mut v = scale(0.125, add(add(add(b(-1, -1), b(1, -1)), b(-1, 1)), b(1, 1)));
        v = add(v, scale(0.125, b(0, 0)));
        v = add(v, scale(0.0625, add(add(add(b(-2, 0), b(2, 0)), b(0, -2)), b(0, 2))));
        add(v, scale(0.03125, add(add(add(b(-2, -2), b(2, -2)), b(-2, 2)), b(2, 2))))
    }

    fn bilinear(&self, u: f32, v: f32) -> Rgb {
        let (fx, fy) = (u.floor(), v.floor());
        let (a, b) = (u - fx, v - fy);
        let (x, y) = (fx as i64, fy as i64);
        let top = add(scale(1.0 - a, self.at(x, y)), scale(a, self.at(x + 1, y)));
        let bottom = add(scale(1.0 - a, self.at(x, y + 1)), scale(a, self.at(x + 1, y + 1)));
        add(scale(1.0 - b, top), scale(b, bottom))
    }

    /// The 3×3 tent over this level read at the centre of texel (x, y) of the level above it.
    fn tent(&self, x: usize, y: usize) -> Rgb {
        let u = (x as f32 + 0.5) * 0.5 - 0.5;
        let v = (y as f32 + 0.5) * 0.5 - 0.5;
        let mut s = [0.0f32; 3];
        for j in -1i32..=1 {
            for i in -1i32..=1 {
                let w = ((2 - i.abs()) * (2 - j.abs())) as f32 / 16.0;
                s = add(s, scale(w, self.bilinear(u + i as f32, v + j as f32)));
            }
        }
        s
    }
}

/// Blooms a `width`×`height` linear HDR frame (RGBA, alpha passed through).
pub fn bloom(width: u32, height: u32, hdr_rgba: &[f32], p: &BloomParams) -> Result<Vec<f32>, InvalidInput> {
    p.validate()?;
    let (w, h) = (width as usize, height as usize);
    let n = w * h;
    if hdr_rgba.len() != 4 * n {
        return Err(InvalidInput::new("bloom input", format!("needs {width}x{height} RGBA values")));
    }
    let bright = |i: usize| -> Rgb { std::array::from_fn(|c| (hdr_rgba[4 * i + c] - p.threshold).max(0.0)) };
    let levels = p.levels(height);
    let mix = 1.0 / levels as f32;
    let mut down = vec![Level::from_fn(w, h, |x, y| bright(y * w + x))];
    for (lw, lh) in level_sizes(width, height, levels) {
        let above = down.last().expect("level 0");
        let next = Level::from_fn(lw as usize, lh as usize, |x, y| above.down(x, y));
        down.push(next);
    }
    let coarsest = down.last().expect("a level");
    let mut acc = Level { w: coarsest.w, h: coarsest.h, px: coarsest.px.iter().map(|&v| scale(mix, v)).collect() };
    for l in (1..levels as usize).rev() {
        let d = &down[l];
        acc = Level::from_fn(d.w, d.h, |x, y| add(scale(mix, d.px[y * d.w + x]), acc.tent(x, y)));
    }
    let mut out = vec![0.0f32; 4 * n];
    out.par_chunks_mut(4 * w).enumerate().for_each(|(y, row)| {
        for x in 0..w {
            let i = y * w + x;
            let (kb, b) = (acc.tent(x, y), bright(i));
            for c in 0..3 {
                row[4 * x + c] = hdr_rgba[4 * i + c] + p.weight * (kb[c] - b[c]);
            }
            row[4 * x + 3] = hdr_rgba[4 * i + 3];
        }
    });
    Ok(out)
}
