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
//!
//! A second table looks at where T2x at K = 30 rejects history (w < 0.5 in eq. 10.6): the share of pixels, their
//! share of T2x's frame-to-frame change, and how many of them have the same velocity alpha before SMAA in both
//! frames (at p and at the reprojected p − v), i.e. are rejected only because SMAA 1x blended the alpha channel
//! (the velocity module, thesis §10.4.4) with different weights under the two jitters.

use rtbake::runtime::cpu::smaa_modes::SmaaModesCpu;
use rtbake::runtime::cpu::FilterPrecision;
use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
use rtbake::runtime::smaa::SmaaTextures;
use rtbake::runtime::smaa_modes::{
    scene_frame, velocity_alpha, with_velocity_alpha, ModeFrame, SmaaMode, TemporalResolve,
};

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

/// Where T2x at K = 30 rejects history on `scene` (module docs): (share of pixels with w < 0.5, their share of the
/// change of the resolved frames, share of them whose velocity alpha before SMAA is equal in both frames).
fn rejections(scene: &MovingScene, luts: &SmaaTextures, (w, h): (u32, u32), resolved: &[Vec<u8>]) -> (f64, f64, f64) {
    let k = 30.0f32;
    let smaa: Vec<(Vec<u8>, Vec<f32>)> = (0..FRAMES)
        .map(|f| {
            let (s, v) = scene_frame(scene, SmaaMode::T2x, f);
            let sub = SmaaMode::T2x.samples(f)[0].subsample;
            let input = with_velocity_alpha(&s[0], &v, w, h);
            (rtbake::runtime::cpu::smaa::smaa_with_subsample(&input, w, h, luts, FilterPrecision::Exact, sub).output, v)
        })
        .collect();
    let (mut rejected, mut equal_raw, mut total) = (0usize, 0usize, 0usize);
    let (mut change_rejected, mut change_all) = (0.0f64, 0.0f64);
    for f in 2..FRAMES as usize {
        let ((cur, v), (prev, v_prev)) = (&smaa[f], &smaa[f - 1]);
        for (i, (y, x)) in (0..h as usize).flat_map(|y| (0..w as usize).map(move |x| (y, x))).enumerate() {
            let qx = ((x as f32 + 0.5 - v[2 * i]).floor() as i32).clamp(0, w as i32 - 1) as usize;
            let qy = ((y as f32 + 0.5 - v[2 * i + 1]).floor() as i32).clamp(0, h as i32 - 1) as usize;
            let j = qy * w as usize + qx;
            let (ac, ap) = (cur[4 * i + 3] as f32 / 255.0, prev[4 * j + 3] as f32 / 255.0);
            let weight = 0.5 * (1.0 - k * ((ac * ac - ap * ap).abs() / 5.0).sqrt()).clamp(0.0, 1.0);
            let change: f64 =
                (0..3).map(|c| (resolved[f][4 * i + c] as f64 - resolved[f - 1][4 * i + c] as f64).abs()).sum();
            change_all += change;
            total += 1;
            if weight < 0.5 {
                rejected += 1;
                change_rejected += change;
                let raw = |v: &[f32], i: usize| velocity_alpha([v[2 * i], v[2 * i + 1]], w, h);
                equal_raw += usize::from(raw(v, i) == raw(v_prev, j));
            }
        }
    }
    (rejected as f64 / total as f64, change_rejected / change_all, equal_raw as f64 / rejected.max(1) as f64)
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
    let mut analysis = Vec::new();
    for (w, h) in sizes {
        let scene = MovingScene::new(w, h, SceneMotion::SUBPIXEL).expect("size in range");
        let run = |mode, resolve| {
            let mut p = SmaaModesCpu::new(w, h, &luts, FilterPrecision::Exact, mode, resolve).expect("valid");
            (0..FRAMES)
                .map(|f| {
                    let (s, v) = scene_frame(&scene, mode, f);
                    p.run_frame(&ModeFrame { samples: &s, velocity_px: &v }).expect("frame")
                })
                .collect::<Vec<Vec<u8>>>()
        };
        let x1 = mean_change(&run(SmaaMode::X1, TemporalResolve::default()));
        let t30_frames = run(SmaaMode::T2x, TemporalResolve::default());
        let t30 = mean_change(&t30_frames);
        analysis.push(((w, h), rejections(&scene, &luts, (w, h), &t30_frames)));
        let t0 = mean_change(&run(SmaaMode::T2x, TemporalResolve::Reprojected { k: 0.0 }));
        let x4 = mean_change(&run(SmaaMode::X4, TemporalResolve::default()));
        let truth: Vec<Vec<u8>> = (0..FRAMES).map(|f| scene.truth(f as f64, 4)).collect();
        println!(
            "{:>10} {x1:>8.4} {t30:>9.4} {t0:>9.4} {x4:>8.4} {:>8.4} {:>13.3}",
            format!("{w}x{h}"),
            mean_change(&truth),
            t30 / x1
        );
    }
    println!("\nT2x K=30, frames 2..{FRAMES}: where eq. 10.6 rejects history (w < 0.5)");
    println!("{:>10} {:>12} {:>16} {:>30}", "size", "pixels", "share of change", "same alpha before SMAA");
    for ((w, h), (px, change, same)) in analysis {
        println!("{:>10} {:>11.2}% {:>15.1}% {:>29.1}%", format!("{w}x{h}"), 100.0 * px, 100.0 * change, 100.0 * same);
    }
}
