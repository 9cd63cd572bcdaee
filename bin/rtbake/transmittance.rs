//! `rtbake transmittance`: not implemented yet.

use crate::cli::{usage_msg, Ctx};

#[derive(clap::Args)]
pub struct TransmittanceArgs {}

pub fn run(_args: TransmittanceArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("rtbake transmittance: not implemented yet"))
}
