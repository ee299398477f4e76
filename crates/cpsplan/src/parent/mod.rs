//! The parent planner (pipeline stage 3, paper section IV-A): where the parent
//! scans next.
//!
//! In: the knowledge map after a scan and the parent's position. Out: a
//! [`ParentPlan`]: the border (step 1), the band and its samples (step 2), k-means
//! clusters (step 3), their centroids as candidates (step 4), each scored by
//! Eq. (1) `G = R·(1/P + α/L + β·S)`, and the chosen target.
//!
//! - [`border_cells`], [`significant_border`]: step 1 (`border`).
//! - [`Frontier`]: the border and the band kept across scans, updated where a scan
//!   changed the map.
//! - [`band()`]: step 2's band; [`scatter`], [`cluster_count`]: the samples and `k`.
//! - [`kmeans()`]: step 3.
//! - [`Candidate`]: step 4 and the terms of Eq. (1); [`evaluate`]: `G`.
//! - [`plan_parent`]: one whole round.
//! - [`relocations`], [`relocated_candidate`]: targets near a candidate that no CPS
//!   move reaches, and [`reachable_frontier`]: other reachable frontier cells
//!   (beyond the paper).
//! - [`open_tour`], [`covering_candidates`], [`travel_matrix`]: the tour planner
//!   (`--planner tour`, beyond the paper).
//! - [`frontier_goals`]: the nearest-frontier baseline of ROS explore_lite
//!   (`--planner frontier`); `--planner gain` takes the candidate of largest `S`.
//! - [`oracle_rate`], [`true_gain_m2`]: the oracle yardstick (`--planner
//!   oracle`): the true gain per unit of campaign time.
//! - [`TravelJitter`]: a fixed relative error on `L` for sensitivity studies
//!   (`parent.travel_jitter`).

mod band;
mod border;
mod candidate;
mod fallback;
mod frontier;
mod jitter;
mod kmeans;
mod nearest_frontier;
mod oracle;
mod planner;
mod relocation;
mod samples;
mod score;
mod tour;
mod viewpoints;

pub use band::band;
pub use border::{border_cells, significant_border};
pub use candidate::{Candidate, CandidateOrigin};
pub use fallback::{fallback_candidate, frontier_cells, reachable_frontier, CPS_FALLBACK_TRIES};
pub use frontier::Frontier;
pub use jitter::TravelJitter;
pub use kmeans::{kmeans, Clustering};
pub use nearest_frontier::{frontier_goals, nearest_valid_cell, FrontierGoal};
pub use oracle::{oracle_rate, true_gain_m2};
pub use planner::{
    plan_parent, plan_parent_with_field, plan_parent_with_reach, Decision, Kept, ParentPlan,
    ParentReach,
};
pub use relocation::{
    relocated_candidate, relocations, RELOCATE_CANDIDATES, RELOCATE_RADIUS_M, RELOCATE_SPACING_M,
    RELOCATE_TRIES,
};
pub use samples::{band_area, cluster_count, scatter};
pub use score::{evaluate, Terms};
pub use tour::{covering_candidates, open_tour, travel_matrix};
pub use viewpoints::{viewpoints, Viewpoint};
