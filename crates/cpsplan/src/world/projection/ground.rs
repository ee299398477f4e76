//! The ground under the cloud: the height every obstacle height is measured
//! from.
//!
//! - none: the ground is `z = 0` (absolute heights);
//! - plane: a plane through the lowest point of every tile, found by RANSAC
//!   (the plane that most tiles lie within a tolerance of, so roofs, canopies
//!   and tables do not tilt it) and refined by least squares on those tiles;
//! - lowest: under every cell, the lowest point within a window around it (a
//!   morphological erosion of the cells' lowest points).

use nalgebra::{Matrix3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::HeightBand;
use crate::geom::Point;
use crate::grid::GridGeometry;

/// How the ground is estimated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GroundModel {
    /// No estimate: heights are absolute `z`.
    None,
    /// One plane under the whole cloud.
    Plane,
    /// The lowest point within `window` metres of each cell.
    Lowest {
        /// Half-width of the square window, metres.
        window: f64,
    },
}

impl GroundModel {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GroundModel::None => "none",
            GroundModel::Plane => "plane",
            GroundModel::Lowest { .. } => "lowest",
        }
    }
}

/// The estimated ground.
#[derive(Debug, Clone, PartialEq)]
pub enum Ground {
    /// `z = 0` everywhere.
    Flat,
    /// `z = a·(x − x0) + b·(y − y0) + c`.
    Plane {
        /// Slope along x.
        a: f64,
        /// Slope along y.
        b: f64,
        /// Height at `(x0, y0)`.
        c: f64,
        /// Where the plane's height is `c` (the tiles' centroid).
        at: Point,
        /// Tiles the plane rests on.
        support: usize,
        /// The grid whose cell centres the heights are taken at.
        geometry: GridGeometry,
    },
    /// A height per cell, row-major (`f64::INFINITY` where no point is near).
    Cells(Vec<f64>),
}

/// Side of the plane fit's tiles, metres (at least two cells).
const TILE_M: f64 = 1.0;

/// A tile whose lowest point lies farther than this from the plane is not on it.
const PLANE_TOLERANCE_M: f64 = 0.15;

/// RANSAC trials (three tiles each; fixed seed, so the fit is reproducible).
const PLANE_TRIALS: usize = 500;

/// Least-squares refits on the inliers at most.
const PLANE_ROUNDS: usize = 5;

impl Ground {
    /// The ground under `geometry`'s cells estimated from the kept points.
    pub fn estimate(
        model: GroundModel,
        band: HeightBand,
        points: &[[f64; 3]],
        keep: &[bool],
        geometry: &GridGeometry,
    ) -> Ground {
        if matches!(band, HeightBand::Absolute { .. }) {
            return Ground::Flat;
        }
        match model {
            GroundModel::None => Ground::Flat,
            GroundModel::Plane => plane(points, keep, geometry),
            GroundModel::Lowest { window } => Ground::Cells(lowest(points, keep, geometry, window)),
        }
    }

    /// The ground's height under cell `index`.
    #[inline]
    pub fn height(&self, index: usize) -> f64 {
        match self {
            Ground::Flat => 0.0,
            Ground::Plane {
                a,
                b,
                c,
                at,
                geometry,
                ..
            } => {
                let q = geometry.cell_center(geometry.cell(index));
                a * (q.x - at.x) + b * (q.y - at.y) + c
            }
            Ground::Cells(cells) => cells[index],
        }
    }

    /// A few words for people.
    pub fn describe(&self) -> String {
        match self {
            Ground::Flat => "none (absolute heights)".into(),
            Ground::Plane {
                a,
                b,
                c,
                at,
                support,
                ..
            } => format!(
                "plane z = {c:.3} m at ({:.2}, {:.2}), slope {:.3} % along x and {:.3} % along y, \
                 fitted to {support} tiles",
                at.x,
                at.y,
                100.0 * a,
                100.0 * b
            ),
            Ground::Cells(h) => {
                let known: Vec<f64> = h.iter().copied().filter(|v| v.is_finite()).collect();
                let (lo, hi) = known
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, u), &v| {
                        (l.min(v), u.max(v))
                    });
                format!("lowest points, from {lo:.2} m to {hi:.2} m")
            }
        }
    }
}

/// The lowest kept point of every cell (`INFINITY` where none).
fn cell_minima(points: &[[f64; 3]], keep: &[bool], geometry: &GridGeometry) -> Vec<f64> {
    let mut low = vec![f64::INFINITY; geometry.len()];
    for (p, _) in points.iter().zip(keep).filter(|(_, &k)| k) {
        if let Some(c) = geometry.world_to_cell(Point::new(p[0], p[1])) {
            let i = geometry.index(c);
            low[i] = low[i].min(p[2]);
        }
    }
    low
}

