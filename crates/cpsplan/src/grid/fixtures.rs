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

/// The three cell states, indexed by random codes.
pub(crate) const STATES: [CellState; 3] =
    [CellState::Unknown, CellState::Free, CellState::Occupied];

/// Paints `state` over the `rw × rh` cells from `(x, y)` (both taken modulo the
/// grid's size, the rectangle clipped to it), and returns the painted cells: the
/// changes to tell a kept state of.
pub(crate) fn paint(
    knowledge: &mut OccupancyGrid,
    (x, y, rw, rh): (usize, usize, usize, usize),
    state: CellState,
) -> Vec<usize> {
    let (w, h) = (knowledge.width(), knowledge.height());
    let (x, y) = (x % w, y % h);
    let (x1, y1) = ((x + rw).min(w), (y + rh).min(h));
    knowledge.fill_rect(x, y, x1, y1, state);
    (y..y1)
        .flat_map(|yy| (x..x1).map(move |xx| yy * w + xx))
        .collect()
}
