//! Sensing (pipeline stage 2): the simulated omni-directional laser scanner on the
//! parent robot and the exact grid visibility it shares with the planner.
//!
//! In: the ground truth or the knowledge map and a position. Out: the cells a scan
//! reveals ([`scan`]), the expected gain `S` of Eq. (1) ([`expected_gain`]), and the
//! certain views that CPS links need ([`View`], [`mutual_view`]).
//!
//! Two visibility rules use the same sweep ([`visible_cells`]): the scanner sees
//! the ground truth (everything but free space stops the beam), and the planner's
//! expected gain `S` (Eq. 1) looks through Unknown cells, stopped only by known
//! obstacles. Because both use one rule, a scan taken at a candidate reveals every
//! cell that was counted in its `S` or the obstacle that hides it. CPS links use
//! *certain* visibility: only known-Free cells let the beam through, and a line of
//! sight may not touch a non-Free cell's square or come nearer to it than the
//! sight clearance ([`sight_clear`]).

mod gain;
mod kept_views;
mod observed;
mod scanner;
mod shadowcast;
mod sight;
mod sight_sweep;
mod view;
mod view_runs;

pub use gain::{Gain, GainEstimate, NearField};
pub use kept_views::{MAX_KEPT_CELLS, MAX_KEPT_VIEWS};
pub use observed::{observed_walls, Neighbours, RangeImage, GAP_CELLS, NUDGE_CELLS, RANGE_BINS};
pub use scanner::{expected_gain, scan, scan_by, seen_walls, true_gain, ScanOutcome};
pub use shadowcast::visible_cells;
pub use sight::{sight_clear, target_in_sight, LinkRule, SightField};
pub use sight_sweep::certain_cells;
pub use view::{certain_view, mutual_view, seen_by_both, View};
