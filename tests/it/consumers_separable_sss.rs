//! `SeparableSSS.h` (Jimenez & Gutierrez 2012) takes a custom kernel either as its built-in preset form
//! (`#define SSSS_N_SAMPLES N` + `float4 kernel[] = {…}`) or set by the runtime as `float4 kernel[N]`. rtbake's
//! `*_SeparableSSS.h` export is substituted for the header's preset of the same N and the shader compiled with
//! glslang's HLSL front end; the SPIR-V must carry rtbake's taps. The raw `*_f32x4.bin` (runtime upload path) is
//! loaded by rtbake's own runtime loader and equals the JSON kernel.

use crate::support::{baked_dir, reference_file, tool_available};

const MAIN: &str = "#define SSSS_HLSL_4 1
#include \"SeparableSSS.h\"
Texture2D colorTex : register(t0);
Texture2D depthTex : register(t1);
float4 main(float4 pos : SV_POSITION, float2 texcoord : TEXCOORD0) : SV_TARGET {
    return SSSSBlurPS(texcoord, colorTex, depthTex, 0.012, float2(1.0, 0.0), false);
}
";

/// The header with its preset of `n` taps replaced by `export` and `SSSS_QUALITY` selecting it.
fn substitute(header: &str, n: usize, export: &str) -> String {
    let quality = match n {
        11 => 0,
        17 => 1,
        25 => 2,
        _ => panic!("no preset with {n} taps"),
    };
    let start = header.find(&format!("#define SSSS_N_SAMPLES {n}\nfloat4 kernel[] = {{")).expect("preset block");
    let end = start + header[start..].find("};").expect("end of preset") + 2;
    let text = format!("{}{export}{}", &header[..start], &header[end..]);
    text.replacen("#define SSSS_QUALITY 1", &format!("#define SSSS_QUALITY {quality}"), 1)
}

fn spirv_words(bytes: &[u8]) -> std::collections::HashSet<u32> {
    bytes.chunks_exact(4).map(|w| u32::from_le_bytes(w.try_into().unwrap())).collect()
}

#[test]
fn export_compiles_in_place_of_the_preset_and_spirv_carries_the_taps() {
    let Some(h) = reference_file("consumers/separable-sss/SeparableSSS.h", "SeparableSSS.h compile") else { return };
    if !tool_available("SeparableSSS.h compile", "glslangValidator", &["--version"], "apt-get install glslang-tools") {
        return;
    }
    let header = std::fs::read_to_string(h).unwrap().replace("\r\n", "\n");
    for (stem, n) in [("table6_1_n17", 17), ("published_n11", 11), ("published_n25", 25)] {
        let dir = tempfile::tempdir().unwrap();
        let export = std::fs::read_to_string(baked_dir().join(format!("sss/separable/{stem}_SeparableSSS.h"))).unwrap();
        std::fs::write(dir.path().join("SeparableSSS.h"), substitute(&header, n, &export)).unwrap();
        std::fs::write(dir.path().join("main.hlsl"), MAIN).unwrap();
        let out = std::process::Command::new("glslangValidator")
            .current_dir(dir.path())
            .args(["-D", "-V", "-S", "frag", "-e", "main", "main.hlsl", "-o", "out.spv"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{stem}: glslang failed:\n{}", String::from_utf8_lossy(&out.stdout));
        let words = spirv_words(&std::fs::read(dir.path().join("out.spv")).unwrap());
        let taps = rtbake::runtime::loader::load_separable_kernel(&baked_dir(), &format!("sss/separable/{stem}.json"))
            .unwrap()
            .kernel
            .taps;
        assert_eq!(taps.len(), n);
        for (i, tap) in taps.iter().enumerate() {
            for v in tap.iter().filter(|v| **v != 0.0) {
                assert!(words.contains(&v.to_bits()), "{stem}: tap {i} value {v:e} not a SPIR-V constant");
            }
        }
    }
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
