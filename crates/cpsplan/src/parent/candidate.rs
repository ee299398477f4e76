//! The parent's candidate target points (section IV-A-2) and their Eq. (1) terms.
//!
//! In: a candidate cell, the parent's drivable cells and travel distances of the
//! round. Out: a [`Candidate`] with `R`, `P`, `L` and `S` (the score `G` is set by
//! [`super::score`] over all candidates of a round).

use serde::{Deserialize, Serialize};

use super::jitter::TravelJitter;
use super::score::Terms;
use crate::config::Config;
use crate::geom::{Cell, Point};
use crate::grid::{DistanceField, GridGeometry, Traversability};
use crate::sensing::Gain;

/// How a candidate was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CandidateOrigin {
    /// The k-means centroid itself.
    Centroid,
    /// The centroid was not a valid position; the cluster's nearest valid sample.
    Snapped,
    /// Found by the reachable-frontier search after every centroid failed.
    Fallback,
    /// A cell near a candidate that no CPS move could reach, taken instead of it
    /// (see `mission`); it keeps that candidate's `G`.
    Relocated,
    /// The nearest-frontier baseline's goal: the drivable cell nearest to an
    /// explore_lite frontier's centroid (`--planner frontier`).
    Frontier,
    /// A viewpoint of a border group, chosen for what it sees of the group
    /// (`parent.viewpoints`; its `cluster_size` is the border cells it sees).
    Viewpoint,
}

/// One candidate target of the parent with the terms of Eq. (1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// Candidate position (cell centre), world frame.
    pub position: Point,
    /// Candidate cell.
    pub cell: Cell,
    /// The k-means centroid it came from, world frame.
    pub centroid: Point,
    /// How it was obtained.
    pub origin: CandidateOrigin,
    /// Samples in its cluster.
    pub cluster_size: usize,
    /// `R` of Eq. (1): 1 for a known-Free, reachable cell with the robot's clearance.
    pub r: u8,
    /// `P` of Eq. (1): the potential, inverse of the clearance (1/m).
    pub p: f64,
    /// The clearance `1/P` in metres (capped at the scanner range).
    pub clearance_m: f64,
    /// `L` of Eq. (1): travel distance in metres, `None` if unreachable.
    pub l_m: Option<f64>,
    /// `S` of Eq. (1): expected newly scanned cells (0 when `R = 0`).
    pub s_cells: usize,
    /// The calibrated estimate of the free area a scan here adds, m² (beyond the
    /// paper, `sensing::GainEstimate`; 0 when `R = 0`).
    #[serde(default)]
    pub gain_m2: f64,
    /// With `--planner tour`: the candidate's place on the round's tour (0: the
    /// next scan); `None` off the tour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tour_rank: Option<usize>,
    /// With `--planner tour`: the position was moved from the cluster's to where
    /// the gain estimate is higher (`parent.refine_step`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub refined: bool,
    /// `G` of Eq. (1).
    pub g: f64,
    /// `R = 1` and worth a scan (`S ≥ min_gain_cells`, the estimated area at
    /// least `min_gain_m2` and `min_gain_share` of the known free area): may be
    /// chosen.
    pub eligible: bool,
    /// With the error term (`parent.gamma > 0`): how much the predicted radial σ
    /// of the parent's position grows on the CPS move to this candidate, metres
    /// (only for the candidates whose moves were planned).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_growth_m: Option<f64>,
    /// `oracle`: the free area a scan here would truly reveal, m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_gain_m2: Option<f64>,
    /// `oracle`: its score, true gain per metre of travel plus a scan's worth of
    /// driving ([`super::oracle_rate`]), m² per m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub oracle_rate: Option<f64>,
}

/// A candidate with no terms yet (`R = 0`, not eligible).
pub(super) fn new_candidate(
    cell: Cell,
    centroid: Point,
    origin: CandidateOrigin,
    cluster_size: usize,
    g: &GridGeometry,
) -> Candidate {
    Candidate {
        position: g.cell_center(cell),
        cell,
        centroid,
        origin,
        cluster_size,
        r: 0,
        p: 0.0,
        clearance_m: 0.0,
        l_m: None,
        s_cells: 0,
        gain_m2: 0.0,
        tour_rank: None,
        refined: false,
        g: 0.0,
        eligible: false,
        error_growth_m: None,
        true_gain_m2: None,
        oracle_rate: None,
    }
}

/// Sets `S` and the area estimate from a gain.
pub(super) fn set_gain(c: &mut Candidate, gain: &Gain) {
    c.s_cells = gain.s_cells;
    c.gain_m2 = gain.m2;
}

/// The raw Eq. (1) terms of a candidate whose `s_cells` is already known.
pub(super) fn candidate_terms(
    c: &Candidate,
    g: &GridGeometry,
    trav: &Traversability,
    field: &DistanceField,
    config: &Config,
) -> Terms {
    let i = g.index(c.cell);
    let reachable = trav.traversable[i] && field.reached(i);
    Terms {
        reachable,
        // Guard: with no known obstacle the clearance is capped at the range.
        clearance: (trav.clearance_at(i) as f64).min(config.scanner.range),
        travel: field.metres(i).unwrap_or(f64::INFINITY) * TravelJitter::from_config(config).to(i),
        gain: c.s_cells,
    }
}

/// Sets `R`, `P`, the clearance and `L` from the raw terms.
pub(super) fn fill_terms(c: &mut Candidate, t: Terms) {
    c.r = u8::from(t.reachable);
    c.clearance_m = t.clearance;
    c.p = if t.clearance > 0.0 {
        1.0 / t.clearance
    } else {
        f64::INFINITY
    };
    c.l_m = t.reachable.then_some(t.travel);
}
