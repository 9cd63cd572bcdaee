//! `rtbake run`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Subcommand)]
pub enum RunCommand {
    /// Placeholder.
    Todo,
}

pub fn run(_cmd: RunCommand, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake run: not implemented yet"))
}
