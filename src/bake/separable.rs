//! Separable-SSS kernels in `baked/sss/separable/` (thesis ch. 6).
//!
//! Asset `sss-separable-kernels`: the published SeparableSSS presets (strength 0.48, 0.41, 0.28; falloff 1.0,
//! 0.37, 0.3) for N = 11, 17, 25 and the thesis' Table 6.1 parameters (width 0.014; strength 0.78, 0.70, 0.75;
//! falloff 0.57, 0.13, 0.08) for N = 9, 17, 33, each as `sss/separable/<name>.json` and HLSL / GLSL / WGSL includes.
//!
//! Asset `sss-separable-fit`: the fit of strength and falloff to d'Eon's 6-Gaussian skin profile under the
//! default objective (`sss/separable/fit_deon6.json`, with Table 6.1's objective value for comparison) and the
//! fitted 17-tap kernel.

use super::{json_file, parse_params, text_file, Asset, BakeError, BakedFile};
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use crate::separable::fit::{self, ObjectiveSpec, TargetKernel};
use crate::separable::kernel::{self, Kernel, KernelSpec, Precision};
use crate::separable::{SeparableParams, PUBLISHED, PUBLISHED_SSS_WIDTH, TABLE_6_1, TABLE_6_1_WIDTH};
use serde::{Deserialize, Serialize};
use serde_json::Value;

pub use crate::baked_layout::path::SEPARABLE_DIR as DIR;

pub fn assets() -> Vec<Asset> {
    vec![
        Asset {
            time_estimate: None,
            name: "sss-separable-kernels",
            summary: "Separable-SSS kernel taps (published presets N=11/17/25, thesis Table 6.1 N=9/17/33): JSON + HLSL/GLSL/WGSL",
            default_params: default_kernels_params,
            bake: bake_kernels,
        },
        Asset {
            time_estimate: None,
            name: "sss-separable-fit",
            summary: "Separable-SSS strength/falloff fitted to d'Eon's 6-Gaussian skin profile (eq. 6.3), with the 17-tap kernel",
            default_params: default_fit_params,
            bake: bake_fit,
        },
    ]
}

/// One kernel of the `sss-separable-kernels` asset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NamedKernel {
    /// File stem under `sss/separable/`.
    pub name: String,
    #[serde(flatten)]
    pub spec: KernelSpec,
    /// sssWidth the parameters were made for (world units), recorded in the files.
    #[serde(default)]
    pub sss_width: Option<f64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct KernelsParams {
    kernels: Vec<NamedKernel>,
}

/// The default bake's kernels.
pub fn default_kernels() -> Vec<NamedKernel> {
    let mut v = Vec::new();
    for n in [11, 17, 25] {
        v.push(NamedKernel {
            name: format!("published_n{n}"),
            spec: KernelSpec::new(n, PUBLISHED),
            sss_width: Some(PUBLISHED_SSS_WIDTH),
        });
    }
    for n in [9, 17, 33] {
        v.push(NamedKernel {
            name: format!("table6_1_n{n}"),
            spec: KernelSpec::new(n, TABLE_6_1),
            sss_width: Some(TABLE_6_1_WIDTH),
        });
    }
    v
}

fn default_kernels_params() -> Value {
    serde_json::to_value(KernelsParams { kernels: default_kernels() }).expect("params serialise")
}

