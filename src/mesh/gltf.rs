//! glTF 2.0 meshes (Khronos glTF 2.0 specification; parsed by the `gltf` crate): every triangle primitive of the
//! default scene (or the first scene), with the node transforms applied (normals by the inverse transpose,
//! winding flipped under a mirroring transform). Attributes read: POSITION, NORMAL, TEXCOORD_0 and the indices;
//! glTF's unit is the metre and its v = 0 is the texture's top row, as in this crate.
//!
//! Buffers come from the GLB binary chunk, from `data:` URIs (base64), or — for a `.gltf` beside its `.bin` — from
//! the caller's `external` function, so this module reads no file itself.

use super::Mesh;
use crate::error::InvalidInput;
use base64::Engine;
use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

/// Parses a `.gltf` or `.glb` file's bytes; `what` names the file in errors; `external(uri)` supplies the bytes of
/// a buffer stored in another file.
pub fn parse_gltf(
    what: &str,
    bytes: &[u8],
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Mesh, InvalidInput> {
    let bad = |m: String| InvalidInput::new(what, m);
    let g = gltf::Gltf::from_slice(bytes).map_err(|e| bad(format!("is not a valid glTF 2.0 file: {e}")))?;
    let buffers = load_buffers(what, &g, external)?;
    let scene = g
        .document
        .default_scene()
        .or_else(|| g.document.scenes().next())
        .ok_or_else(|| bad("has no scene".to_string()))?;
    let (mut pos, mut nrm, mut uvs, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut stack: Vec<(gltf::Node, Matrix4<f32>)> = scene.nodes().map(|n| (n, Matrix4::identity())).collect();
    let mut visited = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1 << 20 {
            return Err(bad("has more than 2^20 node instances (a cycle or a huge scene)".to_string()));
        }
        let m = parent * Matrix4::from(node.transform().matrix());
        stack.extend(node.children().map(|c| (c, m)));
        let Some(mesh) = node.mesh() else { continue };
        let upper: Matrix3<f32> = m.fixed_view::<3, 3>(0, 0).into();
        let normal_m = upper
            .try_inverse()
            .map(|i| i.transpose())
            .ok_or_else(|| bad(format!("node {} has a singular transform", node.index())))?;
        let mirrored = upper.determinant() < 0.0;
        for p in mesh.primitives() {
            let name = format!("mesh {} primitive {}", mesh.index(), p.index());
            if p.mode() != gltf::mesh::Mode::Triangles {
                return Err(bad(format!("{name} has mode {:?}; only triangles are rendered", p.mode())));
            }
            let count = p.get(&gltf::Semantic::Positions).map_or(0, |a| a.count());
            if pos.len() + count > super::MAX_VERTICES {
                return Err(bad(format!("has more than {} vertices", super::MAX_VERTICES)));
            }
            let reader = p.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let positions: Vec<[f32; 3]> =
                reader.read_positions().ok_or_else(|| bad(format!("{name} has no POSITION attribute")))?.collect();
            let normals: Vec<[f32; 3]> = reader
                .read_normals()
                .ok_or_else(|| bad(format!("{name} has no NORMAL attribute; the skin shaders need vertex normals")))?
                .collect();
            let tex: Vec<[f32; 2]> = reader
                .read_tex_coords(0)
                .ok_or_else(|| {
                    bad(format!("{name} has no TEXCOORD_0 attribute; texture-space diffusion needs a UV unwrap"))
                })?
                .into_f32()
                .collect();
            if normals.len() != positions.len() || tex.len() != positions.len() {
                return Err(bad(format!(
                    "{name} has {} positions, {} normals and {} texture coordinates",
                    positions.len(),
                    normals.len(),
                    tex.len()
                )));
            }
            let local: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            if !local.len().is_multiple_of(3) || idx.len() / 3 + local.len() / 3 > super::MAX_TRIANGLES {
                return Err(bad(format!(
                    "{name} has {} indices (a multiple of 3 up to the triangle cap needed)",
                    local.len()
                )));
            }
            if let Some(&i) = local.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(bad(format!("{name} refers to vertex {i}, but it has {}", positions.len())));
            }
            let base = pos.len() as u32;
            pos.extend(positions.iter().map(|p| {
                let v = m * Vector4::new(p[0], p[1], p[2], 1.0);
                [v.x, v.y, v.z]
            }));
            nrm.extend(normals.iter().map(|n| {
                let v = normal_m * Vector3::new(n[0], n[1], n[2]);
                [v.x, v.y, v.z]
            }));
            uvs.extend(tex);
            for t in local.chunks_exact(3) {
                let t = if mirrored { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] };
                idx.extend(t.map(|i| base + i));
            }
        }
    }
    Mesh::new(what, pos, nrm, uvs, idx, 1000.0)
}

