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
//! Cost: two visibility sweeps over the range disc and a few linear passes; the
//! children's reach comes from the connected regions of their [`Terrain`], shared
//! by all children of one size.

use std::sync::Arc;

use crate::geom::Cell;
use crate::planning::terrain::{Terrain, NO_REGION};
use crate::sensing::visible_cells;
use crate::world::{CellState, GridGeometry, OccupancyGrid};

/// The instrument's range limits (paper Table I), in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkRange {
    /// Shortest measurable distance (Table I: 1.3 m).
    pub min: f64,
    /// Longest usable distance.
    pub max: f64,
}

/// The cells in certain line of sight from one position within range, as a mask
/// over the rows and columns of the range disc's bounding box (clipped to the
/// grid). Only known-Free cells let the beam through; only known-Free cells are
/// seen.
#[derive(Debug, Clone)]
pub struct View {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
    /// The grid's width: the mask keeps the grid's row stride (rows `y0..=y1`),
    /// so a visited cell's flag is found without a division.
    stride: usize,
    mask: Vec<bool>,
}

impl View {
    /// The view from `from` within `range` (metres, centre to centre).
    pub fn new(knowledge: &OccupancyGrid, from: Cell, range: LinkRange) -> Self {
        let g = knowledge.geometry();
        let k = knowledge.cells();
        let res = g.resolution;
        // The disc's radius in whole cells, as the sweep rounds it.
        let r = (range.max / res).max(0.0);
        let reach = ((r * r + 1e-9).floor().sqrt().floor()) as usize;
        let (x0, y0) = (from.x.saturating_sub(reach), from.y.saturating_sub(reach));
        let x1 = (from.x + reach).min(g.width.saturating_sub(1));
        let y1 = (from.y + reach).min(g.height.saturating_sub(1));
        let stride = g.width;
        let row0 = y0 * stride;
        let mut mask = vec![false; (y1 + 1 - y0) * stride];
        // Every visited cell lies in the disc, so in the box.
        visible_cells(
            g,
            from,
            range.max / res,
            |i| k[i] != CellState::Free,
            |i| {
                mask[i - row0] = k[i] == CellState::Free;
                false
            },
        );
        // Closer than the minimum range: not measurable.
        let min = range.min / res;
        let near = min.ceil() as usize;
        for y in from.y.saturating_sub(near).max(y0)..=(from.y + near).min(y1) {
            for x in from.x.saturating_sub(near).max(x0)..=(from.x + near).min(x1) {
                let (dx, dy) = (x as f64 - from.x as f64, y as f64 - from.y as f64);
                if dx * dx + dy * dy < min * min - 1e-9 {
                    mask[(y - y0) * stride + x] = false;
                }
            }
        }
        Self {
            x0,
            y0,
            x1,
            y1,
            stride,
            mask,
        }
    }

    /// Whether `cell` is seen.
    #[inline]
    pub fn sees(&self, cell: Cell) -> bool {
        cell.x >= self.x0
            && cell.y >= self.y0
            && cell.x <= self.x1
            && cell.y <= self.y1
            && self.mask[(cell.y - self.y0) * self.stride + cell.x]
    }

    /// The grid indices of the cells seen, ascending.
    pub fn cells(&self) -> impl Iterator<Item = usize> + '_ {
        let start = self.y0 * self.stride;
        self.mask
            .iter()
            .enumerate()
            .filter(|&(_, &seen)| seen)
            .map(move |(i, _)| start + i)
    }

    /// The view as a mask over all cells of a grid of `geometry`.
    pub fn to_mask(&self, geometry: &GridGeometry) -> Vec<bool> {
        let mut out = vec![false; geometry.len()];
        let start = self.y0 * geometry.width;
        out[start..start + self.mask.len()].copy_from_slice(&self.mask);
        out
    }
}

/// Cells in certain line of sight from `from` within `range` (metres, centre to
/// centre), as a mask over the grid. Only known-Free cells let the beam through;
/// only known-Free cells are reported.
pub fn certain_view(knowledge: &OccupancyGrid, from: Cell, range: LinkRange) -> Vec<bool> {
    View::new(knowledge, from, range).to_mask(knowledge.geometry())
}

