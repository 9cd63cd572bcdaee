//! `rtbake importance-kernel`: an importance-sampled SSS disk kernel of any profile (library:
//! `rtbake::sss_sampling`, files: `rtbake::bake::importance::kernel_files`). The profile flags
//! ([`ImportanceProfileArgs`]) are shared with `rtbake run sss --method importance`.

use crate::cli::{prepare_out_dir, usage, usage_msg, Ctx};
use crate::profile_source::{named, BurleyArgs, LayeredArgs, Named};
use rtbake::diffusion::burley::RgbBurley;
use rtbake::diffusion::RadialProfile;
use rtbake::sss_sampling::disk::{self, ImportanceKernel, SampledProfile};
use serde_json::{json, Value};
use std::path::PathBuf;

/// The profile to sample: one of --material, --profile-preset, --layers, --skin-melanin/--skin-hemoglobin,
/// --profile-csv, --burley-albedo/--burley-mfp-mm.
#[derive(clap::Args)]
pub struct ImportanceProfileArgs {
    /// A Jensen et al. 2001 material as a dipole (eta 1.3), e.g. skin1.
    #[arg(long, value_name = "NAME")]
    pub material: Option<String>,
    /// A sum-of-Gaussians preset: deon6 (d'Eon et al. 2007 6-Gaussian skin) or deon4.
    #[arg(long, value_name = "NAME")]
    pub profile_preset: Option<String>,
    #[command(flatten)]
    pub layered: LayeredArgs,
    /// Burley's normalized diffusion (each albedo > 0 here); sampled through its closed-form CDF.
    #[command(flatten)]
    pub burley: BurleyArgs,
}

/// A resolved profile: what to sample, its provenance and a file stem.
pub struct ResolvedProfile {
    burley: Option<RgbBurley>,
    profile: Option<Box<dyn RadialProfile>>,
    pub provenance: Value,
    pub stem: String,
}

impl ImportanceProfileArgs {
    /// True when any profile flag was given.
    pub fn is_set(&self) -> bool {
        self.material.is_some() || self.profile_preset.is_some() || self.layered.is_set() || self.burley.is_set()
    }

    /// The files the profile flags read (outputs must not replace them).
    pub fn inputs(&self) -> Vec<&std::path::Path> {
        self.layered.layers.iter().chain(&self.layered.profile_csv).map(|p| p.as_path()).collect()
    }

    /// Resolves exactly one profile source (exit 2 naming the flags otherwise).
    pub fn resolve(&self, ctx: &crate::cli::Ctx) -> anyhow::Result<ResolvedProfile> {
        let given =
            [self.material.is_some(), self.profile_preset.is_some(), self.layered.is_set(), self.burley.is_set()];
        let count = given.iter().filter(|g| **g).count();
        const FLAGS: &str = "--material, --profile-preset, --layers, --skin-melanin/--skin-hemoglobin, --profile-csv \
                             or --burley-albedo/--burley-mfp-mm";
        if count != 1 {
            return Err(usage_msg(format!("give exactly one profile: {FLAGS}")));
        }
        if let Some((b, src)) = self.burley.resolve()? {
            return Ok(ResolvedProfile {
                burley: Some(b),
                profile: None,
                provenance: src.provenance(),
                stem: "burley".into(),
            });
        }
        if let Some((profile, provenance, stem)) = self.layered.resolve(ctx)? {
            return Ok(ResolvedProfile { burley: None, profile: Some(profile), provenance, stem });
        }
        let kind = match (&self.material, &self.profile_preset) {
            (Some(m), _) => Named::Material { flag: "--material", name: m },
            (None, Some(p)) => Named::Preset { flag: "--profile-preset", name: p },
            (None, None) => unreachable!("one source counted"),
        };
        let (src, profile, stem) = named(kind)?;
        Ok(ResolvedProfile { burley: None, profile: Some(profile), provenance: src.provenance(), stem })
    }
}

