//! Exact Euclidean distance transform: for every cell, the distance in cells from
//! its centre to the centre of the nearest obstacle cell. The column pass is two
//! linear sweeps (Meijster et al. 2000), the row pass the lower envelope of
//! parabolas (Felzenszwalb & Huttenlocher 2012), rows in parallel. O(cells), no
//! saturation. The envelope's breakpoints are kept as exact fractions and
//! compared by cross-multiplication in integers, so every distance is the square
//! root of the exact minimum squared distance.

use std::ops::{Range, RangeInclusive};

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
    lower_envelope(g, v, z, 0..g.len(), |q, p| {
        let dx = q.abs_diff(p) as u64;
        let gp = g[p] as u64;
        out[q] = ((dx * dx + gp * gp) as f64).sqrt() as f32;
    });
}

/// The lower envelope of the parabolas `(x − u)² + g[u]²` over the columns `u`
/// with `g[u]` not [`NONE`]: `emit(q, p)` for every column `q` of `columns`, with
/// `p` the column whose parabola is lowest at `q` (nothing if every `g[u]` is
/// `NONE`). `v` and `z` are working buffers of `g.len()` and `g.len() + 1`
/// entries.
///
/// Of several lowest parabolas at `q`, `p` is the one of the least column: below
/// `q` it is the lowest of them (their differences are linear in `x`), so `q` is
/// the right end of its interval, which the sampling keeps. `p` thus depends only
/// on the parabolas lowest at `q`, not on the others, which lets a row's update
/// leave out the parabolas that cannot be lowest where it samples.
fn lower_envelope(
    g: &[u32],
    v: &mut [usize],
    z: &mut [Breakpoint],
    columns: Range<usize>,
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
    for q in columns {
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
    /// Per row: the largest squared distance in it (0 for none).
    pub row_max: Vec<u32>,
}

impl FeatureBuffers {
    /// Cells the buffers have room for.
    pub fn capacity(&self) -> usize {
        self.feature.capacity()
    }
}

/// [`feature_transform`] into `out` (its `feature`, `d2` and `row_max`, resized
/// to the window).
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
    let row_max = &mut out.row_max;
    row_max.clear();
    row_max.resize(h, 0);
    if w == 0 {
        return;
    }
    feature
        .par_chunks_mut(w)
        .zip(d2.par_chunks_mut(w))
        .zip(row_max.par_iter_mut())
        .enumerate()
        .for_each_init(
            || EnvelopeBuffers::new(w),
            |buffers, (y, ((feat_row, d2_row), top))| {
                row_features(y, &near[y * w..][..w], 0, 0..w, buffers, feat_row, d2_row);
                *top = d2_row.iter().copied().max().unwrap_or(0);
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

/// Working buffers of the lower envelope over a row of `w` columns.
struct EnvelopeBuffers {
    g: Vec<u32>,
    v: Vec<usize>,
    z: Vec<Breakpoint>,
}

impl EnvelopeBuffers {
    fn new(w: usize) -> Self {
        Self {
            g: vec![0; w],
            v: vec![0; w],
            z: vec![Breakpoint::MIN; w + 1],
        }
    }
}

/// Working buffers of one row's update.
struct RowBuffers {
    envelope: EnvelopeBuffers,
    /// The features and squared distances the update computes.
    feat: Vec<(u32, u32)>,
    dist: Vec<u32>,
}

impl RowBuffers {
    fn new(w: usize) -> Self {
        Self {
            envelope: EnvelopeBuffers::new(w),
            feat: Vec::new(),
            dist: Vec::new(),
        }
    }
}

/// The distance `|r − y|` from row `y` to the obstacle row `r` of a column, or
/// [`NONE`] for a column without one.
fn column_gap(r: u32, y: usize) -> u32 {
    if r == NONE {
        NONE
    } else {
        r.abs_diff(y as u32)
    }
}

/// The row pass of row `y` over its columns `base..base + near.len()` (`near`:
/// their column pass), sampled at the columns `base + q` for `q` in `columns`:
/// each one's nearest obstacle cell among those columns into `feat`, and its
/// squared distance into `d2`, both from index 0.
fn row_features(
    y: usize,
    near: &[u32],
    base: usize,
    columns: Range<usize>,
    e: &mut EnvelopeBuffers,
    feat: &mut [(u32, u32)],
    d2: &mut [u32],
) {
    let n = near.len();
    for (gx, &r) in e.g[..n].iter_mut().zip(near) {
        *gx = column_gap(r, y);
    }
    let g = &e.g[..n];
    let first = columns.start;
    lower_envelope(g, &mut e.v[..n], &mut e.z[..=n], columns, |q, p| {
        let dx = q.abs_diff(p) as u32;
        feat[q - first] = ((p + base) as u32, near[p]);
        d2[q - first] = dx * dx + g[p] * g[p];
    });
}

/// The row pass of row `y` again after the column pass changed in its columns
/// `c0..=c1` only (`near_row`: the new column pass; `feat_row`, `d2_row`,
/// `row_max`: the row's features, squared distances and largest squared
/// distance before, brought up to date). Returns the first and last column
/// whose feature or distance changed.
///
/// Only cells `q` with `gap(q, c0..=c1)² ≤ d2(q)` can change: a changed column
/// farther away than the old distance is not lowest at `q`, before or after, and
/// the parabolas lowest at `q` decide its feature ([`lower_envelope`]). They lie
/// within `row_max`'s square root of `c0..=c1`. A cell `q`'s new nearest column
/// lies within `|near_row[q] − y|` of it (its own column holds an obstacle that
/// near), so the envelope over those columns around the changed cells decides
/// them. Every column outside is left out.
fn row_update(
    y: usize,
    near_row: &[u32],
    (c0, c1): (usize, usize),
    b: &mut RowBuffers,
    (feat_row, d2_row, row_max): (&mut [(u32, u32)], &mut [u32], &mut u32),
) -> Option<(usize, usize)> {
    let w = near_row.len();
    let reach = (*row_max as f64).sqrt() as usize + 1;
    let (lo, hi) = (
        c0.saturating_sub(reach),
        c1.saturating_add(reach).min(w - 1),
    );
    let gap = |q: usize| q.abs_diff(q.clamp(c0, c1)) as u64;
    let affected = |q: &usize| gap(*q).pow(2) <= d2_row[*q] as u64;
    let qa = (lo..=hi).find(affected)?;
    let qb = (qa..=hi).rfind(affected)?;
    let around = (qa..=qb)
        .map(|q| column_gap(near_row[q], y))
        .max()
        .filter(|&m| m != NONE)
        .map_or(w, |m| m as usize);
    let (ua, ub) = (
        qa.saturating_sub(around),
        qb.saturating_add(around).min(w - 1),
    );
    let RowBuffers {
        envelope,
        feat,
        dist,
    } = b;
    feat.clear();
    feat.extend_from_slice(&feat_row[qa..=qb]);
    dist.clear();
    dist.extend_from_slice(&d2_row[qa..=qb]);
    let (window, columns) = (&near_row[ua..=ub], qa - ua..qb - ua + 1);
    row_features(y, window, ua, columns, envelope, feat, dist);
    let differs = |j: &usize| feat[*j] != feat_row[qa + j] || dist[*j] != d2_row[qa + j];
    let first = (0..feat.len()).find(differs)?;
    let last = (0..feat.len()).rfind(differs)?;
    let old_top = d2_row[qa + first..=qa + last]
        .iter()
        .copied()
        .max()
        .unwrap_or(0);
    feat_row[qa + first..=qa + last].copy_from_slice(&feat[first..=last]);
    d2_row[qa + first..=qa + last].copy_from_slice(&dist[first..=last]);
    let new_top = dist[first..=last].iter().copied().max().unwrap_or(0);
    *row_max = if new_top >= *row_max {
        new_top
    } else if old_top < *row_max {
        *row_max // the largest lies outside what changed
    } else {
        d2_row.iter().copied().max().unwrap_or(0)
    };
    Some((qa + first, qa + last))
}

impl FeatureBuffers {
    /// Brings the transform of a `width × height` window (computed by
    /// [`feature_transform_into`]) up to date after `obstacle` changed only in the
    /// rectangle of `columns` and `rows`: the column pass is redone in those
    /// columns, between the obstacles above and below the rectangle, and the row
    /// pass in the rows where it changed, around the columns where it did
    /// ([`row_update`]). Appends to `changes` every row whose features changed,
    /// with the first and last column that did, `(row, x0, x1)`, rows in
    /// increasing order.
    pub fn update(
        &mut self,
        width: usize,
        height: usize,
        obstacle: &[bool],
        (columns, rows): (RangeInclusive<usize>, RangeInclusive<usize>),
        changes: &mut Vec<(usize, usize, usize)>,
    ) {
        let (w, h) = (width, height);
        let (x0, x1) = (*columns.start(), (*columns.end()).min(w.saturating_sub(1)));
        let (ya, yb) = (*rows.start(), (*rows.end()).min(h.saturating_sub(1)));
        if x0 > x1 || ya > yb {
            return;
        }
        let cw = x1 - x0 + 1;
        // Per column: the obstacle rows just above and below the rectangle (or
        // the window's edge). A cell outside them keeps its nearest obstacle row.
        let solid = |x: usize| move |y: &usize| obstacle[*y * w + x];
        let above: Vec<usize> = (x0..=x1)
            .map(|x| (0..ya).rfind(solid(x)).unwrap_or(0))
            .collect();
        let below: Vec<usize> = (x0..=x1)
            .map(|x| (yb + 1..h).find(solid(x)).unwrap_or(h - 1))
            .collect();
        let (t, b) = match (above.iter().min(), below.iter().max()) {
            (Some(&t), Some(&b)) => (t, b),
            _ => return,
        };
        let mut fresh = vec![NONE; cw * (b - t + 1)];
        nearest_rows(
            w,
            b - t + 1,
            &obstacle[t * w..(b + 1) * w],
            x0,
            cw,
            &mut fresh,
        );
        // Per row: the first and last column whose column pass changed.
        let mut spans: Vec<Option<(usize, usize)>> = vec![None; h];
        for (y, new) in (t..=b).zip(fresh.chunks_exact(cw)) {
            let old = &mut self.near[y * w + x0..][..cw];
            let mut span: Option<(usize, usize)> = None;
            for (j, (o, &n)) in old.iter_mut().zip(new).enumerate() {
                let n = if n == NONE { NONE } else { n + t as u32 };
                if (above[j]..=below[j]).contains(&y) && *o != n {
                    *o = n;
                    span = Some(span.map_or((x0 + j, x0 + j), |(a, _)| (a, x0 + j)));
                }
            }
            spans[y] = span;
        }
        let near = &self.near;
        let found: Vec<(usize, usize, usize)> = self
            .feature
            .par_chunks_mut(w)
            .zip(self.d2.par_chunks_mut(w))
            .zip(self.row_max.par_iter_mut())
            .zip(spans.par_iter())
            .enumerate()
            .filter_map(|(y, (rows, span))| span.map(|s| (y, rows, s)))
            .map_init(
                || RowBuffers::new(w),
                |buffers, (y, ((feat_row, d2_row), top), span)| {
                    let near_row = &near[y * w..][..w];
                    let (a, b) = row_update(y, near_row, span, buffers, (feat_row, d2_row, top))?;
                    Some((y, a, b))
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

        /// An update after changes in a rectangle gives the features, the
        /// distances and the row maxima of a fresh transform, and reports exactly
        /// the rows and column spans that changed.
        #[test]
        fn update_equals_a_fresh_transform(
            w in 1usize..40,
            h in 2usize..24,
            before in proptest::collection::vec(0u8..5, 960),
            after in proptest::collection::vec(0u8..5, 960),
            a in 0usize..40,
            span in 0usize..12,
            r in 0usize..24,
            rise in 0usize..8,
        ) {
            // The top row is solid, so every column holds an obstacle.
            let solid = |bits: &[u8], i: usize| bits[i] == 0 || i / w == h - 1;
            let old: Vec<bool> = (0..w * h).map(|i| solid(&before, i)).collect();
            let (x0, x1) = (a % w, (a % w + span).min(w - 1));
            let (y0, y1) = (r % h, (r % h + rise).min(h - 1));
            let inside = |i: usize| (x0..=x1).contains(&(i % w)) && (y0..=y1).contains(&(i / w));
            let new: Vec<bool> = (0..w * h)
                .map(|i| if inside(i) { solid(&after, i) } else { old[i] })
                .collect();
            let mut kept = FeatureBuffers::default();
            feature_transform_into(w, h, &old, &mut kept);
            let (was_feature, was_d2) = (kept.feature.clone(), kept.d2.clone());
            let mut changes = Vec::new();
            kept.update(w, h, &new, (x0..=x1, y0..=y1), &mut changes);
            let mut fresh = FeatureBuffers::default();
            feature_transform_into(w, h, &new, &mut fresh);
            prop_assert_eq!(&kept.feature, &fresh.feature);
            prop_assert_eq!(&kept.d2, &fresh.d2);
            prop_assert_eq!(&kept.row_max, &fresh.row_max);
            let expected: Vec<(usize, usize, usize)> = (0..h)
                .filter_map(|y| {
                    let differs = |x: &usize| {
                        let i = y * w + x;
                        was_feature[i] != fresh.feature[i] || was_d2[i] != fresh.d2[i]
                    };
                    Some((y, (0..w).find(differs)?, (0..w).rfind(differs)?))
                })
                .collect();
            prop_assert_eq!(changes, expected);
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
