//! The N-tap runtime kernel of separable SSS, generated exactly as the published `SeparableSSS` shader expects it
//! (thesis ch. 6, eq. 6.1).
//!
//! Given strength t and falloff f per channel:
//!
//! 1. RANGE = 3 if N > 20 else 2, EXPONENT = 2 (both overridable). For i = 0..N−1:
//!    τ = −RANGE + i·(2·RANGE/(N − 1)), offset_i = RANGE·sign(τ)·|τ|^EXPONENT / RANGE^EXPONENT (sign(0) = +1).
//! 2. Profile per channel: P_c(x) = Σᵢ wᵢ·exp(−u²/(2vᵢ))/(2π·vᵢ), u = x/(0.001 + f_c), over d'Eon et al.'s 6-Gaussian
//!    skin profile **without its narrowest Gaussian** and with the **red** weights for every channel
//!    (d'Eon, Luebke, Enderton, "Efficient Rendering of Human Skin", EGSR 2007; [`crate::diffusion::sum_of_gaussians::deon6`]).
//!    The shader writes 3.14 for π; it cancels in the normalisation and is kept so f32 reproduces the shipped digits.
//! 3. weight_i = area_i·P(offset_i), area_i = (|o_i − o_(i−1)| + |o_i − o_(i+1)|)/2, a missing neighbour counting 0.
//! 4. The centre tap (index N/2) moves to slot 0 and the taps before it shift up by one: [0, −RANGE … , +… RANGE].
//! 5. Each channel is normalised to sum 1 over all N taps.
//! 6. Strength (eq. 6.1's δ term): centre = (1 − t) + t·w₀, every other tap × t. Channels still sum to 1.
//!
//! Offsets are in the profile's units (mm of d'Eon's profile when falloff = 1; "kernel units"). The shader scales
//! them by `sssWidth · (1/tan(FOVy/2)) / linearDepth · dir · strength(alpha) / 3`, with the **fixed /3** even when
//! RANGE = 2, so one kernel unit spans (2/3)·sssWidth world units on screen.
//!
//! [`Precision::F32`] evaluates every step in f32 in the shader's order of operations and reproduces the shipped
//! header's digits (whose offsets are very slightly asymmetric); [`Precision::F64`] runs the same steps in f64.

use crate::error::{check_range, InvalidInput};
use crate::io::source::{ShaderInclude, ShaderLang};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{SeparableParams, CHANNELS};

/// Smallest and largest accepted tap count.
pub const MIN_SAMPLES: usize = 3;
pub const MAX_SAMPLES: usize = 63;

/// The shipped shader's exponent of the offset distribution.
pub const DEFAULT_EXPONENT: f64 = 2.0;

/// The divisor the shader applies to every step (fixed, whatever RANGE is).
pub const SHADER_STEP_DIVISOR: f64 = 3.0;

/// π as the published kernel generator writes it (cancels in the normalisation).
#[allow(clippy::approx_constant)]
const PI_AS_PUBLISHED: f64 = 3.14;

/// Offset added to the falloff before dividing (eq. 6.1's `0.001 + f`).
pub const FALLOFF_EPSILON: f64 = 0.001;

/// Arithmetic precision of the generator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// f32 in the shader's order of operations: reproduces the published digits.
    #[default]
    F32,
    /// The same steps in f64.
    F64,
}

impl Precision {
    pub fn as_str(self) -> &'static str {
        match self {
            Self::F32 => "f32",
            Self::F64 => "f64",
        }
    }
}

/// Everything that determines a kernel.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KernelSpec {
    /// Number of taps N: odd, 3..=63.
    pub samples: usize,
    /// Strength t and falloff f per channel.
    #[serde(flatten)]
    pub params: SeparableParams,
    /// Offset range in kernel units; `None` = the shader's rule (3 if N > 20 else 2).
    #[serde(default)]
    pub range: Option<f64>,
    /// Exponent of the offset distribution (shader: 2).
    #[serde(default = "default_exponent")]
    pub exponent: f64,
    #[serde(default)]
    pub precision: Precision,
}

fn default_exponent() -> f64 {
    DEFAULT_EXPONENT
}

