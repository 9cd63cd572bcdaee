//! `rtbake profile`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct ProfileArgs {}

pub fn run(_args: ProfileArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake profile: not implemented yet"))
}
