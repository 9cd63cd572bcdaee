//! Triangle meshes for the skin renderer of TAP 2009 (Jimenez, Sundstedt & Gutierrez, *Screen-Space Perceptual
//! Rendering of Human Skin*, §5–6: heads of 2988 triangles rendered with texture-space and screen-space diffusion)
//! and thesis ch. 3 (texture-space diffusion needs a UV unwrap: the irradiance map lives in UV space).
//!
//! - [`Mesh`]: positions, normals and UVs per vertex, indexed triangles; [`Mesh::new`] is the one validation
//!   (attributes present and of matching counts, indices in range, everything finite, normals non-zero, no
//!   degenerate triangle, sizes capped before allocating), so a renderer never sees a malformed mesh.
//! - [`head`]: the procedural default head (a displaced ellipsoid with a nose, brow and chin, and two thin ears
//!   where the screen-space halo and the transmittance of TAP §7 show), UV-unwrapped in three islands.
//! - [`obj`], [`gltf`]: Wavefront OBJ (`tobj`) and glTF 2.0 (`gltf`) parsed from bytes; the caller reads the files.
//!
//! Positions are in mesh units with [`Mesh::mm_per_unit`] saying what one unit is (glTF: metres, 1000 mm).
//! Texture coordinates follow one convention, v = 0 at the top row of the image; [`UvOrigin`] says where a file's
//! own v = 0 lies, since files do not always follow their format's convention (the three.js distribution of the
//! Lee Perry-Smith scan is a glTF whose v = 0 is the bottom row of its maps, as three.js loads them with `flipY`).

pub mod camera;
pub mod framing;
pub mod gltf;
pub mod head;
pub mod obj;
pub mod tangents;

use crate::error::InvalidInput;

/// Most triangles a mesh may have (a scanned head is 10⁵–10⁶; the TAP heads have 2988).
pub const MAX_TRIANGLES: usize = 8 << 20;
/// Most vertices a mesh may have.
pub const MAX_VERTICES: usize = 8 << 20;

/// Where v = 0 of a file's texture coordinates lies in its texture images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UvOrigin {
    /// v = 0 is the image's top row: glTF 2.0's convention (and D3D's, wgpu's, this crate's).
    TopLeft,
    /// v = 0 is the image's bottom row: OpenGL's and Wavefront OBJ's convention.
    BottomLeft,
}

impl UvOrigin {
    /// The convention a file format states: glTF top-left, OBJ bottom-left.
    pub fn of_format(gltf: bool) -> UvOrigin {
        if gltf {
            UvOrigin::TopLeft
        } else {
            UvOrigin::BottomLeft
        }
    }
}

/// An indexed triangle mesh with one normal and one UV per vertex (counter-clockwise front faces).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    /// Unit vectors (normalised by [`Mesh::new`]).
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates, v = 0 at the top row of the texture (the D3D/wgpu convention).
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    /// Millimetres per position unit.
    pub mm_per_unit: f32,
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn length(a: [f32; 3]) -> f32 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

