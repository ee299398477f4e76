//! The reachable-frontier search (beyond the paper): band cells the parent can
//! reach that expect new cells, nearest first, for when the round's centroids
//! give no eligible candidate, or when no candidate can be reached by CPS cycles.
//!
//! In: the knowledge map, the band (or the whole border), the parent's drivable
//! cells and travel distances. Out: candidate cells, one per square metre, nearest
//! by travel first, each expecting at least `min_gain_cells` new cells.

use std::collections::HashMap;

use super::band::band;
use super::border::{border_cells, significant_border};
use super::candidate::{
    candidate_terms, fill_terms, new_candidate, set_gain, Candidate, CandidateOrigin,
};
use crate::config::Config;
use crate::geom::Cell;
use crate::grid::{DistanceField, OccupancyGrid, Traversability};
use crate::sensing::GainEstimate;

/// Reachable, traversable cells of `band_cells`, one per square metre (the nearest
/// by travel), nearest first, that are worth a scan by `gain` (each tested when
/// the iterator reaches it).
pub fn frontier_cells<'a>(
    knowledge: &'a OccupancyGrid,
    band_cells: &[usize],
    trav: &Traversability,
    field: &DistanceField,
    config: &'a Config,
    gain: &'a GainEstimate,
) -> impl Iterator<Item = Cell> + 'a {
    let g = knowledge.geometry();
    band_blocks(knowledge, band_cells, trav, field)
        .into_iter()
        .filter(move |&i| gain.worth_at(knowledge, g.cell(i), config.range_cells()))
        .map(move |i| g.cell(i))
}

/// Reachable, traversable cells of `band_cells`, one per square metre (the
/// nearest by travel), nearest first, as cell indices.
pub fn band_blocks(
    knowledge: &OccupancyGrid,
    band_cells: &[usize],
    trav: &Traversability,
    field: &DistanceField,
) -> Vec<usize> {
    let g = knowledge.geometry();
    let block = (1.0 / g.resolution).round().max(1.0) as usize;
    let mut best: HashMap<(usize, usize), usize> = HashMap::new();
    for &i in band_cells {
        if !(trav.traversable[i] && field.reached(i)) {
            continue;
        }
        let c = g.cell(i);
        let key = (c.x / block, c.y / block);
        let e = best.entry(key).or_insert(i);
        if (field.cost[i], i) < (field.cost[*e], *e) {
            *e = i;
        }
    }
    let mut order: Vec<usize> = best.into_values().collect();
    order.sort_unstable_by_key(|&i| (field.cost[i], i));
    order
}

/// Up to `limit` cells of the reachable-frontier search over the band of the
/// knowledge map's significant border.
pub fn reachable_frontier(
    knowledge: &OccupancyGrid,
    trav: &Traversability,
    field: &DistanceField,
    config: &Config,
    gain: &GainEstimate,
    limit: usize,
) -> Vec<Cell> {
    let g = knowledge.geometry();
    let pc = &config.parent;
    let border = significant_border(g, &border_cells(knowledge), pc.min_frontier_cells);
    if border.is_empty() {
        return Vec::new();
    }
    let band_cells = band(knowledge, &border, pc.band_width);
    frontier_cells(knowledge, &band_cells, trav, field, config, gain)
        .take(limit)
        .collect()
}

/// How many cells of the reachable-frontier search a step tries at most when no
/// candidate and no relocated target can be reached by CPS cycles.
pub const CPS_FALLBACK_TRIES: usize = 16;

/// The candidate for a cell of the reachable-frontier search, with its own `R`,
/// `P`, `L` and `S` (Eq. 1 terms, from the parent's drivable cells `trav` and
/// travel distances `field` of the round); `G` is 0: it is taken only because no
/// scored candidate could be reached.
pub fn fallback_candidate(
    knowledge: &OccupancyGrid,
    cell: Cell,
    trav: &Traversability,
    field: &DistanceField,
    config: &Config,
    gain: &GainEstimate,
) -> Candidate {
    let g = *knowledge.geometry();
    let mut c = new_candidate(cell, g.cell_center(cell), CandidateOrigin::Fallback, 0, &g);
    let expected = gain.at(knowledge, cell, config.range_cells());
    set_gain(&mut c, &expected);
    let t = candidate_terms(&c, &g, trav, field, config);
    fill_terms(&mut c, t);
    c.eligible = c.r == 1 && gain.worth_a_scan(&expected);
    c
}
