//! Subgoal retrieval with the Visibility Graph (section IV-C, steps 1–8): when no
//! AND region joins the parent's current and target positions, the parent's
//! shortest path through the Visibility Graph is cut into legs, each with an AND
//! region, retrieving subgoals backwards from the target.
//!
//! 1. Check whether a cycle straight to the target has an AND region.
//! 2. If not, build the Visibility Graph and find the shortest path.
//! 3. Take the subgoal farthest along the path (the target first);
//! 4. compute the AND region between the current position and the subgoal;
//! 5. if it exists, place the children (Eq. 2);
//! 6. if not, take the subgoal one step closer to the current position;
//! 7. repeat 4–6 until an AND region exists;
//! 8. make the subgoal the current position and repeat until the target is reached.
//!
//! Consecutive vertices of the path see each other, but an AND region also needs
//! the children to reach it; when even the nearest subgoal has none, the move
//! fails and the caller picks another target.
//!
//! In: the step's [`StepMaps`], the parent's position and target, the children's
//! cells. Out: a [`MovePlan`], the move's CPS cycles in order (where every robot
//! stands; the drives are planned by [`crate::motion`]), or a [`MoveError`].

use std::cell::OnceCell;

use thiserror::Error;

use super::visgraph::VisibilityGraph;
use crate::accuracy::Chain;
use crate::children::{
    frame_cycle, place_min_error, place_random, ChildReach, CpsCycle, CycleError, CycleFrame,
    CycleParams, StepMaps,
};
use crate::config::ChildStrategy;
use crate::geom::Cell;
use crate::grid::{DistanceField, OccupancyGrid};

/// The CPS cycles of one parent move.
#[derive(Debug, Clone, PartialEq)]
pub struct MovePlan {
    /// The cycles in order; the last one ends at the target.
    pub cycles: Vec<CpsCycle>,
    /// Whether subgoals had to be retrieved (more than the direct cycle).
    pub retrieved: bool,
    /// The Visibility Graph's shortest path the subgoals were taken from (its
    /// corners, `from` first; empty when the direct cycle sufficed).
    pub graph_path: Vec<Cell>,
}

/// Why a move cannot be planned.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MoveError {
    /// The Visibility Graph has no path to the target.
    #[error("no Visibility Graph path to the target")]
    NoPath,
    /// At this subgoal no next leg has an AND region the children can use.
    #[error("no leg from ({}, {}) has an AND region", at.x, at.y)]
    Stuck {
        /// Where the retrieval stopped.
        at: Cell,
    },
    /// A child can reach no spot the parent sees from where it stands, so no
    /// cycle can start there, whatever the target.
    #[error("child {} can reach no spot the parent sees", child + 1)]
    ChildCutOff {
        /// Index of the child.
        child: usize,
    },
}

/// Plans the cycles that take the parent (radius `parent_radius`) from `from` to
/// `to` with the children at `children`, on maps of its own.
pub fn plan_move(
    knowledge: &OccupancyGrid,
    from: Cell,
    to: Cell,
    children: &[Cell],
    parent_radius: f64,
    params: &CycleParams,
) -> Result<MovePlan, MoveError> {
    let maps = StepMaps::new(knowledge, from, parent_radius, params);
    Retrieval::new(&maps).plan_move(from, to, children, None)
}

/// Subgoal retrieval on one step's maps: the moves to every candidate of the step
/// share the maps' views and one Visibility Graph of the parent's terrain, built
/// the first time a move needs subgoals (step 2).
#[derive(Debug)]
pub struct Retrieval<'m, 'k> {
    maps: &'m StepMaps<'k>,
    graph: OnceCell<VisibilityGraph>,
    guide: Option<(Cell, &'m DistanceField)>,
    strategy: Option<ChildStrategy>,
}

impl<'m, 'k> Retrieval<'m, 'k> {
    /// Retrieval on `maps`.
    pub fn new(maps: &'m StepMaps<'k>) -> Self {
        Self {
            maps,
            graph: OnceCell::new(),
            guide: None,
            strategy: None,
        }
    }

    /// The retrieval placing the children by `strategy` instead of the maps'
    /// (a tolerance may call for `min-error` on one move).
    pub fn with_strategy(mut self, strategy: ChildStrategy) -> Self {
        self.strategy = Some(strategy);
        self
    }

    /// The retrieval with the parent's travel distances from `source` over its
    /// terrain's passable cells (the planning round's sweep): the Visibility
    /// Graph searches of moves from `source` are guided by them
    /// ([`VisibilityGraph::shortest_path_guided`]).
    pub fn with_guide(mut self, source: Cell, field: &'m DistanceField) -> Self {
        self.guide = Some((source, field));
        self
    }

