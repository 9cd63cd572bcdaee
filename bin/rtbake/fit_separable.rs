//! `rtbake fit separable`: fit the separable-SSS kernel's per-channel strength and falloff (width fixed) to the
//! exact 2-D kernel of a diffusion profile (thesis eq. 6.1–6.3; library: `rtbake::separable::fit`).

use crate::cli::{prepare_out_dir, usage, usage_msg, Ctx};
use crate::profile_source::{named, Named};
use rtbake::diffusion::RadialProfile;
use rtbake::separable::fit::{self, ObjectiveSpec, TargetKernel, Weighting};
use rtbake::separable::kernel::{self, KernelSpec};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct FitSeparableArgs {
    /// Target profile preset: deon6 (d'Eon et al. 2007 6-Gaussian skin) or deon4. Default: deon6.
    #[arg(long, value_name = "NAME", conflicts_with = "material")]
    profile: Option<String>,
    /// Target: a Jensen et al. 2001 material as a dipole (η = 1.3), e.g. skin1.
    #[arg(long, value_name = "NAME")]
    material: Option<String>,
    /// Layered targets: --layers FILE or the physiological skin --skin-melanin/--skin-hemoglobin.
    #[command(flatten)]
    layered: crate::profile_source::LayeredArgs,
    /// Fixed width (the shader's sssWidth, world units); only width × falloff is identifiable.
    #[arg(long, default_value_t = ObjectiveSpec::default().width, allow_negative_numbers = true)]
    width: f64,
    /// mm per world unit (125: a head 1 unit tall); one kernel unit = (2/3)·width world units.
    #[arg(long, default_value_t = ObjectiveSpec::default().mm_per_world_unit, allow_negative_numbers = true)]
    mm_per_world_unit: f64,
    /// Number of 1-D sample nodes (odd, 5..=401); the sample set is their tensor grid.
    #[arg(long, default_value_t = ObjectiveSpec::default().grid_nodes as i64, allow_negative_numbers = true)]
    grid_nodes: i64,
    /// Half-extent of the sample grid, mm.
    #[arg(long, default_value_t = ObjectiveSpec::default().grid_extent_mm, allow_negative_numbers = true)]
    grid_extent_mm: f64,
    /// Node law exponent e: x = extent·sign(τ)|τ|^e (1 = uniform; larger = denser near 0).
    #[arg(long, default_value_t = ObjectiveSpec::default().grid_exponent, allow_negative_numbers = true)]
    grid_exponent: f64,
    /// Pixel footprint, mm (default 125/720: a 125 mm head filling 720 px); the delta term and both kernels are
    /// filtered by a Gaussian of variance pixel²/12.
    #[arg(long, default_value_t = ObjectiveSpec::default().pixel_mm, allow_negative_numbers = true)]
    pixel_mm: f64,
    /// Residual weighting: samples (plain sum, eq. 6.3) or area (cell areas, ≈ eq. 6.2's integral).
    #[arg(long, value_enum, default_value_t = WeightingArg::Samples)]
    weighting: WeightingArg,
    /// Also generate the fitted kernel with this many taps (odd, 3..=63).
    #[arg(long, allow_negative_numbers = true)]
    samples: Option<i64>,
    /// Write fit_<target>.json (and the kernel files with --samples) into DIR, atomically.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum WeightingArg {
    Samples,
    Area,
}

