//! Per-mode timings of SMAA 1x / S2x / T2x / 4x (`rtbake::runtime::smaa_modes`) at 720p and 1080p, and of their CPU
//! twins at 1080p on 2 threads.
//!
//!     cargo run --release --example bench_smaa_modes
//!
//! GPU passes are timed with timestamp queries where the adapter supports them (per pass: 3 SMAA passes per sample,
//! the S2x average, the temporal resolve), else by wall time of submit + wait. The adapter is printed first: figures
//! from a software rasteriser (lavapipe/llvmpipe) are CPU figures, not GPU figures. Uploads are not timed (a renderer
//! produces its frames on the GPU). Thesis anchors (Table 10.1, 1080p, GTX 470): 1x 1.02 ms, T2x 1.32 ms,
//! S2x 2.04 ms, 4x 2.34 ms (S2x/4x without the MSAA rendering overhead). Medians of RUNS runs, min–max printed.
//! Frames: the procedural moving scene (`rtbake::runtime::moving_scene`), frame 1 (temporal modes have history).
//! The passes (SMAA per sample, the S2x average, the temporal resolve) take the shape `RTBAKE_AA_PASSES` names
//! (`compute`, the default, or `fragment`, the full-screen passes before them; printed first): `scripts/gpu_bench.sh` runs this benchmark once per shape.

use rtbake::runtime::aa::three_pass::PassShape;
use rtbake::runtime::cpu::smaa_modes::SmaaModesCpu;
use rtbake::runtime::cpu::FilterPrecision;
use rtbake::runtime::device::{create_headless, DeviceOptions, Gpu};
use rtbake::runtime::gpu::GpuTimer;
use rtbake::runtime::loader;
use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
use rtbake::runtime::smaa_modes::{scene_frame, ModeFrame, SmaaMode, SmaaModes, TemporalResolve};
use std::path::PathBuf;
use std::time::Instant;

const RUNS: usize = 7;

/// (median, min, max), ms.
type Stats = (f64, f64, f64);

/// (median, min, max).
fn stats(mut v: Vec<f64>) -> Stats {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

fn baked_dir() -> PathBuf {
    std::env::var_os("RTBAKE_BAKED_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("baked"))
}

fn anchor(mode: SmaaMode) -> f64 {
    match mode {
        SmaaMode::X1 => 1.02,
        SmaaMode::T2x => 1.32,
        SmaaMode::S2x => 2.04,
        SmaaMode::X4 => 2.34,
    }
}

/// Times the current frame of `pass` RUNS times (after one warm-up): per-pass medians (timestamps) and the
/// sum / wall-time statistics.
fn time_gpu(g: &Gpu, pass: &SmaaModes) -> (Vec<f64>, Stats, Stats) {
    let slots = pass.timed_passes();
    let timer = g.timestamps.then(|| GpuTimer::new(&g.device, slots));
    let mut per_pass: Vec<Vec<f64>> = vec![Vec::new(); slots as usize];
    let (mut sums, mut wall) = (Vec::new(), Vec::new());
    for run in 0..RUNS + 1 {
        let mut enc = g.device.create_command_encoder(&Default::default());
        pass.encode(&mut enc, timer.as_ref().map(|t| (t, 0)));
        if let Some(t) = &timer {
            t.resolve(&mut enc);
        }
        let t0 = Instant::now();
        g.queue.submit([enc.finish()]);
        g.device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if run == 0 {
            continue;
        }
        wall.push(ms);
        if let Some(t) = &timer {
            let v = t.read_ms(&g.device, &g.queue).unwrap();
            sums.push(v.iter().sum());
            for (k, x) in v.into_iter().enumerate() {
                per_pass[k].push(x);
            }
        }
    }
    let pp = per_pass.into_iter().filter(|v| !v.is_empty()).map(|v| stats(v).0).collect();
    let sum = if sums.is_empty() { (f64::NAN, f64::NAN, f64::NAN) } else { stats(sums) };
    (pp, sum, stats(wall))
}

/// Whether the adapter named `name` offers 2× multisampling of `Rgba8Unorm` (`TextureFormatFeatures`), which a
/// renderer feeding S2x/4x needs (wgpu guarantees only 1× and 4×); `None` when it is not found again.
fn msaa_2x_supported(name: &str) -> Option<bool> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::GL);
    let backends = desc.backends;
    let instance = wgpu::Instance::new(desc);
    let adapters = pollster::block_on(instance.enumerate_adapters(backends));
    let a = adapters.into_iter().find(|a| a.get_info().name == name)?;
    Some(a.get_texture_format_features(wgpu::TextureFormat::Rgba8Unorm).flags.sample_count_supported(2))
}

