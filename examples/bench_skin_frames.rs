//! Frames shaped like an engine's: `run skin`'s frame (default passes: bloom on) per shader on a device, its
//! shading recorded into one command encoder with one read-back ("one encoder", the runtime's path) against each
//! pass submitted and read back on its own ("per pass", the path before;
//! `runtime::skin::shade_frame::set_shading_in_one_encoder(false)`), in one run on one adapter: the first frame of
//! each on a fresh device (shader modules and pipelines compiled), then frames of the two paths alternating on one
//! device, and the median of frames 2..=N of each, their ratio and the queue submissions and host read-backs of a
//! steady-state frame (`runtime::gpu::submissions_on_this_thread`, `read_backs_on_this_thread`).
//!
//!     cargo run --release --example bench_skin_frames [-- WIDTH HEIGHT FRAMES [no-bloom] [mesh=SCAN.glb
//!         albedo=ALBEDO.jpg normal=NORMAL.jpg [uv-origin=bottom-left]] [only=ROW] [pool-only]]   # 1280 720 7
//!
//! `pool-only` prints the frame-pool table alone (below).
//!
//! With `mesh=` (a glTF or OBJ head, framed as `run skin --mesh-units auto --distance near` frames it) and its maps
//! (`albedo=`, `normal=`: sRGB albedo, OpenGL-green tangent-space normal map), the scanned head's frame follows:
//! each screen-space shader with the maps, separable SSS with the maps and `--msaa 4`, and texture-space diffusion
//! (the 1024² irradiance map of `run skin` and `run tap-grid`) with the maps — the reference frames of TAP's
//! experiment — and with the maps and `--msaa 4` — e.g. the Lee Perry-Smith scan of
//! `../shared/reference/heads/lee-perry-smith/` (CC BY 3.0; its texture coordinates need `uv-origin=bottom-left`,
//! as `run skin` needs `--uv-origin bottom-left`). `only=ROW` keeps the rows whose name starts with ROW, `_` for a
//! space (`only=scan_ts`: the scan's two TS rows).
//!
//! A second table compares the frame pool (`runtime::frame_pool`: the frame's buffers and textures kept across
//! frames, as an engine keeps its render targets) on and off (`set_frame_pool_enabled`) on the one-encoder path,
//! per screen-space shader: frame 1 on a fresh device and the median of frames 2..=N (the two alternating on one
//! device), and the host's split of a steady-state frame with the pool on (medians): recording + submitting its
//! commands, waiting for the GPU, copying the read-back out — and the same frame left on the device
//! (`render_on_device_with`, no read-back; the wait is then a `device.poll`).
//!
//! The adapter is printed: figures from llvmpipe/lavapipe are CPU figures, not GPU figures (there a read-back is a
//! copy within host memory). Each frame includes what `run skin` does per frame (uploads, the final read-back; on
//! the per-pass path also the G-buffer read-back the host's geometry needs). Texture-space diffusion ("ts") has a one-encoder path too
//! (its irradiance maps lit, blurred and gathered on the device; one read-back of the frame and its texel counts). Tables come from the committed bake (`baked/`, or $RTBAKE_BAKED_DIR).

use rtbake::mesh::head::default_head;
use rtbake::mesh::Mesh;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::{create_headless, Gpu};
use rtbake::runtime::frame_pool::set_frame_pool_enabled;
use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
use rtbake::runtime::skin::shade_frame::last_host_split;
use rtbake::runtime::skin::shade_frame::set_shading_in_one_encoder;
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::render_on_device_with;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, TsSettings};
use std::path::PathBuf;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One frame of `head` on `g` through the one-encoder path or not: wall ms, submissions, read-backs.
fn frame(
    g: &Gpu,
    one_encoder: bool,
    head: &Mesh,
    s: &SkinRenderSettings,
    passes: &SkinPasses,
    assets: &DemoAssets,
) -> [f64; 3] {
    set_shading_in_one_encoder(one_encoder);
    let (sub, read, t) = (submissions_on_this_thread(), read_backs_on_this_thread(), Instant::now());
    render_with(Some(g), head, s, passes, assets).expect("render");
    let ms = t.elapsed().as_secs_f64() * 1e3;
    [ms, (submissions_on_this_thread() - sub) as f64, (read_backs_on_this_thread() - read) as f64]
}

/// The value of the `NAME=VALUE` argument `name`.
fn arg(name: &str) -> Option<String> {
    std::env::args().skip(1).find_map(|a| a.strip_prefix(&format!("{name}=")).map(str::to_string))
}

