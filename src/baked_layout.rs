//! The contract between the bakers and everything that reads `baked/`: where each file lives, the schema ids of
//! its JSON files and the typed sidecars next to the float tables.
//!
//! The bakers (`crate::bake`) write these paths and serialise these types; the runtime loader
//! (`crate::runtime::loader`), `rtbake maps rig-eval` and the tests read them back through the same definitions, so
//! a renamed file or key is a compile error on both sides instead of a runtime surprise. Per-file metadata
//! ([`crate::manifest::FileMeta`]) is the other half of the contract and lives with the manifest.
//!
//! Field order in the structs is the key order in the files (the committed `baked/` is byte-stable: reordering a
//! field re-bakes the files).

use crate::facial::disk_stats::Border;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Paths relative to the bake directory (`/`-separated, as in the manifest).
pub mod path {
    /// Folder of the SMAA textures.
    pub const SMAA_DIR: &str = "aa/smaa";
    /// Folder of the Jimenez MLAA area maps.
    pub const MLAA_DIR: &str = "aa/mlaa";
    /// File names of a texture's stem (the bakers write `{stem}.bin`, `.dds`, `.ktx2`, `.png`, `.h`, `.rs` …).
    pub fn raw_texture(stem: &str) -> String {
        format!("{stem}.bin")
    }
    /// A JSON file of `stem`.
    pub fn json(stem: &str) -> String {
        format!("{stem}.json")
    }

    /// Stem of the SMAA area texture (SMAA 2.8+, U-shape smoothing), the upstream name `AreaTex`.
    pub const SMAA_AREA_STEM: &str = "aa/smaa/AreaTex";
    /// Stem of the SMAA area texture as v2.8 made it (no U-shape smoothing).
    pub const SMAA_AREA_V2_8_STEM: &str = "aa/smaa/AreaTex_v2.8";
    /// Stem of the SMAA search texture, the upstream name `SearchTex`.
    pub const SMAA_SEARCH_STEM: &str = "aa/smaa/SearchTex";
    /// Stem of the SMAA v2.8 search table (66×33, values 0/1/2).
    pub const SMAA_SEARCH_V2_8_STEM: &str = "aa/smaa/SearchTex_v2.8";
    /// Stem of the SMAA search table before its crop (values 0/127/254).
    pub const SMAA_SEARCH_PRECROP_STEM: &str = "aa/smaa/SearchTex_logical_precrop";
    /// The area texture as Bevy's `bevy_anti_alias` ships it (KTX2, Zstandard level 15).
    pub const SMAA_AREA_BEVY: &str = "aa/smaa/SMAAAreaLUT.ktx2";
    /// The search texture as Bevy ships it.
    pub const SMAA_SEARCH_BEVY: &str = "aa/smaa/SMAASearchLUT.ktx2";
    /// SMAA area texture, raw RG8 160×560 (the runtime's copy; `.dds`/`.ktx2`/`.png` beside it):
    /// [`raw_texture`] of [`SMAA_AREA_STEM`].
    pub const SMAA_AREA: &str = "aa/smaa/AreaTex.bin";
    /// SMAA search texture, raw R8 64×16: [`raw_texture`] of [`SMAA_SEARCH_STEM`].
    pub const SMAA_SEARCH: &str = "aa/smaa/SearchTex.bin";

    /// File stem (without folder) of an MLAA area map: upstream's names (`AreaMap{n}_v1.4`, `AreaTex_MLAAv2` for
    /// v2's N = 15, `AreaTex{n}_MLAAv2` otherwise).
    pub fn mlaa_area_name(version: crate::aa::mlaa_area::MlaaVersion, n: u32) -> String {
        use crate::aa::mlaa_area::MlaaVersion;
        match version {
            MlaaVersion::V2 if n == 15 => "AreaTex_MLAAv2".into(),
            MlaaVersion::V2 => format!("AreaTex{n}_MLAAv2"),
            v => format!("AreaMap{n}_{}", v.label()),
        }
    }

