//! Importance-sampled disk kernels in `baked/sss/importance/` ([`crate::sss_sampling`]; the sampling of Unity
//! HDRP's diffusion profiles).
//!
//! Asset `sss-importance-kernels`: for each named profile (a [`ProfileSource`] provenance object: skin1 dipole,
//! d'Eon's 6-Gaussian skin and a Burley skin by default) and each sample budget (20, 40, 80 by default, Unity's
//! presets), the files of [`kernel_files`]: `{name}_n{N}.json` (schema `rtbake-importance-kernel/1`),
//! HLSL / GLSL / WGSL includes and the raw `{name}_n{N}_f32x8.bin`. Burley profiles are sampled through their
//! closed-form CDF, every other profile through the tabulated CDF.

use super::{json_file, parse_params, Asset, BakeError, BakedFile};
use crate::baked_layout::{path, schema, ImportanceKernelFile, ImportanceKernelSample};
use crate::diffusion::burley::RgbBurley;
use crate::diffusion::source::ProfileSource;
use crate::io::source::{ShaderInclude, ShaderLang};
use crate::manifest::{ColorSpace, FileFormat, FileKind, SampleType};
use crate::sss_sampling::disk::{self, ImportanceKernel, SampledProfile, CUTOFF_QUANTILE};
use serde::{Deserialize, Serialize};
use serde_json::Value;

pub use crate::baked_layout::path::IMPORTANCE_DIR as DIR;

/// The binary table's layout (also written into the JSON).
pub const BINARY_LAYOUT: &str = "little-endian f32, no header, N records of 8 floats in sample order: \
    [x_mm, y_mm, r_mm, theta_rad, pdf_per_mm2, w_r, w_g, w_b] (w normalised: each channel sums to 1)";

pub fn assets() -> Vec<Asset> {
    vec![Asset {
        time_estimate: None,
        name: "sss-importance-kernels",
        summary: "Importance-sampled SSS disk kernels (skin1 dipole, deon6, Burley skin; N=20/40/80): JSON + HLSL/GLSL/WGSL + f32 table",
        default_params,
        bake,
    }]
}

/// One profile of the asset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedProfile {
    /// File stem prefix under `sss/importance/`.
    pub name: String,
    /// A [`ProfileSource`] provenance object (`{"model": "dipole", "material": "skin1", …}`).
    pub profile: Value,
    /// Sample budgets, each 1..=1024.
    pub samples: Vec<usize>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Params {
    profiles: Vec<NamedProfile>,
}

/// The default bake's profiles.
pub fn default_profiles() -> Vec<NamedProfile> {
    use crate::diffusion::burley::ShapeFit;
    use crate::diffusion::multipole::Series;
    use crate::diffusion::source::MaterialModel;
    use crate::sss_sampling::compare::{BURLEY_SKIN_ALBEDO, BURLEY_SKIN_MFP_MM};
    let samples = disk::UNITY_SAMPLE_PRESETS.to_vec();
    let skin1 = ProfileSource::Material {
        name: "skin1".into(),
        model: MaterialModel::Dipole,
        fdr: crate::diffusion::FdrForm::Dj05,
        series: Series::Exact,
    };
    let burley = ProfileSource::Burley {
        albedo: BURLEY_SKIN_ALBEDO,
        mean_free_path_mm: BURLEY_SKIN_MFP_MM,
        fit: ShapeFit::DiffuseTransmission,
    };
    vec![
        NamedProfile { name: "skin1_dipole".into(), profile: skin1.provenance(), samples: samples.clone() },
        NamedProfile {
            name: "deon6".into(),
            profile: ProfileSource::Preset("deon6".into()).provenance(),
            samples: samples.clone(),
        },
        NamedProfile { name: "burley_skin".into(), profile: burley.provenance(), samples },
    ]
}

fn default_params() -> Value {
    serde_json::to_value(Params { profiles: default_profiles() }).expect("params serialise")
}

/// Samples `source` with `n` samples: Burley through its closed form, anything else through the tabulated CDF.
pub fn kernel_for_source(source: &ProfileSource, n: usize) -> Result<ImportanceKernel, crate::error::InvalidInput> {
    match source {
        ProfileSource::Burley { albedo, mean_free_path_mm, fit } => {
            let b = RgbBurley::from_mean_free_path(*albedo, *mean_free_path_mm, *fit)?;
            ImportanceKernel::new(SampledProfile::Burley(&b), n)
        }
        other => {
            let p = other.build()?;
            ImportanceKernel::new(SampledProfile::Tabulated(p.as_ref()), n)
        }
    }
}

