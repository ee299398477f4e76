//! The candidate stations of the known-map bound: drivable cells on a square
//! lattice, and drivable cells just off the obstacles' convex corners (where an
//! art-gallery guard sees round two sides at once).

use crate::geom::Cell;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// Why a station was proposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StationOrigin {
    /// A lattice point.
    Lattice,
    /// Beside a convex obstacle corner.
    Corner,
}

/// Drivable cells (`drivable[i]`) on a lattice `step` cells apart, each once, in
/// index order.
pub fn lattice_stations(g: &GridGeometry, drivable: &[bool], step: usize) -> Vec<usize> {
    let step = step.max(1);
    let mut out = Vec::new();
    for y in (step / 2..g.height).step_by(step) {
        for x in (step / 2..g.width).step_by(step) {
            let i = y * g.width + x;
            if drivable[i] {
                out.push(i);
            }
        }
    }
    out
}

/// For every convex corner of an obstacle in `truth` (a non-Free cell whose two
/// orthogonal neighbours on one side, and the diagonal between them, are Free),
/// the cell `offset` cells out along that diagonal, if drivable. Each once, in
/// index order.
pub fn corner_stations(truth: &OccupancyGrid, drivable: &[bool], offset: usize) -> Vec<usize> {
    let g = truth.geometry();
    let (w, h) = (g.width as i64, g.height as i64);
    let free = |x: i64, y: i64| {
        x >= 0
            && y >= 0
            && x < w
            && y < h
            && truth.get(Cell::new(x as usize, y as usize)) == CellState::Free
    };
    let off = offset.max(1) as i64;
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            if free(x, y) {
                continue;
            }
            for (dx, dy) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
                if free(x + dx, y) && free(x, y + dy) && free(x + dx, y + dy) {
                    let (sx, sy) = (x + dx * off, y + dy * off);
                    if sx >= 0 && sy >= 0 && sx < w && sy < h {
                        let i = (sy * w + sx) as usize;
                        if drivable[i] {
                            out.push(i);
                        }
                    }
                }
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;

    #[test]
    fn lattice_keeps_only_drivable_cells_at_the_step() {
        let g = GridGeometry::new(10, 10, 0.1, Point::default());
        let mut drivable = vec![true; 100];
        drivable[g.index(Cell::new(1, 1))] = false;
        let s = lattice_stations(&g, &drivable, 3);
        // x, y in {1, 4, 7}: 9 points, one not drivable.
        assert_eq!(s.len(), 8);
        assert!(s.iter().all(|&i| i % 10 % 3 == 1 && i / 10 % 3 == 1));
    }

    #[test]
    fn a_pillar_has_four_corner_stations() {
        let g = GridGeometry::new(20, 20, 0.1, Point::default());
        let mut t = OccupancyGrid::filled(g, CellState::Free);
        t.fill_rect(8, 8, 12, 12, CellState::Occupied);
        let drivable = vec![true; g.len()];
        let s = corner_stations(&t, &drivable, 3);
        let cells: Vec<Cell> = s.iter().map(|&i| g.cell(i)).collect();
        assert_eq!(
            cells,
            vec![
                Cell::new(5, 5),
                Cell::new(14, 5),
                Cell::new(5, 14),
                Cell::new(14, 14)
            ]
        );
    }
}
