//! `rtbake aa`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct AaArgs {}

pub fn run(_args: AaArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake aa: not implemented yet"))
}
