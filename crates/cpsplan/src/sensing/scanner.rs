//! The scanner model: a scan copies the ground truth of every visible cell within
//! range into the knowledge map.

use serde::{Deserialize, Serialize};

use super::visible_cells;
#[cfg(doc)]
use super::RangeImage;
use crate::geom::Cell;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// What one scan added to the knowledge map.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ScanOutcome {
    /// Cells seen by the sweep in this scan (new or not; wall completion not counted).
    pub seen: usize,
    /// Cells that were Unknown before and are now Free.
    pub new_free: usize,
    /// Cells that were Unknown before and are now Occupied.
    pub new_occupied: usize,
}

/// Scans from `at` with a maximum range of `range_cells` (cells, centre to centre):
/// every cell visible in `truth` is copied into `knowledge`, and `on_new(index)` is
/// called for each cell that was Unknown before. Anything in `truth` that is not
/// Free stops the beam and is recorded as Occupied, so the knowledge map never
/// contradicts a solidified ground truth.
///
/// *Wall completion*: the beams that cross a visible free cell go on until they hit
/// something, so a wall cell that shares a face with a visible free cell, on the
/// far side of it as seen from the scanner (along either axis) and within range, is
/// seen too. The grid sweep alone can miss such cells at grazing angles, and every
/// one it misses would look like frontier.
pub fn scan(
    truth: &OccupancyGrid,
    knowledge: &mut OccupancyGrid,
    at: Cell,
    range_cells: f64,
    on_new: impl FnMut(usize),
) -> ScanOutcome {
    debug_assert_eq!(truth.cells().len(), knowledge.cells().len());
    let t = truth.cells();
    scan_by(
        |i| t[i] != CellState::Free,
        |_| true,
        knowledge,
        at,
        range_cells,
        on_new,
    )
}

/// [`scan`] with the walls given by `solid(index)` instead of a ground truth:
/// a real scan, whose walls are the cells its points lie on (and those known
/// before, [`crate::sensing::observed_walls`]). Every cell the sweep sees is
/// recorded: Occupied where `solid` says it holds a wall, else Free where
/// `keep(index)` accepts it (a real scan keeps only the free space its
/// returns show, [`RangeImage`]).
pub fn scan_by(
    solid: impl Fn(usize) -> bool,
    keep: impl Fn(usize) -> bool,
    knowledge: &mut OccupancyGrid,
    at: Cell,
    range_cells: f64,
    mut on_new: impl FnMut(usize),
) -> ScanOutcome {
    let geometry = *knowledge.geometry();
    let k = knowledge.cells_mut();
    let mut out = ScanOutcome::default();
    sweep(&geometry, &solid, at, range_cells, |i, swept| {
        if swept {
            out.seen += 1;
        }
        if k[i] == CellState::Unknown {
            if solid(i) {
                out.new_occupied += 1;
                k[i] = CellState::Occupied;
            } else if keep(i) {
                out.new_free += 1;
                k[i] = CellState::Free;
            } else {
                return;
            }
            on_new(i);
        }
    });
    out
}

/// The true gain of a scan from `at` (the oracle's, simulation only): the cells
/// Unknown in `knowledge` and Free in `truth` that [`scan`] would reveal.
pub fn true_gain(
    truth: &OccupancyGrid,
    knowledge: &OccupancyGrid,
    at: Cell,
    range_cells: f64,
) -> usize {
    let (t, k) = (truth.cells(), knowledge.cells());
    let mut count = 0;
    let solid = |i: usize| t[i] != CellState::Free;
    sweep(truth.geometry(), &solid, at, range_cells, |i, swept| {
        if swept && k[i] == CellState::Unknown && t[i] == CellState::Free {
            count += 1;
        }
    });
    count
}

/// The cells of `truth` that are not Free and that a scan from `at` with range
/// `range_cells` sees (the sweep and wall completion of [`scan`]): the walls
/// the scan's points lie on. Sorted, each once.
pub fn seen_walls(truth: &OccupancyGrid, at: Cell, range_cells: f64) -> Vec<usize> {
    let t = truth.cells();
    let mut walls = Vec::new();
    let solid = |i: usize| t[i] != CellState::Free;
    sweep(truth.geometry(), &solid, at, range_cells, |i, _| {
        if t[i] != CellState::Free {
            walls.push(i);
        }
    });
    walls.sort_unstable();
    walls.dedup();
    walls
}

