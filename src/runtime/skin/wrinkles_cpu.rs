//! CPU twin of [`crate::runtime::skin::wrinkles`] (`skin/wrinkles.wgsl`): Listing 8.1 at the mesh's uv with
//! the same bilinear reads, the same sums in the same order and the same tangent frame.

use crate::error::InvalidInput;
use crate::runtime::sampler::bilinear;
use crate::runtime::skin::mesh_raster::MeshGBuffer;
use crate::runtime::skin::wrinkles::WrinkleMaps;
use rayon::prelude::*;

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The wrinkled view-space normals of `g` (uncovered pixels keep theirs).
pub fn wrinkled_normals(
    g: &MeshGBuffer,
    maps: &WrinkleMaps,
    weights: &[f32; 8],
) -> Result<Vec<[f32; 3]>, InvalidInput> {
    maps.validate()?;
    let ((pw, ph), (mw, mh)) = (maps.pd_size, maps.mask_size);
    let mut out = g.normal_view.clone();
    out.par_iter_mut().enumerate().for_each(|(i, o)| {
        if !g.covered[i] {
            return;
        }
        let [u, v] = g.uv[i];
        let n = g.normal_view[i];
        // Listing 8.1
        let wr = bilinear(&maps.pd, pw, ph, u, v);
        let m1 = bilinear(&maps.masks[0], mw, mh, u, v);
        let m2 = bilinear(&maps.masks[1], mw, mh, u, v);
        let m: [f32; 8] = std::array::from_fn(|k| if k < 4 { m1[k] * weights[k] } else { m2[k - 4] * weights[k] });
        let mut xy = [0.0f32; 2];
        for mk in m {
            xy = [xy[0] + mk * wr[0], xy[1] + mk * wr[1]];
        }
        let len = (xy[0] * xy[0] + xy[1] * xy[1] + 1.0).sqrt();
        let nts = [xy[0] / len, xy[1] / len, 1.0 / len];
        let t4 = g.tangent_view[i];
        let t = [t4[0], t4[1], t4[2]];
        let d = dot(n, t);
        let to = [t[0] - n[0] * d, t[1] - n[1] * d, t[2] - n[2] * d];
        let l = dot(to, to).sqrt();
        if l < 1e-6 {
            return;
        }
        let t = to.map(|c| c / l);
        let c = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]];
        let b = c.map(|x| t4[3] * x);
        *o = std::array::from_fn(|k| nts[0] * t[k] + nts[1] * b[k] + nts[2] * n[k]);
    });
    Ok(out)
}