/// Files of one kernel: `{dir}/{stem}.json`, `.hlsl`, `.glsl`, `.wgsl`, the upstream-form `{stem}_SeparableSSS.h`
/// kernel (in place of `SeparableSSS.h`'s whole kernel section, any N) and the raw little-endian
/// `{stem}_f32x4.bin` (N taps of `[r, g, b, offset]`, the runtime upload path). Pure; `rtbake kernel --out` uses
/// it too.
pub fn kernel_files(dir: &str, stem: &str, k: &Kernel, sss_width: Option<f64>, source: &str) -> Vec<BakedFile> {
    let stem = crate::baked_layout::path::in_dir(dir, stem);
    let convention = kernel::LAYOUT_DOC;
    let mut files = vec![json_file(
        &crate::baked_layout::path::json(&stem),
        &crate::baked_layout::separable_kernel_json(k, sss_width, source),
        FileKind::Json,
        convention,
    )];
    files.extend(super::shader_include_files(&stem, convention, |lang| k.shader_include(lang, source, sss_width)));
    files.push(text_file(
        &format!("{stem}_SeparableSSS.h"),
        k.separable_sss_h(source),
        FileKind::ShaderInclude,
        FileFormat::Hlsl,
        "SeparableSSS.h form: #define SSSS_N_SAMPLES N + static const float4 kernel[N] (rgb = weight, a = offset), \
         to replace the header's whole kernel section (#ifdef SSSS_N_SAMPLES to its #endif) for any N",
    ));
    let n = k.taps.len() as u32;
    files.push(BakedFile {
        path: format!("{stem}_f32x4.bin"),
        bytes: k.f32x4_le_bytes(),
        meta: crate::manifest::FileMeta {
            kind: FileKind::Kernel,
            format: FileFormat::Raw,
            pixel_format: Some(crate::io::PixelFormat::R32G32B32A32Sfloat),
            width: n,
            height: 1,
            channels: 4,
            sample_type: SampleType::F32,
            color_space: ColorSpace::NotApplicable,
            convention: format!("{convention}; little-endian f32 x 4 x {n}, no header (SeparableSSS.h runtime kernel)"),
            verify_tolerance: None,
            supercompression: None,
        },
    });
    files
}

