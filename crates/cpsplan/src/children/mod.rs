//! The children and the CPS cycle (pipeline stage 4, paper section IV-B): where
//! the child robots stand so that the parent measures them from its current and
//! its next position.
//!
//! In: the knowledge map, the parent's two positions and the children's cells.
//! Out: each child's [`AndRegion`] (cells in certain line of sight from both parent
//! positions, in range, drivable and reachable for the child), the children's spots
//! chosen jointly by Eq. (2) `Gc = 1/P + αc/|θ − θt| + βc/|D − Dt|`
//! ([`place_children`]), and one planned cycle ([`place_cycle`]); a child already in
//! its AND region stays.
//!
//! - [`StepMaps`]: what every cycle, subgoal and candidate of one step shares.
//! - [`and_region()`], [`ChildReach`]: the AND region.
//! - [`place_children`], [`Eq2`]: Eq. (2); [`clearances`]: its `1/P`.
//! - [`place_cycle`], [`CpsCycle`]: one cycle; [`frame_cycle`], [`CycleFrame`]:
//!   its AND regions and who stays, before any spots are chosen.
//! - [`place_random`], [`place_min_error`]: the strategies beyond Eq. (2)'s
//!   weights (random spots; the spots that minimise the predicted error).

mod and_region;
mod clearance;
mod cycle;
mod maps;
mod pair_search;
mod params;
mod placement;
mod spacing;
mod strategy;

pub use and_region::{and_region, AndRegion, ChildReach};
pub use clearance::clearances;
pub use cycle::{frame_cycle, place_cycle, CpsCycle, CycleChild, CycleError, CycleFrame};
pub use maps::StepMaps;
pub use pair_search::SEARCH_GAP;
pub use params::{target_rule, CycleParams};
pub use placement::{place_children, Eq2, Placement, Spot, EPS_D, EPS_THETA};
pub use spacing::apart;
pub use strategy::{place_min_error, place_random, SPOT_PITCH_M};

#[cfg(test)]
pub(crate) use cycle::tests::{params as test_params, plan_cycle as test_plan_cycle};
