//! The walls a real scan's points lie on: the cells that stop the beams of
//! [`super::scan_by`] when a campaign adds a scan (docs/USER-GUIDE.md
//! "Campaigns").
//!
//! In: the scanner's centre and the scan's points, registered in the world
//! frame, and the heights that count as walls. Out: the wall cells, sorted.
//!
//! A point lies on a wall's face, where its beam entered the wall; it is
//! carried a quarter of a cell further along the beam ([`NUDGE_CELLS`]) so
//! that it falls in the cell behind the face, not in the free cell before it.
//!
//! The scan's [`RangeImage`] keeps, per direction, how far the scanner saw:
//! the sweep records a cell only up to the returns around its direction, so
//! a wall cell no point fell in (one seen at a grazing angle) lets no free
//! space leak behind the wall.

use serde::{Deserialize, Serialize};

use crate::geom::Point;
use crate::grid::GridGeometry;

/// How far a point is carried along its beam into the wall it hit, cells.
pub const NUDGE_CELLS: f64 = 0.25;

/// The cells of `geometry` holding a point of `points` whose height lies in
/// `band` (world `z`, inclusive), each carried [`NUDGE_CELLS`] along its
/// horizontal beam from `origin`; sorted, each once. Points outside the grid,
/// at the scanner's centre, or not finite are skipped.
pub fn observed_walls(
    geometry: &GridGeometry,
    origin: Point,
    points: impl IntoIterator<Item = [f64; 3]>,
    band: (f64, f64),
) -> Vec<usize> {
    let nudge = NUDGE_CELLS * geometry.resolution;
    let mut walls: Vec<usize> = points
        .into_iter()
        .filter(|p| p.iter().all(|v| v.is_finite()) && p[2] >= band.0 && p[2] <= band.1)
        .filter_map(|[x, y, _]| {
            let (dx, dy) = (x - origin.x, y - origin.y);
            let d = dx.hypot(dy);
            (d > 0.0).then(|| Point::new(x + nudge * dx / d, y + nudge * dy / d))
        })
        .filter_map(|p| geometry.world_to_cell(p))
        .map(|c| geometry.index(c))
        .collect();
    walls.sort_unstable();
    walls.dedup();
    walls
}

/// Directions of a [`RangeImage`]: 7200, every 0.05°.
pub const RANGE_BINS: usize = 7200;

/// Neighbouring returns farther apart than this many cells (across the
/// direction, at the nearer one's distance) leave a gap the scanner saw
/// through (an opening, or nothing within its range).
pub const GAP_CELLS: f64 = 2.0;

/// A scan's range image: per direction around the scanner, the horizontal
/// distance of the nearest return in the wall band.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RangeImage {
    /// Per direction bin (counter-clockwise from the world's x axis, [`RANGE_BINS`]
    /// of them), the nearest return's distance, metres; `None`: no return.
    pub ranges: Vec<Option<f32>>,
}

impl RangeImage {
    /// The range image of `points` (world frame) in `band` seen from `origin`.
    pub fn new(
        origin: Point,
        points: impl IntoIterator<Item = [f64; 3]>,
        band: (f64, f64),
    ) -> Self {
        let mut ranges: Vec<Option<f32>> = vec![None; RANGE_BINS];
        for p in points {
            if !(p.iter().all(|v| v.is_finite()) && p[2] >= band.0 && p[2] <= band.1) {
                continue;
            }
            let (dx, dy) = (p[0] - origin.x, p[1] - origin.y);
            let d = dx.hypot(dy);
            if d <= 0.0 {
                continue;
            }
            let b = bin(dy.atan2(dx));
            let r = d as f32;
            ranges[b] = Some(ranges[b].map_or(r, |old| old.min(r)));
        }
        Self { ranges }
    }

