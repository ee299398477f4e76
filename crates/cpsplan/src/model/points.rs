//! The points and stations of the registered model.

use serde::{Deserialize, Serialize};

/// One point of the registered model, world frame, metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelPoint {
    /// Position `[x, y, z]`: the simulated measurement expressed in the
    /// estimated pose of its scan.
    pub position: [f64; 3],
    /// Index of its scan, from 0.
    pub scan: u32,
}

/// One scan station of the registered model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelStation {
    /// Index of the scan, from 0.
    pub scan: u32,
    /// Where the scanner's centre truly was, `[x, y, z]`.
    pub truth: [f64; 3],
    /// Where the CPS estimated it (the pose the scan's points are expressed in).
    pub estimate: [f64; 3],
    /// Heading error of the estimate, radians.
    pub heading_error_rad: f64,
    /// Predicted radial 1σ of the horizontal position, metres (`None` without
    /// at least two children).
    pub position_sigma_m: Option<f64>,
}
