//! `cpsplan completions SHELL`: the shell completions of every subcommand and
//! flag, generated from the command line's own definition.

use anyhow::Result;
use clap::Args;
use clap_complete::Shell;

/// Options of `cpsplan completions`.
#[derive(Debug, Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, elvish or powershell.
    #[arg(value_name = "SHELL")]
    pub shell: Shell,
}

/// Prints the completions script for `args.shell` of `command`, the whole
/// command line (given by `cli`, so that no command imports it back).
pub fn run(args: &CompletionsArgs, mut command: clap::Command) -> Result<()> {
    clap_complete::generate(args.shell, &mut command, "cpsplan", &mut std::io::stdout());
    Ok(())
}