    /// Stem of an MLAA area map in the bake: [`MLAA_DIR`]/[`mlaa_area_name`].
    pub fn mlaa_area_stem(version: crate::aa::mlaa_area::MlaaVersion, n: u32) -> String {
        format!("{MLAA_DIR}/{}", mlaa_area_name(version, n))
    }

    /// Jimenez MLAA v1.4 area map for maximum distance `n`, raw RG8 5n×5n.
    pub fn mlaa_area_v1_4(n: u32) -> String {
        raw_texture(&mlaa_area_stem(crate::aa::mlaa_area::MlaaVersion::V1_4, n))
    }

    /// Folder of the Monte Carlo vs diffusion report (`transport-report`).
    pub const TRANSPORT_DIR: &str = "transport";
    /// The report table, one row per case and channel (CSV; `report.json` beside it).
    pub const TRANSPORT_REPORT_CSV: &str = "transport/report.csv";

    /// Folder of the sum-of-Gaussians fits and their screen-space parameters.
    pub const GAUSSIANS_DIR: &str = "sss/gaussians";
    /// Stem of a named sum of Gaussians in [`GAUSSIANS_DIR`] (`.json`, `.hlsl`, `.glsl`, `.wgsl`, `_plot.*`).
    pub fn gaussians_stem(name: &str) -> String {
        format!("{GAUSSIANS_DIR}/{name}")
    }
    /// Default sum-of-Gaussians fit of the screen-space SSS (d'Eon's 6 Gaussians): [`json`] of
    /// [`gaussians_stem`]`("deon6")`.
    pub const GAUSSIANS_DEFAULT: &str = "sss/gaussians/deon6.json";
    /// Folder of the separable-SSS kernels.
    pub const SEPARABLE_DIR: &str = "sss/separable";
    /// Default separable-SSS kernel (17 taps, published parameters).
    pub const SEPARABLE_KERNEL_DEFAULT: &str = "sss/separable/published_n17.json";

    /// Folder of the importance-sampled disk kernels (`sss-importance-kernels`).
    pub const IMPORTANCE_DIR: &str = "sss/importance";
    /// The importance kernel `rtbake run demo --sss importance` reads (skin1 dipole, 40 samples).
    pub const IMPORTANCE_KERNEL_DEFAULT: &str = "sss/importance/skin1_dipole_n40.json";

    /// Stem of an importance kernel's files in [`IMPORTANCE_DIR`]: `{name}_n{samples}` (`.json`, `.hlsl`, `.glsl`,
    /// `.wgsl`, `_f32x8.bin`).
    pub fn importance_kernel_stem(name: &str, samples: usize) -> String {
        format!("{name}_n{samples}")
    }

    /// Folder of the transmittance tables T(s).
    pub const TRANSMITTANCE_DIR: &str = "transmittance";
    /// Burley fits, their plots and transmission profiles (asset `burley-profiles`).
    pub const BURLEY_DIR: &str = "burley";
    /// Stem of the transmittance table of a Gaussian preset in a form (`published` or `physical`).
    pub fn transmittance_stem(preset: &str, form: &str) -> String {
        format!("{TRANSMITTANCE_DIR}/{preset}_{form}")
    }
    /// Default transmittance table (EXR f32, RGB, node-inclusive; `.exr` of
    /// [`transmittance_stem`]`("deon6", "published")`); sidecar [`sidecar`] of it.
    pub const TRANSMITTANCE_DEFAULT: &str = "transmittance/deon6_published.exr";

