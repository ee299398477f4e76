//! The vertices of the Visibility Graph (section IV-C): the convex corners of the
//! non-drivable region of the robot's configuration space, seen from free space.
//!
//! In: the drivable cells of a robot. Out: the graph's vertices (drivable cells at
//! the convex corners of the simplified outlines) and the detail corners of the
//! unsimplified ones ([`corners`]). `N` cells, `P` outline corners.
//!
//! 1. **Outlines** (`O(N)`). Every side shared by a drivable cell and a
//!    non-drivable cell (or the outside of the grid) is a directed *crack* on the
//!    lattice of cell corners, oriented with the drivable cell on its left. Cracks
//!    are chained into closed contours (crack following, equivalent to
//!    Moore-neighbour tracing of the mask; at a saddle corner, where two drivable
//!    cells touch only diagonally, the left turn is taken, so obstacles are
//!    8-connected and free space 4-connected, as the supercover legs of
//!    [`segment_clear`](crate::grid::line::segment_clear) see it). Only the corners where a contour turns are kept.
//! 2. **Simplification** (`O(P log P)` typical, `O(P²)` worst). Each contour is a
//!    closed polygon, simplified with Ramer–Douglas–Peucker (split at the point
//!    farthest from the first one, each half recursively) with a *one-sided*
//!    tolerance: a dropped point may lie up to [`RDP_TOLERANCE`] (1 cell) on the
//!    obstacle side of its chord but only [`FREE_SIDE_TOLERANCE`] (≈ 0) on the
//!    free side. So staircases of diagonal walls and shallow dents become single
//!    edges, but no obstacle corner that sticks out into free space is cut off
//!    (a symmetric 1-cell tolerance dropped one-cell jogs that paths must bend
//!    around, which left goals unreachable in the random-map tests).
//! 3. **Vertices** (`O(P)`). A polygon corner where the contour turns right
//!    (towards the obstacle; the free side is on the left) is a *convex* obstacle
//!    corner seen from free space; reflex corners never lie on a shortest path
//!    between drivable points and are dropped. A convex corner is pushed outward
//!    along its miter direction (the bisector of the two edge normals, scaled so
//!    that the point keeps the same distance from both edge lines, at most three
//!    times that) by [`OFFSET`] = ½ cell, which lands on the cell diagonally at
//!    the corner: the last drivable cell, since the robot radius is already in the
//!    mask. If that cell is not drivable (acute corners) the corner is pushed one
//!    cell further; if that is not drivable either it is dropped. Vertices in the
//!    same cell are merged ([`MERGE_DISTANCE`] = 1 cell). Merging at 2 cells was
//!    tried and dropped: the survivor of two corners a diagonal step apart does
//!    not see what the other one saw, and goals became unreachable.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::geom::Cell;
use crate::grid::GridGeometry;

/// Ramer–Douglas–Peucker tolerance, cells.
pub const RDP_TOLERANCE: f64 = 1.0;
/// Ramer–Douglas–Peucker tolerance on the free side of an outline, cells.
pub const FREE_SIDE_TOLERANCE: f64 = 0.01;
/// How far a convex corner is pushed into free space, cells (to a cell centre).
pub const OFFSET: f64 = 0.5;
/// Vertices closer than this (cells) to an earlier vertex are merged into it
/// (1: only vertices in the same cell).
pub const MERGE_DISTANCE: f64 = 1.0;
/// A point on the lattice of cell corners (or in between), in cells.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pt {
    x: f64,
    y: f64,
}

impl Pt {
    fn new(x: i64, y: i64) -> Self {
        Self {
            x: x as f64,
            y: y as f64,
        }
    }
}

