//! The targets of a mission (beyond the paper; docs/ACCURACY.md "Closed
//! networks"): their records, and where the team leaves targets of its own
//! (`targets.place = "auto"`).

use serde::{Deserialize, Serialize};

use super::record::LeftTarget;
use crate::geom::Point;

/// Where a target came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TargetOrigin {
    /// A control point given with its coordinates.
    Control,
    /// A free target set up before the campaign.
    Free,
    /// A target a child left during the campaign.
    Placed,
}

/// One target or control point of an episode, as `episode.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetRecord {
    /// Its name (`T1`, … for given points without one; `P1`, … for placed ones).
    pub name: String,
    /// Where it came from.
    pub origin: TargetOrigin,
    /// Where it stands, world frame.
    pub position: Point,
    /// A control point's standard deviation of each coordinate, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_mm: Option<f64>,
    /// A placed target: the scan after which it was left.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placed_at_scan: Option<usize>,
    /// A placed target: the child that left it (from 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placed_by_child: Option<usize>,
    /// A placed target: why the planner left it there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The scan whose station (or whose move's stations) first measured it.
    pub first_measured_scan: Option<usize>,
    /// How many stations measured it.
    pub measurements: usize,
    /// Its smoothed radial 1σ at the end (every measurement at once), metres.
    pub smoothed_sigma_m: Option<f64>,
}

impl TargetRecord {
    /// The record of the `ordinal`-th target left by the team (from 1, named
    /// `P{ordinal}`), left during the move after scan `scan`.
    pub fn placed(left: &LeftTarget, ordinal: usize, scan: usize) -> Self {
        Self {
            name: format!("P{ordinal}"),
            origin: TargetOrigin::Placed,
            position: left.position,
            sigma_mm: None,
            placed_at_scan: Some(scan),
            placed_by_child: Some(left.child),
            reason: Some(left.reason.clone()),
            first_measured_scan: None,
            measurements: 0,
            smoothed_sigma_m: None,
        }
    }
}
