//! Ctrl-C during a run: the first press asks the run to end after the scan
//! under way (its report is then written whole, marked `interrupted`); a
//! second press ends the process at once with exit code 130.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use signal_hook::consts::SIGINT;
use signal_hook::SigId;

/// The exit code of a run ended by Ctrl-C (128 + SIGINT, as shells report it).
pub const INTERRUPTED_EXIT: u8 = 130;

/// A run that ended early on Ctrl-C, after writing what it had: the binary
/// prints it and exits with [`INTERRUPTED_EXIT`].
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Interrupted(pub String);

/// The Ctrl-C handlers of one run, removed when it is dropped (so that a
/// caller embedding the command, such as the Python package, gets its own
/// handling back).
#[derive(Debug)]
pub struct CtrlC {
    flag: Arc<AtomicBool>,
    ids: Vec<SigId>,
}

impl CtrlC {
    /// Installs the handlers: the first Ctrl-C sets [`CtrlC::flag`], a second
    /// exits with [`INTERRUPTED_EXIT`]. Where no handler can be installed the
    /// flag is never set and Ctrl-C keeps its default action.
    pub fn install() -> Self {
        let flag = Arc::new(AtomicBool::new(false));
        let mut ids = Vec::new();
        // The shutdown first: it sees the flag as the press before left it.
        let shutdown = signal_hook::flag::register_conditional_shutdown(
            SIGINT,
            i32::from(INTERRUPTED_EXIT),
            Arc::clone(&flag),
        );
        if let Ok(id) = shutdown {
            ids.push(id);
            if let Ok(id) = signal_hook::flag::register(SIGINT, Arc::clone(&flag)) {
                ids.push(id);
            }
        }
        Self { flag, ids }
    }

    /// Set once Ctrl-C was pressed.
    pub fn flag(&self) -> &AtomicBool {
        &self.flag
    }

    /// Whether Ctrl-C was pressed.
    pub fn pressed(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }
}

impl Drop for CtrlC {
    fn drop(&mut self) {
        for id in self.ids.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
}
