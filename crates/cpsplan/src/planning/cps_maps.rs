//! What the CPS planners of one step share: the maps derived from one knowledge
//! map, computed once and reused by every cycle, subgoal and candidate of the step
//! (sections IV-B to IV-D).
//!
//! - the children's [`Terrain`] (drivable cells and connected regions) and the
//!   Generalized Voronoi Diagram they drive along;
//! - the parent's terrain and diagram (the same ones when parent and children have
//!   the same radius);
//! - the certain views of the parent positions tried so far (a view is two
//!   visibility sweeps' worth of work, and subgoal retrieval asks for the same
//!   positions again and again);
//! - the parent's Visibility Graph, built the first time a move needs subgoals.

use std::cell::{OnceCell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;
use std::sync::Arc;

use super::and_region::{seen_by_both, ChildReach, View};
use super::cps_cycle::CycleParams;
use super::distance::transform;
use super::reach::{sweep, DistanceField, UNREACHED};
use super::terrain::Terrain;
use super::traversability::clearance_metres;
use super::visgraph::VisibilityGraph;
use super::voronoi::{gvd, voronoi_path, Gvd};
use super::{ParentReach, Traversability};
use crate::geom::Cell;
use crate::world::{CellState, OccupancyGrid};

/// Views kept at most; the cache starts afresh beyond this (each view is one flag
/// per cell of the rows its range disc spans).
const MAX_VIEWS: usize = 64;

/// Drivable cells with their Voronoi diagram.
#[derive(Debug)]
struct Roads {
    terrain: Arc<Terrain>,
    gvd: Gvd,
}

/// The maps of one planning step for a team on `knowledge`.
#[derive(Debug)]
pub struct CpsMaps<'k> {
    knowledge: &'k OccupancyGrid,
    params: CycleParams,
    children: Roads,
    /// The parent's roads when its radius differs from the children's.
    parent: Option<Roads>,
    views: RefCell<HashMap<Cell, Rc<View>>>,
    own_terrain: RefCell<HashMap<Cell, ChildReach>>,
    graph: OnceCell<VisibilityGraph>,
    /// The parent's travel distances from where the step began.
    parent_field: DistanceField,
}

/// The part of a step's [`CpsMaps`] that does not depend on the parent's planning
/// round, so that it can be computed while that round runs: the Voronoi
/// diagrams, and the children's terrain when their radius differs from the
/// parent's.
#[derive(Debug)]
pub struct Groundwork {
    /// The children's terrain (only when their radius differs from the parent's;
    /// otherwise the parent's terrain serves).
    child_terrain: Option<Terrain>,
    child_gvd: Gvd,
    /// The parent's diagram when its radius differs from the children's.
    parent_gvd: Option<Gvd>,
}

impl Groundwork {
    /// The groundwork for a parent of `parent_radius` metres at `parent` and
    /// children with `params`.
    pub fn new(
        knowledge: &OccupancyGrid,
        parent: Cell,
        parent_radius: f64,
        params: &CycleParams,
    ) -> Self {
        let same = parent_radius == params.child_radius;
        let ((child_terrain, child_gvd), parent_gvd) = rayon::join(
            || {
                if same {
                    let trav = Traversability::new(knowledge, params.child_radius, parent);
                    (None, gvd(knowledge, &trav))
                } else {
                    let t = Terrain::new(knowledge, params.child_radius, parent);
                    let d = gvd(knowledge, &t.trav);
                    (Some(t), d)
                }
            },
            || {
                (!same).then(|| {
                    gvd(
                        knowledge,
                        &Traversability::new(knowledge, parent_radius, parent),
                    )
                })
            },
        );
        Self {
            child_terrain,
            child_gvd,
            parent_gvd,
        }
    }
}

