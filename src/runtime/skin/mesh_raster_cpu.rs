//! CPU twin of [`crate::runtime::skin::mesh_raster`]: the same G-buffer by a reference rasteriser — triangles in index
//! order, pixel centres inside all three edge functions (a centre exactly on a shared edge is drawn by both
//! triangles, where the GPU's top-left rule picks one; the depth test keeps the first), back faces culled, depth
//! linear in screen space with a strict less-than test, attributes interpolated perspective-correctly (barycentrics
//! divided by clip w), the normal renormalised as the fragment shader does. Triangles with a vertex behind the near
//! plane are skipped (the GPU clips them), so the camera must keep the mesh in front of its near plane.

use crate::mesh::camera::Camera;
use crate::mesh::Mesh;
use crate::runtime::skin::mesh_raster::{camera_uniform, MeshGBuffer};
use nalgebra::{Matrix4, Vector4};

/// A vertex projected to the screen (pixels, y down) with the attributes the rasterisers interpolate.
struct V {
    x: f32,
    y: f32,
    z: f32,
    inv_w: f32,
    n: [f32; 3],
    depth_mm: f32,
    uv: [f32; 2],
    t: [f32; 4],
}

/// Every vertex of `mesh` seen by `camera` in a `width`×`height` frame, None behind half the near plane (its
/// triangles are skipped).
fn project(mesh: &Mesh, tangents: &[[f32; 4]], camera: &Camera, width: u32, height: u32) -> Vec<Option<V>> {
    let u = camera_uniform(mesh, camera, width, height);
    let vp = Matrix4::from_column_slice(&u[..16]);
    let view = Matrix4::from_column_slice(&u[16..32]);
    let (wf, hf) = (width as f32, height as f32);
    (0..mesh.positions.len())
        .map(|i| {
            let p = mesh.positions[i];
            let c = vp * Vector4::new(p[0], p[1], p[2], 1.0);
            if c.w <= camera.near * 0.5 {
                return None;
            }
            let pv = view * Vector4::new(p[0], p[1], p[2], 1.0);
            let n = mesh.normals[i];
            let nv = view * Vector4::new(n[0], n[1], n[2], 0.0);
            let tg = tangents[i];
            let tv = view * Vector4::new(tg[0], tg[1], tg[2], 0.0);
            Some(V {
                x: (c.x / c.w * 0.5 + 0.5) * wf,
                y: (0.5 - c.y / c.w * 0.5) * hf,
                z: c.z / c.w,
                inv_w: 1.0 / c.w,
                n: [nv.x, nv.y, nv.z],
                depth_mm: -pv.z * mesh.mm_per_unit,
                uv: mesh.uvs[i],
                t: [tv.x, tv.y, tv.z, tg[3]],
            })
        })
        .collect()
}

/// A front-facing triangle of projected vertices with its pixel bounding box.
struct Tri<'a> {
    v: [&'a V; 3],
    area: f32,
    x: std::ops::Range<u32>,
    y: std::ops::Range<u32>,
}

/// The attributes of a fragment, interpolated perspective-correctly, before rounding.
struct Fragment {
    /// Unit view-space normal.
    normal: [f32; 3],
    depth_mm: f32,
    uv: [f32; 2],
    tangent: [f32; 4],
}

