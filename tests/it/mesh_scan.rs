//! The Lee Perry-Smith scan (Infinite-Realities, CC BY 3.0; the head of the seeds' demos, as distributed with the
//! three.js examples) read the way `run skin` reads it: glTF mesh, framed from its arbitrary units, MikkTSpace
//! tangents, and its two JPEG maps decoded and validated. SKIPPED where `../shared/reference/heads` is absent.

use crate::support::reference_file;
use rtbake::facial::wrinkles::GreenConvention;
use rtbake::image_buf::ImageU8;
use rtbake::mesh::framing::{frame_in_metres, Bounds, MeshUnits, TapDistance};
use rtbake::mesh::gltf::{material_images, parse_gltf};
use rtbake::mesh::tangents::mikktspace_tangents;
use rtbake::shading::material_maps::{albedo_linear, normals_unit};

const WHAT: &str = "the Lee Perry-Smith head scan (reference/heads/lee-perry-smith)";

fn rgb8(path: &std::path::Path) -> ImageU8 {
    let img = image::open(path).unwrap().to_rgb8();
    ImageU8::from_vec(img.width(), img.height(), 3, img.into_raw())
}

fn no_files(uri: &str) -> Result<Vec<u8>, String> {
    Err(format!("{uri}: no outside files"))
}

#[test]
fn the_scan_is_framed_as_a_head_with_mikktspace_tangents() {
    let Some(glb) = reference_file("heads/lee-perry-smith/LeePerrySmith.glb", WHAT) else { return };
    let bytes = std::fs::read(&glb).unwrap();
    let mesh = parse_gltf("LeePerrySmith.glb", &bytes, &no_files).unwrap();
    // As its README states: 9,279 vertices, 17,684 triangles, no images inside.
    assert_eq!((mesh.positions.len(), mesh.triangle_count()), (9279, 17684));
    assert_eq!(material_images("LeePerrySmith.glb", &bytes, &no_files).unwrap().base_color, None);
    // Its units are not metres: about 8 units tall. Read as glTF metres it would be an 8 m head.
    let raw = Bounds::of(&mesh).size();
    assert!(raw[1] > 5.0 && raw[1] < 12.0, "{raw:?}");
    let framed = frame_in_metres(&mesh, MeshUnits::parse("--mesh-units", "auto").unwrap(), "--mesh-units").unwrap();
    let b = Bounds::of(&framed);
    assert!((b.size()[1] - 0.230).abs() < 1e-5, "{:?}", b.size());
    assert!(b.centre().iter().all(|c| c.abs() < 1e-5), "{:?}", b.centre());
    // Width and depth keep the scan's proportions.
    assert!((b.size()[0] / b.size()[1] - raw[0] / raw[1]).abs() < 1e-4);
    // TAP's near camera for this head: 50/27 of its height.
    assert!((TapDistance::Near.camera_distance_m(b.size()[1]) - 0.4259).abs() < 1e-3);
    let (split, t) = mikktspace_tangents(&framed);
    assert_eq!(split.indices.len(), framed.indices.len());
    assert!(split.positions.len() >= framed.positions.len());
    for (v, n) in t.iter().zip(&split.normals) {
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-3, "{v:?}");
        assert!((v[0] * n[0] + v[1] * n[1] + v[2] * n[2]).abs() < 2e-3, "{v:?} vs {n:?}");
        assert!(v[3] == 1.0 || v[3] == -1.0);
    }
}

#[test]
fn the_scans_maps_decode_and_a_colour_picture_is_no_normal_map() {
    let Some(color) = reference_file("heads/lee-perry-smith/color.jpg", WHAT) else { return };
    let Some(normal) = reference_file("heads/lee-perry-smith/normal.jpg", WHAT) else { return };
    let albedo = albedo_linear("--albedo", &rgb8(&color)).unwrap();
    assert_eq!((albedo.width, albedo.height, albedo.channels), (1024, 1024, 3));
    // Skin: red above green above blue on average (linear).
    let mean = |c: usize| albedo.data.iter().skip(c).step_by(3).map(|&v| v as f64).sum::<f64>() / (1024.0 * 1024.0);
    let (r, g, bl) = (mean(0), mean(1), mean(2));
    assert!(r > g && g > bl && r < 1.0 && bl > 0.0, "{r} {g} {bl}");
    let (n, stats) = normals_unit("--normal-map", &rgb8(&normal), GreenConvention::OpenGl).unwrap();
    assert_eq!((n.width, n.height), (1024, 1024));
    assert!(stats.mean_z > 0.8 && stats.non_unit_share < 0.02, "{stats:?}");
    let e = normals_unit("--normal-map", &rgb8(&color), GreenConvention::OpenGl).unwrap_err();
    assert_eq!(e.param, "--normal-map");
    assert!(e.message.contains("is not a tangent-space normal map"), "{e}");
}
