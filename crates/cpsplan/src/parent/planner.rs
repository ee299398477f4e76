//! One planning round of the parent (section IV-A): border, band, samples,
//! k-means, candidates scored by Eq. (1); the best reachable one is the next scan
//! position.
//!
//! In: the knowledge map, the parent's cell, the configuration and the seeded RNG.
//! Out: a [`ParentPlan`] (every candidate with its terms, the decision, the drivable
//! path) and the parent's [`ParentReach`] for the CPS planners of the same step.
//!
//! Stopping must mean that no reachable frontier is left, not that this round's
//! centroids were poor: when no candidate expects at least `min_gain_cells` new
//! cells, the planner searches the reachable part of the band itself (one cell per
//! square metre, nearest first) for a position that does, and only stops when there
//! is none.

use std::borrow::Cow;
use std::collections::HashSet;
use std::sync::Arc;

use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::candidate::{
    candidate_terms, fill_terms, new_candidate, set_gain, Candidate, CandidateOrigin,
};
use super::fallback::frontier_cells;
use super::frontier::Frontier;
use super::kmeans::kmeans;
use super::nearest_frontier::{frontier_goals, nearest_valid_cell};
use super::oracle;
use super::samples::{band_area, cluster_count, scatter};
use super::score::{evaluate, Terms};
use super::tour::TourRound;
use crate::config::{Config, Planner};
use crate::geom::{polyline_length, Cell, Point};
use crate::grid::path::{shortcut_path, to_world};
use crate::grid::travel::sweep;
use crate::grid::{DistanceField, Drivable, OccupancyGrid, Traversability, UNREACHED};
use crate::sensing::{Gain, GainEstimate, NearField};

/// What the planner decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Decision {
    /// Scan next at candidate `index`.
    Target {
        /// Index into [`ParentPlan::candidates`].
        index: usize,
    },
    /// No border is left: the map is fully known.
    Complete,
    /// Border is left, but only in fragments smaller than
    /// `parent.min_frontier_cells` (section IV-A, step 1): nothing is worth a scan.
    FrontierBelowThreshold,
    /// Border remains, but no reachable position would see anything new.
    NoReachableFrontier,
}

/// One planning round of the parent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParentPlan {
    /// Border cells found (step 1).
    pub border_cells: usize,
    /// Band cells (step 2).
    pub band_cells: usize,
    /// Samples scattered in the band (step 2), world frame.
    #[serde(skip)]
    pub samples: Vec<Point>,
    /// Number of samples.
    pub sample_count: usize,
    /// k of k-means (step 3).
    pub clusters: usize,
    /// Candidates with their Eq. (1) terms (step 4).
    pub candidates: Vec<Candidate>,
    /// The decision.
    pub decision: Decision,
    /// Drivable path from the parent to the target, world frame (empty if none).
    pub path: Vec<Point>,
    /// Length of `path` in metres.
    pub path_length_m: f64,
}

impl ParentPlan {
    /// The chosen candidate, if any.
    pub fn target(&self) -> Option<&Candidate> {
        match self.decision {
            Decision::Target { index } => self.candidates.get(index),
            _ => None,
        }
    }

    /// The eligible candidates in `planner`'s order of preference, the target
    /// first: by decreasing `G` (`paper`), the tour's stops in order and then by
    /// `G` (`tour`), in the frontiers' cost order (`frontier`: the candidates'
    /// own order), by decreasing `S` (`gain`), by decreasing true gain per unit
    /// of campaign time (`oracle`); ties to the lower index. A CPS move
    /// that cannot reach the first is tried with the next (`mission`).
    pub fn preference(&self, planner: Planner) -> Vec<usize> {
        let c = &self.candidates;
        let mut order: Vec<usize> = (0..c.len()).filter(|&i| c[i].eligible).collect();
        match planner {
            Planner::Paper | Planner::Tour => order.sort_by(|&a, &b| {
                let rank = |k: usize| c[k].tour_rank.unwrap_or(usize::MAX);
                rank(a)
                    .cmp(&rank(b))
                    .then(c[b].g.total_cmp(&c[a].g))
                    .then(a.cmp(&b))
            }),
            Planner::Frontier => {}
            Planner::Gain => order.sort_by_key(|&k| (std::cmp::Reverse(c[k].s_cells), k)),
            Planner::Oracle => order.sort_by(|&a, &b| {
                let rate = |k: usize| c[k].oracle_rate.unwrap_or(c[k].g);
                rate(b).total_cmp(&rate(a)).then(a.cmp(&b))
            }),
        }
        order
    }
}

