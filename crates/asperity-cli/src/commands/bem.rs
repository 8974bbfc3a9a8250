//! `asperity bem`: not yet implemented (placeholder until its issue lands).

/// Arguments of `asperity bem`.
#[derive(Debug, clap::Args)]
pub struct BemArgs {}

/// Runs `asperity bem`.
pub fn run(_args: &BemArgs) -> anyhow::Result<()> {
    anyhow::bail!("asperity bem is not implemented yet")
}
