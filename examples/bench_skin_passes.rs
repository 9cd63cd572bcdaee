//! Cost of the rig and wrinkle passes added to `run skin` (the rig's eq. 7.6 at the mesh's uv, the wrinkle pass of
//! Listing 8.1, bloom, the 4× MSAA G-buffer) at 1280×720 with the default head: each pass alone (its inputs
//! prepared outside the timing, the host upload and read-back inside, as the chain runs it), then whole SS Full
//! frames with no pass, the defaults (bloom on) and every pass. Median and min–max of 5 runs after a warm-up; the
//! anchor is the frame with no pass.
//!
//!     cargo run --release --example bench_skin_passes            # the adapter (WGPU_BACKEND/WGPU_ADAPTER_NAME)
//!     cargo run --release --example bench_skin_passes -- cpu     # the CPU twins
//!
//! The adapter is printed: figures from llvmpipe/lavapipe are CPU figures, not GPU figures.

use rtbake::mesh::head::default_head;
use rtbake::runtime::bloom::{bloom_for, BloomParams};
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::device::create_headless;
use rtbake::runtime::mesh_skin_inputs::{hemoglobin_for_gbuffer, RigPose};
use rtbake::runtime::skin_passes::{SkinPasses, Wrinkles};
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader};
use rtbake::runtime::wrinkle_pass::{parse_wrinkle_weights, wrinkled_normals_for, WrinkleMaps};
use std::path::PathBuf;
use std::time::Instant;

fn time(mut f: impl FnMut()) -> (f64, f64, f64) {
    f();
    let mut v: Vec<f64> = (0..5)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    v.sort_by(f64::total_cmp);
    (v[2], v[0], v[4])
}

fn main() {
    let cpu = std::env::args().any(|a| a == "cpu");
    let dir = std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"));
    let assets = DemoAssets::load(&dir).expect("baked tables");
    let gpu = if cpu { None } else { Some(create_headless(&Default::default()).expect("an adapter")) };
    let g = gpu.as_ref();
    println!("adapter: {}", g.map(|g| g.describe()).unwrap_or_else(|| "CPU twins".into()));
    let (w, h) = (1280u32, 720u32);
    let head = default_head();
    let s = SkinRenderSettings {
        shader: SkinShader::SsFull,
        heads: 1,
        distance_m: 0.6,
        width: w,
        height: h,
        melanin: 0.02,
        stretch: Default::default(),
    };
    let cam = s.camera();
    let tangents = rtbake::mesh::tangents::vertex_tangents(&head);
    let raster = |samples| match g {
        Some(d) => {
            use rtbake::runtime::mesh_raster::{rasterise_jobs, RasterJob};
            let job = RasterJob { mesh: &head, tangents: &tangents, camera: &cam, width: w, height: h, samples };
            rasterise_jobs(&d.device, &d.queue, &[job]).unwrap().remove(0)
        }
        None => rtbake::runtime::cpu::mesh_raster::rasterise_samples(&head, &cam, w, h, samples).unwrap(),
    };
    let gb = raster(1);
    let rig = assets.baked_rig.as_ref().expect("the example rig");
    let pose = RigPose::for_baked_rig(&serde_json::json!({"anger": 1.0, "global": {"anger": 1.0}}), rig).unwrap();
    let maps = WrinkleMaps::load(&dir).expect("wrinkle maps");
    let zones = parse_wrinkle_weights("anger=1, surprise=1").unwrap();
    let hdr: Vec<f32> = (0..(w * h) as usize)
        .flat_map(|i| {
            let l = if gb.covered[i] { 0.6 + 0.8 * gb.normal_view[i][2] } else { 0.03 };
            [l, 0.8 * l, 0.7 * l, 1.0]
        })
        .collect();
    let cell = |(m, lo, hi): (f64, f64, f64)| format!("{m:8.1} ms ({lo:.1}-{hi:.1})");
    println!("{w}x{h}, the default head ({} triangles), 5 runs after a warm-up", head.triangle_count());
    println!("{:<34} {}", "G-buffer raster, 1 sample", cell(time(|| drop(raster(1)))));
    println!("{:<34} {}", "G-buffer raster, 4x MSAA", cell(time(|| drop(raster(4)))));
    println!(
        "{:<34} {}",
        "rig eq. 7.6 at the mesh uv",
        cell(time(|| drop(hemoglobin_for_gbuffer(g, &gb, rig, &pose).unwrap())))
    );
    println!(
        "{:<34} {}",
        "wrinkle pass (Listing 8.1)",
        cell(time(|| drop(wrinkled_normals_for(g, &gb, &maps, &zones).unwrap())))
    );
    let bp = BloomParams::default();
    println!("{:<34} {}", "bloom (3 Gaussians, 3 stages)", cell(time(|| drop(bloom_for(g, w, h, &hdr, &bp).unwrap()))));
    let frame = |p: &SkinPasses| time(|| drop(render_with(g, &head, &s, p, &assets).unwrap()));
    let none = frame(&SkinPasses { bloom: None, ..Default::default() });
    let defaults = frame(&SkinPasses::default());
    let all = frame(&SkinPasses {
        rig_pose: Some(pose.clone()),
        wrinkles: Some(Wrinkles { maps: maps.clone().into(), zone_weights: zones }),
        msaa: 4,
        ..Default::default()
    });
    println!("{:<34} {}  (anchor)", "SS Full frame, no pass", cell(none));
    println!("{:<34} {}  x{:.2}", "SS Full frame, defaults (bloom)", cell(defaults), defaults.0 / none.0);
    println!("{:<34} {}  x{:.2}", "SS Full frame, every pass", cell(all), all.0 / none.0);
}