/// Plans the parent's next scan position on `knowledge` from `parent`.
pub fn plan_parent(
    knowledge: &OccupancyGrid,
    parent: Cell,
    config: &Config,
    rng: &mut ChaCha8Rng,
) -> ParentPlan {
    plan_parent_with_reach(knowledge, parent, config, rng).0
}

/// The parent's drivable cells and travel distances that a planning round
/// computed, for the CPS planners of the same step to reuse.
#[derive(Debug, Clone)]
pub struct ParentReach {
    /// The parent's drivable cells.
    pub trav: Traversability,
    /// Travel distances from the parent.
    pub field: DistanceField,
    /// The round's gain estimate and stop rule.
    pub gain: GainEstimate,
}

/// [`plan_parent`], also returning the parent's [`ParentReach`].
pub fn plan_parent_with_reach(
    knowledge: &OccupancyGrid,
    parent: Cell,
    config: &Config,
    rng: &mut ChaCha8Rng,
) -> (ParentPlan, ParentReach) {
    plan_parent_with_field(knowledge, parent, config, rng, None)
}

/// What an episode keeps up to date scan by scan for its planning rounds, so that
/// a round does not compute it again over the whole map.
#[derive(Debug, Clone, Copy)]
pub struct Kept<'a> {
    /// The gain estimate's field of the knowledge map.
    pub near: &'a NearField,
    /// The border and the band of the knowledge map (steps 1 and 2).
    pub frontier: &'a Frontier,
    /// The drivable cells of the knowledge map for robots of the parent's radius.
    pub drivable: &'a Drivable,
    /// The ground truth (a simulated episode's), for the `oracle` yardstick;
    /// without it the oracle plans as `paper` does.
    pub truth: Option<&'a OccupancyGrid>,
}

/// [`plan_parent_with_reach`] with the state an episode keeps up to date for
/// `knowledge` ([`Kept`]; `None`: computed here). With a travel horizon
/// (`parent.horizon`), the round first weighs only the candidates within it.
pub fn plan_parent_with_field(
    knowledge: &OccupancyGrid,
    parent: Cell,
    config: &Config,
    rng: &mut ChaCha8Rng,
    kept: Option<Kept<'_>>,
) -> (ParentPlan, ParentReach) {
    let horizon_m = config.parent.horizon;
    if horizon_m > 0.0 {
        // The same samples either way: the wider round starts from the same
        // random state.
        let saved = rng.clone();
        let h = DistanceField::cost_of(horizon_m, knowledge.geometry().resolution);
        if let Some(round) = plan_within(knowledge, parent, config, rng, kept, Some(h)) {
            return round;
        }
        *rng = saved;
    }
    match plan_within(knowledge, parent, config, rng, kept, None) {
        Some(round) => round,
        None => unreachable!("a round without a horizon always ends in a decision"),
    }
}