impl Tri<'_> {
    /// The triangles of `mesh` in index order whose three vertices were projected, front faces only (counter-
    /// clockwise in NDC, y up, is clockwise on screen, y down: signed area < 0), clipped to the frame.
    fn front_faces<'a>(
        mesh: &'a Mesh,
        verts: &'a [Option<V>],
        width: u32,
        height: u32,
    ) -> impl Iterator<Item = Tri<'a>> {
        mesh.indices.chunks_exact(3).filter_map(move |t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| verts[i as usize].as_ref());
            let (a, b, c) = (a?, b?, c?);
            let area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if area.is_nan() || area >= 0.0 {
                return None;
            }
            let x0 = a.x.min(b.x).min(c.x).floor().max(0.0) as u32;
            let x1 = (a.x.max(b.x).max(c.x).ceil() as i64).clamp(0, width as i64) as u32;
            let y0 = a.y.min(b.y).min(c.y).floor().max(0.0) as u32;
            let y1 = (a.y.max(b.y).max(c.y).ceil() as i64).clamp(0, height as i64) as u32;
            Some(Tri { v: [a, b, c], area, x: x0..x1, y: y0..y1 })
        })
    }

    /// Screen-space barycentrics at (x, y): each the signed area opposite a vertex, all ≥ 0 inside.
    fn bary(&self, x: f32, y: f32) -> [f32; 3] {
        let edge = |p: &V, q: &V| (q.x - p.x) * (y - p.y) - (x - p.x) * (q.y - p.y);
        let [a, b, c] = self.v;
        [edge(b, c) / self.area, edge(c, a) / self.area, edge(a, b) / self.area]
    }

    /// Depth (NDC z) at barycentrics `w`, linear in screen space.
    fn z(&self, w: [f32; 3]) -> f32 {
        let [a, b, c] = self.v;
        w[0] * a.z + w[1] * b.z + w[2] * c.z
    }

    /// The attributes at screen barycentrics `w` (divided by clip w), the normal renormalised.
    fn fragment(&self, w: [f32; 3]) -> Fragment {
        let [a, b, c] = self.v;
        let (pa, pb, pc) = (w[0] * a.inv_w, w[1] * b.inv_w, w[2] * c.inv_w);
        let s = 1.0 / (pa + pb + pc);
        let lerp = |fa: f32, fb: f32, fc: f32| (pa * fa + pb * fb + pc * fc) * s;
        let n: [f32; 3] = std::array::from_fn(|k| lerp(a.n[k], b.n[k], c.n[k]));
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        Fragment {
            normal: n.map(|v| v / l),
            depth_mm: lerp(a.depth_mm, b.depth_mm, c.depth_mm),
            uv: [lerp(a.uv[0], b.uv[0], c.uv[0]), lerp(a.uv[1], b.uv[1], c.uv[1])],
            tangent: std::array::from_fn(|k| lerp(a.t[k], b.t[k], c.t[k])),
        }
    }
}

/// The standard 4× sample positions in a pixel (Vulkan's standard sample locations, D3D's standard pattern), from
/// its top-left corner.
pub const STANDARD_4X: [[f32; 2]; 4] = [[0.375, 0.125], [0.875, 0.375], [0.125, 0.625], [0.625, 0.875]];

/// [`rasterise`] with `samples` (1 or 4) samples per pixel: with 4, the standard pattern ([`STANDARD_4X`]),
/// coverage and depth tested per sample, attributes interpolated once at the pixel centre and stored (f16) in the
/// covered samples, the samples averaged (f16) and resolved as the GPU path does
/// (`mesh_raster::resolve_coverage`).
pub fn rasterise_samples(
    mesh: &Mesh,
    camera: &Camera,
    width: u32,
    height: u32,
    samples: u32,
) -> Result<MeshGBuffer, crate::error::InvalidInput> {
    let tangents = crate::mesh::tangents::vertex_tangents(mesh);
    rasterise_with_tangents(mesh, &tangents, camera, width, height, samples)
}

/// [`rasterise_samples`] with the caller's per-vertex `tangents` (as `mesh_raster::rasterise_with_tangents`).
pub fn rasterise_with_tangents(
    mesh: &Mesh,
    tangents: &[[f32; 4]],
    camera: &Camera,
    width: u32,
    height: u32,
    samples: u32,
) -> Result<MeshGBuffer, crate::error::InvalidInput> {
    crate::runtime::skin::mesh_raster::check_raster_inputs(mesh, tangents, samples)?;
    if samples == 1 {
        return Ok(rasterise_one(mesh, tangents, camera, width, height));
    }
    let n = (width * height) as usize;
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    // Per sample: depth, and the three targets' RGBA (zero where nothing covers the sample).
    let mut zbuf = vec![1.0f32; 4 * n];
    let mut targets = vec![[[0.0f32; 4]; 3]; 4 * n];
    let verts = project(mesh, tangents, camera, width, height);
    for tri in Tri::front_faces(mesh, &verts, width, height) {
        for py in tri.y.clone() {
            for px in tri.x.clone() {
                let i = (py * width + px) as usize;
                let mut pass = [false; 4];
                for (k, sp) in STANDARD_4X.iter().enumerate() {
                    let w = tri.bary(px as f32 + sp[0], py as f32 + sp[1]);
                    if w.iter().any(|&v| v < 0.0) {
                        continue;
                    }
                    let z = tri.z(w);
                    if z.is_nan() || z >= zbuf[4 * i + k] || z < 0.0 {
                        continue;
                    }
                    zbuf[4 * i + k] = z;
                    pass[k] = true;
                }
                if !pass.iter().any(|&p| p) {
                    continue;
                }
                // One fragment per pixel, attributes at the pixel centre (extrapolated when it lies outside).
                let f = tri.fragment(tri.bary(px as f32 + 0.5, py as f32 + 0.5));
                let out = [
                    [f16(f.normal[0]), f16(f.normal[1]), f16(f.normal[2]), f16(f.depth_mm)],
                    [f16(f.uv[0]), f16(f.uv[1]), 1.0, 0.0],
                    f.tangent.map(f16),
                ];
                for k in (0..4).filter(|&k| pass[k]) {
                    targets[4 * i + k] = out;
                }
            }
        }
    }
    // The resolve: the mean of the four samples, stored as f16.
    let mut resolved = [vec![0.0f32; 4 * n], vec![0.0f32; 4 * n], vec![0.0f32; 4 * n]];
    for i in 0..n {
        for (t, r) in resolved.iter_mut().enumerate() {
            for ch in 0..4 {
                let sum: f32 = (0..4).map(|k| targets[4 * i + k][t][ch]).sum();
                r[4 * i + ch] = f16(sum * 0.25);
            }
        }
    }
    let mut g = MeshGBuffer::empty(width, height);
    crate::runtime::skin::mesh_raster::resolve_coverage(&mut g, &resolved[0], &resolved[1], &resolved[2]);
    Ok(g)
}

