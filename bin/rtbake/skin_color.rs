//! `rtbake skin-color`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct SkinColorArgs {}

pub fn run(_args: SkinColorArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake skin-color: not implemented yet"))
}
