//! `rtbake`: command-line glue over the `rtbake` library. Parsing happens in two layers: clap turns flags into
//! raw arguments, each subcommand validates them into library settings; no maths lives here.
//!
//! Exit codes: 0 success, 1 runtime failure, 2 bad usage or input, 3 an output directory is locked by another
//! rtbake process and `--no-wait` was given.

mod aa;
mod bake;
mod cli;
mod evaluate;
mod fit;
mod flags;
mod importance;
mod kernel;
mod maps;
mod profile;
mod profile_source;
mod report;
mod run;
mod run_edges;
mod run_skin;
mod run_smaa_modes;
mod run_tap_grid;
mod skin_color;
mod transmittance;
mod transport;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use cli::Ctx;

#[derive(Parser)]
#[command(
    name = "rtbake",
    version,
    about = "Bake and verify lookup tables for real-time skin rendering and morphological antialiasing (Jimenez 2012)",
    propagate_version = true,
    args_override_self = true
)]
struct Cli {
    /// Machine-readable JSON results on stdout (human messages stay on stderr).
    #[arg(long, global = true)]
    json: bool,
    /// No progress bars or informational messages.
    #[arg(long, short, global = true)]
    quiet: bool,
    /// When another rtbake process is writing (or verifying) the same directory, fail at once with exit 3 instead of
    /// waiting for it.
    #[arg(long, global = true)]
    no_wait: bool,
    /// Memory budget for one command (e.g. 12G, 512M): sizes whose estimated peak memory exceeds it are refused
    /// before anything is allocated. Default: half of physical memory.
    #[arg(long, global = true, value_name = "SIZE", value_parser = cli::parse_bytes)]
    max_memory: Option<u64>,
    /// Time budget for one command in seconds: sizes whose estimated run time on this kind of machine exceeds it
    /// are refused up front, with the estimate. Default: 600.
    #[arg(long, global = true, value_name = "SECONDS", value_parser = cli::parse_seconds)]
    max_seconds: Option<f64>,
    /// Read parameters from a JSON object {"flag-name": value, ...}; flags given on the command line override it.
    #[arg(long, global = true, value_name = "FILE")]
    params: Option<std::path::PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Bake assets (all by default) into baked/ (or --out DIR) and update the manifest.
    Bake(bake::BakeArgs),
    /// Recompute every file listed in the manifest and compare; report missing, extra, modified or corrupted files.
    Verify(bake::VerifyArgs),
    /// List the bakeable assets.
    Assets,
    /// Generate SMAA / MLAA lookup textures, including variants (other distances, subsample offsets).
    Aa(aa::AaArgs),
    /// Evaluate a diffusion profile R(r) (and T(r) for slabs and layer stacks).
    Profile(profile::ProfileArgs),
    /// Fit diffusion profiles: sums of Gaussians, or the separable-SSS kernel.
    #[command(subcommand)]
    Fit(fit::FitCommand),
    /// Report the error of given parameters (Gaussians, separable strength/falloff, Burley) against a target
    /// profile; --max-error gates a pipeline (exit 1 above it).
    Evaluate(evaluate::EvaluateArgs),
    /// Generate separable-SSS kernel taps from strength and falloff.
    Kernel(kernel::KernelArgs),
    /// An importance-sampled SSS disk kernel of a profile (N samples of its radial CDF, golden-angle spiral):
    /// JSON, HLSL/GLSL/WGSL includes and an f32 table.
    ImportanceKernel(importance::ImportanceKernelArgs),
    /// Evaluate or bake the transmittance table T(s) (thesis eq. 5.12).
    Transmittance(transmittance::TransmittanceArgs),
    /// Monte Carlo photon transport in a layer stack (MCML-style): R(r), T(r) with standard errors, against diffusion.
    Transport(transport::TransportArgs),
    /// Evaluate the spectral two-layer skin model (melanin × hemoglobin → RGB albedo).
    SkinColor(skin_color::SkinColorArgs),
    /// Facial appearance maps: hemoglobin scale/bias rig, wrinkle maps.
    #[command(subcommand)]
    Maps(maps::MapsCommand),
    /// Run the GPU runtime (or its CPU reference with --cpu) on images.
    #[command(subcommand)]
    Run(run::RunCommand),
    /// Statistics of the published studies: the 2AFC chi-square of TAP 2009 Table II.
    #[command(subcommand)]
    Report(report::ReportCommand),
}

