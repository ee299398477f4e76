//! The `cpsplan` command: see `cpsplan --help`.

use std::process::ExitCode;

fn main() -> ExitCode {
    match cpsplan_cli::cli::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => match e.downcast_ref::<cpsplan_cli::interrupt::Interrupted>() {
            Some(done) => {
                eprintln!("interrupted: {done}");
                ExitCode::from(cpsplan_cli::interrupt::INTERRUPTED_EXIT)
            }
            None => {
                eprintln!("error: {}", cpsplan_cli::cli::one_line(&e));
                ExitCode::from(2)
            }
        },
    }
}