fn bake_kernels(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: KernelsParams = parse_params("sss-separable-kernels", params)?;
    let mut files = Vec::new();
    for nk in &p.kernels {
        super::check_kernel_name("sss-separable-kernels.kernels[].name", &nk.name)?;
        let k = kernel::generate(&nk.spec)?;
        let source = format!(
            "SeparableSSS kernel generator (N={}, strength {:?}, falloff {:?}, {})",
            nk.spec.samples,
            nk.spec.params.strength,
            nk.spec.params.falloff,
            nk.spec.precision.as_str()
        );
        files.extend(kernel_files(DIR, &nk.name, &k, nk.sss_width, &source));
    }
    Ok(files)
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FitParams {
    /// Target profile preset (`deon6`, `deon4`).
    profile: String,
    objective: ObjectiveSpec,
    /// Taps of the fitted kernel.
    samples: usize,
}

fn default_fit_params() -> Value {
    serde_json::to_value(FitParams { profile: "deon6".into(), objective: ObjectiveSpec::default(), samples: 17 })
        .expect("params serialise")
}

fn bake_fit(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: FitParams = parse_params("sss-separable-fit", params)?;
    let profile = crate::diffusion::source::gaussian_preset("sss-separable-fit.profile", &p.profile)?;
    let description = format!("{} profile preset (sum of Gaussians)", p.profile);
    let map = |e: fit::SeparableFitError| match e {
        fit::SeparableFitError::Invalid(i) => BakeError::Invalid(i),
        other => BakeError::Other(other.to_string()),
    };
    let target = TargetKernel::from_profile(&profile, &p.objective, &description).map_err(map)?;
    let result = fit::fit(&target).map_err(map)?;
    let sep = fit::separability(&profile, &p.objective).map_err(map)?;
    // Rounded to 7 significant digits so the file's bytes do not hinge on the last ulp of the platform's libm.
    let report = round_json(fit::report_json(&target, &result, Some(&sep)), 7);
    let stem = format!("fit_{}", p.profile);
    let mut files = vec![json_file(
        &format!("{DIR}/{stem}.json"),
        &report,
        FileKind::Json,
        "fitted separable-SSS parameters (strength, falloff per channel; width fixed) and the objective definition",
    )];
    let spec = KernelSpec { precision: Precision::F32, ..KernelSpec::new(p.samples, rounded(&result.params)) };
    let k = kernel::generate(&spec)?;
    let source = format!("the separable fit to {} (strength/falloff rounded to 1e-6)", p.profile);
    files.extend(kernel_files(DIR, &format!("{stem}_n{}", p.samples), &k, Some(result.width), &source));
    Ok(files)
}

/// Every non-integer number of `v` rounded to `digits` significant digits.
fn round_json(v: Value, digits: i32) -> Value {
    match v {
        Value::Number(n) if n.is_f64() => {
            let x = n.as_f64().unwrap_or(0.0);
            if x == 0.0 || !x.is_finite() {
                return Value::Number(n);
            }
            let rounded: f64 = format!("{:.*e}", (digits - 1) as usize, x).parse().unwrap_or(x);
            serde_json::Number::from_f64(rounded).map(Value::Number).unwrap_or(Value::Null)
        }
        Value::Array(a) => Value::Array(a.into_iter().map(|x| round_json(x, digits)).collect()),
        Value::Object(o) => Value::Object(o.into_iter().map(|(k, x)| (k, round_json(x, digits))).collect()),
        other => other,
    }
}

/// Fitted parameters rounded to 6 decimals before generating taps (stable bytes across platforms' libm).
fn rounded(p: &SeparableParams) -> SeparableParams {
    let r = |v: f64| (v * 1e6).round() / 1e6;
    SeparableParams { strength: p.strength.map(r), falloff: p.falloff.map(r) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_kernels_bake_to_json_and_three_includes_each() {
        let files = bake_kernels(&default_kernels_params()).unwrap();
        assert_eq!(files.len(), 6 * 6, "json, 3 includes, SeparableSSS.h form and raw f32x4 per kernel");
        let raw = files.iter().find(|f| f.path == "sss/separable/published_n17_f32x4.bin").unwrap();
        assert_eq!(raw.bytes.len(), 17 * 16);
        let upstream = files.iter().find(|f| f.path == "sss/separable/published_n17_SeparableSSS.h").unwrap();
        let text = std::str::from_utf8(&upstream.bytes).unwrap();
        assert!(text.contains("#define SSSS_N_SAMPLES 17\nstatic const float4 kernel[] = {\n"), "{text}");
        assert_eq!(text.matches("float4(").count(), 17);
        assert!(files.iter().all(|f| f.path.starts_with("sss/separable/")));
        let j = files.iter().find(|f| f.path == "sss/separable/published_n17.json").unwrap();
        let v: Value = serde_json::from_slice(&j.bytes).unwrap();
        assert!((v["kernel"][0][0].as_f64().unwrap() - 0.536343).abs() <= 5e-7);
        assert_eq!(v["samples"], 17);
        let hlsl = files.iter().find(|f| f.path == "sss/separable/table6_1_n33.hlsl").unwrap();
        let text = std::str::from_utf8(&hlsl.bytes).unwrap();
        assert!(text.contains("static const float4 SSSS_KERNEL[33] = {"));
        assert!(text.contains("static const float SSSS_KERNEL_RANGE = 3.0;"));
        assert!(text.contains("/ 3;"));
    }

    #[test]
    fn params_round_trip_through_json() {
        let v = default_kernels_params();
        let back: KernelsParams = serde_json::from_value(v.clone()).unwrap();
        assert_eq!(serde_json::to_value(&back).unwrap(), v);
        let f = default_fit_params();
        let back: FitParams = serde_json::from_value(f.clone()).unwrap();
        assert_eq!(serde_json::to_value(&back).unwrap(), f);
    }

    #[test]
    fn fit_asset_is_deterministic_and_not_worse_than_table_6_1() {
        let a = bake_fit(&default_fit_params()).unwrap();
        let b = bake_fit(&default_fit_params()).unwrap();
        assert_eq!(a, b);
        let paths: Vec<&str> = a.iter().map(|f| f.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "sss/separable/fit_deon6.json",
                "sss/separable/fit_deon6_n17.json",
                "sss/separable/fit_deon6_n17.hlsl",
                "sss/separable/fit_deon6_n17.glsl",
                "sss/separable/fit_deon6_n17.wgsl",
                "sss/separable/fit_deon6_n17_SeparableSSS.h",
                "sss/separable/fit_deon6_n17_f32x4.bin"
            ]
        );
        let v: Value = serde_json::from_slice(&a[0].bytes).unwrap();
        assert!(v["objective"].as_f64().unwrap() <= v["objective_table_6_1"].as_f64().unwrap());
        assert_eq!(round_json(serde_json::json!([0.123456789, 3, 2.0]), 3), serde_json::json!([0.123, 3, 2.0]));
    }

    #[test]
    fn bad_kernel_params_are_refused() {
        let mut v = default_kernels_params();
        v["kernels"][0]["samples"] = 16.into();
        assert!(matches!(bake_kernels(&v), Err(BakeError::Invalid(_))));
        let mut v = default_kernels_params();
        v["kernels"][0]["name"] = "../escape".into();
        assert!(matches!(bake_kernels(&v), Err(BakeError::Invalid(_))));
    }
}
