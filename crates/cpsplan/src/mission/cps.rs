//! The CPS part of a mission step: the children's starting places, and the parent's
//! move to its target as CPS cycles (paper Fig. 1), with subgoals when needed
//! (section IV-C) and the next candidate when even that fails.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::config::Config;
use crate::geom::{polyline_length, Cell, Point};
use crate::planning::and_region::LinkRange;
use crate::planning::and_region::{and_region, mutual_view, ChildReach};
use crate::planning::children::Eq2;
use crate::planning::cps_cycle::{CpsCycle, CycleParams};
use crate::planning::cps_maps::{CpsMaps, Groundwork};
use crate::planning::path::to_world;
use crate::planning::reach::{sweep, UNREACHED};
use crate::planning::subgoals::{plan_move_in, MoveError, MovePlan};
use crate::planning::terrain::Terrain;
use crate::planning::{
    plan_parent_with_reach, relocated_candidate, ParentPlan, ParentReach, Traversability,
};
use crate::sensing::expected_gain;
use crate::world::OccupancyGrid;
use rand_chacha::ChaCha8Rng;

/// One child during one CPS cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChildMove {
    /// Where it stood before the cycle, world frame.
    pub from: Point,
    /// Where it stands while the parent moves.
    pub to: Point,
    /// It was already in its AND region and stayed.
    pub stays: bool,
    /// Its driven path, world frame.
    pub path: Vec<Point>,
    /// Size of its AND region, cells.
    pub and_region_cells: usize,
    /// Eq. (2): clearance `1/P` of its spot, metres (when it moved).
    pub clearance_m: Option<f64>,
    /// Eq. (2): distance `D` to the parent's target, metres (when it moved).
    pub distance_m: Option<f64>,
    /// Eq. (2): angle `θ` to its partner seen from the target, degrees.
    pub theta_deg: Option<f64>,
}

/// One CPS cycle as executed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleRecord {
    /// The parent's position while the children move, world frame.
    pub parent_from: Point,
    /// The parent's position after its move, world frame.
    pub parent_to: Point,
    /// The parent's driven path, world frame.
    pub parent_path: Vec<Point>,
    /// Every child, in order.
    pub children: Vec<ChildMove>,
}

/// A target the parent could not reach by CPS cycles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RejectedTarget {
    /// Index into the step's candidates.
    pub candidate: usize,
    /// Why.
    pub reason: String,
}

/// The executed move of one step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct MoveRecord {
    /// The candidate actually reached.
    pub target: Option<usize>,
    /// Whether subgoals were retrieved.
    pub subgoal_retrieval: bool,
    /// With subgoals: the Visibility Graph's shortest path they were taken from
    /// (its corners, world frame, the parent's position first).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub graph_path: Vec<Point>,
    /// The cycles in order.
    pub cycles: Vec<CycleRecord>,
    /// Candidates tried first and given up.
    pub rejected: Vec<RejectedTarget>,
}

/// The AND region of every child of a recorded cycle, recomputed on the knowledge
/// map the cycle was planned on: per child, a mask over the grid's cells (row-major)
/// of where that child could have stood (section IV-B). The children's terrain is
/// taken with the parent at `parent_from`, as the planner takes it with the parent
/// where the step began. For pictures and checks.
pub fn cycle_and_regions(
    knowledge: &OccupancyGrid,
    cycle: &CycleRecord,
    config: &Config,
) -> Vec<Vec<bool>> {
    let g = knowledge.geometry();
    let params = cycle_params(config);
    let (Some(from), Some(to)) = (
        g.world_to_cell(cycle.parent_from),
        g.world_to_cell(cycle.parent_to),
    ) else {
        return vec![vec![false; g.len()]; cycle.children.len()];
    };
    let mutual = mutual_view(knowledge, from, to, params.link);
    let terrain = Arc::new(Terrain::new(knowledge, params.child_radius, from));
    cycle
        .children
        .iter()
        .map(|c| match g.world_to_cell(c.from) {
            Some(cell) => {
                let reach = ChildReach::on(&terrain, g, cell)
                    .unwrap_or_else(|| ChildReach::new(knowledge, cell, params.child_radius));
                and_region(&mutual, &reach).to_mask(g.len())
            }
            None => vec![false; g.len()],
        })
        .collect()
}

