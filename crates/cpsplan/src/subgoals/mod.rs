//! Subgoals (pipeline stage 5, paper section IV-C): when no AND region joins the
//! parent's current and target positions, the move is cut into legs at subgoals
//! taken from the shortest path through a Visibility Graph, retrieved backwards
//! from the target so that each leg has an AND region.
//!
//! In: the step's maps ([`crate::children::StepMaps`]), the parent's position and
//! target, the children's cells. Out: the move's CPS cycles ([`MovePlan`]) or why
//! there are none ([`MoveError`]).
//!
//! - [`VisibilityGraph`]: the graph over the convex obstacle corners (`corners`)
//!   and its shortest paths.
//! - [`Retrieval`], [`plan_move`]: steps 1–8 of the retrieval.

mod corners;
mod retrieval;
mod visgraph;

pub use corners::{FREE_SIDE_TOLERANCE, MERGE_DISTANCE, OFFSET, RDP_TOLERANCE};
pub use retrieval::{plan_move, MoveError, MovePlan, Retrieval, FINE_SPACING_M};
pub use visgraph::{path_length, VisibilityGraph, DETAIL_LINKS};