/// The shader's RANGE rule: 3 kernel units for more than 20 taps, else 2.
pub fn default_range(samples: usize) -> f64 {
    if samples > 20 {
        3.0
    } else {
        2.0
    }
}

impl KernelSpec {
    /// The shader's defaults (RANGE rule, exponent 2, f32) for the given taps and parameters.
    pub fn new(samples: usize, params: SeparableParams) -> Self {
        Self { samples, params, range: None, exponent: DEFAULT_EXPONENT, precision: Precision::F32 }
    }

    /// RANGE actually used.
    pub fn effective_range(&self) -> f64 {
        self.range.unwrap_or_else(|| default_range(self.samples))
    }

    /// Checks every field, naming the CLI flag (JSON field in brackets) and the accepted range.
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let n = self.samples;
        if !(MIN_SAMPLES..=MAX_SAMPLES).contains(&n) || n.is_multiple_of(2) {
            return Err(InvalidInput::new(
                "samples",
                format!("must be an odd number of taps in {MIN_SAMPLES}..={MAX_SAMPLES}, got {n}"),
            ));
        }
        validate_params(&self.params)?;
        if let Some(r) = self.range {
            check_range("range", r, 0.01, 100.0, "kernel units")?;
        }
        check_range("exponent", self.exponent, 0.1, 10.0, "")?;
        Ok(())
    }
}

/// Strength in 0..=1 and falloff finite and >= 0 per channel; names the flag and the channel.
pub fn validate_params(p: &SeparableParams) -> Result<(), InvalidInput> {
    for (c, name) in CHANNELS.iter().enumerate() {
        let s = p.strength[c];
        if !(0.0..=1.0).contains(&s) {
            return Err(InvalidInput::new("strength", format!("({name}) must be in 0..=1, got {s}")));
        }
        let f = p.falloff[c];
        if !(f.is_finite() && f >= 0.0) {
            return Err(InvalidInput::new("falloff", format!("({name}) must be a finite number >= 0, got {f}")));
        }
    }
    Ok(())
}

/// A generated kernel: taps in the shader's order (centre first).
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub spec: KernelSpec,
    /// RANGE used, kernel units.
    pub range: f64,
    /// `[r, g, b, offset]`: per-channel weight and offset in kernel units. Values are exactly representable in
    /// the precision of `spec.precision`.
    pub taps: Vec<[f64; 4]>,
}

/// Minimal float abstraction so one generator runs in f32 or f64.
trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn of(v: f64) -> Self;
    fn to_f64(self) -> f64;
    fn abs(self) -> Self;
    fn powf(self, e: Self) -> Self;
    fn exp(self) -> Self;
}

impl Real for f32 {
    fn of(v: f64) -> Self {
        v as f32
    }
    fn to_f64(self) -> f64 {
        self as f64
    }
    fn abs(self) -> Self {
        f32::abs(self)
    }
    fn powf(self, e: Self) -> Self {
        f32::powf(self, e)
    }
    fn exp(self) -> Self {
        f32::exp(self)
    }
}