fn bake(params: &Value) -> Result<Vec<BakedFile>, BakeError> {
    let p: Params = parse_params("sss-importance-kernels", params)?;
    let mut files = Vec::new();
    for (i, np) in p.profiles.iter().enumerate() {
        super::check_kernel_name("sss-importance-kernels.profiles[].name", &np.name)?;
        let source = ProfileSource::from_json(&np.profile).map_err(|e| {
            crate::error::InvalidInput::new(
                format!("sss-importance-kernels.profiles[{i}].profile.{}", e.param),
                e.message,
            )
        })?;
        for &n in &np.samples {
            disk::check_samples(n).map_err(|e| {
                crate::error::InvalidInput::new(format!("sss-importance-kernels.profiles[{i}].samples"), e.message)
            })?;
            let k = kernel_for_source(&source, n)?;
            let from = format!("rtbake sss-importance-kernels ({}, N = {n})", np.name);
            files.extend(kernel_files(
                DIR,
                &path::importance_kernel_stem(&np.name, n),
                &k,
                &source.provenance(),
                &from,
            ));
        }
    }
    Ok(files)
}

/// A number rounded to 9 significant digits (f32 round-trips; the file's bytes do not hinge on the last ulp of
/// the platform's libm).
fn r9(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.8e}").parse().unwrap_or(x)
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// The kernel file ([`ImportanceKernelFile`], schema [`schema::IMPORTANCE_KERNEL`]): what was sampled and how, the
/// cut-off, the totals, the binary layout and the samples.
pub fn kernel_file(k: &ImportanceKernel, provenance: &Value, source: &str) -> ImportanceKernelFile {
    let kernel = k
        .samples
        .iter()
        .map(|s| {
            let [x, y] = s.offset_mm();
            ImportanceKernelSample {
                r_mm: r9(s.r_mm),
                theta_rad: r9(s.theta_rad),
                x_mm: r9(x),
                y_mm: r9(y),
                pdf_per_mm2: r9(s.pdf_per_mm2),
                weight: s.weight.map(r9),
                weight_unnormalised: s.weight_unnormalised.map(r9),
            }
        })
        .collect();
    ImportanceKernelFile {
        schema: schema::IMPORTANCE_KERNEL.into(),
        source: source.into(),
        profile: provenance.clone(),
        samples: k.len(),
        sampled_channel: CHANNELS[k.sampled_channel].into(),
        sampled_channel_rule: "the channel with the largest mean radius of its normalised radial density".into(),
        mean_radius_mm: k.mean_radius_mm.map(r9),
        inversion: k.inversion.name().into(),
        quantiles: "u_i = (i + 0.5)/N of the sampled channel's radial CDF F(r) = int_0^r 2 pi r' R(r') dr' / total"
            .into(),
        angles: "theta_i = i * pi * (3 - sqrt(5)) (golden angle), offset = r_i (cos theta_i, sin theta_i) mm".into(),
        pdf: "area density of the sampled channel R_s(r)/A_s, mm^-2".into(),
        weights: "w_c,i = R_c(r_i)/pdf(r_i)/N (weight_unnormalised, sums to the estimated total); weight = w / sum_i w per channel".into(),
        estimated_totals: k.estimated_totals.map(r9),
        profile_totals: k.profile_totals.map(r9),
        cutoff_quantile: CUTOFF_QUANTILE,
        cutoff_mm: r9(k.cutoff_mm),
        binary_layout: BINARY_LAYOUT.into(),
        kernel,
    }
}

/// [`kernel_file`] as a JSON value (the file's content; `rtbake importance-kernel --json` adds its `files`).
pub fn kernel_json(k: &ImportanceKernel, provenance: &Value, source: &str) -> Value {
    serde_json::to_value(kernel_file(k, provenance, source)).expect("the kernel file always serialises")
}

/// HLSL / GLSL / WGSL include: `SSS_IMPORTANCE_N_SAMPLES`, `SSS_IMPORTANCE_CUTOFF_MM`, the float4 array
/// `SSS_IMPORTANCE_OFFSETS` (x mm, y mm, r mm, pdf mm⁻²) and the float3 array `SSS_IMPORTANCE_WEIGHTS` (normalised).
pub fn shader_include(k: &ImportanceKernel, lang: ShaderLang, from: &str) -> String {
    let offsets: Vec<[f64; 4]> = k
        .samples
        .iter()
        .map(|s| {
            let [x, y] = s.offset_mm();
            [x, y, s.r_mm, s.pdf_per_mm2]
        })
        .collect();
    let weights: Vec<[f64; 3]> = k.samples.iter().map(|s| s.weight).collect();
    ShaderInclude::new(lang, from)
        .comment(&format!(
            "Importance-sampled SSS disk kernel, {} samples of the {} channel's radial CDF ({}).",
            k.len(),
            CHANNELS[k.sampled_channel],
            k.inversion.name()
        ))
        .comment("OFFSETS[i] = (x mm, y mm, r mm, pdf mm^-2): r_i = F^-1((i + 0.5)/N), theta_i = i * pi * (3 - sqrt(5)).")
        .comment("WEIGHTS[i] = per-channel weight R_c(r_i)/pdf(r_i)/N normalised so each channel sums to 1.")
        .comment("Runtime: uv_i = uv + OFFSETS[i].xy * strength * (H/2) / tan(0.5 * FOVy) / (depth * mm_per_world_unit) / (W, H).")
        .int_const("SSS_IMPORTANCE_N_SAMPLES", k.len() as i64)
        .float_const("SSS_IMPORTANCE_CUTOFF_MM", k.cutoff_mm)
        .vec_array("SSS_IMPORTANCE_OFFSETS", &offsets)
        .vec_array("SSS_IMPORTANCE_WEIGHTS", &weights)
        .finish()
}

