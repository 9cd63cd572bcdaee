//! Per-pass timings of the runtime at 720p and 1080p, and the CPU reference SMAA at 1080p on 2 threads (a fresh
//! result per frame, `smaa`, and into buffers reused from frame to frame, `smaa_into`; the difference is the
//! allocation and first-touch page faults of 20 MB per frame).
//!
//!     cargo run --release --example bench_runtime          # GPU passes, then the CPU reference SMAA
//!     cargo run --release --example bench_runtime -- cpu   # the CPU reference SMAA only (no adapter needed)
//!     cargo run --release --example bench_runtime -- 1920x1080 [gpu-only]   # one size; no CPU reference SMAA
//!
//! Each pass is printed beside its bytes-moved bound: the bytes it must read and write (its input and output
//! images at their formats, each texel once; the look-up tables are left out) divided by the adapter's copy
//! bandwidth, measured first in the same run with buffer-to-buffer copies (read + write bytes per second), and
//! the ratio time / bound.
//!
//! SMAA 1x and MLAA run three times, in their fragment shape (three full-screen fragment passes, as before) and their
//! compute shape (three compute passes, the default; `rtbake::runtime::aa::three_pass::PassShape`) with its edges
//! texture written as the portable `Rgba8Unorm` and as the device's format (`Rg8Unorm` where the adapter allows it
//! as a storage texture; `EdgeFormat`), each pass beside the bound of its own bytes, and a line per pass gives the
//! speed-up and time/bound of the fragment and the device's compute shape. On a GPU (exact command, from the repository root):
//!
//!     cargo build --release --example bench_runtime --example bench_smaa_modes && \
//!         scripts/gpu_bench.sh target/release/examples 1920x1080
//!
//! The SSS passes likewise (`rtbake::runtime::sss::PassShape`): separable (two fragment passes, then the two compute
//! passes over line tiles), the sum of Gaussians (d'Eon's six: ten fragment passes after two copies, then ten compute
//! passes over line tiles with the blend folded in) and the importance-sampled pass (TAP's SS Jittered, 13 taps: one
//! fragment pass, then one compute pass), each pass beside its bound and a line per method with both.
//!
//! GPU passes are timed with timestamp queries when the adapter supports them, else by wall time of
//! submit + wait (which includes driver overhead). The adapter is printed first: figures from a software
//! rasteriser (lavapipe/llvmpipe) are CPU figures, not GPU figures. Thesis anchors: SMAA 1x 1.02 ms at 1080p
//! (GTX 470); Jimenez MLAA 0.44 ms at 720p (9800 GTX+). CPU anchor: Reshetov's CPU MLAA, 350 ms; goal ≤ 100 ms.
//! Tables: the committed bake (`baked/` beside the crate, or $RTBAKE_BAKED_DIR) through the manifest-checked
//! loader: SMAA area/search, MLAA AreaMap33 v1.4, the published 17-tap separable kernel, d'Eon's 6 Gaussians.

use rtbake::runtime::aa::three_pass::{set_portable_edges, PassShape};
use rtbake::runtime::cpu::{self, FilterPrecision, Tex8};
use rtbake::runtime::device::{create_headless, DeviceOptions};
use rtbake::runtime::gaussian_sss::GaussianSss;
use rtbake::runtime::gpu::GpuTimer;
use rtbake::runtime::importance_sss::{ImportanceSss, ImportanceSssParams};
use rtbake::runtime::loader;
use rtbake::runtime::mlaa::{Mlaa, MlaaAreaMap, MlaaOptions};
use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
use rtbake::runtime::scene::render_shapes;
use rtbake::runtime::separable_sss::{SeparableSss, SssParams};
use rtbake::runtime::smaa::{Smaa, SmaaOptions, SubsampleIndices};
use rtbake::runtime::sss::separable_tiled::SeparableSssTiled;
use std::path::PathBuf;
use std::time::Instant;

const RUNS: usize = 7;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v[v.len() / 2]
}

fn baked_dir() -> PathBuf {
    std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"))
}

type Encode<'a> = dyn Fn(&mut wgpu::CommandEncoder, Option<(&GpuTimer, u32)>) + 'a;

