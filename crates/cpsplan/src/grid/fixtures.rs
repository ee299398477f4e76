//! Small knowledge maps shared by the tests of the stages above the grid.

use crate::geom::Point;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// A `w × h` map at 0.1 m from one code per cell, row-major: 0 Occupied,
/// 1 Unknown, anything else Free (cells beyond `codes` are Free).
pub(crate) fn coded(w: usize, h: usize, codes: &[u8]) -> OccupancyGrid {
    let g = GridGeometry::new(w, h, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Free);
    for (c, &v) in k.cells_mut().iter_mut().zip(codes) {
        match v {
            0 => *c = CellState::Occupied,
            1 => *c = CellState::Unknown,
            _ => {}
        }
    }
    k
}

/// An L-shaped corridor, 2 m wide.
pub(crate) fn l_corridor() -> OccupancyGrid {
    let g = GridGeometry::new(120, 120, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Occupied);
    k.fill_rect(5, 5, 115, 25, CellState::Free);
    k.fill_rect(95, 5, 115, 115, CellState::Free);
    k
}

/// A U-shaped corridor 2 m wide: the two ends share no line of sight.
pub(crate) fn u_corridor() -> OccupancyGrid {
    let g = GridGeometry::new(120, 120, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Occupied);
    k.fill_rect(5, 5, 25, 115, CellState::Free);
    k.fill_rect(5, 95, 115, 115, CellState::Free);
    k.fill_rect(95, 5, 115, 115, CellState::Free);
    k
}
