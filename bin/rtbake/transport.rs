//! `rtbake transport`: Monte Carlo photon transport in a layer stack (`rtbake::transport`, MCML-style), printed or
//! written as a profile table (CSV in the `rtbake profile --csv` layout, JSON with standard errors) and plotted
//! against rtbake's diffusion model of the same stack. Parsing and validation only.

use crate::cli::{usage, usage_msg, Ctx};
use rtbake::diffusion::materials::JENSEN_2001_ETA;
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::source::ProfileSource;
use rtbake::diffusion::FdrForm;
use rtbake::error::InvalidInput;
use rtbake::plot::profile::render;
use rtbake::runtime::chain;
use rtbake::runtime::device::create_headless;
use rtbake::runtime::RuntimeError;
use rtbake::transport::compare::{bin_averaged, compare, diffusion_counterpart};
use rtbake::transport::{report, McSettings, McStack};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["material", "layers", "skin_melanin"])))]
pub struct TransportArgs {
    /// Transport layer stack JSON, top layer first (mm, mm^-1): {"eta_above": 1.0, "eta_below": 1.0, "layers":
    /// [{"thickness_mm": .. | "infinite" (last layer only), "eta": .. (>= 1), "sigma_a": [r,g,b], "sigma_s": [r,g,b]
    /// or "sigma_s_prime": [r,g,b], "g": g or [r,g,b] (default 0)}, ...]}. `rtbake profile --layers` files are
    /// accepted as they are (g = 0).
    #[arg(long, value_name = "FILE")]
    layers: Option<PathBuf>,
    /// Jensen 2001 material (eta 1.3 under air): semi-infinite (compared with the dipole), or a slab of
    /// --thickness-mm (compared with the multipole).
    #[arg(long, value_name = "NAME")]
    material: Option<String>,
    /// Slab thickness for --material, mm.
    #[arg(long, value_name = "MM", requires = "material")]
    thickness_mm: Option<f64>,
    /// Physiological two-layer skin (as `rtbake profile --skin-melanin`) with melanin volume fraction Cm in 0..=0.5.
    #[arg(long, value_name = "CM", requires = "skin_hemoglobin")]
    skin_melanin: Option<f64>,
    /// Dermal hemoglobin volume fraction Chd in 0..=0.32 for --skin-melanin.
    #[arg(long, value_name = "CHD", requires = "skin_melanin")]
    skin_hemoglobin: Option<f64>,
    /// Henyey-Greenstein anisotropy for --material and --skin-* (sigma_s = sigma_s' / (1 - g)), in (-1, 1).
    #[arg(long, value_name = "G", default_value_t = 0.0)]
    g: f64,
    /// Photons per channel, 1..=1e10 (rounded up to a multiple of --batches).
    #[arg(long, value_name = "N", default_value_t = 100_000)]
    photons: u64,
    /// Seed of the counter-based random numbers (the same seed gives the same bytes on any thread count).
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,
    /// Independent batches for the standard errors, 2..=1000.
    #[arg(long, value_name = "B", default_value_t = 10)]
    batches: u32,
    /// Radial bin width, mm (1e-6..=1e4).
    #[arg(long, value_name = "MM", default_value_t = 0.05)]
    bin_mm: f64,
    /// Number of radial bins, 1..=100000 (bins x --bin-mm <= 1e4 mm).
    #[arg(long, value_name = "N", default_value_t = 200)]
    bins: usize,
    /// Write R(r) (and T(r) for finite stacks) as CSV in the `rtbake profile --csv` layout (r_mm,R_r,R_g,R_b[,T_r,
    /// T_g,T_b], mm^-2 at the bin centres), readable by the fits' --profile-csv; standard errors are in --out.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write the full result as JSON (as --json prints): R, T, their standard errors, totals, absorbed per layer,
    /// and the diffusion comparison.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Write a plot (.png or .svg): r R(r) and R(r) from Monte Carlo with +-1 SE bars, and the diffusion model.
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Trace on the GPU (wgpu compute, f32, the same random streams; WGPU_BACKEND / WGPU_ADAPTER_NAME choose the
    /// adapter) instead of the CPU reference (f64). The outputs have the same layout; the JSON names the path and
    /// the adapter. No adapter: exit 2.
    #[arg(long)]
    gpu: bool,
}

/// Library parameter names → the flags a user typed.
fn flag_error(e: InvalidInput, layers_file: Option<&PathBuf>) -> anyhow::Error {
    const TRANSPORT_FLAGS: [&str; 5] = ["--photons", "--batches", "--bin-mm", "--bins", "--g"];
    let param = match (e.param.as_str(), crate::flags::flag_of(&e.param)) {
        (p, Some(f)) if TRANSPORT_FLAGS.contains(&f) && !p.contains('[') => f.to_string(),
        (p, _) => match layers_file {
            Some(f) => format!("--layers {}: {p}", f.display()),
            None => p.to_string(),
        },
    };
    usage(InvalidInput::new(param, e.message))
}

/// The stack, its provenance and a title.
fn resolve(args: &TransportArgs) -> anyhow::Result<(McStack, Value, String)> {
    if let Some(path) = &args.layers {
        if args.skin_melanin.is_some() || args.material.is_some() {
            return Err(usage_msg("--layers, --material and --skin-melanin are exclusive"));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| usage(anyhow::anyhow!("--layers {}: cannot read: {e}", path.display())))?;
        let stack = McStack::from_json_str(&text).map_err(|e| flag_error(e, Some(path)))?;
        let title = format!("{}-layer stack", stack.layers().len());
        return Ok((
            stack.clone(),
            json!({"layers_file": path.display().to_string(), "stack": stack.to_json()}),
            title,
        ));
    }
    if let Some(name) = &args.material {
        if args.skin_melanin.is_some() {
            return Err(usage_msg("--material and --skin-melanin are exclusive"));
        }
        let m = rtbake::diffusion::source::jensen_material("--material", name)
            .map_err(|e| usage_msg(format!("--material: {}", e.message)))?;
        let g = args.g;
        let stack = match args.thickness_mm {
            None => McStack::semi_infinite(m.sigma_a_per_mm, m.sigma_s_prime_per_mm, g, JENSEN_2001_ETA),
            Some(t) => {
                if !(t.is_finite() && t > 0.0) {
                    return Err(usage_msg(format!("--thickness-mm must be a finite number > 0 mm, got {t}")));
                }
                McStack::slab(t, m.sigma_a_per_mm, m.sigma_s_prime_per_mm, g, JENSEN_2001_ETA)
            }
        }
        .map_err(|e| flag_error(e, None))?;
        let title = match args.thickness_mm {
            None => format!("{} (semi-infinite)", m.name),
            Some(t) => format!("{} ({t} mm slab)", m.name),
        };
        return Ok((stack.clone(), json!({"material": m.name, "g": g, "stack": stack.to_json()}), title));
    }
    let (cm, chd) = (args.skin_melanin.expect("clap group"), args.skin_hemoglobin.expect("clap requires"));
    let (src, extra) = crate::profile_source::physiological_skin(
        cm,
        chd,
        Default::default(),
        Series::Exact,
        FdrForm::Dj05,
        Default::default(),
        rtbake::spectral::skin_layers::SkinProjection::BandAveraged { reduction: Default::default() },
    )?;
    let ProfileSource::Layers { stack, .. } = &src else { unreachable!("physiological skin is a layer stack") };
    let stack = McStack::from_layer_stack(stack, args.g).map_err(|e| flag_error(e, None))?;
    let mut prov = extra;
    prov["g"] = json!(args.g);
    prov["stack"] = stack.to_json();
    Ok((stack, prov, format!("skin Cm {cm}, Chd {chd}")))
}

pub fn run(args: TransportArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let settings = McSettings::new(args.photons, args.seed, args.batches, args.bin_mm, args.bins)
        .map_err(|e| flag_error(e, None))?;
    let (stack, mut provenance, title) = resolve(&args)?;
    let (bytes, seconds) =
        chain::transport_estimate(&settings, stack.layers().len(), args.gpu, rayon::current_num_threads());
    ctx.check_memory("--bins/--batches", bytes)?;
    // The per-photon figure ignores how many times each photon scatters; the stack's optics bound that (albedo,
    // g: `McSettings::time_estimate_for_stack`), on either path.
    let seconds = seconds.max(settings.time_estimate_for_stack(&stack, rayon::current_num_threads()));
    ctx.check_time(&format!("--photons {} in this stack (its albedo and g)", args.photons), seconds)?;
    let plot_format =
        crate::profile_source::check_table_outputs(&args.csv, &args.out, &args.plot, args.layers.as_slice())?;
    provenance["model"] = json!("monte-carlo (MCML, Wang, Jacques & Zheng 1995)");
    let gpu = if args.gpu {
        let g = create_headless(&Default::default()).map_err(|e| usage(anyhow::anyhow!("--gpu: {e}")))?;
        ctx.info(format!("adapter: {}", g.describe()));
        provenance["path"] = json!("gpu (wgpu compute, f32; runtime::transport_gpu)");
        provenance["adapter"] = json!(g.describe());
        Some(g)
    } else {
        provenance["path"] = json!("cpu (f64 reference; transport::mc)");
        None
    };

    let pb = ctx.progress(1000, "photons");
    let result =
        chain::transport(gpu.as_ref(), &stack, &settings, &|f| pb.set_position((f * 1000.0) as u64)).map_err(|e| {
            match e {
                RuntimeError::Invalid(e) => flag_error(e, None),
                e => anyhow::Error::new(e),
            }
        })?;
    pb.finish_and_clear();

    let diffusion = diffusion_counterpart(&stack);
    let (comparison, averaged) = match &diffusion {
        Ok((profile, _)) => {
            let avg = bin_averaged(profile.as_ref(), settings.bin_mm, settings.bins);
            if avg.iter().flatten().all(|v| v.is_finite()) {
                (Some(compare(&result, profile.as_ref(), [0.0, f64::INFINITY])), Some(avg))
            } else {
                (None, None)
            }
        }
        Err(e) => {
            ctx.info(format!("note: no diffusion comparison: {e}"));
            (None, None)
        }
    };
    let name = diffusion.as_ref().map(|d| d.1).unwrap_or("diffusion");
    let json = report::to_json(&result, &provenance, comparison.as_ref());
    let csv = report::to_csv(&result, &provenance);
    let plot_bytes = match plot_format {
        Some(format) => {
            let panels = rtbake::plot::transport::transport_panels(
                &result,
                averaged.as_deref().map(|a| (a, name)),
                &format!("{title}, Monte Carlo vs {name}"),
            );
            Some(render(&panels, format, &provenance)?)
        }
        None => None,
    };

    // Everything computed: now write (one locked set where the outputs share a directory) and print.
    let mut outputs: Vec<(&str, &Path, Vec<u8>)> = Vec::new();
    if let Some(path) = &args.csv {
        outputs.push(("--csv", path, csv.as_bytes().to_vec()));
    }
    if let Some(path) = &args.out {
        outputs.push(("--out", path, (serde_json::to_string_pretty(&json)? + "\n").into_bytes()));
    }
    if let (Some(path), Some(bytes)) = (&args.plot, &plot_bytes) {
        outputs.push(("--plot", path, bytes.clone()));
    }
    let inputs: Vec<&Path> = args.layers.iter().map(PathBuf::as_path).collect();
    crate::cli::write_outputs(ctx, &outputs, &inputs)?;
    for (c, ch) in result.channels.iter().enumerate() {
        let mut line = format!(
            "{}: Rd {:.5} ± {:.5}, T {:.5} ± {:.5}, Rsp {:.5}",
            ["R", "G", "B"][c],
            ch.diffuse_reflectance.mean,
            ch.diffuse_reflectance.se,
            ch.transmittance.mean,
            ch.transmittance.se,
            ch.specular_reflectance
        );
        if let Some(cmp) = &comparison {
            let k = &cmp.channels[c];
            line += &format!(
                "; {name} total R {:.5} ({:+.2} %), r R(r) error {}",
                k.total_r_diffusion,
                k.total_r_difference_percent,
                k.rr_error_percent.map(|e| format!("{e:.1} %")).unwrap_or("n/a".into())
            );
        }
        ctx.info(line);
    }
    if comparison.as_ref().is_some_and(|cmp| cmp.channels.iter().any(|k| k.total_r_difference_percent.abs() > 20.0)) {
        ctx.info(
            "note: large differences mean the diffusion model is outside its validity here (it assumes scattering \
             dominates absorption and layers many transport mean free paths thick); the Monte Carlo result is the \
             reference, within the ± standard errors printed",
        );
    }
    if ctx.json {
        ctx.emit_json(&json);
    } else if args.csv.is_none() && args.out.is_none() && args.plot.is_none() {
        let text: String = csv.lines().filter(|l| !l.starts_with('#')).map(|l| format!("{l}\n")).collect();
        crate::cli::print_stdout(&text);
    }
    Ok(())
}
