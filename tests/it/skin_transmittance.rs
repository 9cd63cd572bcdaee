//! `run skin --transmittance off|green|shadow-map` (thesis §5.3, §5.6): Green's Beer–Lambert T(s) tabulated as the
//! skin-inputs pass reads it, the light it adds only ever brightening the frame, GPU and CPU twin agreeing, and the
//! flag on the command line.

use crate::support::{baked_dir, gpu, rtbake};
use rtbake::mesh::head::default_head;
use rtbake::runtime::demo::DemoAssets;
use rtbake::runtime::skin::lighting::{SceneLights, TransmittanceMode};
use rtbake::runtime::skin_passes::SkinPasses;
use rtbake::runtime::skin_render::{render_with, SkinRenderSettings, SkinShader, StretchPreset};

fn settings() -> SkinRenderSettings {
    SkinRenderSettings {
        shader: SkinShader::Separable,
        heads: 1,
        distance_m: 0.6,
        width: 160,
        height: 120,
        melanin: 0.02,
        stretch: StretchPreset::Thesis,
    }
}

#[test]
fn green_table_is_beer_lambert_and_off_is_zero() {
    let base = DemoAssets::load(&baked_dir()).unwrap();
    let mut green = base.clone();
    green.set_transmittance(TransmittanceMode::green_skin1());
    let n = green.luts.transmittance.len();
    assert_eq!(n, base.luts.transmittance.len());
    let s_max = green.luts.s_max_mm as f64;
    // skin1 (Jensen et al. 2001): σt′ = σa + σs′ = (0.772, 1.05, 1.49) mm⁻¹.
    let sigma_t = [0.032 + 0.74, 0.17 + 0.88, 0.48 + 1.01];
    for (i, t) in green.luts.transmittance.iter().enumerate() {
        let s = s_max * i as f64 / (n - 1) as f64;
        for c in 0..3 {
            assert!((t[c] as f64 - (-s * sigma_t[c]).exp()).abs() < 1e-6, "texel {i} channel {c}");
        }
    }
    assert_eq!(green.luts.transmittance[0], [1.0; 3]);
    // Red travels furthest through skin.
    let last = green.luts.transmittance[n - 1];
    assert!(last[0] > last[1] && last[1] > last[2]);
    let mut off = base.clone();
    off.set_transmittance(TransmittanceMode::Off);
    assert!(off.luts.transmittance.iter().all(|t| *t == [0.0; 3]));
    let mut same = base.clone();
    same.set_transmittance(TransmittanceMode::ShadowMap);
    assert_eq!(same.luts.transmittance, base.luts.transmittance);
}

#[test]
fn transmitted_light_only_adds_and_gpu_matches_cpu() {
    let g = gpu();
    let base = DemoAssets::load(&baked_dir()).unwrap();
    let head = default_head();
    let s = settings();
    let frame = |mode: TransmittanceMode, on_gpu: bool| {
        let mut a = base.clone();
        a.set_transmittance(mode);
        // TAP's light almost behind the head (150°): the ears and the silhouette let light through.
        a.lights = SceneLights::single(150.0, 45.0, &s.camera()).unwrap();
        let backend = if on_gpu { Some(&g) } else { None };
        render_with(backend, &head, &s, &SkinPasses::none(), &a).unwrap().data
    };
    let (shadow, green, off) = (
        frame(TransmittanceMode::ShadowMap, false),
        frame(TransmittanceMode::green_skin1(), false),
        frame(TransmittanceMode::Off, false),
    );
    let sum = |p: &[u8]| p[..3].iter().map(|&c| c as i32).sum::<i32>();
    let (mut lit_s, mut lit_g) = (0, 0);
    for ((a, b), c) in shadow.chunks(4).zip(green.chunks(4)).zip(off.chunks(4)) {
        // Off never brighter than either mode (1/255 per channel of rounding).
        assert!(sum(c) <= sum(a) + 3 && sum(c) <= sum(b) + 3, "{a:?} {b:?} {c:?}");
        lit_s += (sum(a) > sum(c) + 3) as usize;
        lit_g += (sum(b) > sum(c) + 3) as usize;
    }
    assert!(lit_s > 20 && lit_g > 20, "pixels brightened: shadow-map {lit_s}, green {lit_g}");
    assert!(shadow != green, "the two laws give different frames");
    let on_gpu = frame(TransmittanceMode::green_skin1(), true);
    let close = on_gpu.iter().zip(&green).filter(|(x, y)| x.abs_diff(**y) <= 2).count();
    assert!(close as f64 >= 0.99 * green.len() as f64, "{close} of {} channels within 2/255", green.len());
}

#[test]
fn the_transmittance_flag_is_reported_and_checked() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("t.png");
    let o_s = out.to_str().unwrap();
    let base = ["--json", "run", "skin", "--cpu", "--width", "48", "--height", "36", "--output", o_s];
    let o = rtbake(&[&base[..], &["--transmittance", "green"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["transmittance"], "green");
    std::fs::remove_file(&out).unwrap();
    let o = rtbake(&[&base[..], &["--transmittance", "beer"]].concat());
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--transmittance"));
    assert!(!out.exists());
}
