//! `rtbake profile`: evaluate a diffusion profile R(r) (and T(r) for slabs and layer stacks) on a radius grid and
//! print / write it as JSON or CSV, and plot it (`--plot`, PNG or SVG, optionally with a fitted sum of Gaussians).
//! Parsing and validation only; the maths is `rtbake::diffusion` and `rtbake::fitting`.

use crate::cli::AddingArg;
use crate::cli::{parse_f64_list, usage, usage_msg, Ctx};
use rtbake::diffusion::layered::LayerStack;
use rtbake::diffusion::multipole::Series;
use rtbake::diffusion::source::{MaterialModel, ProfileSource};
use rtbake::diffusion::table::{self, ProfileTable};
use rtbake::diffusion::FdrForm;
use rtbake::error::InvalidInput;
use rtbake::fitting::{fit_sum_of_gaussians, FitSettings};
use rtbake::plot::profile::{profile_panels, render};
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ModelArg {
    /// Semi-infinite medium (Jensen et al. 2001).
    Dipole,
    /// Slab of --thickness-mm in air (Donner & Jensen 2005); also prints T(r). With --layers / --skin-*: the
    /// layered multipole (the default there).
    Multipole,
    /// Monte Carlo photon transport (MCML-style) for --layers and --skin-* (--g, --photons, --seed).
    Mc,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum FdrArg {
    /// Donner & Jensen 2005 polynomial (full digits).
    Dj05,
    /// Jensen et al. 2001 polynomial as printed (rounded).
    Jensen01,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["material", "profile_preset", "layers", "skin_melanin", "burley_albedo"])))]
