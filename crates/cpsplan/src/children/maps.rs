//! What the CPS planners of one step share (sections IV-B and IV-C): the maps
//! derived from one knowledge map, computed once and reused by every cycle,
//! subgoal and candidate of the step.
//!
//! In: the knowledge map, the parent's position and radius, the cycle parameters.
//! Out: a [`StepMaps`] holding
//! - the parent's [`Terrain`] (drivable cells, the region it can reach) and the
//!   children's: their drivable cells without the parent's escape region (a
//!   parent standing in a tight spot may squeeze out of it; the children must not
//!   drive through it), the parent's own terrain when the radii agree and the
//!   parent has no escape region;
//! - the certain views of the parent positions tried so far (a view is two
//!   visibility sweeps' worth of work, and subgoal retrieval asks for the same
//!   positions again and again);
//! - the terrains of children standing off the shared one.
//!
//! The stages above add what they own: the Visibility Graph (subgoals) and the
//! Voronoi diagrams (motion).

use std::cell::{OnceCell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;
use std::sync::Arc;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::and_region::ChildReach;
use super::params::CycleParams;
use crate::geom::Cell;
use crate::grid::travel::sweep;
use crate::grid::{OccupancyGrid, Terrain, Traversability, UNREACHED};
use crate::sensing::{seen_by_both, SightField, View};

/// Views kept at most; the cache starts afresh beyond this (each view is one flag
/// per cell of the rows its range disc spans).
const MAX_VIEWS: usize = 64;

/// The maps of one planning step for a team on `knowledge`.
#[derive(Debug)]
pub struct StepMaps<'k> {
    knowledge: &'k OccupancyGrid,
    params: CycleParams,
    parent: Arc<Terrain>,
    children: Arc<Terrain>,
    views: RefCell<HashMap<Cell, Rc<View<'k>>>>,
    own_terrain: RefCell<HashMap<Cell, ChildReach>>,
    /// The sight tests of every view, built with the first view.
    sight: OnceCell<Rc<SightField>>,
    /// The random choices of the step's child placements (strategy `random`).
    rng: RefCell<ChaCha8Rng>,
}

impl<'k> StepMaps<'k> {
    /// The maps for a parent of `parent_radius` metres standing at `parent` and
    /// children with `params`.
    pub fn new(
        knowledge: &'k OccupancyGrid,
        parent: Cell,
        parent_radius: f64,
        params: &CycleParams,
    ) -> Self {
        let g = knowledge.geometry();
        let (parent_terrain, child_terrain) = rayon::join(
            || {
                let trav = Traversability::new(knowledge, parent_radius, parent);
                let field = sweep(g, &trav.passable, &[g.index(parent)], UNREACHED);
                Terrain::from_sweep(trav, field)
            },
            || {
                (parent_radius != params.child_radius)
                    .then(|| Terrain::without_escape(knowledge, params.child_radius))
            },
        );
        Self::assemble(knowledge, parent_terrain, child_terrain, params)
    }

    /// The maps from the parent's terrain and, when the children's radius differs
    /// from the parent's, the children's terrain
    /// ([`Terrain::without_escape`]).
    pub fn assemble(
        knowledge: &'k OccupancyGrid,
        parent_terrain: Terrain,
        child_terrain: Option<Terrain>,
        params: &CycleParams,
    ) -> Self {
        let parent = Arc::new(parent_terrain);
        let children = match child_terrain {
            Some(t) => Arc::new(t),
            None if parent.trav.has_escape_region() => {
                Arc::new(Terrain::without_escape(knowledge, params.child_radius))
            }
            None => Arc::clone(&parent),
        };
        Self {
            knowledge,
            params: *params,
            parent,
            children,
            views: RefCell::default(),
            own_terrain: RefCell::default(),
            sight: OnceCell::new(),
            rng: RefCell::new(ChaCha8Rng::seed_from_u64(0)),
        }
    }

