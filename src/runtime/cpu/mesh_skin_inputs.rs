//! CPU twin of [`crate::runtime::mesh_skin_inputs`] (`shaders/mesh_skin_inputs.wgsl`): eq. 7.6 at the mesh's
//! texture coordinates, the same bilinear reads (texel centres, clamp to edge) and the same f32 sums in the same
//! order.

use crate::runtime::mesh_skin_inputs::RigAtUv;
use crate::runtime::RuntimeError;
use rayon::prelude::*;

/// Bilinear read of a row-major `w`×`h` map of `C` channels at (u, v), as the shader's `taps` + `rig_at`/`h0_at`.
pub(crate) fn bilinear<const C: usize>(data: &[[f32; C]], w: u32, h: u32, u: f32, v: f32) -> [f32; C] {
    let (x, y) = (u * w as f32 - 0.5, v * h as f32 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (xi, yi) = (x0 as i32, y0 as i32);
    let (wm, hm) = (w as i32 - 1, h as i32 - 1);
    let (i0, i1) = (xi.clamp(0, wm) as usize, (xi + 1).clamp(0, wm) as usize);
    let (j0, j1) = (yi.clamp(0, hm) as usize, (yi + 1).clamp(0, hm) as usize);
    let w = w as usize;
    let (a, b, c, d) = (data[j0 * w + i0], data[j0 * w + i1], data[j1 * w + i0], data[j1 * w + i1]);
    std::array::from_fn(|k| {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        top + (bottom - top) * fy
    })
}

/// Per pixel, H of eq. 7.6 at the pixel's texture coordinates (0 where not covered).
pub fn hemoglobin_at_uv(uv: &[[f32; 2]], covered: &[bool], maps: &RigAtUv<'_>) -> Result<Vec<f32>, RuntimeError> {
    maps.validate()?;
    let (rig, pose) = (maps.rig, maps.pose);
    let h0: Vec<[f32; 1]> = maps.h0.data.iter().map(|&v| [v]).collect();
    let mut out = vec![0.0f32; uv.len()];
    out.par_iter_mut().enumerate().for_each(|(i, o)| {
        if !covered[i] {
            return;
        }
        let [u, v] = uv[i];
        let (mut scale, mut bias) = (0.0f32, 0.0f32);
        for (k, map) in rig.targets.iter().enumerate() {
            let sb = bilinear(map, rig.width, rig.height, u, v);
            scale += pose.weights[k] * sb[0];
            bias += pose.weights[k] * sb[1];
        }
        let h0 = bilinear(&h0, maps.h0.width, maps.h0.height, u, v)[0];
        *o = pose.global_scale * (bias + h0 * scale); // eq. 7.6
    });
    Ok(out)
}