/// The scanned head of `mesh=` framed as `run skin --mesh-units auto` frames it, the camera distance of TAP's
/// "near" for it, and its maps (`albedo=`, `normal=`).
fn scan() -> Option<(Mesh, f32, rtbake::runtime::skin::surface_maps::SurfaceMaps)> {
    use rtbake::mesh::framing::{head_height_units, to_metres, MeshOrigin, MeshUnits, TapDistance};
    let path = PathBuf::from(arg("mesh")?);
    let bytes = std::fs::read(&path).expect("mesh= readable");
    let dir = path.parent().map(PathBuf::from).unwrap_or_default();
    let mesh = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
        rtbake::mesh::obj::parse_obj("mesh", &bytes, 1000.0)
    } else {
        rtbake::mesh::gltf::parse_gltf("mesh", &bytes, &|uri: &str| {
            std::fs::read(dir.join(uri)).map_err(|e| e.to_string())
        })
    }
    .expect("a valid mesh");
    // uv-origin=bottom-left for the three.js copy of the Lee Perry-Smith scan (as `run skin --uv-origin`).
    let mesh = match arg("uv-origin").as_deref() {
        Some("bottom-left") => mesh.with_uv_origin(rtbake::mesh::UvOrigin::TopLeft, rtbake::mesh::UvOrigin::BottomLeft),
        _ => mesh,
    };
    let units = MeshUnits::parse("mesh_units", "auto").expect("auto");
    let mesh = to_metres(&mesh, units, MeshOrigin::Head, "mesh_units").expect("a framable head");
    let height_m = head_height_units(&mesh) * mesh.mm_per_unit / 1000.0;
    let distance = TapDistance::parse("near").expect("near").camera_distance_m(height_m);
    let picture = |name: &str| {
        arg(name).map(|p| {
            let bytes = std::fs::read(&p).expect("map readable");
            rtbake::io::picture::decode_u8(name, &p, &bytes).expect("a PNG or JPEG map")
        })
    };
    let (albedo, normal) = (picture("albedo"), picture("normal"));
    let green = rtbake::facial::wrinkles::GreenConvention::OpenGl;
    let maps = rtbake::runtime::skin::surface_maps::SurfaceMaps::from_pictures(albedo.as_ref(), normal.as_ref(), green)
        .expect("valid maps");
    Some((mesh, distance, maps))
}

/// The frame pool on vs off per screen-space shader, and the host split of a steady-state frame with and without
/// its read-back (see the module doc).
fn pool_table(width: u32, height: u32, frames: usize, passes: &SkinPasses, assets: &DemoAssets) {
    let g = create_headless(&Default::default()).expect("an adapter");
    println!(
        "\nframe pool, one encoder, {width}x{height}: frame 1 (fresh device) and the median of frames 2..={frames}, wall \
         ms, pool on vs off; host split of a steady frame with the pool on, ms: record+submit / GPU wait / read-back \
         copy, and left on the device: record+submit / GPU wait"
    );
    println!(
        "{:<12} {:>9} {:>9} {:>9} {:>9} {:>7} {:>24} {:>17}",
        "shader", "1st on", "1st off", "2..N on", "2..N off", "ratio", "split (read back)", "split (on device)"
    );
    let shaders = [
        ("none", SkinShader::None),
        ("ss-jittered", SkinShader::SsJittered),
        ("ss-full", SkinShader::SsFull),
        ("separable", SkinShader::Separable),
    ];
    set_shading_in_one_encoder(true);
    for (name, shader) in shaders {
        let s = SkinRenderSettings {
            shader,
            heads: 1,
            distance_m: 0.6,
            width,
            height,
            melanin: 0.02,
            stretch: Default::default(),
        };
        let timed = |g: &Gpu, pool: bool| {
            set_frame_pool_enabled(pool);
            let t = Instant::now();
            render_with(Some(g), &default_head(), &s, passes, assets).expect("render");
            let ms = t.elapsed().as_secs_f64() * 1e3;
            set_frame_pool_enabled(true);
            ms
        };
        let first = [true, false].map(|pool| timed(&device(), pool));
        let (mut on, mut off, mut split, mut resident) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for _ in 0..frames {
            on.push(timed(&g, true));
            split.push(last_host_split().expect("a one-encoder frame"));
            off.push(timed(&g, false));
            let frame = render_on_device_with(&g, &default_head(), &s, passes, assets).expect("render");
            let record = last_host_split().expect("a one-encoder frame").record_submit_ms;
            let t = Instant::now();
            let _ = g.device.poll(wgpu::PollType::wait_indefinitely());
            resident.push([record, t.elapsed().as_secs_f64() * 1e3]);
            drop(frame);
        }
        let steady = |v: &[f64]| median(v[1..].to_vec());
        let (o, f) = (steady(&on), steady(&off));
        let part = |k: usize| match k {
            0 => steady(&split.iter().map(|h| h.record_submit_ms).collect::<Vec<_>>()),
            1 => steady(&split.iter().map(|h| h.wait_ms).collect::<Vec<_>>()),
            _ => steady(&split.iter().map(|h| h.copy_ms).collect::<Vec<_>>()),
        };
        let res = |k: usize| steady(&resident.iter().map(|r| r[k]).collect::<Vec<_>>());
        let split_text = format!("{:.1} / {:.1} / {:.1}", part(0), part(1), part(2));
        let resident_text = format!("{:.1} / {:.1}", res(0), res(1));
        println!(
            "{name:<12} {:>9.1} {:>9.1} {o:>9.1} {f:>9.1} {:>6.2}x {split_text:>24} {resident_text:>17}",
            first[0],
            first[1],
            f / o
        );
    }
}

