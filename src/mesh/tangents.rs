//! Per-vertex tangent frames from texture-coordinate derivatives (Lengyel, "Computing Tangent Space Basis Vectors
//! for an Arbitrary Mesh", 2001; the frame tangent-space normal maps such as the wrinkle maps of thesis ch. 8 are
//! expressed in).
//!
//! Per triangle with edges `e1 = p1 − p0`, `e2 = p2 − p0` and texture-coordinate deltas `(Δu1, Δv1)`,
//! `(Δu2, Δv2)`, the surface derivatives `∂p/∂u` and `∂p/∂v` solve `e = ∂p/∂u·Δu + ∂p/∂v·Δv`:
//!
//! ```text
//! r = 1 / (Δu1·Δv2 − Δu2·Δv1)
//! T = (e1·Δv2 − e2·Δv1)·r        (∂p/∂u)
//! B = (e2·Δu1 − e1·Δu2)·r        (∂p/∂v)
//! ```
//!
//! summed over the triangles around each vertex (weighted by the triangle's size through e1, e2), then made
//! orthonormal to the vertex normal (Gram–Schmidt, `T' = normalize(T − N·(N·T))`) with the handedness
//! `w = sign((N × T')·B)`, so that the bitangent is `w·(N × T')`. With rtbake's texture convention (v grows down
//! the texture, [`super::Mesh::uvs`]) B points towards increasing v: the DirectX green convention of the wrinkle
//! maps ([`crate::facial::wrinkles`]). Triangles whose uv area is zero add nothing; a vertex with no usable
//! triangle gets an arbitrary unit tangent perpendicular to its normal and w = 1.
//!
//! **MikkTSpace** ([`mikktspace_tangents`]; Mikkelsen, *Simulation of Wrinkled Surfaces Revisited*, MSc thesis,
//! University of Copenhagen, 2008) is the frame normal maps are baked in by xNormal, Blender and Substance and the
//! one glTF 2.0 prescribes: per face corner, order-independent, with the same sign convention (the bitangent is
//! `w·(N × T)` and points along ∂p/∂v). A scanned head's normal map is only reproduced exactly in that frame, so a
//! mesh rendered with a normal map uses it; where the corners of one vertex get different frames (mirrored UVs
//! without a seam) the vertex is split. The computation is `bevy_mikktspace`'s port of the reference C code.

use super::Mesh;
use bevy_mikktspace::{Geometry, TangentSpace};

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Unit tangent `(x, y, z)` and handedness `w` (±1) per vertex of `mesh` (see the module doc).
pub fn vertex_tangents(mesh: &Mesh) -> Vec<[f32; 4]> {
    let n = mesh.positions.len();
    let (mut t_sum, mut b_sum) = (vec![[0.0f64; 3]; n], vec![[0.0f64; 3]; n]);
    for tri in mesh.indices.chunks_exact(3) {
        let [i0, i1, i2] = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
        let (e1, e2) = (sub(mesh.positions[i1], mesh.positions[i0]), sub(mesh.positions[i2], mesh.positions[i0]));
        let (uv0, uv1, uv2) = (mesh.uvs[i0], mesh.uvs[i1], mesh.uvs[i2]);
        let (du1, dv1) = ((uv1[0] - uv0[0]) as f64, (uv1[1] - uv0[1]) as f64);
        let (du2, dv2) = ((uv2[0] - uv0[0]) as f64, (uv2[1] - uv0[1]) as f64);
        let det = du1 * dv2 - du2 * dv1;
        if det.abs() < 1e-20 {
            continue;
        }
        let r = 1.0 / det;
        let t: [f64; 3] = std::array::from_fn(|k| (e1[k] as f64 * dv2 - e2[k] as f64 * dv1) * r);
        let b: [f64; 3] = std::array::from_fn(|k| (e2[k] as f64 * du1 - e1[k] as f64 * du2) * r);
        for &i in &[i0, i1, i2] {
            for k in 0..3 {
                t_sum[i][k] += t[k];
                b_sum[i][k] += b[k];
            }
        }
    }
    (0..n)
        .map(|i| {
            let nrm = mesh.normals[i];
            let t = t_sum[i].map(|v| v as f32);
            let t = sub(t, nrm.map(|c| c * dot(nrm, t)));
            let len = dot(t, t).sqrt();
            if len.is_nan() || len <= 1e-12 {
                // No uv gradient here: any unit vector perpendicular to the normal.
                let a = if nrm[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
                let t = cross(cross(nrm, a), nrm);
                let l = dot(t, t).sqrt();
                return [t[0] / l, t[1] / l, t[2] / l, 1.0];
            }
            let t = t.map(|c| c / len);
            let w = if dot(cross(nrm, t), b_sum[i].map(|v| v as f32)) < 0.0 { -1.0 } else { 1.0 };
            [t[0], t[1], t[2], w]
        })
        .collect()
}

/// The mesh's face corners as MikkTSpace sees them, and the frame it writes back per corner.
struct Corners<'a> {
    mesh: &'a Mesh,
    frames: Vec<Option<[f32; 4]>>,
}

