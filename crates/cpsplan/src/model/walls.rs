//! Distances to the ground-truth walls: from any point to the vertical faces of
//! the truth's solid cells (every cell not Free), extruded from the floor to the
//! wall height. What the model's accuracy is measured against.

use crate::geom::Point;
use crate::grid::distance::distance_transform;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// The ground-truth walls of a map, ready for distance queries.
#[derive(Debug, Clone)]
pub struct GroundTruthWalls {
    geometry: GridGeometry,
    solid: Vec<bool>,
    /// Per cell, the distance in cells from its centre to the nearest solid
    /// cell's centre.
    to_solid: Vec<f32>,
    /// The same to the nearest Free cell.
    to_free: Vec<f32>,
    wall_height: f64,
}

impl GroundTruthWalls {
    /// The walls of `truth`, `wall_height` metres tall.
    pub fn new(truth: &OccupancyGrid, wall_height: f64) -> Self {
        let geometry = *truth.geometry();
        let solid: Vec<bool> = truth
            .cells()
            .iter()
            .map(|&c| c != CellState::Free)
            .collect();
        let to_solid = distance_transform(&geometry, |i| solid[i]);
        let to_free = distance_transform(&geometry, |i| !solid[i]);
        Self {
            geometry,
            solid,
            to_solid,
            to_free,
            wall_height,
        }
    }

    /// Distance in metres from `p` (world frame, `z` over the floor) to the
    /// nearest wall face: horizontally to the boundary between solid and free
    /// space (from either side), combined with how far `z` lies outside the
    /// walls' height. Outside the grid everything counts as solid.
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        let g = &self.geometry;
        let r = g.resolution;
        let (lx, ly) = g.to_local(Point::new(p[0], p[1]));
        let (fx, fy) = (lx / r, ly / r);
        let dz = (-p[2]).max(p[2] - self.wall_height).max(0.0);
        if !(fx.is_finite() && fy.is_finite()) {
            return f64::INFINITY;
        }
        let (cx, cy) = (fx.floor(), fy.floor());
        let inside = cx >= 0.0 && cy >= 0.0 && cx < g.width as f64 && cy < g.height as f64;
        let horizontal = if inside {
            let i = cy as usize * g.width + cx as usize;
            let solid = self.solid[i];
            let d = if solid {
                self.to_free[i]
            } else {
                self.to_solid[i]
            };
            self.nearest_square(fx, fy, cx as i64, cy as i64, !solid, f64::from(d))
        } else {
            // Outside: the distance back to the nearest free cell, found from
            // the nearest cell inside.
            let nx = cx.clamp(0.0, g.width as f64 - 1.0);
            let ny = cy.clamp(0.0, g.height as f64 - 1.0);
            let i = ny as usize * g.width + nx as usize;
            let back =
                (fx - fx.clamp(0.0, g.width as f64)).hypot(fy - fy.clamp(0.0, g.height as f64));
            let d = f64::from(self.to_free[i]) + 2.0 * back;
            self.nearest_square(fx, fy, nx as i64, ny as i64, false, d)
        };
        (horizontal * r).hypot(dz)
    }

    /// Distance in cells from `(fx, fy)` to the nearest cell square that is solid
    /// (`want_solid`) or free, searching around `(cx, cy)`: `reach` is the
    /// transform's centre-to-centre distance there, and every square closer to
    /// the point than that one has its centre within `reach` + 3/√2 cells.
    fn nearest_square(
        &self,
        fx: f64,
        fy: f64,
        cx: i64,
        cy: i64,
        want_solid: bool,
        reach: f64,
    ) -> f64 {
        let g = &self.geometry;
        if !reach.is_finite() {
            return f64::INFINITY;
        }
        let k = ((reach + 2.5).ceil() as i64).min(g.width.max(g.height) as i64);
        // Squared distances: one square root at the end instead of a `hypot`
        // per square. Rows and columns outward from the centre, each direction
        // given up once its nearest square is no nearer than the best: the
        // same squares' least distance, found sooner.
        let mut best2 = f64::INFINITY;
        let (x0, x1) = ((cx - k).max(0), (cx + k).min(g.width as i64 - 1));
        let (y0, y1) = ((cy - k).max(0), (cy + k).min(g.height as i64 - 1));
        outward(cy, y0, y1, |y| {
            let dy = gap(y, fy);
            let dy2 = dy * dy;
            if dy2 >= best2 {
                return false;
            }
            let cells = &self.solid[y as usize * g.width..][..g.width];
            outward(cx, x0, x1, |x| {
                let dx = gap(x, fx);
                let d2 = dx * dx + dy2;
                if d2 >= best2 {
                    return false;
                }
                if cells[x as usize] == want_solid {
                    best2 = d2;
                }
                true
            });
            true
        });
        best2.sqrt()
    }
}

