//! Texture-space diffusion maths (d'Eon, Luebke and Enderton, "Efficient Rendering of Human Skin", EGSR 2007;
//! GPU Gems 3 ch. 14), with the three optimisations of Jimenez's thesis ch. 3 (Jimenez and Gutierrez, CEIG 2008).
//! Pure computation: the GPU pass is `runtime::texture_space`, its CPU twin `runtime::cpu::texture_space`.
//!
//! - **UV rasterisation** ([`rasterise_uv`]): the mesh drawn at its texture coordinates into a `T`×`T` map; each
//!   covered texel gets the interpolated position and normal, and the **stretch** of its triangle, the length of
//!   ∂P/∂u and ∂P/∂v in mm per texel (d'Eon's stretch map, computed exactly per triangle instead of from
//!   screen-space derivatives).
//! - **Chained blurs**: Gaussian i is applied on top of Gaussian i − 1 with the incremental variance
//!   vᵢ − vᵢ₋₁ (`GaussianBlurs::incremental_sigma_mm`), as a u and a v pass of 7 taps at 0, ±1, ±2, ±3 σ, the tap
//!   step in texels being σ / stretch; the final diffuse is Σ wᵢ · blurᵢ ([`normalised_weights`]).
//! - **Culled irradiance map** (§3.2, Listing 3.2): a texel is occluded when the angle between its normal and the
//!   view vector exceeds 105°, i.e. N·V < cos 105° = −0.2588 ([`is_culled`]).
//! - **Depth-based irradiance map** (§3.3, eq. 3.1–3.2): s = min(d_ref / d, 1), T = s·T_max, d the distance from
//!   the eye to the nearest corner of the object's bounding box (Fig. 3.3) ([`depth_sized_map`]).
//! - **Clipped irradiance map** (§3.4, eq. 3.3–3.4): the six clip-space planes Π = (±1, 0, 0, 1), (0, ±1, 0, 1),
//!   (0, 0, ±1, 1) moved to eye space by Π_eye = Pᵀ Π_clip; a texel whose eye-space position is behind any plane
//!   is clipped ([`frustum_planes_eye`], [`inside_frustum`]). wgpu's clip depth is z ∈ `[0, w]`, so the near plane
//!   is (0, 0, 1, 0) here where OpenGL's (z ∈ `[−w, w]`) is (0, 0, 1, 1).

use crate::mesh::Mesh;
use nalgebra::{Matrix4, Vector4};

/// Culling angle between normal and view vector beyond which a texel is occluded (thesis §3.2), degrees.
pub const CULL_ANGLE_DEG: f32 = 105.0;

/// The 7 tap weights at 0, ±1, ±2, ±3 σ (d'Eon et al. 2007's and the thesis' Listing 4.1 kernel; sum 1.000).
pub const TAP_WEIGHTS: [f32; 7] = [0.006, 0.061, 0.242, 0.382, 0.242, 0.061, 0.006];

/// Smallest irradiance map the depth-based optimisation shrinks to, texels.
pub const MIN_MAP_SIZE: u32 = 16;

/// Listing 3.2: occluded when N·V̂ < cos 105°, `n` the unit normal and `to_eye` the vector from the surface to the
/// eye (any length, same space).
pub fn is_culled(n: [f32; 3], to_eye: [f32; 3]) -> bool {
    let len = (to_eye[0] * to_eye[0] + to_eye[1] * to_eye[1] + to_eye[2] * to_eye[2]).sqrt();
    let d = (n[0] * to_eye[0] + n[1] * to_eye[1] + n[2] * to_eye[2]) / len;
    d < CULL_ANGLE_DEG.to_radians().cos()
}

/// Eq. 3.1–3.2: the irradiance map edge for an object whose nearest bounding-box corner is `d` from the eye, with
/// `t_max` at `d_ref` or closer (at least [`MIN_MAP_SIZE`], at most `t_max`).
pub fn depth_sized_map(t_max: u32, d_ref: f32, d: f32) -> u32 {
    let s = (d_ref / d).min(1.0); // eq. 3.1
    ((s * t_max as f32).round() as u32).clamp(MIN_MAP_SIZE.min(t_max), t_max) // eq. 3.2
}

