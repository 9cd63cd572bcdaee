//! `rtbake importance-kernel` (an importance-sampled disk kernel of any profile; files and their
//! consumers) and `rtbake run sss --method importance`; bad input exits 2 naming the flag and writes nothing.

use crate::support::rtbake;
use rtbake::image_buf::Image;
use rtbake::io::exr::{encode, ExrPrecision};
use serde_json::Value;
use wgpu::naga;

/// The WGSL include followed by an entry point that reads every constant (arrays with a run-time index).
fn naga_check(src: &str) {
    let mut body = String::new();
    for l in src.lines().filter_map(|l| l.strip_prefix("const ")) {
        let (name, ty) = l.split_once(':').unwrap();
        let ty = ty.split('=').next().unwrap().trim();
        match ty.strip_prefix("array<") {
            Some(a) => {
                let n: u32 = a.trim_end_matches('>').rsplit(',').next().unwrap().trim().parse().unwrap();
                body.push_str(&format!("    var a_{0} = {0};\n    _ = a_{0}[id.x % {n}u];\n", name.trim()));
            }
            None => body.push_str(&format!("    _ = {};\n", name.trim())),
        }
    }
    let text = format!(
        "{src}\n@compute @workgroup_size(1)\nfn check(@builtin(global_invocation_id) id: vec3<u32>) {{\n{body}}}\n"
    );
    let module = naga::front::wgsl::parse_str(&text).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&text)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&text)));
}