    /// The parent's Visibility Graph (section IV-C step 2), built on first use.
    pub fn visibility_graph(&self) -> &VisibilityGraph {
        self.graph.get_or_init(|| {
            VisibilityGraph::build(self.maps.knowledge(), &self.maps.parent_terrain().trav)
        })
    }

    /// [`plan_move`] on the step's shared maps; `chain` is the CPS chain at the
    /// start of the move (strategy `min-error` needs it: without it, the Eq. (2)
    /// spots are kept).
    pub fn plan_move(
        &self,
        from: Cell,
        to: Cell,
        children: &[Cell],
        chain: Option<&Chain>,
    ) -> Result<MovePlan, MoveError> {
        let mut chain = chain.cloned();
        retrieve(self, from, to, children, &mut chain)
    }
}

/// Steps 1–8 of section IV-C.
fn retrieve(
    retrieval: &Retrieval,
    from: Cell,
    to: Cell,
    children: &[Cell],
    chain: &mut Option<Chain>,
) -> Result<MovePlan, MoveError> {
    let maps = retrieval.maps;
    // The legs are found by whether Eq. (2) can place the children (feasible
    // exactly when any spots are); the leg taken then gets the strategy's spots.
    // Under `min-error` the Eq. (2) spots are chosen only when that search finds
    // none (up to two movers: whether they fit is known without them).
    let strategy = retrieval.strategy.unwrap_or(maps.params().strategy);
    let leg = |from: Cell, to: Cell, kids: &[Cell], reach: &[ChildReach]| {
        let frame = frame_cycle(maps, from, to, kids, reach)?;
        match frame.placeable(maps) {
            Some(true) if strategy == ChildStrategy::MinError => Ok(Leg { frame, eq2: None }),
            Some(false) => Err(CycleError::NoJointPlacement),
            _ => {
                let eq2 = frame.place_eq2(maps)?;
                Ok(Leg {
                    frame,
                    eq2: Some(eq2),
                })
            }
        }
    };
    let finish = |leg: Leg, reach: &[ChildReach], chain: &mut Option<Chain>| {
        let Leg { frame, eq2 } = leg;
        let eq2 = || eq2.map_or_else(|| frame.place_eq2(maps), Ok);
        let placed = match strategy {
            ChildStrategy::Random => place_random(maps, &eq2()?, reach, &mut maps.rng()),
            ChildStrategy::MinError => match chain
                .as_ref()
                .and_then(|c| place_min_error(maps, &frame, c, maps.params().travel_weight))
            {
                Some(cycle) => cycle,
                None => eq2()?,
            },
            _ => eq2()?,
        };
        if let Some(c) = chain.as_mut() {
            let g = maps.knowledge().geometry();
            let kids: Vec<_> = placed
                .children
                .iter()
                .map(|k| g.cell_center(k.to))
                .collect();
            let moved: Vec<bool> = placed.children.iter().map(|k| !k.stays).collect();
            let rule = maps.params().targets;
            if c.cycle_on(maps.knowledge(), &rule, placed.parent_to, &kids, &moved)
                .is_err()
            {
                *chain = None;
            }
        }
        Ok::<_, CycleError>(placed)
    };
    let done = |cycles: Vec<CpsCycle>, graph_path: Vec<Cell>| -> Result<MovePlan, MoveError> {
        Ok(MovePlan {
            cycles,
            retrieved: !graph_path.is_empty(),
            graph_path,
        })
    };
    let reach_of =
        |kids: &[Cell]| -> Vec<ChildReach> { kids.iter().map(|&c| maps.reach(c)).collect() };
    let mut reach = reach_of(children);
    // Every child must stand, during the first cycle, on a spot the parent sees
    // from here: without one, no target can be reached (checked once, cheaply,
    // instead of through every subgoal of every candidate).
    let view = maps.view(from);
    if let Some(child) = reach.iter().position(|r| !view.sees_any(|i| r.reaches(i))) {
        return Err(MoveError::ChildCutOff { child });
    }
    // Step 1.
    let stuck = |at: Cell| move |_: CycleError| MoveError::Stuck { at };
    match leg(from, to, children, &reach) {
        Ok(leg) => {
            let cycle = finish(leg, &reach, chain).map_err(stuck(from))?;
            return done(vec![cycle], Vec::new());
        }
        Err(CycleError::NoAndRegion { .. } | CycleError::NoJointPlacement) => {}
    }
    // Step 2. No drivable path at all means no Visibility Graph path either (its
    // legs are drivable), which the graph would find out only after searching
    // every vertex.
    let terrain = maps.parent_terrain();
    let g = maps.knowledge().geometry();
    let region = terrain.region_of(g.index(to));
    if region.is_none() || region != terrain.region_of(g.index(from)) {
        return Err(MoveError::NoPath);
    }
    let trav = &terrain.trav;
    let corners = retrieval
        .visibility_graph()
        .shortest_path_guided(
            maps.knowledge().geometry(),
            trav,
            from,
            to,
            retrieval
                .guide
                .and_then(|(source, field)| (source == from).then_some(field)),
        )
        .ok_or(MoveError::NoPath)?;
    let link = maps.params().link;
    let res = maps.knowledge().geometry().resolution;
    let mut path = densify(&corners, subgoal_spacing(link.max, res));
    let fine_spacing = (FINE_SPACING_M / res).max(1.0);
    // No cell is within range of two parent positions more than twice the range
    // apart.
    let too_far = |a: Cell, b: Cell| {
        let (dx, dy) = (a.x as f64 - b.x as f64, a.y as f64 - b.y as f64);
        dx.hypot(dy) * maps.knowledge().geometry().resolution > 2.0 * link.max
    };
    // Steps 3–8.
    let mut cycles = Vec::new();
    let mut here = 0;
    let mut kids: Vec<Cell> = children.to_vec();
    while here + 1 < path.len() {
        let next = (here + 1..path.len()).rev().find_map(|j| {
            if too_far(path[here], path[j]) {
                return None;
            }
            leg(path[here], path[j], &kids, &reach).ok().map(|c| (j, c))
        });
        // Step 6 taken further when even the nearest subgoal fails: points of the
        // leg to it, every FINE_SPACING_M metres, nearest last.
        let next = next.or_else(|| {
            let fine = densify(&[path[here], path[here + 1]], fine_spacing);
            fine.get(1..fine.len().saturating_sub(1))?
                .iter()
                .rev()
                .find_map(|&p| leg(path[here], p, &kids, &reach).ok().map(|c| (p, c)))
                .map(|(p, c)| {
                    path.insert(here + 1, p);
                    (here + 1, c)
                })
        });
        let Some((j, cycle)) = next else {
            return Err(MoveError::Stuck { at: path[here] });
        };
        let cycle = finish(cycle, &reach, chain).map_err(stuck(path[here]))?;
        kids = cycle.children.iter().map(|c| c.to).collect();
        reach = reach_of(&kids);
        cycles.push(cycle);
        here = j;
    }
    done(cycles, corners)
}

/// A leg whose cycle can be planned: its frame, and its Eq. (2) cycle unless
/// the strategy may not need it.
struct Leg {
    frame: CycleFrame,
    eq2: Option<CpsCycle>,
}

/// Spacing, metres, of the points tried on the leg to the next subgoal when no
/// subgoal of the path gives a cycle (narrow, cluttered passages, where only short
/// legs have an AND region).
pub const FINE_SPACING_M: f64 = 0.5;

/// Spacing, in cells, of the extra subgoals on a straight Visibility Graph leg: a
/// quarter of the link range (at least one cell), so that a leg longer than the
/// instrument reaches still offers subgoals every few metres.
fn subgoal_spacing(link_max: f64, resolution: f64) -> f64 {
    (link_max / 4.0 / resolution).max(1.0)
}

/// The path's corners with extra points on every straight leg longer than
/// `spacing` cells, evenly spaced: the candidate subgoals of steps 3–7. Each
/// point is the cell the segment between the corners' centres passes through, so
/// it is as drivable as the leg.
fn densify(corners: &[Cell], spacing: f64) -> Vec<Cell> {
    let mut out: Vec<Cell> = Vec::with_capacity(corners.len());
    for leg in corners.windows(2) {
        let (a, b) = (leg[0], leg[1]);
        out.push(a);
        let (dx, dy) = (b.x as f64 - a.x as f64, b.y as f64 - a.y as f64);
        let parts = (dx.hypot(dy) / spacing).ceil() as usize;
        for k in 1..parts {
            let t = k as f64 / parts as f64;
            let cell = Cell::new(
                (a.x as f64 + 0.5 + t * dx).floor() as usize,
                (a.y as f64 + 0.5 + t * dy).floor() as usize,
            );
            if out.last() != Some(&cell) && cell != b {
                out.push(cell);
            }
        }
    }
    out.extend(corners.last());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::children::test_params as params;
    use crate::grid::fixtures::u_corridor;
    use crate::grid::CellState;
    use crate::sensing::certain_view;

    #[test]
    fn u_turn_needs_subgoals_and_every_leg_keeps_the_links() {
        let k = u_corridor();
        let g = *k.geometry();
        let (from, to) = (Cell::new(15, 10), Cell::new(105, 10));
        let children = [Cell::new(15, 20), Cell::new(15, 30)];
        let plan = plan_move(&k, from, to, &children, 0.25, &params()).unwrap();
        assert!(plan.retrieved);
        assert!(plan.cycles.len() >= 2, "{} cycles", plan.cycles.len());
        assert_eq!(plan.graph_path.first(), Some(&from));
        assert_eq!(plan.graph_path.last(), Some(&to));
        assert!(
            plan.graph_path.len() >= 3,
            "a U-turn bends: {:?}",
            plan.graph_path
        );
        assert_eq!(plan.cycles[0].parent_from, from);
        assert_eq!(plan.cycles.last().unwrap().parent_to, to);
        let link = params().link;
        for (n, cycle) in plan.cycles.iter().enumerate() {
            if n > 0 {
                assert_eq!(cycle.parent_from, plan.cycles[n - 1].parent_to);
            }
            for c in &cycle.children {
                let sees = certain_view(&k, c.to, link);
                assert!(sees[g.index(cycle.parent_from)] && sees[g.index(cycle.parent_to)]);
            }
        }
    }

    #[test]
    fn long_legs_get_subgoals_on_the_segment() {
        let corners = [Cell::new(0, 0), Cell::new(100, 0), Cell::new(100, 30)];
        let path = densify(&corners, 25.0);
        assert_eq!(path.first(), Some(&corners[0]));
        assert_eq!(path.last(), Some(&corners[2]));
        assert!(path.contains(&corners[1]));
        for l in path.windows(2) {
            let d = (l[0].x as f64 - l[1].x as f64).hypot(l[0].y as f64 - l[1].y as f64);
            assert!(d > 0.0 && d <= 25.0, "{l:?}");
        }
        assert!(path.iter().all(|c| c.y == 0 || c.x == 100));
    }

    #[test]
    fn a_leg_longer_than_twice_the_range_is_split() {
        // A straight corridor 40 m long, link range 8 m: no single cycle can do it.
        let g = crate::grid::GridGeometry::new(420, 30, 0.1, crate::geom::Point::default());
        let mut k = crate::grid::OccupancyGrid::filled(g, CellState::Occupied);
        k.fill_rect(5, 5, 415, 25, CellState::Free);
        let mut p = params();
        p.link.max = 8.0;
        let (from, to) = (Cell::new(10, 15), Cell::new(410, 15));
        let plan = plan_move(
            &k,
            from,
            to,
            &[Cell::new(30, 10), Cell::new(30, 20)],
            0.25,
            &p,
        )
        .unwrap();
        assert!(plan.retrieved);
        assert!(plan.cycles.len() >= 3, "{} cycles", plan.cycles.len());
        assert_eq!(plan.cycles.last().unwrap().parent_to, to);
        for cycle in &plan.cycles {
            for c in &cycle.children {
                let sees = certain_view(&k, c.to, p.link);
                assert!(sees[g.index(cycle.parent_from)] && sees[g.index(cycle.parent_to)]);
            }
        }
    }

    #[test]
    fn a_child_cut_off_from_the_parent_is_reported_at_once() {
        let mut k = u_corridor();
        // A pocket around the second child, walled off from the corridor.
        k.fill_rect(4, 40, 26, 42, CellState::Occupied);
        k.fill_rect(4, 60, 26, 62, CellState::Occupied);
        let r = plan_move(
            &k,
            Cell::new(15, 10),
            Cell::new(105, 10),
            &[Cell::new(15, 20), Cell::new(15, 50)],
            0.25,
            &params(),
        );
        assert_eq!(r, Err(MoveError::ChildCutOff { child: 1 }));
    }

    #[test]
    fn straight_corridor_needs_one_cycle() {
        let k = u_corridor();
        let plan = plan_move(
            &k,
            Cell::new(15, 10),
            Cell::new(15, 80),
            &[Cell::new(10, 20), Cell::new(20, 20)],
            0.25,
            &params(),
        )
        .unwrap();
        assert!(!plan.retrieved);
        assert!(plan.graph_path.is_empty());
        assert_eq!(plan.cycles.len(), 1);
    }

    #[test]
    fn unreachable_target_is_an_error() {
        let mut k = u_corridor();
        k.fill_rect(5, 60, 25, 62, CellState::Occupied);
        let r = plan_move(
            &k,
            Cell::new(15, 10),
            Cell::new(105, 10),
            &[Cell::new(15, 20), Cell::new(15, 30)],
            0.25,
            &params(),
        );
        assert_eq!(r, Err(MoveError::NoPath));
    }
}
