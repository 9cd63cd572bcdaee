//! `rtbake fit gaussians`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct FitGaussiansArgs {}

pub fn run(_args: FitGaussiansArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("not implemented yet"))
}
