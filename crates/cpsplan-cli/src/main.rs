//! The `cpsplan` command: see `cpsplan --help`.

use std::process::ExitCode;

fn main() -> ExitCode {
    match cpsplan_cli::cli::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", cpsplan_cli::cli::one_line(&e));
            ExitCode::from(2)
        }
    }
}