/// Unit steps of the crack directions: east, north, west, south.
const DIRS: [(i64, i64); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

/// The graph's vertices (merged convex corners of the simplified outlines, in the
/// order found) and the detail corners (convex corners of the unsimplified
/// outlines, unsorted, with repeats) of the non-drivable region of `drivable`.
pub(super) fn corners(g: &GridGeometry, drivable: &[bool]) -> (Vec<Cell>, Vec<Cell>) {
    let contours = trace_contours(g, drivable);
    // The contours are simplified in parallel; their corners join in the
    // contours' order.
    let per_contour: Vec<(Vec<Cell>, Vec<Cell>)> = contours
        .par_iter()
        .map(|contour| {
            let (mut candidates, mut detail) = (Vec::new(), Vec::new());
            let polygon = simplify_closed(contour, RDP_TOLERANCE);
            convex_corners(g, drivable, &polygon, &mut candidates);
            let raw: Vec<Pt> = contour.iter().map(|&(x, y)| Pt::new(x, y)).collect();
            convex_corners(g, drivable, &raw, &mut detail);
            (candidates, detail)
        })
        .collect();
    let (candidates, detail): (Vec<Vec<Cell>>, Vec<Vec<Cell>>) = per_contour.into_iter().unzip();
    let detail = detail.concat();
    (merge_close(candidates.concat(), MERGE_DISTANCE), detail)
}

/// Lattice corners passed over at once while looking for a crack to follow.
const SKIP: usize = 64;

/// The closed outlines of the non-drivable region, as the lattice corners where
/// they turn, with the drivable side on the left.
fn trace_contours(g: &GridGeometry, drivable: &[bool]) -> Vec<Vec<(i64, i64)>> {
    let lw = g.width as i64 + 1;
    let mut out = cracks(g, drivable);
    let at = |x: i64, y: i64| (y * lw + x) as usize;
    let mut contours = Vec::new();
    // Start at corners with a single crack first, so that no contour is cut at a
    // saddle; a second pass picks up anything left (none in practice).
    for single_only in [true, false] {
        let mut p = 0;
        while p < out.len() {
            // Cracks are only ever taken away, so a block of corners without one
            // stays without.
            if p % SKIP == 0
                && out
                    .get(p..p + SKIP)
                    .is_some_and(|b| b.iter().fold(0, |m, &c| m | c) == 0)
            {
                p += SKIP;
                continue;
            }
            while out[p] != 0 && (!single_only || out[p].count_ones() == 1) {
                let (sx, sy) = ((p as i64) % lw, (p as i64) / lw);
                let mut d = out[p].trailing_zeros() as usize;
                out[p] &= !(1 << d);
                let mut contour = vec![(sx, sy)];
                let (mut x, mut y) = (sx + DIRS[d].0, sy + DIRS[d].1);
                while (x, y) != (sx, sy) {
                    let bits = &mut out[at(x, y)];
                    // Left turn first, then straight on, then right.
                    let next = [(d + 1) % 4, d, (d + 3) % 4]
                        .into_iter()
                        .find(|&e| *bits & (1 << e) != 0);
                    let Some(e) = next else { break };
                    *bits &= !(1 << e);
                    if e != d {
                        contour.push((x, y));
                    }
                    d = e;
                    x += DIRS[d].0;
                    y += DIRS[d].1;
                }
                contours.push(contour);
            }
            p += 1;
        }
    }
    contours
}

/// The outgoing crack directions (bit `d` for `DIRS[d]`) of every lattice corner
/// (`(width + 1) × (height + 1)`, row by row): the sides between a drivable cell
/// and a non-drivable one or the outside, the drivable cell on the left.
fn cracks(g: &GridGeometry, drivable: &[bool]) -> Vec<u8> {
    let (w, h) = (g.width, g.height);
    let lw = w + 1;
    let mut out = vec![0u8; lw * (h + 1)];
    if w == 0 {
        return out;
    }
    for (y, row) in drivable[..w * h].chunks_exact(w).enumerate() {
        let below = y.checked_sub(1).map(|b| &drivable[b * w..(b + 1) * w]);
        let above = (y + 1 < h).then(|| &drivable[(y + 1) * w..(y + 2) * w]);
        let (bottom, top) = (y * lw, (y + 1) * lw);
        for (x, _) in row.iter().enumerate().filter(|(_, &d)| d) {
            if !below.is_some_and(|b| b[x]) {
                out[bottom + x] |= 1 << 0; // east along the bottom
            }
            if !row.get(x + 1).is_some_and(|&d| d) {
                out[bottom + x + 1] |= 1 << 1; // north along the right side
            }
            if !above.is_some_and(|a| a[x]) {
                out[top + x + 1] |= 1 << 2; // west along the top
            }
            if x == 0 || !row[x - 1] {
                out[top + x] |= 1 << 3; // south along the left side
            }
        }
    }
    out
}

/// How far `p` lies to the left of the line from `a` to `b` (the free side of an
/// outline), negative to the right; the distance from `a` if they coincide.
fn signed_distance(p: Pt, a: Pt, b: Pt) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let len = dx.hypot(dy);
    if len == 0.0 {
        return (p.x - a.x).hypot(p.y - a.y);
    }
    (dx * (p.y - a.y) - dy * (p.x - a.x)) / len
}

