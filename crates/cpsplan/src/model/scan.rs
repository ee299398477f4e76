//! One simulated scan's points: every wall cell the scanner sees, hit where the
//! beam through its centre enters it, extruded from the floor to the wall height,
//! each point displaced along its beam by the range noise and then expressed in
//! the parent's estimated pose (the CPS alignment, paper section III: "transformed
//! to the world coordinate frame using the position information").

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::points::ModelPoint;
use crate::geom::Point;
use crate::grid::traversal::Traversal;
use crate::grid::{CellState, OccupancyGrid};

/// The scanner at one scan: its true pose and the pose the CPS estimated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanPose {
    /// True centre `[x, y, z]`, world frame.
    pub truth: [f64; 3],
    /// Error of the estimate `[x, y, z]`, metres.
    pub error: [f64; 3],
    /// Error of the estimated heading, radians.
    pub heading_error: f64,
}

impl ScanPose {
    /// The estimated centre.
    pub fn estimate(&self) -> [f64; 3] {
        [
            self.truth[0] + self.error[0],
            self.truth[1] + self.error[1],
            self.truth[2] + self.error[2],
        ]
    }
}

/// How the points of a scan are sampled and disturbed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sampling {
    /// Heights of the points over the floor, one per row of every wall column.
    pub rows: usize,
    /// Height of the walls, m.
    pub wall_height: f64,
    /// Range noise 1σ at a distance `d`: `a + b·d`, metres (`[a, b]`).
    pub range_sigma: [f64; 2],
}

impl Sampling {
    /// The height of row `k`: rows spread evenly over the wall, half a row off
    /// the floor and the top.
    pub fn height(&self, k: usize) -> f64 {
        (k as f64 + 0.5) * self.wall_height / self.rows as f64
    }
}

/// Where the beam from `from` towards the centre of the cell at `index` first
/// enters a cell of `truth` that is not Free (that cell, or a nearer wall the
/// beam grazes on its way), world frame ([`Traversal`], in the grid's frame).
pub fn wall_hit(truth: &OccupancyGrid, from: Point, index: usize) -> Point {
    let g = truth.geometry();
    let cells = truth.cells();
    let r = g.resolution;
    let target = g.cell(index);
    let (sx, sy) = g.to_local(from);
    let centre = ((target.x as f64 + 0.5) * r, (target.y as f64 + 0.5) * r);
    let (dx, dy) = (centre.0 - sx, centre.1 - sy);
    let (tx, ty) = (target.x as i64, target.y as i64);
    let mut t = 0.0;
    for (x, y, entry) in Traversal::new(r, (sx, sy), centre) {
        t = entry;
        let solid = g
            .checked_cell(x, y)
            .is_none_or(|c| cells[g.index(c)] != CellState::Free);
        if solid || (x, y) == (tx, ty) {
            break;
        }
    }
    let t = t.clamp(0.0, 1.0);
    g.grid_to_world(sx + t * dx, sy + t * dy)
}