/// The bytes of every buffer of `g`: the GLB binary chunk, `data:` URIs, or `external(uri)`.
fn load_buffers(
    what: &str,
    g: &gltf::Gltf,
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<Vec<Vec<u8>>, InvalidInput> {
    let bad = |m: String| InvalidInput::new(what, m);
    let mut buffers = Vec::new();
    for b in g.document.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => g
                .blob
                .clone()
                .ok_or_else(|| bad(format!("buffer {} refers to a GLB binary chunk it lacks", b.index())))?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                decode_data_uri(uri).map_err(|e| bad(format!("buffer {}: {e}", b.index())))?
            }
            gltf::buffer::Source::Uri(uri) => {
                external(uri).map_err(|e| bad(format!("buffer {} ({uri}): {e}", b.index())))?
            }
        };
        if data.len() < b.length() {
            return Err(bad(format!("buffer {} holds {} bytes, declares {}", b.index(), data.len(), b.length())));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The payload of a base64 `data:` URI.
fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let payload = uri.split_once(";base64,").map(|(_, p)| p).ok_or("a data URI that is not base64")?;
    base64::engine::general_purpose::STANDARD.decode(payload).map_err(|e| format!("bad base64: {e}"))
}

/// An image a glTF material refers to, still encoded (PNG or JPEG as the file stores it).
#[derive(Clone, Debug, PartialEq)]
pub struct EncodedImage {
    /// The MIME type the file declares, if any (`image/png`, `image/jpeg`).
    pub mime_type: Option<String>,
    pub bytes: Vec<u8>,
    /// Where it came from, for messages: `image 0 (buffer view 3)` or its URI.
    pub origin: String,
}

/// The maps of a glTF material that the skin renderer uses (glTF 2.0 §3.9: `pbrMetallicRoughness.
/// baseColorTexture`, sRGB; `normalTexture`, linear, tangent space in MikkTSpace with green up).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialImages {
    pub base_color: Option<EncodedImage>,
    pub normal: Option<EncodedImage>,
}