impl Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.indices[face * 3 + vert] as usize]
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.mesh.indices[face * 3 + vert] as usize]
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.mesh.uvs[self.mesh.indices[face * 3 + vert] as usize]
    }
    fn set_tangent(&mut self, frame: Option<TangentSpace>, face: usize, vert: usize) {
        self.frames[face * 3 + vert] = frame.map(|t| t.tangent_encoded());
    }
}

/// MikkTSpace tangents (see the module doc): the mesh, with a vertex split wherever its corners got different
/// frames, and one unit tangent `(x, y, z)` with handedness `w` (±1) per vertex of that mesh. Corners MikkTSpace
/// leaves without a frame (no usable neighbour) take [`vertex_tangents`]' frame of their vertex.
pub fn mikktspace_tangents(mesh: &Mesh) -> (Mesh, Vec<[f32; 4]>) {
    let mut corners = Corners { mesh, frames: vec![None; mesh.indices.len()] };
    let fallback = vertex_tangents(mesh);
    // The port reports an error only for meshes it cannot index (none of ours: every face is a triangle); the
    // fallback frame then stands for every corner.
    let _ = bevy_mikktspace::generate_tangents(&mut corners);
    let mut out = mesh.clone();
    let mut tangents: Vec<Option<[f32; 4]>> = vec![None; mesh.positions.len()];
    for (k, idx) in out.indices.iter_mut().enumerate() {
        let v = *idx as usize;
        let frame = corners.frames[k].unwrap_or(fallback[v]);
        match tangents[v] {
            None => tangents[v] = Some(frame),
            Some(t) if t == frame => {}
            Some(_) => {
                // Another frame at the same vertex: reuse a split copy with this frame, or make one.
                let copy = (mesh.positions.len()..out.positions.len()).find(|&c| {
                    tangents[c] == Some(frame)
                        && out.positions[c] == mesh.positions[v]
                        && out.normals[c] == mesh.normals[v]
                        && out.uvs[c] == mesh.uvs[v]
                });
                *idx = match copy {
                    Some(c) => c as u32,
                    None => {
                        out.positions.push(mesh.positions[v]);
                        out.normals.push(mesh.normals[v]);
                        out.uvs.push(mesh.uvs[v]);
                        tangents.push(Some(frame));
                        (out.positions.len() - 1) as u32
                    }
                };
            }
        }
    }
    let tangents =
        tangents.iter().enumerate().map(|(v, t)| t.unwrap_or_else(|| fallback[v.min(fallback.len() - 1)])).collect();
    (out, tangents)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(uvs: Vec<[f32; 2]>) -> Mesh {
        let q = 0.1f32;
        Mesh::new(
            "square",
            vec![[-q, -q, 0.0], [q, -q, 0.0], [q, q, 0.0], [-q, q, 0.0]],
            vec![[0.0, 0.0, 1.0]; 4],
            uvs,
            vec![0, 1, 2, 0, 2, 3],
            1000.0,
        )
        .unwrap()
    }

    /// u along +x and v down the texture (towards −y, as images are stored): T = +x, B = ∂p/∂v = −y = −(N × T),
    /// so w = −1; mirroring v flips only w; rotating the uv layout by 90° rotates T.
    #[test]
    fn a_square_gets_its_uv_axes() {
        let t = vertex_tangents(&square(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]));
        for v in &t {
            assert!((v[0] - 1.0).abs() < 1e-6 && v[1].abs() < 1e-6 && v[2].abs() < 1e-6, "{v:?}");
            assert_eq!(v[3], -1.0);
        }
        let t = vertex_tangents(&square(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]));
        assert!(t.iter().all(|v| (v[0] - 1.0).abs() < 1e-6 && v[3] == 1.0), "{t:?}");
        // u along +y: T = +y.
        let t = vertex_tangents(&square(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]));
        assert!(t.iter().all(|v| (v[1] - 1.0).abs() < 1e-6), "{t:?}");
    }

    /// On the procedural head every tangent is unit, perpendicular to its normal, and agrees in direction with
    /// ∂p/∂u of its triangles.
    #[test]
    fn the_head_has_unit_tangents_perpendicular_to_its_normals() {
        let m = crate::mesh::head::default_head();
        let t = vertex_tangents(&m);
        assert_eq!(t.len(), m.positions.len());
        for (v, n) in t.iter().zip(&m.normals) {
            let tv = [v[0], v[1], v[2]];
            assert!((dot(tv, tv) - 1.0).abs() < 1e-5, "{v:?}");
            assert!(dot(tv, *n).abs() < 1e-5, "{v:?} vs {n:?}");
            assert!(v[3] == 1.0 || v[3] == -1.0);
        }
        // The first triangle: its own ∂p/∂u points the same way as each vertex's tangent.
        let tri = &m.indices[..3];
        let p = |i: u32| m.positions[i as usize];
        let uv = |i: u32| m.uvs[i as usize];
        let (e1, e2) = (sub(p(tri[1]), p(tri[0])), sub(p(tri[2]), p(tri[0])));
        let (d1, d2) = (
            sub([uv(tri[1])[0], uv(tri[1])[1], 0.0], [uv(tri[0])[0], uv(tri[0])[1], 0.0]),
            sub([uv(tri[2])[0], uv(tri[2])[1], 0.0], [uv(tri[0])[0], uv(tri[0])[1], 0.0]),
        );
        let r = 1.0 / (d1[0] * d2[1] - d2[0] * d1[1]);
        let dpdu: [f32; 3] = std::array::from_fn(|k| (e1[k] * d2[1] - e2[k] * d1[1]) * r);
        for &i in tri {
            let v = t[i as usize];
            assert!(dot([v[0], v[1], v[2]], dpdu) > 0.0);
        }
    }

    /// MikkTSpace gives the flat square the same frame as the derivative construction (T = +x, bitangent along
    /// ∂p/∂v, w = −1 for v down the texture), keeps every vertex, and on the head agrees with it closely.
    #[test]
    fn mikktspace_agrees_with_the_uv_derivatives() {
        let sq = square(vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
        let (m, t) = mikktspace_tangents(&sq);
        assert_eq!(m.positions.len(), 4);
        for v in &t {
            assert!((v[0] - 1.0).abs() < 1e-6 && v[1].abs() < 1e-6 && v[2].abs() < 1e-6 && v[3] == -1.0, "{v:?}");
        }
        let head = crate::mesh::head::default_head();
        let (m, t) = mikktspace_tangents(&head);
        assert_eq!(t.len(), m.positions.len());
        assert_eq!(m.indices.len(), head.indices.len());
        let lengyel = vertex_tangents(&m);
        let mut close = 0;
        for ((v, n), l) in t.iter().zip(&m.normals).zip(&lengyel) {
            let tv = [v[0], v[1], v[2]];
            assert!((dot(tv, tv) - 1.0).abs() < 1e-4, "{v:?}");
            assert!(dot(tv, *n).abs() < 1e-3, "{v:?} vs {n:?}");
            if dot(tv, [l[0], l[1], l[2]]) > 0.95 && v[3] == l[3] {
                close += 1;
            }
        }
        assert!(close as f64 > 0.95 * t.len() as f64, "{close} of {} within 18°", t.len());
    }

    /// Two triangles that share an edge but mirror their UVs (no seam): the shared vertices get two frames of
    /// opposite handedness, so they are split and every corner keeps its own frame.
    #[test]
    fn mirrored_uvs_split_the_shared_vertices() {
        let m = Mesh::new(
            "mirror",
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
            vec![[0.0, 0.0, 1.0]; 4],
            vec![[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 1.0]],
            vec![0, 1, 2, 0, 2, 3],
            1000.0,
        )
        .unwrap();
        let (out, t) = mikktspace_tangents(&m);
        assert_eq!(out.positions.len(), 6, "vertices 0 and 2 split");
        let w: Vec<f32> = out.indices.iter().map(|&i| t[i as usize][3]).collect();
        assert!(w[..3].iter().all(|&x| x == w[0]) && w[3..].iter().all(|&x| x == w[3]) && w[0] != w[3], "{w:?}");
    }
}
