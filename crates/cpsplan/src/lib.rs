//! # cpsplan
//!
//! Scan planning for a cooperative multi-robot laser-scanning system (CPS-SLAM,
//! Kurazume et al., IROS 2015). The modules follow the paper's pipeline (Fig. 3)
//! in the order data flows, each resting only on the ones listed before it:
//!
//! - [`geom`], [`config`]: points and cells; every parameter of a run.
//! - [`grid`]: the occupancy grid and the grid algorithms every stage stands on
//!   (distance transforms, travel-distance sweeps, searches, straight legs,
//!   connected regions, drivable terrain).
//! - [`world`] (stage 1): maps, built-in maps, resampling to the planning
//!   resolution, coverage, start ("transform 3D model to 2D grid map").
//! - [`sensing`] (stage 2): the omni-directional scanner, the expected gain `S`,
//!   certain visibility for CPS links.
//! - [`accuracy`] (stage 7 of the design notes): the CPS measurement chain, the
//!   instrument, first-order error propagation, batch adjustment, Monte Carlo;
//!   below the planners, which ask it what a placement costs.
//! - [`parent`] (stage 3, section IV-A): border, band, samples, k-means, Eq. (1),
//!   the parent's target ("calculate candidate positions of parent robot",
//!   "determine the optimum position of parent robot").
//! - [`children`] (stage 4, IV-B): AND region, Eq. (2), one CPS cycle ("calculate
//!   candidate positions of child robots", "determine the optimum positions").
//! - [`subgoals`] (stage 5, IV-C): the Visibility Graph and subgoal retrieval ("set
//!   subgoals for the parent robot using Visibility Graph").
//! - [`motion`] (stage 6, IV-D): the Generalized Voronoi Diagram and every robot's
//!   path ("plan the trajectories to the target positions").
//! - [`mission`] (stage 8): the scan → plan → move loop, its records, and
//!   [`mission::plan_step`], one step for a real team ("move to the target
//!   positions").
//! - [`model`] (stage 9, sections III and V-B): the registered 3D model, every scan's
//!   points in the parent's estimated pose, and its accuracy against the walls.
//! - [`bound`] (beyond the paper): the known-map yardstick, how few stations a
//!   team that knew the map would need (greedy set cover and an LP lower bound).
//!
//! Stage numbers are those of the design notes (DESIGN.md). The CPS measurement
//! chain (stage 7) sits below the planners in the import order because the
//! children's placement and the parent's score consult it.
//! No module imports from a stage listed after it.
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
//! // Stopped when no reachable position would add 0.05 % of the known free area.
//! assert_eq!(episode.summary.stop_reason, StopReason::NoReachableFrontier);
//! assert!(episode.summary.coverage > 0.99);
//! // Two children by default: every move ran as CPS cycles.
//! assert!(episode.summary.cps_cycles >= episode.summary.scans - 1);
//! # Ok::<(), cpsplan::MissionError>(())
//! ```

// The modules in the order data flows (each group kept in order by a comment).
pub mod geom;

pub mod config;

// Stage 0: the grid and its algorithms.
pub mod grid;

// Stage 1.
pub mod world;

// Stage 2.
pub mod sensing;

// Stage 7, consulted by the planners.
pub mod accuracy;

// Stage 3, section IV-A.
pub mod parent;

// Stage 4, IV-B.
pub mod children;

// Stage 5, IV-C.
pub mod subgoals;

// Stage 6, IV-D.
pub mod motion;

// Stage 8.
pub mod mission;

// Stage 9.
pub mod model;

// Beyond the pipeline: the known-map yardstick.
pub mod bound;

pub use config::Config;
pub use geom::{Cell, Point};
pub use grid::{CellState, GridGeometry, OccupancyGrid};
pub use mission::{plan_step, run_episode, run_episode_with, Episode, MissionError, StopReason};