/// The parent's planning round (Eq. 1) and, with children, the groundwork of the
/// CPS planners computed alongside it.
pub fn plan_round(
    knowledge: &OccupancyGrid,
    here: Cell,
    config: &Config,
    rng: &mut ChaCha8Rng,
) -> (ParentPlan, ParentReach, Option<Groundwork>) {
    let ((plan, reach), groundwork) = rayon::join(
        || plan_parent_with_reach(knowledge, here, config, rng),
        || {
            (config.children.count > 0).then(|| {
                Groundwork::new(knowledge, here, config.robot.radius, &cycle_params(config))
            })
        },
    );
    (plan, reach, groundwork)
}

/// The cycle parameters of a configuration.
pub fn cycle_params(config: &Config) -> CycleParams {
    let c = &config.children;
    CycleParams {
        child_radius: c.radius,
        link: LinkRange {
            min: c.min_range,
            max: c.max_range.unwrap_or(config.scanner.range),
        },
        eq2: Eq2 {
            alpha_c: c.alpha_c,
            beta_c: c.beta_c,
            theta_t: c.theta_t_deg.to_radians(),
            d_t: c.d_t,
            clearance_cap: c.clearance_cap,
        },
    }
}

/// Starting places of the children after the first scan: the drivable cells
/// nearest (by travel) to the parent that are at least the minimum link range from
/// it and two radii plus a cell from each other; the parent's own cell if there is
/// no room.
pub fn initial_children(knowledge: &OccupancyGrid, parent: Cell, config: &Config) -> Vec<Cell> {
    let g = knowledge.geometry();
    let c = &config.children;
    let trav = Traversability::new(knowledge, c.radius, parent);
    let field = sweep(g, &trav.passable, &[g.index(parent)], UNREACHED);
    let mut order: Vec<usize> = (0..g.len())
        .filter(|&i| trav.traversable[i] && field.reached(i))
        .collect();
    order.sort_unstable_by_key(|&i| (field.cost[i], i));
    let res = g.resolution;
    let dist = |a: Cell, b: Cell| (a.x as f64 - b.x as f64).hypot(a.y as f64 - b.y as f64) * res;
    let mut out: Vec<Cell> = Vec::with_capacity(c.count);
    for i in order {
        if out.len() == c.count {
            break;
        }
        let cell = g.cell(i);
        if dist(cell, parent) >= c.min_range + 0.2
            && out.iter().all(|&o| dist(o, cell) >= 2.0 * c.radius + res)
        {
            out.push(cell);
        }
    }
    while out.len() < c.count {
        out.push(parent);
    }
    out
}

/// Where a move left the robots and how far they drove.
#[derive(Debug, Clone, PartialEq)]
pub struct Moved {
    /// The parent's new cell.
    pub parent: Cell,
    /// The children's new cells.
    pub children: Vec<Cell>,
    /// The parent's driven length, metres.
    pub parent_length: f64,
    /// Each child's driven length, metres.
    pub child_lengths: Vec<f64>,
}

/// How far from a candidate no CPS move can reach a relocated target may lie,
/// metres.
pub const RELOCATE_RADIUS_M: f64 = 3.0;
/// Spacing of the cells tried around such a candidate, metres.
pub const RELOCATE_SPACING_M: f64 = 0.3;
/// Relocated targets tried at most per candidate, best expected gain first.
pub const RELOCATE_TRIES: usize = 12;
/// Candidates relocated at most per step, best `G` first.
pub const RELOCATE_CANDIDATES: usize = 3;