/// Times `encode` (`slots` passes) RUNS times; returns per-pass medians (timestamps) or the wall-time median.
fn time_passes(g: &rtbake::runtime::device::Gpu, slots: u32, encode: &Encode<'_>) -> (Vec<f64>, f64) {
    let timer = g.timestamps.then(|| GpuTimer::new(&g.device, slots));
    let mut per_pass: Vec<Vec<f64>> = vec![Vec::new(); slots as usize];
    let mut wall = Vec::new();
    for run in 0..RUNS + 1 {
        let mut enc = g.device.create_command_encoder(&Default::default());
        encode(&mut enc, timer.as_ref().map(|t| (t, 0)));
        if let Some(t) = &timer {
            t.resolve(&mut enc);
        }
        let t0 = Instant::now();
        g.queue.submit([enc.finish()]);
        g.device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if run == 0 {
            continue; // warm-up (pipeline compilation on first use)
        }
        wall.push(ms);
        if let Some(t) = &timer {
            for (k, v) in t.read_ms(&g.device, &g.queue).unwrap().into_iter().enumerate() {
                per_pass[k].push(v);
            }
        }
    }
    let pp = if timer.is_some() { per_pass.into_iter().map(median).collect() } else { Vec::new() };
    (pp, median(wall))
}

fn main() {
    let dir = baked_dir();
    let luts = loader::load_smaa_textures(&dir).unwrap_or_else(|e| panic!("{e}"));
    let args: Vec<String> = std::env::args().skip(1).collect();
    let sizes: Vec<(u32, u32)> = args
        .iter()
        .filter_map(|a| a.split_once('x').and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?))))
        .collect();
    let sizes = if sizes.is_empty() { vec![(1280u32, 720u32), (1920, 1080)] } else { sizes };
    if args.first().map(String::as_str) != Some("cpu") {
        gpu_passes(&dir, &luts, &sizes);
    }
    if !args.iter().any(|a| a == "gpu-only") {
        cpu_smaa(&luts);
    }
}

/// The adapter's copy bandwidth (read + write bytes per second), printed.
fn copy_bandwidth(g: &rtbake::runtime::device::Gpu) -> f64 {
    let c = rtbake::runtime::gpu::copy_bandwidth(&g.device, &g.queue, g.timestamps, RUNS);
    println!("{}", c.describe());
    c.bytes_per_s
}

fn gpu_passes(dir: &std::path::Path, luts: &rtbake::runtime::smaa::SmaaTextures, sizes: &[(u32, u32)]) {
    let g = create_headless(&DeviceOptions { timestamps: true }).expect("an adapter");
    println!("adapter: {}", g.describe());
    println!("timestamps: {}", if g.timestamps { "yes (per-pass GPU time)" } else { "no (wall time only)" });
    let bw = copy_bandwidth(&g);
    let n = 33;
    let map = MlaaAreaMap::new(n, loader::load_mlaa_area(dir, n).unwrap_or_else(|e| panic!("{e}"))).unwrap();
    let kernel = loader::load_separable_kernel(dir, rtbake::baked_layout::path::SEPARABLE_KERNEL_DEFAULT)
        .unwrap_or_else(|e| panic!("{e}"));
    let fit =
        loader::load_gaussians(dir, rtbake::baked_layout::path::GAUSSIANS_DEFAULT).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "medians of {RUNS} runs; scene: procedural shapes (rtbake::runtime::scene), for SMAA and MLAA also the moving \
         scene's textured frame (rtbake::runtime::moving_scene, edges almost everywhere)"
    );
    for &(w, h) in sizes {
        let img = render_shapes(w, h, 1);
        aa_shapes(&g, luts, &map, (w, h), &img, "shapes", bw);
        let moving = MovingScene::new(w, h, SceneMotion::DEFAULT).unwrap().render(1.0, [0.0, 0.0]);
        aa_shapes(&g, luts, &map, (w, h), &moving, "moving scene", bw);
        sss_shapes(&g, &kernel.kernel, &fit, (w, h), bw);
    }
}

