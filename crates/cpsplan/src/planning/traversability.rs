//! Where a robot may stand and drive on the knowledge map.
//!
//! A cell is *traversable* when it is known Free and its clearance from every known
//! obstacle, every Unknown cell and the grid's edge is at least the robot radius.
//! Keeping clear of Unknown cells too means a later scan can never reveal a wall
//! inside the robot's footprint, so a robot is never sealed in where it stands.
//! A robot that starts in a tighter spot may still leave through its *escape
//! region*: the known-Free cells connected to it within one robot radius plus two
//! cells.
//!
//! Clearance is measured from a cell's centre to the nearest obstacle cell's centre
//! minus half a cell (the exact gap for axis-aligned neighbours).

use super::distance::transform;
use crate::geom::Cell;
use crate::world::{CellState, OccupancyGrid};

/// Clearances and drivable cells of one knowledge map.
#[derive(Debug, Clone)]
pub struct Traversability {
    /// Per cell: metres to the nearest known Occupied cell (the `1/P` of Eq. 1),
    /// `f32::INFINITY` if none is known.
    pub clearance: Vec<f32>,
    /// Per cell: metres to the nearest known Occupied or Unknown cell or the edge.
    pub safe_clearance: Vec<f32>,
    /// Per cell: a robot of the given radius may stand here.
    pub traversable: Vec<bool>,
    /// Per cell: traversable, or in the escape region of the robot.
    pub passable: Vec<bool>,
}

impl Traversability {
    /// Computes clearances for `knowledge` and the drivable cells of a robot of
    /// `radius` metres standing at `robot`.
    pub fn new(knowledge: &OccupancyGrid, radius: f64, robot: Cell) -> Self {
        let g = *knowledge.geometry();
        let res = g.resolution;
        let k = knowledge.cells();
        let (w, h) = (g.width, g.height);
        let n = g.len();
        let to_metres = |d: f32| ((d - 0.5).max(0.0) as f64 * res) as f32;
        let mut clearance = vec![f32::INFINITY; n];
        let mut safe_clearance = vec![0.0f32; n];
        // Everything outside the bounding box of known cells is Unknown: only the
        // box needs transforming (plus a one-cell ring of Unknown for the safe one).
        if let Some((x0, y0, x1, y1)) = known_bounds(knowledge) {
            let (bw, bh) = (x1 - x0 + 1, y1 - y0 + 1);
            let d = transform(bw, bh, |x, y| {
                k[(y0 + y) * w + x0 + x] == CellState::Occupied
            });
            for y in 0..bh {
                for x in 0..bw {
                    clearance[(y0 + y) * w + x0 + x] = to_metres(d[y * bw + x]);
                }
            }
            let (sx0, sy0) = (x0.saturating_sub(1), y0.saturating_sub(1));
            let (sx1, sy1) = ((x1 + 1).min(w - 1), (y1 + 1).min(h - 1));
            let (sw, sh) = (sx1 - sx0 + 1, sy1 - sy0 + 1);
            let d = transform(sw, sh, |x, y| k[(sy0 + y) * w + sx0 + x] != CellState::Free);
            for y in 0..sh {
                for x in 0..sw {
                    let (gx, gy) = (sx0 + x, sy0 + y);
                    let edge = (gx.min(gy).min(w - 1 - gx).min(h - 1 - gy) + 1) as f32;
                    safe_clearance[gy * w + gx] = to_metres(d[y * sw + x].min(edge));
                }
            }
        }
        let need = radius as f32 - 1e-6;
        let traversable: Vec<bool> = safe_clearance
            .iter()
            .zip(k)
            .map(|(&c, &s)| s == CellState::Free && c >= need)
            .collect();
        let mut passable = traversable.clone();
        mark_escape_region(knowledge, robot, radius, &mut passable);
        Self {
            clearance,
            safe_clearance,
            traversable,
            passable,
        }
    }
}

/// Inclusive bounds `(x0, y0, x1, y1)` of the cells that are not Unknown.
fn known_bounds(knowledge: &OccupancyGrid) -> Option<(usize, usize, usize, usize)> {
    let w = knowledge.width();
    let mut b: Option<(usize, usize, usize, usize)> = None;
    for (y, row) in knowledge.cells().chunks(w).enumerate() {
        let Some(first) = row.iter().position(|&c| c != CellState::Unknown) else {
            continue;
        };
        let last = row
            .iter()
            .rposition(|&c| c != CellState::Unknown)
            .unwrap_or(first);
        b = Some(match b {
            None => (first, y, last, y),
            Some((x0, y0, x1, _)) => (x0.min(first), y0, x1.max(last), y),
        });
    }
    b
}

/// Marks the known-Free cells connected to `robot` within `radius` plus two cells.
fn mark_escape_region(knowledge: &OccupancyGrid, robot: Cell, radius: f64, passable: &mut [bool]) {
    let g = knowledge.geometry();
    let reach = radius / g.resolution + 2.0;
    let reach2 = reach * reach;
    let start = g.index(robot);
    passable[start] = true;
    if knowledge.get(robot) != CellState::Free {
        return;
    }
    let mut stack = vec![robot];
    let mut seen = std::collections::HashSet::new();
    seen.insert(start);
    while let Some(c) = stack.pop() {
        for (dx, dy) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
            let Some(n) = g.checked_cell(c.x as i64 + dx, c.y as i64 + dy) else {
                continue;
            };
            let (ex, ey) = (n.x as f64 - robot.x as f64, n.y as f64 - robot.y as f64);
            let j = g.index(n);
            if ex * ex + ey * ey > reach2 || knowledge.get(n) != CellState::Free || !seen.insert(j)
            {
                continue;
            }
            passable[j] = true;
            stack.push(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::world::GridGeometry;

    #[test]
    fn clearance_from_unknown_and_edges() {
        let g = GridGeometry::new(20, 11, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Free);
        k.fill_rect(15, 0, 20, 11, CellState::Unknown);
        let t = Traversability::new(&k, 0.25, Cell::new(5, 5));
        // Column 11 is 4 cells from Unknown column 15: 0.35 m; column 12: 0.25 m; 13: 0.15 m.
        assert!(t.traversable[g.index(Cell::new(12, 5))]);
        assert!(!t.traversable[g.index(Cell::new(13, 5))]);
        // Rows near the grid edge are not traversable.
        assert!(!t.traversable[g.index(Cell::new(5, 1))]);
        assert!(t.traversable[g.index(Cell::new(5, 2))]);
        // No known obstacle: clearance is infinite.
        assert!(t.clearance[0].is_infinite());
    }

    #[test]
    fn robot_in_a_pinch_can_escape() {
        let g = GridGeometry::new(30, 30, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Free);
        k.fill_rect(0, 14, 14, 15, CellState::Occupied);
        let robot = Cell::new(5, 15);
        let t = Traversability::new(&k, 0.25, robot);
        assert!(!t.traversable[g.index(robot)]);
        assert!(t.passable[g.index(robot)]);
        assert!(t.passable[g.index(Cell::new(5, 18))]);
        assert!(!t.passable[g.index(Cell::new(5, 13))]);
    }
}
