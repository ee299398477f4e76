//! The CPS measurement chain and its error (pipeline stage 7; paper sections III
//! and V-A-2, Table I, Fig. 10): the instrument's observation model, first-order
//! propagation of the positioning error through every CPS cycle, the batch
//! adjustment it is checked against, and a Monte Carlo simulation with real noise.
//!
//! In: an instrument and the geometry of a chain of cycles (the parent's stations,
//! the children's points). Out: the covariance of every parent pose, hence of every
//! scan position. It rests on [`crate::geom`] and [`crate::config`] only, so the
//! planners above (the children's `min-error` strategy, the parent's error term)
//! can ask it what a placement would cost.
//!
//! - [`Instrument`]: presets and figures.
//! - [`Model`]: one link's observation, Jacobians, noise.
//! - [`Chain`]: the sequential propagation over the joint state.
//! - [`batch_station_covariance`]: the whole network at once.
//! - [`monte_carlo()`]: noise drawn through the chain, estimated by nonlinear least
//!   squares.
//! - [`Objective`]: what a placement of the children costs at the next pose.
//! - [`Reading`]: one reading as a total station records it.

mod batch;
mod chain;
mod geometry;
mod instrument;
mod model;
mod monte_carlo;
mod network;
mod placement;
mod reading;
mod script;
mod survey;

pub use batch::{batch_covariances, batch_station_covariance};
pub use chain::{Chain, ChainError, PoseCovariance};
pub use geometry::{CycleGeometry, NetworkGeometry, TargetPoint};
pub use instrument::{Instrument, ARCSEC};
pub use model::Model;
pub use monte_carlo::{monte_carlo, realisation, MonteCarlo, Realisation};
pub use network::{
    Fit, Measurement, Network, NetworkError, StationFit, Unknown, MIN_TESTED_REDUNDANCY,
};
pub use placement::Objective;
pub use reading::{Reading, MAX_NAME};
pub use script::{Event, Role, Script, ScriptVar};
pub use survey::{
    adjust_readings, child_spot, reading_name, Adjusted, Blunder, ControlPoint, Datum, Survey,
    SurveyError, BLUNDER_SIGMAS,
};