    /// Stem of the skin-colour LUT's texture files (`.exr`, `_f16.exr`, `.ktx2`, `_preview_srgb.png`).
    pub const SKIN_LUT_STEM: &str = "skin/skin_color_lut";
    /// Skin-colour LUT (EXR f32, RGB, melanin × hemoglobin); sidecar [`SKIN_LUT_SIDECAR`].
    pub const SKIN_LUT: &str = "skin/skin_color_lut.exr";
    /// Sidecar of the skin-colour LUT ([`super::SkinLutSidecar`]).
    pub const SKIN_LUT_SIDECAR: &str = "skin/skin_color_lut.json";
    /// Skin colours evaluated directly by the spectral model at sample points (CSV).
    pub const SKIN_SAMPLES: &str = "skin/skin_color_samples.csv";
    /// Reflectance spectra R(λ) at the corner points (CSV).
    pub const SKIN_SPECTRA: &str = "skin/skin_color_spectra.csv";
    /// Published skin-colour LUT against Monte Carlo transport: CIELAB ΔE*ab map for people (sRGB PNG).
    pub const SKIN_MC_DIFFERENCE_PNG: &str = "skin/skin_color_mc_difference.png";
    /// The same map as numbers, one row per texel (CSV).
    pub const SKIN_MC_DIFFERENCE_CSV: &str = "skin/skin_color_mc_difference.csv";
    /// The Monte Carlo grid nodes with their standard errors (CSV).
    pub const SKIN_MC_NODES: &str = "skin/skin_color_mc_nodes.csv";

    /// Folder of the example hemoglobin rig.
    pub const RIG_EXAMPLE_DIR: &str = "facial/hemoglobin/example";
    /// The example rig's description ([`super::RigDescription`]); its maps are named relative to its folder.
    pub const RIG_EXAMPLE: &str = "facial/hemoglobin/example/rig.json";
    /// File name of a rig description inside its folder.
    pub const RIG_FILE_NAME: &str = "rig.json";
    /// The rig description in the folder `dir` (`dir/rig.json`; `dir` empty: the file name alone).
    pub fn rig_description(dir: &str) -> String {
        in_dir(dir, RIG_FILE_NAME)
    }
    /// Folder of the wrinkle assets.
    pub const WRINKLES_DIR: &str = "facial/wrinkles";
    /// Folder of the wrinkle example.
    pub const WRINKLE_EXAMPLE_DIR: &str = "facial/wrinkles/example";
    /// Stem of the partial-derivative wrinkle map in the folder `dir` (`.bin`, `.png`, `.ktx2`, `.dds` …).
    pub fn wrinkle_pd_stem(dir: &str) -> String {
        in_dir(dir, "wrinkle_pd")
    }
    /// Stem of the `i`-th texture of packed zone masks in the folder `dir`.
    pub fn wrinkle_masks_stem(dir: &str, i: usize) -> String {
        in_dir(dir, &format!("wrinkle_masks_{i}"))
    }
    /// The example's partial-derivative wrinkle map (raw R8G8_UNORM, `pd = 2·texel − 1`, thesis §8.2):
    /// [`raw_texture`] of [`wrinkle_pd_stem`] in [`WRINKLE_EXAMPLE_DIR`].
    pub const WRINKLE_PD_EXAMPLE: &str = "facial/wrinkles/example/wrinkle_pd.bin";
    /// The example's zone masks (raw R8G8B8A8_UNORM: red, green, blue, brown; cyan, magenta, orange, gray):
    /// [`raw_texture`] of [`wrinkle_masks_stem`] in [`WRINKLE_EXAMPLE_DIR`].
    pub const WRINKLE_MASKS_EXAMPLE: [&str; 2] =
        ["facial/wrinkles/example/wrinkle_masks_0.bin", "facial/wrinkles/example/wrinkle_masks_1.bin"];

    /// `name` in the folder `dir` (`dir` empty: `name` alone; a trailing `/` on `dir` is allowed).
    pub fn in_dir(dir: &str, name: &str) -> String {
        match dir.trim_end_matches('/') {
            "" => name.to_string(),
            d => format!("{d}/{name}"),
        }
    }

