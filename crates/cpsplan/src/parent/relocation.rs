//! Relocated targets (beyond the paper): when no candidate of a round can be
//! reached by CPS cycles, cells near the best candidates that still expect new
//! cells are tried instead (docs/DESIGN-CHOICES.md).
//!
//! In: the knowledge map, the parent's terrain, a candidate. Out: the cells to try
//! ([`relocations`]) and the candidate that stands in for the original
//! ([`relocated_candidate`]).

use super::candidate::{
    candidate_terms, fill_terms, new_candidate, set_gain, Candidate, CandidateOrigin,
};
use crate::config::Config;
use crate::geom::Cell;
use crate::grid::{DistanceField, OccupancyGrid, Terrain, Traversability};
use crate::sensing::GainEstimate;

/// How far from a candidate no CPS move can reach a relocated target may lie,
/// metres.
pub const RELOCATE_RADIUS_M: f64 = 3.0;
/// Spacing of the cells tried around such a candidate, metres.
pub const RELOCATE_SPACING_M: f64 = 0.3;
/// Relocated targets tried at most per candidate, best expected gain first.
pub const RELOCATE_TRIES: usize = 12;
/// Candidates relocated at most per step, best `G` first.
pub const RELOCATE_CANDIDATES: usize = 3;

/// The raw Eq. (1) terms of a candidate whose `s_cells` is already known.
/// The candidate at `cell` that stands in for `original` when no CPS move can
/// reach `original`: its own `R`, `P`, `L` and `S` (Eq. 1 terms, from the parent's
/// drivable cells `trav` and travel distances `field` of the same planning
/// round), `original`'s `G` and cluster.
pub fn relocated_candidate(
    knowledge: &OccupancyGrid,
    cell: Cell,
    original: &Candidate,
    trav: &Traversability,
    field: &DistanceField,
    config: &Config,
    gain: &GainEstimate,
) -> Candidate {
    let g = *knowledge.geometry();
    let mut c = new_candidate(
        cell,
        original.centroid,
        CandidateOrigin::Relocated,
        original.cluster_size,
        &g,
    );
    let expected = gain.at(knowledge, cell, config.range_cells());
    set_gain(&mut c, &expected);
    let t = candidate_terms(&c, &g, trav, field, config);
    fill_terms(&mut c, t);
    c.g = original.g;
    c.tour_rank = original.tour_rank;
    c.eligible = c.r == 1 && gain.worth_a_scan(&expected);
    c
}

/// Cells to try instead of `candidate`: drivable for the parent and reachable
/// from where it stands (on the parent's `terrain`), on a lattice of [`RELOCATE_SPACING_M`] within
/// [`RELOCATE_RADIUS_M`], worth a scan by `gain`; the [`RELOCATE_TRIES`] with
/// the largest expected gain (ties: nearest first).
pub fn relocations(
    knowledge: &OccupancyGrid,
    terrain: &Terrain,
    candidate: Cell,
    config: &Config,
    gain: &GainEstimate,
) -> Vec<Cell> {
    let g = knowledge.geometry();
    let step = (RELOCATE_SPACING_M / g.resolution).round().max(1.0) as i64;
    let reach = (RELOCATE_RADIUS_M / g.resolution).floor() as i64;
    let mut found: Vec<(usize, i64, Cell)> = Vec::new();
    for dy in (-reach..=reach).step_by(step as usize) {
        for dx in (-reach..=reach).step_by(step as usize) {
            let d2 = dx * dx + dy * dy;
            if d2 == 0 || d2 > reach * reach {
                continue;
            }
            let (x, y) = (candidate.x as i64 + dx, candidate.y as i64 + dy);
            if x < 0 || y < 0 || x >= g.width as i64 || y >= g.height as i64 {
                continue;
            }
            let cell = Cell::new(x as usize, y as usize);
            let i = g.index(cell);
            if !terrain.trav.traversable[i] || terrain.region_of(i).is_none() {
                continue;
            }
            let expected = gain.at(knowledge, cell, config.range_cells());
            if gain.worth_a_scan(&expected) {
                found.push((expected.s_cells, d2, cell));
            }
        }
    }
    found.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    found
        .into_iter()
        .take(RELOCATE_TRIES)
        .map(|(_, _, c)| c)
        .collect()
}
