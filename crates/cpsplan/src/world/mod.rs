//! World: occupancy grids (ground truth and knowledge map), built-in procedural maps,
//! resampling to the planning resolution, and coverage measures (pipeline stage 1).

pub mod builtin;
mod coverage;
mod grid;
pub mod region;
mod resample;
mod start;

pub use coverage::CoverageTracker;
pub use grid::{CellState, GridGeometry, OccupancyGrid};
pub use resample::resample_conservative;
pub use start::default_start;
