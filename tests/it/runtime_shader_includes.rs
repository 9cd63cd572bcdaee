//! Every baked WGSL include (`format` wgsl in `baked/manifest.json`) is accepted by naga, wgpu's shader front end,
//! when appended to a tiny compute entry point that reads each constant (arrays with a run-time index), and by
//! the device (`create_shader_module` + pipeline under a validation error scope on the test adapter).

use crate::support::*;
use rtbake::manifest::{sha256_hex, Manifest};
use wgpu::naga;

/// The baked WGSL includes: (manifest path, source), checksums verified.
fn includes() -> Vec<(String, String)> {
    let dir = baked_dir();
    let m = Manifest::load(&dir).unwrap();
    let v: Vec<(String, String)> = m
        .files
        .iter()
        .filter(|e| e.meta.format.as_str() == "wgsl")
        .map(|e| {
            let bytes = std::fs::read(dir.join(&e.path)).unwrap();
            assert_eq!(sha256_hex(&bytes), e.sha256, "{}: sha256 differs from the manifest", e.path);
            (e.path.clone(), String::from_utf8(bytes).unwrap())
        })
        .collect();
    assert!(v.iter().any(|(p, _)| p == "sss/separable/published_n17.wgsl"), "published_n17.wgsl not in the bake");
    assert!(v.iter().any(|(p, _)| p == "sss/gaussians/deon6.wgsl"), "deon6.wgsl not in the bake");
    v
}

/// `const NAME: TYPE = …;` declarations of an include: (name, array length if an array).
fn constants(src: &str) -> Vec<(String, Option<u32>)> {
    src.lines()
        .filter_map(|l| l.strip_prefix("const "))
        .map(|rest| {
            let (name, ty) = rest.split_once(':').expect("typed constant");
            let ty = ty.split('=').next().unwrap().trim();
            let len = ty
                .strip_prefix("array<")
                .map(|a| a.trim_end_matches('>').rsplit(',').next().unwrap().trim().parse::<u32>().unwrap());
            (name.trim().to_string(), len)
        })
        .collect()
}

/// The include followed by an entry point that reads every constant.
fn with_entry_point(src: &str) -> String {
    let mut body = String::new();
    for (name, len) in constants(src) {
        match len {
            Some(n) => body.push_str(&format!("    var a_{name} = {name};\n    _ = a_{name}[id.x % {n}u];\n")),
            None => body.push_str(&format!("    _ = {name};\n")),
        }
    }
    format!("{src}\n@compute @workgroup_size(1)\nfn rtbake_include_check(@builtin(global_invocation_id) id: vec3<u32>) {{\n{body}}}\n")
}

fn naga_check(path: &str, src: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(src).map_err(|e| format!("{path}: parse: {}", e.emit_to_string(src)))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .map_err(|e| format!("{path}: validate: {}", e.emit_to_string(src)))?;
    Ok(())
}

#[test]
fn baked_wgsl_includes_parse_and_validate_with_naga() {
    let incs = includes();
    let mut failures = Vec::new();
    for (path, src) in &incs {
        assert!(!constants(src).is_empty(), "{path}: no constants found");
        for (what, text) in [("alone", src.clone()), ("with entry point", with_entry_point(src))] {
            if let Err(e) = naga_check(path, &text) {
                failures.push(format!("{what}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{} of {} includes rejected:\n{}", failures.len(), incs.len(), failures.join("\n"));
}

#[test]
fn baked_wgsl_includes_compile_on_the_device() {
    let g = gpu();
    let mut failures = Vec::new();
    for (path, src) in includes() {
        let scope = g.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = g.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&path),
            source: wgpu::ShaderSource::Wgsl(with_entry_point(&src).into()),
        });
        let _pipe = g.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(&path),
            layout: None,
            module: &module,
            entry_point: Some("rtbake_include_check"),
            compilation_options: Default::default(),
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            failures.push(format!("{path}: {e}"));
        }
    }
    assert!(failures.is_empty(), "rejected by the device:\n{}", failures.join("\n"));
}

/// The check can fail: an include with an f32 literal out of range, or an array shorter than declared, is refused.
#[test]
fn naga_check_refuses_broken_includes() {
    let too_big = "const SSS_ALPHA: f32 = 1e39;\n";
    assert!(naga_check("too_big.wgsl", &with_entry_point(too_big)).is_err());
    let short = "const SSSS_KERNEL: array<vec4<f32>, 3> = array<vec4<f32>, 3>(vec4<f32>(1.0, 1.0, 1.0, 0.0));\n";
    assert!(naga_check("short.wgsl", &with_entry_point(short)).is_err());
    // The subnormal tap of Table 6.1 (3.56e-43) is representable in f32 and accepted.
    let subnormal = "const T: array<f32, 2> = array<f32, 2>(3.56e-43, 1.0);\n";
    naga_check("subnormal.wgsl", &with_entry_point(subnormal)).unwrap();
}