/// The visibility sweep of a scan with wall completion: `visit(i, true)` for
/// every cell the sweep sees, `visit(j, false)` for every wall cell wall
/// completion adds (possibly more than once, possibly one the sweep saw).
fn sweep(
    geometry: &GridGeometry,
    solid: &impl Fn(usize) -> bool,
    at: Cell,
    range_cells: f64,
    mut visit: impl FnMut(usize, bool),
) {
    let (w, h) = (geometry.width, geometry.height);
    let r2 = range_cells * range_cells + 1e-9;
    let (ax, ay) = (at.x as i64, at.y as i64);
    visible_cells(geometry, at, range_cells, solid, |i| {
        visit(i, true);
        if !solid(i) {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            let (sx, sy) = ((x - ax).signum(), (y - ay).signum());
            for (nx, ny) in [(x + sx, y), (x, y + sy)] {
                if (nx, ny) == (x, y) || nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let (dx, dy) = ((nx - ax) as f64, (ny - ay) as f64);
                let j = ny as usize * w + nx as usize;
                if solid(j) && dx * dx + dy * dy <= r2 {
                    visit(j, false);
                }
            }
        }
        false
    });
}

/// The expected newly scanned area `S` of Eq. (1): the number of Unknown cells of
/// `knowledge` within `range_cells` visible from `at` when Unknown is treated as
/// empty (only known Occupied cells block). Counting stops at `limit`, so a caller
/// that only needs "at least `limit`" pays for no more.
pub fn expected_gain(knowledge: &OccupancyGrid, at: Cell, range_cells: f64, limit: usize) -> usize {
    let k = knowledge.cells();
    let mut count = 0usize;
    visible_cells(
        knowledge.geometry(),
        at,
        range_cells,
        |i| k[i] == CellState::Occupied,
        |i| {
            if k[i] == CellState::Unknown {
                count += 1;
            }
            count >= limit
        },
    );
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;

    fn room() -> OccupancyGrid {
        // 30×20 free room with a solid border and a pillar.
        let g = GridGeometry::new(30, 20, 0.1, Point::default());
        let mut t = OccupancyGrid::filled(g, CellState::Occupied);
        t.fill_rect(1, 1, 29, 19, CellState::Free);
        t.fill_rect(14, 8, 16, 12, CellState::Occupied);
        t
    }

    #[test]
    fn the_true_gain_is_what_a_scan_reveals() {
        let truth = room();
        let mut k = OccupancyGrid::filled(*truth.geometry(), CellState::Unknown);
        for (at, range) in [((3, 10), 100.0), ((25, 15), 8.0), ((20, 3), 30.0)] {
            let at = Cell::new(at.0, at.1);
            let expected = true_gain(&truth, &k, at, range);
            let out = scan(&truth, &mut k, at, range, |_| {});
            assert_eq!(expected, out.new_free);
            assert_eq!(true_gain(&truth, &k, at, range), 0);
        }
    }

    #[test]
    fn scan_copies_truth_and_second_scan_adds_nothing() {
        let truth = room();
        let mut k = OccupancyGrid::filled(*truth.geometry(), CellState::Unknown);
        let a = scan(&truth, &mut k, Cell::new(3, 10), 100.0, |_| {});
        assert!(a.new_free > 0 && a.new_occupied > 0);
        for (kc, tc) in k.cells().iter().zip(truth.cells()) {
            assert!(*kc == CellState::Unknown || kc == tc);
        }
        // Behind the pillar from (3,10) lies a shadow.
        assert_eq!(k.get(Cell::new(25, 10)), CellState::Unknown);
        let b = scan(&truth, &mut k, Cell::new(3, 10), 100.0, |_| {});
        assert_eq!((b.new_free, b.new_occupied), (0, 0));
        assert_eq!(b.seen, a.seen);
    }

    #[test]
    fn gain_is_zero_right_after_a_scan_there() {
        let truth = room();
        let mut k = OccupancyGrid::filled(*truth.geometry(), CellState::Unknown);
        let at = Cell::new(3, 10);
        scan(&truth, &mut k, at, 12.0, |_| {});
        assert_eq!(expected_gain(&k, at, 12.0, usize::MAX), 0);
        let elsewhere = Cell::new(26, 10);
        assert!(expected_gain(&k, elsewhere, 12.0, usize::MAX) > 0);
        assert_eq!(expected_gain(&k, elsewhere, 12.0, 3), 3);
    }
}
