//! rtbake — precomputation and asset baking for real-time skin rendering and morphological antialiasing, after
//! J. Jimenez, *Practical Real-Time Strategies for Photorealistic Skin Rendering and Antialiasing* (PhD thesis,
//! Universidad de Zaragoza, 2012).
//!
//! The library is the whole tool: every table the `rtbake` command line writes comes from a pure function here
//! (parameters in, typed buffers out, no file system, no GPU), so a `build.rs`, an asset pipeline or a test can
//! call the same code and get the same bytes.
//!
//! # What it computes
//!
//! | job | entry point | result |
//! | --- | --- | --- |
//! | bake registered assets into a directory with a manifest | [`bake::registry`], [`baked_dir::bake_into`], [`baked_dir::verify`] | files + `manifest.json` (sha256, parameters, conventions) |
//! | SMAA / MLAA lookup textures | [`aa::smaa_area::smaa_area_texture`], [`aa::smaa_search::search_texture`], [`aa::mlaa_area::mlaa_area_map`] | [`Image<u8>`], byte-identical to the published textures |
//! | diffusion profiles R(r), T(r) | [`diffusion::dipole`], [`diffusion::multipole`], [`diffusion::layered`], [`diffusion::sum_of_gaussians`], all [`RadialProfile`] | mm⁻² per channel |
//! | Monte Carlo ground truth for layer stacks (MCML) | [`transport::simulate`], [`transport::compare`] | R(r), T(r) in mm⁻² with standard errors; diffusion vs transport |
//! | sum-of-Gaussians fit (thesis eq. 2.2) | [`fit_sum_of_gaussians`] | variances (mm²) and weights |
//! | separable-SSS kernel (thesis eq. 6.1) | [`separable::kernel::generate`] | taps `[r, g, b, offset]` |
//! | transmittance T(s) (thesis eq. 5.12) | [`transmittance`] | table over thickness s in mm |
//! | skin colour (thesis §7.6, eq. 7.7) | [`SkinColorParams`], [`skin_color::lut::bake_lut`] | linear-sRGB melanin × hemoglobin LUT |
//! | facial maps (thesis ch. 7–8) | [`facial`] | hemoglobin scale/bias rig, wrinkle maps |
//! | encoders | [`io`] (PNG, EXR, DDS, KTX2, C/Rust/HLSL/GLSL/WGSL sources) | bytes |
//! | GPU runtime (feature `runtime`) | `runtime` | wgpu passes that consume a bake |
//!
//! # Conventions (every module keeps them)
//!
//! - **Lengths in mm**, scattering and absorption coefficients σs′, σa in **mm⁻¹**, radial profiles R(r) in
//!   **mm⁻²** (so ∫₀^∞ 2πr R(r) dr is the dimensionless total reflectance), variances in **mm²**, wavelengths in
//!   nm. Names carry the unit (`r_mm`, `variance_mm2`, `sigma_a`…).
//! - **Images are row-major, top row first, channels interleaved** ([`Image`]): texture coordinate v = 0 is the
//!   first stored row — the D3D / Vulkan / Metal / wgpu convention. OpenGL samples v = 0 at the *bottom* row, so a
//!   GL engine either flips the rows on upload or uses v′ = 1 − v; the MLAA/SMAA shaders already assume this
//!   layout (their GL ports flip). Wrinkle maps are written in the DirectX green convention (+y points down
//!   the image); an input normal map in the OpenGL convention (+y up) is declared as such and flipped on input.
//! - **Data textures are linear.** Only files labelled `color_space: srgb` in the manifest (viewing previews)
//!   are sRGB-encoded; sampling a LUT through an sRGB view silently breaks it.
//! - **Node-inclusive tables:** texel i of an n-texel axis holds the parameter value at t = i / (n − 1); sample it
//!   at texcoord `(t·(n − 1) + 0.5) / n` so that t = 0 and t = 1 hit texel centres.
//! - **Deterministic bytes:** every baker gives the same bytes for any rayon thread count and across runs; no
//!   timestamps. The manifest records rtbake's version and the git tree id of its `src/`
//!   ([`manifest::SOURCE_TREE`]), not the caller's directory, so re-baking the same sources changes no byte.
//! - **Errors name the parameter:** bad input returns [`InvalidInput`] naming the field (as the CLI flag) and the
//!   accepted range before anything is allocated or written.
//!
//! # Cargo features
//!
//! - `runtime` (default): the wgpu runtime, module `runtime` (pulls in wgpu and pollster).
//! - `cli` (default): the dependencies of the `rtbake` binary (clap, anyhow, indicatif).
//!
//! A `build.rs` or asset tool that only bakes tables depends on the bakers alone:
//!
//! ```toml
//! [build-dependencies]
//! rtbake = { path = "../rtbake", default-features = false }
//! ```
//!
//! # Examples
//!
//! Bake one registered asset (here the SMAA textures) into a directory, with its manifest, and verify it — what
//! `rtbake bake smaa-area smaa-search --out DIR` does:
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("rtbake-doc-bake-{}", std::process::id()));
//! let registry = rtbake::bake::registry();
//! let jobs: Vec<_> = registry
//!     .iter()
//!     .filter(|a| a.name == "smaa-area" || a.name == "smaa-search")
//!     .map(|a| (a, (a.default_params)()))
//!     .collect();
//! let summary = rtbake::baked_dir::bake_into(&dir, &jobs)?;
//! assert!(dir.join("aa/smaa/AreaTex.dds").is_file() && dir.join("manifest.json").is_file());
//! assert_eq!(summary.assets, ["smaa-area", "smaa-search"]);
//! let report = rtbake::baked_dir::verify(&dir, &registry)?;
//! assert!(report.is_ok());
//! # std::fs::remove_dir_all(&dir)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The same textures in memory, without a directory (160 × 560 RG8 area texture, 64 × 16 R8 search texture):
//!
//! ```
//! use rtbake::aa::{smaa_area::{smaa_area_texture, SmaaAreaParams}, smaa_search::search_texture};
//! let area = smaa_area_texture(&SmaaAreaParams::default())?;
//! assert_eq!((area.width, area.height, area.channels), (160, 560, 2));
//! let search = search_texture();
//! assert_eq!((search.width, search.height, search.channels), (64, 16, 1));
//! let dds = rtbake::io::dds::encode_u8(&area)?; // or io::ktx2::encode_u8, io::png::encode_u8, the raw `area.data`
//! assert_eq!(&dds[..4], b"DDS ");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Fit a sum of four Gaussians with shared variances to the dipole profile of Jensen et al. 2001's "skin1"
//! (thesis eq. 2.2: minimise ∫₀^∞ r (R(r) − Σᵢ wᵢ G(vᵢ, r))² dr with G(v, r) = exp(−r²/2v) / 2πv):
//!
//! ```
//! use rtbake::{diffusion::{materials, FdrForm}, fit_sum_of_gaussians, FitSettings};
//! let skin1 = materials::find("skin1").expect("a Jensen 2001 material").dipole(FdrForm::default());
//! let fit = fit_sum_of_gaussians(&skin1, &FitSettings { count: 4, ..FitSettings::default() })?;
//! let variances_mm2 = &fit.sum.variances_mm2[0]; // ascending; the same for R, G and B
//! assert_eq!(variances_mm2.len(), 4);
//! assert!(fit.error_percent.iter().all(|e| *e < 10.0), "{:?}", fit.error_percent);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Generate the 17-tap separable-SSS kernel of the published shader (strength 0.48, 0.41, 0.28; falloff 1, 0.37,
//! 0.3). Taps are `[r, g, b, offset]`, centre tap first; each channel sums to 1; offsets are in kernel units, which
//! the shader scales by `sssWidth / tan(FOVy/2) / linearDepth / 3`:
//!
//! ```
//! use rtbake::separable::{kernel::{generate, KernelSpec}, PUBLISHED};
//! let kernel = generate(&KernelSpec::new(17, PUBLISHED))?;
//! assert_eq!(kernel.taps.len(), 17);
//! assert_eq!(kernel.taps[0][3], 0.0); // centre first
//! let red: f64 = kernel.taps.iter().map(|t| t[0]).sum();
//! assert!((red - 1.0).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Evaluate the spectral skin model at one melanin / hemoglobin volume fraction, then bake a small LUT. The LUT
//! is indexed u = ∛(Cm / 0.5) along columns and v = ∛(Chd / 0.32) along rows (row 0 is Chd = 0), node-inclusive:
//!
//! ```
//! use rtbake::{skin_color::lut::bake_lut, SkinColorParams};
//! let params = SkinColorParams { width: 16, height: 16, spectral_step_nm: 10, ..SkinColorParams::default() };
//! let model = params.model()?;
//! let sample = model.evaluate(0.05, 0.1, false)?; // Cm = 5 %, Chd = 10 %
//! assert!(sample.linear_rgb[0] > sample.linear_rgb[2], "skin reflects more red than blue");
//! let lut = bake_lut(&model, &params.layout()?, params.lut_evaluation)?;
//! assert_eq!((lut.width, lut.height, lut.channels), (16, 16, 3)); // linear RGB f32, top row first
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Sources
//!
//! Each module names the paper and equation it implements at the line that implements it: Jensen et al. 2001
//! (dipole), Donner & Jensen 2005 (multipole, layered adding), d'Eon, Luebke & Enderton 2007 (sums of Gaussians),
//! Jimenez et al. 2009–2012 (screen-space and separable SSS, transmittance, skin colour, wrinkles, SMAA/MLAA).

pub mod aa;
pub mod bake;
pub mod baked_dir;
pub mod baked_layout;
pub mod color;
pub mod diffusion;
pub mod error;
pub mod facial;
pub mod fitting;
pub mod image_buf;
pub mod io;
pub mod manifest;
pub mod mesh;
pub mod plot;
#[cfg(feature = "runtime")]
pub mod runtime;
pub mod separable;
pub mod shading;
pub mod skin_color;
pub mod spectral;
pub mod sss_sampling;
pub mod study;
pub mod transmittance;
pub mod transport;

pub use bake::{registry, Asset, BakeError, BakedFile, FileMeta};
pub use baked_dir::{bake_into, verify, BakeDirError, BakeSummary, VerifyReport};
pub use diffusion::RadialProfile;
pub use error::InvalidInput;
pub use fitting::sum_of_gaussians_fit::{fit_sum_of_gaussians, FitSettings, GaussianFit};
pub use fitting::RgbGaussians;
pub use image_buf::Image;
pub use manifest::Manifest;
pub use separable::kernel::{Kernel, KernelSpec};
pub use separable::SeparableParams;
pub use skin_color::two_layer::TwoLayerSkinModel;
pub use skin_color::SkinColorParams;