impl Mesh {
    /// Validates and builds a mesh. `what` names the source in errors (a file name, "procedural head"). Missing
    /// attributes are named as the formats name them (`NORMAL`, `TEXCOORD_0`); a degenerate triangle (area below
    /// 1e-12 of the bounding box diagonal squared) is named by its index.
    pub fn new(
        what: &str,
        positions: Vec<[f32; 3]>,
        normals: Vec<[f32; 3]>,
        uvs: Vec<[f32; 2]>,
        indices: Vec<u32>,
        mm_per_unit: f32,
    ) -> Result<Mesh, InvalidInput> {
        let n = positions.len();
        if n == 0 || indices.is_empty() {
            return Err(InvalidInput::new(what, "has no triangles; a mesh needs at least one"));
        }
        if n > MAX_VERTICES || indices.len() / 3 > MAX_TRIANGLES {
            return Err(InvalidInput::new(
                what,
                format!(
                    "has {n} vertices and {} triangles; accepted at most {MAX_VERTICES} and {MAX_TRIANGLES}",
                    indices.len() / 3
                ),
            ));
        }
        if normals.is_empty() {
            return Err(InvalidInput::new(what, "has no vertex normals (NORMAL / vn); the skin shaders need them"));
        }
        if uvs.is_empty() {
            return Err(InvalidInput::new(
                what,
                "has no texture coordinates (TEXCOORD_0 / vt); texture-space diffusion needs a UV unwrap",
            ));
        }
        if normals.len() != n || uvs.len() != n {
            return Err(InvalidInput::new(
                what,
                format!(
                    "has {n} positions but {} normals and {} UVs; each vertex needs one of each",
                    normals.len(),
                    uvs.len()
                ),
            ));
        }
        if !indices.len().is_multiple_of(3) {
            return Err(InvalidInput::new(what, format!("has {} indices, not a multiple of 3", indices.len())));
        }
        if !(mm_per_unit.is_finite() && mm_per_unit > 0.0) {
            return Err(InvalidInput::new(
                "mesh_mm_per_unit",
                format!("must be a finite number > 0, got {mm_per_unit}"),
            ));
        }
        if let Some(i) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(InvalidInput::new(what, format!("position {i} is not finite: {:?}", positions[i])));
        }
        if let Some(i) = uvs.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(InvalidInput::new(what, format!("texture coordinate {i} is not finite: {:?}", uvs[i])));
        }
        let mut unit_normals = Vec::with_capacity(n);
        for (i, v) in normals.iter().enumerate() {
            let l = length(*v);
            if !(l.is_finite() && l > 1e-12) {
                return Err(InvalidInput::new(what, format!("normal {i} is zero or not finite: {v:?}")));
            }
            unit_normals.push([v[0] / l, v[1] / l, v[2] / l]);
        }
        if let Some(t) = indices.iter().position(|&i| i as usize >= n) {
            return Err(InvalidInput::new(
                what,
                format!("triangle {} refers to vertex {}, but there are {n}", t / 3, indices[t]),
            ));
        }
        let (lo, hi) = positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            ([lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])], [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])])
        });
        let diag2 = length(sub(hi, lo)).powi(2);
        let degenerate: Vec<usize> = indices
            .chunks_exact(3)
            .enumerate()
            .filter(|(_, t)| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
                let area = 0.5 * length(cross(sub(b, a), sub(c, a)));
                area.is_nan() || area <= 1e-12 * diag2
            })
            .map(|(i, _)| i)
            .collect();
        if let Some(&first) = degenerate.first() {
            return Err(InvalidInput::new(
                what,
                format!(
                    "has {} degenerate (zero-area) triangle(s), the first is triangle {first}; remove them before rendering",
                    degenerate.len()
                ),
            ));
        }
        Ok(Mesh { positions, normals: unit_normals, uvs, indices, mm_per_unit })
    }

    /// The mesh with its texture coordinates re-read as if its file put v = 0 at `file_origin` rather than at
    /// `parsed_as` (the convention it was parsed with): v becomes 1 − v where the two differ, nothing else changes.
    pub fn with_uv_origin(mut self, parsed_as: UvOrigin, file_origin: UvOrigin) -> Mesh {
        if parsed_as != file_origin {
            for uv in &mut self.uvs {
                uv[1] = 1.0 - uv[1];
            }
        }
        self
    }

    /// A 64-bit hash of everything the mesh holds (positions, normals and uvs bit for bit, indices, the unit): the
    /// key of the renderers' per-mesh caches (a different mesh, even by one bit, gets another key but for a
    /// 2⁻⁶⁴ collision).
    pub fn content_key(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for v in self.positions.iter().chain(&self.normals) {
            v.iter().for_each(|x| x.to_bits().hash(&mut h));
        }
        self.uvs.iter().for_each(|t| t.iter().for_each(|x| x.to_bits().hash(&mut h)));
        self.indices.hash(&mut h);
        self.mm_per_unit.to_bits().hash(&mut h);
        h.finish()
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Axis-aligned bounds (min, max) in mesh units.
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        self.positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            ([lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])], [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])])
        })
    }

    /// Total surface area in mesh units².
    pub fn area(&self) -> f64 {
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
                0.5 * length(cross(sub(b, a), sub(c, a))) as f64
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Parts = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u32>);

    fn quad() -> Parts {
        (
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0.0, 0.0, 2.0]; 4],
            vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
            vec![0, 1, 2, 0, 2, 3],
        )
    }

    #[test]
    fn a_valid_quad_has_unit_normals_and_area_one() {
        let (p, n, uv, i) = quad();
        let m = Mesh::new("quad", p, n, uv, i, 1000.0).unwrap();
        assert_eq!(m.normals[0], [0.0, 0.0, 1.0]);
        assert!((m.area() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_bottom_left_file_origin_mirrors_v_and_only_v() {
        let (p, n, uv, i) = quad();
        let m = Mesh::new("quad", p, n, uv, i, 1000.0).unwrap();
        let same = m.clone().with_uv_origin(UvOrigin::TopLeft, UvOrigin::TopLeft);
        assert_eq!(same, m);
        let flipped = m.clone().with_uv_origin(UvOrigin::TopLeft, UvOrigin::BottomLeft);
        assert_eq!(flipped.uvs, vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        assert_eq!((flipped.positions.clone(), flipped.indices.clone()), (m.positions.clone(), m.indices.clone()));
        assert_eq!(flipped.with_uv_origin(UvOrigin::BottomLeft, UvOrigin::TopLeft), m);
        assert_eq!(UvOrigin::of_format(true), UvOrigin::TopLeft);
        assert_eq!(UvOrigin::of_format(false), UvOrigin::BottomLeft);
    }

    #[test]
    fn malformed_meshes_are_refused_with_the_defect_named() {
        let msg = |f: &dyn Fn(&mut Parts)| {
            let mut q = quad();
            f(&mut q);
            let (p, n, uv, i) = q;
            Mesh::new("m", p, n, uv, i, 1.0).unwrap_err().to_string()
        };
        assert!(msg(&|q| q.1.clear()).contains("NORMAL"));
        assert!(msg(&|q| q.2.clear()).contains("TEXCOORD_0"));
        assert!(msg(&|q| q.3.clear()).contains("no triangles"));
        assert!(msg(&|q| q.3[4] = 9).contains("triangle 1 refers to vertex 9"));
        assert!(msg(&|q| q.3.push(1)).contains("multiple of 3"));
        assert!(msg(&|q| q.0[2][1] = f32::NAN).contains("position 2"));
        assert!(msg(&|q| q.1[3] = [0.0; 3]).contains("normal 3"));
        assert!(msg(&|q| q.3.extend([0, 1, 1])).contains("the first is triangle 2"));
        assert!(msg(&|q| q.2.pop().map(|_| ()).unwrap()).contains("4 positions but 4 normals and 3 UVs"));
    }
}