    /// The maps with the random choices of the step seeded by `seed`.
    pub fn seeded(self, seed: u64) -> Self {
        *self.rng.borrow_mut() = ChaCha8Rng::seed_from_u64(seed);
        self
    }

    /// The random generator of the step's child placements.
    pub fn rng(&self) -> std::cell::RefMut<'_, ChaCha8Rng> {
        self.rng.borrow_mut()
    }

    /// The knowledge map.
    pub fn knowledge(&self) -> &'k OccupancyGrid {
        self.knowledge
    }

    /// The cycle parameters.
    pub fn params(&self) -> &CycleParams {
        &self.params
    }

    /// The parent's terrain.
    pub fn parent_terrain(&self) -> &Terrain {
        &self.parent
    }

    /// Where a child standing at `child` can drive: the shared terrain, or a
    /// terrain of its own when it stands on no passable cell of the shared one
    /// (then its own escape region applies).
    pub fn reach(&self, child: Cell) -> ChildReach {
        let g = self.knowledge.geometry();
        if let Some(r) = ChildReach::on(&self.children, g, child) {
            return r;
        }
        self.own_terrain
            .borrow_mut()
            .entry(child)
            .or_insert_with(|| ChildReach::new(self.knowledge, child, self.params.child_radius))
            .clone()
    }

    /// The cells a child can stand on in certain line of sight from `from` by the
    /// link rule ([`View`]), cached.
    pub fn view(&self, from: Cell) -> Rc<View<'k>> {
        if let Some(v) = self.views.borrow().get(&from) {
            return Rc::clone(v);
        }
        // Only cells a child can stand on matter (the same for every child:
        // drivability does not depend on where the child stands).
        let drivable = &self.children.trav.traversable;
        let link = self.params.link;
        let field = View::needs_field(self.knowledge, link).then(|| {
            Rc::clone(
                self.sight
                    .get_or_init(|| Rc::new(SightField::of_known(self.knowledge, link))),
            )
        });
        let v = Rc::new(View::of(self.knowledge, from, link, field, |i| drivable[i]));
        let mut views = self.views.borrow_mut();
        if views.len() >= MAX_VIEWS {
            views.clear();
        }
        views.insert(from, Rc::clone(&v));
        v
    }

    /// Cells in certain line of sight from both parent positions within range
    /// ([`crate::sensing::mutual_view`]), ascending grid indices.
    pub fn mutual_view(&self, parent_from: Cell, parent_to: Cell) -> Vec<u32> {
        let (a, b) = (self.view(parent_from), self.view(parent_to));
        seen_by_both(self.knowledge.geometry(), &a, &b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::children::test_params;
    use crate::geom::Point;
    use crate::grid::{CellState, GridGeometry};

    /// A room with the parent squeezed against its west wall: its escape region
    /// is passable for the parent, and for nobody else.
    #[test]
    fn children_do_not_drive_through_the_parents_escape_region() {
        let g = GridGeometry::new(60, 40, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Occupied);
        k.fill_rect(1, 1, 59, 39, CellState::Free);
        let params = test_params();
        let parent = Cell::new(1, 20);
        let maps = StepMaps::new(&k, parent, params.child_radius, &params);
        let trav = &maps.parent_terrain().trav;
        assert!(trav.has_escape_region());
        let escape: Vec<usize> = (0..g.len())
            .filter(|&i| trav.passable[i] && !trav.traversable[i])
            .collect();
        assert!(escape.len() > 3, "{} escape cells", escape.len());
        let child = maps.reach(Cell::new(30, 20));
        for &i in &escape {
            assert!(!child.reaches(i), "a child reaches {:?}", g.cell(i));
            assert!(!child.terrain.trav.passable[i]);
        }
        // With the parent on a drivable cell, parent and children share one terrain.
        let maps = StepMaps::new(&k, Cell::new(10, 20), params.child_radius, &params);
        assert!(Arc::ptr_eq(&maps.parent, &maps.children));
    }
}
