//! The team part of a mission step: the parent's planning round with the CPS
//! planners' groundwork beside it, the children's starting places, and the
//! parent's move to its target as CPS cycles (paper Fig. 1), with subgoals when
//! needed (section IV-C), Voronoi drives (IV-D) and the next candidate when even
//! that fails.

use rand::SeedableRng as _;
use rand_chacha::ChaCha8Rng;

use super::record::{ChildMove, CycleRecord, MoveRecord, RejectedTarget};
use super::tolerance::{hold, Anchor, Held, Tolerance};
use crate::accuracy::Chain;
use crate::children::{CpsCycle, CycleParams, StepMaps};
use crate::config::{ChildStrategy, Config};
use crate::geom::{polyline_length, Cell};
use crate::grid::path::to_world;
use crate::grid::travel::sweep;
use crate::grid::{Drivable, OccupancyGrid, Terrain, Traversability, UNREACHED};
use crate::motion::{gvd, Roads, VoronoiField};
use crate::parent::{
    fallback_candidate, plan_parent_with_field, reachable_frontier, relocated_candidate,
    relocations, Kept, ParentPlan, ParentReach, CPS_FALLBACK_TRIES, RELOCATE_CANDIDATES,
};
use crate::subgoals::{MoveError, MovePlan, Retrieval};

/// The part of a step's CPS planning that does not depend on the parent's
/// planning round, so that it can be computed while that round runs: the Voronoi
/// diagrams, and the children's terrain when their radius differs from the
/// parent's.
#[derive(Debug)]
pub struct Groundwork {
    /// The children's terrain (only when their radius differs from the parent's;
    /// otherwise the parent's terrain serves).
    child_terrain: Option<Terrain>,
    roads: Roads,
}

impl Groundwork {
    /// The groundwork for a parent of `parent_radius` metres at `parent` and
    /// children with `params`; `kept`: drivable cells the caller keeps up to date
    /// for `knowledge`, used for the robots of their radius; `voronoi`: the GVD's
    /// obstacle side kept up to date for `knowledge`.
    pub fn new(
        knowledge: &OccupancyGrid,
        parent: Cell,
        parent_radius: f64,
        params: &CycleParams,
        kept: Option<&Drivable>,
        voronoi: Option<&VoronoiField>,
    ) -> Self {
        let same = parent_radius == params.child_radius;
        let for_robot = |radius: f64| Traversability::kept_or_new(kept, knowledge, radius, parent);
        let diagram = |trav: &Traversability| match voronoi {
            Some(v) => v.diagram(knowledge, trav),
            None => gvd(knowledge, trav),
        };
        let ((child_terrain, children), parent_gvd) = rayon::join(
            || {
                if same {
                    (None, diagram(&for_robot(params.child_radius)))
                } else {
                    let t = Terrain::without_escape(knowledge, params.child_radius);
                    let d = diagram(&t.trav);
                    (Some(t), d)
                }
            },
            || (!same).then(|| diagram(&for_robot(parent_radius))),
        );
        Self {
            child_terrain,
            roads: Roads {
                children,
                parent: parent_gvd,
            },
        }
    }
}