/// One planning round; with a `horizon` (travel cost units), only the
/// candidates within it are weighed, the sweep stops at twice it, and `None`
/// means none of them is worth a scan (the caller plans without it).
fn plan_within(
    knowledge: &OccupancyGrid,
    parent: Cell,
    config: &Config,
    rng: &mut ChaCha8Rng,
    kept: Option<Kept<'_>>,
    horizon: Option<u32>,
) -> Option<(ParentPlan, ParentReach)> {
    let g = *knowledge.geometry();
    let pc = &config.parent;
    let range_cells = config.range_cells();
    // Steps 1–3 (border, band, samples, k-means: the only users of `rng`) do not
    // depend on the drivable cells and travel distances from the parent: both run
    // at once.
    let ((trav, field, gain), (frontier, stages)) = rayon::join(
        || {
            let (trav, gain) = rayon::join(
                || {
                    let drivable = kept.map(|k| k.drivable);
                    Traversability::kept_or_new(drivable, knowledge, config.robot.radius, parent)
                },
                || match kept {
                    Some(k) => GainEstimate::from_field(k.near, knowledge, config),
                    None => GainEstimate::new(knowledge, config),
                },
            );
            let limit = horizon.map_or(UNREACHED, |h| h.saturating_mul(2));
            let field = sweep(&g, &trav.passable, &[g.index(parent)], limit);
            (trav, field, gain)
        },
        || {
            let frontier = match kept {
                Some(k) => Cow::Borrowed(k.frontier),
                None => Cow::Owned(Frontier::new(knowledge, pc)),
            };
            let stages = (!frontier.significant().is_empty()).then(|| {
                // Steps 2 and 3: samples scattered in the band, k adapted to its size.
                let band_cells = frontier.band();
                let samples = scatter(&g, band_cells, pc, rng);
                let k = cluster_count(band_area(&g, band_cells.len()), pc);
                let clustering = kmeans(&samples, k, pc.kmeans_iterations, rng);
                (samples, clustering)
            });
            (frontier, stages)
        },
    );
    let mut plan = ParentPlan {
        border_cells: frontier.significant().len(),
        band_cells: 0,
        samples: Vec::new(),
        sample_count: 0,
        clusters: 0,
        candidates: Vec::new(),
        decision: Decision::Complete,
        path: Vec::new(),
        path_length_m: 0.0,
    };
    let Some((samples, clustering)) = stages else {
        if !frontier.border().is_empty() {
            plan.decision = Decision::FrontierBelowThreshold;
        }
        return Some((plan, ParentReach { trav, field, gain }));
    };
    let band_cells = frontier.band();
    plan.band_cells = band_cells.len();
    plan.clusters = clustering.centroids.len();
    plan.sample_count = samples.len();
    let to_point = |p: [f64; 2]| g.grid_to_world(p[0] * g.resolution, p[1] * g.resolution);
    plan.samples = samples.iter().map(|&p| to_point(p)).collect();

    // Step 4: centroids as candidates, snapped to a valid member sample if needed.
    let valid = |i: usize| {
        trav.traversable[i] && field.reached(i) && horizon.is_none_or(|h| field.cost[i] <= h)
    };
    let cell_of = |p: [f64; 2]| Cell::new(p[0] as usize, p[1] as usize);
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); clustering.centroids.len()];
    for (s, &a) in clustering.assignment.iter().enumerate() {
        members[a].push(s);
    }
    let mut seen_cells = HashSet::new();
    for (ci, &centroid) in clustering.centroids.iter().enumerate() {
        let mut cell = cell_of(centroid);
        let mut origin = CandidateOrigin::Centroid;
        if !valid(g.index(cell)) {
            let snapped = members[ci]
                .iter()
                .map(|&s| samples[s])
                .filter(|&p| valid(g.index(cell_of(p))))
                .min_by(|a, b| {
                    let da = (a[0] - centroid[0]).powi(2) + (a[1] - centroid[1]).powi(2);
                    let db = (b[0] - centroid[0]).powi(2) + (b[1] - centroid[1]).powi(2);
                    da.total_cmp(&db)
                });
            if let Some(p) = snapped {
                cell = cell_of(p);
                origin = CandidateOrigin::Snapped;
            }
        }
        if !seen_cells.insert(cell) {
            continue;
        }
        plan.candidates.push(new_candidate(
            cell,
            to_point(centroid),
            origin,
            members[ci].len(),
            &g,
        ));
    }
    if pc.viewpoints && pc.planner != Planner::Frontier {
        // Viewpoints that see into the border's groups, beside the centroids.
        let cost = |i: usize| field.metres(i).unwrap_or(f64::INFINITY);
        for v in frontier.viewpoints(knowledge, range_cells, valid, cost) {
            if seen_cells.insert(v.cell) {
                let c = g.cell_center(v.cell);
                plan.candidates.push(new_candidate(
                    v.cell,
                    c,
                    CandidateOrigin::Viewpoint,
                    v.sees,
                    &g,
                ));
            }
        }
    }
    if pc.planner == Planner::Frontier {
        // The baseline's own candidates: explore_lite's frontiers, cheapest first,
        // each at the drivable cell nearest to its centroid.
        plan.candidates.clear();
        seen_cells.clear();
        for f in frontier_goals(knowledge, parent, pc) {
            let Some(cell) = nearest_valid_cell(&g, f.centroid, valid) else {
                break;
            };
            if seen_cells.insert(cell) {
                let position = to_point(f.centroid);
                let origin = CandidateOrigin::Frontier;
                plan.candidates
                    .push(new_candidate(cell, position, origin, f.cells, &g));
            }
        }
    }
    // Terms of Eq. (1), S and the gain estimate in parallel (with the tour, also
    // the frontier cells each candidate would see).
    let tour = pc.planner == Planner::Tour && u32::try_from(g.len()).is_ok();
    let terms = |c: &Candidate| candidate_terms(c, &g, &trav, &field, config);
    let none = Gain {
        s_cells: 0,
        near_cells: 0,
        m2: 0.0,
    };
    let view = |cell: Cell| -> (Gain, Arc<[u32]>) {
        if !valid(g.index(cell)) {
            return (none, Arc::default());
        }
        if tour {
            gain.view(knowledge, cell, range_cells)
        } else {
            (gain.at(knowledge, cell, range_cells), Arc::default())
        }
    };
    let (gains, mut views): (Vec<Gain>, Vec<Arc<[u32]>>) =
        plan.candidates.par_iter().map(|c| view(c.cell)).unzip();
    let mut worth: Vec<bool> = Vec::with_capacity(plan.candidates.len());
    for (c, s) in plan.candidates.iter_mut().zip(&gains) {
        set_gain(c, s);
        let t = terms(c);
        fill_terms(c, t);
        worth.push(c.r == 1 && gain.worth_a_scan(s));
    }
    if !worth.iter().any(|&w| w) {
        if horizon.is_some() {
            return None;
        }
        if let Some(cell) =
            frontier_cells(knowledge, band_cells, &trav, &field, config, &gain).next()
        {
            let mut c = new_candidate(cell, g.cell_center(cell), CandidateOrigin::Fallback, 0, &g);
            let (s, cells) = view(cell);
            set_gain(&mut c, &s);
            let t = terms(&c);
            fill_terms(&mut c, t);
            worth.push(c.r == 1 && gain.worth_a_scan(&s));
            views.push(cells);
            plan.candidates.push(c);
        }
    }
    // Eq. (1).
    let all_terms: Vec<Terms> = plan.candidates.iter().map(terms).collect();
    let scores = evaluate(&all_terms, pc.alpha, pc.beta, pc.scoring, g.resolution);
    let mut best: Option<(usize, f64)> = None;
    for (i, ((c, gv), &w)) in plan
        .candidates
        .iter_mut()
        .zip(scores)
        .zip(&worth)
        .enumerate()
    {
        c.g = gv;
        c.eligible = w;
        if c.eligible && best.is_none_or(|(_, b)| gv > b) {
            best = Some((i, gv));
        }
    }
    // The oracle scores by the true gain.
    if let (Planner::Oracle, Some(truth)) = (pc.planner, kept.and_then(|k| k.truth)) {
        let threshold = gain.threshold_m2();
        best = oracle::choose(&mut plan.candidates, truth, knowledge, config, threshold)
            .or_else(|| {
                let c = oracle::fallback(
                    knowledge, truth, band_cells, &trav, &field, config, &gain, threshold,
                )?;
                plan.candidates.push(c);
                Some(plan.candidates.len() - 1)
            })
            .map(|i| (i, plan.candidates[i].g));
    }
    // The baselines take the first of their own order of preference.
    if matches!(pc.planner, Planner::Frontier | Planner::Gain) {
        best = plan
            .preference(pc.planner)
            .first()
            .map(|&i| (i, plan.candidates[i].g));
    }
    if tour {
        let round = TourRound {
            knowledge,
            trav: &trav,
            field: &field,
            gain: &gain,
            config,
        };
        if let Some(first) = round.target(&mut plan.candidates, views) {
            best = Some((first, plan.candidates[first].g));
        }
    }
    match best {
        None => plan.decision = Decision::NoReachableFrontier,
        Some((index, _)) => {
            plan.decision = Decision::Target { index };
            let target = plan.candidates[index].cell;
            if let Some(cells) = shortcut_path(&g, &field, &trav.passable, target) {
                plan.path = to_world(&g, &cells);
                plan.path_length_m = polyline_length(&plan.path);
            }
        }
    }
    Some((plan, ParentReach { trav, field, gain }))
}