impl Real for f64 {
    fn of(v: f64) -> Self {
        v
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn abs(self) -> Self {
        f64::abs(self)
    }
    fn powf(self, e: Self) -> Self {
        f64::powf(self, e)
    }
    fn exp(self) -> Self {
        f64::exp(self)
    }
}

/// The kernel profile: variances (mm²) and red weights of d'Eon's 6-Gaussian fit without the narrowest Gaussian.
pub fn kernel_profile() -> Vec<(f64, f64)> {
    let deon = crate::diffusion::sum_of_gaussians::deon6();
    deon.variances_mm2.iter().zip(&deon.weights).skip(1).map(|(v, w)| (*v, w[0])).collect()
}

/// Generates the kernel (steps 1–6 of the module docs).
pub fn generate(spec: &KernelSpec) -> Result<Kernel, InvalidInput> {
    spec.validate()?;
    let range = spec.effective_range();
    let taps = match spec.precision {
        Precision::F32 => generate_in::<f32>(spec, range),
        Precision::F64 => generate_in::<f64>(spec, range),
    };
    Ok(Kernel { spec: *spec, range, taps })
}

fn generate_in<T: Real>(spec: &KernelSpec, range_f64: f64) -> Vec<[f64; 4]> {
    let n = spec.samples;
    let range = T::of(range_f64);
    let exponent = T::of(spec.exponent);
    let zero = T::of(0.0);
    let one = T::of(1.0);
    let two = T::of(2.0);
    let falloff = spec.params.falloff.map(T::of);
    let strength = spec.params.strength.map(T::of);
    let profile: Vec<(T, T)> = kernel_profile().into_iter().map(|(v, w)| (T::of(v), T::of(w))).collect();

    // Step 1: offsets, denser near 0.
    let step = two * range / T::of((n - 1) as f64);
    let offsets: Vec<T> = (0..n)
        .map(|i| {
            let tau = -range + T::of(i as f64) * step;
            let sign = if tau < zero { -one } else { one };
            range * sign * tau.abs().powf(exponent) / range.powf(exponent)
        })
        .collect();

    // Step 2: the profile at one offset, per channel; each Gaussian exp(−u²/(2v))/(2·3.14·v), summed in order.
    let eval_profile = |x: T| -> [T; 3] {
        let mut out = [zero; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let u = x / (T::of(FALLOFF_EPSILON) + falloff[c]);
            let mut acc: Option<T> = None;
            for &(v, w) in &profile {
                let g = (-(u * u) / (two * v)).exp() / (two * T::of(PI_AS_PUBLISHED) * v);
                let term = w * g;
                acc = Some(match acc {
                    None => term,
                    Some(a) => a + term,
                });
            }
            *o = acc.unwrap_or(zero);
        }
        out
    };

    // Step 3: weights by the area rule.
    let mut taps: Vec<[T; 4]> = (0..n)
        .map(|i| {
            let w0 = if i > 0 { (offsets[i] - offsets[i - 1]).abs() } else { zero };
            let w1 = if i + 1 < n { (offsets[i] - offsets[i + 1]).abs() } else { zero };
            let area = (w0 + w1) / two;
            let p = eval_profile(offsets[i]);
            [area * p[0], area * p[1], area * p[2], offsets[i]]
        })
        .collect();

    // Step 4: centre first, the taps before it shifted up by one.
    let centre = taps[n / 2];
    for i in (1..=n / 2).rev() {
        taps[i] = taps[i - 1];
    }
    taps[0] = centre;

    // Step 5: per-channel normalisation over all N taps.
    let mut sum = [zero; 3];
    for t in &taps {
        for c in 0..3 {
            sum[c] = sum[c] + t[c];
        }
    }
    for t in &mut taps {
        for c in 0..3 {
            t[c] = t[c] / sum[c];
        }
    }

    // Step 6: strength (eq. 6.1's δ(x)·(1 − t) term lands on the centre tap).
    for c in 0..3 {
        taps[0][c] = (one - strength[c]) * one + strength[c] * taps[0][c];
    }
    for t in taps.iter_mut().skip(1) {
        for c in 0..3 {
            t[c] = t[c] * strength[c];
        }
    }

    taps.iter().map(|t| t.map(T::to_f64)).collect()
}

/// A JSON number carrying the shortest decimal that round-trips in the kernel's precision
/// (f32 kernels print `0.536343`, not the f64 expansion of the f32).
fn rounded(v: f64, precision: Precision) -> f64 {
    match precision {
        Precision::F32 => format!("{:?}", v as f32).parse::<f64>().unwrap_or(v),
        Precision::F64 => v,
    }
}

/// A separable-SSS kernel file (its schema id is the contract's, `crate::baked_layout::schema::SEPARABLE_KERNEL`). Numbers are already rounded to the kernel's
/// arithmetic precision by the writer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeparableKernelFile {
    pub schema: String,
    pub source: String,
    pub samples: usize,
    pub range: f64,
    pub exponent: f64,
    /// The shader's fixed step divisor (3).
    pub step_divisor: f64,
    /// `f32` or `f64`.
    pub precision: String,
    pub strength: [f64; 3],
    pub falloff: [f64; 3],
    /// The width (world units) the parameters were made for, if known.
    pub sss_width: Option<f64>,
    pub layout: String,
    /// `[r, g, b, offset]`, centre first.
    pub kernel: Vec<[f64; 4]>,
}

