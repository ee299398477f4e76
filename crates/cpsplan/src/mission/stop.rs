//! Why a mission ends ([`StopReason`]).

use serde::{Deserialize, Serialize};

/// Why a mission ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// No border between known-Free and Unknown space is left.
    Complete,
    /// Border is left, but only in fragments smaller than
    /// `parent.min_frontier_cells`.
    FrontierBelowThreshold,
    /// Border remains, but no reachable position would see anything new: none
    /// the parent can drive to, or, when the round's own candidates expected
    /// too little and only the search of the band's reachable cells found one
    /// (a `fallback` candidate), none of those the team reaches by CPS cycles.
    NoReachableFrontier,
    /// `mission.max_scans` was reached.
    ScanLimit,
    /// The last `mission.stop_window` scans together added less than
    /// `mission.stop_share` of the known free area (beyond the paper).
    DiminishingReturns,
    /// Targets remain, but none can be reached by CPS cycles (no usable AND region
    /// even with subgoals).
    NoCpsMove,
    /// The robots could only drive within a small region around the start (less
    /// than [`START_REGION_SHARE`] of the free space 4-connected to it, or less
    /// than [`START_REGION_SHARE_OF_MAP`] of all the map's free space), and the
    /// episode ended there: the start, the robot radius or the map is likely
    /// wrong.
    StartRegionTooSmall,
    /// The user stopped the run ([`super::run_episode_until`]); the scans made
    /// until then are whole.
    Interrupted,
}

/// The share of the free space 4-connected to the start below which a start
/// region counts as too small ([`StopReason::StartRegionTooSmall`]).
pub const START_REGION_SHARE: f64 = 0.1;

/// The share of all the map's free space below which a start region counts as
/// too small ([`StopReason::StartRegionTooSmall`]).
pub const START_REGION_SHARE_OF_MAP: f64 = 0.01;

impl StopReason {
    /// Every stop reason.
    pub const ALL: [StopReason; 8] = [
        StopReason::Complete,
        StopReason::FrontierBelowThreshold,
        StopReason::NoReachableFrontier,
        StopReason::ScanLimit,
        StopReason::DiminishingReturns,
        StopReason::NoCpsMove,
        StopReason::StartRegionTooSmall,
        StopReason::Interrupted,
    ];

    /// The snake_case name, as in the JSON records.
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Complete => "complete",
            StopReason::FrontierBelowThreshold => "frontier_below_threshold",
            StopReason::NoReachableFrontier => "no_reachable_frontier",
            StopReason::ScanLimit => "scan_limit",
            StopReason::DiminishingReturns => "diminishing_returns",
            StopReason::NoCpsMove => "no_cps_move",
            StopReason::StartRegionTooSmall => "start_region_too_small",
            StopReason::Interrupted => "interrupted",
        }
    }

    /// A few words for people.
    pub fn describe(self) -> &'static str {
        match self {
            StopReason::Complete => "complete",
            StopReason::FrontierBelowThreshold => "frontier below threshold",
            StopReason::NoReachableFrontier => "no reachable frontier",
            StopReason::ScanLimit => "scan limit",
            StopReason::DiminishingReturns => "diminishing returns",
            StopReason::NoCpsMove => "no CPS move",
            StopReason::StartRegionTooSmall => "start region too small",
            StopReason::Interrupted => "interrupted",
        }
    }
}