/// The distance, in cells, from `f` to the cell `v`'s span `[v, v + 1]`.
fn gap(v: i64, f: f64) -> f64 {
    (v as f64 - f).max(f - (v as f64 + 1.0)).max(0.0)
}

/// Visits `mid` (clamped to `lo..=hi`) and the values above it in order, then
/// those below it in order, each direction until `visit` says stop.
fn outward(mid: i64, lo: i64, hi: i64, mut visit: impl FnMut(i64) -> bool) {
    let mid = mid.clamp(lo, hi);
    for v in mid..=hi {
        if !visit(v) {
            break;
        }
    }
    for v in (lo..mid).rev() {
        if !visit(v) {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room() -> OccupancyGrid {
        // 20 × 20 cells of 0.1 m: a free room inside a one-cell wall.
        let g = GridGeometry::new(20, 20, 0.1, Point::new(0.0, 0.0));
        let mut grid = OccupancyGrid::filled(g, CellState::Occupied);
        grid.fill_rect(1, 1, 19, 19, CellState::Free);
        grid
    }

    #[test]
    fn distances_to_the_faces_from_both_sides_and_above() {
        let w = GroundTruthWalls::new(&room(), 2.0);
        // On the inner face of the left wall (x = 0.1 m).
        assert!(w.distance([0.1, 1.0, 1.0]) < 1e-12);
        // 3 cm in front of it, and 3 cm inside it.
        assert!((w.distance([0.13, 1.0, 1.0]) - 0.03).abs() < 1e-9);
        assert!((w.distance([0.07, 1.0, 1.0]) - 0.03).abs() < 1e-9);
        // In the middle of the room: 0.9 m to every wall.
        assert!((w.distance([1.0, 1.0, 1.0]) - 0.9).abs() < 1e-9);
        // Above the wall by 0.4 m, on the face.
        assert!((w.distance([0.1, 1.0, 2.4]) - 0.4).abs() < 1e-9);
        // Outside the map, 0.5 m beyond the wall's outer edge: 0.6 m to free space.
        assert!((w.distance([-0.5, 1.0, 1.0]) - 0.6).abs() < 1e-9);
    }

    #[test]
    fn corner_distances_are_euclidean() {
        let w = GroundTruthWalls::new(&room(), 2.0);
        // 3 cm and 4 cm from the two inner faces of the lower-left corner.
        assert!((w.distance([0.13, 0.14, 1.0]) - 0.03).abs() < 1e-9);
        // Inside the corner cell, 3 cm and 4 cm from the free room's corner.
        assert!((w.distance([0.07, 0.06, 1.0]) - 0.05).abs() < 1e-9);
    }

    proptest::proptest! {
        /// The distance is the least over every square of the other kind
        /// (solid from a free cell, free from a solid one or from outside the
        /// grid), bit for bit: the search's pruning never drops the nearest
        /// square.
        #[test]
        fn the_distance_is_the_nearest_square_of_all(
            walls in proptest::collection::vec(0usize..144, 0..60),
            points in proptest::collection::vec((-0.6f64..1.8, -0.6f64..1.8), 1..30),
        ) {
            let g = GridGeometry::new(12, 12, 0.1, Point::new(0.0, 0.0));
            let mut grid = OccupancyGrid::filled(g, CellState::Free);
            for &i in &walls {
                grid.set(g.cell(i), CellState::Occupied);
            }
            let w = GroundTruthWalls::new(&grid, 2.0);
            for (x, y) in points {
                let (fx, fy) = (x / 0.1, y / 0.1);
                // Outside the grid everything counts as solid.
                let inside = (0.0..12.0).contains(&fx) && (0.0..12.0).contains(&fy);
                let here = !inside || w.solid[fy as usize * 12 + fx as usize];
                let mut best2 = f64::INFINITY;
                for (i, &s) in w.solid.iter().enumerate() {
                    if s != here {
                        let (sx, sy) = ((i % 12) as f64, (i / 12) as f64);
                        let dx = (sx - fx).max(fx - (sx + 1.0)).max(0.0);
                        let dy = (sy - fy).max(fy - (sy + 1.0)).max(0.0);
                        best2 = best2.min(dx * dx + dy * dy);
                    }
                }
                let want = if best2.is_finite() { best2.sqrt() * 0.1 } else { f64::INFINITY };
                proptest::prop_assert_eq!(w.distance([x, y, 1.0]), want.hypot(0.0), "at ({}, {})", x, y);
            }
        }
    }
}