/// Ramer–Douglas–Peucker on an open chain of an outline (free side on the left),
/// with a one-sided tolerance: a point may lie up to `tolerance` on the obstacle
/// side of its chord but only [`FREE_SIDE_TOLERANCE`] on the free side, so the
/// simplified outline never cuts off a corner of the obstacle. Returns the
/// indices kept, ascending, first and last included.
fn rdp(chain: &[Pt], tolerance: f64) -> Vec<usize> {
    let n = chain.len();
    if n <= 2 {
        return (0..n).collect();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0, n - 1)];
    while let Some((a, b)) = stack.pop() {
        let (mut best, mut far) = (0.0, a);
        for (i, &p) in chain.iter().enumerate().take(b).skip(a + 1) {
            let s = signed_distance(p, chain[a], chain[b]);
            let excess = if s > 0.0 {
                s / FREE_SIDE_TOLERANCE
            } else {
                -s / tolerance
            };
            if excess > best {
                best = excess;
                far = i;
            }
        }
        if best > 1.0 {
            keep[far] = true;
            stack.push((a, far));
            stack.push((far, b));
        }
    }
    (0..n).filter(|&i| keep[i]).collect()
}

/// A closed contour simplified by RDP: split at the first point and the point
/// farthest from it, each half simplified on its own.
fn simplify_closed(contour: &[(i64, i64)], tolerance: f64) -> Vec<Pt> {
    let pts: Vec<Pt> = contour.iter().map(|&(x, y)| Pt::new(x, y)).collect();
    let n = pts.len();
    if n <= 4 {
        return pts;
    }
    let far = (1..n)
        .max_by(|&i, &j| {
            let di = (pts[i].x - pts[0].x).hypot(pts[i].y - pts[0].y);
            let dj = (pts[j].x - pts[0].x).hypot(pts[j].y - pts[0].y);
            di.total_cmp(&dj).then(j.cmp(&i))
        })
        .unwrap_or(1);
    let first: Vec<Pt> = pts[..=far].to_vec();
    let mut second: Vec<Pt> = pts[far..].to_vec();
    second.push(pts[0]);
    let mut out: Vec<Pt> = rdp(&first, tolerance)
        .into_iter()
        .map(|i| first[i])
        .collect();
    out.pop();
    let kept = rdp(&second, tolerance);
    out.extend(kept[..kept.len() - 1].iter().map(|&i| second[i]));
    out
}

/// Appends the drivable cells near the convex corners of a closed polygon (free
/// side on the left) to `out`.
fn convex_corners(g: &GridGeometry, drivable: &[bool], polygon: &[Pt], out: &mut Vec<Cell>) {
    let m = polygon.len();
    if m < 3 {
        return;
    }
    for i in 0..m {
        let (p, c, q) = (polygon[(i + m - 1) % m], polygon[i], polygon[(i + 1) % m]);
        let (d1x, d1y) = (c.x - p.x, c.y - p.y);
        let (d2x, d2y) = (q.x - c.x, q.y - c.y);
        let (l1, l2) = (d1x.hypot(d1y), d2x.hypot(d2y));
        if l1 == 0.0 || l2 == 0.0 || d1x * d2y - d1y * d2x >= 0.0 {
            continue; // straight on or a left turn: not convex from free space
        }
        // Unit left normals of the two edges.
        let (n1x, n1y) = (-d1y / l1, d1x / l1);
        let (n2x, n2y) = (-d2y / l2, d2x / l2);
        let (mut bx, mut by) = (n1x + n2x, n1y + n2y);
        let blen = bx.hypot(by);
        if blen < 1e-9 {
            // A U-turn: push out past the tip.
            (bx, by) = (d1x / l1, d1y / l1);
        } else {
            (bx, by) = (bx / blen, by / blen);
        }
        let cos = n1x * n2x + n1y * n2y;
        let miter = if 1.0 + cos > 2.0 / 9.0 {
            (2.0 / (1.0 + cos)).sqrt()
        } else {
            3.0
        };
        for k in [OFFSET, OFFSET + 1.0] {
            let (x, y) = (c.x + bx * miter * k, c.y + by * miter * k);
            if let Some(cell) = g.checked_cell(x.floor() as i64, y.floor() as i64) {
                if drivable[g.index(cell)] {
                    out.push(cell);
                    break;
                }
            }
        }
    }
}