/// Fig. 3.3: distance from `eye` to the nearest of the 8 corners of the box `lo`..`hi` (same units).
pub fn nearest_corner_distance(eye: [f32; 3], lo: [f32; 3], hi: [f32; 3]) -> f32 {
    (0..8)
        .map(|k| {
            let c = [0, 1, 2].map(|a| if k >> a & 1 == 0 { lo[a] } else { hi[a] });
            let d = [0, 1, 2].map(|a| c[a] - eye[a]);
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .fold(f32::INFINITY, f32::min)
}

/// Eq. 3.3–3.4: the six view-frustum planes (A, B, C, D) in eye coordinates, Π_eye = Pᵀ Π_clip with `p` the eye →
/// clip projection (wgpu: depth z ∈ `[0, w]`, so the near plane is (0, 0, 1, 0); D = 1 for the others as the thesis).
pub fn frustum_planes_eye(p: &Matrix4<f32>) -> [Vector4<f32>; 6] {
    let clip = [
        Vector4::new(1.0, 0.0, 0.0, 1.0),
        Vector4::new(-1.0, 0.0, 0.0, 1.0),
        Vector4::new(0.0, 1.0, 0.0, 1.0),
        Vector4::new(0.0, -1.0, 0.0, 1.0),
        Vector4::new(0.0, 0.0, 1.0, 0.0),
        Vector4::new(0.0, 0.0, -1.0, 1.0),
    ];
    clip.map(|pl| p.transpose() * pl)
}

/// Whether the eye-space point `p_eye` is on the inner side of all `planes` (eq. 3.3: Ax + By + Cz + D ≥ 0).
pub fn inside_frustum(planes: &[Vector4<f32>; 6], p_eye: [f32; 3]) -> bool {
    let p = Vector4::new(p_eye[0], p_eye[1], p_eye[2], 1.0);
    planes.iter().all(|pl| pl.dot(&p) >= 0.0)
}

/// |∂P/∂u| and |∂P/∂v| of a triangle, in position units per uv unit; None for a triangle degenerate in uv.
pub fn triangle_stretch(p: [[f32; 3]; 3], uv: [[f32; 2]; 3]) -> Option<[f32; 2]> {
    let e1 = [0, 1, 2].map(|k| p[1][k] - p[0][k]);
    let e2 = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
    let (d1, d2) = ([uv[1][0] - uv[0][0], uv[1][1] - uv[0][1]], [uv[2][0] - uv[0][0], uv[2][1] - uv[0][1]]);
    let det = d1[0] * d2[1] - d2[0] * d1[1];
    if det.abs() < 1e-12 || !det.is_finite() {
        return None;
    }
    let dpdu = [0, 1, 2].map(|k| (e1[k] * d2[1] - e2[k] * d1[1]) / det);
    let dpdv = [0, 1, 2].map(|k| (e2[k] * d1[0] - e1[k] * d2[0]) / det);
    let len = |v: [f32; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    Some([len(dpdu), len(dpdv)])
}

/// The weights wᵢ / Σⱼ wⱼ per channel of a fit from its blend constants w′ᵢ = wᵢ / Σⱼ≤ᵢ wⱼ (eq. 4.8, w′₁ = 1):
/// going down from the last, wᵢ/W = w′ᵢ · Fᵢ with F_N = 1 and Fᵢ₋₁ = Fᵢ (1 − w′ᵢ).
pub fn normalised_weights(blend: &[[f32; 3]]) -> Vec<[f32; 3]> {
    let mut out = vec![[0.0f32; 3]; blend.len()];
    let mut f = [1.0f32; 3];
    for i in (0..blend.len()).rev() {
        for c in 0..3 {
            out[i][c] = blend[i][c] * f[c];
            f[c] *= 1.0 - blend[i][c];
        }
    }
    out
}

/// A mesh drawn in UV space: per texel (row-major, v = 0 on the top row) the interpolated position (mesh units)
/// and unit normal, and the stretch of the covering triangle (mm per texel along u and v); `covered` false where
/// no triangle covers the texel centre.
#[derive(Clone, Debug, PartialEq)]
pub struct UvMap {
    pub size: u32,
    pub position: Vec<[f32; 3]>,
    pub normal: Vec<[f32; 3]>,
    pub stretch_mm_per_texel: Vec<[f32; 2]>,
    pub covered: Vec<bool>,
}

impl UvMap {
    pub fn covered_count(&self) -> usize {
        self.covered.iter().filter(|&&c| c).count()
    }
}

/// Rasterises `mesh` at its texture coordinates into a `size`×`size` map: texel centres inside a triangle (either
/// winding) take its barycentric interpolation; where UV triangles overlap, the first in index order wins
/// (overlapping UVs are accepted: the overlapped texels then carry one surface's irradiance for both).
pub fn rasterise_uv(mesh: &Mesh, size: u32) -> UvMap {
    let n = (size * size) as usize;
    let mut m = UvMap {
        size,
        position: vec![[0.0; 3]; n],
        normal: vec![[0.0; 3]; n],
        stretch_mm_per_texel: vec![[0.0; 2]; n],
        covered: vec![false; n],
    };
    let t = size as f32;
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let p = [mesh.positions[a], mesh.positions[b], mesh.positions[c]];
        let uv = [mesh.uvs[a], mesh.uvs[b], mesh.uvs[c]];
        let Some(st) = triangle_stretch(p, uv) else { continue };
        let stretch = st.map(|s| s * mesh.mm_per_unit / t);
        let na = [mesh.normals[a], mesh.normals[b], mesh.normals[c]];
        for_each_new_texel(uv, size, &mut m.covered, |i, w| {
            let lerp3 = |v: [[f32; 3]; 3]| [0, 1, 2].map(|k| w[0] * v[0][k] + w[1] * v[1][k] + w[2] * v[2][k]);
            let nn = lerp3(na);
            let l = (nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]).sqrt();
            m.position[i] = lerp3(p);
            m.normal[i] = nn.map(|v| v / l);
            m.stretch_mm_per_texel[i] = stretch;
        });
    }
    m
}

/// Calls `texel(i, w)` for every texel `i` of a `size`×`size` map whose centre lies in the triangle of texture
/// coordinates `uv` (barycentric weights `w`, none negative) and is not yet `covered`, marking it covered first: the
/// texel walk [`rasterise_uv`] and [`rasterise_uv_attribute`] share.
fn for_each_new_texel(uv: [[f32; 2]; 3], size: u32, covered: &mut [bool], mut texel: impl FnMut(usize, [f32; 3])) {
    let t = size as f32;
    let q = uv.map(|u| [u[0] * t, u[1] * t]);
    let area = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
    let x0 = q.iter().map(|v| v[0]).fold(f32::INFINITY, f32::min).floor().max(0.0) as u32;
    let x1 = (q.iter().map(|v| v[0]).fold(f32::NEG_INFINITY, f32::max).ceil() as i64).clamp(0, size as i64) as u32;
    let y0 = q.iter().map(|v| v[1]).fold(f32::INFINITY, f32::min).floor().max(0.0) as u32;
    let y1 = (q.iter().map(|v| v[1]).fold(f32::NEG_INFINITY, f32::max).ceil() as i64).clamp(0, size as i64) as u32;
    let edge = |p: [f32; 2], r: [f32; 2], x: f32, y: f32| (r[0] - p[0]) * (y - p[1]) - (x - p[0]) * (r[1] - p[1]);
    for py in y0..y1 {
        for px in x0..x1 {
            let i = (py * size + px) as usize;
            if covered[i] {
                continue;
            }
            let (x, y) = (px as f32 + 0.5, py as f32 + 0.5);
            let w = [edge(q[1], q[2], x, y) / area, edge(q[2], q[0], x, y) / area, edge(q[0], q[1], x, y) / area];
            if w.iter().any(|&v| v < 0.0) {
                continue;
            }
            covered[i] = true;
            texel(i, w);
        }
    }
}

/// A per-vertex attribute of `mesh` (e.g. its tangents) interpolated over a `size`×`size` map at its texture
/// coordinates, texel by texel as [`rasterise_uv`] covers them (texel centres inside a triangle of non-degenerate
/// stretch, first triangle in index order wins); zero where [`rasterise_uv`] covers nothing.
pub fn rasterise_uv_attribute(mesh: &Mesh, attribute: &[[f32; 4]], size: u32) -> Vec<[f32; 4]> {
    let n = (size * size) as usize;
    let mut out = vec![[0.0f32; 4]; n];
    let mut covered = vec![false; n];
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| i as usize);
        let p = [mesh.positions[a], mesh.positions[b], mesh.positions[c]];
        let uv = [mesh.uvs[a], mesh.uvs[b], mesh.uvs[c]];
        if triangle_stretch(p, uv).is_none() {
            continue;
        }
        let va = [attribute[a], attribute[b], attribute[c]];
        for_each_new_texel(uv, size, &mut covered, |i, w| {
            out[i] = [0, 1, 2, 3].map(|k| w[0] * va[0][k] + w[1] * va[1][k] + w[2] * va[2][k]);
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn culling_switches_at_105_degrees() {
        let n = [0.0, 0.0, 1.0];
        let at = |deg: f32| [deg.to_radians().sin(), 0.0, deg.to_radians().cos()];
        assert!(!is_culled(n, at(0.0)));
        assert!(!is_culled(n, at(100.0)));
        assert!(!is_culled(n, at(104.9)));
        assert!(is_culled(n, at(105.1)));
        assert!(is_culled(n, at(180.0)));
    }

    #[test]
    fn depth_sized_map_follows_eq_3_1_and_3_2() {
        assert_eq!(depth_sized_map(2048, 4.5, 2.0), 2048);
        assert_eq!(depth_sized_map(2048, 4.5, 4.5), 2048);
        assert_eq!(depth_sized_map(2048, 4.5, 9.0), 1024);
        assert_eq!(depth_sized_map(2048, 4.5, 1e6), MIN_MAP_SIZE);
        assert_eq!(nearest_corner_distance([0.0, 0.0, 5.0], [-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]), 18f32.sqrt());
    }

    /// Points projected inside the clip volume are inside the eye-space planes and vice versa.
    #[test]
    fn eye_space_planes_agree_with_the_clip_space_test() {
        let cam = crate::mesh::camera::Camera::facing(1.0).unwrap();
        let p = cam.projection(16.0 / 9.0);
        let planes = frustum_planes_eye(&p);
        let mut inside = 0;
        for k in 0..2000 {
            let f = |s: u32| ((k * s + 17) % 1000) as f32 / 1000.0;
            let e = [(f(37) - 0.5) * 3.0, (f(91) - 0.5) * 2.0, -f(53) * 12.0];
            let c = p * Vector4::new(e[0], e[1], e[2], 1.0);
            let in_clip = c.x.abs() <= c.w && c.y.abs() <= c.w && c.z >= 0.0 && c.z <= c.w;
            assert_eq!(inside_frustum(&planes, e), in_clip, "{e:?} clip {c:?}");
            inside += in_clip as u32;
        }
        assert!(inside > 200 && inside < 1800, "{inside}");
    }

    #[test]
    fn stretch_of_a_square_and_weights_of_the_blend_constants() {
        // A 0.1 × 0.2 rectangle mapped onto the unit uv square: ∂P/∂u = 0.1, ∂P/∂v = 0.2.
        let s =
            triangle_stretch([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.2, 0.0]], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        let s = s.unwrap();
        assert!((s[0] - 0.1).abs() < 1e-6 && (s[1] - 0.2).abs() < 1e-6, "{s:?}");
        assert!(triangle_stretch([[0.0; 3]; 3], [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]).is_none());
        // Weights (1, 2, 3, 4) / 10 → blend constants 1, 2/3, 3/6, 4/10.
        let blend = [[1.0; 3], [2.0 / 3.0; 3], [0.5; 3], [0.4; 3]];
        let w = normalised_weights(&blend);
        for (i, wi) in w.iter().enumerate() {
            assert!((wi[0] - (i + 1) as f32 / 10.0).abs() < 1e-6, "{w:?}");
        }
    }

    #[test]
    fn a_square_fills_its_uv_rectangle_with_its_stretch() {
        // 100 mm × 100 mm square on uv [0.25, 0.75]²: 200 mm per uv unit, 200/64 mm per texel at 64².
        let mesh = Mesh::new(
            "square",
            vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.1, 0.0], [0.0, 0.1, 0.0]],
            vec![[0.0, 0.0, 1.0]; 4],
            vec![[0.25, 0.75], [0.75, 0.75], [0.75, 0.25], [0.25, 0.25]],
            vec![0, 1, 2, 0, 2, 3],
            1000.0,
        )
        .unwrap();
        let m = rasterise_uv(&mesh, 64);
        assert_eq!(m.covered_count(), 32 * 32);
        let i = (20 * 64 + 40) as usize;
        assert!(m.covered[i]);
        for s in m.stretch_mm_per_texel[i] {
            assert!((s - 200.0 / 64.0).abs() < 1e-3, "{s}");
        }
        // Texel (40, 20): u = 40.5/64, v = 20.5/64 → x = (u − 0.25)·0.2, y = (0.75 − v)·0.2.
        let p = m.position[i];
        assert!((p[0] - (40.5 / 64.0 - 0.25) * 0.2).abs() < 1e-5 && (p[1] - (0.75 - 20.5 / 64.0) * 0.2).abs() < 1e-5);
    }
}
