//! Occupancy grids: cell states, the grid's placement in the world, and world↔cell
//! transforms (DESIGN.md "Frames": cell (ix, iy) has its lower-left corner at
//! `origin + (ix, iy)·resolution`, rotated by the origin's yaw).

use serde::{Deserialize, Serialize};

use crate::config::{Config, ConfigError};
use crate::geom::{Cell, Point};

/// What is known about one cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[repr(u8)]
pub enum CellState {
    /// Not observed yet (knowledge map) or neither free nor occupied (ground truth).
    #[default]
    Unknown = 0,
    /// Observed empty space.
    Free = 1,
    /// Observed obstacle.
    Occupied = 2,
}

/// Where a grid lies in the world: size in cells, cell width and the pose of the
/// lower-left corner of cell (0, 0).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GridGeometry {
    /// Number of columns.
    pub width: usize,
    /// Number of rows.
    pub height: usize,
    /// Cell width in metres.
    pub resolution: f64,
    /// World position of the lower-left corner of cell (0, 0).
    pub origin: Point,
    /// Rotation of the grid about `origin`, radians (ROS map_server `origin[2]`).
    #[serde(default)]
    pub yaw: f64,
}

impl GridGeometry {
    /// Checks this grid's size and placement against `config`'s limits
    /// ([`Config::check_grid`]).
    pub fn check_limits(&self, config: &Config) -> Result<(), ConfigError> {
        config.check_grid(
            self.width as u64,
            self.height as u64,
            self.resolution,
            (self.origin.x, self.origin.y),
        )
    }

