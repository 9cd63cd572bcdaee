//! `rtbake maps …` end to end: a rig baked from the fixtures evaluates back to the neutral map, wrinkles and
//! masks convert, and every kind of bad input exits 2 naming the flag/file with nothing written.

use rtbake::image_buf::Image;
use std::path::{Path, PathBuf};
use std::process::Output;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/facial/hemoglobin_{name}.png"))
}

use crate::support::rtbake;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs a command that must fail with exit 2, mention every `needle` and leave `out` absent.
fn assert_bad(args: &[&str], needles: &[&str], out: &Path) {
    let o = rtbake(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}\nstderr: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: stderr should mention '{n}':\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{args:?}: {} must not be written", out.display());
}

fn write_png16(path: &Path, w: u32, h: u32, ch: u32, v: u16) {
    let img = Image::from_vec(w, h, ch, vec![v; (w * h * ch) as usize]);
    std::fs::write(path, rtbake::io::png::encode_u16(&img).unwrap()).unwrap();
}

#[test]
fn hemoglobin_rig_bakes_and_evaluates_back_to_the_neutral_map() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rig");
    let o = rtbake(&[
        "maps",
        "hemoglobin",
        "--neutral",
        s(&fixture("neutral")),
        "--target",
        &format!("anger={}", s(&fixture("anger"))),
        "--target",
        &format!("fear={}", s(&fixture("fear"))),
        "--radius",
        "4",
        "--rig-size",
        "16",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for f in ["rig.json", "h0.exr", "h0.ktx2", "anger_scale.exr", "fear_bias_f16.exr", "neutral_scale_bias.ktx2"] {
        assert!(out.join(f).is_file(), "missing {f}");
    }
    let h = dir.path().join("h.exr");
    let rig = out.join("rig.json");
    let o = rtbake(&["maps", "rig-eval", "--rig", s(&rig), "--weights", "neutral=1", "--out", s(&h)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (img, _) = rtbake::io::exr::decode(&std::fs::read(&h).unwrap(), "h").unwrap();
    let neutral = match rtbake::io::png::decode(&std::fs::read(fixture("neutral")).unwrap(), "n").unwrap() {
        rtbake::io::png::DecodedPng::U16(i) => i,
        _ => unreachable!(),
    };
    for (a, &b) in img.data.iter().zip(&neutral.data) {
        let b = (b as f64 / 65535.0) as f32;
        assert!((a - b).abs() <= 1e-7, "{a} vs {b}");
    }
    // Weights must sum to 1 unless normalised; unknown names are refused.
    let h2 = dir.path().join("h2.exr");
    assert_bad(
        &["maps", "rig-eval", "--rig", s(&rig), "--weights", "anger=0.7,neutral=0.2", "--out", s(&h2)],
        &["--weights", "sum to 1"],
        &h2,
    );
    assert_bad(
        &["maps", "rig-eval", "--rig", s(&rig), "--weights", "joy=1", "--out", s(&h2)],
        &["--weights", "unknown target 'joy'"],
        &h2,
    );
    assert_bad(
        &["maps", "rig-eval", "--rig", s(&rig), "--weights", "anger=x", "--out", s(&h2)],
        &["--weights", "not a number"],
        &h2,
    );
    let o = rtbake(&[
        "maps",
        "rig-eval",
        "--rig",
        s(&rig),
        "--weights",
        "anger=0.7,neutral=0.2",
        "--normalize-weights",
        "--out",
        s(&h2),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // A rig whose files are missing is bad input naming the file.
    std::fs::remove_file(out.join("fear_bias.exr")).unwrap();
    let h3 = dir.path().join("h3.exr");
    assert_bad(
        &["maps", "rig-eval", "--rig", s(&rig), "--weights", "neutral=1", "--out", s(&h3)],
        &["fear_bias.exr"],
        &h3,
    );
    let missing = dir.path().join("nope.json");
    assert_bad(
        &["maps", "rig-eval", "--rig", s(&missing), "--weights", "neutral=1", "--out", s(&h3)],
        &["--rig", "nope.json"],
        &h3,
    );
}

#[test]
fn hemoglobin_bad_inputs_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let n = fixture("neutral");
    let a = fixture("anger");
    let target = format!("anger={}", s(&a));
    let base = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> =
            ["maps", "hemoglobin", "--neutral", s(&n), "--out", s(&out)].iter().map(|x| x.to_string()).collect();
        v.extend(extra.iter().map(|x| x.to_string()));
        v
    };
    let run = |extra: &[&str], needles: &[&str]| {
        let args = base(extra);
        let refs: Vec<&str> = args.iter().map(|x| x.as_str()).collect();
        assert_bad(&refs, needles, &out);
    };
    // Radius 0 or larger than the map allows (64² → max 31).
    run(&["--target", &target, "--radius", "0"], &["--radius", "1..=31"]);
    run(&["--target", &target, "--radius", "40"], &["--radius", "got 40"]);
    // Unknown / reserved / malformed target names.
    run(&["--target", &format!("neutral={}", s(&a)), "--radius", "4"], &["--target", "reserved"]);
    run(&["--target", &format!("Anger!={}", s(&a)), "--radius", "4"], &["--target", "[a-z0-9_-]"]);
    run(&["--target", s(&a), "--radius", "4"], &["--target", "NAME=VALUE"]);
    run(&["--target", &target, "--target", &target, "--radius", "4"], &["given twice"]);
    // Maps of different sizes.
    let small = dir.path().join("small.png");
    write_png16(&small, 32, 32, 1, 3000);
    run(
        &["--target", &format!("fear={}", s(&small)), "--radius", "4"],
        &["--target fear", "small.png", "32x32", "64x64"],
    );
    // Wrong channel count.
    let rgb = dir.path().join("rgb.png");
    write_png16(&rgb, 64, 64, 3, 3000);
    run(&["--target", &format!("fear={}", s(&rgb)), "--radius", "4"], &["rgb.png", "single-channel", "3 channels"]);
    // 8-bit map without a declared value range; with one it is accepted (checked below).
    let gray8 = dir.path().join("gray8.png");
    let img8 = Image::from_vec(64, 64, 1, (0..64 * 64).map(|i| (i % 200) as u8).collect::<Vec<u8>>());
    std::fs::write(&gray8, rtbake::io::png::encode_u8(&img8).unwrap()).unwrap();
    run(&["--target", &format!("fear={}", s(&gray8)), "--radius", "4"], &["gray8.png", "--value-range"]);
    run(&["--target", &target, "--radius", "4", "--value-range", "0.5,0.1"], &["--value-range", "MIN < MAX"]);
    // NaN texels in an EXR.
    let nan = dir.path().join("nan.exr");
    let mut v = vec![0.05f32; 64 * 64];
    v[64 * 3 + 5] = f32::NAN;
    std::fs::write(
        &nan,
        rtbake::io::exr::encode(&Image::from_vec(64, 64, 1, v), rtbake::io::exr::ExrPrecision::F32).unwrap(),
    )
    .unwrap();
    run(&["--target", &format!("fear={}", s(&nan)), "--radius", "4"], &["nan.exr", "texel (5, 3)", "NaN"]);
    // Missing and corrupt files.
    let missing = dir.path().join("missing.exr");
    run(
        &["--target", &format!("fear={}", s(&missing)), "--radius", "4"],
        &["--target fear", "missing.exr", "cannot read"],
    );
    let corrupt = dir.path().join("corrupt.png");
    let mut bytes = std::fs::read(&a).unwrap();
    bytes.truncate(bytes.len() / 2);
    std::fs::write(&corrupt, bytes).unwrap();
    run(&["--target", &format!("fear={}", s(&corrupt)), "--radius", "4"], &["corrupt.png", "corrupt"]);
    let text = dir.path().join("text.png");
    std::fs::write(&text, b"hello").unwrap();
    run(&["--target", &format!("fear={}", s(&text)), "--radius", "4"], &["text.png", "not a PNG or OpenEXR"]);
    // Bad sigma floor.
    run(&["--target", &target, "--radius", "4", "--sigma-floor", "0"], &["--sigma-floor"]);
    // The 8-bit map with a range works, next to an f16 EXR target (comma-separated pairs are accepted).
    let f16 = dir.path().join("anger_f16.exr");
    let anger16 = rtbake::facial::inputs::decode_concentration("t", "a", &std::fs::read(&a).unwrap(), None).unwrap();
    std::fs::write(&f16, rtbake::io::exr::encode(&anger16.image, rtbake::io::exr::ExrPrecision::F16).unwrap()).unwrap();
    let pair = format!("fear={},anger={}", s(&gray8), s(&f16));
    let args = base(&["--target", &pair, "--radius", "4", "--value-range", "0,0.32"]);
    let refs: Vec<&str> = args.iter().map(|x| x.as_str()).collect();
    let o = rtbake(&refs);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let desc: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("rig.json")).unwrap()).unwrap();
    assert_eq!(desc["maps"][1]["source"]["mapping"], "concentration = 0 + (0.32 - 0) * s / 255");
    assert_eq!(desc["maps"][2]["source"]["format"], "exr-f16");
}

fn write_normal_png(path: &Path, w: u32, h: u32, ch: u32, n: [f64; 3]) {
    let px: Vec<u8> = n.iter().map(|c| ((0.5 + 0.5 * c) * 255.0).round() as u8).collect();
    let mut data = Vec::new();
    for _ in 0..w * h {
        data.extend_from_slice(&px[..3]);
        if ch == 4 {
            data.push(255);
        }
    }
    std::fs::write(path, rtbake::io::png::encode_u8(&Image::from_vec(w, h, ch, data)).unwrap()).unwrap();
}

#[test]
fn wrinkles_and_masks() {
    let dir = tempfile::tempdir().unwrap();
    let normal = dir.path().join("n.png");
    let base = dir.path().join("b.png");
    write_normal_png(&normal, 32, 32, 3, [0.3, 0.2, 0.932_737_905]);
    write_normal_png(&base, 32, 32, 4, [0.0, 0.0, 1.0]);
    let out = dir.path().join("w");
    let o = rtbake(&["maps", "wrinkles", "--normal", s(&normal), "--size", "16", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rg = std::fs::read(out.join("wrinkle_pd.bin")).unwrap();
    assert_eq!(rg.len(), 16 * 16 * 2);
    // pd = (0.3/0.9327, 0.2/0.9327) → 0.5 + 0.5·pd in 8 bits.
    let want = |v: f64| ((0.5 + 0.5 * v) * 255.0).round() as u8;
    assert!((rg[0] as i32 - want(0.3 / 0.932_737_905) as i32).abs() <= 1);
    assert!((rg[1] as i32 - want(0.2 / 0.932_737_905) as i32).abs() <= 1);
    // OpenGL input flips green.
    let out_gl = dir.path().join("wgl");
    let o = rtbake(&["maps", "wrinkles", "--normal", s(&normal), "--green", "opengl", "--out", s(&out_gl)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rg_gl = std::fs::read(out_gl.join("wrinkle_pd.bin")).unwrap();
    assert!((rg_gl[1] as i32 - want(-0.2 / 0.932_737_905) as i32).abs() <= 1);
    // Difference encoding needs --base.
    let out_d = dir.path().join("d");
    assert_bad(
        &["maps", "wrinkles", "--normal", s(&normal), "--encoding", "difference", "--out", s(&out_d)],
        &["--base"],
        &out_d,
    );
    let o = rtbake(&[
        "maps",
        "wrinkles",
        "--normal",
        s(&normal),
        "--base",
        s(&base),
        "--encoding",
        "difference",
        "--out",
        s(&out_d),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read(out_d.join("wrinkle_difference.bin")).unwrap().len(), 32 * 32 * 4);
    // Bad inputs: wrong channel count, different sizes, cone rejection, missing file.
    let gray = dir.path().join("gray.png");
    write_png16(&gray, 32, 32, 1, 100);
    let out_bad = dir.path().join("bad");
    assert_bad(
        &["maps", "wrinkles", "--normal", s(&gray), "--out", s(&out_bad)],
        &["--normal", "gray.png", "3 (RGB) or 4"],
        &out_bad,
    );
    let big = dir.path().join("big.png");
    write_normal_png(&big, 64, 32, 3, [0.0, 0.0, 1.0]);
    assert_bad(
        &["maps", "wrinkles", "--normal", s(&normal), "--base", s(&big), "--out", s(&out_bad)],
        &["--base", "64x32"],
        &out_bad,
    );
    let steep = dir.path().join("steep.png");
    write_normal_png(&steep, 8, 8, 3, [0.9, 0.0, 0.436]);
    assert_bad(
        &["maps", "wrinkles", "--normal", s(&steep), "--cone", "reject", "--out", s(&out_bad)],
        &["--normal", "64 texels", "45° cone"],
        &out_bad,
    );
    let o = rtbake(&["--json", "maps", "wrinkles", "--normal", s(&steep), "--out", s(&out_bad)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["wrinkle"]["cone_clamped_texels"], 64);
    let out_m = dir.path().join("m");
    assert_bad(
        &["maps", "wrinkles", "--normal", s(&dir.path().join("x.png")), "--out", s(&out_m)],
        &["--normal", "x.png"],
        &out_m,
    );

    // Masks.
    let m1 = dir.path().join("m1.png");
    write_png16(&m1, 32, 32, 1, 65535);
    let o = rtbake(&[
        "maps",
        "wrinkle-masks",
        "--zone",
        &format!("red={}", s(&m1)),
        "--zone",
        &format!("gray={}", s(&m1)),
        "--size",
        "8",
        "--out",
        s(&out_m),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let t0 = std::fs::read(out_m.join("wrinkle_masks_0.bin")).unwrap();
    let t1 = std::fs::read(out_m.join("wrinkle_masks_1.bin")).unwrap();
    assert_eq!((t0.len(), &t0[..4], &t1[..4]), (8 * 8 * 4, &[255u8, 0, 0, 0][..], &[0u8, 0, 0, 255][..]));
    let out_m2 = dir.path().join("m2");
    assert_bad(
        &["maps", "wrinkle-masks", "--zone", &format!("purple={}", s(&m1)), "--out", s(&out_m2)],
        &["--zone", "unknown zone 'purple'"],
        &out_m2,
    );
    let m2 = dir.path().join("m2.png");
    write_png16(&m2, 16, 16, 1, 0);
    assert_bad(
        &[
            "maps",
            "wrinkle-masks",
            "--zone",
            &format!("red={}", s(&m1)),
            "--zone",
            &format!("blue={}", s(&m2)),
            "--out",
            s(&out_m2),
        ],
        &["--zone blue", "16x16"],
        &out_m2,
    );
}

#[test]
fn synthetic_command_writes_the_fixtures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("syn");
    let o = rtbake(&[
        "maps",
        "synthetic",
        "--size",
        "64",
        "--seed",
        "1",
        "--targets",
        "joy,anger,fear,disgust",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for n in ["neutral", "joy", "anger", "fear", "disgust"] {
        assert_eq!(std::fs::read(out.join(format!("{n}.png"))).unwrap(), std::fs::read(fixture(n)).unwrap(), "{n}");
    }
    let bad = dir.path().join("bad");
    assert_bad(
        &["maps", "synthetic", "--targets", "smile", "--out", s(&bad)],
        &["--targets", "unknown synthetic expression 'smile'"],
        &bad,
    );
}

/// Appearance transfer (thesis §7.4.2): `rig-eval --neutral OTHER` with the neutral weight gives OTHER back, with a
/// target it gives OTHER's detail under the subject's change (not the subject's own map); a neutral map of the
/// wrong size exits 2 naming `--neutral`, nothing written.
#[test]
fn rig_eval_transfers_the_rig_to_another_neutral_map() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rig");
    let anger = format!("anger={}", s(&fixture("anger")));
    let neutral_fixture = fixture("neutral");
    let args = ["maps", "hemoglobin", "--neutral", s(&neutral_fixture), "--target", &anger, "--radius", "4"];
    let o = rtbake(&[&args[..], &["--rig-size", "16", "--out", s(&out)]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Another character: the subject's neutral map mirrored left to right, 10 % more blood.
    let subject = match rtbake::io::png::decode(&std::fs::read(fixture("neutral")).unwrap(), "n").unwrap() {
        rtbake::io::png::DecodedPng::U16(i) => i,
        _ => unreachable!(),
    };
    let (w, h) = (subject.width, subject.height);
    let mut other = subject.clone();
    for y in 0..h {
        for x in 0..w {
            let v = subject.data[(y * w + (w - 1 - x)) as usize] as f64 * 1.1;
            other.data[(y * w + x) as usize] = v.min(65535.0) as u16;
        }
    }
    let other_png = dir.path().join("other.png");
    std::fs::write(&other_png, rtbake::io::png::encode_u16(&other).unwrap()).unwrap();
    let rig = out.join("rig.json");
    let eval = |weights: &str, neutral: Option<&Path>, name: &str| -> Vec<f32> {
        let path = dir.path().join(name);
        let mut a = vec!["maps", "rig-eval", "--rig", s(&rig), "--weights", weights, "--out", s(&path)];
        if let Some(n) = neutral {
            a.extend_from_slice(&["--neutral", s(n)]);
        }
        let o = rtbake(&a);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        rtbake::io::exr::decode(&std::fs::read(&path).unwrap(), "h").unwrap().0.data
    };
    let back = eval("neutral=1", Some(&other_png), "b.exr");
    let worst = back.iter().zip(&other.data).map(|(a, &b)| (a - b as f32 / 65535.0).abs()).fold(0.0f32, f32::max);
    assert!(worst < 1e-6, "the neutral weight reproduces the other map: {worst}");
    let angry_other = eval("anger=1", Some(&other_png), "a.exr");
    let angry_subject = eval("anger=1", None, "s.exr");
    let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    // The subject's mean change carries over; the detail is the other character's (mirrored), not the subject's.
    let other_mean = mean(&other.data.iter().map(|&v| v as f32 / 65535.0).collect::<Vec<_>>());
    let subject_mean = mean(&subject.data.iter().map(|&v| v as f32 / 65535.0).collect::<Vec<_>>());
    let (shift_other, shift_subject) = (mean(&angry_other) - other_mean, mean(&angry_subject) - subject_mean);
    assert!(
        (shift_other - shift_subject).abs() < 0.05 * shift_subject.abs().max(1e-4),
        "{shift_other} vs {shift_subject}"
    );
    let differs = angry_other.iter().zip(&angry_subject).filter(|(a, b)| (*a - *b).abs() > 1e-3).count();
    assert!(differs > angry_other.len() / 4, "{differs} of {} texels differ", angry_other.len());

    let small = dir.path().join("small.png");
    write_png16(&small, w / 2, h / 2, 1, 3000);
    let none = dir.path().join("none.exr");
    assert_bad(
        &["maps", "rig-eval", "--rig", s(&rig), "--weights", "anger=1", "--neutral", s(&small), "--out", s(&none)],
        &["--neutral", &format!("must be {w}x{h}")],
        &none,
    );
}
