//! `rtbake fit gaussians|separable|burley`.

use crate::cli::{usage_msg, Ctx};
use crate::profile_source::{Named, ResolvedProfile};

#[path = "fit_burley.rs"]
mod fit_burley;
#[path = "fit_gaussians.rs"]
mod fit_gaussians;
#[path = "fit_separable.rs"]
mod fit_separable;

#[derive(clap::Subcommand)]
pub enum FitCommand {
    /// Fit a sum of Gaussians (thesis eq. 2.2) to a diffusion profile.
    Gaussians(fit_gaussians::FitGaussiansArgs),
    /// Fit the separable-SSS kernel's strength and falloff (thesis eq. 6.1–6.3).
    Separable(fit_separable::FitSeparableArgs),
    /// Fit Burley's normalized diffusion (albedo A and shape parameter d per channel, Christensen & Burley 2015).
    Burley(fit_burley::FitBurleyArgs),
}

pub use fit_gaussians::fit_error;

/// The profile `fit gaussians` and `fit burley` fit: a named material or preset, or a layered target.
#[derive(clap::Args)]
pub struct FitTarget {
    /// Target: a Jensen 2001 material as a dipole (η = 1.3, DJ05 Fdr): apple, chicken1, …, wholemilk.
    #[arg(long, value_name = "NAME", conflicts_with = "profile_preset")]
    pub material: Option<String>,
    /// Target: a sum-of-Gaussians preset: deon6 | deon4.
    #[arg(long, value_name = "NAME")]
    pub profile_preset: Option<String>,
    /// Layered targets (--layers, --skin-melanin/--skin-hemoglobin) or your own profile (--profile-csv).
    #[command(flatten)]
    pub layered: crate::profile_source::LayeredArgs,
}

impl FitTarget {
    /// The target the flags give (profile, provenance, file stem), `None` when none is given; more than one is
    /// refused (exit 2).
    pub fn resolve(&self, ctx: &Ctx) -> anyhow::Result<Option<ResolvedProfile>> {
        if self.layered.is_set() && (self.material.is_some() || self.profile_preset.is_some()) {
            return Err(usage_msg(
                "give one target: --material, --profile-preset, --layers, --skin-melanin/--skin-hemoglobin or \
                 --profile-csv",
            ));
        }
        if let Some(resolved) = self.layered.resolve(ctx)? {
            return Ok(Some(resolved));
        }
        let named = match (&self.material, &self.profile_preset) {
            (Some(name), _) => Named::Material { flag: "--material", name },
            (None, Some(name)) => Named::Preset { flag: "--profile-preset", name },
            (None, None) => return Ok(None),
        };
        let (src, profile, stem) = crate::profile_source::named(named)?;
        Ok(Some((profile, src.provenance(), stem)))
    }
}

pub fn run(cmd: FitCommand, ctx: &Ctx) -> anyhow::Result<()> {
    match cmd {
        FitCommand::Gaussians(a) => fit_gaussians::run(a, ctx),
        FitCommand::Separable(a) => fit_separable::run(a, ctx),
        FitCommand::Burley(a) => fit_burley::run(a, ctx),
    }
}