impl ResolvedProfile {
    /// The kernel of `samples` samples; bad input exits 2 naming the flag.
    pub fn kernel(&self, samples: usize) -> anyhow::Result<ImportanceKernel> {
        let sampled = match (&self.burley, &self.profile) {
            (Some(b), _) => SampledProfile::Burley(b),
            (None, Some(p)) => SampledProfile::Tabulated(p.as_ref()),
            (None, None) => unreachable!("resolved"),
        };
        ImportanceKernel::new(sampled, samples).map_err(|e| {
            let flag = match (e.param.as_str(), crate::flags::flag_of(&e.param)) {
                (_, Some(f @ "--samples")) => f.to_string(),
                (p, Some(f @ "--burley-albedo")) => format!("{f} {p}"),
                ("profile", _) => "profile".to_string(),
                (p, _) => format!("profile ({p})"),
            };
            usage(anyhow::anyhow!("{flag} {}", e.message))
        })
    }
}

/// `--samples N`: 1..=1024 (exit 2 naming the flag otherwise, before any work).
pub fn parse_samples(n: i64) -> anyhow::Result<usize> {
    usize::try_from(n)
        .ok()
        .and_then(|n| disk::check_samples(n).ok())
        .ok_or_else(|| usage_msg(format!("--samples must be in 1..={} samples, got {n}", disk::MAX_SAMPLES)))
}

#[derive(clap::Args)]
pub struct ImportanceKernelArgs {
    /// Sample budget N, 1..=1024 (Unity HDRP's presets: 20, 40, 80).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    samples: i64,
    #[command(flatten)]
    profile: ImportanceProfileArgs,
    /// Write {stem}_n{N}.json, .hlsl, .glsl, .wgsl and _f32x8.bin into DIR, atomically.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

pub fn run(args: ImportanceKernelArgs, ctx: &Ctx) -> anyhow::Result<()> {
    let n = parse_samples(args.samples)?;
    let resolved = args.profile.resolve(ctx)?;
    let k = resolved.kernel(n)?;
    if let Some(dir) = &args.out {
        prepare_out_dir("--out", dir)?;
    }
    let stem = rtbake::baked_layout::path::importance_kernel_stem(&resolved.stem, n);
    let source = format!("rtbake importance-kernel ({}, N = {n})", resolved.stem);
    let files = rtbake::bake::importance::kernel_files("", &stem, &k, &resolved.provenance, &source);
    if let Some(dir) = &args.out {
        crate::cli::write_set(ctx, "--out", dir, &files, &args.profile.inputs())?;
        ctx.info(format!("wrote {} files to {}", files.len(), dir.display()));
    }
    if ctx.json {
        let mut v = rtbake::bake::importance::kernel_json(&k, &resolved.provenance, &source);
        if let Some(dir) = &args.out {
            v["files"] = json!(files.iter().map(|f| dir.join(&f.path).display().to_string()).collect::<Vec<_>>());
        }
        ctx.emit_json(&v);
    } else {
        let ch = ["red", "green", "blue"][k.sampled_channel];
        println!("profile: {}", resolved.stem);
        println!("samples: {n} ({}; sampled channel: {ch}, the widest)", k.inversion.name());
        println!(
            "mean radius (mm): {:.6}, {:.6}, {:.6}",
            k.mean_radius_mm[0], k.mean_radius_mm[1], k.mean_radius_mm[2]
        );
        println!("cut-off F^-1(0.999): {:.6} mm", k.cutoff_mm);
        println!(
            "estimated totals (sum of un-normalised weights): {:.6}, {:.6}, {:.6}; profile totals {:.6}, {:.6}, {:.6}",
            k.estimated_totals[0],
            k.estimated_totals[1],
            k.estimated_totals[2],
            k.profile_totals[0],
            k.profile_totals[1],
            k.profile_totals[2]
        );
    }
    Ok(())
}