/// Renders `mesh` seen by `camera` into a `width`×`height` G-buffer (values rounded to f16 as the GPU stores them).
pub fn rasterise(mesh: &Mesh, camera: &Camera, width: u32, height: u32) -> MeshGBuffer {
    rasterise_one(mesh, &crate::mesh::tangents::vertex_tangents(mesh), camera, width, height)
}

fn rasterise_one(mesh: &Mesh, tangents: &[[f32; 4]], camera: &Camera, width: u32, height: u32) -> MeshGBuffer {
    let mut g = MeshGBuffer::empty(width, height);
    let mut zbuf = vec![1.0f32; (width * height) as usize];
    let verts = project(mesh, tangents, camera, width, height);
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    for tri in Tri::front_faces(mesh, &verts, width, height) {
        for py in tri.y.clone() {
            for px in tri.x.clone() {
                let w = tri.bary(px as f32 + 0.5, py as f32 + 0.5);
                if w.iter().any(|&v| v < 0.0) {
                    continue;
                }
                let z = tri.z(w);
                let i = (py * width + px) as usize;
                if z.is_nan() || z >= zbuf[i] || z < 0.0 {
                    continue;
                }
                zbuf[i] = z;
                let f = tri.fragment(w);
                g.covered[i] = true;
                g.coverage[i] = 1.0;
                g.normal_view[i] = f.normal.map(f16);
                g.depth_mm[i] = f16(f.depth_mm);
                g.uv[i] = f.uv.map(f16);
                g.tangent_view[i] = f.tangent.map(f16);
            }
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square facing the camera covers exactly the pixel centres inside its projection; seen from behind it is
    /// culled.
    #[test]
    fn a_facing_square_covers_its_projection_and_its_back_is_culled() {
        let q = 0.1f32;
        let mesh = Mesh::new(
            "square",
            vec![[-q, -q, 0.0], [q, -q, 0.0], [q, q, 0.0], [-q, q, 0.0]],
            vec![[0.0, 0.0, 1.0]; 4],
            vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
            vec![0, 1, 2, 0, 2, 3],
            1000.0,
        )
        .unwrap();
        let cam = Camera::facing(1.0).unwrap();
        let g = rasterise(&mesh, &cam, 64, 64);
        // Half-width on screen: q / tan(15°) of the half image = 0.1 / 0.26795 · 32 = 11.94 px around the centre.
        let half = 0.1 / (15f32).to_radians().tan() * 32.0;
        let expect = (0..64u32).filter(|&x| ((x as f32 + 0.5) - 32.0).abs() < half).count().pow(2);
        assert_eq!(g.covered.iter().filter(|&&c| c).count(), expect);
        let centre = (32 * 64 + 32) as usize;
        assert_eq!(g.depth_mm[centre], 1000.0);
        assert_eq!(g.normal_view[centre], [0.0, 0.0, 1.0]);
        // uv: v = 0 at the top of the square, which is the top of the image.
        let top_left = ((32.0 - half).floor() as u32 * 64 + (32.0 - half).floor() as u32) as usize;
        assert!(g.uv[top_left][0] < 0.05 && g.uv[top_left][1] < 0.05, "{:?}", g.uv[top_left]);
        let behind = Camera { eye: [0.0, 0.0, -1.0], ..cam };
        assert!(rasterise(&mesh, &behind, 64, 64).covered.iter().all(|&c| !c));
    }
}
