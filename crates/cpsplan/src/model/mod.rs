//! The registered 3D model (pipeline stage 9, the paper's output): every scan's
//! points expressed in the parent's *estimated* pose at that scan, the CPS
//! positions alone aligning the scans with no ICP ("simple algebra", section
//! III; the models of V-B and V-C), and the model's accuracy against the
//! ground-truth walls.
//!
//! In: the ground truth, an [`crate::Episode`] and its configuration. Out: the
//! points of each scan, the scan stations, and the distances of the points to the
//! ground-truth walls ([`build_model`]).
//!
//! - `scan`: one scan's points ([`scan_points`]).
//! - `walls`: distances to the ground-truth walls ([`GroundTruthWalls`]).
//! - `accuracy`: the figures per scan and overall.
//! - `build`: the whole episode.

mod accuracy;
mod build;
mod points;
mod scan;
mod walls;

pub use accuracy::{mean_and_p95, ModelAccuracy, ScanAccuracy};
pub use build::{
    build_model, build_model_in, model_point_count, scanner_frame_scans, ModelError,
    RegisteredModel, Registration,
};
pub use points::{ModelPoint, ModelStation};
pub use scan::{scan_points, wall_hit, Sampling, ScanPose};
pub use walls::GroundTruthWalls;
