//! The AND region of section IV-B: where a child robot may stand during a CPS
//! cycle so that the parent measures it from its current position and, after
//! moving, from its target position (paper Fig. 1 and Fig. 6).
//!
//! A cell is in the AND region of a child when it is
//! - in *certain* line of sight from both parent positions: only known-Free cells
//!   let the beam through (DESIGN.md "Visibility"), by the same exact sweep the
//!   scanner uses, so links are symmetric;
//! - within the instrument's range limits from both (paper Table I: 1.3 m minimum;
//!   the maximum defaults to the scanner range);
//! - drivable for the child (its own radius, clear of obstacles and Unknown cells);
//! - reachable from the child's current position over drivable cells.
//!
//! Cost: two visibility sweeps over the range disc, one traversability pass and one
//! travel sweep per child.

use crate::geom::Cell;
use crate::planning::reach::{sweep, DistanceField, UNREACHED};
use crate::planning::Traversability;
use crate::sensing::visible_cells;
use crate::world::{CellState, OccupancyGrid};

/// The instrument's range limits (paper Table I), in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkRange {
    /// Shortest measurable distance (Table I: 1.3 m).
    pub min: f64,
    /// Longest usable distance.
    pub max: f64,
}

/// Cells in certain line of sight from `from` within `range` (metres, centre to
/// centre), as a mask. Only known-Free cells let the beam through; only known-Free
/// cells are reported.
pub fn certain_view(knowledge: &OccupancyGrid, from: Cell, range: LinkRange) -> Vec<bool> {
    let g = knowledge.geometry();
    let k = knowledge.cells();
    let mut mask = vec![false; g.len()];
    let res = g.resolution;
    let min2 = (range.min / res).powi(2);
    let w = g.width;
    visible_cells(
        g,
        from,
        range.max / res,
        |i| k[i] != CellState::Free,
        |i| {
            if k[i] == CellState::Free {
                let (dx, dy) = (
                    (i % w) as f64 - from.x as f64,
                    (i / w) as f64 - from.y as f64,
                );
                if dx * dx + dy * dy >= min2 - 1e-9 {
                    mask[i] = true;
                }
            }
            false
        },
    );
    mask
}

/// Cells in certain line of sight from both parent positions within range.
pub fn mutual_view(
    knowledge: &OccupancyGrid,
    parent_from: Cell,
    parent_to: Cell,
    range: LinkRange,
) -> Vec<bool> {
    let a = certain_view(knowledge, parent_from, range);
    let mut b = certain_view(knowledge, parent_to, range);
    for (x, y) in b.iter_mut().zip(a) {
        *x &= y;
    }
    b
}

/// One child's AND region.
#[derive(Debug, Clone)]
pub struct AndRegion {
    /// Per cell: the child may stand here for the cycle.
    pub cells: Vec<bool>,
    /// Number of cells in the region.
    pub size: usize,
}

/// Where a child can drive: its drivable cells and travel distances from where it
/// stands. Independent of the parent, so computed once per child position.
#[derive(Debug, Clone)]
pub struct ChildReach {
    /// Drivable cells of the child.
    pub trav: Traversability,
    /// Travel distances of the child from its current position.
    pub travel: DistanceField,
}

impl ChildReach {
    /// The reach of a child of `radius` metres at `child`.
    pub fn new(knowledge: &OccupancyGrid, child: Cell, radius: f64) -> Self {
        let g = knowledge.geometry();
        let trav = Traversability::new(knowledge, radius, child);
        let travel = sweep(g, &trav.passable, &[g.index(child)], UNREACHED);
        Self { trav, travel }
    }
}

/// The AND region of a child with reach `reach`, given the cells that both parent
/// positions see (`mutual`, from [`mutual_view`]).
pub fn and_region(mutual: &[bool], reach: &ChildReach) -> AndRegion {
    let cells: Vec<bool> = mutual
        .iter()
        .enumerate()
        .map(|(i, &m)| m && reach.trav.traversable[i] && reach.travel.reached(i))
        .collect();
    let size = cells.iter().filter(|&&c| c).count();
    AndRegion { cells, size }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::cps_cycle::tests::l_corridor;

    const RANGE: LinkRange = LinkRange {
        min: 1.3,
        max: 20.0,
    };

    #[test]
    fn certain_view_respects_unknown_and_range() {
        let mut k = l_corridor();
        let from = Cell::new(10, 15);
        let v = certain_view(&k, from, RANGE);
        let g = *k.geometry();
        assert!(
            !v[g.index(Cell::new(12, 15))],
            "closer than the minimum range"
        );
        assert!(v[g.index(Cell::new(40, 15))]);
        assert!(!v[g.index(Cell::new(105, 80))], "around the corner");
        // An Unknown band across the corridor blocks certain sight.
        k.fill_rect(50, 5, 52, 25, CellState::Unknown);
        let v = certain_view(&k, from, RANGE);
        assert!(!v[g.index(Cell::new(60, 15))]);
        assert!(v[g.index(Cell::new(40, 15))]);
    }

    #[test]
    fn and_region_lies_at_the_corner_and_is_mutually_visible() {
        let k = l_corridor();
        let g = *k.geometry();
        let from = Cell::new(20, 15);
        let to = Cell::new(105, 100);
        let mutual = mutual_view(&k, from, to, RANGE);
        let region = and_region(&mutual, &ChildReach::new(&k, Cell::new(30, 15), 0.25));
        assert!(region.size > 0);
        for i in (0..g.len()).filter(|&i| region.cells[i]) {
            let c = g.cell(i);
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
        let mutual = mutual_view(&k, Cell::new(105, 15), Cell::new(105, 100), RANGE);
        let blocked = and_region(&mutual, &ChildReach::new(&k, Cell::new(30, 15), 0.25));
        assert_eq!(blocked.size, 0);
        let open = and_region(&mutual, &ChildReach::new(&k, Cell::new(100, 40), 0.25));
        assert!(open.size > 0);
    }
}
