//! `rtbake kernel`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct KernelArgs {}

pub fn run(_args: KernelArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake kernel: not implemented yet"))
}