    /// The JSON sidecar next to a baked EXR (`x.exr` → `x.json`).
    pub fn sidecar(exr_path: &str) -> String {
        match exr_path.strip_suffix(".exr") {
            Some(stem) => format!("{stem}.json"),
            None => format!("{exr_path}.json"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::path::*;
    use crate::aa::mlaa_area::MlaaVersion;

    /// Every full-path constant a reader uses is the composition the bakers write through (a renamed stem that
    /// left its constant behind fails here, not in a reader).
    #[test]
    fn read_paths_are_the_bakers_compositions() {
        assert_eq!(SMAA_AREA, raw_texture(SMAA_AREA_STEM));
        assert_eq!(SMAA_SEARCH, raw_texture(SMAA_SEARCH_STEM));
        assert_eq!(mlaa_area_v1_4(33), "aa/mlaa/AreaMap33_v1.4.bin");
        assert_eq!(mlaa_area_stem(MlaaVersion::V2, 15), "aa/mlaa/AreaTex_MLAAv2");
        assert_eq!(GAUSSIANS_DEFAULT, json(&gaussians_stem("deon6")));
        assert_eq!(SEPARABLE_KERNEL_DEFAULT, json(&in_dir(SEPARABLE_DIR, "published_n17")));
        assert_eq!(
            IMPORTANCE_KERNEL_DEFAULT,
            json(&in_dir(IMPORTANCE_DIR, &importance_kernel_stem("skin1_dipole", 40)))
        );
        assert_eq!(TRANSMITTANCE_DEFAULT, format!("{}.exr", transmittance_stem("deon6", "published")));
        assert_eq!(SKIN_LUT, format!("{SKIN_LUT_STEM}.exr"));
        assert_eq!(SKIN_LUT_SIDECAR, sidecar(SKIN_LUT));
        assert_eq!(RIG_EXAMPLE, rig_description(RIG_EXAMPLE_DIR));
        assert_eq!(rig_description(""), RIG_FILE_NAME);
        assert_eq!(WRINKLE_PD_EXAMPLE, raw_texture(&wrinkle_pd_stem(WRINKLE_EXAMPLE_DIR)));
        for (i, p) in WRINKLE_MASKS_EXAMPLE.iter().enumerate() {
            assert_eq!(*p, raw_texture(&wrinkle_masks_stem(WRINKLE_EXAMPLE_DIR, i)));
        }
        assert_eq!(WRINKLE_EXAMPLE_DIR, in_dir(WRINKLES_DIR, "example"));
    }
}

/// Schema ids written into the JSON files and checked by their readers.
pub mod schema {
    /// `baked/manifest.json`.
    pub const MANIFEST: &str = "rtbake-manifest/1";
    /// A separable-SSS kernel file ([`super::separable_kernel_json`]).
    pub const SEPARABLE_KERNEL: &str = "rtbake-separable-kernel/1";
    /// The wrinkle weights of Table 8.1 (`crate::facial::wrinkles::table_8_1_json`).
    pub const WRINKLE_WEIGHTS: &str = "rtbake-wrinkle-weights/1";
    /// An importance-sampled disk kernel ([`super::ImportanceKernelFile`]).
    pub const IMPORTANCE_KERNEL: &str = "rtbake-importance-kernel/1";
    /// A hemoglobin rig description ([`super::RigDescription`]).
    pub const HEMOGLOBIN_RIG: &str = "rtbake-hemoglobin-rig/1";
    /// The report of a wrinkle conversion (`rtbake maps wrinkles`, `crate::bake::wrinkle_maps`).
    pub const WRINKLES: &str = "rtbake-wrinkles/1";
    /// The report of packed wrinkle zone masks (`rtbake maps wrinkle-masks`).
    pub const WRINKLE_MASKS: &str = "rtbake-wrinkle-masks/1";
}

/// Sidecar of a transmittance table T(s) (`transmittance/*.json`): provenance and the lookup convention.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransmittanceSidecar {
    /// Where the profile came from (preset, fit, layers …), as the command recorded it.
    pub source: Value,
    /// `published` (eq. 5.12 as printed) or `physical`.
    pub form: String,
    pub formula: String,
    /// Texels per row (node-inclusive samples over 0..=s_max).
    pub samples: u32,
    /// Rows (identical; for engines that want a 2-D texture).
    pub height: u32,
    /// Thickness of the last node, mm.
    pub s_max_mm: f64,
    /// `node-inclusive: …` ([`TransmittanceSidecar::TEXEL_CONVENTION`]).
    pub texel_convention: String,
    pub shader_lookup: String,
    /// The profile's Gaussians: variances (mm²) per channel (empty for a Burley table).
    #[serde(default, skip_serializing_if = "no_gaussians")]
    pub variances_mm2: [Vec<f64>; 3],
    /// Weights per channel (empty for a Burley table).
    #[serde(default, skip_serializing_if = "no_gaussians")]
    pub weights: [Vec<f64>; 3],
    /// Burley's parameters, for a table of [`crate::transmittance::BURLEY_FORMULA`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub burley: Option<BurleyParams>,
}

fn no_gaussians(v: &[Vec<f64>; 3]) -> bool {
    v.iter().all(Vec::is_empty)
}

/// Burley's normalized diffusion per channel, as files record it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BurleyParams {
    /// Surface albedo A per channel.
    pub albedo: [f64; 3],
    /// Shape parameter d per channel, mm.
    pub d_mm: [f64; 3],
}

impl From<&crate::diffusion::burley::RgbBurley> for BurleyParams {
    fn from(b: &crate::diffusion::burley::RgbBurley) -> Self {
        Self { albedo: b.0.map(|c| c.albedo), d_mm: b.0.map(|c| c.d_mm) }
    }
}

impl TransmittanceSidecar {
    /// Texel i holds s = s_max·i/(n−1).
    pub const TEXEL_CONVENTION: &'static str = "node-inclusive: texel i holds s = s_max*i/(n-1)";
    /// How a shader samples the table.
    pub const SHADER_LOOKUP: &'static str = "u = s/s_max*(n-1)/n + 0.5/n, linear filtering, clamp to edge";
}

/// An importance-sampled disk kernel (schema [`schema::IMPORTANCE_KERNEL`]; `sss/importance/*.json`,
/// `burley/kernels/*.json`): what was sampled and how, the cut-off, the totals, the binary layout of the
/// `_f32x8.bin` beside it and the samples. Written by `crate::bake::importance`, read by the runtime loader.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImportanceKernelFile {
    pub schema: String,
    /// What wrote it.
    pub source: String,
    /// Provenance of the sampled profile.
    pub profile: Value,
    /// Number of samples N (the length of `kernel`).
    pub samples: usize,
    /// `red`, `green` or `blue`: the channel whose radial CDF is sampled.
    pub sampled_channel: String,
    pub sampled_channel_rule: String,
    /// Mean radius of each channel's normalised radial density, mm.
    pub mean_radius_mm: [f64; 3],
    /// How the CDF is inverted (closed form or tabulated).
    pub inversion: String,
    pub quantiles: String,
    pub angles: String,
    pub pdf: String,
    pub weights: String,
    /// Σ of the unnormalised weights per channel (the estimated total diffuse reflectance).
    pub estimated_totals: [f64; 3],
    /// The profile's own totals per channel.
    pub profile_totals: [f64; 3],
    pub cutoff_quantile: f64,
    /// Radius beyond which the profile is cut, mm.
    pub cutoff_mm: f64,
    pub binary_layout: String,
    pub kernel: Vec<ImportanceKernelSample>,
}