    /// How far the scanner saw in `direction` (radians): the farther of the
    /// nearest returns on either side, or `None` when they are more than
    /// [`GAP_CELLS`] cells of `resolution` apart (it saw through) or there
    /// are none. `near` are the bins of the nearest returns
    /// ([`Self::neighbours`]).
    pub fn depth(&self, near: &Neighbours, direction: f64, resolution: f64) -> Option<f64> {
        let b = bin(direction);
        let (l, r) = (near.left[b]?, near.right[b]?);
        let (rl, rr) = (f64::from(self.ranges[l]?), f64::from(self.ranges[r]?));
        if l == r {
            return Some(rl);
        }
        let bins = (r + RANGE_BINS - l) % RANGE_BINS;
        let apart = bins as f64 * std::f64::consts::TAU / RANGE_BINS as f64 * rl.min(rr);
        (apart <= GAP_CELLS * resolution).then_some(rl.max(rr))
    }

    /// The nearest bin with a return at or before, and at or after, every bin.
    pub fn neighbours(&self) -> Neighbours {
        let n = RANGE_BINS;
        let mut left = vec![None; n];
        let mut right = vec![None; n];
        let Some(any) = self.ranges.iter().position(Option::is_some) else {
            return Neighbours { left, right };
        };
        // Two turns around the circle, so that every bin sees a return.
        let mut last = any;
        for k in 0..2 * n {
            let b = (any + k) % n;
            if self.ranges[b].is_some() {
                last = b;
            }
            left[b] = Some(last);
        }
        let mut next = any;
        for k in 0..2 * n {
            let b = (any + 2 * n - k) % n;
            if self.ranges[b].is_some() {
                next = b;
            }
            right[b] = Some(next);
        }
        Neighbours { left, right }
    }
}

/// For every bin of a [`RangeImage`], the nearest bins with a return on
/// either side.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbours {
    left: Vec<Option<usize>>,
    right: Vec<Option<usize>>,
}

/// The bin of `direction`, radians.
fn bin(direction: f64) -> usize {
    let turns = direction.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU;
    ((turns * RANGE_BINS as f64) as usize).min(RANGE_BINS - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Cell;

    #[test]
    fn a_point_on_a_face_falls_in_the_wall_behind_it() {
        let g = GridGeometry::new(10, 10, 0.1, Point::new(0.0, 0.0));
        // The face x = 0.8 of the cell (8, 5), seen from (0.25, 0.55); a point a
        // millimetre short of it, one on it, one in the floor band, one too high.
        let points = [
            [0.799, 0.55, 1.0],
            [0.8, 0.55, 1.0],
            [0.8, 0.35, 0.05],
            [0.8, 0.45, 2.5],
        ];
        let walls = observed_walls(&g, Point::new(0.25, 0.55), points, (0.2, 2.0));
        assert_eq!(walls, vec![g.index(Cell::new(8, 5))]);
    }

    #[test]
    fn points_outside_the_grid_or_at_the_scanner_are_skipped() {
        let g = GridGeometry::new(10, 10, 0.1, Point::new(0.0, 0.0));
        let points = [[5.0, 5.0, 1.0], [0.25, 0.55, 1.0], [f64::NAN, 0.1, 1.0]];
        assert!(observed_walls(&g, Point::new(0.25, 0.55), points, (0.0, 2.0)).is_empty());
    }

    #[test]
    fn the_range_image_sees_up_to_its_returns_and_through_gaps() {
        // A wall 5 m east from -1 m to 1 m in y, a return every 5 cm.
        let points = (0..=40).map(|k| [5.0, -1.0 + 0.05 * f64::from(k), 1.0]);
        let image = RangeImage::new(Point::new(0.0, 0.0), points, (0.2, 2.0));
        let near = image.neighbours();
        let d = image.depth(&near, 0.1, 0.1).expect("between returns");
        assert!((d - 5.0 / 0.1f64.cos()).abs() < 0.06, "{d}");
        // West: no return at all.
        assert_eq!(image.depth(&near, std::f64::consts::PI, 0.1), None);
        // Past the wall's end the returns are far apart: a gap.
        assert_eq!(image.depth(&near, 0.5, 0.1), None);
    }
}
