//! The drives of one step (section IV-D): every robot of a planned move follows
//! the Voronoi edges of the known map.
//!
//! In: the step's [`StepMaps`] and a planned [`MovePlan`] (or one [`CpsCycle`]),
//! whose children have spots but no paths yet. Out: every moving child's path, and
//! the parent's path of each cycle.

use thiserror::Error;

use super::gvd::{gvd, Gvd};
use super::voronoi_path::voronoi_path;
use crate::children::{CpsCycle, StepMaps};
use crate::geom::Cell;
use crate::grid::{OccupancyGrid, Traversability};
use crate::subgoals::MovePlan;

/// The Voronoi diagrams robots of one step drive along: the children's, and the
/// parent's when its radius differs from the children's.
#[derive(Debug, Clone)]
pub struct Roads {
    /// The diagram of the children's drivable cells.
    pub children: Gvd,
    /// The diagram of the parent's drivable cells (`None`: the children's serves).
    pub parent: Option<Gvd>,
}

/// A moving child of a cycle has no drivable path to its spot.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("child {} has no drivable path to its spot in the cycle from ({}, {})", child + 1, parent_from.x, parent_from.y)]
pub struct NoDrivablePath {
    /// Index of the child.
    pub child: usize,
    /// Where the parent stands while the child drives.
    pub parent_from: Cell,
}

impl Roads {
    /// The diagrams for a parent of `parent_radius` metres and children of
    /// `child_radius` metres, both with the parent's escape region at `parent`.
    pub fn new(
        knowledge: &OccupancyGrid,
        parent: Cell,
        parent_radius: f64,
        child_radius: f64,
    ) -> Self {
        let diagram = |radius: f64| gvd(knowledge, &Traversability::new(knowledge, radius, parent));
        let (children, parent) = rayon::join(
            || diagram(child_radius),
            || (parent_radius != child_radius).then(|| diagram(parent_radius)),
        );
        Self { children, parent }
    }

    /// A child's path along the children's Voronoi edges over the drivable cells
    /// of the terrain it stands on ([`StepMaps::reach`]).
    pub fn child_path(&self, maps: &StepMaps, from: Cell, to: Cell) -> Option<Vec<Cell>> {
        let terrain = maps.reach(from).terrain;
        voronoi_path(maps.knowledge(), &terrain.trav, &self.children, from, to)
    }

    /// The parent's path along its Voronoi edges.
    pub fn parent_path(&self, maps: &StepMaps, from: Cell, to: Cell) -> Option<Vec<Cell>> {
        let diagram = self.parent.as_ref().unwrap_or(&self.children);
        voronoi_path(
            maps.knowledge(),
            &maps.parent_terrain().trav,
            diagram,
            from,
            to,
        )
    }

    /// Plans every moving child's path of `cycle` along the Voronoi edges.
    pub fn drive_children(
        &self,
        maps: &StepMaps,
        cycle: &mut CpsCycle,
    ) -> Result<(), NoDrivablePath> {
        for (child, c) in cycle
            .children
            .iter_mut()
            .enumerate()
            .filter(|(_, c)| !c.stays)
        {
            c.path = self.child_path(maps, c.from, c.to).ok_or(NoDrivablePath {
                child,
                parent_from: cycle.parent_from,
            })?;
        }
        Ok(())
    }

    /// Plans the children's paths of every cycle of `plan`, in order; the first
    /// cycle with a child that cannot drive to its spot stops it.
    pub fn drive(&self, maps: &StepMaps, plan: &mut MovePlan) -> Result<(), NoDrivablePath> {
        plan.cycles
            .iter_mut()
            .try_for_each(|c| self.drive_children(maps, c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::children::{test_params as params, test_plan_cycle as plan_cycle};
    use crate::grid::fixtures::l_corridor;
    use crate::grid::CellState;
    use crate::subgoals::plan_move;

    fn leg_drivable(maps: &StepMaps, child: Cell, path: &[Cell]) -> bool {
        let g = maps.knowledge().geometry();
        let reach = maps.reach(child);
        path.windows(2).all(|l| {
            crate::grid::line::segment_clear(g, l[0], l[1], |i| reach.terrain.trav.passable[i])
        })
    }

    #[test]
    fn moving_children_get_drivable_paths_and_staying_ones_none() {
        let k = l_corridor();
        let (from, to) = (Cell::new(20, 15), Cell::new(105, 100));
        let children = [Cell::new(10, 10), Cell::new(10, 20)];
        let p = params();
        let maps = StepMaps::new(&k, from, p.child_radius, &p);
        let roads = Roads::new(&k, from, p.child_radius, p.child_radius);
        let mut cycle = plan_cycle(&k, from, to, &children, &p).unwrap();
        roads.drive_children(&maps, &mut cycle).unwrap();
        for c in &cycle.children {
            assert!(!c.stays);
            assert_eq!(c.path.first(), Some(&c.from));
            assert_eq!(c.path.last(), Some(&c.to));
            assert!(leg_drivable(&maps, c.from, &c.path), "{:?}", c.path);
        }
        let parent = roads.parent_path(&maps, from, to).unwrap();
        assert_eq!((parent.first(), parent.last()), (Some(&from), Some(&to)));
    }

    #[test]
    fn a_child_with_no_way_to_its_spot_is_reported() {
        let mut k = l_corridor();
        let p = params();
        let (from, to) = (Cell::new(20, 15), Cell::new(105, 100));
        let mut plan = plan_move(
            &k,
            from,
            to,
            &[Cell::new(10, 10), Cell::new(10, 20)],
            0.25,
            &p,
        )
        .unwrap();
        // The corridor is walled off behind the children after planning.
        k.fill_rect(30, 5, 32, 25, CellState::Occupied);
        let maps = StepMaps::new(&k, from, p.child_radius, &p);
        let roads = Roads::new(&k, from, p.child_radius, p.child_radius);
        let err = roads.drive(&maps, &mut plan).unwrap_err();
        assert_eq!(err.parent_from, from);
    }
}