pub struct ProfileArgs {
    /// Jensen 2001 measured material (apple, chicken1, chicken2, cream, ketchup, marble, potato, skimmilk, skin1,
    /// skin2, wholemilk); eta = 1.3.
    #[arg(long, value_name = "NAME")]
    material: Option<String>,
    /// Model: for --material dipole (default) or multipole; for --layers / --skin-* multipole (diffusion) or mc
    /// (Monte Carlo transport).
    #[arg(long, value_enum, default_value = "dipole")]
    model: ModelArg,
    #[command(flatten)]
    mc: crate::profile_source::McArgs,
    /// How --skin-* spectra become RGB: spectral (per-wavelength profiles projected to linear sRGB under D65,
    /// default) or band-averaged (one RGB stack of averaged coefficients).
    #[arg(long, value_enum, default_value = "spectral")]
    skin_projection: crate::profile_source::SkinProjectionArg,
    /// Slab thickness for --model multipole, mm (must exceed 1/sigma_t' of every channel).
    #[arg(long, value_name = "MM")]
    thickness_mm: Option<f64>,
    /// Published sum-of-Gaussians profile: deon6 (d'Eon et al. 2007) or deon4 (thesis Table 4.2).
    #[arg(long, value_name = "NAME")]
    profile_preset: Option<String>,
    /// Layer stack JSON, top layer first (mm, mm^-1): {"eta_above": 1.0, "eta_below": 1.0, "layers":
    /// [{"thickness_mm": .., "eta": .., "sigma_a": [r,g,b], "sigma_s_prime": [r,g,b]}, ...]}.
    #[arg(long, value_name = "FILE")]
    layers: Option<PathBuf>,
    /// Physiological two-layer skin (Donner & Jensen 2006 coefficients, `skin-color.md`; epidermis 0.25 mm over
    /// dermis 20 mm, eta 1.4) with melanin volume fraction Cm in 0..=0.5 (needs --skin-hemoglobin). Per-channel
    /// coefficients are D65 x linear-sRGB-sensitivity weighted spectral means.
    #[arg(long, value_name = "CM", requires = "skin_hemoglobin")]
    skin_melanin: Option<f64>,
    /// Dermal hemoglobin volume fraction Chd in 0..=0.32 for --skin-melanin.
    #[arg(long, value_name = "CHD", requires = "skin_melanin")]
    skin_hemoglobin: Option<f64>,
    #[command(flatten)]
    burley: crate::profile_source::BurleyArgs,
    /// How layers are combined (--layers and --skin-* only).
    #[arg(long, value_enum, default_value = "symmetric")]
    adding: AddingArg,
    /// Sum image pairs i = -N..N instead of the exact infinite series (multipole and --layers only; N in 0..=10000;
    /// DJ05 used 5). Default: exact series.
    #[arg(long, value_name = "N")]
    dipole_pairs: Option<u32>,
    /// Polynomial for the average diffuse Fresnel reflectance Fdr(eta).
    #[arg(long, value_enum, default_value = "dj05")]
    fdr: FdrArg,
    /// Radii in mm, comma-separated, ascending, in 0..=1000. Default: --count radii log-spaced over [--r-min-mm, --r-max-mm].
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    radii: Option<String>,
    /// Smallest radius of the default log grid, mm (> 0).
    #[arg(long, value_name = "MM", default_value_t = table::DEFAULT_R_MIN_MM)]
    r_min_mm: f64,
    /// Largest radius of the default log grid, mm (> --r-min-mm, <= 1000).
    #[arg(long, value_name = "MM", default_value_t = table::DEFAULT_R_MAX_MM)]
    r_max_mm: f64,
    /// Number of radii of the default log grid (2..=1000000).
    #[arg(long, value_name = "N", default_value_t = table::DEFAULT_COUNT)]
    count: usize,
    /// Also write the table as CSV (r_mm, R per channel, T per channel; totals and options in '#' lines).
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Also write the table as JSON (same object as --json prints).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Also write a plot, PNG or SVG by the extension (.png / .svg): two stacked panels over a log r axis (mm),
    /// r R(r) on a linear y axis above and R(r) on a log y axis below, at the tabulated radii; solid R per channel,
    /// dashed lighter T where present, dashed darker --overlay-fit. PNG and SVG carry the same text: titles,
    /// tick labels, axis names with units and the legend.
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Overlay a K-Gaussian fit with shared variances (R, G, B share the variances; fitted in profile units, not
    /// normalised; 8 deterministic starts) on --plot. K in 2..=8.
    #[arg(long, value_name = "K", requires = "plot")]
    overlay_fit: Option<usize>,
}

/// Renames library parameter names to the flags a user typed.
fn flag_error(e: InvalidInput, layers_file: Option<&PathBuf>) -> anyhow::Error {
    const PROFILE_FLAGS: [&str; 7] =
        ["--material", "--profile-preset", "--thickness-mm", "--radii", "--r-min-mm", "--r-max-mm", "--count"];
    let param = match (e.param.as_str(), crate::flags::flag_of(&e.param)) {
        (p, Some(f)) if PROFILE_FLAGS.contains(&f) && !p.contains('[') => f.to_string(),
        (p, _) if p.starts_with("layers") || p.starts_with("eta_") => match layers_file {
            Some(f) => format!("--layers {}: {p}", f.display()),
            None => p.to_string(),
        },
        (p, _) => p.to_string(),
    };
    usage(InvalidInput::new(param, e.message))
}

/// A non-finite result names the input that produced it (the layer file, material or preset).
fn non_finite_error(e: InvalidInput, args: &ProfileArgs) -> anyhow::Error {
    if e.param != "profile" {
        return flag_error(e, None);
    }
    let input = if let Some(l) = &args.layers {
        format!("--layers {}", l.display())
    } else if let Some(m) = &args.material {
        format!("--material {m}")
    } else if let Some(p) = &args.profile_preset {
        format!("--profile-preset {p}")
    } else if args.burley.is_set() {
        if e.message.contains("at r = 0 mm") {
            // R(r) = A·s·(e^(−s·r/d) + e^(−s·r/(3d))) / (8π·d·r) diverges at r = 0: the radius is at fault.
            return usage(InvalidInput::new(
                "--radii",
                "includes r = 0, where Burley's normalized diffusion R(r) diverges (it falls as 1/r from r = 0; \
                 Christensen & Burley 2015); give radii > 0 (e.g. the default log grid from --r-min-mm)",
            ));
        }
        "--burley-albedo/--burley-mfp-mm".to_string()
    } else {
        "--skin-melanin/--skin-hemoglobin".to_string()
    };
    usage(InvalidInput::new(format!("{input}:"), e.message))
}

pub fn run(args: ProfileArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let fdr = match args.fdr {
        FdrArg::Dj05 => FdrForm::Dj05,
        FdrArg::Jensen01 => FdrForm::Jensen01,
    };
    if let Some(n) = args.dipole_pairs {
        if n > 10_000 {
            return Err(usage_msg(format!("--dipole-pairs must be in 0..=10000, got {n}")));
        }
    }
    let series = args.dipole_pairs.map(|pairs| Series::Truncated { pairs }).unwrap_or_default();
    let layered = args.layers.is_some() || args.skin_melanin.is_some();
    let multipole = args.material.is_some() && matches!(args.model, ModelArg::Multipole);
    if args.dipole_pairs.is_some() && !(layered || multipole) {
        return Err(usage_msg("--dipole-pairs applies only to --model multipole and --layers"));
    }
    if args.thickness_mm.is_some() && !multipole {
        return Err(usage_msg("--thickness-mm applies only to --material with --model multipole"));
    }

    let transport = args.mc.transport(if matches!(args.model, ModelArg::Mc) {
        crate::profile_source::TransportArg::Mc
    } else {
        crate::profile_source::TransportArg::Multipole
    })?;
    if matches!(args.model, ModelArg::Mc) && !layered {
        return Err(usage_msg("--model mc applies to --layers and --skin-melanin/--skin-hemoglobin"));
    }
    let mut extra = serde_json::Value::Null;
    let source = if let Some(name) = &args.material {
        let model = match args.model {
            ModelArg::Dipole | ModelArg::Mc => MaterialModel::Dipole,
            ModelArg::Multipole => MaterialModel::Multipole {
                thickness_mm: args
                    .thickness_mm
                    .ok_or_else(|| usage_msg("--model multipole needs --thickness-mm (slab thickness in mm)"))?,
            },
        };
        ProfileSource::Material { name: name.clone(), model, fdr, series }
    } else if let Some(name) = &args.profile_preset {
        ProfileSource::Preset(name.clone())
    } else if let Some(path) = &args.layers {
        let text = std::fs::read_to_string(path)
            .map_err(|e| usage(anyhow::anyhow!("--layers {}: cannot read: {e}", path.display())))?;
        let stack = LayerStack::from_json_str(&text).map_err(|e| flag_error(e, Some(path)))?;
        ProfileSource::Layers { stack, adding: args.adding.into(), series, fdr, transport }
    } else if let Some((_, src)) = args.burley.resolve()? {
        src
    } else if let (Some(cm), Some(chd)) = (args.skin_melanin, args.skin_hemoglobin) {
        let (src, skin) = crate::profile_source::physiological_skin(
            cm,
            chd,
            args.adding.into(),
            series,
            fdr,
            transport,
            args.skin_projection.into(),
        )?;
        extra = skin;
        src
    } else {
        return Err(usage_msg("one of --material, --profile-preset or --layers is required"));
    };

    let radii = match &args.radii {
        Some(list) => {
            let r = parse_f64_list("--radii", list)?;
            table::check_radii("radii", &r).map_err(|e| flag_error(e, None))?;
            r
        }
        None => table::log_radii(args.r_min_mm, args.r_max_mm, args.count).map_err(|e| flag_error(e, None))?,
    };

    let plot_format =
        crate::profile_source::check_table_outputs(&args.csv, &args.out, &args.plot, args.layers.as_slice())?;
    let fit_settings =
        args.overlay_fit.map(|count| FitSettings { count, shared_variances: true, normalize: false, starts: 8 });
    if let Some(s) = &fit_settings {
        s.validate().map_err(|e| match e.param.as_str() {
            // The overlay fit's count is set by its own flag here.
            "count" => usage(InvalidInput::new("--overlay-fit", e.message)),
            _ => flag_error(e, None),
        })?;
    }

    if layered {
        let grid = if args.radii.is_some() { "--radii" } else { "--count" };
        let estimate = source.time_estimate_seconds(radii.len(), rayon::current_num_threads());
        let what = match source.transport() {
            Some(rtbake::diffusion::source::TransportModel::MonteCarlo { g, photons, .. }) => {
                format!("--model mc --photons {photons} --g {g}")
            }
            _ => {
                let pairs = match series {
                    Series::Exact => "exact series".to_string(),
                    Series::Truncated { pairs } => format!("--dipole-pairs {pairs}"),
                };
                format!("{grid} ({} radii), {pairs}", radii.len())
            }
        };
        ctx.check_time(&what, estimate)?;
    }
    let profile = source.build().map_err(|e| flag_error(e, args.layers.as_ref()))?;
    let mut provenance = source.provenance();
    if let (serde_json::Value::Object(p), serde_json::Value::Object(e)) = (&mut provenance, extra) {
        p.extend(e);
    }
    crate::profile_source::add_standard_errors(&mut provenance, profile.as_ref());
    let table = ProfileTable::compute(profile.as_ref(), &radii, provenance).map_err(|e| non_finite_error(e, &args))?;
    let json = table.to_json();
    let plot_bytes = match plot_format {
        Some(format) => {
            let fit = match &fit_settings {
                Some(s) => Some(fit_sum_of_gaussians(profile.as_ref(), s).map_err(crate::fit::fit_error)?),
                None => None,
            };
            let panels = profile_panels(&table, fit.as_ref().map(|f| &f.sum), &plot_title(&source));
            let mut provenance = table.provenance.clone();
            if let (Some(f), Some(s)) = (&fit, &fit_settings) {
                provenance["overlay_fit"] = serde_json::json!({
                    "count": s.count, "shared_variances": s.shared_variances, "normalize": s.normalize,
                    "starts": s.starts, "variances_mm2": f.sum.variances_mm2[0], "weights": f.sum.weights,
                    "error_percent": f.error_percent,
                });
            }
            Some(render(&panels, format, &provenance)?)
        }
        None => None,
    };

    // Everything computed: now write (atomically) and print.
    if let Some(path) = &args.csv {
        rtbake::io::atomic::write_atomic(path, table.to_csv().as_bytes())?;
        ctx.info(format!("wrote {}", path.display()));
    }
    if let Some(path) = &args.out {
        let text = serde_json::to_string_pretty(&json)? + "\n";
        rtbake::io::atomic::write_atomic(path, text.as_bytes())?;
        ctx.info(format!("wrote {}", path.display()));
    }
    if let (Some(path), Some(bytes)) = (&args.plot, &plot_bytes) {
        rtbake::io::atomic::write_atomic(path, bytes)?;
        ctx.info(format!("wrote {}", path.display()));
    }
    // Totals are messages (stderr); stdout is pure CSV, and only when no file was asked for.
    if let Some(note) = table.clamped_negative.describe() {
        ctx.info(format!("note: {note}"));
    }
    let t = &table.total_reflectance;
    ctx.info(format!("total R (r, g, b): {:.6} {:.6} {:.6}", t[0], t[1], t[2]));
    if let Some(t) = &table.total_transmittance {
        ctx.info(format!("total T (r, g, b): {:.6} {:.6} {:.6}", t[0], t[1], t[2]));
    }
    let wrote_file = args.csv.is_some() || args.out.is_some() || args.plot.is_some();
    if ctx.json {
        ctx.emit_json(&json);
    } else if !wrote_file {
        let mut text = String::new();
        for line in table.to_csv().lines().filter(|l| !l.starts_with('#')) {
            text.push_str(line);
            text.push('\n');
        }
        // A closed pipe (`| head`) is not an error.
        use std::io::Write;
        if let Err(e) = std::io::stdout().lock().write_all(text.as_bytes()) {
            if e.kind() != std::io::ErrorKind::BrokenPipe {
                return Err(e.into());
            }
        }
    }
    Ok(())
}

/// Before any work: `path` must not be a directory, and its directory must exist and accept a new file.
pub(crate) fn check_output_file(flag: &str, path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        return Err(usage_msg(format!("{flag} {}: is a directory, expected a file path", path.display())));
    }
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(usage_msg(format!("{flag} {}: directory {} does not exist", path.display(), dir.display())));
    }
    rtbake::io::file_set::check_dir_writable(dir)
        .map_err(|e| usage(anyhow::anyhow!("{flag} {}: directory is not writable: {e}", path.display())))
}