impl Kernel {
    /// The taps as `[[r, g, b, offset], …]`, centre first.
    pub fn taps_json(&self) -> Value {
        let p = self.spec.precision;
        serde_json::to_value(self.taps.iter().map(|t| t.map(|v| rounded(v, p))).collect::<Vec<_>>())
            .expect("finite taps serialise")
    }

    /// The kernel file under the schema id `schema`: `{"schema", "samples", "range", "exponent", "step_divisor",
    /// "precision", "strength", "falloff", "sss_width", "layout", "kernel": [[r, g, b, offset], …]}` (see the module
    /// docs). `sss_width` is the width the parameters were made for (world units), if known.
    pub fn to_file(&self, schema: &str, sss_width: Option<f64>, source: &str) -> SeparableKernelFile {
        let p = self.spec.precision;
        SeparableKernelFile {
            schema: schema.into(),
            source: source.into(),
            samples: self.spec.samples,
            range: rounded(self.range, p),
            exponent: rounded(self.spec.exponent, p),
            step_divisor: SHADER_STEP_DIVISOR,
            precision: p.as_str().into(),
            strength: self.spec.params.strength,
            falloff: self.spec.params.falloff,
            sss_width,
            layout: LAYOUT_DOC.into(),
            kernel: self.taps.iter().map(|t| t.map(|v| rounded(v, p))).collect(),
        }
    }

    /// HLSL / GLSL / WGSL include: `SSSS_KERNEL_N_SAMPLES`, `SSSS_KERNEL_RANGE`, `SSSS_KERNEL_EXPONENT`,
    /// `SSSS_KERNEL_STEP_DIVISOR` and the float4 array `SSSS_KERNEL` (rgb = weight, a = offset), documented in place.
    pub fn shader_include(&self, lang: ShaderLang, from: &str, sss_width: Option<f64>) -> String {
        let s = &self.spec;
        let mut inc = ShaderInclude::new(lang, from)
            .comment(&format!(
                "Separable SSS kernel (Jimenez 2012, thesis ch. 6): strength {:?}, falloff {:?}, {} arithmetic.",
                s.params.strength,
                s.params.falloff,
                s.precision.as_str()
            ))
            .comment(&format!(
                "{} taps, centre first, then offsets -RANGE..+RANGE; RANGE = {}, EXPONENT = {}.",
                s.samples, self.range, s.exponent
            ))
            .comment(
                "rgb = per-channel weight (each channel sums to 1); a = offset in kernel units (mm of the profile).",
            )
            .comment("Runtime step (fixed /3 even when RANGE = 2):")
            .comment("  step = sssWidth * (1 / tan(0.5 * FOVy)) / linearDepth * dir * strength(alpha) / 3;")
            .comment("  uv_i = texcoord + SSSS_KERNEL[i].a * step;  one kernel unit = (2/3) * sssWidth world units.");
        if let Some(w) = sss_width {
            inc = inc.comment(&format!("Parameters made for sssWidth = {w} world units."));
        }
        inc.int_const("SSSS_KERNEL_N_SAMPLES", s.samples as i64)
            .float_const("SSSS_KERNEL_RANGE", self.range)
            .float_const("SSSS_KERNEL_EXPONENT", s.exponent)
            .float_const("SSSS_KERNEL_STEP_DIVISOR", SHADER_STEP_DIVISOR)
            .vec_array("SSSS_KERNEL", &self.taps)
            .finish()
    }
}