fn device() -> Gpu {
    create_headless(&Default::default()).expect("an adapter")
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (width, height) = (args.first().copied().unwrap_or(1280), args.get(1).copied().unwrap_or(720));
    let frames = args.get(2).copied().unwrap_or(7).max(3) as usize;
    let bloom = !std::env::args().any(|a| a == "no-bloom");
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let g = device();
    println!("adapter: {}", g.describe());
    println!(
        "run skin frame, {} the default head ({} triangles), {width}x{height}; frame 1 (a fresh device) and the \
         median of frames 2..={frames} (the two paths alternating), wall ms; submissions / read-backs per frame",
        if bloom { "default passes (bloom on)," } else { "no bloom," },
        default_head().triangle_count()
    );
    println!(
        "{:<12} {:>13} {:>13} {:>13} {:>13} {:>8} {:>13} {:>13}",
        "shader",
        "1st per-pass",
        "1st one-enc",
        "2..N per-pass",
        "2..N one-enc",
        "ratio",
        "per-pass s/r",
        "one-enc s/r"
    );
    let plain = if bloom { SkinPasses::default() } else { SkinPasses::none() };
    let shaders = [
        ("none", SkinShader::None),
        ("ss-jittered", SkinShader::SsJittered),
        ("ss-full", SkinShader::SsFull),
        ("separable", SkinShader::Separable),
        ("ts", SkinShader::Ts(TsSettings::default())),
    ];
    // (row, head, camera distance m, shader, passes)
    let mut rows: Vec<(String, Mesh, f32, SkinShader, SkinPasses)> =
        shaders.iter().map(|(n, sh)| (n.to_string(), default_head(), 0.6, *sh, plain.clone())).collect();
    if let Some((mesh, distance, maps)) = scan() {
        let (a, n) = (maps.albedo.is_some(), maps.normal.is_some());
        let t = mesh.triangle_count();
        println!("scan: {t} triangles at {distance:.3} m (TAP's near), maps: albedo {a}, normal map {n}");
        let mapped = SkinPasses { surface_maps: Some(maps), ..plain.clone() };
        for (n, sh) in &shaders[..4] {
            rows.push((format!("scan {n}"), mesh.clone(), distance, *sh, mapped.clone()));
        }
        let msaa = SkinPasses { msaa: 4, ..mapped.clone() };
        rows.push(("scan sep 4x".to_string(), mesh.clone(), distance, SkinShader::Separable, msaa.clone()));
        let (_, ts) = shaders[4];
        rows.push(("scan ts".to_string(), mesh.clone(), distance, ts, mapped));
        rows.push(("scan ts 4x".to_string(), mesh, distance, ts, msaa));
    }
    if let Some(only) = arg("only") {
        rows.retain(|(name, ..)| name.starts_with(&only.replace('_', " ")));
    }
    // `pool-only`: the frame-pool table alone.
    let rows = if std::env::args().any(|a| a == "pool-only") { Vec::new() } else { rows };
    for (name, head, distance_m, shader, passes) in &rows {
        let (shader, distance_m) = (*shader, *distance_m);
        let s = SkinRenderSettings {
            shader,
            heads: 1,
            distance_m,
            width,
            height,
            melanin: 0.02,
            stretch: Default::default(),
        };
        let first = [false, true].map(|one| frame(&device(), one, head, &s, passes, &assets)[0]);
        let (mut per_pass, mut one_enc) = (Vec::new(), Vec::new());
        for _ in 0..frames {
            per_pass.push(frame(&g, false, head, &s, passes, &assets));
            one_enc.push(frame(&g, true, head, &s, passes, &assets));
        }
        let ms = |v: &[[f64; 3]]| median(v[1..].iter().map(|f| f[0]).collect());
        let (p, o) = (ms(&per_pass), ms(&one_enc));
        let counts = |v: &[[f64; 3]]| format!("{}/{}", v[frames - 1][1], v[frames - 1][2]);
        eprintln!("  {name}: per pass {:.0?} ms, one encoder {:.0?} ms", per_pass, one_enc);
        println!(
            "{name:<12} {:>13.1} {:>13.1} {p:>13.1} {o:>13.1} {:>7.2}x {:>13} {:>13}",
            first[0],
            first[1],
            p / o,
            counts(&per_pass),
            counts(&one_enc)
        );
    }
    pool_table(width, height, frames, &plain, &assets);
}
