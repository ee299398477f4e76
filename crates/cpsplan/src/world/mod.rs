//! World: occupancy grids (ground truth and knowledge map), built-in procedural maps,
//! resampling to the planning resolution, and coverage measures (pipeline stage 1).

mod grid;

pub use grid::{CellState, GridGeometry, OccupancyGrid};
