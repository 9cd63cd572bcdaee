//! Texture-space diffusion (`run skin --shader ts`; d'Eon et al. 2007, thesis ch. 3): the GPU pass agrees
//! with its CPU twin, every shader's error against a converged TS reference (TS at a 2048² map, no optimisation),
//! each ch. 3 optimisation leaves the image within a stated tolerance while skipping the texels it claims, and bad
//! `--ts-*` input exits 2 naming the flag, writing nothing.

use crate::support::{baked_dir, gpu, rtbake};
use rtbake::mesh::head::default_head;
use rtbake::runtime::cpu;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::skin_render::{render, SkinRenderSettings, SkinShader, StretchPreset};
use rtbake::runtime::texture_space::{self, TextureSpaceDiffusion, TsSettings};
use rtbake::shading::texture_space::{normalised_weights, rasterise_uv};

const BACKGROUND: [u8; 3] = [46, 48, 52];

fn settings(shader: SkinShader, heads: u32, distance_m: f32, w: u32, h: u32) -> SkinRenderSettings {
    SkinRenderSettings { shader, heads, distance_m, width: w, height: h, melanin: 0.02, stretch: StretchPreset::Thesis }
}

fn srgb_to_linear(v: u8) -> f64 {
    cpu::srgb_to_linear(v as f32 / 255.0) as f64
}

/// RMSE in linear light over the reference's skin pixels (RGB), and the PSNR (peak 1).
fn rmse_psnr(img: &[u8], reference: &[u8]) -> (f64, f64) {
    let mask: Vec<bool> = reference.chunks(4).map(|r| r[..3] != BACKGROUND).collect();
    rmse_psnr_over(img, reference, &mask)
}

/// Skin pixels of a `w`-wide `reference` at least `r` pixels (Chebyshev) from any background pixel.
fn interior(reference: &[u8], w: usize, r: usize) -> Vec<bool> {
    let h = reference.len() / 4 / w;
    let skin = |x: usize, y: usize| reference[4 * (y * w + x)..4 * (y * w + x) + 3] != BACKGROUND;
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            x >= r
                && y >= r
                && x + r < w
                && y + r < h
                && (y - r..=y + r).all(|yy| (x - r..=x + r).all(|xx| skin(xx, yy)))
        })
        .collect()
}

fn rmse_psnr_over(img: &[u8], reference: &[u8], mask: &[bool]) -> (f64, f64) {
    let (mut se, mut n) = (0.0, 0usize);
    for ((p, r), &m) in img.chunks(4).zip(reference.chunks(4)).zip(mask) {
        if !m {
            continue;
        }
        for c in 0..3 {
            let d = srgb_to_linear(p[c]) - srgb_to_linear(r[c]);
            se += d * d;
            n += 1;
        }
    }
    let rmse = (se / n as f64).sqrt();
    (rmse, -20.0 * rmse.log10())
}

/// The blur-and-gather pass on the GPU and its CPU twin, on the same lit-like irradiance map of the default head
/// (256²) gathered at every covered texel's centre and at off-centre uvs: within 1/255 on ≥ 99.9 % of channels.
#[test]
fn ts_pass_gpu_matches_its_cpu_twin() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let size = 256u32;
    let uv = rasterise_uv(&default_head(), size);
    let irr: Vec<[f32; 4]> = (0..(size * size) as usize)
        .map(|t| {
            if !uv.covered[t] {
                return [0.0; 4];
            }
            let n = uv.normal[t];
            let (x, y) = ((t as u32 % size) as f32, (t as u32 / size) as f32);
            let pattern = 0.5 + 0.5 * (x * 0.7).sin() * (y * 0.45).cos();
            [0.8 * n[2].max(0.0) + 0.1 * pattern, 0.5 * n[1].abs() + 0.2 * pattern, 0.3 * pattern, 1.0]
        })
        .collect();
    let uvs: Vec<[f32; 2]> = (0..(size * size) as usize)
        .filter(|&t| uv.covered[t])
        .flat_map(|t| {
            let (x, y) = ((t as u32 % size) as f32, (t as u32 / size) as f32);
            [[(x + 0.5) / size as f32, (y + 0.5) / size as f32], [(x + 0.8) / size as f32, (y + 0.3) / size as f32]]
        })
        .collect();
    let weights = normalised_weights(&assets.blurs.blend);
    let sigmas = &assets.blurs.incremental_sigma_mm;
    let pass = TextureSpaceDiffusion::new(&g.device).unwrap();
    let on_gpu = pass.run(&g.device, &g.queue, &irr, &uv.stretch_mm_per_texel, size, sigmas, &weights, &uvs).unwrap();
    let sum = cpu::texture_space::blur_sum(&irr, &uv.stretch_mm_per_texel, size, sigmas, &weights);
    let on_cpu = cpu::texture_space::gather(&sum, size, &uvs);
    let (mut close, mut total) = (0usize, 0usize);
    for (a, b) in on_gpu.iter().zip(&on_cpu) {
        for c in 0..4 {
            total += 1;
            close += usize::from((a[c] - b[c]).abs() <= 1.0 / 255.0);
        }
    }
    assert!(close as f64 >= 0.999 * total as f64, "{close} of {total} channels within 1/255");
    // Every gathered uv reaches a covered texel, and the blur keeps irradiance in range.
    assert!(on_gpu.iter().all(|p| p[3] == 1.0 && p[..3].iter().all(|v| (0.0..=1.0).contains(v))));
}