/// Appends the points of one scan to `out`: for every wall cell in `walls`
/// (indices into `truth`), `sampling.rows` points from the floor to the wall
/// height, each measured from `pose.truth` with range noise and expressed in the
/// estimated pose.
pub fn scan_points(
    truth: &OccupancyGrid,
    walls: &[usize],
    pose: &ScanPose,
    sampling: &Sampling,
    scan: u32,
    rng: &mut ChaCha8Rng,
    out: &mut Vec<ModelPoint>,
) {
    let [tx, ty, tz] = pose.truth;
    let [ex, ey, ez] = pose.estimate();
    let (s, c) = pose.heading_error.sin_cos();
    let from = Point::new(tx, ty);
    out.reserve(walls.len().saturating_mul(sampling.rows));
    for &w in walls {
        let hit = wall_hit(truth, from, w);
        for k in 0..sampling.rows {
            let v = [hit.x - tx, hit.y - ty, sampling.height(k) - tz];
            let range = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let sigma = sampling.range_sigma[0] + sampling.range_sigma[1] * range;
            let e: f64 = StandardNormal.sample(rng);
            let scale = if range > 0.0 {
                (range + sigma * e) / range
            } else {
                1.0
            };
            let q = [v[0] * scale, v[1] * scale, v[2] * scale];
            out.push(ModelPoint {
                position: [
                    ex + c * q[0] - s * q[1],
                    ey + s * q[0] + c * q[1],
                    ez + q[2],
                ],
                scan,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    use crate::geom::Cell;
    use crate::grid::GridGeometry;

    fn open(w: usize, h: usize, walls: &[(usize, usize)]) -> OccupancyGrid {
        let g = GridGeometry::new(w, h, 0.1, Point::new(0.0, 0.0));
        let mut grid = OccupancyGrid::filled(g, CellState::Free);
        for &(x, y) in walls {
            grid.set(Cell::new(x, y), CellState::Occupied);
        }
        grid
    }

    #[test]
    fn beams_enter_the_face_towards_the_scanner() {
        let t = open(10, 10, &[(8, 5)]);
        let g = *t.geometry();
        // Scanner at (0.25, 0.55); the cell (8, 5) spans x 0.8..0.9, y 0.5..0.6.
        let hit = wall_hit(&t, Point::new(0.25, 0.55), g.index(Cell::new(8, 5)));
        assert!((hit.x - 0.8).abs() < 1e-12 && (hit.y - 0.55).abs() < 1e-12);
        // Diagonal: from (0.05, 0.05) to cell (5, 5) enters at its corner.
        let t = open(10, 10, &[(5, 5)]);
        let hit = wall_hit(&t, Point::new(0.05, 0.05), g.index(Cell::new(5, 5)));
        assert!((hit.x - 0.5).abs() < 1e-9 && (hit.y - 0.5).abs() < 1e-9);
    }

    #[test]
    fn a_beam_stops_at_the_first_wall_it_grazes() {
        // A beam from (0.05, 0.05) towards cell (9, 2) passes through cell (4, 1).
        let t = open(10, 10, &[(9, 2), (4, 1)]);
        let g = *t.geometry();
        let hit = wall_hit(&t, Point::new(0.05, 0.05), g.index(Cell::new(9, 2)));
        let c = g
            .world_to_cell(Point::new(hit.x + 1e-9, hit.y + 1e-9))
            .unwrap();
        assert_eq!(c, Cell::new(4, 1), "{hit:?}");
        assert!((hit.x - 0.4).abs() < 1e-9 || (hit.y - 0.1).abs() < 1e-9);
    }

    #[test]
    fn a_rotated_and_shifted_estimate_moves_the_points_rigidly() {
        let t = open(10, 10, &[(8, 5)]);
        let walls = [t.geometry().index(Cell::new(8, 5))];
        let sampling = Sampling {
            rows: 4,
            wall_height: 2.0,
            range_sigma: [0.0, 0.0],
        };
        let truth = [0.25, 0.55, 1.0];
        let exact = ScanPose {
            truth,
            error: [0.0; 3],
            heading_error: 0.0,
        };
        let moved = ScanPose {
            truth,
            error: [0.01, -0.02, 0.003],
            heading_error: 0.5,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        scan_points(&t, &walls, &exact, &sampling, 0, &mut rng, &mut a);
        scan_points(&t, &walls, &moved, &sampling, 0, &mut rng, &mut b);
        assert_eq!(a.len(), 4);
        let heights: Vec<f64> = a.iter().map(|p| p.position[2]).collect();
        assert_eq!(heights, vec![0.25, 0.75, 1.25, 1.75]);
        for (p, q) in a.iter().zip(&b) {
            // The same distance from the (estimated) scanner.
            let d = |p: &ModelPoint, s: [f64; 3]| {
                (0..3)
                    .map(|i| (p.position[i] - s[i]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            assert!((d(p, truth) - d(q, moved.estimate())).abs() < 1e-12);
            assert!((p.position[0] - 0.8).abs() < 1e-12);
        }
    }

    #[test]
    fn range_noise_has_the_stated_spread() {
        let t = open(200, 10, &[(150, 5)]);
        let walls = [t.geometry().index(Cell::new(150, 5))];
        let sampling = Sampling {
            rows: 20_000,
            wall_height: 1.0,
            range_sigma: [0.002, 0.0],
        };
        let pose = ScanPose {
            truth: [0.05, 0.55, 0.5],
            error: [0.0; 3],
            heading_error: 0.0,
        };
        let mut out = Vec::new();
        scan_points(
            &t,
            &walls,
            &pose,
            &sampling,
            3,
            &mut ChaCha8Rng::seed_from_u64(7),
            &mut out,
        );
        // Along a near-horizontal beam the noise is almost all in x.
        let dx: Vec<f64> = out.iter().map(|p| p.position[0] - 15.0).collect();
        let mean = dx.iter().sum::<f64>() / dx.len() as f64;
        let sd = (dx.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / dx.len() as f64).sqrt();
        assert!(mean.abs() < 1e-4, "mean {mean}");
        assert!((sd - 0.002).abs() < 1e-4, "sd {sd}");
        assert!(out.iter().all(|p| p.scan == 3));
    }
}