impl Kernel {
    /// The kernel in the form `SeparableSSS.h` takes (Jimenez et al., github.com/iryoku/separable-sss): a
    /// `#define SSSS_N_SAMPLES N` and a `float4 kernel[] = { … };` array that replaces the header's whole kernel
    /// section (`#ifdef SSSS_N_SAMPLES` … its `#endif`: the runtime declaration and the three `SSSS_QUALITY`
    /// presets), so any N works and the hard-coded `#define SSSS_QUALITY 1` cannot select a preset instead.
    /// A guard `#error`s when `SSSS_N_SAMPLES` is already defined (the text pasted beside the section, not in
    /// place of it), and the licence line the header's terms ask for is carried. The array is `static const`:
    /// a plain global would be a uniform of `$Global` whose initializer D3D without the Effects framework and
    /// glslang both drop (measured: glslang's SPIR-V holds no kernel constants then), while `static const`
    /// compiles the taps into the shader. Taps are printed with 9 significant digits (f32 round-trip).
    pub fn separable_sss_h(&self, from: &str) -> String {
        let s = &self.spec;
        let n = s.samples;
        let mut t = format!("/* {} */\n", crate::io::source::preamble_text(from));
        t.push_str(SEPARABLE_SSS_NOTICE);
        t.push_str(&format!(
            "/* Separable SSS kernel, N = {n}: strength {:?}, falloff {:?}, range {}, exponent {}.\n   \
             Use: in SeparableSSS.h, replace its whole kernel section (from the line `#ifdef SSSS_N_SAMPLES` to the \
             `#endif` that closes it,\n   just before \"Porting Functions\") by this text or an #include of this \
             file; SSSS_QUALITY is then not used. The README's\n   \"Separable SSS\" section gives a one-line \
             awk command that does it. */\n",
            s.params.strength, s.params.falloff, self.range, s.exponent
        ));
        t.push_str(&format!(
            "#if defined(SSSS_N_SAMPLES)\n#error \"SSSS_N_SAMPLES is already defined: this file replaces SeparableSSS.h's \
             kernel section (see above), it is not an addition to it\"\n#endif\n\
             #define SSSS_N_SAMPLES {n}\nstatic const float4 kernel[] = {{\n"
        ));
        for tap in &self.taps {
            let c: Vec<String> = tap.iter().map(|v| format!("{:.8e}", *v as f32)).collect();
            t.push_str(&format!("    float4({}),\n", c.join(", ")));
        }
        t.push_str("};\n");
        t
    }

    /// The taps as raw little-endian `f32 × 4 × N` (`[r, g, b, offset]` per tap, centre first): the runtime
    /// upload path of `SeparableSSS.h` (`#define SSSS_N_SAMPLES N` before the include, then set `kernel`).
    pub fn f32x4_le_bytes(&self) -> Vec<u8> {
        self.taps.iter().flat_map(|t| t.iter().flat_map(|&v| (v as f32).to_le_bytes())).collect()
    }
}

/// Parses raw little-endian `f32 × 4 × N` taps (see [`Kernel::f32x4_le_bytes`]).
pub fn taps_from_f32x4_le(bytes: &[u8]) -> Result<Vec<[f32; 4]>, InvalidInput> {
    if bytes.is_empty() || !bytes.len().is_multiple_of(16) {
        return Err(InvalidInput::new(
            "kernel",
            format!("raw f32x4 kernel must be a non-empty multiple of 16 bytes, got {}", bytes.len()),
        ));
    }
    Ok(bytes
        .chunks_exact(16)
        .map(|t| std::array::from_fn(|i| f32::from_le_bytes(t[4 * i..4 * i + 4].try_into().expect("4 bytes"))))
        .collect())
}

/// The licence line SeparableSSS's terms ask for, carried by every file in its kernel form (see NOTICE).
pub const SEPARABLE_SSS_NOTICE: &str = "/* Kernel form and generator after Separable SSS \
(https://github.com/iryoku/separable-sss, BSD-style licence, see rtbake's NOTICE):\n   \
\"Uses Separable SSS. Copyright (C) 2012 by Jorge Jimenez and Diego Gutierrez.\" */\n";

/// How the `kernel` array is laid out (recorded in every kernel file).
pub const LAYOUT_DOC: &str = "kernel[i] = [r, g, b, offset]: per-channel weight (each channel sums to 1 over all \
taps) and offset in kernel units (mm of the profile); kernel[0] is the centre (offset 0), then offsets from -range \
to +range; the shader steps by sssWidth * (1/tan(FOVy/2)) / linearDepth * dir * strength / step_divisor (fixed 3)";
