//! `rtbake kernel`: separable-SSS kernel taps from strength and falloff (thesis ch. 6; library:
//! `rtbake::separable::kernel`).

use crate::cli::{parse_rgb, prepare_out_dir, usage, usage_msg, Ctx};
use rtbake::separable::kernel::{self, KernelSpec, Precision};
use rtbake::separable::{SeparableParams, PUBLISHED};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct KernelArgs {
    /// Number of taps N (odd, 3..=63; published presets: 11, 17, 25).
    #[arg(long, default_value_t = 17, allow_negative_numbers = true)]
    samples: i64,
    /// Strength per channel R,G,B in 0..=1 (fraction of light that scatters). Default: the published 0.48,0.41,0.28.
    #[arg(long, value_name = "R,G,B", allow_hyphen_values = true)]
    strength: Option<String>,
    /// Falloff per channel R,G,B, >= 0 (profile radius scale). Default: the published 1.0,0.37,0.3.
    #[arg(long, value_name = "R,G,B", allow_hyphen_values = true)]
    falloff: Option<String>,
    /// Arithmetic: f32 reproduces the shipped header's digits; f64 is the same algorithm in double precision.
    #[arg(long, value_enum, default_value_t = PrecisionArg::F32)]
    precision: PrecisionArg,
    /// Offset range in kernel units (default: the shader's rule, 3 if N > 20 else 2).
    #[arg(long, allow_negative_numbers = true)]
    range: Option<f64>,
    /// Exponent of the offset distribution (shader: 2; larger = denser near the centre).
    #[arg(long, default_value_t = kernel::DEFAULT_EXPONENT, allow_negative_numbers = true)]
    exponent: f64,
    /// Recorded in the files: the sssWidth (world units) these parameters were made for.
    #[arg(long, allow_negative_numbers = true)]
    sss_width: Option<f64>,
    /// Write <NAME>.json and <NAME>.hlsl/.glsl/.wgsl into DIR (atomically).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// File stem for --out (default: kernel_n<N>).
    #[arg(long, value_name = "NAME")]
    name: Option<String>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum PrecisionArg {
    F32,
    F64,
}

pub fn run(args: KernelArgs, ctx: &Ctx) -> anyhow::Result<()> {
    // Validate everything before any output.
    let samples = usize::try_from(args.samples).map_err(|_| {
        usage_msg(format!(
            "--samples must be an odd number of taps in {}..={}, got {}",
            kernel::MIN_SAMPLES,
            kernel::MAX_SAMPLES,
            args.samples
        ))
    })?;
    let strength = match &args.strength {
        Some(s) => parse_rgb("--strength", s)?,
        None => PUBLISHED.strength,
    };
    let falloff = match &args.falloff {
        Some(s) => parse_rgb("--falloff", s)?,
        None => PUBLISHED.falloff,
    };
    let precision = match args.precision {
        PrecisionArg::F32 => Precision::F32,
        PrecisionArg::F64 => Precision::F64,
    };
    let spec = KernelSpec {
        samples,
        params: SeparableParams { strength, falloff },
        range: args.range,
        exponent: args.exponent,
        precision,
    };
    if let Some(w) = args.sss_width {
        rtbake::error::check_positive("--sss-width", w, "world units").map_err(usage)?;
    }
    let stem = args.name.clone().unwrap_or_else(|| format!("kernel_n{samples}"));
    if !stem.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') || stem.is_empty() {
        return Err(usage_msg(format!("--name must be 1 or more characters of [A-Za-z0-9_-], got {stem:?}")));
    }
    let k = kernel::generate(&spec).map_err(usage)?;

    if let Some(dir) = &args.out {
        prepare_out_dir("--out", dir)?;
        let source = format!(
            "rtbake kernel --samples {samples} --strength {} --falloff {} --precision {}",
            join(&strength),
            join(&falloff),
            precision.as_str()
        );
        let files = rtbake::bake::separable::kernel_files("", &stem, &k, args.sss_width, &source);
        crate::cli::write_set(ctx, "--out", dir, &files, &[])?;
        ctx.info(format!("wrote {} files to {}", files.len(), dir.display()));
    }

    if ctx.json {
        ctx.emit_json(&serde_json::json!({ "kernel": k.taps_json() }));
    } else if args.out.is_none() {
        println!(
            "# {samples} taps, RANGE {}, EXPONENT {}, {} (r, g, b, offset), centre first",
            k.range,
            args.exponent,
            precision.as_str()
        );
        for t in &k.taps {
            let f = |v: f64| match precision {
                Precision::F32 => format!("{:?}", v as f32),
                Precision::F64 => format!("{v:?}"),
            };
            println!("{}, {}, {}, {}", f(t[0]), f(t[1]), f(t[2]), f(t[3]));
        }
    }
    Ok(())
}

fn join(v: &[f64; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}
