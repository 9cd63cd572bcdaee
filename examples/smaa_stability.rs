//! Temporal stability of SMAA 1x, T2x and 4x on the moving scene's static-camera, sub-pixel-motion sequence
//! (`SceneMotion::SUBPIXEL`: drift 0.1 px/frame, slow rotation, static background), at several frame sizes, with
//! the CPU twins: the mean absolute frame-to-frame change of frames 1..12 (per channel, /255), as the test
//! `smaa_temporal_reprojection_is_more_stable_than_1x` measures it at 256×192.
//!
//!     cargo run --release --example smaa_stability [W H ...]      (default: 256 192 640 360 1280 720 1920 1080)
//!
//! Eq. 10.6 compares velocity modules in normalised screen units (SMAA's texture-coordinate velocity, carried as
//! a = sqrt(5‖v‖)), so the same motion in pixels weighs the history down more in a small frame: this example shows
//! how T2x at K = 30 compares with 1x as the frame grows. A measurement, not a test.

use rtbake::runtime::cpu::smaa_modes::SmaaModesCpu;
use rtbake::runtime::cpu::FilterPrecision;
use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
use rtbake::runtime::smaa_modes::{scene_frame, ModeFrame, SmaaMode, TemporalResolve};

const FRAMES: u64 = 12;

fn mean_change(frames: &[Vec<u8>]) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for pair in frames[1..].windows(2) {
        for (p, q) in pair[0].chunks(4).zip(pair[1].chunks(4)) {
            for k in 0..3 {
                sum += (p[k] as f64 - q[k] as f64).abs();
                n += 1;
            }
        }
    }
    sum / n as f64
}

fn main() {
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse().expect("sizes are integers")).collect();
    let sizes: Vec<(u32, u32)> = if args.len() >= 2 {
        args.chunks(2).filter(|c| c.len() == 2).map(|c| (c[0], c[1])).collect()
    } else {
        vec![(256, 192), (640, 360), (1280, 720), (1920, 1080)]
    };
    let luts = rtbake::runtime::loader::load_smaa_textures(std::path::Path::new("baked"))
        .unwrap_or_else(|e| panic!("run from the crate root (needs baked/): {e}"));
    println!("mean |frame-to-frame change| /255, frames 1..{FRAMES}, SceneMotion::SUBPIXEL, CPU twins");
    println!(
        "{:>10} {:>8} {:>9} {:>9} {:>8} {:>8} {:>13}",
        "size", "1x", "T2x K=30", "T2x K=0", "4x", "16x", "T2x30 / 1x"
    );
    for (w, h) in sizes {
        let scene = MovingScene::new(w, h, SceneMotion::SUBPIXEL).expect("size in range");
        let run = |mode, resolve| {
            let mut p = SmaaModesCpu::new(w, h, &luts, FilterPrecision::Exact, mode, resolve).expect("valid");
            let frames: Vec<Vec<u8>> = (0..FRAMES)
                .map(|f| {
                    let (s, v) = scene_frame(&scene, mode, f);
                    p.run_frame(&ModeFrame { samples: &s, velocity_px: &v }).expect("frame")
                })
                .collect();
            mean_change(&frames)
        };
        let x1 = run(SmaaMode::X1, TemporalResolve::default());
        let t30 = run(SmaaMode::T2x, TemporalResolve::default());
        let t0 = run(SmaaMode::T2x, TemporalResolve::Reprojected { k: 0.0 });
        let x4 = run(SmaaMode::X4, TemporalResolve::default());
        let truth: Vec<Vec<u8>> = (0..FRAMES).map(|f| scene.truth(f as f64, 4)).collect();
        println!(
            "{:>10} {x1:>8.4} {t30:>9.4} {t0:>9.4} {x4:>8.4} {:>8.4} {:>13.3}",
            format!("{w}x{h}"),
            mean_change(&truth),
            t30 / x1
        );
    }
}
