//! The oracle (beyond the paper; docs/DESIGN-CHOICES.md "The oracle"): the
//! yardstick an explorer can be measured against. The same team, candidates and
//! reachability as the explorer, but clairvoyant about what each candidate sees:
//! its gain is the free area a scan there would truly reveal on the ground
//! truth, never a guess; never about where it can go (reachability and travel
//! are the explorer's, on the knowledge map).
//!
//! **The rule.** A candidate is eligible when it is reachable and its true gain
//! passes the explorer's stop rule (`parent.min_gain_m2` and
//! `parent.min_gain_share` of the known free area). Among them the oracle takes
//! the one of largest
//!
//! ```text
//! true gain (m²) / (L + d_scan)
//! ```
//!
//! `L` the parent's travel to it and `d_scan` the travel whose team driving takes
//! as long as one scan ([`crate::config::TimeConfig::scan_equivalent_m`]): the
//! true free area per unit of campaign time (scan plus driving, every robot in
//! turn), CPS measurements left out as the explorer's Eq. (1) leaves them out.

use super::candidate::{
    candidate_terms, fill_terms, new_candidate, set_gain, Candidate, CandidateOrigin,
};
use super::fallback::band_blocks;
use super::jitter::TravelJitter;
use crate::config::Config;
use crate::geom::Cell;
use crate::grid::{DistanceField, OccupancyGrid, Traversability};
use crate::sensing::{true_gain, GainEstimate};

/// How many band cells (one per square metre, nearest first) the oracle's own
/// fallback tests when no candidate is worth a scan by its true gain.
pub const ORACLE_FALLBACK_CELLS: usize = 2000;

/// The oracle's score of a candidate with true gain `gain_m2` (m²) at travel
/// `l_m` (m): `gain / (L + d_scan)`, m² per m.
pub fn oracle_rate(gain_m2: f64, l_m: f64, config: &Config) -> f64 {
    let d_scan = config.time.scan_equivalent_m(config.children.count);
    gain_m2 / (l_m + d_scan).max(f64::MIN_POSITIVE)
}

/// The true free area a scan at `at` would reveal, m².
pub fn true_gain_m2(
    truth: &OccupancyGrid,
    knowledge: &OccupancyGrid,
    at: Cell,
    config: &Config,
) -> f64 {
    let res = knowledge.geometry().resolution;
    true_gain(truth, knowledge, at, config.range_cells()) as f64 * res * res
}

/// Scores `candidates` (their `R` and `L` filled) by the oracle's rule against
/// `truth`; returns the index of the best eligible one. `threshold_m2`: the
/// least true gain worth a scan.
pub(super) fn choose(
    candidates: &mut [Candidate],
    truth: &OccupancyGrid,
    knowledge: &OccupancyGrid,
    config: &Config,
    threshold_m2: f64,
) -> Option<usize> {
    use rayon::prelude::*;
    let gains: Vec<f64> = candidates
        .par_iter()
        .map(|c| {
            if c.r == 1 {
                true_gain_m2(truth, knowledge, c.cell, config)
            } else {
                0.0
            }
        })
        .collect();
    let mut best: Option<(usize, f64)> = None;
    for (i, (c, &gain)) in candidates.iter_mut().zip(&gains).enumerate() {
        c.true_gain_m2 = Some(gain);
        c.eligible = c.r == 1 && gain > 0.0 && gain >= threshold_m2;
        let rate = oracle_rate(gain, c.l_m.unwrap_or(f64::INFINITY), config);
        c.oracle_rate = Some(rate);
        if c.eligible && best.is_none_or(|(_, b)| rate > b) {
            best = Some((i, rate));
        }
    }
    best.map(|b| b.0)
}

/// When no candidate is worth a scan by its true gain: the band's reachable
/// cells (one per square metre, nearest first, at most
/// [`ORACLE_FALLBACK_CELLS`]) whose true gain passes `threshold_m2`, the one of
/// largest rate as a new candidate (as the explorer's reachable-frontier search
/// does with its estimate), with the explorer's estimate `gain` of it beside.
#[allow(clippy::too_many_arguments)]
pub(super) fn fallback(
    knowledge: &OccupancyGrid,
    truth: &OccupancyGrid,
    band_cells: &[usize],
    trav: &Traversability,
    field: &DistanceField,
    config: &Config,
    gain: &GainEstimate,
    threshold_m2: f64,
) -> Option<Candidate> {
    use rayon::prelude::*;
    let g = *knowledge.geometry();
    let blocks = band_blocks(knowledge, band_cells, trav, field);
    let scored: Vec<(usize, f64)> = blocks
        .par_iter()
        .take(ORACLE_FALLBACK_CELLS)
        .filter_map(|&i| {
            let gain = true_gain_m2(truth, knowledge, g.cell(i), config);
            (gain > 0.0 && gain >= threshold_m2).then_some((i, gain))
        })
        .collect();
    let jitter = TravelJitter::from_config(config);
    let (i, true_m2) = scored
        .into_iter()
        .map(|(i, m2)| {
            let l = field.metres(i).unwrap_or(f64::INFINITY) * jitter.to(i);
            (i, m2, oracle_rate(m2, l, config))
        })
        .max_by(|a, b| a.2.total_cmp(&b.2).then(b.0.cmp(&a.0)))
        .map(|(i, m2, _)| (i, m2))?;
    let cell = g.cell(i);
    let mut c = new_candidate(cell, g.cell_center(cell), CandidateOrigin::Fallback, 0, &g);
    set_gain(&mut c, &gain.at(knowledge, cell, config.range_cells()));
    let t = candidate_terms(&c, &g, trav, field, config);
    fill_terms(&mut c, t);
    c.true_gain_m2 = Some(true_m2);
    c.oracle_rate = Some(oracle_rate(true_m2, c.l_m.unwrap_or(f64::INFINITY), config));
    c.eligible = c.r == 1;
    Some(c)
}
