//! The AND region of section IV-B: where a child robot may stand during a CPS
//! cycle so that the parent measures it from its current position and, after
//! moving, from its target position (paper Fig. 1 and Fig. 6).
//!
//! In: the cells both parent positions see ([`crate::sensing::mutual_view`]) and
//! where the child can drive ([`ChildReach`]). Out: the child's [`AndRegion`].
//! A cell is in the AND region of a child when it is
//! - in *certain* line of sight from both parent positions: only known-Free cells
//!   let the beam through (DESIGN.md "Visibility"), by the same exact sweep the
//!   scanner uses, so links are symmetric;
//! - within the instrument's range limits from both (paper Table I: 1.3 m minimum;
//!   the maximum defaults to the scanner range);
//! - drivable for the child (its own radius, clear of obstacles and Unknown cells);
//! - reachable from the child's current position over drivable cells.
//!
//! Cost: two visibility sweeps over the range disc and a few linear passes; the
//! children's reach comes from the connected regions of their [`Terrain`], shared
//! by all children of one size.

use std::sync::Arc;

use crate::geom::Cell;
use crate::grid::{GridGeometry, OccupancyGrid, Terrain, NO_REGION};

/// One child's AND region.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AndRegion {
    /// The cells where the child may stand for the cycle, ascending grid indices.
    pub cells: Vec<u32>,
}

impl AndRegion {
    /// Number of cells in the region.
    pub fn size(&self) -> usize {
        self.cells.len()
    }

    /// Whether cell `index` is in the region.
    pub fn contains(&self, index: usize) -> bool {
        self.cells.binary_search(&(index as u32)).is_ok()
    }

    /// The region as a mask over the `len` cells of the grid.
    pub fn to_mask(&self, len: usize) -> Vec<bool> {
        let mut out = vec![false; len];
        for &i in &self.cells {
            out[i as usize] = true;
        }
        out
    }
}

/// Where a child can drive: its terrain and the connected region it stands in.
/// Independent of the parent, and shared by every child on the same terrain.
#[derive(Debug, Clone)]
pub struct ChildReach {
    /// Drivable cells of the child and their connected regions.
    pub terrain: Arc<Terrain>,
    /// The region the child stands in ([`NO_REGION`] if it stands on no passable
    /// cell, so that it reaches nothing).
    pub region: u32,
}

impl ChildReach {
    /// The reach of a child of `radius` metres at `child`, on a terrain of its own.
    pub fn new(knowledge: &OccupancyGrid, child: Cell, radius: f64) -> Self {
        let terrain = Arc::new(Terrain::new(knowledge, radius, child));
        let region = terrain.region(knowledge.geometry().index(child));
        Self { terrain, region }
    }

    /// The reach of a child at `child` on a shared `terrain`, if the child stands
    /// on one of its passable cells.
    pub fn on(terrain: &Arc<Terrain>, geometry: &GridGeometry, child: Cell) -> Option<Self> {
        let region = terrain.region_of(geometry.index(child))?;
        Some(Self {
            terrain: Arc::clone(terrain),
            region,
        })
    }

    /// Whether the child can stand on cell `index` and drive there.
    #[inline]
    pub fn reaches(&self, index: usize) -> bool {
        self.region != NO_REGION
            && self.terrain.trav.traversable[index]
            && self.terrain.region(index) == self.region
    }
}

/// The AND region of a child with reach `reach`, given the cells that both parent
/// positions see (`mutual`, ascending indices from [`mutual_view`](crate::sensing::mutual_view)).
pub fn and_region(mutual: &[u32], reach: &ChildReach) -> AndRegion {
    AndRegion {
        cells: mutual
            .iter()
            .copied()
            .filter(|&i| reach.reaches(i as usize))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::fixtures::l_corridor;
    use crate::grid::CellState;
    use crate::sensing::{certain_view, mutual_view, LinkRule};

    const RANGE: LinkRule = LinkRule {
        min: 1.3,
        max: 20.0,
        clearance: 0.1,
    };

    #[test]
    fn and_region_lies_at_the_corner_and_is_mutually_visible() {
        let k = l_corridor();
        let g = *k.geometry();
        let from = Cell::new(20, 15);
        let to = Cell::new(105, 100);
        let mutual = mutual_view(&k, from, to, RANGE, |_| true);
        let region = and_region(&mutual, &ChildReach::new(&k, Cell::new(30, 15), 0.25));
        assert!(region.size() > 0);
        for &i in &region.cells {
            let c = g.cell(i as usize);
            // Both parents see the cell: it lies around the corner where the arms
            // meet (grazing lines reach a little past the arms' edges).
            assert!(c.x >= 85 && c.y < 35, "{c:?}");
            assert!(certain_view(&k, c, RANGE)[g.index(from)]);
            assert!(certain_view(&k, c, RANGE)[g.index(to)]);
        }
    }

    #[test]
    fn unreachable_cells_are_not_in_the_region() {
        let mut k = l_corridor();
        // A wall cuts the child off from the corner.
        k.fill_rect(60, 5, 62, 25, CellState::Occupied);
        let mutual = mutual_view(&k, Cell::new(105, 15), Cell::new(105, 100), RANGE, |_| true);
        let blocked = and_region(&mutual, &ChildReach::new(&k, Cell::new(30, 15), 0.25));
        assert_eq!(blocked.size(), 0);
        let open = and_region(&mutual, &ChildReach::new(&k, Cell::new(100, 40), 0.25));
        assert!(open.size() > 0);
    }
}
