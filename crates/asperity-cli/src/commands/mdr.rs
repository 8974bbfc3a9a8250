//! `asperity mdr`: not yet implemented (placeholder until its issue lands).

/// Arguments of `asperity mdr`.
#[derive(Debug, clap::Args)]
pub struct MdrArgs {}

/// Runs `asperity mdr`.
pub fn run(_args: &MdrArgs) -> anyhow::Result<()> {
    anyhow::bail!("asperity mdr is not implemented yet")
}