#[test]
fn importance_kernel_writes_json_includes_and_table() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("k");
    let o = rtbake(&[
        "--json",
        "importance-kernel",
        "--samples",
        "40",
        "--burley-albedo",
        "0.8,0.5,0.3",
        "--burley-mfp-mm",
        "1,0.5,0.25",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let printed: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(printed["files"].as_array().unwrap().len(), 5);
    let v: Value = serde_json::from_slice(&std::fs::read(out.join("burley_n40.json")).unwrap()).unwrap();
    assert_eq!(v["schema"], rtbake::baked_layout::schema::IMPORTANCE_KERNEL);
    assert_eq!(v["samples"], 40);
    assert_eq!(v["inversion"], "burley-closed-form");
    assert_eq!(v["sampled_channel"], "red");
    assert_eq!(v["profile"]["model"], "burley");
    let samples = v["kernel"].as_array().unwrap();
    assert_eq!(samples.len(), 40);
    for c in 0..3 {
        let s: f64 = samples.iter().map(|s| s["weight"][c].as_f64().unwrap()).sum();
        assert!((s - 1.0).abs() < 1e-6, "channel {c}: {s}");
    }
    // The binary table: 40 records of 8 little-endian f32, as the JSON's layout says.
    assert!(v["binary_layout"].as_str().unwrap().contains("[x_mm, y_mm, r_mm, theta_rad, pdf_per_mm2, w_r, w_g, w_b]"));
    let bin = std::fs::read(out.join("burley_n40_f32x8.bin")).unwrap();
    assert_eq!(bin.len(), 40 * 8 * 4);
    let f = |i: usize| f32::from_le_bytes(bin[4 * i..4 * i + 4].try_into().unwrap()) as f64;
    for (i, s) in samples.iter().enumerate() {
        assert!((f(8 * i + 2) - s["r_mm"].as_f64().unwrap()).abs() <= 1e-6 * f(8 * i + 2).max(1e-3));
        assert!((f(8 * i + 6) - s["weight"][1].as_f64().unwrap()).abs() <= 1e-7);
    }
    // The includes: WGSL through naga; HLSL/GLSL declare the same arrays.
    let wgsl = std::fs::read_to_string(out.join("burley_n40.wgsl")).unwrap();
    assert!(wgsl.contains("const SSS_IMPORTANCE_OFFSETS: array<vec4<f32>, 40>"), "{wgsl}");
    naga_check(&wgsl);
    let hlsl = std::fs::read_to_string(out.join("burley_n40.hlsl")).unwrap();
    assert!(hlsl.contains("static const float3 SSS_IMPORTANCE_WEIGHTS[40] = {"));
    let glsl = std::fs::read_to_string(out.join("burley_n40.glsl")).unwrap();
    assert!(glsl.contains("const int SSS_IMPORTANCE_N_SAMPLES = 40;"));
}

#[test]
fn importance_kernel_accepts_every_profile_flag() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("p.csv");
    let o = rtbake(&["profile", "--material", "skin1", "--csv", csv.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    for args in [
        vec!["--material", "skin1"],
        vec!["--profile-preset", "deon6"],
        vec!["--profile-csv", csv.to_str().unwrap()],
        vec!["--skin-melanin", "0.1", "--skin-hemoglobin", "0.05"],
    ] {
        let mut a = vec!["--json", "importance-kernel", "--samples", "20"];
        a.extend(&args);
        let o = rtbake(&a);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        let v: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["inversion"], "tabulated-cdf", "{args:?}");
        assert!(v["cutoff_mm"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn importance_kernel_bad_input_exits_2_naming_the_flag_and_writes_nothing() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("k");
    let o_s = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--samples", "0", "--material", "skin1"], "--samples"),
        (vec!["--samples", "1025", "--material", "skin1"], "1..=1024"),
        (vec!["--samples", "-3", "--material", "skin1"], "--samples"),
        (vec!["--samples", "20"], "give exactly one profile"),
        (vec!["--samples", "20", "--material", "skin1", "--profile-preset", "deon6"], "give exactly one profile"),
        (vec!["--samples", "20", "--material", "unobtainium"], "--material"),
        (vec!["--samples", "20", "--profile-preset", "deon9"], "--profile-preset"),
        (vec!["--samples", "20", "--burley-albedo", "0.8,0,0.3", "--burley-mfp-mm", "1,1,1"], "--burley-albedo"),
        (vec!["--samples", "20", "--burley-albedo", "0.8,0.5,0.3", "--burley-mfp-mm", "1,-1,1"], "--burley-mfp-mm"),
        (vec!["--samples", "20", "--profile-csv", "/nonexistent/p.csv"], "--profile-csv"),
    ];
    for (args, needle) in cases {
        let mut a = vec!["importance-kernel", "--out", o_s];
        a.extend(&args);
        let o = rtbake(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        let written = std::fs::read_dir(&out).map(|d| d.count()).unwrap_or(0);
        assert_eq!(written, 0, "{args:?} wrote files");
    }
}

fn write_exr(path: &std::path::Path, img: &Image<f32>) {
    std::fs::write(path, encode(img, ExrPrecision::F32).unwrap()).unwrap();
}

#[test]
fn importance_run_sss_matches_the_library_and_refuses_mixed_flags() {
    let t = tempfile::tempdir().unwrap();
    let (w, h) = (48u32, 32u32);
    let mut rgba = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let lit = if (x / 4 + y / 4) % 2 == 0 { 1.0 } else { 0.1 };
            rgba.extend_from_slice(&[0.9 * lit, 0.6 * lit, 0.4 * lit, if x < 40 { 1.0 } else { 0.0 }]);
        }
    }
    let depth = vec![0.5f32; (w * h) as usize];
    let (c, d, out) = (t.path().join("c.exr"), t.path().join("d.exr"), t.path().join("o.exr"));
    write_exr(&c, &Image::from_vec(w, h, 4, rgba.clone()));
    write_exr(&d, &Image::from_vec(w, h, 1, depth.clone()));
    let (cs, ds, os) = (c.to_str().unwrap(), d.to_str().unwrap(), out.to_str().unwrap());
    let base = ["run", "sss", "--cpu", "--color", cs, "--depth", ds, "--output", os];
    let mut a = base.to_vec();
    a.extend(["--method", "importance", "--samples", "20", "--profile-preset", "deon6"]);
    let o = rtbake(&a);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let (got, _) = rtbake::io::exr::decode(&std::fs::read(&out).unwrap(), "o.exr").unwrap();
    let g = rtbake::diffusion::sum_of_gaussians::deon6();
    let k =
        rtbake::sss_sampling::ImportanceKernel::new(rtbake::sss_sampling::SampledProfile::Tabulated(&g), 20).unwrap();
    let samples = rtbake::runtime::importance_sss::ImportanceSamples::from_kernel(&k);
    let params = rtbake::runtime::importance_sss::ImportanceSssParams::default();
    let method = rtbake::runtime::chain::Subsurface::Importance { samples: &samples, params: &params };
    let want = rtbake::runtime::chain::subsurface(None, &rgba, &depth, (w, h), &method).unwrap();
    assert_eq!(got.data.len(), want.len());
    let max = got.data.iter().zip(&want).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(max < 1e-3, "max difference {max}");
    assert!(got.data.iter().zip(&rgba).any(|(a, b)| (a - b).abs() > 0.05), "the blur did something");
    std::fs::remove_file(&out).unwrap();
    // The baked deon6 kernel of 20 samples, read through the manifest, gives the same frame (its JSON holds 9
    // significant digits, so the f32 samples may differ in the last bit).
    let baked = crate::support::baked_dir();
    let mut a = base.to_vec();
    a.extend([
        "--method",
        "importance",
        "--importance-kernel",
        "sss/importance/deon6_n20.json",
        "--baked-dir",
        baked.to_str().unwrap(),
    ]);
    let o = rtbake(&a);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let (from_bake, _) = rtbake::io::exr::decode(&std::fs::read(&out).unwrap(), "o.exr").unwrap();
    let max = from_bake.data.iter().zip(&got.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    assert!(max < 1e-5, "baked kernel vs computed kernel: max difference {max}");
    std::fs::remove_file(&out).unwrap();
    for (extra, needle) in [
        (vec!["--method", "separable", "--samples", "20"], "--method importance"),
        (vec!["--method", "importance"], "give exactly one profile"),
        (vec!["--method", "importance", "--material", "skin1", "--samples", "0"], "--samples"),
        (vec!["--method", "importance", "--material", "skin1", "--mm-per-world-unit", "0"], "--mm-per-world-unit"),
        (vec!["--importance-kernel", "sss/importance/deon6_n20.json"], "--method importance"),
        (
            vec!["--method", "importance", "--importance-kernel", "sss/importance/deon6_n20.json", "--samples", "20"],
            "--importance-kernel",
        ),
        (
            vec![
                "--method",
                "importance",
                "--importance-kernel",
                "sss/importance/nothing_n20.json",
                "--baked-dir",
                baked.to_str().unwrap(),
            ],
            "nothing_n20",
        ),
    ] {
        let mut a = base.to_vec();
        a.extend(&extra);
        let o = rtbake(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} wrote the output");
    }
}

/// The importance-kernel loader's content checks (what a kernel file edited together with its manifest hash would
/// still have to pass): a wrong schema, a count that disagrees, an offset whose length is not its radius, a channel
/// whose weights do not sum to 1 — each refused naming the file and the defect; the baked file itself loads.
#[test]
fn importance_kernel_loader_refuses_inconsistent_kernels() {
    use rtbake::runtime::loader::importance_kernel_from_json;
    let baked = crate::support::baked_dir();
    let path = "sss/importance/deon6_n20.json";
    let good: serde_json::Value = serde_json::from_slice(&std::fs::read(baked.join(path)).unwrap()).unwrap();
    let k = importance_kernel_from_json(&good, path).unwrap();
    assert_eq!(k.offsets_mm.len(), 20);
    type Edit<'a> = (&'a str, &'a dyn Fn(&mut serde_json::Value));
    let edits: [Edit; 4] = [
        ("schema", &|v| v["schema"] = "rtbake-separable-kernel/1".into()),
        ("\"samples\" = 21", &|v| v["samples"] = 21.into()),
        ("kernel[3]", &|v| v["kernel"][3]["r_mm"] = 9.0.into()),
        ("channel g", &|v| v["kernel"][0]["weight"][1] = 0.9.into()),
    ];
    for (needle, edit) in edits {
        let mut v = good.clone();
        edit(&mut v);
        let err = importance_kernel_from_json(&v, path).unwrap_err().to_string();
        assert!(err.contains(needle) && err.contains("deon6_n20"), "{needle}: {err}");
    }
}

/// Every baked importance-kernel include compiles where a shader author pastes it: the GLSL include in a GLSL 4.50
/// fragment shader and the HLSL include in an HLSL pixel shader, both through glslangValidator (Khronos' reference
/// front end; `.ci/run` installs it), each reading the arrays so they are not dead code.
#[test]
fn baked_importance_includes_compile_with_glslang() {
    if !crate::support::tool_available(
        "importance include compile",
        "glslangValidator",
        &["--version"],
        "apt-get install glslang-tools",
    ) {
        return;
    }
    let baked = crate::support::baked_dir();
    let t = tempfile::tempdir().unwrap();
    let spv = t.path().join("k.spv");
    let mut compiled = 0;
    for dir in ["sss/importance", "burley/kernels"] {
        for entry in std::fs::read_dir(baked.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or_default().to_string();
            if ext != "glsl" && ext != "hlsl" {
                continue;
            }
            let body = std::fs::read_to_string(&path).unwrap();
            let (src, args): (String, Vec<&str>) = match ext.as_str() {
                "glsl" => (
                    format!(
                        "#version 450\n{body}\nlayout(location = 0) out vec4 o;\nvoid main() {{\n    o = vec4(SSS_IMPORTANCE_WEIGHTS[SSS_IMPORTANCE_N_SAMPLES - 1] * SSS_IMPORTANCE_OFFSETS[0].z, SSS_IMPORTANCE_CUTOFF_MM);\n}}\n"
                    ),
                    vec!["-S", "frag"],
                ),
                "hlsl" => (
                    format!(
                        "{body}\nfloat4 main() : SV_Target {{\n    return float4(SSS_IMPORTANCE_WEIGHTS[SSS_IMPORTANCE_N_SAMPLES - 1] * SSS_IMPORTANCE_OFFSETS[0].z, SSS_IMPORTANCE_CUTOFF_MM);\n}}\n"
                    ),
                    vec!["-D", "-V", "-e", "main", "-S", "frag", "-o", spv.to_str().unwrap()],
                ),
                _ => continue,
            };
            let file = t.path().join(format!("k.{ext}"));
            std::fs::write(&file, src).unwrap();
            let o = std::process::Command::new("glslangValidator").args(&args).arg(&file).output().unwrap();
            assert!(o.status.success(), "{}: {}", path.display(), String::from_utf8_lossy(&o.stdout));
            compiled += 1;
        }
    }
    // 9 kernels of sss-importance-kernels and 14 of burley-profiles, two languages each.
    assert_eq!(compiled, 2 * (9 + 14));
}
