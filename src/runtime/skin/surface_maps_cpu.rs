//! CPU twin of [`crate::runtime::skin::surface_maps`] (`skin/surface_maps.wgsl`): the same bilinear reads and the
//! same MikkTSpace per-pixel frame, in f32.

use crate::runtime::sampler::bilinear;
use crate::runtime::skin::mesh_raster::MeshGBuffer;
use crate::runtime::skin::surface_maps::{SurfaceMap, SurfaceMaps, SurfacedPixels};
use rayon::prelude::*;

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The tangent-space normal `s` (need not be unit) taken to the frame of unit normal `n` and tangent `t4`
/// (xyz interpolated, w the handedness): normalize(s.x·T + s.y·w·(N × T) + s.z·N); `n` where either is degenerate.
pub fn mapped_normal(n: [f32; 3], t4: [f32; 4], s: [f32; 3]) -> [f32; 3] {
    let t = [t4[0], t4[1], t4[2]];
    let c = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]];
    let b = c.map(|x| t4[3] * x);
    let v: [f32; 3] = std::array::from_fn(|k| s[0] * t[k] + s[1] * b[k] + s[2] * n[k]);
    let (ls, lv) = (dot(s, s).sqrt(), dot(v, v).sqrt());
    if ls > 1e-6 && lv > 1e-6 {
        v.map(|x| x / lv)
    } else {
        n
    }
}

/// The map's value at (u, v): bilinear, clamp to edge.
pub fn sample(m: &SurfaceMap, u: f32, v: f32) -> [f32; 3] {
    let s = bilinear(&m.texels, m.width, m.height, u, v);
    [s[0], s[1], s[2]]
}

/// The pass on the CPU (see [`crate::runtime::skin::surface_maps`]).
pub fn surface_pixels(g: &MeshGBuffer, maps: &SurfaceMaps) -> SurfacedPixels {
    let n = (g.width * g.height) as usize;
    let mut normals = g.normal_view.clone();
    if let Some(nm) = &maps.normal {
        normals.par_iter_mut().enumerate().filter(|(i, _)| g.covered[*i]).for_each(|(i, o)| {
            let [u, v] = g.uv[i];
            *o = mapped_normal(g.normal_view[i], g.tangent_view[i], sample(nm, u, v));
        });
    }
    let albedo = maps.albedo.as_ref().map(|a| {
        (0..n)
            .into_par_iter()
            .map(|i| if g.covered[i] { sample(a, g.uv[i][0], g.uv[i][1]) } else { [0.0; 3] })
            .collect()
    });
    SurfacedPixels { normals, albedo }
}
