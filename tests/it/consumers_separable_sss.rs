//! `SeparableSSS.h` (Jimenez & Gutierrez 2012) takes a custom kernel either compiled in or set by the runtime as
//! `float4 kernel[N]`. rtbake's `*_SeparableSSS.h` replaces the header's whole kernel section; the README gives the
//! one command that does it. The test runs exactly that README block on the published header for every kernel the
//! bake writes (every N), compiles the shader with glslang's HLSL front end and requires every tap as a SPIR-V
//! constant and no `$Global` uniform block (upstream's preset or runtime `kernel` lives there). The raw
//! `*_f32x4.bin` (runtime upload path) is loaded by rtbake's own runtime loader and equals the JSON kernel.

use crate::support::{baked_dir, crate_dir, reference_file, tool_available};

const MAIN: &str = "#define SSSS_HLSL_4 1
#include \"SeparableSSS_rtbake.h\"
Texture2D colorTex : register(t0);
Texture2D depthTex : register(t1);
float4 main(float4 pos : SV_POSITION, float2 texcoord : TEXCOORD0) : SV_TARGET {
    return SSSSBlurPS(texcoord, colorTex, depthTex, 0.012, float2(1.0, 0.0), false);
}
";

/// The README's ```shell block that patches `SeparableSSS.h` (the one running `awk -v kernel=`).
fn readme_patch_block() -> String {
    let readme = std::fs::read_to_string(crate_dir().join("README.md")).unwrap();
    let blocks: Vec<&str> = readme.split("```shell\n").skip(1).map(|b| b.split("```").next().unwrap()).collect();
    let hits: Vec<&&str> = blocks.iter().filter(|b| b.contains("awk -v kernel=")).collect();
    assert_eq!(hits.len(), 1, "the README must have one SeparableSSS.h patch block");
    hits[0].to_string()
}

/// The block with its `K=` line pointing at `kernel` (the README's "the kernel to use").
fn with_kernel(block: &str, kernel: &str) -> String {
    assert!(block.starts_with("K="), "the block starts by naming the kernel file: {block}");
    let rest = block.split_once('\n').unwrap().1;
    format!("K={kernel}\n{rest}")
}

fn spirv_words(bytes: &[u8]) -> std::collections::HashSet<u32> {
    bytes.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().unwrap())).collect()
}

/// Every file of the default bake's separable assets (kernels and fit), freshly baked: path → bytes.
fn baked_separable_files() -> std::collections::BTreeMap<String, Vec<u8>> {
    rtbake::bake::registry()
        .into_iter()
        .filter(|a| a.name.starts_with("sss-separable"))
        .flat_map(|a| a.run(&(a.default_params)()).unwrap())
        .map(|f| (f.path, f.bytes))
        .collect()
}