/// One sample of an [`ImportanceKernelFile`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImportanceKernelSample {
    pub r_mm: f64,
    pub theta_rad: f64,
    pub x_mm: f64,
    pub y_mm: f64,
    /// Area density of the sampled channel at r, mm⁻².
    pub pdf_per_mm2: f64,
    /// Weights normalised per channel (each channel sums to 1).
    pub weight: [f64; 3],
    /// R_c(r)/pdf/N (sums to the estimated total).
    pub weight_unnormalised: [f64; 3],
}

/// Sidecar of the skin-colour LUT ([`path::SKIN_LUT_SIDECAR`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkinLutSidecar {
    pub asset: String,
    pub description: String,
    pub files: SkinLutFiles,
    pub color_space: String,
    pub width: u32,
    pub height: u32,
    pub channels: [String; 3],
    pub index: SkinLutIndex,
    pub value_range: SkinLutRange,
    pub model: SkinLutModel,
    /// The asset parameters that produced it.
    pub parameters: Value,
}

/// The files of the skin-colour asset, by role.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkinLutFiles {
    pub linear_f32: String,
    pub linear_f16: String,
    pub linear_f16_ktx2: String,
    pub preview_srgb8_not_for_sampling: String,
    pub samples: String,
    pub spectra: String,
}