impl<'k> CpsMaps<'k> {
    /// The maps for a parent of `parent_radius` metres standing at `parent` and
    /// children with `params`.
    pub fn new(
        knowledge: &'k OccupancyGrid,
        parent: Cell,
        parent_radius: f64,
        params: &CycleParams,
    ) -> Self {
        let g = knowledge.geometry();
        let (reach, groundwork) = rayon::join(
            || {
                let trav = Traversability::new(knowledge, parent_radius, parent);
                let field = sweep(g, &trav.passable, &[g.index(parent)], UNREACHED);
                ParentReach { trav, field }
            },
            || Groundwork::new(knowledge, parent, parent_radius, params),
        );
        Self::assemble(knowledge, reach, groundwork, params)
    }

    /// The maps from what the parent's planning round computed (`reach`) and the
    /// `groundwork` computed for the same knowledge map, parent position and radii.
    pub fn assemble(
        knowledge: &'k OccupancyGrid,
        reach: ParentReach,
        groundwork: Groundwork,
        params: &CycleParams,
    ) -> Self {
        let ParentReach { trav, field } = reach;
        let parent_terrain = Arc::new(Terrain::from_sweep(trav, &field));
        let Groundwork {
            child_terrain,
            child_gvd,
            parent_gvd,
        } = groundwork;
        let (children, parent) = match (child_terrain, parent_gvd) {
            (Some(t), Some(pg)) => (
                Roads {
                    terrain: Arc::new(t),
                    gvd: child_gvd,
                },
                Some(Roads {
                    terrain: parent_terrain,
                    gvd: pg,
                }),
            ),
            _ => (
                Roads {
                    terrain: parent_terrain,
                    gvd: child_gvd,
                },
                None,
            ),
        };
        Self {
            knowledge,
            params: *params,
            children,
            parent,
            views: RefCell::default(),
            own_terrain: RefCell::default(),
            graph: OnceCell::new(),
            parent_field: field,
        }
    }

    /// The parent's travel distances from where the step began.
    pub fn parent_field(&self) -> &DistanceField {
        &self.parent_field
    }

    /// Eq. (2)'s `1/P` of every cell in `cells` (grid indices): metres to the
    /// nearest known Occupied cell by the rule of
    /// [`super::Traversability::clearance_at`], capped at Eq. (2)'s clearance cap.
    /// One exact distance transform of the cells' bounding box widened by the cap:
    /// an Occupied cell nearer than the cap to any of them lies inside, and farther
    /// ones only give values the cap replaces.
    pub fn clearances(&self, cells: &[u32]) -> Vec<f64> {
        let g = self.knowledge.geometry();
        let w = g.width;
        let Some(bounds) =
            cells
                .iter()
                .fold(None, |b: Option<(usize, usize, usize, usize)>, &i| {
                    let (x, y) = (i as usize % w, i as usize / w);
                    Some(match b {
                        None => (x, y, x, y),
                        Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
                    })
                })
        else {
            return Vec::new();
        };
        let cap = self.params.eq2.clearance_cap;
        let res = g.resolution;
        let margin = (cap / res + 0.5).ceil() as usize + 1;
        let x0 = bounds.0.saturating_sub(margin);
        let y0 = bounds.1.saturating_sub(margin);
        let x1 = (bounds.2 + margin).min(w - 1);
        let y1 = (bounds.3 + margin).min(g.height - 1);
        let bw = x1 + 1 - x0;
        let k = self.knowledge.cells();
        let d = transform(bw, y1 + 1 - y0, |x, y| {
            k[(y0 + y) * w + x0 + x] == CellState::Occupied
        });
        cells
            .iter()
            .map(|&i| {
                let (x, y) = (i as usize % w, i as usize / w);
                let cells_away = d[(y - y0) * bw + (x - x0)];
                clearance_metres(cells_away, res).min(cap as f32) as f64
            })
            .collect()
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
        &self.parent_roads().terrain
    }

    fn parent_roads(&self) -> &Roads {
        self.parent.as_ref().unwrap_or(&self.children)
    }