/// Moves the parent from `here` to the best reachable candidate of `plan` by CPS
/// cycles, trying the eligible candidates in decreasing `G`; `reach` is what the
/// planning round computed for the parent, `groundwork` what [`plan_round`]
/// computed alongside it (computed here if `None`).
///
/// When no candidate can be reached (the paper's planner would stop here), the
/// [`RELOCATE_CANDIDATES`] best eligible candidates in turn are *relocated*:
/// drivable cells within
/// [`RELOCATE_RADIUS_M`] of it that still expect `min_gain_cells` new cells are
/// tried, best gain first, and the first one a CPS move reaches is appended to
/// `plan.candidates` (origin `Relocated`) and taken. Returns the record and where
/// the robots ended up; `None` when nothing can be reached.
pub fn execute_move(
    knowledge: &OccupancyGrid,
    here: Cell,
    children: &[Cell],
    plan: &mut ParentPlan,
    reach: ParentReach,
    groundwork: Option<Groundwork>,
    config: &Config,
) -> (MoveRecord, Option<Moved>) {
    let params = cycle_params(config);
    let groundwork = groundwork
        .unwrap_or_else(|| Groundwork::new(knowledge, here, config.robot.radius, &params));
    let maps = CpsMaps::assemble(knowledge, reach, groundwork, &params);
    let mut order: Vec<usize> = (0..plan.candidates.len())
        .filter(|&i| plan.candidates[i].eligible)
        .collect();
    order.sort_by(|&a, &b| {
        plan.candidates[b]
            .g
            .total_cmp(&plan.candidates[a].g)
            .then(a.cmp(&b))
    });
    let mut record = MoveRecord::default();
    for &index in &order {
        let target = plan.candidates[index].cell;
        match plan_move_in(&maps, here, target, children) {
            Ok(m) => return finish(&maps, record, index, target, children, &m),
            Err(e) => {
                record.rejected.push(RejectedTarget {
                    candidate: index,
                    reason: match e {
                        MoveError::NoPath => "no Visibility Graph path".into(),
                        MoveError::Stuck { .. } | MoveError::ChildCutOff { .. } => e.to_string(),
                    },
                });
                if let MoveError::ChildCutOff { .. } = e {
                    // The same for every target: nothing else to try.
                    return (record, None);
                }
            }
        }
    }
    for &index in order.iter().take(RELOCATE_CANDIDATES) {
        for cell in relocations(&maps, plan.candidates[index].cell, config) {
            if let Ok(m) = plan_move_in(&maps, here, cell, children) {
                let terrain = maps.parent_terrain();
                let c = relocated_candidate(
                    knowledge,
                    cell,
                    &plan.candidates[index],
                    &terrain.trav,
                    maps.parent_field(),
                    config,
                );
                plan.candidates.push(c);
                let new = plan.candidates.len() - 1;
                return finish(&maps, record, new, cell, children, &m);
            }
        }
    }
    (record, None)
}

/// The record and the robots' new places after the planned move `m` to `target`
/// (candidate `index`).
fn finish(
    maps: &CpsMaps,
    mut record: MoveRecord,
    index: usize,
    target: Cell,
    children: &[Cell],
    m: &MovePlan,
) -> (MoveRecord, Option<Moved>) {
    record.target = Some(index);
    record.subgoal_retrieval = m.retrieved;
    record.graph_path = to_world(maps.knowledge().geometry(), &m.graph_path);
    let mut parent_len = 0.0;
    let mut child_len = vec![0.0; children.len()];
    for cycle in &m.cycles {
        let (rec, plen) = cycle_record(maps, cycle);
        parent_len += plen;
        for (l, c) in child_len.iter_mut().zip(&rec.children) {
            *l += polyline_length(&c.path);
        }
        record.cycles.push(rec);
    }
    let kids = m
        .cycles
        .last()
        .map(|c| c.children.iter().map(|k| k.to).collect())
        .unwrap_or_else(|| children.to_vec());
    let moved = Moved {
        parent: target,
        children: kids,
        parent_length: parent_len,
        child_lengths: child_len,
    };
    (record, Some(moved))
}

/// Cells to try instead of `candidate`: drivable for the parent and reachable
/// from where it stands, on a lattice of [`RELOCATE_SPACING_M`] within
/// [`RELOCATE_RADIUS_M`], expecting at least `min_gain_cells` new cells; the
/// [`RELOCATE_TRIES`] with the largest expected gain (ties: nearest first).
fn relocations(maps: &CpsMaps, candidate: Cell, config: &Config) -> Vec<Cell> {
    let knowledge = maps.knowledge();
    let g = knowledge.geometry();
    let terrain = maps.parent_terrain();
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
            let need = config.parent.min_gain_cells;
            let s = expected_gain(knowledge, cell, config.range_cells(), usize::MAX);
            if s >= need {
                found.push((s, d2, cell));
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

/// The record of a cycle with the parent's Voronoi path, and that path's length.
fn cycle_record(maps: &CpsMaps, cycle: &CpsCycle) -> (CycleRecord, f64) {
    let g = maps.knowledge().geometry();
    let cells = maps
        .parent_path(cycle.parent_from, cycle.parent_to)
        .unwrap_or_else(|| vec![cycle.parent_from, cycle.parent_to]);
    let parent_path = to_world(g, &cells);
    let length = polyline_length(&parent_path);
    let children = cycle
        .children
        .iter()
        .map(|c| ChildMove {
            from: g.cell_center(c.from),
            to: g.cell_center(c.to),
            stays: c.stays,
            path: to_world(g, &c.path),
            and_region_cells: c.and_region_cells,
            clearance_m: c.placement.map(|p| p.clearance),
            distance_m: c.placement.map(|p| p.distance),
            theta_deg: c.placement.and_then(|p| p.theta).map(f64::to_degrees),
        })
        .collect();
    (
        CycleRecord {
            parent_from: g.cell_center(cycle.parent_from),
            parent_to: g.cell_center(cycle.parent_to),
            parent_path,
            children,
        },
        length,
    )
}