/// The SSS passes on a lit sphere filling the frame height (alpha 1 on skin), each in the fragment shape (full-screen
/// fragment passes, before) and the compute shape (after; `rtbake::runtime::sss::PassShape`), each pass beside its
/// bytes-moved bound, then per method the speed-up and time/bound of both.
fn sss_shapes(
    g: &rtbake::runtime::device::Gpu,
    kernel: &rtbake::runtime::separable_sss::SssKernel,
    fit: &loader::BakedGaussians,
    (w, h): (u32, u32),
    bw: f64,
) {
    let px = w as u64 * h as u64;
    let (color, depth) = sss_frame(w, h);
    let mut totals = Vec::new();
    // Separable, each pass: RGBA16F colour and R32F depth in, RGBA16F out (both shapes).
    let bytes = [20 * px, 20 * px];
    for shape in [PassShape::Fragment, PassShape::Compute] {
        let (pp, wall) = match shape {
            PassShape::Fragment => {
                let sss = SeparableSss::new(&g.device, w, h, kernel, &SssParams::default()).unwrap();
                sss.upload(&g.queue, &color, &depth).unwrap();
                time_passes(g, 2, &|e, t| sss.encode(e, t))
            }
            PassShape::Compute => {
                let sss = SeparableSssTiled::new(&g.device, w, h, kernel, &SssParams::default()).unwrap();
                sss.upload(&g.queue, &color, &depth).unwrap();
                time_passes(g, 2, &|e, t| sss.encode(e, t))
            }
        };
        let name = format!("separable SSS 17 taps {w}x{h}, {}", shape.name());
        print_sum(&name, &pp, wall, "thesis 1.05 ms @1080p GTX 580; goal 0.2 ms @1080p H100");
        print_bounds(&["horizontal", "vertical"], &pp, wall, &bytes, bw);
        totals.push(("separable SSS 17 taps", total_ms(&pp, wall), wall, bytes.iter().sum::<u64>()));
    }
    // Sum of Gaussians (d'Eon's six, α scaled to the viewport as `run skin` does; bytes per pass in
    // `rtbake::runtime::sss::gaussian_tiled`'s docs). Fragment: the two copies of the input (32 B/px, untimed) before
    // horizontal passes of 28 B/px (source, depth, matte in; RT2 out) and vertical ones of 44 (RT2, depth, matte in;
    // RT1 out; RTF blended, read and written). Compute: no copies, horizontal 20, vertical 36, the last 28.
    let params = fit.params.for_viewport_height(h);
    for shape in [PassShape::Fragment, PassShape::Compute] {
        let gs = GaussianSss::with_shape(&g.device, (w, h), &fit.blurs, &params, shape).unwrap();
        gs.upload(&g.queue, &color, &depth).unwrap();
        let n = gs.passes();
        let (pp, wall) = time_passes(g, n, &|e, t| gs.encode(e, t));
        let name = format!("sum-of-Gaussians SSS (deon6) {w}x{h}, {}", shape.name());
        print_sum(&name, &pp, wall, "thesis 3.07 ms @1080p GTX 580");
        let names: Vec<String> = (0..n).map(|i| format!("{}{}", ["h", "v"][i as usize % 2], i / 2 + 1)).collect();
        let per_px = |i: u32| match (shape, i.is_multiple_of(2)) {
            (PassShape::Fragment, true) => 28,
            (PassShape::Fragment, false) => 44,
            (PassShape::Compute, true) => 20,
            (PassShape::Compute, false) if i + 1 == n => 28,
            (PassShape::Compute, false) => 36,
        };
        let bytes: Vec<u64> = (0..n).map(|i| per_px(i) * px).collect();
        print_bounds(&names.iter().map(String::as_str).collect::<Vec<_>>(), &pp, wall, &bytes, bw);
        let copies = if shape == PassShape::Fragment { 32 * px } else { 0 };
        totals.push(("sum-of-Gaussians SSS", total_ms(&pp, wall), wall, bytes.iter().sum::<u64>() + copies));
    }
    // Importance-sampled, TAP's SS Jittered (13 taps): RGBA16F colour and R32F depth in, RGBA16F out.
    let samples = rtbake::runtime::skin::frame::jittered_samples().unwrap();
    let bytes = [20 * px];
    for shape in [PassShape::Fragment, PassShape::Compute] {
        let params = ImportanceSssParams::default();
        let is = ImportanceSss::with_shape(&g.device, (w, h), &samples, &params, shape).unwrap();
        is.upload(&g.queue, &color, &depth).unwrap();
        let (pp, wall) = time_passes(g, 1, &|e, t| is.encode(e, t));
        print_sum(&format!("importance-sampled SSS (SS Jittered, 13 taps) {w}x{h}, {}", shape.name()), &pp, wall, "");
        print_bounds(&["gather"], &pp, wall, &bytes, bw);
        totals.push(("importance-sampled SSS (SS Jittered)", total_ms(&pp, wall), wall, bytes[0]));
    }
    // Software adapters do not time compute passes faithfully (their timestamps miss the work): there the speed-up
    // and time/bound are taken from the wall times of submit + wait, which include the driver's overhead.
    let bound = |b: u64| b as f64 / bw * 1e3;
    let by = if g.is_software() { "wall time (software adapter)" } else { "GPU time" };
    for pair in totals.chunks(2) {
        let ((pass, old, old_wall, old_b), (_, new, new_wall, new_b)) = (pair[0], pair[1]);
        let (old, new) = if g.is_software() { (old_wall, new_wall) } else { (old, new) };
        println!(
            "{pass} {w}x{h} by {by}: fragment {old:.3} ms -> compute {new:.3} ms ({:.2}x); bound {:.4} -> {:.4} ms \
             ({:.0} -> {:.0} B/px), time/bound {:.1} -> {:.1}",
            old / new,
            bound(old_b),
            bound(new_b),
            old_b as f64 / px as f64,
            new_b as f64 / px as f64,
            old / bound(old_b),
            new / bound(new_b),
        );
    }
}

