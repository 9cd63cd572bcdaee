//! The Lee Perry-Smith scan (Infinite-Realities, CC BY 3.0; the head of the seeds' demos, as distributed with the
//! three.js examples) read the way `run skin` reads it: glTF mesh, framed from its arbitrary units, MikkTSpace
//! tangents, and its two JPEG maps decoded and validated. SKIPPED where `../shared/reference/heads` is absent.

use crate::support::reference_file;
use rtbake::facial::wrinkles::GreenConvention;
use rtbake::image_buf::ImageU8;
use rtbake::mesh::framing::{frame_in_metres, head_height_units, Bounds, MeshUnits, TapDistance};
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
    // A bust: crown to chin about 4.5 of its 7.9 units.
    let head = head_height_units(&mesh);
    assert!(head > 4.3 && head < 4.9, "{head}");
    let framed = frame_in_metres(&mesh, MeshUnits::parse("--mesh-units", "auto").unwrap(), "--mesh-units").unwrap();
    let b = Bounds::of(&framed);
    assert!((head_height_units(&framed) - 0.230).abs() < 1e-5, "{:?}", b.size());
    // The head's middle at the origin: x and z centred, the crown 115 mm above it.
    assert!(b.centre()[0].abs() < 1e-5 && b.centre()[2].abs() < 1e-5, "{:?}", b.centre());
    assert!((b.max[1] - 0.115).abs() < 1e-5, "{:?}", b.max);
    // Width and depth keep the scan's proportions.
    assert!((b.size()[0] / b.size()[1] - raw[0] / raw[1]).abs() < 1e-4);
    // TAP's near camera for this head: 50/27 of its head's height.
    assert!((TapDistance::Near.camera_distance_m(0.230) - 0.4259).abs() < 1e-3);
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
    let (n, stats) = normals_unit("normal_map", &rgb8(&normal), GreenConvention::OpenGl).unwrap();
    assert_eq!((n.width, n.height), (1024, 1024));
    assert!(stats.mean_z > 0.8 && stats.non_unit_share < 0.02, "{stats:?}");
    let e = normals_unit("normal_map", &rgb8(&color), GreenConvention::OpenGl).unwrap_err();
    assert_eq!(e.param, "normal_map");
    assert!(e.message.contains("is not a tangent-space normal map"), "{e}");
}

/// The scan's texture coordinates put v = 0 at the bottom row of its maps (three.js, whose copy this is, loads
/// them with `flipY`), not at the top as glTF states: read as glTF, the crown samples the neck's rows of color.jpg
/// and the lips (its reddest texels) land on the chin; with the bottom-left origin (`--uv-origin bottom-left`) the
/// crown samples the scalp's top rows and the lips lie a mouth's distance below the nose tip.
#[test]
fn the_scans_texture_coordinates_have_their_origin_at_the_bottom_left() {
    use rtbake::mesh::UvOrigin;
    let Some(glb) = reference_file("heads/lee-perry-smith/LeePerrySmith.glb", WHAT) else { return };
    let Some(color) = reference_file("heads/lee-perry-smith/color.jpg", WHAT) else { return };
    let bytes = std::fs::read(&glb).unwrap();
    let parsed = parse_gltf("LeePerrySmith.glb", &bytes, &no_files).unwrap();
    let auto = MeshUnits::parse("--mesh-units", "auto").unwrap();
    let as_gltf = frame_in_metres(&parsed, auto, "--mesh-units").unwrap();
    let fixed = as_gltf.clone().with_uv_origin(UvOrigin::TopLeft, UvOrigin::BottomLeft);
    let top = Bounds::of(&as_gltf).max[1];
    let crown_v = |m: &rtbake::mesh::Mesh| {
        let v: Vec<f32> =
            m.positions.iter().zip(&m.uvs).filter(|(p, _)| p[1] > top - 0.02).map(|(_, t)| t[1]).collect();
        v.iter().sum::<f32>() / v.len() as f32
    };
    assert!(crown_v(&as_gltf) > 0.8, "{}", crown_v(&as_gltf));
    assert!(crown_v(&fixed) < 0.2, "{}", crown_v(&fixed));
    // The lips: the 1 % of the albedo's middle third (the face; the corners hold dark red discs) with the highest
    // linear red-to-green ratio, their mean uv.
    let albedo = albedo_linear("--albedo", &rgb8(&color)).unwrap();
    let w = albedo.width as usize;
    let middle = |i: usize| (w / 3..2 * w / 3).contains(&(i % w)) && (w / 3..2 * w / 3).contains(&(i / w));
    let mut red: Vec<(f32, usize)> = albedo
        .data
        .chunks_exact(3)
        .enumerate()
        .filter(|(i, _)| middle(*i))
        .map(|(i, c)| (c[0] / (c[1] + 1e-3), i))
        .collect();
    red.sort_by(|a, b| b.0.total_cmp(&a.0));
    let lips = &red[..red.len() / 100];
    let mean_uv = lips.iter().fold([0.0f32; 2], |a, &(_, i)| {
        let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
        [a[0] + x / w as f32 / lips.len() as f32, a[1] + y / w as f32 / lips.len() as f32]
    });
    // Mesh points there: the vertices within 0.01 in uv of the lips' mean, in front (the face looks +z).
    let nose = as_gltf.positions.iter().copied().max_by(|a, b| a[2].total_cmp(&b[2])).unwrap();
    let lips_y = |m: &rtbake::mesh::Mesh| {
        let near: Vec<f32> = m
            .positions
            .iter()
            .zip(&m.uvs)
            .filter(|(p, t)| p[2] > nose[2] - 0.05 && (t[0] - mean_uv[0]).hypot(t[1] - mean_uv[1]) < 0.01)
            .map(|(p, _)| p[1])
            .collect();
        assert!(!near.is_empty(), "no vertex at the lips' uv {mean_uv:?}");
        near.iter().sum::<f32>() / near.len() as f32
    };
    let (wrong, right) = (nose[1] - lips_y(&as_gltf), nose[1] - lips_y(&fixed));
    // A head 230 mm tall: the mouth 15-45 mm below the nose tip (the scan: 34 mm; read as glTF, 58 mm).
    assert!(right > 0.015 && right < 0.045, "the lips {right} m below the nose tip");
    assert!(wrong > 0.05, "read as glTF, the lips {wrong} m below the nose tip");
}

