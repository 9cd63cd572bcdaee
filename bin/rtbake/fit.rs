//! `rtbake fit gaussians|separable|burley`.

use crate::cli::Ctx;

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

pub fn run(cmd: FitCommand, ctx: &Ctx) -> anyhow::Result<()> {
    match cmd {
        FitCommand::Gaussians(a) => fit_gaussians::run(a, ctx),
        FitCommand::Separable(a) => fit_separable::run(a, ctx),
        FitCommand::Burley(a) => fit_burley::run(a, ctx),
    }
}
