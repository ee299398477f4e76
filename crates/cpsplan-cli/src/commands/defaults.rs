//! `cpsplan config`: every configuration key with its default value, as the
//! TOML file `--config` reads, so that a user without the sources has the
//! reference at hand.

use anyhow::{Context, Result};
use cpsplan::Config;

/// Prints the default configuration as TOML.
pub fn print_config() -> Result<()> {
    let text =
        toml::to_string_pretty(&Config::default()).context("cannot write the configuration")?;
    println!(
        "# cpsplan's configuration with every default (cpsplan {}); a --config file\n\
         # gives any of these keys, the rest keep these values. Flags override the file.\n\n{text}",
        env!("CARGO_PKG_VERSION")
    );
    Ok(())
}