/// Share of pixels of an RGBA frame that differ from the background (the top-left pixel).
fn coverage(path: &std::path::Path) -> (f64, Vec<u8>) {
    let img = image::open(path).unwrap().to_rgba8();
    let bg = img.get_pixel(0, 0).0;
    let n = img.pixels().filter(|p| p.0 != bg).count();
    (n as f64 / (img.width() * img.height()) as f64, img.into_raw())
}

fn run_skin(args: &[&str], out: &std::path::Path) -> serde_json::Value {
    let mut a = vec!["--json", "run", "skin", "--cpu", "--shader", "none", "--bloom", "off", "--width", "160"];
    a.extend_from_slice(&["--height", "120", "--output", out.to_str().unwrap()]);
    a.extend_from_slice(args);
    let o = crate::support::rtbake(&a);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The scan, read as glTF metres about its own origin, is an 8 m bust that fills the frame; framed with
/// `--mesh-units auto` it is a 230 mm head at TAP's distances, smaller at far than at near, never touching the
/// frame at near; `--json` reports the camera.
#[test]
fn run_skin_frames_the_scan_as_a_head_at_taps_distances() {
    let Some(glb) = reference_file("heads/lee-perry-smith/LeePerrySmith.glb", WHAT) else { return };
    let glb = glb.to_str().unwrap();
    let t = tempfile::tempdir().unwrap();
    let metres = t.path().join("m.png");
    let v = run_skin(&["--mesh", glb, "--mesh-units", "m", "--mesh-origin", "authored", "--distance", "1.2"], &metres);
    assert!(v["camera"]["head_height_mm"].as_f64().unwrap() > 4000.0, "{v}");
    let (full, _) = coverage(&metres);
    assert!(full > 0.95, "an 8 m head at 1.2 m fills the frame: {full}");
    let mut seen = Vec::new();
    for d in ["zoom", "near", "far"] {
        let out = t.path().join(format!("{d}.png"));
        let v = run_skin(&["--mesh", glb, "--mesh-units", "auto", "--distance", d], &out);
        let cam = &v["camera"];
        assert!((cam["head_height_mm"].as_f64().unwrap() - 230.0).abs() < 0.1, "{cam}");
        assert_eq!(cam["tap_distance"], d);
        assert_eq!(cam["fov_y_deg"], 30.0);
        assert_eq!(cam["viewport"], serde_json::json!([160, 120]));
        let want = 0.230 * [28.0, 50.0, 132.0][seen.len()] / 27.0;
        assert!((cam["distance_m"].as_f64().unwrap() - want).abs() < 1e-4, "{cam}");
        seen.push(coverage(&out).0);
    }
    assert!(seen[0] > seen[1] && seen[1] > seen[2] && seen[2] > 0.01, "{seen:?}");
    // The face is in the middle of every frame; at far the whole bust is inside it (its border is background).
    for d in ["zoom", "near", "far"] {
        let (_, img) = coverage(&t.path().join(format!("{d}.png")));
        let centre = 4 * (60 * 160 + 80);
        assert_ne!(img[centre..centre + 4], img[..4], "{d}: the frame's centre is background");
    }
    let (_, far) = coverage(&t.path().join("far.png"));
    let px = |x: usize, y: usize| &far[4 * (y * 160 + x)..4 * (y * 160 + x) + 4];
    let border = (0..160).all(|x| px(x, 0) == px(0, 0) && px(x, 119) == px(0, 0))
        && (0..120).all(|y| px(0, y) == px(0, 0) && px(159, y) == px(0, 0));
    assert!(border, "the bust at far touches the frame");
}

/// Bad framing flags exit 2 naming the flag and the accepted values, and write nothing.
#[test]
fn run_skin_refuses_bad_units_and_distances() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("x.png");
    let head = t.path().join("head.obj");
    std::fs::write(&head, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1/1 2/2/1 3/3/1\n")
        .unwrap();
    let head = head.to_str().unwrap();
    for (args, want) in [
        (vec!["--mesh", head, "--mesh-units", "furlong"], "--mesh-units"),
        (vec!["--mesh", head, "--mesh-units", "-2"], "--mesh-units"),
        (vec!["--mesh-units", "cm"], "--mesh only"),
        (vec!["--distance", "close"], "zoom, near, far"),
        (vec!["--distance", "0.1"], "--distance"),
        (vec!["--mesh", head, "--uv-origin", "top"], "format, top-left, bottom-left"),
    ] {
        let mut a = vec!["run", "skin", "--cpu", "--width", "64", "--height", "48", "--output", out.to_str().unwrap()];
        a.extend_from_slice(&args);
        let o = crate::support::rtbake(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!out.exists());
    }
}
