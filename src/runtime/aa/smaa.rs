//! SMAA 1x on the GPU (Jimenez, Echevarria, Sousa, Gutierrez, "SMAA: Enhanced Subpixel Morphological
//! Antialiasing", Eurographics 2012; thesis ch. 10): luma edge detection with local contrast adaptation
//! (threshold 0.1, adaptation factor 2.0), blending weights with orthogonal and diagonal patterns and sharp-corner
//! rounding looked up in the area and search textures, neighbourhood blending in linear light.
//!
//! Textures: colour `Rgba8Unorm` holding sRGB-encoded values (decoded in the shader), edges `Rg8Unorm`, weights
//! `Rgba8Unorm`, area `Rg8Unorm` 160×560, search `R8Unorm` 64×16, output `Rgba8Unorm` (sRGB-encoded). All
//! resources are created once in [`Smaa::new`] and reused for every frame. The CPU twin is [`crate::runtime::aa::smaa_cpu`].
//! Colour or depth edges, predicated thresholding and a matte/stencil mask: [`Smaa::with_options`]
//! ([`crate::runtime::aa::edges`]).

use crate::error::InvalidInput;
use crate::runtime::aa::edges::{EdgeSettings, SMAA_LOCAL_CONTRAST_ADAPTATION};
use crate::runtime::aa::three_pass::{PassShape, PassSpec, ThreePass, COMPUTE_WGSL};
use crate::runtime::gpu;
use crate::runtime::RuntimeError;

/// SMAA area texture size (RG8).
pub const AREA_TEX_SIZE: (u32, u32) = (160, 560);
/// SMAA search texture size (R8, cropped and flipped).
pub const SEARCH_TEX_SIZE: (u32, u32) = (64, 16);

/// The two SMAA lookup textures as raw bytes (top row first). Where they come from (rtbake's bake, the upstream
/// golden files, a test fixture) is the caller's business; [`crate::runtime::loader`] reads them from `baked/`.
#[derive(Clone, Debug, PartialEq)]
pub struct SmaaTextures {
    /// 160×560 RG8.
    pub area: Vec<u8>,
    /// 64×16 R8.
    pub search: Vec<u8>,
}

impl SmaaTextures {
    pub fn new(area: Vec<u8>, search: Vec<u8>) -> Result<Self, InvalidInput> {
        let (aw, ah) = AREA_TEX_SIZE;
        let (sw, sh) = SEARCH_TEX_SIZE;
        if area.len() != (aw * ah * 2) as usize {
            return Err(InvalidInput::new(
                "area texture",
                format!("must be {aw}x{ah} RG8 ({} bytes), got {} bytes", aw * ah * 2, area.len()),
            ));
        }
        if search.len() != (sw * sh) as usize {
            return Err(InvalidInput::new(
                "search texture",
                format!("must be {sw}x{sh} R8 ({} bytes), got {} bytes", sw * sh, search.len()),
            ));
        }
        Ok(Self { area, search })
    }
}

/// Area-texture slice indices of one SMAA sample: (vertical orthogonal, horizontal orthogonal, diagonal 1,
/// diagonal 2), as in the SMAA shader's `subsampleIndices`. Orthogonal slices 0..6, diagonal slices 0..4
/// (thesis ch. 10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubsampleIndices(pub [u32; 4]);

impl SubsampleIndices {
    /// SMAA 1x: slice 0 everywhere.
    pub const SMAA_1X: Self = Self([0, 0, 0, 0]);
    /// SMAA S2x / T2x, first and second sample (frame).
    pub const SMAA_2X: [Self; 2] = [Self([1, 1, 1, 0]), Self([2, 2, 2, 0])];
    /// SMAA 4x, the four samples.
    pub const SMAA_4X: [Self; 4] = [Self([5, 3, 1, 3]), Self([4, 6, 2, 3]), Self([3, 5, 1, 4]), Self([6, 4, 2, 4])];

    pub fn validate(&self) -> Result<(), InvalidInput> {
        let [v, h, d1, d2] = self.0;
        if v > 6 || h > 6 || d1 > 4 || d2 > 4 {
            return Err(InvalidInput::new(
                "subsample",
                format!("orthogonal indices must be in 0..=6 and diagonal ones in 0..=4, got {:?}", self.0),
            ));
        }
        Ok(())
    }

    pub fn as_f32(&self) -> [f32; 4] {
        self.0.map(|v| v as f32)
    }
}

/// Everything [`Smaa::with_options`] can set: the area-texture slices, the edge detector (luma, colour, depth,
/// predicated thresholding; [`crate::runtime::aa::edges`]) and whether a matte/stencil mask leaves pixels outside it
/// untouched. The default is SMAA 1x with luma edges, unmasked ([`Smaa::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmaaOptions {
    pub subsample: SubsampleIndices,
    pub edges: EdgeSettings,
    pub masked: bool,
}

impl Default for SmaaOptions {
    fn default() -> Self {
        Self { subsample: SubsampleIndices::SMAA_1X, edges: EdgeSettings::default(), masked: false }
    }
}

/// Uniform block of `smaa.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    rt: [f32; 4],
    subsample: [f32; 4],
}