/// The cells both views see, as ascending grid indices.
pub fn seen_by_both(geometry: &GridGeometry, a: &View, b: &View) -> Vec<u32> {
    let w = geometry.width;
    let (x0, y0) = (a.x0.max(b.x0), a.y0.max(b.y0));
    let (x1, y1) = (a.x1.min(b.x1), a.y1.min(b.y1));
    let mut out = Vec::new();
    if x0 > x1 || y0 > y1 {
        return out;
    }
    for y in y0..=y1 {
        let ra = &a.mask[(y - a.y0) * a.stride..][x0..=x1];
        let rb = &b.mask[(y - b.y0) * b.stride..][x0..=x1];
        for (dx, (&p, &q)) in ra.iter().zip(rb).enumerate() {
            if p && q {
                out.push((y * w + x0 + dx) as u32);
            }
        }
    }
    out
}

/// Cells in certain line of sight from both parent positions within range, as
/// ascending grid indices.
pub fn mutual_view(
    knowledge: &OccupancyGrid,
    parent_from: Cell,
    parent_to: Cell,
    range: LinkRange,
) -> Vec<u32> {
    let a = View::new(knowledge, parent_from, range);
    let b = View::new(knowledge, parent_to, range);
    seen_by_both(knowledge.geometry(), &a, &b)
}

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
        let region = terrain.region[knowledge.geometry().index(child)];
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
            && self.terrain.region[index] == self.region
    }
}

/// The AND region of a child with reach `reach`, given the cells that both parent
/// positions see (`mutual`, ascending indices from [`mutual_view`]).
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
    use crate::planning::cps_cycle::tests::l_corridor;

    const RANGE: LinkRange = LinkRange {
        min: 1.3,
        max: 20.0,
    };

    proptest::proptest! {
        /// The windowed view agrees with a plain whole-grid mask of the visible,
        /// known-Free cells between the range limits.
        #[test]
        fn view_matches_the_plain_rule(
            w in 3usize..60,
            h in 3usize..60,
            cells in proptest::collection::vec(0u8..5, 3600),
            ox in 0usize..60,
            oy in 0usize..60,
            min in 0.0f64..1.5,
            max in 0.5f64..4.0,
        ) {
            let g = GridGeometry::new(w, h, 0.1, crate::Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Free);
            for (i, &v) in cells.iter().enumerate().take(g.len()) {
                let c = g.cell(i);
                match v {
                    0 => k.fill_rect(c.x, c.y, c.x + 1, c.y + 1, CellState::Occupied),
                    1 => k.fill_rect(c.x, c.y, c.x + 1, c.y + 1, CellState::Unknown),
                    _ => {}
                }
            }
            let from = Cell::new(ox % w, oy % h);
            let range = LinkRange { min, max };
            let mut plain = vec![false; g.len()];
            let kc = k.cells();
            visible_cells(&g, from, max / 0.1, |i| kc[i] != CellState::Free, |i| {
                let (dx, dy) = ((i % w) as f64 - from.x as f64, (i / w) as f64 - from.y as f64);
                plain[i] = kc[i] == CellState::Free && dx * dx + dy * dy >= (min / 0.1).powi(2) - 1e-9;
                false
            });
            let view = View::new(&k, from, range);
            proptest::prop_assert_eq!(view.to_mask(&g), plain.clone());
            for (i, &p) in plain.iter().enumerate() {
                proptest::prop_assert_eq!(view.sees(g.cell(i)), p);
            }
        }
    }

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
        let mutual = mutual_view(&k, Cell::new(105, 15), Cell::new(105, 100), RANGE);
        let blocked = and_region(&mutual, &ChildReach::new(&k, Cell::new(30, 15), 0.25));
        assert_eq!(blocked.size(), 0);
        let open = and_region(&mutual, &ChildReach::new(&k, Cell::new(100, 40), 0.25));
        assert!(open.size() > 0);
    }
}
