//! Coverage measures of a simulated episode.
//!
//! - `coverage`: known-Free cells among the ground-truth free cells 4-connected to
//!   the start, over the latter.
//! - `wall_coverage`: seen cells among the ground-truth occupied cells 8-adjacent to
//!   that free region, over the latter.
//!
//! The denominator counts every free cell a point-sized robot could reach, so free
//! space behind gaps narrower than the robot counts as missed.

use crate::geom::Cell;
use crate::world::{CellState, OccupancyGrid};

/// Tracks coverage incrementally as scans reveal cells.
#[derive(Debug, Clone)]
pub struct CoverageTracker {
    /// Per cell: 1 if a reachable free cell, 2 if a wall bordering them, else 0.
    role: Vec<u8>,
    free_total: usize,
    wall_total: usize,
    free_seen: usize,
    wall_seen: usize,
}

const FREE: u8 = 1;
const WALL: u8 = 2;

impl CoverageTracker {
    /// Sets up the measure for `truth` and a robot starting at `start`, counting the
    /// cells `knowledge` already knows.
    pub fn new(truth: &OccupancyGrid, start: Cell, knowledge: &OccupancyGrid) -> Self {
        let g = truth.geometry();
        let (w, h) = (g.width as i64, g.height as i64);
        let t = truth.cells();
        let mut role = vec![0u8; g.len()];
        let s = g.index(start);
        if t[s] == CellState::Free {
            role[s] = FREE;
            let mut stack = vec![s];
            while let Some(i) = stack.pop() {
                let (x, y) = ((i as i64) % w, (i as i64) / w);
                for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w || ny >= h {
                        continue;
                    }
                    let j = (ny * w + nx) as usize;
                    if role[j] == 0 && t[j] == CellState::Free {
                        role[j] = FREE;
                        stack.push(j);
                    }
                }
            }
        }
        for i in 0..g.len() {
            if role[i] != FREE {
                continue;
            }
            let (x, y) = ((i as i64) % w, (i as i64) / w);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w || ny >= h {
                        continue;
                    }
                    let j = (ny * w + nx) as usize;
                    if t[j] != CellState::Free && role[j] == 0 {
                        role[j] = WALL;
                    }
                }
            }
        }
        let mut me = Self {
            free_total: role.iter().filter(|&&r| r == FREE).count(),
            wall_total: role.iter().filter(|&&r| r == WALL).count(),
            role,
            free_seen: 0,
            wall_seen: 0,
        };
        for (i, &k) in knowledge.cells().iter().enumerate() {
            if k != CellState::Unknown {
                me.note_seen(i);
            }
        }
        me
    }

    /// Records that cell `index` has just become known.
    #[inline]
    pub fn note_seen(&mut self, index: usize) {
        match self.role[index] {
            FREE => self.free_seen += 1,
            WALL => self.wall_seen += 1,
            _ => {}
        }
    }

    /// Share of reachable free cells known so far.
    pub fn coverage(&self) -> f64 {
        ratio(self.free_seen, self.free_total)
    }

    /// Share of walls bordering the reachable free space seen so far.
    pub fn wall_coverage(&self) -> f64 {
        ratio(self.wall_seen, self.wall_total)
    }

    /// Number of reachable free cells (the coverage denominator).
    pub fn free_total(&self) -> usize {
        self.free_total
    }

    /// Whether cell `index` counts in the coverage denominator.
    pub fn is_reachable_free(&self, index: usize) -> bool {
        self.role[index] == FREE
    }

    /// Whether cell `index` counts in the wall-coverage denominator.
    pub fn is_bordering_wall(&self, index: usize) -> bool {
        self.role[index] == WALL
    }
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        1.0
    } else {
        a as f64 / b as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::world::GridGeometry;

    #[test]
    fn counts_only_the_starts_region() {
        let g = GridGeometry::new(10, 5, 0.1, Point::default());
        let mut t = OccupancyGrid::filled(g, CellState::Occupied);
        t.fill_rect(1, 1, 4, 4, CellState::Free); // 9 cells, reachable
        t.fill_rect(6, 1, 9, 4, CellState::Free); // 9 cells, sealed off
        let k = OccupancyGrid::filled(g, CellState::Unknown);
        let mut c = CoverageTracker::new(&t, Cell::new(2, 2), &k);
        assert_eq!(c.free_total(), 9);
        assert_eq!(c.coverage(), 0.0);
        // Walls: 5×5 ring around the 3×3 room = 16 cells.
        assert_eq!(c.wall_total, 16);
        for y in 1..4 {
            for x in 1..4 {
                c.note_seen(g.index(Cell::new(x, y)));
            }
        }
        c.note_seen(g.index(Cell::new(7, 2)));
        assert_eq!(c.coverage(), 1.0);
        assert_eq!(c.wall_coverage(), 0.0);
    }
}
