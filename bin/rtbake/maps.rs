//! `rtbake maps`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Subcommand)]
pub enum MapsCommand {
    /// Placeholder.
    Todo,
}

pub fn run(_cmd: MapsCommand, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake maps: not implemented yet"))
}
