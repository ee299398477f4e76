//! Small knowledge maps shared by the tests of the stages above the grid.

use crate::geom::Point;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

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
