//! Lines of sight for CPS links with full cell squares (DESIGN.md "Visibility",
//! *certain*): the straight segment between two cell centres is clear when it
//! keeps more than a clearance from every cell that is not known-Free, each cell
//! taken as its whole closed square (a segment touching a wall cell's corner is
//! blocked).
//!
//! In: the knowledge map, two cells, a clearance in cells. Out: whether the link
//! is clear ([`sight_clear`]), or for many links from one cell, the same answer
//! sped up by a distance field ([`SightField`]).
//!
//! # Method
//!
//! With no clearance the rule is exactly the segment's supercover
//! ([`crate::grid::line::segment_clear`]): every cell whose closed square the
//! segment touches, all four at a lattice corner it passes through. With a
//! clearance `c`, a non-Free square is in the way when its distance to the
//! segment is at most `c`; squares near the segment are tested one by one (exact
//! integer test for touching, distance in `f64` beyond). [`SightField`] skips the
//! open stretches of a segment by sphere tracing on the exact distance transform
//! of the non-Free cells: from a point `q` in cell `X` no non-Free square is
//! nearer than `D(X) − |q − centre(X)| − √2/2`, where `D(X)` is the distance from
//! `X`'s centre to the nearest non-Free cell centre, so the segment may advance by
//! that much less the clearance; where the bound gives no room, the squares within
//! a few cells are tested and the segment advances by the stretch they certify.

use crate::geom::Cell;
use crate::grid::distance::transform;
use crate::grid::line::segment_clear;
use crate::grid::{CellState, OccupancyGrid};

/// Which parent–child links the instrument can measure: its range limits (paper
/// Table I) and the clearance a line of sight keeps from every cell that is not
/// known-Free, all in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkRule {
    /// Shortest measurable distance (Table I: 1.3 m).
    pub min: f64,
    /// Longest usable distance.
    pub max: f64,
    /// Least distance between a line of sight and any non-Free cell's square
    /// (0: the line may pass a wall as close as it likes without touching it).
    pub clearance: f64,
}

/// Whether the segment between the centres of `a` and `b` keeps more than
/// `clearance` cells from every cell of `knowledge` that is not known-Free (and
/// from the outside of the grid), cells taken as closed squares: touching counts
/// as blocked.
pub fn sight_clear(knowledge: &OccupancyGrid, a: Cell, b: Cell, clearance: f64) -> bool {
    let g = knowledge.geometry();
    let k = knowledge.cells();
    if !segment_clear(g, a, b, |i| k[i] == CellState::Free) {
        return false;
    }
    if clearance <= 0.0 {
        return true;
    }
    // Every non-Free square within `clearance` of the segment has its cell within
    // `reach` cells (Chebyshev) of a cell of the supercover.
    let reach = clearance.ceil() as i64 + 1;
    let seg = Segment::between(a, b);
    segment_clear(g, a, b, |i| {
        let c = g.cell(i);
        squares_clear(knowledge, &seg, c.x as i64, c.y as i64, reach, clearance)
    })
}

/// Whether an instrument at the centre of `from` measures a target standing at
/// `target`: the distance between them within `rule`'s range, and the line of
/// sight between `from` and the target's cell clear under `rule` on `knowledge`
/// (cells as full squares; the target's own cell does not block, since a target
/// may stand on a pillar or a wall).
pub fn target_in_sight(
    knowledge: &OccupancyGrid,
    from: Cell,
    target: crate::geom::Point,
    rule: &LinkRule,
) -> bool {
    let g = knowledge.geometry();
    let d = g.cell_center(from).distance(target);
    if !(d >= rule.min && d <= rule.max) {
        return false;
    }
    let Some(cell) = g.world_to_cell(target) else {
        return false;
    };
    if cell == from {
        return false;
    }
    let k = knowledge.cells();
    let own = g.index(cell);
    if k[own] == CellState::Free {
        return sight_clear(knowledge, from, cell, rule.clearance / g.resolution);
    }
    segment_clear(g, from, cell, |i| i == own || k[i] == CellState::Free)
}

/// A segment between two cell centres, in doubled cell coordinates (centres at
/// odd integers, cell corners at even ones) so that every test is exact.
#[derive(Debug, Clone, Copy)]
struct Segment {
    ax: i64,
    ay: i64,
    bx: i64,
    by: i64,
}