    /// An axis-aligned grid of `width × height` cells.
    pub fn new(width: usize, height: usize, resolution: f64, origin: Point) -> Self {
        Self {
            width,
            height,
            resolution,
            origin,
            yaw: 0.0,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// True when the grid has no cells.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row-major index of a cell (row 0 at the bottom).
    #[inline]
    pub fn index(&self, cell: Cell) -> usize {
        cell.y * self.width + cell.x
    }

    /// The cell at a row-major index.
    #[inline]
    pub fn cell(&self, index: usize) -> Cell {
        Cell::new(index % self.width, index / self.width)
    }

    /// Inclusive bounds `(x0, y0, x1, y1)` of the cells with grid indices
    /// `indices`, if any.
    pub fn index_bounds(
        &self,
        indices: impl IntoIterator<Item = usize>,
    ) -> Option<(usize, usize, usize, usize)> {
        indices.into_iter().fold(None, |b, i| {
            let c = self.cell(i);
            Some(match b {
                None => (c.x, c.y, c.x, c.y),
                Some((x0, y0, x1, y1)) => (x0.min(c.x), y0.min(c.y), x1.max(c.x), y1.max(c.y)),
            })
        })
    }

    /// The cell at signed coordinates, if inside the grid.
    #[inline]
    pub fn checked_cell(&self, x: i64, y: i64) -> Option<Cell> {
        (x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height)
            .then(|| Cell::new(x as usize, y as usize))
    }

    /// Grid-frame coordinates (metres from the origin along the grid's rows and
    /// columns) of a world point; the inverse of [`Self::grid_to_world`].
    pub fn to_local(self, p: Point) -> (f64, f64) {
        let (dx, dy) = (p.x - self.origin.x, p.y - self.origin.y);
        let (s, c) = self.yaw.sin_cos();
        (c * dx + s * dy, -s * dx + c * dy)
    }

    /// World point of grid-frame coordinates (metres from the origin along the
    /// grid's rows and columns).
    pub fn grid_to_world(self, lx: f64, ly: f64) -> Point {
        let (s, c) = self.yaw.sin_cos();
        Point::new(
            self.origin.x + c * lx - s * ly,
            self.origin.y + s * lx + c * ly,
        )
    }

    /// The cell containing a world point, if inside the grid.
    pub fn world_to_cell(&self, p: Point) -> Option<Cell> {
        let (lx, ly) = self.to_local(p);
        let (fx, fy) = (lx / self.resolution, ly / self.resolution);
        if !(fx.is_finite() && fy.is_finite()) {
            return None;
        }
        self.checked_cell(fx.floor() as i64, fy.floor() as i64)
    }

    /// World position of a cell's centre.
    pub fn cell_center(&self, cell: Cell) -> Point {
        self.grid_to_world(
            (cell.x as f64 + 0.5) * self.resolution,
            (cell.y as f64 + 0.5) * self.resolution,
        )
    }

    /// World extent of the grid as (width, height) in metres.
    pub fn extent(&self) -> (f64, f64) {
        (
            self.width as f64 * self.resolution,
            self.height as f64 * self.resolution,
        )
    }
}

/// A grid of [`CellState`]s: ground truth or knowledge map.
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyGrid {
    geometry: GridGeometry,
    cells: Vec<CellState>,
}

impl OccupancyGrid {
    /// A grid with every cell in `state`.
    pub fn filled(geometry: GridGeometry, state: CellState) -> Self {
        Self {
            geometry,
            cells: vec![state; geometry.len()],
        }
    }

    /// A grid from row-major cells (row 0 at the bottom); `None` if the length is wrong.
    pub fn from_cells(geometry: GridGeometry, cells: Vec<CellState>) -> Option<Self> {
        (cells.len() == geometry.len()).then_some(Self { geometry, cells })
    }

    /// The grid's placement.
    pub fn geometry(&self) -> &GridGeometry {
        &self.geometry
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.geometry.width
    }

    /// Number of rows.
    pub fn height(&self) -> usize {
        self.geometry.height
    }

    /// Cell width in metres.
    pub fn resolution(&self) -> f64 {
        self.geometry.resolution
    }

    /// All cells, row-major from the bottom row.
    pub fn cells(&self) -> &[CellState] {
        &self.cells
    }

    /// All cells, mutable.
    pub fn cells_mut(&mut self) -> &mut [CellState] {
        &mut self.cells
    }

    /// State of a cell.
    #[inline]
    pub fn get(&self, cell: Cell) -> CellState {
        self.cells[self.geometry.index(cell)]
    }

    /// Set the state of a cell.
    #[inline]
    pub fn set(&mut self, cell: Cell, state: CellState) {
        let i = self.geometry.index(cell);
        self.cells[i] = state;
    }

    /// Number of cells in `state`.
    pub fn count(&self, state: CellState) -> usize {
        self.cells.iter().filter(|&&c| c == state).count()
    }

    /// Inclusive bounds `(x0, y0, x1, y1)` of the cells whose state satisfies
    /// `keep`, if any.
    pub fn bounds_of(
        &self,
        keep: impl Fn(CellState) -> bool,
    ) -> Option<(usize, usize, usize, usize)> {
        let mut b: Option<(usize, usize, usize, usize)> = None;
        for (y, row) in self.cells.chunks(self.width().max(1)).enumerate() {
            let Some(first) = row.iter().position(|&c| keep(c)) else {
                continue;
            };
            let last = row.iter().rposition(|&c| keep(c)).unwrap_or(first);
            b = Some(match b {
                None => (first, y, last, y),
                Some((x0, y0, x1, _)) => (x0.min(first), y0, x1.max(last), y),
            });
        }
        b
    }

    /// Fill the axis-aligned rectangle of cells `[x0, x1) × [y0, y1)` (clipped).
    pub fn fill_rect(&mut self, x0: usize, y0: usize, x1: usize, y1: usize, state: CellState) {
        let (x1, y1) = (x1.min(self.width()), y1.min(self.height()));
        for y in y0..y1 {
            for x in x0..x1 {
                self.set(Cell::new(x, y), state);
            }
        }
    }

    /// A binary ground truth: every cell that is not `Free` becomes `Occupied`
    /// (DESIGN.md: the grey outside a SLAM map is solid).
    pub fn solidified(&self) -> Self {
        let cells = self
            .cells
            .iter()
            .map(|&c| {
                if c == CellState::Free {
                    CellState::Free
                } else {
                    CellState::Occupied
                }
            })
            .collect();
        Self {
            geometry: self.geometry,
            cells,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn world_cell_round_trip_with_yaw() {
        let mut g = GridGeometry::new(40, 30, 0.1, Point::new(-2.0, 3.0));
        for yaw in [0.0, 0.7, std::f64::consts::PI, -2.0] {
            g.yaw = yaw;
            for idx in [0, 17, 611, 1199] {
                let c = g.cell(idx);
                assert_eq!(g.index(c), idx);
                assert_eq!(g.world_to_cell(g.cell_center(c)), Some(c));
            }
        }
    }

    #[test]
    fn lower_left_corner_is_origin() {
        let g = GridGeometry::new(10, 10, 0.5, Point::new(1.0, 2.0));
        assert_eq!(
            g.world_to_cell(Point::new(1.01, 2.01)),
            Some(Cell::new(0, 0))
        );
        assert_eq!(g.world_to_cell(Point::new(0.99, 2.01)), None);
        assert_eq!(
            g.world_to_cell(Point::new(5.99, 6.99)),
            Some(Cell::new(9, 9))
        );
        assert_eq!(g.world_to_cell(Point::new(6.01, 3.0)), None);
        assert_eq!(g.cell_center(Cell::new(1, 0)), Point::new(1.75, 2.25));
    }

    #[test]
    fn solidified_is_binary() {
        let g = GridGeometry::new(3, 1, 1.0, Point::default());
        let grid = OccupancyGrid::from_cells(
            g,
            vec![CellState::Unknown, CellState::Free, CellState::Occupied],
        )
        .unwrap();
        let s = grid.solidified();
        assert_eq!(
            s.cells(),
            &[CellState::Occupied, CellState::Free, CellState::Occupied]
        );
    }
}