/// The whole `run skin --shader ts` chain on the GPU and on the CPU twins (128² frame, 256² map): within 2/255 on
/// ≥ 99 % of channels, as the other shaders' chains (their G-buffer rasterisers differ on edge pixels).
#[test]
fn ts_chain_gpu_and_cpu_agree() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let ts = TsSettings { map_size: 256, ..Default::default() };
    let s = settings(SkinShader::Ts(ts), 1, 0.6, 128, 128);
    let head = default_head();
    let a = render(Some(&g), &head, &s, &assets).unwrap().data;
    let b = render(None, &head, &s, &assets).unwrap().data;
    let close = a.iter().zip(&b).filter(|(x, y)| x.abs_diff(**y) <= 2).count();
    assert!(close as f64 >= 0.99 * a.len() as f64, "{close} of {} channels within 2/255", a.len());
    let exact = a.iter().zip(&b).filter(|(x, y)| x.abs_diff(**y) <= 1).count();
    eprintln!("GPU vs CPU chain: {:.4} of channels within 1/255", exact as f64 / a.len() as f64);
}

/// Heads entirely outside the frame still have their maps blurred (nothing to gather: an empty uv list) on the
/// GPU, and the frame matches the CPU twin.
#[test]
fn heads_outside_the_frame_render_on_both_paths() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let ts = TsSettings { map_size: 64, ..Default::default() };
    let s = settings(SkinShader::Ts(ts), 5, 0.3, 96, 54);
    let head = default_head();
    let (a, stats) = texture_space::render(Some(&g), &head, &s, ts, &assets).unwrap();
    assert!(stats.heads.iter().any(|h| h.pixels == 0) && stats.heads.iter().any(|h| h.pixels > 0), "{stats:?}");
    let (b, _) = texture_space::render(None, &head, &s, ts, &assets).unwrap();
    let close = a.data.iter().zip(&b.data).filter(|(x, y)| x.abs_diff(**y) <= 2).count();
    assert!(close as f64 >= 0.99 * a.data.len() as f64, "{close} of {}", a.data.len());
}

/// The comparison is fair: with the Gaussians shrunk to 0.1 µm, TS (2048² map) reproduces the no-SSS frame within
/// RMSE 0.003 — its texels are lit as the screen-space shaders' pixels, only the diffusion differs.
#[test]
fn ts_without_diffusion_is_the_no_sss_frame() {
    let g = gpu();
    let mut assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let none = render(Some(&g), &head, &settings(SkinShader::None, 1, 0.6, 320, 180), &assets).unwrap().data;
    for s in assets.blurs.incremental_sigma_mm.iter_mut() {
        *s = 1e-4;
    }
    let ts = SkinShader::Ts(TsSettings { map_size: 2048, ..Default::default() });
    let sharp = render(Some(&g), &head, &settings(ts, 1, 0.6, 320, 180), &assets).unwrap().data;
    let (rmse, psnr) = rmse_psnr(&sharp, &none);
    eprintln!("TS with no diffusion vs no SSS: RMSE {rmse:.5} PSNR {psnr:.1} dB");
    // Measured 0.0023 (52.9 dB), spread thinly over the skin: the G-buffer's f16 uv (2⁻¹¹ steps) against the texel
    // centres where the map samples H0, bilinear gathering of the lit irradiance, and the transmitted light, which
    // the map holds with the shadow map's thickness at each texel's surface point and the pixel at its own (the
    // 6 mm ears change T(s) quickly). A missing light term or a different albedo would be ≥ 0.01.
    assert!(rmse < 0.003, "RMSE {rmse}");
}