pub fn run(args: FitSeparableArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let grid_nodes = usize::try_from(args.grid_nodes)
        .map_err(|_| usage_msg(format!("--grid-nodes must be an odd number in 5..=401, got {}", args.grid_nodes)))?;
    let spec = ObjectiveSpec {
        width: args.width,
        mm_per_world_unit: args.mm_per_world_unit,
        grid_nodes,
        grid_extent_mm: args.grid_extent_mm,
        grid_exponent: args.grid_exponent,
        pixel_mm: args.pixel_mm,
        weighting: match args.weighting {
            WeightingArg::Samples => Weighting::Samples,
            WeightingArg::Area => Weighting::Area,
        },
    };
    spec.validate().map_err(usage)?;
    let samples = match args.samples {
        None => None,
        Some(n) => {
            let n = usize::try_from(n)
                .map_err(|_| usage_msg(format!("--samples must be an odd number of taps in 3..=63, got {n}")))?;
            // Validate the tap count now, before any work.
            KernelSpec::new(n, rtbake::separable::PUBLISHED).validate().map_err(usage)?;
            Some(n)
        }
    };

    if args.layered.is_set() && (args.material.is_some() || args.profile.is_some()) {
        return Err(usage_msg("give one target: --profile, --material, --layers or --skin-melanin/--skin-hemoglobin"));
    }
    let layered = args.layered.resolve(ctx)?;
    let (profile, name, description): (Box<dyn RadialProfile>, String, String) = match (&args.material, &args.profile) {
        _ if layered.is_some() => {
            let (profile, provenance, stem) = layered.expect("checked");
            let kind = if provenance.get("skin").is_some() { "physiological skin" } else { "layer stack" };
            (profile, stem.clone(), format!("layered profile ({kind} {stem})"))
        }
        (Some(m), _) => {
            let (_, profile, stem) = named(Named::Material { flag: "--material", name: m })?;
            (profile, stem.trim_end_matches("_dipole").to_string(), format!("{m} (Jensen et al. 2001) dipole, eta 1.3"))
        }
        (None, p) => {
            let p = p.as_deref().unwrap_or("deon6");
            let (_, profile, stem) = named(Named::Preset { flag: "--profile", name: p })?;
            (profile, stem, format!("{p} profile preset (sum of Gaussians)"))
        }
    };
    if let Some(dir) = &args.out {
        prepare_out_dir("--out", dir)?;
    }

    ctx.info(format!("fitting separable kernel to {description} …"));
    let target = TargetKernel::from_profile(profile.as_ref(), &spec, &description).map_err(lib_err)?;
    let result = fit::fit(&target).map_err(lib_err)?;
    let sep = fit::separability(profile.as_ref(), &spec).map_err(lib_err)?;
    let mut report = fit::report_json(&target, &result, Some(&sep));

    let mut files = Vec::new();
    if let Some(n) = samples {
        let k = kernel::generate(&KernelSpec::new(n, result.params))?;
        report["kernel"] = k.taps_json();
        if args.out.is_some() {
            let source = format!("rtbake fit separable ({description})");
            files.extend(rtbake::bake::separable::kernel_files(
                "",
                &format!("fit_{name}_n{n}"),
                &k,
                Some(result.width),
                &source,
            ));
        }
    }
    if let Some(dir) = &args.out {
        files.push(rtbake::bake::json_file(
            &format!("fit_{name}.json"),
            &report,
            rtbake::bake::FileKind::Json,
            "separable fit report",
        ));
        let inputs: Vec<&std::path::Path> =
            args.layered.layers.iter().chain(&args.layered.profile_csv).map(|p| p.as_path()).collect();
        crate::cli::write_set(ctx, "--out", dir, &files, &inputs)?;
        ctx.info(format!("wrote {} files to {}", files.len(), dir.display()));
    }

    if ctx.json {
        ctx.emit_json(&report);
    } else {
        let p = result.params;
        println!("target: {description}");
        println!("width (fixed): {}", result.width);
        println!("strength: {:.6}, {:.6}, {:.6}", p.strength[0], p.strength[1], p.strength[2]);
        println!("falloff:  {:.6}, {:.6}, {:.6}", p.falloff[0], p.falloff[1], p.falloff[2]);
        println!(
            "objective: {:.6e} (Table 6.1 under the same objective: {:.6e}; ratio {:.4})",
            result.objective(),
            result.objective_table_6_1(),
            result.objective() / result.objective_table_6_1()
        );
        let (e, s) = (sep.energy, sep.share);
        println!(
            "first singular value: energy (σ1²/Σσ²) R {:.2} %, G {:.2} %, B {:.2} %; share (σ1/Σσ) R {:.2} %, G {:.2} %, B {:.2} %",
            100.0 * e[0],
            100.0 * e[1],
            100.0 * e[2],
            100.0 * s[0],
            100.0 * s[1],
            100.0 * s[2]
        );
    }
    Ok(())
}

/// Bad input from the library exits 2, anything else 1.
fn lib_err(e: fit::SeparableFitError) -> anyhow::Error {
    match e {
        fit::SeparableFitError::Invalid(i) => usage(i),
        other => other.into(),
    }
}
