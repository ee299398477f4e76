//! Coverage measures of a simulated episode.
//!
//! - `coverage`: known-Free cells among the ground-truth free cells *reachable from
//!   the start* by the robot, over the latter. Reachable means inside the robot's
//!   footprint at some drivable position (a free cell with at least the robot
//!   radius of clearance, connected to the start through such cells): the free
//!   space the robot can get to.
//! - `wall_coverage`: seen cells among the ground-truth occupied cells that share a
//!   face with that reachable free space (its wall surface), over the latter. Cells
//!   that touch it only at a corner are not counted: no beam from inside can hit
//!   them.
//! - `connected_coverage`: the same share over every free cell 4-connected to the
//!   start, including space behind gaps narrower than the robot (doors drawn half
//!   shut, laser streaks of a SLAM map): a stricter figure for comparison.

use crate::geom::Cell;
use crate::grid::distance::transform;
use crate::grid::region::flood4;
use crate::grid::travel::{sweep, DistanceField, UNREACHED};
use crate::grid::Traversability;
use crate::grid::{CellState, OccupancyGrid};

/// Tracks coverage incrementally as scans reveal cells.
#[derive(Debug, Clone)]
pub struct CoverageTracker {
    /// Per cell: a bit set of [`REACHABLE`], [`WALL`], [`CONNECTED`].
    role: Vec<u8>,
    free_total: usize,
    wall_total: usize,
    connected_total: usize,
    free_seen: usize,
    wall_seen: usize,
    connected_seen: usize,
}

const REACHABLE: u8 = 1;
const WALL: u8 = 2;
const CONNECTED: u8 = 4;

impl CoverageTracker {
    /// Sets up the measures for `truth` (anything not Free is solid) and a robot of
    /// `radius` metres starting at `start`, counting the cells `knowledge` already
    /// knows.
    pub fn new(truth: &OccupancyGrid, start: Cell, radius: f64, knowledge: &OccupancyGrid) -> Self {
        let g = truth.geometry();
        let s = g.index(start);
        // Drivable positions connected to the start.
        let field = (truth.cells()[s] == CellState::Free).then(|| {
            let solid = truth.solidified();
            let trav = Traversability::new(&solid, radius, start);
            sweep(g, &trav.passable, &[s], UNREACHED)
        });
        Self::build(truth, start, radius, knowledge, field.as_ref())
    }

    /// [`Self::new`] for a caller that already has the robot's travel `field`
    /// from `start` (over its passable cells on the solidified `truth`).
    pub fn with_field(
        truth: &OccupancyGrid,
        start: Cell,
        radius: f64,
        knowledge: &OccupancyGrid,
        field: &DistanceField,
    ) -> Self {
        let free = truth.cells()[truth.geometry().index(start)] == CellState::Free;
        Self::build(truth, start, radius, knowledge, free.then_some(field))
    }