/// The command line, with every value-taking flag of every subcommand accepting a negative number after a space
/// (`--thickness-mm -1`), so the range check names the flag instead of clap reporting an unexpected `-1`.
///
/// Also: one spelling works everywhere — a command with `--out` accepts `--output` and the other way round, and
/// `--profile-preset` and `--profile` name the same flag (where a command has only one of each pair); and the
/// global options are listed under their own heading in every subcommand's help instead of mixed into its flags.
fn command() -> clap::Command {
    fn negatives(cmd: clap::Command) -> clap::Command {
        let longs: Vec<String> = cmd.get_arguments().filter_map(|a| a.get_long().map(str::to_string)).collect();
        let has = |l: &str| longs.iter().any(|x| x == l);
        let synonym = |long: &str| -> Option<&'static str> {
            let other = match long {
                "out" => "output",
                "output" => "out",
                "profile-preset" => "profile",
                "profile" => "profile-preset",
                _ => return None,
            };
            (!has(other)).then_some(other)
        };
        cmd.mut_args(|a| {
            let a = if a.is_global_set() { a.help_heading("Global options") } else { a };
            let a = match a.get_long().and_then(synonym) {
                Some(other) => a.visible_alias(other),
                None => a,
            };
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negatives)
    }
    negatives(Cli::command())
}

fn main() {
    // Behave like other Unix tools when stdout is closed early (`rtbake … | head`): end quietly, no panic.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Before any thread starts and before any command can open an adapter (`run`, `transport --gpu`).
    run::ensure_runtime_dir();
    let raw: Vec<std::ffi::OsString> = std::env::args_os().collect();
    let json = cli::json_requested(&raw);
    let argv = match cli::expand_params_file::<Cli>(raw) {
        Ok(a) => a,
        Err(e) => cli::exit_with(&e, json),
    };
    let cmd = command();
    let argv = cli::join_negative_values(argv, &cmd);
    flags::set_command(&cmd, &argv);
    let parsed = match cmd.clone().try_get_matches_from(argv.clone()).and_then(|m| Cli::from_arg_matches(&m)) {
        Ok(c) => c,
        // clap prints help/version to stdout with exit 0, usage errors to stderr with exit 2.
        Err(e) => cli::exit_clap(e, json, &cmd, &argv),
    };
    let ctx = Ctx {
        json: parsed.json,
        quiet: parsed.quiet,
        no_wait: parsed.no_wait,
        max_memory: parsed.max_memory,
        max_seconds: parsed.max_seconds,
    };
    let result = match parsed.command {
        Command::Bake(a) => bake::run_bake(a, &ctx),
        Command::Verify(a) => bake::run_verify(a, &ctx),
        Command::Assets => bake::run_assets(&ctx),
        Command::Aa(a) => aa::run(a, &ctx),
        Command::Profile(a) => profile::run(a, &ctx),
        Command::Fit(c) => fit::run(c, &ctx),
        Command::Evaluate(a) => evaluate::run(a, &ctx),
        Command::Kernel(a) => kernel::run(a, &ctx),
        Command::ImportanceKernel(a) => importance::run(a, &ctx),
        Command::Transmittance(a) => transmittance::run(a, &ctx),
        Command::Transport(a) => transport::run(a, &ctx),
        Command::SkinColor(a) => skin_color::run(a, &ctx),
        Command::Maps(c) => maps::run(c, &ctx),
        Command::Run(c) => run::run(c, &ctx),
        Command::Report(c) => report::run(c, &ctx),
    };
    if let Err(e) = result {
        cli::exit_with(&e, ctx.json);
    }
}
