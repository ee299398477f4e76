//! # cpsplan
//!
//! Scan planning for a cooperative multi-robot laser-scanning system (CPS-SLAM,
//! Kurazume et al., IROS 2015). The modules follow the paper's pipeline (Fig. 3):
//!
//! - [`world`]: occupancy grids, built-in maps, resampling, coverage.
//! - [`sensing`]: the simulated omni-directional scanner and exact grid visibility.
//! - [`planning`]: the parent planner of section IV-A (border, band, k-means
//!   candidates, Eq. 1 scores), the children's AND regions and Eq. 2 placements
//!   (IV-B), subgoals on the Visibility Graph (IV-C), Voronoi-edge paths (IV-D) and
//!   the CPS cycle that ties them together.
//! - [`mission`]: the scan → plan → move loop (every move as CPS cycles with the
//!   children), its records, and [`mission::plan_step`], one step for a real team.
//!
//! # Example
//!
//! ```
//! use cpsplan::world::builtin::BuiltinMap;
//! use cpsplan::{run_episode, Config, StopReason};
//!
//! let truth = BuiltinMap::Site.generate(0);
//! let start = BuiltinMap::Site.default_start();
//! let episode = run_episode(&truth, start, &Config::default(), |_| {})?;
//! assert_eq!(episode.summary.stop_reason, StopReason::Complete);
//! assert!(episode.summary.coverage > 0.99);
//! // Two children by default: every move ran as CPS cycles.
//! assert!(episode.summary.cps_cycles >= episode.summary.scans - 1);
//! # Ok::<(), cpsplan::MissionError>(())
//! ```

pub mod config;
pub mod geom;
pub mod mission;
pub mod planning;
pub mod sensing;
pub mod world;

pub use config::Config;
pub use geom::{Cell, Point};
pub use mission::{run_episode, run_episode_with, Episode, MissionError, StopReason};
pub use world::{CellState, GridGeometry, OccupancyGrid};