/// How texels map to (melanin Cm, dermal hemoglobin Chd), eq. 7.7.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkinLutIndex {
    pub form: String,
    pub u_axis: String,
    pub v_axis: String,
    /// Cm of the last column.
    pub melanin_max: f64,
    /// Chd of the last row.
    pub hemoglobin_max: f64,
    pub texel_to_concentration: String,
    pub concentration_to_texcoord: String,
    pub hlsl: String,
    pub epidermal_hemoglobin: String,
}

/// Per-channel minimum and maximum of the table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkinLutRange {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

/// The model behind the skin-colour LUT, in words.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkinLutModel {
    pub layers: String,
    pub adding: String,
    pub dermis_bottom: String,
    pub colorimetry: String,
    pub data: String,
}

/// Where one basis map of a rig came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigSource {
    pub name: String,
    /// File name or `synthetic:…` description.
    pub source: String,
    /// `exr-f32`, `exr-f16`, `png16`, `png8`, `synthetic-png16`.
    pub format: String,
    /// How samples map to concentration.
    pub mapping: String,
}

/// The rig description written as `rig.json` (schema [`schema::HEMOGLOBIN_RIG`]); read back by
/// `rtbake maps rig-eval` and the GPU runtime. File names inside are relative to the rig's folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigDescription {
    pub schema: String,
    pub generated_by: String,
    pub model: String,
    pub evaluation: String,
    pub sampling: String,
    pub radius_texels: u32,
    pub border: Border,
    pub sigma_floor: f64,
    pub sigma_floored_texels: u64,
    pub full_size: [u32; 2],
    pub rig_size: [u32; 2],
    pub value_unit: String,
    pub h0: RigH0Files,
    pub maps: Vec<RigMapFiles>,
    pub global_scales: serde_json::Map<String, Value>,
    pub previews: String,
}

