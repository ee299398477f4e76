//! Planning: the parent planner of section IV-A and the grid machinery it stands on
//! (distance transform, travel-distance sweep, traversability, straight legs,
//! drivable paths).

pub mod and_region;
pub mod children;
pub mod cps_cycle;
pub mod cps_maps;
pub mod distance;
pub mod frontier;
pub mod kmeans;
pub mod line;
mod parent;
pub mod path;
pub mod reach;
pub mod score;
pub mod search;
pub mod subgoals;
pub mod terrain;
pub mod traversability;
pub mod visgraph;
pub mod voronoi;

pub use parent::{
    plan_parent, plan_parent_with_reach, relocated_candidate, Candidate, CandidateOrigin, Decision,
    ParentPlan, ParentReach,
};
pub use traversability::Traversability;
