//! `topple impact FILE`: JSON in, JSON out.

use std::path::PathBuf;

/// Arguments of `topple impact`.
#[derive(clap::Args)]
pub struct Args {
    /// JSON file with bodies and contacts, or - for stdin.
    pub file: PathBuf,
}

pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