/// Keeps each cell unless an earlier kept one lies closer than `min` cells.
fn merge_close(cells: Vec<Cell>, min: f64) -> Vec<Cell> {
    let bucket = min.ceil().max(1.0) as usize;
    let mut grid: HashMap<(usize, usize), Vec<Cell>> = HashMap::new();
    let mut kept = Vec::new();
    for c in cells {
        let (bx, by) = (c.x / bucket, c.y / bucket);
        let near = (bx.saturating_sub(1)..=bx + 1).any(|x| {
            (by.saturating_sub(1)..=by + 1).any(|y| {
                grid.get(&(x, y))
                    .is_some_and(|v| v.iter().any(|&o| cell_distance(o, c) < min))
            })
        });
        if !near {
            grid.entry((bx, by)).or_default().push(c);
            kept.push(c);
        }
    }
    kept
}

/// Euclidean distance between cell centres, cells.
pub(super) fn cell_distance(a: Cell, b: Cell) -> f64 {
    let (dx, dy) = (a.x as f64 - b.x as f64, a.y as f64 - b.y as f64);
    // Exact squares of cell counts: one rounding, in the square root.
    (dx * dx + dy * dy).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simplify_keeps_the_corners_of_a_rectangle() {
        let contour = vec![(0, 0), (10, 0), (10, 5), (0, 5)];
        assert_eq!(simplify_closed(&contour, 1.0).len(), 4);
        // A staircase becomes a straight edge.
        let mut stairs = vec![(0, 0)];
        for i in 0..10 {
            stairs.push((i + 1, i));
            stairs.push((i + 1, i + 1));
        }
        stairs.push((0, 10));
        assert!(simplify_closed(&stairs, 1.0).len() <= 4);
    }

    /// The cracks of the four sides of every drivable cell, each side's
    /// neighbour asked with bounds checks: the reference for [`cracks`].
    fn cracks_cell_by_cell(g: &GridGeometry, drivable: &[bool]) -> Vec<u8> {
        let (w, h) = (g.width as i64, g.height as i64);
        let lw = w + 1;
        let free =
            |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h && drivable[(y * w + x) as usize];
        let mut out = vec![0u8; ((w + 1) * (h + 1)) as usize];
        let at = |x: i64, y: i64| (y * lw + x) as usize;
        for y in 0..h {
            for x in (0..w).filter(|&x| free(x, y)) {
                for (d, (nx, ny), corner) in [
                    (0, (x, y - 1), (x, y)),
                    (1, (x + 1, y), (x + 1, y)),
                    (2, (x, y + 1), (x + 1, y + 1)),
                    (3, (x - 1, y), (x, y + 1)),
                ] {
                    if !free(nx, ny) {
                        out[at(corner.0, corner.1)] |= 1 << d;
                    }
                }
            }
        }
        out
    }

    proptest::proptest! {
        #[test]
        fn cracks_are_the_sides_of_drivable_cells_by_non_drivable_ones(
            w in 1usize..20,
            h in 1usize..20,
            bits in proptest::collection::vec(proptest::bool::ANY, 400),
        ) {
            let g = GridGeometry::new(w, h, 0.1, crate::geom::Point::default());
            let drivable = &bits[..w * h];
            proptest::prop_assert_eq!(cracks(&g, drivable), cracks_cell_by_cell(&g, drivable));
        }
    }
}
