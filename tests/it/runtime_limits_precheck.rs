//! `run skin` on a device checks every pass's buffers against the adapter's real limits before any work: a frame
//! whose bloom buffer exceeds the storage-binding limit is refused at once (exit 2, the flags named, nothing
//! written), not after rendering; the same frame without bloom passes the check.

use crate::support::{gpu, rtbake};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{check_frame_fits, SkinRenderSettings, SkinShader, StretchPreset};
use std::time::Instant;

/// The smallest frame, as wide as possible, whose bloom buffer (the frame, 16 bytes per pixel) exceeds the adapter's
/// storage-binding limit while its G-buffer still fits; `None` where no frame rtbake accepts does.
fn frame_over_bloom_limit(limits: &wgpu::Limits) -> Option<(u32, u32)> {
    let storage = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    let edge = limits.max_texture_dimension_2d.min(rtbake::error::MAX_TEXTURE_EDGE);
    let side = ((storage / 16) as f64).sqrt() as u64 + 1;
    let (w, h) = if side <= edge as u64 { (side, side) } else { (edge as u64, (storage / 16 / edge as u64) + 1) };
    (h <= edge as u64 && rtbake::runtime::bloom::largest_buffer_bytes(w as u32, h as u32) > storage)
        .then_some((w as u32, h as u32))
}

fn settings(width: u32, height: u32) -> SkinRenderSettings {
    SkinRenderSettings {
        shader: SkinShader::Separable,
        heads: 1,
        distance_m: 0.6,
        width,
        height,
        melanin: 0.02,
        stretch: StretchPreset::Thesis,
    }
}

#[test]
fn a_frame_over_the_bloom_storage_limit_is_refused_before_any_work() {
    let g = gpu();
    let limits = g.device.limits();
    let Some((w, h)) = frame_over_bloom_limit(&limits) else {
        eprintln!(
            "{}: storage-binding limit {} bytes is beyond any frame rtbake accepts; nothing to refuse",
            g.describe(),
            limits.max_storage_buffer_binding_size
        );
        return;
    };
    // The pre-check, without rendering: bloom is the culprit, the frame fits without it.
    let s = settings(w, h);
    let err = check_frame_fits(&limits, &s, &SkinPasses::default()).unwrap_err();
    assert!(err.message.contains("bloom"), "{err}");
    assert_eq!(check_frame_fits(&limits, &s, &SkinPasses::none()), Ok(()));
    drop(g);

    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("frame.png");
    let (ws, hs) = (w.to_string(), h.to_string());
    let start = Instant::now();
    let o = rtbake(&["run", "skin", "--width", &ws, "--height", &hs, "--output", out.to_str().unwrap()]);
    let took = start.elapsed().as_secs_f64();
    let msg = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{w}x{h}: {msg}");
    for flag in ["bloom", "--width", "--height", "--bloom off", "--cpu", "max_storage_buffer_binding_size"] {
        assert!(msg.contains(flag), "{w}x{h}: the message must name {flag}: {msg}");
    }
    // Refused before rendering: device creation and asset loading only (a render of this size on a software
    // adapter takes tens of seconds).
    assert!(took < 10.0, "{w}x{h} refused after {took:.1} s: {msg}");
    assert!(!out.exists(), "nothing may be written");
    assert_eq!(std::fs::read_dir(t.path()).unwrap().count(), 0, "no stray file");
    eprintln!("{w}x{h} refused in {took:.2} s: {msg}");
}

/// On a software adapter the GPU path is timed with the adapter's own estimate, once the device is known: a size
/// the generic GPU estimate lets through but the software estimate puts over `--max-seconds` is refused before
/// rendering, for `run skin` and `run demo`.
#[test]
fn a_frame_over_the_time_budget_on_a_software_adapter_is_refused_before_rendering() {
    let g = gpu();
    if !g.is_software() {
        eprintln!("{}: not a software adapter; its GPU estimate is the generic one", g.describe());
        return;
    }
    drop(g);
    let (w, h) = (1024u32, 1024u32);
    let budget = 2.0;
    let s = settings(w, h);
    assert!(rtbake::runtime::demo::time_estimate_seconds(w, h, false) + 0.5 < budget);
    assert!(rtbake::runtime::skin_render::software_adapter_time_estimate_seconds(&s) > budget);
    let (wd, hd) = (2048u32, 2048u32);
    assert!(rtbake::runtime::demo::time_estimate_seconds(wd, hd, false) < budget);
    assert!(rtbake::runtime::demo::software_adapter_time_estimate_seconds(wd, hd) > budget);
    for (cmd, w, h) in [("skin", w, h), ("demo", wd, hd)] {
        let t = tempfile::tempdir().unwrap();
        let out = t.path().join("frame.png");
        let (ws, hs, bs) = (w.to_string(), h.to_string(), budget.to_string());
        let start = Instant::now();
        let o = rtbake(&[
            "run",
            cmd,
            "--width",
            &ws,
            "--height",
            &hs,
            "--max-seconds",
            &bs,
            "--output",
            out.to_str().unwrap(),
        ]);
        let took = start.elapsed().as_secs_f64();
        let msg = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "run {cmd} {w}x{h}: {msg}");
        assert!(msg.contains("software adapter") && msg.contains("--max-seconds"), "run {cmd}: {msg}");
        // Refused before rendering: well under the budget it would have overrun.
        assert!(took < budget, "run {cmd} {w}x{h} refused after {took:.2} s: {msg}");
        assert!(!out.exists() && std::fs::read_dir(t.path()).unwrap().count() == 0, "run {cmd}: nothing written");
    }
}
