//! `rtbake fit separable`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct FitSeparableArgs {}

pub fn run(_args: FitSeparableArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("not implemented yet"))
}
