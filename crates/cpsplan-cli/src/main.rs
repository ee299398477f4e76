//! The `cpsplan` command: see `cpsplan --help`.

use std::any::Any;
use std::process::ExitCode;

/// The exit code of a process whose output's reader went away (128 + SIGPIPE,
/// as a shell reports one the signal ended).
const BROKEN_PIPE_EXIT: u8 = 141;

fn main() -> ExitCode {
    // `cpsplan … | head` closes the pipe early; Rust ignores SIGPIPE, so the
    // next `println!` panics. That is no error of the run: end quietly, after
    // unwinding (which removes any temporary output), as a shell expects.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !is_broken_pipe(info.payload()) {
            default_hook(info);
        }
    }));
    let outcome = match std::panic::catch_unwind(cpsplan_cli::cli::run) {
        Ok(outcome) => outcome,
        Err(payload) if is_broken_pipe(&*payload) => return ExitCode::from(BROKEN_PIPE_EXIT),
        Err(payload) => std::panic::resume_unwind(payload),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e)
            if e.chain().any(|cause| {
                cause
                    .downcast_ref::<std::io::Error>()
                    .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            }) =>
        {
            ExitCode::from(BROKEN_PIPE_EXIT)
        }
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

/// Whether a panic is `print!`'s on a closed standard output (the message
/// the standard library gives it; the OS error is EPIPE, whatever the locale,
/// as Rust formats it).
fn is_broken_pipe(payload: &(dyn Any + Send)) -> bool {
    let message = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied());
    message
        .is_some_and(|m| m.starts_with("failed printing to stdout") && m.contains("(os error 32)"))
}