    /// Where a child standing at `child` can drive: the shared terrain, or a
    /// terrain of its own when it stands on no passable cell of the shared one
    /// (then its own escape region applies).
    pub fn reach(&self, child: Cell) -> ChildReach {
        let g = self.knowledge.geometry();
        if let Some(r) = ChildReach::on(&self.children.terrain, g, child) {
            return r;
        }
        self.own_terrain
            .borrow_mut()
            .entry(child)
            .or_insert_with(|| ChildReach::new(self.knowledge, child, self.params.child_radius))
            .clone()
    }

    /// The cells in certain line of sight from `from` within the link range
    /// ([`View`]), cached.
    pub fn view(&self, from: Cell) -> Rc<View> {
        if let Some(v) = self.views.borrow().get(&from) {
            return Rc::clone(v);
        }
        let v = Rc::new(View::new(self.knowledge, from, self.params.link));
        let mut views = self.views.borrow_mut();
        if views.len() >= MAX_VIEWS {
            views.clear();
        }
        views.insert(from, Rc::clone(&v));
        v
    }

    /// Cells in certain line of sight from both parent positions within range
    /// ([`super::and_region::mutual_view`]), ascending grid indices.
    pub fn mutual_view(&self, parent_from: Cell, parent_to: Cell) -> Vec<u32> {
        let (a, b) = (self.view(parent_from), self.view(parent_to));
        seen_by_both(self.knowledge.geometry(), &a, &b)
    }

    /// A child's path along the Voronoi edges ([`voronoi_path`]).
    pub fn child_path(&self, from: Cell, to: Cell) -> Option<Vec<Cell>> {
        let terrain = self.reach(from).terrain;
        voronoi_path(self.knowledge, &terrain.trav, &self.children.gvd, from, to)
    }

    /// The parent's path along the Voronoi edges ([`voronoi_path`]).
    pub fn parent_path(&self, from: Cell, to: Cell) -> Option<Vec<Cell>> {
        let roads = self.parent_roads();
        voronoi_path(self.knowledge, &roads.terrain.trav, &roads.gvd, from, to)
    }

    /// The parent's Visibility Graph (section IV-C step 2), built on first use.
    pub fn visibility_graph(&self) -> &VisibilityGraph {
        self.graph.get_or_init(|| {
            VisibilityGraph::build(self.knowledge, &self.parent_roads().terrain.trav)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::cps_cycle::tests::params;
    use crate::world::GridGeometry;
    use crate::Point;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        /// The windowed transform gives every cell the capped clearance of the
        /// column walk.
        #[test]
        fn clearances_match_the_capped_walk(
            rects in proptest::collection::vec((0usize..60, 0usize..50, 1usize..8, 1usize..8), 0..10),
            unknown in (0usize..60, 0usize..50, 0usize..20, 0usize..20),
            picks in proptest::collection::vec(0usize..3000, 1..40),
        ) {
            let g = GridGeometry::new(60, 50, 0.1, Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Free);
            for (x, y, w, h) in rects {
                k.fill_rect(x, y, x + w, y + h, CellState::Occupied);
            }
            let (ux, uy, uw, uh) = unknown;
            k.fill_rect(ux, uy, ux + uw, uy + uh, CellState::Unknown);
            let maps = CpsMaps::new(&k, Cell::new(1, 1), 0.25, &params());
            let mut cells: Vec<u32> = picks.into_iter().map(|p| p as u32).collect();
            cells.sort_unstable();
            cells.dedup();
            let got = maps.clearances(&cells);
            let trav = &maps.parent_terrain().trav;
            let cap = params().eq2.clearance_cap as f32;
            for (&c, &v) in cells.iter().zip(&got) {
                let walk = trav.clearance_at(c as usize).min(cap) as f64;
                prop_assert_eq!(v.to_bits(), walk.to_bits(), "cell {}", c);
            }
        }
    }
}
