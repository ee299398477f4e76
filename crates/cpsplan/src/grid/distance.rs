//! Exact Euclidean distance transform: for every cell, the distance in cells from
//! its centre to the centre of the nearest obstacle cell. The column pass is two
//! linear sweeps (Meijster et al. 2000), the row pass the lower envelope of
//! parabolas (Felzenszwalb & Huttenlocher 2012), rows in parallel. O(cells), no
//! saturation. The envelope's breakpoints are kept as exact fractions and
//! compared by cross-multiplication in integers, so every distance is the square
//! root of the exact minimum squared distance.

use rayon::prelude::*;

use crate::grid::GridGeometry;

/// Distance value used where the grid holds no obstacle at all.
pub const NO_OBSTACLE: f32 = f32::INFINITY;

const NONE: u32 = u32::MAX;

/// Distances in cells from each cell to the nearest cell with `is_obstacle(index)`;
/// [`NO_OBSTACLE`] everywhere if there is none.
pub fn distance_transform(
    geometry: &GridGeometry,
    is_obstacle: impl Fn(usize) -> bool,
) -> Vec<f32> {
    let w = geometry.width;
    transform(w, geometry.height, |x, y| is_obstacle(y * w + x))
}

/// The transform of a `width × height` window; `is_obstacle(x, y)` in window
/// coordinates. Row-major output, row 0 first.
pub fn transform(
    width: usize,
    height: usize,
    is_obstacle: impl Fn(usize, usize) -> bool,
) -> Vec<f32> {
    let (w, h) = (width, height);
    if w == 0 || h == 0 {
        return Vec::new();
    }
    // Column pass: vertical distance to the nearest obstacle in the same column.
    let mut g = vec![NONE; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            g[i] = if is_obstacle(x, y) {
                0
            } else if y > 0 {
                g[i - w].saturating_add(1)
            } else {
                NONE
            };
        }
    }
    for y in (0..h - 1).rev() {
        let (row, below) = g.split_at_mut((y + 1) * w);
        let row = &mut row[y * w..];
        for (a, &b) in row.iter_mut().zip(&below[..w]) {
            let up = b.saturating_add(1);
            if up < *a {
                *a = up;
            }
        }
    }
    // Row pass.
    let mut out = vec![NO_OBSTACLE; w * h];
    out.par_chunks_mut(w).zip(g.par_chunks(w)).for_each_init(
        || (vec![0usize; w], vec![Breakpoint::MIN; w + 1]),
        |(v, z), (out_row, g_row)| envelope(g_row, out_row, v, z),
    );
    out
}

/// Where two parabolas of the envelope cross: the abscissa `num / den` (`den > 0`),
/// or ±∞.
#[derive(Debug, Clone, Copy)]
struct Breakpoint {
    num: i64,
    den: i64,
}

impl Breakpoint {
    const MIN: Self = Self { num: -1, den: 0 };
    const MAX: Self = Self { num: 1, den: 0 };

    /// `self ≤ other`, exactly. With `|num| < (w² + h²)` and `den ≤ 2w` the products
    /// stay far inside `i64` for any grid that fits in memory.
    fn le(self, other: Self) -> bool {
        match (self.den, other.den) {
            (0, 0) => self.num <= other.num,
            (0, _) => self.num < 0,
            (_, 0) => other.num > 0,
            _ => self.num * other.den <= other.num * self.den,
        }
    }

    /// `self < q` for a column `q`, exactly.
    fn lt_column(self, q: usize) -> bool {
        if self.den == 0 {
            self.num < 0
        } else {
            self.num < q as i64 * self.den
        }
    }
}

/// Lower envelope of the parabolas `(x − u)² + g[u]²` over the columns `u` with a
/// finite `g[u]`, sampled at every column.
fn envelope(g: &[u32], out: &mut [f32], v: &mut [usize], z: &mut [Breakpoint]) {
    lower_envelope(g, v, z, |q, p| {
        let dx = q.abs_diff(p) as u64;
        let gp = g[p] as u64;
        out[q] = ((dx * dx + gp * gp) as f64).sqrt() as f32;
    });
}

