//! Wavefront OBJ meshes (parsed by `tobj`, triangulated, one index per vertex). Every object of the file is kept;
//! materials are ignored (the skin shaders take their inputs from the bake). OBJ puts v = 0 at the bottom of the
//! texture, so v is flipped to this crate's top-row convention. OBJ has no unit: the caller says what one unit
//! is (`mm_per_unit`).

use super::Mesh;
use crate::error::InvalidInput;

/// Parses an OBJ file's bytes; `what` names the file in errors.
pub fn parse_obj(what: &str, bytes: &[u8], mm_per_unit: f32) -> Result<Mesh, InvalidInput> {
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let (models, _materials) =
        tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| InvalidInput::new(what, format!("is not a valid OBJ file: {e}")))?;
    let (mut pos, mut nrm, mut uvs, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for m in &models {
        let mesh = &m.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        if mesh.normals.is_empty() {
            return Err(InvalidInput::new(
                what,
                format!("object {:?} has no vertex normals (vn, glTF's NORMAL); the skin shaders need them", m.name),
            ));
        }
        if mesh.texcoords.is_empty() {
            return Err(InvalidInput::new(
                what,
                format!(
                    "object {:?} has no texture coordinates (vt, glTF's TEXCOORD_0); texture-space diffusion needs a UV unwrap",
                    m.name
                ),
            ));
        }
        let base = pos.len() as u32;
        pos.extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        nrm.extend(mesh.normals.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        uvs.extend(mesh.texcoords.chunks_exact(2).map(|t| [t[0], 1.0 - t[1]]));
        idx.extend(mesh.indices.iter().map(|&i| base + i));
        if pos.len() > super::MAX_VERTICES || idx.len() / 3 > super::MAX_TRIANGLES {
            break; // Mesh::new reports the sizes
        }
    }
    Mesh::new(what, pos, nrm, uvs, idx, mm_per_unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
                        f 1/1/1 2/2/1 3/3/1 4/4/1\n";

    #[test]
    fn a_quad_is_triangulated_with_v_flipped() {
        let m = parse_obj("quad.obj", QUAD.as_bytes(), 10.0).unwrap();
        assert_eq!(m.triangle_count(), 2);
        assert!((m.area() - 1.0).abs() < 1e-9);
        let top_right = m.positions.iter().position(|p| *p == [1.0, 1.0, 0.0]).unwrap();
        assert_eq!(m.uvs[top_right], [1.0, 0.0]);
    }

    #[test]
    fn missing_attributes_and_garbage_are_named() {
        let no_vt = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";
        assert!(parse_obj("a.obj", no_vt.as_bytes(), 1.0).unwrap_err().to_string().contains("vt"));
        let no_vn = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n";
        assert!(parse_obj("a.obj", no_vn.as_bytes(), 1.0).unwrap_err().to_string().contains("vn"));
        let e = parse_obj("a.obj", b"v 0 0 0\n", 1.0).unwrap_err();
        assert!(e.to_string().contains("no triangles"), "{e}");
        let e = parse_obj("a.obj", b"f 1/1/1 7/1/1 2/1/1\n", 1.0).unwrap_err();
        assert_eq!(e.param, "a.obj");
        let degenerate = "v 0 0 0\nv 1 0 0\nv 2 0 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n";
        assert!(parse_obj("a.obj", degenerate.as_bytes(), 1.0).unwrap_err().to_string().contains("degenerate"));
    }
}