fn main() {
    let g = create_headless(&DeviceOptions { timestamps: true }).expect("an adapter");
    println!("adapter: {}", g.describe());
    println!(
        "2x MSAA of Rgba8Unorm on this adapter: {} (the passes take one image per sample either way)",
        match msaa_2x_supported(&g.adapter_info.name) {
            Some(true) => "supported",
            Some(false) => "not supported",
            None => "unknown",
        }
    );
    println!("timestamps: {}", if g.timestamps { "yes (per-pass GPU time)" } else { "no (wall time only)" });
    let shape = PassShape::from_env().unwrap_or_else(|e| panic!("{e}"));
    println!("SMAA pass shape: {} ({} = compute | fragment)", shape.name(), PassShape::ENV);
    let bw = rtbake::runtime::gpu::copy_bandwidth(&g.device, &g.queue, g.timestamps, RUNS);
    println!("{}", bw.describe());
    println!("medians of {RUNS} runs (min–max); scene: rtbake::runtime::moving_scene, frame 1");
    let luts = loader::load_smaa_textures(&baked_dir()).unwrap_or_else(|e| panic!("{e}"));
    for (w, h) in [(1280u32, 720u32), (1920, 1080)] {
        let scene = MovingScene::new(w, h, SceneMotion::DEFAULT).unwrap();
        for mode in SmaaMode::ALL {
            let mut pass = SmaaModes::new(&g.device, &g.queue, w, h, &luts, mode, TemporalResolve::default()).unwrap();
            let (s0, v0) = scene_frame(&scene, mode, 0);
            pass.run_frame(&g.device, &g.queue, &ModeFrame { samples: &s0, velocity_px: &v0 }).unwrap();
            let (s1, v1) = scene_frame(&scene, mode, 1);
            pass.upload(&g.queue, &ModeFrame { samples: &s1, velocity_px: &v1 }).unwrap();
            let (pp, sum, wall) = time_gpu(&g, &pass);
            let per = pp.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(" + ");
            let ratio = if h == 1080 {
                format!(", {:.2}× the thesis' {} ms", sum.0 / anchor(mode), anchor(mode))
            } else {
                String::new()
            };
            println!(
                "SMAA {:>3} {w}x{h}: GPU {:.3} ms ({:.3}–{:.3}) [passes {per}]{ratio}; wall {:.2} ms ({:.2}–{:.2})",
                mode.name(),
                sum.0,
                sum.1,
                sum.2,
                wall.0,
                wall.1,
                wall.2
            );
            // Bytes per pixel: per sample edges 4 + 2, weights 2 + 4, blend 4 + 4 + 4 (RGBA8 colour, RG8 edges, RGBA8
            // weights and result); two samples averaged 4 + 4 + 4; the temporal resolve reads the frame, the
            // previous frame (RGBA8) and the velocity (RG32F) and writes RGBA8.
            let per_px = 24 * mode.samples_per_frame() as u64
                + if mode.samples_per_frame() == 2 { 12 } else { 0 }
                + if mode.is_temporal() { 20 } else { 0 };
            let bytes = per_px * w as u64 * h as u64;
            let bound_ms = bytes as f64 / bw.bytes_per_s * 1e3;
            // A software adapter's timestamps miss compute work: its wall time is the figure there.
            let by_gpu = sum.0.is_finite() && g.adapter_info.device_type != wgpu::DeviceType::Cpu;
            let t = if by_gpu { sum.0 } else { wall.0 };
            println!(
                "    {:.1} MB moved, bytes-moved bound {bound_ms:.4} ms, time/bound {:.1} ({})",
                bytes as f64 * 1e-6,
                t / bound_ms,
                if by_gpu { "GPU time" } else { "wall time" }
            );
        }
    }
    // CPU twins at 1080p on 2 threads.
    let (w, h) = (1920u32, 1080u32);
    let scene = MovingScene::new(w, h, SceneMotion::DEFAULT).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for mode in SmaaMode::ALL {
        let inputs: Vec<_> = (0..RUNS as u64 + 1).map(|f| scene_frame(&scene, mode, f)).collect();
        let mut cpu = SmaaModesCpu::new(w, h, &luts, FilterPrecision::Exact, mode, TemporalResolve::default()).unwrap();
        let mut times = Vec::new();
        for (f, (s, v)) in inputs.iter().enumerate() {
            let t = Instant::now();
            let out = pool.install(|| cpu.run_frame(&ModeFrame { samples: s, velocity_px: v }).unwrap());
            std::hint::black_box(out.len());
            if f > 0 {
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        let (m, lo, hi) = stats(times);
        println!("CPU twin SMAA {:>3} {w}x{h} (2 threads): {m:.0} ms ({lo:.0}–{hi:.0}) per frame", mode.name());
    }
}
