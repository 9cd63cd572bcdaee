//! `rtbake kernel`: separable-SSS kernel taps from strength and falloff (thesis ch. 6; library:
//! `rtbake::separable::kernel`).

use crate::cli::{parse_rgb, prepare_out_dir, usage, usage_msg, Ctx};
use rtbake::separable::fit::{self, ObjectiveSpec};
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
    /// Instead of --strength/--falloff: fit them to a profile first (as `rtbake fit separable` does, width
    /// --sss-width or 0.014) — your own --profile-csv, a --layers stack or the physiological --skin-*.
    #[command(flatten)]
    layered: crate::profile_source::LayeredArgs,
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
    let fitted = fitted_params(&args, ctx)?;
    let (strength, falloff) = match &fitted {
        Some((p, _)) => (p.strength, p.falloff),
        None => (
            match &args.strength {
                Some(s) => parse_rgb("--strength", s)?,
                None => PUBLISHED.strength,
            },
            match &args.falloff {
                Some(s) => parse_rgb("--falloff", s)?,
                None => PUBLISHED.falloff,
            },
        ),
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
    let stem = args.name.clone().unwrap_or_else(|| format!("kernel_n{samples}"));
    if !stem.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') || stem.is_empty() {
        return Err(usage_msg(format!("--name must be 1 or more characters of [A-Za-z0-9_-], got {stem:?}")));
    }
    let k = kernel::generate(&spec).map_err(usage)?;

    if let Some(dir) = &args.out {
        prepare_out_dir("--out", dir)?;
        let mut source = format!(
            "rtbake kernel --samples {samples} --strength {} --falloff {} --precision {}",
            join(&strength),
            join(&falloff),
            precision.as_str()
        );
        if let Some((_, from)) = &fitted {
            source.push_str(&format!(" (strength and falloff fitted to {from})"));
        }
        let width = args.sss_width.or(fitted.as_ref().map(|_| ObjectiveSpec::default().width));
        let files = rtbake::bake::separable::kernel_files("", &stem, &k, width, &source);
        crate::cli::write_set(ctx, "--out", dir, &files, &[])?;
        ctx.info(format!("wrote {} files to {}", files.len(), dir.display()));
    }

    if ctx.json {
        let mut v = serde_json::json!({ "kernel": k.taps_json(), "strength": strength, "falloff": falloff });
        if let Some((_, from)) = &fitted {
            v["fitted_to"] = serde_json::json!(from);
        }
        ctx.emit_json(&v);
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

/// Strength and falloff fitted to the layered / CSV profile, if one was given (width: --sss-width or the fit's
/// default), with a description of the target.
fn fitted_params(args: &KernelArgs, ctx: &Ctx) -> anyhow::Result<Option<(SeparableParams, String)>> {
    if let Some(w) = args.sss_width {
        rtbake::error::check_positive("--sss-width", w, "world units").map_err(usage)?;
    }
    if !args.layered.is_set() {
        return Ok(None);
    }
    if args.strength.is_some() || args.falloff.is_some() {
        return Err(usage_msg(
            "--strength/--falloff and a profile (--profile-csv, --layers, --skin-*) are exclusive: the profile's are fitted",
        ));
    }
    let (profile, provenance, stem) = args.layered.resolve(ctx)?.expect("is_set");
    let spec = ObjectiveSpec { width: args.sss_width.unwrap_or(ObjectiveSpec::default().width), ..Default::default() };
    let target = fit::TargetKernel::from_profile(profile.as_ref(), &spec, &stem).map_err(usage)?;
    let result = fit::fit(&target)?;
    let from = provenance.get("file").and_then(|f| f.as_str()).map(str::to_string).unwrap_or(stem);
    Ok(Some((result.params, from)))
}

fn join(v: &[f64; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}