/// SMAA's preset HIGH (SMAA.hlsl, `SMAA_PRESET_HIGH`) and the area texture's layout: the constants the shader and
/// the CPU twin ([`super::smaa_cpu`]) share. The shader receives them as WGSL constants written ahead of its source
/// ([`shader_source`]), so each value is stated once.
pub(crate) mod preset {
    pub const THRESHOLD: f32 = 0.1;
    pub const LOCAL_CONTRAST_ADAPTATION: f32 = 2.0;
    pub const MAX_SEARCH_STEPS: f32 = 16.0;
    pub const MAX_SEARCH_STEPS_DIAG: f32 = 8.0;
    /// Corner rounding 25 %.
    pub const CORNER_ROUNDING_NORM: f32 = 0.25;
    pub const AREATEX_MAX_DISTANCE: f32 = 16.0;
    pub const AREATEX_MAX_DISTANCE_DIAG: f32 = 20.0;
    /// Rows of one subsample slice of the area texture.
    pub const AREATEX_SUBTEX_ROWS: f32 = 80.0;
}

/// The SMAA shader: the [`preset`] constants as WGSL, then the full-screen triangle, the shared AA fetches and
/// `smaa.wgsl`.
fn shader_source() -> &'static str {
    use preset::*;
    static SOURCE: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
        let scalars = [
            ("THRESHOLD", THRESHOLD),
            ("LOCAL_CONTRAST_ADAPTATION", LOCAL_CONTRAST_ADAPTATION),
            ("MAX_SEARCH_STEPS", MAX_SEARCH_STEPS),
            ("MAX_SEARCH_STEPS_DIAG", MAX_SEARCH_STEPS_DIAG),
            ("CORNER_ROUNDING_NORM", CORNER_ROUNDING_NORM),
            ("AREATEX_MAX_DISTANCE", AREATEX_MAX_DISTANCE),
            ("AREATEX_MAX_DISTANCE_DIAG", AREATEX_MAX_DISTANCE_DIAG),
            ("AREATEX_SUBTEX_ROWS", AREATEX_SUBTEX_ROWS),
        ];
        let mut s: String = scalars.iter().map(|(name, v)| format!("const {name}: f32 = {v:?};\n")).collect();
        let (w, h) = (AREA_TEX_SIZE.0 as f32, AREA_TEX_SIZE.1 as f32);
        s += &format!("const AREATEX_SIZE: vec2<f32> = vec2<f32>({w:?}, {h:?});\n");
        s + concat!(
            include_str!("../fullscreen.wgsl"),
            include_str!("srgb.wgsl"),
            include_str!("morphological.wgsl"),
            include_str!("smaa.wgsl")
        ) + COMPUTE_WGSL
    });
    &SOURCE
}

/// Number of timed passes [`ThreePass::encode`] records (edges, weights, blending).
pub const SMAA_PASSES: u32 = 3;

/// SMAA 1x for one frame size. Create once, run per frame.
pub struct Smaa(ThreePass);

impl std::ops::Deref for Smaa {
    type Target = ThreePass;
    fn deref(&self) -> &ThreePass {
        &self.0
    }
}

impl Smaa {
    /// Creates every resource for `width × height` frames and uploads the lookup textures (SMAA 1x).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        luts: &SmaaTextures,
    ) -> Result<Self, RuntimeError> {
        Self::with_subsample(device, queue, width, height, luts, SubsampleIndices::SMAA_1X)
    }

    /// As [`Self::new`] with explicit area-texture slices (S2x/T2x/4x samples).
    pub fn with_subsample(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        luts: &SmaaTextures,
        subsample: SubsampleIndices,
    ) -> Result<Self, RuntimeError> {
        Self::with_options(device, queue, width, height, luts, &SmaaOptions { subsample, ..Default::default() })
    }

    /// As [`Self::new`] with every option; a pass that reads depth or a mask takes them through [`ThreePass::run_with`]
    /// (or [`ThreePass::upload_inputs`]).
    pub fn with_options(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        luts: &SmaaTextures,
        options: &SmaaOptions,
    ) -> Result<Self, RuntimeError> {
        Self::with_shape(device, queue, (width, height), luts, options, PassShape::from_env()?)
    }

    /// As [`Self::with_options`] in the given [`PassShape`] (the benchmarks build both; same output bytes).
    pub fn with_shape(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        luts: &SmaaTextures,
        options: &SmaaOptions,
        shape: PassShape,
    ) -> Result<Self, RuntimeError> {
        let subsample = options.subsample;
        gpu::check_frame(device, width, height, 4)?;
        subsample.validate()?;
        use wgpu::TextureFormat as F;
        let area = gpu::texture(device, "smaa area", AREA_TEX_SIZE.0, AREA_TEX_SIZE.1, F::Rg8Unorm);
        let search = gpu::texture(device, "smaa search", SEARCH_TEX_SIZE.0, SEARCH_TEX_SIZE.1, F::R8Unorm);
        gpu::upload(queue, &area, &luts.area);
        gpu::upload(queue, &search, &luts.search);
        let params = Params {
            rt: [1.0 / width as f32, 1.0 / height as f32, width as f32, height as f32],
            subsample: subsample.as_f32(),
        };
        let ubo = gpu::uniform_buffer(device, "smaa params", bytemuck::bytes_of(&params));
        let sampler = gpu::linear_clamp_sampler(device);
        let view = |t: &wgpu::Texture| t.create_view(&Default::default());
        let (area_view, search_view) = (view(&area), view(&search));
        use wgpu::BindingResource as R;
        let weight_luts =
            vec![(3, R::TextureView(&area_view)), (4, R::TextureView(&search_view)), (6, R::Sampler(&sampler))];
        let spec = PassSpec { name: "smaa", source: ("smaa.wgsl", shader_source()), ubo: &ubo, weight_luts };
        let edges = (&options.edges, SMAA_LOCAL_CONTRAST_ADAPTATION, options.masked);
        Ok(Self(ThreePass::build(device, (width, height), spec, shape, edges)?))
    }
}