fn plane(points: &[[f64; 3]], keep: &[bool], geometry: &GridGeometry) -> Ground {
    let r = geometry.resolution;
    let k = ((TILE_M / r).round() as usize).max(2);
    let (tw, th) = (geometry.width.div_ceil(k), geometry.height.div_ceil(k));
    let mut tiles: Vec<Option<[f64; 3]>> = vec![None; tw.saturating_mul(th)];
    for (p, _) in points.iter().zip(keep).filter(|(_, &k)| k) {
        if let Some(c) = geometry.world_to_cell(Point::new(p[0], p[1])) {
            let t = &mut tiles[(c.y / k) * tw + c.x / k];
            if t.is_none_or(|q| p[2] < q[2]) {
                *t = Some(*p);
            }
        }
    }
    let tiles: Vec<[f64; 3]> = tiles.into_iter().flatten().collect();
    let n = tiles.len().max(1) as f64;
    let at = Point::new(
        tiles.iter().map(|p| p[0]).sum::<f64>() / n,
        tiles.iter().map(|p| p[1]).sum::<f64>() / n,
    );
    let (mut a, mut b, mut c) = ransac(&tiles, at);
    let mut used = inliers(&tiles, at, (a, b, c));
    for _ in 0..PLANE_ROUNDS {
        let Some((na, nb, nc)) = fit(&tiles, &used, at) else {
            break;
        };
        (a, b, c) = (na, nb, nc);
        let next = inliers(&tiles, at, (a, b, c));
        if next == used {
            break;
        }
        used = next;
    }
    let support = used.iter().filter(|&&u| u).count();
    Ground::Plane {
        a,
        b,
        c,
        at,
        support,
        geometry: *geometry,
    }
}

/// Which tiles lie within the tolerance of the plane `(a, b, c)`.
fn inliers(tiles: &[[f64; 3]], at: Point, (a, b, c): (f64, f64, f64)) -> Vec<bool> {
    tiles
        .iter()
        .map(|p| (p[2] - (a * (p[0] - at.x) + b * (p[1] - at.y) + c)).abs() <= PLANE_TOLERANCE_M)
        .collect()
}

/// The plane through three tiles that most tiles lie near (ties: the lower
/// plane at the tiles' centroid); a level plane at the lowest tile when fewer
/// than three tiles or no trial gives a plane. Planes steeper than 45° are not
/// ground.
fn ransac(tiles: &[[f64; 3]], at: Point) -> (f64, f64, f64) {
    let lowest = tiles.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    let mut best = (0.0, 0.0, if lowest.is_finite() { lowest } else { 0.0 });
    if tiles.len() < 3 {
        return best;
    }
    let mut best_count = inliers(tiles, at, best).iter().filter(|&&u| u).count();
    let mut rng = ChaCha8Rng::seed_from_u64(0x6772_6f75_6e64);
    for _ in 0..PLANE_TRIALS {
        let pick = |rng: &mut ChaCha8Rng| tiles[rng.random_range(0..tiles.len())];
        let (p, q, r) = (pick(&mut rng), pick(&mut rng), pick(&mut rng));
        let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let norm = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        // Degenerate trios and steep planes (walls) are skipped.
        if norm < 1e-12 || n[2].abs() < std::f64::consts::FRAC_1_SQRT_2 * norm {
            continue;
        }
        let (a, b) = (-n[0] / n[2], -n[1] / n[2]);
        let c = p[2] - a * (p[0] - at.x) - b * (p[1] - at.y);
        let count = inliers(tiles, at, (a, b, c)).iter().filter(|&&u| u).count();
        if count > best_count || (count == best_count && c < best.2) {
            best = (a, b, c);
            best_count = count;
        }
    }
    best
}

/// Least-squares plane `z = a·dx + b·dy + c` through the used tiles; `None`
/// with fewer than three or a degenerate layout (then the plane is level).
fn fit(tiles: &[[f64; 3]], used: &[bool], at: Point) -> Option<(f64, f64, f64)> {
    let mut m = Matrix3::zeros();
    let mut v = Vector3::zeros();
    let mut count = 0usize;
    for (p, _) in tiles.iter().zip(used).filter(|(_, &u)| u) {
        let row = Vector3::new(p[0] - at.x, p[1] - at.y, 1.0);
        m += row * row.transpose();
        v += row * p[2];
        count += 1;
    }
    if count == 0 {
        return None;
    }
    if count >= 3 {
        if let Some(x) = m.lu().solve(&v) {
            if x.iter().all(|e| e.is_finite()) {
                return Some((x[0], x[1], x[2]));
            }
        }
    }
    Some((0.0, 0.0, v[2] / count as f64))
}

