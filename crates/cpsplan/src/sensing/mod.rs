//! Sensing: the simulated omni-directional laser scanner on the parent robot
//! (pipeline stage 2) and the exact grid visibility it shares with the planner.
//!
//! Two visibility rules use the same sweep ([`visible_cells`]): the scanner sees
//! the ground truth (everything but free space stops the beam), and the planner's
//! expected gain `S` (Eq. 1) looks through Unknown cells, stopped only by known
//! obstacles. Because both use one rule, a scan taken at a candidate reveals every
//! cell that was counted in its `S` or the obstacle that hides it.

mod scanner;
mod shadowcast;

pub use scanner::{expected_gain, scan, ScanOutcome};
pub use shadowcast::visible_cells;