/// SMAA 1x and MLAA on `img` in the fragment shape (three full-screen fragment passes, before) and the compute shape
/// (three compute passes, after; the same output bytes) with its edges texture in both forms (`EdgeFormat`: the
/// portable `Rgba8Unorm`, then the device's, `Rg8Unorm` where the adapter allows it as a storage texture), each pass
/// beside its bytes-moved bound, then the speed-up of the device's compute shape over the fragment shape.
fn aa_shapes(
    g: &rtbake::runtime::device::Gpu,
    luts: &rtbake::runtime::smaa::SmaaTextures,
    map: &MlaaAreaMap,
    (w, h): (u32, u32),
    img: &[u8],
    scene: &str,
    bw: f64,
) {
    // Bytes per pass (`ThreePass::pass_bytes`): edges: colour RGBA8 in, edges out at the edges texture's format
    // (RG8, or RGBA8 in the portable compute form); weights: edges in, weights RGBA8 out; blend: colour + weights in,
    // RGBA8 out. The look-up tables, the texels the searches read twice, the edge list and the zeroed weights are
    // left out: a bound, not a model.
    let names = ["edges", "weights", "blend"];
    let forms = [(PassShape::Fragment, false), (PassShape::Compute, true), (PassShape::Compute, false)];
    let form_name = |shape: PassShape, edges: &wgpu::Texture| format!("{}, {:?} edges", shape.name(), edges.format());
    // (pass, time, wall, bytes) of the fragment shape and the device's compute shape.
    let mut totals = Vec::new();
    for (shape, portable) in forms {
        set_portable_edges(portable);
        let smaa = Smaa::with_shape(&g.device, &g.queue, (w, h), luts, &SmaaOptions::default(), shape).unwrap();
        set_portable_edges(false);
        smaa.upload(&g.queue, img).unwrap();
        let (pp, wall) = time_passes(g, 3, &|e, t| smaa.encode(e, t));
        let name = format!("SMAA 1x {w}x{h} {scene}, {}", form_name(shape, smaa.edges()));
        print_line(&name, &pp, wall, "thesis 1.02 ms @1080p GTX 470; goal 0.2 ms @1080p H100");
        let bytes = smaa.pass_bytes();
        print_bounds(&names, &pp, wall, &bytes, bw);
        if !portable {
            totals.push(("SMAA 1x", total_ms(&pp, wall), wall, bytes.iter().sum::<u64>()));
        }
    }
    for (shape, portable) in forms {
        set_portable_edges(portable);
        let mlaa = Mlaa::with_shape(&g.device, &g.queue, (w, h), map, &MlaaOptions::default(), shape).unwrap();
        set_portable_edges(false);
        mlaa.upload(&g.queue, img).unwrap();
        let (pp, wall) = time_passes(g, 3, &|e, t| mlaa.encode(e, t));
        let name = format!("MLAA N={} {w}x{h} {scene}, {}", map.n, form_name(shape, mlaa.edges()));
        print_line(&name, &pp, wall, "thesis 0.44 ms @720p 9800 GTX+");
        let bytes = mlaa.pass_bytes();
        print_bounds(&names, &pp, wall, &bytes, bw);
        if !portable {
            totals.push(("MLAA", total_ms(&pp, wall), wall, bytes.iter().sum::<u64>()));
        }
    }
    // Software adapters do not time compute passes faithfully (their timestamps miss the work): the wall times of
    // submit + wait are printed beside the timestamp sums, and on such an adapter only they compare.
    let bound = |b: u64| b as f64 / bw * 1e3;
    for pair in totals.chunks(2) {
        let ((pass, old, old_wall, old_b), (_, new, new_wall, new_b)) = (pair[0], pair[1]);
        println!(
            "{pass} {w}x{h} {scene}: fragment {old:.3} ms -> compute {new:.3} ms ({:.2}x); bound {:.4} -> {:.4} ms, \
             time/bound {:.1} -> {:.1}; wall {old_wall:.3} -> {new_wall:.3} ms ({:.2}x)",
            old / new,
            bound(old_b),
            bound(new_b),
            old / bound(old_b),
            new / bound(new_b),
            old_wall / new_wall
        );
    }
}