/// Plot title naming the profile.
fn plot_title(source: &ProfileSource) -> String {
    match source {
        ProfileSource::Material { name, model: MaterialModel::Dipole, .. } => format!("{name} (dipole)"),
        ProfileSource::Material { name, model: MaterialModel::Multipole { thickness_mm }, .. } => {
            format!("{name} (multipole, {thickness_mm} mm slab)")
        }
        ProfileSource::Preset(name) => format!("{name} (sum of Gaussians)"),
        ProfileSource::Burley { fit, .. } => format!("Burley normalized diffusion ({} fit)", fit.name()),
        ProfileSource::Layers { stack, adding, transport, .. } => match transport {
            rtbake::diffusion::source::TransportModel::Multipole => {
                format!("{}-layer stack ({} adding)", stack.layers().len(), adding.name())
            }
            rtbake::diffusion::source::TransportModel::MonteCarlo { g, .. } => {
                format!("{}-layer stack (Monte Carlo, g {g})", stack.layers().len())
            }
        },
        ProfileSource::Spectral { transport, adding, .. } => match transport {
            rtbake::diffusion::source::TransportModel::Multipole => {
                format!("spectral skin ({} adding, projected to linear sRGB)", adding.name())
            }
            rtbake::diffusion::source::TransportModel::MonteCarlo { g, .. } => {
                format!("spectral skin (Monte Carlo, g {g}, projected to linear sRGB)")
            }
        },
    }
}