/// The binary table ([`BINARY_LAYOUT`]).
pub fn f32x8_le_bytes(k: &ImportanceKernel) -> Vec<u8> {
    k.samples
        .iter()
        .flat_map(|s| {
            let [x, y] = s.offset_mm();
            [x, y, s.r_mm, s.theta_rad, s.pdf_per_mm2, s.weight[0], s.weight[1], s.weight[2]]
        })
        .flat_map(|v| (v as f32).to_le_bytes())
        .collect()
}

/// Files of one kernel: `{dir}/{stem}.json`, `.hlsl`, `.glsl`, `.wgsl` and `{stem}_f32x8.bin`. Pure;
/// `rtbake importance-kernel --out` uses it too.
pub fn kernel_files(dir: &str, stem: &str, k: &ImportanceKernel, provenance: &Value, source: &str) -> Vec<BakedFile> {
    let stem = crate::baked_layout::path::in_dir(dir, stem);
    let convention = "importance-sampled disk kernel: offsets in mm, weights normalised per channel";
    let mut files = vec![json_file(
        &crate::baked_layout::path::json(&stem),
        &kernel_json(k, provenance, source),
        FileKind::Json,
        convention,
    )];
    files.extend(super::shader_include_files(&stem, convention, |lang| shader_include(k, lang, source)));
    let n = k.len() as u32;
    files.push(BakedFile {
        path: format!("{stem}_f32x8.bin"),
        bytes: f32x8_le_bytes(k),
        meta: crate::manifest::FileMeta {
            kind: FileKind::Kernel,
            format: FileFormat::Raw,
            pixel_format: None,
            width: n,
            height: 1,
            channels: 8,
            sample_type: SampleType::F32,
            color_space: ColorSpace::NotApplicable,
            convention: BINARY_LAYOUT.into(),
            verify_tolerance: None,
            supercompression: None,
        },
    });
    files
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn importance_asset_bakes_every_profile_and_budget_deterministically() {
        let a = bake(&default_params()).unwrap();
        assert_eq!(a.len(), 3 * 3 * 5);
        assert!(a.iter().all(|f| f.path.starts_with("sss/importance/")));
        let b = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| bake(&default_params()));
        assert_eq!(a, b.unwrap(), "same bytes on one thread");
        let bin = a.iter().find(|f| f.path == "sss/importance/burley_skin_n40_f32x8.bin").unwrap();
        assert_eq!(bin.bytes.len(), 40 * 8 * 4);
        let j = a.iter().find(|f| f.path == "sss/importance/deon6_n80.json").unwrap();
        let v: Value = serde_json::from_slice(&j.bytes).unwrap();
        assert_eq!(v["schema"], schema::IMPORTANCE_KERNEL);
        assert_eq!(v["samples"], 80);
        assert_eq!(v["sampled_channel"], "red");
        assert_eq!(v["kernel"].as_array().unwrap().len(), 80);
        let s: f64 = v["kernel"].as_array().unwrap().iter().map(|s| s["weight"][1].as_f64().unwrap()).sum();
        assert!((s - 1.0).abs() < 1e-6);
        let j = a.iter().find(|f| f.path == "sss/importance/burley_skin_n20.json").unwrap();
        let v: Value = serde_json::from_slice(&j.bytes).unwrap();
        assert_eq!(v["inversion"], "burley-closed-form");
        // The binary table's first record holds the first sample's x.
        let x0 = f32::from_le_bytes(bin.bytes[0..4].try_into().unwrap());
        let j = a.iter().find(|f| f.path == "sss/importance/burley_skin_n40.json").unwrap();
        let v: Value = serde_json::from_slice(&j.bytes).unwrap();
        assert!((x0 as f64 - v["kernel"][0]["x_mm"].as_f64().unwrap()).abs() < 1e-7);
    }

    #[test]
    fn importance_asset_refuses_bad_params_naming_the_field() {
        let mut v = default_params();
        v["profiles"][0]["samples"] = json!([0]);
        let e = bake(&v).unwrap_err().to_string();
        assert!(e.contains("profiles[0].samples") && e.contains("1..=1024"), "{e}");
        let mut v = default_params();
        v["profiles"][1]["profile"] = json!({"model": "sum-of-gaussians", "profile_preset": "nope"});
        let e = bake(&v).unwrap_err().to_string();
        assert!(e.contains("profile_preset"), "{e}");
        let mut v = default_params();
        v["profiles"][0]["name"] = json!("../x");
        assert!(matches!(bake(&v), Err(BakeError::Invalid(_))));
    }
}
