//! CPU twin of [`crate::runtime::skin::mesh_inputs`] (`skin/mesh_inputs.wgsl`): eq. 7.6 at the mesh's
//! texture coordinates, the same bilinear reads (texel centres, clamp to edge) and the same f32 sums in the same
//! order.

use crate::runtime::sampler::bilinear;
use crate::runtime::skin::mesh_inputs::RigAtUv;
use crate::runtime::RuntimeError;
use rayon::prelude::*;

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
