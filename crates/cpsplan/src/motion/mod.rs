//! Motion (pipeline stage 6, paper section IV-D): safe paths for every robot
//! along the edges of the Generalized Voronoi Diagram of the known map: to the
//! nearest Voronoi edge, along it, off it to the target.
//!
//! In: the knowledge map, the robots' drivable cells, a planned move. Out: the
//! diagram ([`Gvd`]) and every robot's path ([`voronoi_path()`], [`Roads`]).
//!
//! - [`gvd()`]: the diagram.
//! - [`VoronoiField`]: its obstacle side kept across scans.
//! - [`voronoi_path()`]: one robot's path along it.
//! - [`Roads`]: the diagrams of one step and the drives of a planned move.

mod gvd;
mod roads;
mod voronoi_path;

pub(crate) use gvd::release_buffers;
pub use gvd::{gvd, Gvd, VoronoiField, MIN_EDGE_ANGLE_DEG};
pub use roads::{NoDrivablePath, Roads};
pub use voronoi_path::voronoi_path;