/// The base-colour and normal images of the first material of the default scene's meshes that has either (the
/// Lee Perry-Smith file of the three.js examples has none: its maps are separate files). Reads no file itself:
/// `external(uri)` supplies images stored beside a `.gltf`.
pub fn material_images(
    what: &str,
    bytes: &[u8],
    external: &dyn Fn(&str) -> Result<Vec<u8>, String>,
) -> Result<MaterialImages, InvalidInput> {
    let bad = |m: String| InvalidInput::new(what, m);
    let g = gltf::Gltf::from_slice(bytes).map_err(|e| bad(format!("is not a valid glTF 2.0 file: {e}")))?;
    let buffers = load_buffers(what, &g, external)?;
    let image = |tex: gltf::Texture| -> Result<EncodedImage, InvalidInput> {
        let img = tex.source();
        match img.source() {
            gltf::image::Source::View { view, mime_type } => {
                let buf = &buffers[view.buffer().index()];
                let range = view.offset()..view.offset() + view.length();
                let bytes = buf
                    .get(range)
                    .ok_or_else(|| bad(format!("image {} lies outside its buffer", img.index())))?
                    .to_vec();
                Ok(EncodedImage {
                    mime_type: Some(mime_type.to_string()),
                    bytes,
                    origin: format!("image {} (buffer view {})", img.index(), view.index()),
                })
            }
            gltf::image::Source::Uri { uri, mime_type } => {
                let bytes =
                    if uri.starts_with("data:") { decode_data_uri(uri) } else { external(uri) }.map_err(|e| {
                        bad(format!("image {} ({}): {e}", img.index(), uri.chars().take(64).collect::<String>()))
                    })?;
                Ok(EncodedImage {
                    mime_type: mime_type.map(str::to_string),
                    bytes,
                    origin: if uri.starts_with("data:") {
                        format!("image {} (data URI)", img.index())
                    } else {
                        uri.to_string()
                    },
                })
            }
        }
    };
    for mesh in g.document.meshes() {
        for p in mesh.primitives() {
            let m = p.material();
            let base = m.pbr_metallic_roughness().base_color_texture().map(|t| t.texture());
            let normal = m.normal_texture().map(|t| t.texture());
            if base.is_some() || normal.is_some() {
                return Ok(MaterialImages {
                    base_color: base.map(image).transpose()?,
                    normal: normal.map(image).transpose()?,
                });
            }
        }
    }
    Ok(MaterialImages::default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// A one-triangle glTF with its buffer as a data URI; `attrs` chooses the attributes written.
    fn triangle_gltf(with_normals: bool, with_uvs: bool, translation: [f32; 3], scale: [f32; 3]) -> Vec<u8> {
        let mut bin = Vec::new();
        for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            v.iter().for_each(|c| bin.extend(c.to_le_bytes()));
        }
        for _ in 0..3 {
            [0.0f32, 0.0, 1.0].iter().for_each(|c| bin.extend(c.to_le_bytes()));
        }
        for t in [[0.0f32, 1.0], [1.0, 1.0], [0.0, 0.0]] {
            t.iter().for_each(|c| bin.extend(c.to_le_bytes()));
        }
        let mut attributes = serde_json::Map::new();
        attributes.insert("POSITION".into(), json!(0));
        if with_normals {
            attributes.insert("NORMAL".into(), json!(1));
        }
        if with_uvs {
            attributes.insert("TEXCOORD_0".into(), json!(2));
        }
        let doc = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "translation": translation, "scale": scale}],
            "meshes": [{"primitives": [{"attributes": attributes}]}],
            "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}",
                base64::engine::general_purpose::STANDARD.encode(&bin))}],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": 36},
                {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                {"buffer": 0, "byteOffset": 72, "byteLength": 24}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}
            ]
        });
        serde_json::to_vec(&doc).unwrap()
    }

    fn no_files(uri: &str) -> Result<Vec<u8>, String> {
        Err(format!("{uri} not available"))
    }

    #[test]
    fn a_triangle_with_a_node_transform() {
        let m = parse_gltf("t.gltf", &triangle_gltf(true, true, [0.0, 0.0, 2.0], [2.0, 2.0, 2.0]), &no_files).unwrap();
        assert_eq!(m.positions[1], [2.0, 0.0, 2.0]);
        assert!((m.area() - 2.0).abs() < 1e-6);
        assert_eq!(m.normals[0], [0.0, 0.0, 1.0]);
        assert_eq!(m.mm_per_unit, 1000.0);
        // A mirroring scale flips x, the normal stays +z and the winding is reversed so the face stays front.
        let m = parse_gltf("t.gltf", &triangle_gltf(true, true, [0.0; 3], [-1.0, 1.0, 1.0]), &no_files).unwrap();
        assert_eq!(m.indices, vec![0, 2, 1]);
        assert_eq!(m.normals[0], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn missing_attributes_and_garbage_are_named() {
        let e = parse_gltf("t.gltf", &triangle_gltf(false, true, [0.0; 3], [1.0; 3]), &no_files).unwrap_err();
        assert!(e.to_string().contains("NORMAL"), "{e}");
        let e = parse_gltf("t.gltf", &triangle_gltf(true, false, [0.0; 3], [1.0; 3]), &no_files).unwrap_err();
        assert!(e.to_string().contains("TEXCOORD_0"), "{e}");
        let e = parse_gltf("t.gltf", b"{\"asset\": 3}", &no_files).unwrap_err();
        assert!(e.to_string().contains("not a valid glTF"), "{e}");
        let e = parse_gltf("t.gltf", &triangle_gltf(true, true, [0.0; 3], [1.0, 0.0, 1.0]), &no_files).unwrap_err();
        assert!(e.to_string().contains("singular"), "{e}");
    }

    #[test]
    fn material_images_come_from_data_uris_and_outside_files() {
        let mut doc: serde_json::Value =
            serde_json::from_slice(&triangle_gltf(true, true, [0.0; 3], [1.0; 3])).unwrap();
        let b64 = base64::engine::general_purpose::STANDARD.encode(b"PNGBYTES");
        doc["meshes"][0]["primitives"][0]["material"] = json!(0);
        doc["materials"] =
            json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 1}}]);
        doc["textures"] = json!([{"source": 0}, {"source": 1}]);
        doc["images"] = json!([
            {"uri": format!("data:image/png;base64,{b64}"), "mimeType": "image/png"},
            {"uri": "normal.jpg"}
        ]);
        let bytes = serde_json::to_vec(&doc).unwrap();
        let files = |uri: &str| if uri == "normal.jpg" { Ok(b"JPEG".to_vec()) } else { Err(format!("{uri} missing")) };
        let m = material_images("t.gltf", &bytes, &files).unwrap();
        assert_eq!(m.base_color.as_ref().unwrap().bytes, b"PNGBYTES");
        assert_eq!(m.base_color.unwrap().mime_type.as_deref(), Some("image/png"));
        let n = m.normal.unwrap();
        assert_eq!((n.bytes.as_slice(), n.origin.as_str()), (&b"JPEG"[..], "normal.jpg"));
        // A missing outside image is named; a material-less file has no maps.
        let e = material_images("t.gltf", &bytes, &no_files).unwrap_err();
        assert!(e.to_string().contains("normal.jpg"), "{e}");
        let plain = triangle_gltf(true, true, [0.0; 3], [1.0; 3]);
        assert_eq!(material_images("t.gltf", &plain, &no_files).unwrap(), MaterialImages::default());
    }
}