/// Error of every shader against the converged reference (TS, 2048² map, no optimisation), 320×180, one head at
/// 0.6 m. The reference is converged: TS at 1024² is within PSNR 55 dB of it and closer than TS at 256². TS at the
/// default map is closer than every screen-space shader; SS Full — with TAP 2009's α = 11, β = 800 and with α at
/// the physical scale — is closer than SS Jittered and no SSS; and, 3 pixels or more inside the
/// silhouette, the physically scaled SS Jittered (taps in mm) is closer than no SSS.
#[test]
fn error_of_each_shader_against_a_converged_ts_reference() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let img = |shader, stretch| {
        let s = SkinRenderSettings { stretch, ..settings(shader, 1, 0.6, 320, 180) };
        render(Some(&g), &head, &s, &assets).unwrap().data
    };
    let ts_at = |map_size| SkinShader::Ts(TsSettings { map_size, ..Default::default() });
    let reference = img(ts_at(2048), StretchPreset::Thesis);
    let inner = interior(&reference, 320, 3);
    let errors: Vec<(&str, (f64, f64), f64)> = [
        ("none", SkinShader::None, StretchPreset::Thesis),
        ("ss-jittered", SkinShader::SsJittered, StretchPreset::Thesis),
        ("ss-full", SkinShader::SsFull, StretchPreset::Thesis),
        ("ss-full tap", SkinShader::SsFull, StretchPreset::Tap2009),
        ("ss-full phys", SkinShader::SsFull, StretchPreset::Physical),
        ("separable", SkinShader::Separable, StretchPreset::Thesis),
        ("ts 1024", ts_at(1024), StretchPreset::Thesis),
        ("ts 256", ts_at(256), StretchPreset::Thesis),
    ]
    .into_iter()
    .map(|(name, shader, stretch)| {
        let i = img(shader, stretch);
        (name, rmse_psnr(&i, &reference), rmse_psnr_over(&i, &reference, &inner).0)
    })
    .collect();
    for (name, (rmse, psnr), inside) in &errors {
        eprintln!("{name:<12} RMSE {rmse:.5} (linear)  PSNR {psnr:.2} dB  RMSE 3 px inside the silhouette {inside:.5}");
    }
    let e = |name: &str| errors.iter().find(|(n, ..)| *n == name).unwrap().1 .0;
    let e_inside = |name: &str| errors.iter().find(|(n, ..)| *n == name).unwrap().2;
    assert!(e("ts 1024") < e("ts 256"), "TS does not converge with the map size");
    assert!(-20.0 * e("ts 1024").log10() > 55.0, "TS 1024 vs 2048: {}", e("ts 1024"));
    for ss in ["none", "ss-jittered", "ss-full", "separable"] {
        assert!(e("ts 1024") < e(ss), "TS 1024 ({}) must be closer than {ss} ({})", e("ts 1024"), e(ss));
    }
    // The requirement, with SS Full as TAP 2009 ran it (α = 11, β = 800, no clamp) and with α at the
    // physical scale: closer than SS Jittered and than no SSS. The thesis' empirical α = 31.5 (a "global level"
    // tuned by eye, §4.2) blurs about three times wider than the physical profile here and is reported, not
    // asserted (README, `run skin`).
    for full in ["ss-full tap", "ss-full phys"] {
        for other in ["ss-jittered", "none"] {
            assert!(e(full) < e(other), "{full} ({}) must be closer than {other} ({})", e(full), e(other));
        }
    }
    // Over the whole head SS Jittered and no SSS are close to the floor of
    // `ts_without_diffusion_is_the_no_sss_frame`; away from the silhouette the physically scaled taps are clearly
    // closer.
    let (j, n) = (e_inside("ss-jittered"), e_inside("none"));
    assert!(j < n, "inside the silhouette: SS Jittered {j} vs none {n}");
}