/// The CPU reference SMAA at 1080p on 2 threads: whole run (median and min–max of RUNS) and per stage.
fn cpu_smaa(luts: &rtbake::runtime::smaa::SmaaTextures) {
    let (w, h) = (1920, 1080);
    let img = render_shapes(w, h, 1);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let times: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            let out = pool.install(|| cpu::smaa::smaa(&img, w, h, luts, FilterPrecision::Exact));
            std::hint::black_box(out.output.len());
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let (lo, hi) = min_max(&times);
    let m = median(times);
    // The same frames into buffers reused from frame to frame (`smaa_into`, as the GPU pass reuses its textures):
    // no allocation and no first-touch page faults per frame.
    let mut reused = cpu::smaa::smaa(&img, w, h, luts, FilterPrecision::Exact);
    let times: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = Instant::now();
            pool.install(|| {
                cpu::smaa::smaa_into(&img, w, h, luts, FilterPrecision::Exact, SubsampleIndices::SMAA_1X, &mut reused)
            });
            std::hint::black_box(reused.output.len());
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let (lo_r, hi_r) = min_max(&times);
    let m_r = median(times);
    // Per-stage split of the CPU reference (same pool).
    let stage = |f: &(dyn Fn() -> usize + Sync)| {
        median(
            (0..RUNS)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(pool.install(f));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        )
    };
    let color = Tex8::new(w, h, 4, &img);
    let edges = cpu::smaa::edge_detection(&color);
    let weights = cpu::smaa::blending_weights(&Tex8::new(w, h, 2, &edges), luts, FilterPrecision::Exact);
    let t_e = stage(&|| cpu::smaa::edge_detection(&color).len());
    let t_w = stage(&|| cpu::smaa::blending_weights(&Tex8::new(w, h, 2, &edges), luts, FilterPrecision::Exact).len());
    let t_b = stage(&|| cpu::smaa::neighbourhood_blending(&color, &Tex8::new(w, h, 4, &weights)).len());
    println!("CPU reference SMAA stages (2 threads): edges {t_e:.1} ms, weights {t_w:.1} ms, blend {t_b:.1} ms");
    println!(
        "CPU reference SMAA 1x 1920x1080, 2 threads: {m:.1} ms (min-max {lo:.1}-{hi:.1} ms of {RUNS}; goal <= 100 ms: {}; \
         vs Reshetov CPU MLAA 350 ms: {:.2}x; memory bound 2.3 ms: {:.2}x)",
        if m <= 100.0 { "met" } else { "NOT met" },
        350.0 / m,
        m / 2.3
    );
    println!(
        "CPU reference SMAA 1x 1920x1080, 2 threads, buffers reused: {m_r:.1} ms (min-max {lo_r:.1}-{hi_r:.1} ms of \
         {RUNS}; memory bound 2.3 ms: {:.2}x)",
        m_r / 2.3
    );
}

fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter().fold((f64::MAX, 0.0f64), |(lo, hi), &t| (lo.min(t), hi.max(t)))
}

fn sss_frame(w: u32, h: u32) -> (Vec<f32>, Vec<f32>) {
    let (mut color, mut depth) = (vec![0.0f32; (w * h * 4) as usize], vec![50.0f32; (w * h) as usize]);
    let r = 0.45 * h as f32;
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = (x as f32 + 0.5 - w as f32 / 2.0, y as f32 + 0.5 - h as f32 / 2.0);
            let i = (y * w + x) as usize;
            if dx * dx + dy * dy < r * r {
                let z = (r * r - dx * dx - dy * dy).sqrt() / r;
                let stripe = if (x / 8 + y / 8) % 2 == 0 { 1.0 } else { 0.3 };
                color[4 * i..4 * i + 4].copy_from_slice(&[0.8 * z * stripe, 0.5 * z * stripe, 0.4 * z * stripe, 1.0]);
                depth[i] = 2.0 - 0.3 * z;
            }
        }
    }
    (color, depth)
}

/// Per pass: GPU time, bytes read + written, the bytes-moved bound at `bw` bytes/s and time / bound (the whole
/// chain by wall time when there are no timestamps).
fn print_bounds(names: &[&str], per_pass: &[f64], wall: f64, bytes: &[u64], bw: f64) {
    let bound_ms = |b: u64| b as f64 / bw * 1e3;
    if per_pass.is_empty() {
        let total: u64 = bytes.iter().sum();
        println!(
            "    all passes: wall {wall:.3} ms, {:.1} MB moved, bound {:.4} ms, time/bound {:.1}",
            total as f64 * 1e-6,
            bound_ms(total),
            wall / bound_ms(total)
        );
        return;
    }
    let total: u64 = bytes.iter().sum();
    println!(
        "    all passes by wall time (submit + wait): {wall:.3} ms, {:.1} MB, time/bound {:.1} (a check on the \
         per-pass timestamps below, which a software adapter's compute passes do not report faithfully)",
        total as f64 * 1e-6,
        wall / bound_ms(total)
    );
    for ((name, ms), b) in names.iter().zip(per_pass).zip(bytes) {
        println!(
            "    {name:<10} {ms:.4} ms, {:.1} MB moved, bound {:.4} ms, time/bound {:.1}",
            *b as f64 * 1e-6,
            bound_ms(*b),
            ms / bound_ms(*b)
        );
    }
}

/// The sum of the per-pass timestamps, else the wall time.
fn total_ms(per_pass: &[f64], wall: f64) -> f64 {
    if per_pass.is_empty() {
        wall
    } else {
        per_pass.iter().sum()
    }
}

fn print_sum(name: &str, per_pass: &[f64], wall: f64, anchor: &str) {
    if per_pass.is_empty() {
        println!("{name}: wall {wall:.2} ms (submit+wait)  [{anchor}]");
    } else {
        let total: f64 = per_pass.iter().sum();
        let parts: Vec<String> = per_pass.iter().map(|v| format!("{v:.2}")).collect();
        println!(
            "{name}: {} passes [{}] ms, total {total:.2} ms (wall {wall:.2} ms)  [{anchor}]",
            per_pass.len(),
            parts.join(", ")
        );
    }
}

fn print_line(name: &str, per_pass: &[f64], wall: f64, anchor: &str) {
    if per_pass.is_empty() {
        println!("{name}: wall {wall:.2} ms (submit+wait)  [{anchor}]");
    } else {
        let total: f64 = per_pass.iter().sum();
        println!(
            "{name}: edges {:.2} ms, weights {:.2} ms, blend {:.2} ms, total {total:.2} ms (wall {wall:.2} ms)  [{anchor}]",
            per_pass[0], per_pass[1], per_pass[2]
        );
    }
}
