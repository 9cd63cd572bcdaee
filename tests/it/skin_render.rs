//! `rtbake run skin` — heads from a mesh through the skin chain. The GPU chain agrees with its CPU twin,
//! the SSS shaders (separable, SS Full, SS Jittered) soften the lit skin (red more than blue, as the skin profiles are widest in red), a mesh file is
//! rendered like the built-in head, and bad meshes and settings exit 2 naming the file or flag, writing nothing.

use crate::support::rtbake;
use rtbake::mesh::head::default_head;

fn render(args: &[&str], out: &std::path::Path) -> Vec<u8> {
    let mut a = vec!["run", "skin", "--width", "320", "--height", "180", "--output", out.to_str().unwrap()];
    a.extend_from_slice(args);
    let o = rtbake(&a);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    image::open(out).unwrap().to_rgba8().into_raw()
}

/// Mean squared Laplacian of one channel over pixels whose 3×3 neighbourhood differs from the background.
fn roughness(img: &[u8], w: usize, h: usize, c: usize) -> f64 {
    let at = |x: usize, y: usize| img[4 * (y * w + x) + c] as f64;
    let bg = at(0, 0);
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let nb = [at(x, y), at(x - 1, y), at(x + 1, y), at(x, y - 1), at(x, y + 1)];
            if nb.contains(&bg) {
                continue;
            }
            let l = 4.0 * nb[0] - nb[1] - nb[2] - nb[3] - nb[4];
            sum += l * l;
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

#[test]
fn gpu_and_cpu_chains_agree_and_sss_softens_red_most() {
    let t = tempfile::tempdir().unwrap();
    let p = |n: &str| t.path().join(n);
    let gpu = render(&["--shader", "separable"], &p("gpu.png"));
    let cpu = render(&["--shader", "separable", "--cpu"], &p("cpu.png"));
    let close = gpu.iter().zip(&cpu).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
    assert!(close as f64 >= 0.99 * gpu.len() as f64, "{close} of {} channels within 2/255", gpu.len());
    let none = render(&["--shader", "none"], &p("none.png"));
    let full = render(&["--shader", "ss-full", "--stretch", "thesis"], &p("full.png"));
    let jittered = render(&["--shader", "ss-jittered"], &p("jittered.png"));
    let jittered_cpu = render(&["--shader", "ss-jittered", "--cpu"], &p("jittered_cpu.png"));
    let close = jittered.iter().zip(&jittered_cpu).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
    assert!(close as f64 >= 0.99 * jittered.len() as f64, "ss-jittered: {close} of {} within 2/255", jittered.len());
    let covered = none.chunks(4).filter(|px| px[..3] != [46, 48, 52]).count();
    assert!(covered > 5000, "{covered} head pixels");
    // The default stretch is TAP's.
    let tap = render(&["--shader", "ss-full"], &p("tap.png"));
    assert_ne!(tap, full, "the TAP 2009 stretch (alpha 11) must differ from the thesis' (alpha 31.5)");
    let tap_cpu = render(&["--shader", "ss-full", "--stretch", "tap2009", "--cpu"], &p("tap_cpu.png"));
    let close = tap.iter().zip(&tap_cpu).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
    assert!(close as f64 >= 0.99 * tap.len() as f64, "ss-full tap2009: {close} of {} within 2/255", tap.len());
    for (name, img) in [("separable", &gpu), ("ss-full", &full), ("ss-jittered", &jittered), ("ss-full tap2009", &tap)]
    {
        let ratio = |c| roughness(img, 320, 180, c) / roughness(&none, 320, 180, c);
        let (r, b) = (ratio(0), ratio(2));
        eprintln!("{name}: Laplacian energy vs no SSS: red {r:.3}, blue {b:.3}");
        assert!(r < 0.9, "{name} does not soften red: {r}");
        assert!(r < b, "{name}: red {r} must be softened more than blue {b}");
    }
}

#[test]
fn a_mesh_file_renders_like_the_built_in_head_and_heads_multiply() {
    let t = tempfile::tempdir().unwrap();
    let m = default_head();
    let mut obj = String::new();
    for p in &m.positions {
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    for n in &m.normals {
        obj.push_str(&format!("vn {} {} {}\n", n[0], n[1], n[2]));
    }
    for uv in &m.uvs {
        obj.push_str(&format!("vt {} {}\n", uv[0], 1.0 - uv[1]));
    }
    for f in m.indices.chunks(3) {
        let v = |i: u32| format!("{0}/{0}/{0}", i + 1);
        obj.push_str(&format!("f {} {} {}\n", v(f[0]), v(f[1]), v(f[2])));
    }
    let path = t.path().join("head.obj");
    std::fs::write(&path, obj).unwrap();
    let built_in = render(&["--shader", "none", "--cpu"], &t.path().join("a.png"));
    let from_file = render(
        &["--shader", "none", "--cpu", "--mesh", path.to_str().unwrap(), "--mesh-origin", "authored"],
        &t.path().join("b.png"),
    );
    let close = built_in.iter().zip(&from_file).filter(|(a, b)| a.abs_diff(**b) <= 1).count();
    assert!(close as f64 >= 0.999 * built_in.len() as f64, "{close} of {}", built_in.len());
    // Three heads at 1 m: three separate silhouettes along the middle row.
    let three = render(&["--shader", "none", "--cpu", "--heads", "3", "--distance", "1.0"], &t.path().join("c.png"));
    let row = 90 * 320 * 4;
    let mut runs = 0;
    let mut inside = false;
    for x in 0..320 {
        let skin = three[row + 4 * x..row + 4 * x + 3] != [46, 48, 52];
        runs += usize::from(skin && !inside);
        inside = skin;
    }
    assert!(runs >= 3, "{runs} silhouettes on the middle row");
}

#[test]
fn bad_meshes_and_settings_exit_2_naming_them_and_write_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out.png");
    let o = out.to_str().unwrap();
    let write = |name: &str, body: &[u8]| {
        let p = t.path().join(name);
        std::fs::write(&p, body).unwrap();
        p.to_str().unwrap().to_string()
    };
    let no_vn = write("no_vn.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\n");
    let no_vt = write("no_vt.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n");
    let degenerate = write("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n");
    let empty = write("empty.obj", b"");
    let garbage = write("bad.gltf", b"{\"asset\": 7}");
    let unknown = write("head.stl", b"solid");
    // A huge mesh file is refused from its size, before it is read (a sparse 600 MiB file).
    let huge = t.path().join("huge.glb");
    std::fs::File::create(&huge).unwrap().set_len(600 << 20).unwrap();
    let huge = huge.to_str().unwrap().to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--mesh", &no_vn], "vn"),
        (vec!["--mesh", &no_vt], "TEXCOORD_0"),
        (vec!["--mesh", &degenerate], "degenerate"),
        (vec!["--mesh", &empty], "no triangles"),
        (vec!["--mesh", &garbage], "not a valid glTF"),
        (vec!["--mesh", &unknown], "extension"),
        (vec!["--mesh", "/nonexistent/head.glb"], "--mesh"),
        (vec!["--mesh", &huge], "accepted at most"),
        (vec!["--heads", "0"], "--heads"),
        (vec!["--heads", "17"], "--heads"),
        (vec!["--distance", "0"], "--distance"),
        (vec!["--melanin", "-0.1"], "--melanin"),
        (vec!["--mesh-mm-per-unit", "0"], "--mesh-mm-per-unit"),
        (vec!["--stretch", "wide"], "--stretch"),
        (vec!["--stretch", ""], "--stretch"),
    ];
    for (args, needle) in cases {
        let mut a = vec!["run", "skin", "--cpu", "--width", "64", "--height", "64", "--output", o];
        a.extend_from_slice(&args);
        let r = rtbake(&a);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote the output");
    }
    // The spelling `--out` is the same flag: a bad setting through it is refused the same way (nothing
    // written), a good one writes the frame there.
    let r = rtbake(&["run", "skin", "--cpu", "--width", "64", "--height", "64", "--out", o, "--heads", "0"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("--heads"));
    assert!(!out.exists(), "a refused command wrote the output");
    let r = rtbake(&["run", "skin", "--cpu", "--width", "64", "--height", "64", "--out", o]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert_eq!(image::open(&out).unwrap().to_rgba8().dimensions(), (64, 64));
}

/// The specular layer (Kelemen/Szirmay-Kalos, added after the SSS pass): zero off the head, and its peak where the
/// normal is within 8° of the half vector of the key light and the view.
#[test]
fn the_specular_layer_peaks_at_the_mirror_normal() {
    use rtbake::mesh::camera::Camera;
    use rtbake::runtime::skin_render::specular_layer;
    let cam = Camera::facing(0.6).unwrap();
    let g = rtbake::runtime::cpu::mesh_raster::rasterise(&default_head(), &cam, 256, 192);
    let spec = specular_layer(&g, &cam);
    assert!(spec.iter().zip(&g.covered).all(|(s, c)| *c || *s == 0.0));
    let (peak_i, peak) = spec.iter().copied().enumerate().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    assert!(peak > 0.0);
    // Key light (view space) as the demo's, the view direction at the peak pixel ≈ +z (30° field of view).
    let l = {
        let v = [-0.5f32, 0.6, 0.62];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / n, v[1] / n, v[2] / n]
    };
    let hv = {
        let h = [l[0], l[1], l[2] + 1.0];
        let n = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        [h[0] / n, h[1] / n, h[2] / n]
    };
    let n = g.normal_view[peak_i];
    let n_dot_h = n[0] * hv[0] + n[1] * hv[1] + n[2] * hv[2];
    assert!(n_dot_h > 0.99, "peak normal {n:?} vs half vector {hv:?}: {n_dot_h}");
}

/// `run skin` on the adapter with `RTBAKE_RASTER` naming no shape: exit 2 naming the variable and its values,
/// nothing written; `compute` and `render` both render the frame, within 2/255 on 99 % of the channels of each
/// other (the compute rasteriser's own tests hold it to the render pass and the CPU twin pixel by pixel).
#[test]
fn run_skin_refuses_an_unknown_raster_shape_and_renders_both() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out.png");
    let run = |shape: &str| {
        let _ = std::fs::remove_file(&out);
        let args = ["run", "skin", "--width", "96", "--height", "64", "--shader", "none", "--output"];
        std::process::Command::new(env!("CARGO_BIN_EXE_rtbake"))
            .args(args)
            .arg(&out)
            .env("RTBAKE_RASTER", shape)
            .output()
            .unwrap()
    };
    let o = run("fragment");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("RTBAKE_RASTER") && err.contains("must be compute or render, got \"fragment\""), "{err}");
    assert!(!out.exists(), "nothing may be written");
    let frames: Vec<Vec<u8>> = ["compute", "render"]
        .iter()
        .map(|shape| {
            let o = run(shape);
            assert!(o.status.success(), "{shape}: {}", String::from_utf8_lossy(&o.stderr));
            image::open(&out).unwrap().to_rgba8().into_raw()
        })
        .collect();
    let close = frames[0].iter().zip(&frames[1]).filter(|(a, b)| a.abs_diff(**b) <= 2).count();
    assert!(close as f64 >= 0.99 * frames[0].len() as f64, "{close} of {} channels within 2/255", frames[0].len());
}