/// Each ch. 3 optimisation against the unoptimised TS (512² map, 320×180): three heads at 0.45 m (the outer ones
/// partly outside the frame) for culling and clipping, one head at 2 m for the depth-sized map. Each skips the
/// texels it claims and changes the image by less than its stated tolerance (RMSE in linear light over skin:
/// culling 0.002, clipping and all three 0.004 — the texels lost at the 105° and frustum borders; the depth-sized
/// map 0.002 and less than switching SSS off, its map is 286² instead of 512² for a head ~35 pixels tall).
#[test]
fn each_optimisation_skips_work_and_keeps_the_image() {
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let run = |ts: TsSettings, heads, d| {
        let s = settings(SkinShader::Ts(ts), heads, d, 320, 180);
        let (img, stats) = texture_space::render(Some(&g), &head, &s, ts, &assets).unwrap();
        (img.data, stats)
    };
    let base = TsSettings { map_size: 512, ..Default::default() };
    let (ref3, none3) = run(base, 3, 0.45);
    let (ref1, none1) = run(base, 1, 2.0);
    for (name, ts, heads, d, tol) in [
        ("cull", TsSettings { cull: true, ..base }, 3, 0.45, 0.002),
        ("clip", TsSettings { clip: true, ..base }, 3, 0.45, 0.004),
        ("depth", TsSettings { depth_sized: true, ..base }, 1, 2.0, 0.002),
        ("all", TsSettings::optimised(512), 3, 0.45, 0.004),
    ] {
        let (img, stats) = run(ts, heads, d);
        let (reference, plain) = if heads == 3 { (&ref3, &none3) } else { (&ref1, &none1) };
        let (rmse, psnr) = rmse_psnr(&img, reference);
        let ratio = stats.blur_evaluations() as f64 / plain.blur_evaluations() as f64;
        eprintln!(
            "{name:<6} shaded texels {} of {} ({ratio:.3}), map texels {} of {}, RMSE {rmse:.5} PSNR {psnr:.1} dB",
            stats.shaded_texels(),
            plain.shaded_texels(),
            stats.map_texels(),
            plain.map_texels()
        );
        assert!(rmse < tol, "{name}: RMSE {rmse} over the tolerance {tol}");
        assert!(ratio < 0.75, "{name}: blurs {ratio} of the unoptimised");
        let culled: u64 = stats.heads.iter().map(|h| h.culled_texels).sum();
        let clipped: u64 = stats.heads.iter().map(|h| h.clipped_texels).sum();
        assert_eq!(culled > 0, ts.cull, "{name}: culled {culled}");
        assert_eq!(clipped > 0, ts.clip, "{name}: clipped {clipped}");
        if name == "depth" {
            assert!(stats.map_texels() < plain.map_texels(), "{name}: map texels");
            // The depth-sized map changes the image less than switching SSS off does at that distance.
            let none = render(Some(&g), &head, &settings(SkinShader::None, 1, d, 320, 180), &assets).unwrap().data;
            let (none_rmse, _) = rmse_psnr(&none, reference);
            eprintln!("depth: no SSS at {d} m: RMSE {none_rmse:.5}");
            assert!(rmse < none_rmse, "{name}: RMSE {rmse} vs no SSS {none_rmse}");
        }
        if !ts.depth_sized {
            assert_eq!(stats.map_texels(), plain.map_texels(), "{name}: map texels");
        }
    }
}

#[test]
fn bad_ts_input_exits_2_naming_the_flag_and_writes_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out.png");
    let o = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["--shader", "ts", "--ts-map-size", "16"], "--ts-map-size"),
        (vec!["--shader", "ts", "--ts-map-size", "4096"], "--ts-map-size"),
        (vec!["--shader", "ts", "--ts-map-size", "-1"], "--ts-map-size"),
        (vec!["--shader", "ts", "--ts-opt", "none,cull"], "--ts-opt"),
        (vec!["--shader", "ts", "--ts-opt", "fast"], "--ts-opt"),
        (vec!["--shader", "ss-full", "--ts-map-size", "512"], "--ts-map-size"),
        (vec!["--shader", "none", "--ts-opt", "cull"], "--ts-opt"),
    ] {
        let mut a = vec!["run", "skin", "--cpu", "--width", "64", "--height", "64", "--output", o];
        a.extend_from_slice(&args);
        let r = rtbake(&a);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} wrote {o}");
    }
}