/// The random stream of the planning round after scan `scan` (counted from 1)
/// of a run seeded by `seed`: each round draws from its own stream, so one
/// round can be planned again on its own ([`plan_step_after`](super::plan_step_after))
/// with the same choices as in the episode.
pub fn round_rng(seed: u64, scan: usize) -> ChaCha8Rng {
    // A fixed odd multiplier (the golden ratio's) spreads neighbouring scan
    // numbers over the seed space; the salt keeps the rounds' streams apart
    // from the scans' range noise, which mixes the same seed.
    const SALT: u64 = 0x726f_756e_6473;
    ChaCha8Rng::seed_from_u64(seed ^ SALT ^ (scan as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// The parent's planning round (Eq. 1) and, with children, the groundwork of the
/// CPS planners computed alongside it; `kept`: what the caller keeps up to date
/// for `knowledge` ([`plan_parent_with_field`]), `voronoi`: the GVD's obstacle
/// side likewise ([`Groundwork::new`]).
pub fn plan_round(
    knowledge: &OccupancyGrid,
    here: Cell,
    config: &Config,
    rng: &mut ChaCha8Rng,
    kept: Option<Kept<'_>>,
    voronoi: Option<&VoronoiField>,
) -> (ParentPlan, ParentReach, Option<Groundwork>) {
    let ((plan, reach), groundwork) = rayon::join(
        || plan_parent_with_field(knowledge, here, config, rng, kept),
        || {
            (config.children.count > 0).then(|| {
                Groundwork::new(
                    knowledge,
                    here,
                    config.robot.radius,
                    &CycleParams::from_config(config),
                    kept.map(|k| k.drivable),
                    voronoi,
                )
            })
        },
    );
    (plan, reach, groundwork)
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

/// Where the team stands when a move is planned.
#[derive(Debug, Clone, Copy)]
pub struct Team<'a> {
    /// The parent's cell.
    pub parent: Cell,
    /// The children's cells.
    pub children: &'a [Cell],
    /// The CPS chain there (`None`: accuracy not tracked).
    pub chain: Option<&'a Chain>,
    /// Earlier stations where the parent measured targets (closures return
    /// there under a tolerance).
    pub anchors: &'a [Anchor],
    /// Targets the team still carries.
    pub carried: usize,
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

/// Moves the parent from `here` to the best reachable candidate of `plan` by CPS
/// cycles, trying the eligible candidates in decreasing `G`; `reach` is what the
/// planning round computed for the parent, `groundwork` what [`plan_round`]
/// computed alongside it (computed here if `None`).
///
/// When no candidate can be reached (the paper's planner would stop here), the
/// [`RELOCATE_CANDIDATES`] best eligible candidates in turn are *relocated*:
/// drivable cells within
/// [`RELOCATE_RADIUS_M`](crate::parent::RELOCATE_RADIUS_M) of it that still expect `min_gain_cells` new cells are
/// tried, best gain first, and the first one a CPS move reaches is appended to
/// `plan.candidates` (origin `Relocated`) and taken. Returns the record and where
/// the robots ended up; `None` when nothing can be reached.
pub fn execute_move(
    knowledge: &OccupancyGrid,
    team: Team,
    plan: &mut ParentPlan,
    reach: ParentReach,
    groundwork: Option<Groundwork>,
    config: &Config,
) -> (MoveRecord, Option<Moved>) {
    let Team {
        parent: here,
        children,
        chain,
        anchors,
        carried,
    } = team;
    let params = CycleParams::from_config(config);
    let Groundwork {
        child_terrain,
        roads,
    } = groundwork.unwrap_or_else(|| {
        Groundwork::new(knowledge, here, config.robot.radius, &params, None, None)
    });
    let ParentReach { trav, field, gain } = reach;
    let parent_terrain = Terrain::from_sweep(trav, field);
    // The random choices of the step's placements follow the seed and the state.
    let seed =
        config.seed ^ ((here.y as u64) << 32 | here.x as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let maps = StepMaps::assemble(knowledge, parent_terrain, child_terrain, &params).seeded(seed);
    let field = maps
        .parent_terrain()
        .field()
        .expect("the parent's terrain keeps its sweep");
    let retrieval = Retrieval::new(&maps).with_guide(here, field);
    let accurate = Retrieval::new(&maps)
        .with_guide(here, field)
        .with_strategy(ChildStrategy::MinError);
    let tolerance = match (config.mission.max_sigma_m, chain) {
        (Some(max), Some(_)) => Some(Tolerance {
            max,
            anchors,
            time: config.time,
            rule: params.targets,
            strategy: ChildStrategy::MinError,
            carried,
        }),
        _ => None,
    };
    // Under a tolerance the children are placed for accuracy on every move: a
    // heading error the chain carries cannot be undone by a later placement.
    let step = TeamStep {
        maps: &maps,
        roads: &roads,
        retrieval: if tolerance.is_some() {
            &accurate
        } else {
            &retrieval
        },
        chain,
    };
    let plan_with = |from: Cell, to: Cell, kids: &[Cell], c: &Chain, s: ChildStrategy| {
        let r = if s == params.strategy {
            &retrieval
        } else {
            &accurate
        };
        let mut p = r.plan_move(from, to, kids, Some(c))?;
        roads
            .drive(&maps, &mut p)
            .map_err(|e| MoveError::Stuck { at: e.parent_from })?;
        Ok(p)
    };
    // The move taken to the scan station: under a tolerance, with the closure
    // it may need first.
    let finish = |record: MoveRecord, index: usize, target: Cell, m: MovePlan| {
        let held = match (&tolerance, chain) {
            (Some(tol), Some(c)) => hold(knowledge, tol, c, here, target, children, m, &plan_with),
            _ => Held {
                plan: m,
                closure: None,
                left: None,
            },
        };
        let (mut record, moved) = finish(&step, record, index, target, children, &held.plan);
        record.closure = held.closure;
        if let (Some(left), Some(first)) = (held.left, record.cycles.first_mut()) {
            first.left_targets.push(left);
        }
        (record, moved)
    };
    let order = plan.preference(config.parent.planner);
    let mut record = MoveRecord::default();
    // The error term: the moves to the best candidates planned, and the one with
    // the best G − γ·E taken.
    let mut planned: Vec<(usize, MovePlan, f64)> = Vec::new();
    let evaluate = (config.parent.gamma > 0.0 || tolerance.is_some()) && chain.is_some();
    let before = chain.map_or(0.0, |c| c.pose().position_sigma());
    // Under a tolerance without the error term, the first candidate in the
    // planner's order whose move keeps the tolerance is taken at once.
    let first_keeper = |growth: f64| {
        config.parent.gamma == 0.0 && tolerance.as_ref().is_some_and(|t| before + growth <= t.max)
    };
    for &index in &order {
        if evaluate && planned.len() >= config.parent.error_candidates {
            break;
        }
        let target = plan.candidates[index].cell;
        match step.plan_move(here, target, children) {
            Ok(m) if evaluate => {
                let growth = error_growth(&step, chain, &m).unwrap_or(f64::INFINITY);
                plan.candidates[index].error_growth_m = Some(growth);
                if first_keeper(growth) {
                    return finish(record, index, target, m);
                }
                planned.push((index, m, growth));
            }
            Ok(m) => return finish(record, index, target, m),
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
    if !planned.is_empty() {
        let worst = planned
            .iter()
            .map(|p| p.2)
            .filter(|g| g.is_finite())
            .fold(0.0f64, f64::max);
        let term = |growth: f64| match config.parent.scoring {
            crate::config::Scoring::Normalized if worst > 0.0 => (growth / worst).min(1.0),
            crate::config::Scoring::Normalized => 0.0,
            crate::config::Scoring::Literal => growth * 1e3,
        };
        let score = |(i, _, growth): &(usize, MovePlan, f64)| {
            plan.candidates[*i].g - config.parent.gamma * term(*growth)
        };
        // Under a tolerance, the moves that keep it come first.
        let before = chain.map_or(0.0, |c| c.pose().position_sigma());
        let keeps = |growth: f64| tolerance.as_ref().is_none_or(|t| before + growth <= t.max);
        let best = planned
            .iter()
            .max_by(|a, b| {
                keeps(a.2)
                    .cmp(&keeps(b.2))
                    .then(score(a).total_cmp(&score(b)))
                    .then(b.0.cmp(&a.0))
            })
            .map(|p| p.0);
        if let Some((index, m, _)) = planned.into_iter().find(|p| Some(p.0) == best) {
            let target = plan.candidates[index].cell;
            return finish(record, index, target, m);
        }
    }
    for &index in order.iter().take(RELOCATE_CANDIDATES) {
        let terrain = maps.parent_terrain();
        for cell in relocations(
            knowledge,
            terrain,
            plan.candidates[index].cell,
            config,
            &gain,
        ) {
            if let Ok(m) = step.plan_move(here, cell, children) {
                let c = relocated_candidate(
                    knowledge,
                    cell,
                    &plan.candidates[index],
                    &terrain.trav,
                    field,
                    config,
                    &gain,
                );
                plan.candidates.push(c);
                let new = plan.candidates.len() - 1;
                return finish(record, new, cell, m);
            }
        }
    }
    // Last, other reachable frontier cells, nearest first.
    let terrain = maps.parent_terrain();
    for cell in reachable_frontier(
        knowledge,
        &terrain.trav,
        field,
        config,
        &gain,
        CPS_FALLBACK_TRIES,
    ) {
        if plan.candidates.iter().any(|c| c.cell == cell) {
            continue;
        }
        if let Ok(m) = step.plan_move(here, cell, children) {
            let c = fallback_candidate(knowledge, cell, &terrain.trav, field, config, &gain);
            plan.candidates.push(c);
            let new = plan.candidates.len() - 1;
            return finish(record, new, cell, m);
        }
    }
    (record, None)
}

/// How much the predicted radial σ of the parent's position grows on the planned
/// move `m`, metres; `None` when the chain cannot follow it.
fn error_growth(step: &TeamStep, chain: Option<&Chain>, m: &MovePlan) -> Option<f64> {
    let mut c = chain?.clone();
    let before = c.pose().position_sigma();
    let g = step.maps.knowledge().geometry();
    for cycle in &m.cycles {
        let kids: Vec<_> = cycle.children.iter().map(|k| g.cell_center(k.to)).collect();
        let moved: Vec<bool> = cycle.children.iter().map(|k| !k.stays).collect();
        let rule = step.maps.params().targets;
        c.cycle_on(step.maps.knowledge(), &rule, cycle.parent_to, &kids, &moved)
            .ok()?;
    }
    Some(c.pose().position_sigma() - before)
}

/// The record and the robots' new places after the planned move `m` to `target`
/// (candidate `index`).
fn finish(
    step: &TeamStep,
    mut record: MoveRecord,
    index: usize,
    target: Cell,
    children: &[Cell],
    m: &MovePlan,
) -> (MoveRecord, Option<Moved>) {
    record.target = Some(index);
    record.subgoal_retrieval = m.retrieved;
    record.graph_path = to_world(step.maps.knowledge().geometry(), &m.graph_path);
    let mut parent_len = 0.0;
    let mut child_len = vec![0.0; children.len()];
    for cycle in &m.cycles {
        let (rec, plen) = cycle_record(step, cycle);
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

/// The record of a cycle with the parent's Voronoi path, and that path's length.
fn cycle_record(step: &TeamStep, cycle: &CpsCycle) -> (CycleRecord, f64) {
    let g = step.maps.knowledge().geometry();
    let cells = step
        .roads
        .parent_path(step.maps, cycle.parent_from, cycle.parent_to)
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
            position_sigma_m: None,
            search_gap: cycle.search_gap.filter(|g| g.is_finite()),
            targets: Vec::new(),
            left_targets: Vec::new(),
        },
        length,
    )
}

/// The planners of one step's moves: its shared maps, the Voronoi diagrams and the
/// subgoal retrieval with its Visibility Graph.
struct TeamStep<'s, 'k> {
    maps: &'s StepMaps<'k>,
    roads: &'s Roads,
    retrieval: &'s Retrieval<'s, 'k>,
    /// The CPS chain where the step begins.
    chain: Option<&'s Chain>,
}

impl TeamStep<'_, '_> {
    /// The move's cycles (section IV-C) with every child's drive (IV-D). A child
    /// that cannot drive to its spot rejects the move as stuck where its cycle
    /// starts.
    fn plan_move(&self, from: Cell, to: Cell, children: &[Cell]) -> Result<MovePlan, MoveError> {
        let mut plan = self.retrieval.plan_move(from, to, children, self.chain)?;
        self.roads
            .drive(self.maps, &mut plan)
            .map_err(|e| MoveError::Stuck { at: e.parent_from })?;
        Ok(plan)
    }
}
