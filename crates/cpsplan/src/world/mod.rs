//! World (pipeline stage 1): the ground truth of a simulation and what is done
//! with it before planning starts.
//!
//! In: a map ([`OccupancyGrid`], from a file, from a point cloud by
//! [`projection`], or [`builtin`]). Out: the map at the
//! planning resolution ([`resample_conservative`]), a start ([`default_start`]),
//! and the coverage measures of an episode ([`CoverageTracker`]). Stands on
//! [`crate::grid`] only; the grid types are re-exported here.

pub mod builtin;
mod coverage;
pub mod projection;
mod resample;
mod start;

pub use crate::grid::{CellState, GridGeometry, OccupancyGrid};
pub use coverage::CoverageTracker;
pub use resample::{resample_conservative, resample_for, resampled_size};
pub use start::default_start;