/// The lower envelope of the parabolas `(x − u)² + g[u]²` over the columns `u`
/// with `g[u]` not [`NONE`]: `emit(q, p)` for every column `q`, with `p` the
/// column whose parabola is lowest at `q` (nothing if every `g[u]` is `NONE`).
/// `v` and `z` are working buffers of `g.len()` and `g.len() + 1` entries.
fn lower_envelope(
    g: &[u32],
    v: &mut [usize],
    z: &mut [Breakpoint],
    mut emit: impl FnMut(usize, usize),
) {
    let f = |u: usize| {
        let gu = g[u] as i64;
        gu * gu + (u * u) as i64
    };
    let mut k: usize = 0;
    let mut any = false;
    for (q, &gq) in g.iter().enumerate() {
        if gq == NONE {
            continue;
        }
        if !any {
            any = true;
            v[0] = q;
            z[0] = Breakpoint::MIN;
            z[1] = Breakpoint::MAX;
            continue;
        }
        let fq = f(q);
        let mut s;
        loop {
            let p = v[k];
            s = Breakpoint {
                num: fq - f(p),
                den: 2 * (q as i64 - p as i64),
            };
            // z[0] is −∞, so this never steps below the first parabola.
            if s.le(z[k]) {
                k -= 1;
            } else {
                break;
            }
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = Breakpoint::MAX;
    }
    if !any {
        return;
    }
    k = 0;
    for q in 0..g.len() {
        while z[k + 1].lt_column(q) {
            k += 1;
        }
        emit(q, v[k]);
    }
}

/// Exact Euclidean feature transform of a `width × height` window in which every
/// column holds an obstacle cell (`obstacle`, row-major): per cell the column and
/// row of a nearest obstacle cell, and the squared distance to it.
#[cfg(test)]
pub(crate) fn feature_transform(
    width: usize,
    height: usize,
    obstacle: &[bool],
) -> (Vec<(u32, u32)>, Vec<u32>) {
    let mut buffers = FeatureBuffers::default();
    feature_transform_into(width, height, obstacle, &mut buffers);
    (buffers.feature, buffers.d2)
}

/// The buffers of a feature transform, kept between calls so that a repeated
/// transform reuses their memory.
#[derive(Debug, Default)]
pub(crate) struct FeatureBuffers {
    /// Per cell: the row of the nearest obstacle cell in its column.
    near: Vec<u32>,
    /// Per cell: column and row of a nearest obstacle cell.
    pub feature: Vec<(u32, u32)>,
    /// Per cell: the squared distance to it.
    pub d2: Vec<u32>,
}

impl FeatureBuffers {
    /// Cells the buffers have room for.
    pub fn capacity(&self) -> usize {
        self.feature.capacity()
    }
}

/// [`feature_transform`] into `out` (its `feature` and `d2`, resized to the
/// window).
pub(crate) fn feature_transform_into(
    width: usize,
    height: usize,
    obstacle: &[bool],
    out: &mut FeatureBuffers,
) {
    let (w, h) = (width, height);
    let n = w * h;
    let near = &mut out.near;
    near.clear();
    near.resize(n, NONE);
    nearest_rows(w, h, obstacle, 0, w, near);
    let near = &out.near;
    let (feature, d2) = (&mut out.feature, &mut out.d2);
    feature.clear();
    feature.resize(n, (0, 0));
    d2.clear();
    d2.resize(n, 0);
    feature
        .par_chunks_mut(w)
        .zip(d2.par_chunks_mut(w))
        .enumerate()
        .for_each_init(
            || RowBuffers::new(w),
            |buffers, (y, (feat_row, d2_row))| {
                row_features(y, &near[y * w..][..w], buffers, feat_row, d2_row)
            },
        );
}

/// The column pass over the columns `x0..x0 + cw` of a `w × h` window: per cell
/// the row of the nearest obstacle cell in its column (ties: the lower row), into
/// `out`, a `cw × h` row-major buffer.
fn nearest_rows(w: usize, h: usize, obstacle: &[bool], x0: usize, cw: usize, out: &mut [u32]) {
    for y in 0..h {
        for x in 0..cw {
            let (i, o) = (y * w + x0 + x, y * cw + x);
            out[o] = if obstacle[i] {
                y as u32
            } else if y > 0 {
                out[o - cw]
            } else {
                NONE
            };
        }
    }
    for y in (0..h.saturating_sub(1)).rev() {
        for x in 0..cw {
            let o = y * cw + x;
            let up = out[o + cw];
            if out[o] == NONE || up.abs_diff(y as u32) < out[o].abs_diff(y as u32) {
                out[o] = up;
            }
        }
    }
}

/// Working buffers of one row of the row pass.
struct RowBuffers {
    g: Vec<u32>,
    v: Vec<usize>,
    z: Vec<Breakpoint>,
}

impl RowBuffers {
    fn new(w: usize) -> Self {
        Self {
            g: vec![0; w],
            v: vec![0; w],
            z: vec![Breakpoint::MIN; w + 1],
        }
    }
}

/// The row pass of row `y`: from the column pass's rows `near_row`, every cell's
/// nearest obstacle cell and squared distance.
fn row_features(
    y: usize,
    near_row: &[u32],
    b: &mut RowBuffers,
    feat_row: &mut [(u32, u32)],
    d2_row: &mut [u32],
) {
    let RowBuffers { g, v, z } = b;
    for (gx, &r) in g.iter_mut().zip(near_row) {
        *gx = if r == NONE {
            NONE
        } else {
            r.abs_diff(y as u32)
        };
    }
    lower_envelope(g, v, z, |q, p| {
        let dx = q.abs_diff(p) as u32;
        feat_row[q] = (p as u32, near_row[p]);
        d2_row[q] = dx * dx + g[p] * g[p];
    });
}

impl FeatureBuffers {
    /// Brings the transform of a `width × height` window (computed by
    /// [`feature_transform_into`]) up to date after `obstacle` changed only in the
    /// columns `columns`: the column pass is redone in those columns, and the row
    /// pass in the rows where it changed. Appends to `changes` every row whose
    /// features changed, with the first and last column that did, `(row, x0,
    /// x1)`, rows in increasing order.
    pub fn update(
        &mut self,
        width: usize,
        height: usize,
        obstacle: &[bool],
        columns: std::ops::RangeInclusive<usize>,
        changes: &mut Vec<(usize, usize, usize)>,
    ) {
        let (w, h) = (width, height);
        let (x0, x1) = (*columns.start(), (*columns.end()).min(w.saturating_sub(1)));
        if x0 > x1 || h == 0 {
            return;
        }
        let cw = x1 - x0 + 1;
        let mut fresh = vec![NONE; cw * h];
        nearest_rows(w, h, obstacle, x0, cw, &mut fresh);
        let mut rows = vec![false; h];
        for (y, new) in fresh.chunks_exact(cw).enumerate() {
            let old = &mut self.near[y * w + x0..][..cw];
            if old != new {
                old.copy_from_slice(new);
                rows[y] = true;
            }
        }
        let near = &self.near;
        let found: Vec<(usize, usize, usize)> = self
            .feature
            .par_chunks_mut(w)
            .zip(self.d2.par_chunks_mut(w))
            .enumerate()
            .filter(|(y, _)| rows[*y])
            .map_init(
                || (RowBuffers::new(w), vec![(0, 0); w], vec![0; w]),
                |(buffers, feat, dist), (y, (feat_row, d2_row))| {
                    row_features(y, &near[y * w..][..w], buffers, feat, dist);
                    let differs = |x: &usize| feat[*x] != feat_row[*x] || dist[*x] != d2_row[*x];
                    let first = (0..w).find(differs)?;
                    let last = (0..w).rfind(differs)?;
                    feat_row[first..=last].copy_from_slice(&feat[first..=last]);
                    d2_row[first..=last].copy_from_slice(&dist[first..=last]);
                    Some((y, first, last))
                },
            )
            .flatten()
            .collect();
        changes.extend(found);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use proptest::prelude::*;

    proptest! {
        /// Every feature is an obstacle cell at the least squared distance.
        #[test]
        fn features_are_nearest_obstacles(w in 1usize..14, h in 1usize..14, bits in proptest::collection::vec(0u8..6, 196)) {
            // Every column holds an obstacle: the top row is solid.
            let obstacle: Vec<bool> = (0..w * h).map(|i| bits[i] == 0 || i / w == h - 1).collect();
            let (feature, d2) = feature_transform(w, h, &obstacle);
            for i in 0..w * h {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                let best = (0..w * h)
                    .filter(|&j| obstacle[j])
                    .map(|j| (x - (j % w) as i64).pow(2) + (y - (j / w) as i64).pow(2))
                    .min()
                    .unwrap();
                prop_assert_eq!(d2[i] as i64, best, "cell {}", i);
                let (fx, fy) = feature[i];
                prop_assert!(obstacle[fy as usize * w + fx as usize]);
                prop_assert_eq!((x - fx as i64).pow(2) + (y - fy as i64).pow(2), best);
            }
        }

        #[test]
        fn matches_brute_force(w in 1usize..14, h in 1usize..14, bits in proptest::collection::vec(0u8..6, 196)) {
            let g = GridGeometry::new(w, h, 1.0, Point::default());
            let obstacle = |i: usize| bits[i] == 0;
            let got = distance_transform(&g, obstacle);
            for (i, &got_i) in got.iter().enumerate() {
                let c = g.cell(i);
                let mut best = f64::INFINITY;
                for j in 0..w * h {
                    if obstacle(j) {
                        let o = g.cell(j);
                        let dx = c.x as f64 - o.x as f64;
                        let dy = c.y as f64 - o.y as f64;
                        best = best.min((dx * dx + dy * dy).sqrt());
                    }
                }
                if best.is_infinite() {
                    prop_assert_eq!(got_i, NO_OBSTACLE);
                } else {
                    prop_assert!((got_i as f64 - best).abs() < 1e-4, "cell {:?}: {} vs {}", c, got_i, best);
                    // Exactly the square root of the least squared distance.
                    prop_assert_eq!(got_i.to_bits(), (best as f32).to_bits());
                }
            }
        }
    }
}