/// The one reader of a hemoglobin rig: rebuilds it from its description (`rig.json`, [`RigDescription`]) and the
/// EXR files it names, for `rtbake maps rig-eval` and the runtime's loader. `read(file)` returns the bytes of a file
/// named relative to the rig's folder (the caller does the I/O, and may check each file against a manifest first);
/// checked here: the schema, the sizes, at least one map and the neutral map first (eq. 7.6 blends targets over
/// it), every map single-channel at the size the description states with finite values. Errors name `param` (the
/// flag the user gave, or the file's path) and the file. A renderer adds only its own limits (the number of
/// targets a pass holds, the hemoglobin range its LUT indexes).
pub fn rig_from_description(
    param: &str,
    desc: &RigDescription,
    read: &mut dyn FnMut(&str) -> Result<Vec<u8>, crate::error::InvalidInput>,
) -> Result<crate::facial::hemoglobin_rig::HemoglobinRig, crate::error::InvalidInput> {
    if desc.schema != schema::HEMOGLOBIN_RIG {
        return Err(crate::error::InvalidInput::new(
            param,
            format!("schema '{}', expected '{}'", desc.schema, schema::HEMOGLOBIN_RIG),
        ));
    }
    let [w, h] = desc.full_size;
    let [rw, rh] = desc.rig_size;
    crate::error::check_size(&format!("{param} full_size"), w as u64, h as u64)?;
    crate::error::check_size(&format!("{param} rig_size"), rw as u64, rh as u64)?;
    match desc.maps.first() {
        None => return Err(crate::error::InvalidInput::new(param, "lists no maps; a rig needs the neutral map first")),
        Some(m) if m.name != "neutral" => {
            return Err(crate::error::InvalidInput::new(
                param,
                format!("maps[0] is {:?}; eq. 7.6 needs the neutral map first", m.name),
            ))
        }
        Some(_) => {}
    }
    let mut map = |file: &str, (mw, mh): (u32, u32)| -> Result<Vec<f32>, crate::error::InvalidInput> {
        let bytes = read(file)?;
        let (img, _) =
            crate::io::exr::decode(&bytes, file).map_err(|e| crate::error::InvalidInput::new(param, e.to_string()))?;
        if (img.width, img.height, img.channels) != (mw, mh, 1) {
            return Err(crate::error::InvalidInput::new(
                param,
                format!("{file} is {}x{}x{}, the rig says {mw}x{mh}x1", img.width, img.height, img.channels),
            ));
        }
        if let Some(i) = img.data.iter().position(|v| !v.is_finite()) {
            return Err(crate::error::InvalidInput::new(
                param,
                format!(
                    "{file}: texel ({}, {}) is {}; a rig map must be finite",
                    i % mw as usize,
                    i / mw as usize,
                    img.data[i]
                ),
            ));
        }
        Ok(img.data)
    };
    let h0 = map(&desc.h0.exr, (w, h))?;
    let mut maps = Vec::with_capacity(desc.maps.len());
    for m in &desc.maps {
        maps.push(crate::facial::hemoglobin_rig::RigMap {
            name: m.name.clone(),
            scale: map(&m.scale_exr, (rw, rh))?,
            bias: map(&m.bias_exr, (rw, rh))?,
        });
    }
    Ok(crate::facial::hemoglobin_rig::HemoglobinRig {
        width: w,
        height: h,
        rig_width: rw,
        rig_height: rh,
        settings: crate::facial::hemoglobin_rig::RigSettings {
            radius_texels: desc.radius_texels,
            border: desc.border,
            sigma_floor: desc.sigma_floor,
            rig_size: rw.max(rh),
        },
        h0,
        maps,
        sigma_floored_texels: desc.sigma_floored_texels,
    })
}

/// Files of H0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigH0Files {
    pub definition: String,
    pub exr: String,
    pub exr_f16: String,
    pub ktx2: String,
    pub preview: String,
    pub preview_range: [f64; 2],
}

/// Files of one basis map (index 0 is the neutral map).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigMapFiles {
    pub index: usize,
    pub name: String,
    pub scale_exr: String,
    pub scale_exr_f16: String,
    pub bias_exr: String,
    pub bias_exr_f16: String,
    /// RG16F: R = scale, G = bias.
    pub scale_bias_ktx2: String,
    pub scale_preview: String,
    pub bias_preview: String,
    pub source: RigSource,
}

/// The separable-SSS kernel file: defined with the kernel it serialises (so the model does not import the
/// contract), re-exported here with the other files of the contract.
pub use crate::separable::kernel::SeparableKernelFile;

/// A separable-SSS kernel's file under [`schema::SEPARABLE_KERNEL`], as JSON.
pub fn separable_kernel_json(
    k: &crate::separable::kernel::Kernel,
    sss_width: Option<f64>,
    source: &str,
) -> serde_json::Value {
    serde_json::to_value(k.to_file(schema::SEPARABLE_KERNEL, sss_width, source)).expect("kernel file serialises")
}

/// The sum-of-Gaussians / screen-space parameter file, likewise defined with the parameters it serialises.
pub use crate::fitting::screen_space::{GaussiansFile, LodThresholds};
