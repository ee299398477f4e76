//! Grid algorithms (the bottom layer, below pipeline stage 1): the occupancy grid
//! type and the algorithms every stage stands on; it imports nothing but
//! [`crate::geom`].
//!
//! In: an [`OccupancyGrid`] (ground truth or knowledge map). Out: distances to
//! obstacles, travel distances and cheapest paths, straight legs and string
//! pulling, connected regions, and where a robot of a given radius can stand and
//! drive.
//!
//! - [`occupancy`]: cell states, the grid's placement in the world (DESIGN.md
//!   "Frames").
//! - [`distance`]: exact Euclidean distance and feature transforms.
//! - [`travel`]: travel-distance sweeps (canonical Dijkstra; Dial's bucket queue for
//!   short ones) and descent to a path.
//! - [`traversal`]: the cells a segment crosses with its parameter at each
//!   (Amanatides–Woo).
//! - [`search`]: early-stopping Dijkstra / A* with the sweep's step costs.
//! - [`mod@line`]: the supercover of a straight segment.
//! - [`path`]: string pulling and drivable shortcut paths.
//! - [`region`]: 4-connected regions (flood fill, labelling).
//! - [`cover`]: greedy set cover with lazy evaluation.
//! - [`traversability`]: clearances and drivable cells of a robot.
//! - [`terrain`]: drivable cells with their connected regions.
//! - [`window`]: rectangles of cells, and sorted cell lists updated inside them
//!   (state kept across scans).

pub mod cover;
pub mod distance;
pub mod line;
pub mod occupancy;
pub mod path;
pub mod region;
pub mod search;
pub mod terrain;
pub mod travel;
pub mod traversability;
pub mod traversal;
pub mod window;

#[cfg(test)]
pub(crate) mod fixtures;

pub use occupancy::{CellState, GridGeometry, OccupancyGrid};
pub use terrain::{Terrain, NO_REGION};
pub use travel::{DistanceField, UNREACHED};
pub use traversability::{Drivable, Traversability};
