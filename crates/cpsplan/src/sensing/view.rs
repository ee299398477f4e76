//! Certain lines of sight for CPS links (DESIGN.md "Visibility"; paper section
//! IV-B): which cells a robot at one cell can measure, or be measured from, with
//! the instrument.
//!
//! In: the knowledge map, a position and the instrument's range limits. Out: the
//! [`View`] from it (only known-Free cells let the beam through and only
//! known-Free cells are seen, by the scanner's exact sweep, so links are
//! symmetric), and the cells two positions both see ([`mutual_view`]), from which
//! the AND region of section IV-B is cut.

use crate::geom::Cell;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};
use crate::sensing::visible_cells;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::fixtures::l_corridor;

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
}