    fn build(
        truth: &OccupancyGrid,
        start: Cell,
        radius: f64,
        knowledge: &OccupancyGrid,
        field: Option<&DistanceField>,
    ) -> Self {
        let g = truth.geometry();
        let t = truth.cells();
        let mut role = vec![0u8; g.len()];
        let s = g.index(start);
        if let Some(field) = field {
            let connected = flood4(g.width, g.height, s, |i| t[i] == CellState::Free);
            for (r, c) in role.iter_mut().zip(connected) {
                if c {
                    *r = CONNECTED;
                }
            }
            // The drivable positions' footprints.
            let reach = radius / g.resolution + 0.5;
            let d = transform(g.width, g.height, |x, y| field.reached(y * g.width + x));
            for (i, r) in role.iter_mut().enumerate() {
                if *r & CONNECTED != 0 && d[i] as f64 <= reach + 1e-9 {
                    *r |= REACHABLE;
                }
            }
        }
        // The walls: solid cells that share a face with a reachable one.
        let (w, h) = (g.width, g.height);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if role[i] & REACHABLE == 0 {
                    continue;
                }
                let faces = [
                    (x + 1 < w).then(|| i + 1),
                    (x > 0).then(|| i - 1),
                    (y + 1 < h).then(|| i + w),
                    (y > 0).then(|| i - w),
                ];
                for j in faces.into_iter().flatten() {
                    if t[j] != CellState::Free {
                        role[j] |= WALL;
                    }
                }
            }
        }
        let (mut free_total, mut wall_total, mut connected_total) = (0, 0, 0);
        for &r in &role {
            free_total += usize::from(r & REACHABLE != 0);
            wall_total += usize::from(r & WALL != 0);
            connected_total += usize::from(r & CONNECTED != 0);
        }
        let mut me = Self {
            free_total,
            wall_total,
            connected_total,
            role,
            free_seen: 0,
            wall_seen: 0,
            connected_seen: 0,
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
        let r = self.role[index];
        self.free_seen += usize::from(r & REACHABLE != 0);
        self.wall_seen += usize::from(r & WALL != 0);
        self.connected_seen += usize::from(r & CONNECTED != 0);
    }

    /// Share of the free cells 4-connected to the start known so far.
    pub fn connected_coverage(&self) -> f64 {
        ratio(self.connected_seen, self.connected_total)
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

    /// Number of free cells 4-connected to the start.
    pub fn connected_total(&self) -> usize {
        self.connected_total
    }

    /// Whether cell `index` counts in the coverage denominator.
    pub fn is_reachable_free(&self, index: usize) -> bool {
        self.role[index] & REACHABLE != 0
    }

    /// Whether cell `index` is free and 4-connected to the start.
    pub fn is_connected_free(&self, index: usize) -> bool {
        self.role[index] & CONNECTED != 0
    }

    /// Whether cell `index` counts in the wall-coverage denominator.
    pub fn is_bordering_wall(&self, index: usize) -> bool {
        self.role[index] & WALL != 0
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
    use crate::grid::GridGeometry;

    #[test]
    fn counts_only_what_the_robot_can_reach() {
        // Two 2 m × 2 m rooms joined by a 0.2 m slit, and a sealed third room.
        let g = GridGeometry::new(80, 30, 0.1, Point::default());
        let mut t = OccupancyGrid::filled(g, CellState::Occupied);
        t.fill_rect(1, 1, 21, 21, CellState::Free); // 400 cells, the start's room
        t.fill_rect(21, 10, 30, 12, CellState::Free); // slit, 2 cells wide
        t.fill_rect(30, 1, 50, 21, CellState::Free); // behind the slit
        t.fill_rect(55, 1, 75, 21, CellState::Free); // sealed
        let k = OccupancyGrid::filled(g, CellState::Unknown);
        let mut c = CoverageTracker::new(&t, Cell::new(10, 10), 0.25, &k);
        assert_eq!(c.connected_total, 400 + 18 + 400);
        // The robot (0.25 m) drives in its room; its footprint reaches the walls and
        // the slit's mouth (one cell deep), not beyond.
        assert_eq!(c.free_total(), 402);
        assert!(c.is_reachable_free(g.index(Cell::new(21, 10))));
        assert!(!c.is_reachable_free(g.index(Cell::new(22, 10))));
        assert!(c.is_connected_free(g.index(Cell::new(40, 10))));
        // Walls: the 80 cells sharing a face with the room, less the two free cells
        // of the slit's mouth (whose side walls are already room walls).
        assert_eq!(c.wall_total, 78);
        assert_eq!(c.coverage(), 0.0);
        for y in 1..21 {
            for x in 1..21 {
                c.note_seen(g.index(Cell::new(x, y)));
            }
        }
        c.note_seen(g.index(Cell::new(21, 10)));
        c.note_seen(g.index(Cell::new(21, 11)));
        c.note_seen(g.index(Cell::new(60, 5)));
        assert_eq!(c.coverage(), 1.0);
        assert_eq!(c.wall_coverage(), 0.0);
        assert!((c.connected_coverage() - 402.0 / 818.0).abs() < 1e-12);
    }
}