/// The ground of `lowest`: every cell's minimum, eroded over a square window of
/// half-width `window` metres (van Herk / Gil–Werman: three comparisons per
/// cell and pass, whatever the window).
fn lowest(points: &[[f64; 3]], keep: &[bool], geometry: &GridGeometry, window: f64) -> Vec<f64> {
    let (w, h) = (geometry.width, geometry.height);
    let half = ((window / geometry.resolution).round() as usize).min(w.max(h));
    let mut low = cell_minima(points, keep, geometry);
    if half == 0 {
        return low;
    }
    let mut line = Vec::new();
    let mut out = Vec::new();
    for y in 0..h {
        line.clear();
        line.extend_from_slice(&low[y * w..(y + 1) * w]);
        erode(&line, half, &mut out);
        low[y * w..(y + 1) * w].copy_from_slice(&out);
    }
    for x in 0..w {
        line.clear();
        line.extend((0..h).map(|y| low[y * w + x]));
        erode(&line, half, &mut out);
        for (y, &v) in out.iter().enumerate() {
            low[y * w + x] = v;
        }
    }
    low
}

/// `out[i]` = the minimum of `v[i − half ..= i + half]` (clipped to `v`).
fn erode(v: &[f64], half: usize, out: &mut Vec<f64>) {
    let n = v.len();
    let k = 2 * half + 1;
    // Pad with +∞ so every window lies inside; block prefix and suffix minima.
    let padded = n + 2 * half;
    let len = padded.div_ceil(k) * k;
    let at = |i: usize| {
        if i >= half && i - half < n {
            v[i - half]
        } else {
            f64::INFINITY
        }
    };
    let mut pre = vec![f64::INFINITY; len];
    let mut suf = vec![f64::INFINITY; len];
    for i in 0..len {
        pre[i] = if i % k == 0 {
            at(i)
        } else {
            pre[i - 1].min(at(i))
        };
    }
    for i in (0..len).rev() {
        suf[i] = if i % k == k - 1 || i + 1 == len {
            at(i)
        } else {
            suf[i + 1].min(at(i))
        };
    }
    out.clear();
    // Window of padded positions [i, i + k − 1] for output i.
    out.extend((0..n).map(|i| suf[i].min(pre[i + k - 1])));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erosion_is_the_window_minimum() {
        let v: Vec<f64> = [5.0, 3.0, 8.0, 1.0, 9.0, 7.0, 6.0, 2.0, 4.0].to_vec();
        for half in 0..5 {
            let mut out = Vec::new();
            erode(&v, half, &mut out);
            for (i, &o) in out.iter().enumerate() {
                let lo = i.saturating_sub(half);
                let hi = (i + half).min(v.len() - 1);
                let m = v[lo..=hi].iter().copied().fold(f64::INFINITY, f64::min);
                assert_eq!(o, m, "half {half} at {i}");
            }
            assert_eq!(out.len(), v.len());
        }
    }

    #[test]
    fn the_plane_rests_on_the_floor_under_furniture() {
        // A 10 m × 10 m floor tilted by 1 % along x at z = -1.5, with a 2 m
        // box of tables at z = -0.7 over a quarter of it.
        let g = GridGeometry::new(100, 100, 0.1, Point::new(0.0, 0.0));
        let mut pts = Vec::new();
        for i in 0..100 {
            for j in 0..100 {
                let (x, y) = (i as f64 * 0.1 + 0.05, j as f64 * 0.1 + 0.05);
                let floor = -1.5 + 0.01 * x;
                pts.push([x, y, if i < 50 && j < 50 { floor + 0.8 } else { floor }]);
            }
        }
        let keep = vec![true; pts.len()];
        let ground = plane(&pts, &keep, &g);
        let Ground::Plane { a, b, .. } = ground else {
            panic!("a plane")
        };
        assert!((a - 0.01).abs() < 1e-6 && b.abs() < 1e-6, "{a} {b}");
        for &i in &[0usize, 5050, 9999] {
            let q = g.cell_center(g.cell(i));
            assert!((ground.height(i) - (-1.5 + 0.01 * q.x)).abs() < 1e-6);
        }
    }
}
