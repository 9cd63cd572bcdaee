//! `rtbake bake`, `rtbake verify`, `rtbake assets`.

use crate::cli::{usage_msg, Ctx};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct BakeArgs {
    /// Assets to bake (default: all; see `rtbake assets`).
    pub assets: Vec<String>,
    /// Output directory.
    #[arg(long, default_value = "baked")]
    pub out: PathBuf,
}

#[derive(clap::Args)]
pub struct VerifyArgs {
    /// Bake directory holding manifest.json.
    #[arg(long, default_value = "baked")]
    pub dir: PathBuf,
}

pub fn run_bake(_a: BakeArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("not implemented yet"))
}

pub fn run_verify(_a: VerifyArgs, _ctx: &Ctx) -> anyhow::Result<()> {
    Err(usage_msg("not implemented yet"))
}

pub fn run_assets(ctx: &Ctx) -> anyhow::Result<()> {
    for a in rtbake::bake::registry() {
        ctx.info(format!("{:<28} {}", a.name, a.summary));
    }
    Ok(())
}