impl Segment {
    fn between(a: Cell, b: Cell) -> Self {
        Self {
            ax: 2 * a.x as i64 + 1,
            ay: 2 * a.y as i64 + 1,
            bx: 2 * b.x as i64 + 1,
            by: 2 * b.y as i64 + 1,
        }
    }

    /// Whether the closed segment meets the closed square of cell (`x`, `y`).
    fn touches(&self, x: i64, y: i64) -> bool {
        let (x0, y0, x1, y1) = (2 * x, 2 * y, 2 * x + 2, 2 * y + 2);
        if self.ax.max(self.bx) < x0
            || self.ax.min(self.bx) > x1
            || self.ay.max(self.by) < y0
            || self.ay.min(self.by) > y1
        {
            return false;
        }
        let (dx, dy) = (self.bx - self.ax, self.by - self.ay);
        let side = |px: i64, py: i64| (dx * (py - self.ay) - dy * (px - self.ax)).signum();
        let s = [side(x0, y0), side(x1, y0), side(x0, y1), side(x1, y1)];
        !(s.iter().all(|&v| v > 0) || s.iter().all(|&v| v < 0))
    }

    /// Distance in cells between the segment and the square of cell (`x`, `y`).
    fn distance_to_square(&self, x: i64, y: i64) -> f64 {
        if self.touches(x, y) {
            return 0.0;
        }
        let (ax, ay) = (self.ax as f64 / 2.0, self.ay as f64 / 2.0);
        let (bx, by) = (self.bx as f64 / 2.0, self.by as f64 / 2.0);
        let (x0, y0) = (x as f64, y as f64);
        let (x1, y1) = (x0 + 1.0, y0 + 1.0);
        // Disjoint convex sets: the distance is attained at an end of the segment
        // or at a corner of the square.
        let point_box = |px: f64, py: f64| {
            let dx = (x0 - px).max(0.0).max(px - x1);
            let dy = (y0 - py).max(0.0).max(py - y1);
            (dx * dx + dy * dy).sqrt()
        };
        let (sx, sy) = (bx - ax, by - ay);
        let len2 = sx * sx + sy * sy;
        let point_segment = |px: f64, py: f64| {
            let t = if len2 > 0.0 {
                (((px - ax) * sx + (py - ay) * sy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let (ex, ey) = (px - ax - t * sx, py - ay - t * sy);
            (ex * ex + ey * ey).sqrt()
        };
        point_box(ax, ay)
            .min(point_box(bx, by))
            .min(point_segment(x0, y0))
            .min(point_segment(x1, y0))
            .min(point_segment(x0, y1))
            .min(point_segment(x1, y1))
    }
}

/// Whether every non-Free square (or square outside the grid) of the cells within
/// `reach` (Chebyshev) of cell (`x`, `y`) keeps more than `clearance` cells from
/// the segment.
fn squares_clear(
    knowledge: &OccupancyGrid,
    seg: &Segment,
    x: i64,
    y: i64,
    reach: i64,
    clearance: f64,
) -> bool {
    let g = knowledge.geometry();
    let k = knowledge.cells();
    for cy in y - reach..=y + reach {
        for cx in x - reach..=x + reach {
            let blocked = match g.checked_cell(cx, cy) {
                Some(c) => k[g.index(c)] != CellState::Free,
                None => true,
            };
            if blocked && seg.distance_to_square(cx, cy) <= clearance {
                return false;
            }
        }
    }
    true
}

/// Sight tests from one cell to many, within a window of the grid: the distance
/// transform of the window's non-Free cells lets every test skip the open
/// stretches of its segment. The answers are exactly those of [`sight_clear`].
#[derive(Debug, Clone)]
pub struct SightField {
    /// The window: columns `x0..x0 + w`, rows `y0..y0 + h`.
    x0: usize,
    y0: usize,
    w: usize,
    h: usize,
    /// Per window cell: distance in cells from its centre to the nearest non-Free
    /// cell centre (cells outside the window count as non-Free).
    distance: Vec<f32>,
    clearance: f64,
}

impl SightField {
    /// The field for segments that stay within `reach` cells of the box of cells
    /// `x0..=x1`, `y0..=y1` (clipped to the grid), for a clearance of `clearance`
    /// cells.
    pub fn new(
        knowledge: &OccupancyGrid,
        (x0, y0, x1, y1): (usize, usize, usize, usize),
        reach: f64,
        clearance: f64,
    ) -> Self {
        let g = knowledge.geometry();
        // A margin wide enough that the local tests near the segment never need a
        // distance from outside the window.
        let reach = if reach.is_finite() {
            reach.max(0.0).ceil().min(g.width.max(g.height) as f64) as usize
        } else {
            g.width.max(g.height)
        };
        let margin = reach.saturating_add(clearance.max(0.0).ceil() as usize + 3);
        let x0 = x0.saturating_sub(margin);
        let y0 = y0.saturating_sub(margin);
        let x1 = x1.saturating_add(margin).min(g.width.saturating_sub(1));
        let y1 = y1.saturating_add(margin).min(g.height.saturating_sub(1));
        let (w, h) = (x1 + 1 - x0, y1 + 1 - y0);
        let k = knowledge.cells();
        // The window plus a ring of non-Free cells around it.
        let distance_ring = transform(w + 2, h + 2, |x, y| {
            x == 0 || y == 0 || x == w + 1 || y == h + 1 || {
                k[(y0 + y - 1) * g.width + x0 + x - 1] != CellState::Free
            }
        });
        let mut distance = Vec::with_capacity(w * h);
        for y in 0..h {
            distance.extend_from_slice(&distance_ring[(y + 1) * (w + 2) + 1..][..w]);
        }
        Self {
            x0,
            y0,
            w,
            h,
            distance,
            clearance: clearance.max(0.0),
        }
    }

    /// The field for every link from `from` by `rule`.
    pub fn around(knowledge: &OccupancyGrid, from: Cell, rule: LinkRule) -> Self {
        let res = knowledge.resolution();
        Self::new(
            knowledge,
            (from.x, from.y, from.x, from.y),
            rule.max / res,
            rule.clearance / res,
        )
    }

    /// The field for every link between two known-Free cells of `knowledge` by
    /// `rule`: the window of the known cells (a line between Free cells never
    /// leaves it).
    pub fn of_known(knowledge: &OccupancyGrid, rule: LinkRule) -> Self {
        let g = knowledge.geometry();
        let b = knowledge.bounds_of(|c| c == CellState::Free);
        Self::new(
            knowledge,
            b.unwrap_or((0, 0, 0, 0)),
            0.0,
            rule.clearance / g.resolution,
        )
    }

    /// The clearance, cells, this field tests for.
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// [`sight_clear`] from `a` to `b` (both inside the window).
    pub fn clear(&self, knowledge: &OccupancyGrid, a: Cell, b: Cell) -> bool {
        let seg = Segment::between(a, b);
        let (ax, ay) = (a.x as f64 + 0.5, a.y as f64 + 0.5);
        let (dx, dy) = (b.x as f64 - a.x as f64, b.y as f64 - a.y as f64);
        let len = (dx * dx + dy * dy).sqrt();
        let c = self.clearance;
        let reach = c.ceil() as i64 + 2;
        // The stretch a local test certifies: a square it did not test is at
        // least `reach` cells from the point tested.
        let certified = reach as f64 - c - 0.5;
        let mut t = 0.0f64;
        loop {
            let f = if len > 0.0 { (t / len).min(1.0) } else { 0.0 };
            let (qx, qy) = (ax + f * dx, ay + f * dy);
            // Points of the segment lie in the grid: truncation is the floor.
            let (cx, cy) = (qx as i64, qy as i64);
            let (wx, wy) = (cx - self.x0 as i64, cy - self.y0 as i64);
            let inside = wx >= 0 && wy >= 0 && (wx as usize) < self.w && (wy as usize) < self.h;
            let room = if inside {
                let d = self.distance[wy as usize * self.w + wx as usize] as f64;
                let (ox, oy) = (qx - cx as f64 - 0.5, qy - cy as f64 - 0.5);
                let off = (ox * ox + oy * oy).sqrt();
                d - off - std::f64::consts::FRAC_1_SQRT_2 - c - 1e-6 * (1.0 + d)
            } else {
                0.0
            };
            // Steps shorter than half a cell (a segment grazing a wall) would shrink
            // without end: a local test certifies more.
            let step = if room > 0.5 {
                room
            } else {
                if !squares_clear(knowledge, &seg, cx, cy, reach, c) {
                    return false;
                }
                certified
            };
            if t >= len {
                return true;
            }
            t = (t + step).min(len);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;
    use proptest::prelude::*;

    fn open(w: usize, h: usize) -> OccupancyGrid {
        OccupancyGrid::filled(
            GridGeometry::new(w, h, 0.1, Point::default()),
            CellState::Free,
        )
    }

    /// Distance between the segment and a square by dense sampling of both.
    fn sampled_distance(a: Cell, b: Cell, x: i64, y: i64) -> f64 {
        let (ax, ay) = (a.x as f64 + 0.5, a.y as f64 + 0.5);
        let (bx, by) = (b.x as f64 + 0.5, b.y as f64 + 0.5);
        let mut best = f64::INFINITY;
        for i in 0..=400 {
            let t = i as f64 / 400.0;
            let (px, py) = (ax + t * (bx - ax), ay + t * (by - ay));
            let dx = (x as f64 - px).max(0.0).max(px - x as f64 - 1.0);
            let dy = (y as f64 - py).max(0.0).max(py - y as f64 - 1.0);
            best = best.min(dx.hypot(dy));
        }
        best
    }

    #[test]
    fn a_line_through_a_wall_corner_is_blocked() {
        let mut k = open(10, 10);
        // The diagonal from (1, 1) to (5, 5) passes through the corner (3, 3)
        // shared with cell (3, 2).
        k.set(Cell::new(3, 2), CellState::Occupied);
        assert!(!sight_clear(&k, Cell::new(1, 1), Cell::new(5, 5), 0.0));
        // One row up, the line misses the cell by half a cell.
        assert!(sight_clear(&k, Cell::new(1, 2), Cell::new(5, 6), 0.0));
        assert!(!sight_clear(&k, Cell::new(1, 2), Cell::new(5, 6), 1.0));
        assert!(sight_clear(&k, Cell::new(1, 2), Cell::new(5, 6), 0.3));
    }

    #[test]
    fn unknown_cells_and_the_grid_edge_block() {
        let mut k = open(10, 4);
        k.set(Cell::new(5, 2), CellState::Unknown);
        assert!(!sight_clear(&k, Cell::new(1, 2), Cell::new(8, 2), 0.0));
        assert!(sight_clear(&k, Cell::new(1, 0), Cell::new(8, 0), 0.0));
        assert!(sight_clear(&k, Cell::new(1, 0), Cell::new(8, 0), 0.49));
        assert!(!sight_clear(&k, Cell::new(1, 0), Cell::new(8, 0), 0.5));
    }

    proptest! {
        /// The exact segment–square distance agrees with dense sampling.
        #[test]
        fn square_distance_matches_sampling(
            a in (0usize..12, 0usize..12),
            b in (0usize..12, 0usize..12),
            s in (-2i64..14, -2i64..14),
        ) {
            let (a, b) = (Cell::new(a.0, a.1), Cell::new(b.0, b.1));
            let seg = Segment::between(a, b);
            let exact = seg.distance_to_square(s.0, s.1);
            let sampled = sampled_distance(a, b, s.0, s.1);
            // Sampling overestimates by at most half a sample step.
            prop_assert!(exact <= sampled + 1e-9, "{} > {}", exact, sampled);
            prop_assert!(sampled - exact <= 0.03, "{} vs {}", exact, sampled);
            prop_assert_eq!(seg.touches(s.0, s.1), exact == 0.0);
        }

        /// The field's sphere tracing gives exactly the answers of the plain test.
        #[test]
        fn field_agrees_with_the_plain_test(
            w in 4usize..40,
            h in 4usize..40,
            cells in proptest::collection::vec(0u8..12, 1600),
            from in (0usize..40, 0usize..40),
            clearance in proptest::sample::select(vec![0.0, 0.3, 1.0, 2.5]),
        ) {
            let k = crate::grid::fixtures::coded(w, h, &cells);
            let g = *k.geometry();
            let a = Cell::new(from.0 % w, from.1 % h);
            let field = SightField::new(&k, (0, 0, w - 1, h - 1), 0.0, clearance);
            for i in 0..g.len() {
                let b = g.cell(i);
                prop_assert_eq!(field.clear(&k, a, b), sight_clear(&k, a, b, clearance), "{:?} -> {:?}", a, b);
            }
        }
    }
}