#[test]
fn readme_recipe_compiles_every_baked_kernel_into_the_published_header() {
    // Both inputs are checked (and each missing one reported) before returning, so one skip never hides the other.
    let header = reference_file("consumers/separable-sss/SeparableSSS.h", "SeparableSSS.h compile");
    let glslang =
        tool_available("SeparableSSS.h compile", "glslangValidator", &["--version"], "apt-get install glslang-tools");
    let (Some(h), true) = (header, glslang) else { return };
    let block = readme_patch_block();
    let files = baked_separable_files();
    let mut ns: Vec<usize> = Vec::new();
    for (path, bytes) in files.iter().filter(|(p, _)| p.ends_with("_SeparableSSS.h")) {
        let stem = path.trim_start_matches("sss/separable/").trim_end_matches("_SeparableSSS.h");
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(text.contains("\"Uses Separable SSS. Copyright (C) 2012 by Jorge Jimenez and Diego Gutierrez.\""));
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(&h, dir.path().join("SeparableSSS.h")).unwrap();
        std::fs::create_dir_all(dir.path().join("baked/sss/separable")).unwrap();
        std::fs::write(dir.path().join("baked").join(path), bytes).unwrap();
        std::fs::write(dir.path().join("main.hlsl"), MAIN).unwrap();
        let sh = |script: &str| {
            std::process::Command::new("sh").arg("-c").arg(script).current_dir(dir.path()).output().unwrap()
        };
        let out = sh(&with_kernel(&block, &format!("baked/{path}")));
        assert!(out.status.success(), "{stem}: README patch failed: {}", String::from_utf8_lossy(&out.stderr));
        let glslang = || {
            std::process::Command::new("glslangValidator")
                .current_dir(dir.path())
                .args(["-D", "-V", "-S", "frag", "-e", "main", "main.hlsl", "-o", "out.spv"])
                .output()
                .unwrap()
        };
        let out = glslang();
        assert!(out.status.success(), "{stem}: glslang failed:\n{}", String::from_utf8_lossy(&out.stdout));
        let spv = std::fs::read(dir.path().join("out.spv")).unwrap();
        assert!(
            !spv.windows(7).any(|w| w == b"$Global"),
            "{stem}: the shader still has a $Global uniform block (upstream's kernel), not the baked constants"
        );
        let words = spirv_words(&spv);
        let json = path.replace("_SeparableSSS.h", ".json");
        let v: serde_json::Value = serde_json::from_slice(&files[&json]).unwrap();
        let taps: Vec<Vec<f64>> = serde_json::from_value(v["kernel"].clone()).unwrap();
        for (i, tap) in taps.iter().enumerate() {
            for v in tap.iter().map(|v| *v as f32).filter(|v| *v != 0.0) {
                assert!(words.contains(&v.to_bits()), "{stem}: tap {i} value {v:e} not a SPIR-V constant");
            }
        }
        ns.push(taps.len());

        // Bad input: the patched header patched again has no kernel section; a missing kernel file is named.
        std::fs::rename(dir.path().join("SeparableSSS_rtbake.h"), dir.path().join("SeparableSSS.h")).unwrap();
        let again = sh(&with_kernel(&block, &format!("baked/{path}")));
        assert_eq!(again.status.code(), Some(1), "{stem}: patching twice must fail");
        assert!(String::from_utf8_lossy(&again.stderr).contains("no #ifdef SSSS_N_SAMPLES section"));
        std::fs::copy(&h, dir.path().join("SeparableSSS.h")).unwrap();
        let missing = sh(&with_kernel(&block, "baked/sss/separable/nope_SeparableSSS.h"));
        assert_eq!(missing.status.code(), Some(1), "{stem}: a missing kernel file must fail");
        assert!(String::from_utf8_lossy(&missing.stderr).contains("cannot read baked/sss/separable/nope"));
        // The kernel pasted beside the section instead of in place of it stops the compile with its own #error.
        let header = std::fs::read_to_string(&h).unwrap();
        let at = header.find("#if SSSS_HLSL_3 == 1").unwrap();
        let beside = format!("{}{}\n{}", &header[..at], text, &header[at..]);
        std::fs::write(dir.path().join("SeparableSSS_rtbake.h"), beside).unwrap();
        let out = glslang();
        assert!(!out.status.success(), "{stem}: a kernel pasted beside the section compiled");
        assert!(String::from_utf8_lossy(&out.stdout).contains("SSSS_N_SAMPLES is already defined"), "{stem}");
    }
    ns.sort();
    ns.dedup();
    assert_eq!(ns, [9, 11, 17, 25, 33], "every baked N");
}

#[test]
fn raw_f32x4_kernel_loads_in_the_runtime_and_equals_the_json() {
    for stem in ["published_n17", "table6_1_n33", "fit_deon6_n17"] {
        let raw = rtbake::runtime::loader::load_separable_kernel_f32x4(
            &baked_dir(),
            &format!("sss/separable/{stem}_f32x4.bin"),
        )
        .unwrap();
        let json = rtbake::runtime::loader::load_separable_kernel(&baked_dir(), &format!("sss/separable/{stem}.json"))
            .unwrap();
        assert_eq!(raw, json.kernel, "{stem}");
        let bytes = std::fs::read(baked_dir().join(format!("sss/separable/{stem}_f32x4.bin"))).unwrap();
        assert_eq!(bytes.len(), 16 * raw.taps.len());
        assert_eq!(f32::from_le_bytes(bytes[0..4].try_into().unwrap()), raw.taps[0][0]);
    }
    // A truncated file is refused.
    let e = rtbake::separable::kernel::taps_from_f32x4_le(&[0u8; 20]).unwrap_err();
    assert!(e.to_string().contains("multiple of 16"), "{e}");
}
