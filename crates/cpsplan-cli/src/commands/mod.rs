//! The work of each subcommand, one module each; arguments are parsed in
//! [`crate::cli`].

pub mod explore;
pub mod instruments;
pub mod maps;
pub mod plan;

use std::path::Path;

use anyhow::{Context, Result};
use cpsplan::Config;

/// Reads a TOML configuration file, or the defaults.
pub(crate) fn read_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read config file {}", path.display()))?;
            toml::from_str::<Config>(&text)
                .map_err(|e| anyhow::anyhow!("config file {}: {}", path.display(), e.message()))
        }
        None => Ok(Config::default()),
    }
}
