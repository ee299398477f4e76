//! Visibility Graph on the known grid map and shortest paths through it, for the
//! subgoal retrieval of section IV-C: the subgoals are the vertices of the
//! shortest path, and consecutive subgoals see each other along a drivable
//! straight leg.
//!
//! # Method
//!
//! The graph is built in the robot's configuration space: the *obstacles* are the
//! cells that are not [`Traversability::traversable`] (Occupied, Unknown, the grid
//! edge and everything closer than the robot radius to them), so no further
//! inflation is needed. `N` cells, `P` outline corners, `V` vertices, `E` edges,
//! legs of up to `L` cells.
//!
//! 1. **Outlines** (`O(N)`). Every side shared by a drivable cell and a
//!    non-drivable cell (or the outside of the grid) is a directed *crack* on the
//!    lattice of cell corners, oriented with the drivable cell on its left. Cracks
//!    are chained into closed contours (crack following, equivalent to
//!    Moore-neighbour tracing of the mask; at a saddle corner, where two drivable
//!    cells touch only diagonally, the left turn is taken, so obstacles are
//!    8-connected and free space 4-connected, as the supercover legs of
//!    [`segment_clear`] see it). Only the corners where a contour turns are kept.
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
//! 4. **Edges** (`O(V·L)` per vertex, when first needed). Every pair of vertices
//!    whose straight leg (the supercover of the segment between the cell centres)
//!    consists of traversable cells is an edge, weighted by its Euclidean length in
//!    **metres** (cell centre distance × resolution). A vertex's edges are found
//!    when a search expands it ([`VisibilityGraph::neighbours`], in parallel over
//!    the other vertices, sorted by vertex, so nothing depends on the thread
//!    count). Testing all `V²` pairs up front took seconds per step on a
//!    275 m × 220 m campus map with thousands of vertices; a query expands only
//!    the vertices A* reaches inside its ellipse (below).
//! 5. **Queries** (`O(V·L + (V + E) log V)` at worst). [`VisibilityGraph::shortest_path`]
//!    returns the straight leg if `from` sees `to`; otherwise it links `from` and
//!    `to` to every vertex they see and runs A* (straight-line distance to the
//!    goal as the bound; binary heap, `f64` metres, ties broken by node index) over
//!    the graph plus these two nodes, in rounds restricted to the vertices inside
//!    an ellipse with foci `from` and `to` that doubles until the path found fits
//!    in it (then it is the shortest over the whole graph). Query legs are checked over
//!    [`Traversability::passable`] (a superset of `traversable`), so a robot in its
//!    escape region can still leave.
//! 6. **Fallback.** An endpoint inside a dent that the simplification smoothed
//!    away may see no vertex. The convex corners of the *unsimplified* outlines
//!    are kept as [`VisibilityGraph::detail`]; if the first search finds no path,
//!    it is repeated with the [`DETAIL_LINKS`] detail corners nearest to each
//!    endpoint as extra nodes, linked to every vertex and to each other
//!    (`O(K·V·L)` more for `K` extra nodes).
//!
//! # Properties and limits
//!
//! Every leg of a returned path is clear over `passable`, and its vertices are
//! drivable. The vertices sit half a cell off the obstacle corners, so paths are
//! near-shortest rather than exact: in the random-map property test (20 000 cases
//! run once, 128 kept) they were never longer than the 8-connected grid path
//! ([`crate::planning::reach::sweep`]) plus one cell plus two cells per bend,
//! and a path was always found when the grid path existed (goal and start
//! traversable). Not guaranteed in general:
//!
//! - A start inside its escape region (passable but not traversable) may need a
//!   bend at a *reflex* corner of the traversable region, which has no vertex;
//!   the path found is then longer than needed (or, in principle, missing).
//! - The fallback is heuristic (nearest detail corners only).
//!
//! On the built-in office map (800 × 600 cells of 0.1 m, full knowledge, robot
//! radius 0.25 m, 2 cores, release): 480 vertices, 5 143 edges, built in about
//! 10–15 ms; a query takes 0.2–0.3 ms. Tunnel map: 950 vertices, 41 719 edges,
//! about 30 ms (its curved walls keep many corners); site map: 82 vertices.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use rayon::prelude::*;

use crate::geom::Cell;
use crate::planning::line::segment_clear;
use crate::planning::Traversability;
use crate::world::{GridGeometry, OccupancyGrid};

/// Ramer–Douglas–Peucker tolerance, cells.
pub const RDP_TOLERANCE: f64 = 1.0;
/// Ramer–Douglas–Peucker tolerance on the free side of an outline, cells.
pub const FREE_SIDE_TOLERANCE: f64 = 0.01;
/// How far a convex corner is pushed into free space, cells (to a cell centre).
pub const OFFSET: f64 = 0.5;
/// Vertices closer than this (cells) to an earlier vertex are merged into it
/// (1: only vertices in the same cell).
pub const MERGE_DISTANCE: f64 = 1.0;
/// How many of the nearest detail corners an endpoint is linked to in the
/// fallback search of [`VisibilityGraph::shortest_path`].
pub const DETAIL_LINKS: usize = 16;

/// A Visibility Graph over the convex corners of the non-drivable region. Its
/// edges are found when a search first needs them ([`Self::neighbours`]).
#[derive(Debug, Clone)]
pub struct VisibilityGraph {
    /// The graph's vertices: drivable cells near the convex obstacle corners.
    pub vertices: Vec<Cell>,
    /// The drivable cells at the convex corners of the *unsimplified* outlines
    /// (sorted, none of them a vertex): the fallback of
    /// [`VisibilityGraph::shortest_path`] for endpoints in pockets that the
    /// simplification smoothed away.
    pub detail: Vec<Cell>,
    /// The drivable cells the graph was built on.
    drivable: Vec<bool>,
    geometry: GridGeometry,
}

impl PartialEq for VisibilityGraph {
    /// Graphs are equal when built from the same cells (edges follow from them).
    fn eq(&self, other: &Self) -> bool {
        self.vertices == other.vertices
            && self.detail == other.detail
            && self.geometry == other.geometry
            && self.drivable == other.drivable
    }
}

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

impl VisibilityGraph {
    /// Builds the graph on `knowledge` with the drivable cells of `trav`.
    pub fn build(knowledge: &OccupancyGrid, trav: &Traversability) -> VisibilityGraph {
        let g = *knowledge.geometry();
        let drivable = &trav.traversable;
        let contours = trace_contours(&g, drivable);
        let mut candidates = Vec::new();
        let mut detail = Vec::new();
        for contour in &contours {
            let polygon = simplify_closed(contour, RDP_TOLERANCE);
            convex_corners(&g, drivable, &polygon, &mut candidates);
            let raw: Vec<Pt> = contour.iter().map(|&(x, y)| Pt::new(x, y)).collect();
            convex_corners(&g, drivable, &raw, &mut detail);
        }
        let vertices = merge_close(candidates, MERGE_DISTANCE);
        let mut sorted = vertices.clone();
        sorted.sort_unstable();
        detail.sort_unstable();
        detail.dedup();
        detail.retain(|c| sorted.binary_search(c).is_err());
        VisibilityGraph {
            vertices,
            detail,
            drivable: drivable.clone(),
            geometry: g,
        }
    }

    /// The neighbours of vertex `v`: `(other vertex, leg length in metres)` for
    /// every vertex whose straight leg from `v` is drivable, sorted by the other
    /// vertex (`O(V·L)`, in parallel).
    pub fn neighbours(&self, v: usize) -> Vec<(usize, f64)> {
        let all: Vec<usize> = (0..self.vertices.len()).collect();
        self.neighbours_among(v, &all)
    }

    /// [`Self::neighbours`] among the vertices `among` (ascending).
    fn neighbours_among(&self, v: usize, among: &[usize]) -> Vec<(usize, f64)> {
        let g = &self.geometry;
        let a = self.vertices[v];
        let drivable = &self.drivable;
        among
            .par_iter()
            .filter(|&&j| j != v)
            .filter_map(|&j| {
                let b = self.vertices[j];
                segment_clear(g, a, b, |k| drivable[k])
                    .then(|| (j, cell_distance(a, b) * g.resolution))
            })
            .collect()
    }

    /// Number of (undirected) edges (computes every vertex's neighbours).
    pub fn edge_count(&self) -> usize {
        (0..self.vertices.len())
            .map(|v| self.neighbours(v).len())
            .sum::<usize>()
            / 2
    }

    /// The shortest path from `from` to `to` through the graph: its cells, `from`
    /// first and `to` last, each leg a straight segment over `trav.passable`
    /// cells. `None` when either cell is off the grid or not passable, or no path
    /// is found.
    ///
    /// If `from` sees `to` the path is the straight leg. Otherwise both are linked
    /// to every vertex they see and Dijkstra runs over the graph; if that finds no
    /// path, the search is repeated with up to [`DETAIL_LINKS`] of the nearest
    /// [`detail`](Self::detail) corners to each endpoint (seen or not) as extra
    /// nodes, linked to the vertices and to each other, which gets endpoints out
    /// of shallow pockets of the outline that the simplification removed.
    pub fn shortest_path(
        &self,
        geometry: &GridGeometry,
        trav: &Traversability,
        from: Cell,
        to: Cell,
    ) -> Option<Vec<Cell>> {
        let g = geometry;
        if from.x >= g.width || from.y >= g.height || to.x >= g.width || to.y >= g.height {
            return None;
        }
        let ok = |k: usize| trav.passable[k];
        if !ok(g.index(from)) || !ok(g.index(to)) {
            return None;
        }
        if from == to {
            return Some(vec![from]);
        }
        if segment_clear(g, from, to, ok) {
            return Some(vec![from, to]);
        }
        self.search(g, &ok, vec![from, to]).or_else(|| {
            let mut overlay = vec![from, to];
            for end in [from, to] {
                let mut near: Vec<(f64, Cell)> = self
                    .detail
                    .iter()
                    .map(|&d| (cell_distance(end, d), d))
                    .collect();
                near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                overlay.extend(near.into_iter().take(DETAIL_LINKS).map(|(_, d)| d));
            }
            overlay[2..].sort_unstable();
            overlay.dedup();
            if overlay.len() == 2 {
                return None;
            }
            self.search(g, &ok, overlay)
        })
    }

    /// The shortest path from `overlay[0]` to `overlay[1]` over the graph plus the
    /// `overlay` cells as extra nodes, linked to every vertex and overlay cell they
    /// see.
    ///
    /// Bounded rounds: only the vertices `v` with `|v − from| + |v − to| ≤ s` take
    /// part (an ellipse with foci at the two ends), starting with `s` = 1.2 times
    /// the straight distance plus 10 m and doubling. Every vertex of a path no
    /// longer than `s` lies in that ellipse, so a path found no longer than `s` is
    /// the shortest over the whole graph; the last round takes every vertex.
    fn search(
        &self,
        g: &GridGeometry,
        ok: &(impl Fn(usize) -> bool + Sync),
        overlay: Vec<Cell>,
    ) -> Option<Vec<Cell>> {
        let n = self.vertices.len();
        let res = g.resolution;
        let (from, to) = (overlay[0], overlay[1]);
        let sum = |c: Cell| (cell_distance(c, from) + cell_distance(c, to)) * res;
        let mut bound = 1.2 * sum(from) + 10.0;
        loop {
            let among: Vec<usize> = (0..n).filter(|&v| sum(self.vertices[v]) <= bound).collect();
            let last = among.len() == n;
            match self.search_among(g, ok, &overlay, &among) {
                Some((path, length)) if last || length <= bound => return Some(path),
                None if last => return None,
                _ => bound *= 2.0,
            }
        }
    }

    /// A* from `overlay[0]` to `overlay[1]` over the vertices `among` and the
    /// overlay cells: the path's cells and its length in metres.
    fn search_among(
        &self,
        g: &GridGeometry,
        ok: &(impl Fn(usize) -> bool + Sync),
        overlay: &[Cell],
        among: &[usize],
    ) -> Option<(Vec<Cell>, f64)> {
        let n = self.vertices.len();
        let res = g.resolution;
        let cell_of = |node: usize| {
            if node < n {
                self.vertices[node]
            } else {
                overlay[node - n]
            }
        };
        let all = n + overlay.len();
        // Links of each overlay node to the vertices and to the later overlay nodes.
        let links: Vec<Vec<(usize, f64)>> = overlay
            .par_iter()
            .enumerate()
            .map(|(o, &c)| {
                among
                    .iter()
                    .copied()
                    .chain(n + o + 1..all)
                    .filter_map(|node| {
                        let v = cell_of(node);
                        segment_clear(g, c, v, ok).then(|| (node, cell_distance(c, v) * res))
                    })
                    .collect()
            })
            .collect();
        if links[0].is_empty() {
            return None;
        }
        let mut extra: Vec<Vec<(usize, f64)>> = vec![Vec::new(); all];
        for (o, list) in links.into_iter().enumerate() {
            for &(node, d) in &list {
                extra[node].push((n + o, d));
            }
            extra[n + o].extend(list);
        }
        let (src, dst) = (n, n + 1);
        // A*: the straight-line distance to the goal is a consistent bound.
        let goal = cell_of(dst);
        let h = |node: usize| cell_distance(cell_of(node), goal) * res;
        let mut dist = vec![f64::INFINITY; all];
        let mut prev = vec![usize::MAX; all];
        let mut done = vec![false; all];
        let mut heap = BinaryHeap::new();
        dist[src] = 0.0;
        heap.push(State {
            cost: h(src),
            node: src,
        });
        while let Some(State { node, .. }) = heap.pop() {
            if done[node] {
                continue;
            }
            done[node] = true;
            if node == dst {
                break;
            }
            let base = if node < n {
                self.neighbours_among(node, among)
            } else {
                Vec::new()
            };
            for &(next, d) in base.iter().chain(&extra[node]) {
                let c = dist[node] + d;
                if c < dist[next] {
                    dist[next] = c;
                    prev[next] = node;
                    heap.push(State {
                        cost: c + h(next),
                        node: next,
                    });
                }
            }
        }
        if !dist[dst].is_finite() {
            return None;
        }
        let mut path = vec![cell_of(dst)];
        let mut node = dst;
        while node != src {
            node = prev[node];
            path.push(cell_of(node));
        }
        path.reverse();
        Some((path, dist[dst]))
    }
}

/// Length of a path of cells, metres.
pub fn path_length(geometry: &GridGeometry, path: &[Cell]) -> f64 {
    path.windows(2)
        .map(|w| cell_distance(w[0], w[1]))
        .sum::<f64>()
        * geometry.resolution
}

/// Euclidean distance between cell centres, cells.
fn cell_distance(a: Cell, b: Cell) -> f64 {
    (a.x as f64 - b.x as f64).hypot(a.y as f64 - b.y as f64)
}

/// A Dijkstra queue entry: smallest cost first, ties by node.
#[derive(Debug, Clone, Copy, PartialEq)]
struct State {
    cost: f64,
    node: usize,
}

impl Eq for State {}

impl Ord for State {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.node.cmp(&self.node))
    }
}

impl PartialOrd for State {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The closed outlines of the non-drivable region, as the lattice corners where
/// they turn, with the drivable side on the left.
fn trace_contours(g: &GridGeometry, drivable: &[bool]) -> Vec<Vec<(i64, i64)>> {
    let (w, h) = (g.width as i64, g.height as i64);
    let lw = w + 1;
    let free =
        |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h && drivable[(y * w + x) as usize];
    // Outgoing crack directions (bit d for DIRS[d]) per lattice corner.
    let mut out = vec![0u8; ((w + 1) * (h + 1)) as usize];
    let at = |x: i64, y: i64| (y * lw + x) as usize;
    for y in 0..h {
        for x in 0..w {
            if !free(x, y) {
                continue;
            }
            if !free(x, y - 1) {
                out[at(x, y)] |= 1 << 0; // east along the bottom
            }
            if !free(x + 1, y) {
                out[at(x + 1, y)] |= 1 << 1; // north along the right side
            }
            if !free(x, y + 1) {
                out[at(x + 1, y + 1)] |= 1 << 2; // west along the top
            }
            if !free(x - 1, y) {
                out[at(x, y + 1)] |= 1 << 3; // south along the left side
            }
        }
    }
    let mut contours = Vec::new();
    // Start at corners with a single crack first, so that no contour is cut at a
    // saddle; a second pass picks up anything left (none in practice).
    for single_only in [true, false] {
        for p in 0..out.len() {
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
        }
    }
    contours
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::planning::reach;
    use crate::world::CellState;
    use proptest::prelude::*;

    const RES: f64 = 0.1;
    const RADIUS: f64 = 0.15;

    fn open(w: usize, h: usize) -> OccupancyGrid {
        OccupancyGrid::filled(
            GridGeometry::new(w, h, RES, Point::default()),
            CellState::Free,
        )
    }

    fn setup(map: &OccupancyGrid, robot: Cell) -> (Traversability, VisibilityGraph) {
        let trav = Traversability::new(map, RADIUS, robot);
        let graph = VisibilityGraph::build(map, &trav);
        (trav, graph)
    }

    fn grid_metres(map: &OccupancyGrid, trav: &Traversability, a: Cell, b: Cell) -> Option<f64> {
        let g = map.geometry();
        let field = reach::sweep(g, &trav.passable, &[g.index(a)], reach::UNREACHED - 1);
        field.metres(g.index(b))
    }

    fn check_legs(map: &OccupancyGrid, trav: &Traversability, path: &[Cell], a: Cell, b: Cell) {
        let g = map.geometry();
        assert_eq!(path.first(), Some(&a));
        assert_eq!(path.last(), Some(&b));
        for w in path.windows(2) {
            assert!(
                segment_clear(g, w[0], w[1], |k| trav.passable[k]),
                "leg {:?} -> {:?} blocked in {path:?}",
                w[0],
                w[1]
            );
        }
    }

    fn straight(g: &GridGeometry, a: Cell, b: Cell) -> f64 {
        g.cell_center(a).distance(g.cell_center(b))
    }

    #[test]
    fn open_space_is_one_straight_leg() {
        let map = open(60, 40);
        let (a, b) = (Cell::new(5, 5), Cell::new(50, 33));
        let (trav, graph) = setup(&map, a);
        let path = graph
            .shortest_path(map.geometry(), &trav, a, b)
            .unwrap_or_default();
        assert_eq!(path, vec![a, b]);
        assert_eq!(
            graph.shortest_path(map.geometry(), &trav, a, a),
            Some(vec![a])
        );
    }

    #[test]
    fn around_one_square_obstacle() {
        let mut map = open(60, 60);
        map.fill_rect(25, 25, 34, 34, CellState::Occupied);
        let g = *map.geometry();
        for (a, b) in [
            (Cell::new(10, 30), Cell::new(50, 30)),
            (Cell::new(30, 10), Cell::new(30, 50)),
            (Cell::new(12, 20), Cell::new(48, 40)),
            (Cell::new(15, 15), Cell::new(45, 45)),
        ] {
            let (trav, graph) = setup(&map, a);
            let path = graph.shortest_path(&g, &trav, a, b).unwrap();
            check_legs(&map, &trav, &path, a, b);
            let inner = &path[1..path.len() - 1];
            assert!((1..=2).contains(&inner.len()), "{path:?}");
            for c in inner {
                // Near a corner of the obstacle (cells 25..34, lattice corners 25 and 34).
                let near = |v: usize| v.abs_diff(25).min(v.abs_diff(35)) <= 5;
                assert!(
                    near(c.x) && near(c.y),
                    "{c:?} not near a corner in {path:?}"
                );
            }
            let len = path_length(&g, &path);
            let grid = grid_metres(&map, &trav, a, b).unwrap();
            assert!(len <= grid + 2.0 * RES, "{len} vs grid {grid}");
            assert!(len >= straight(&g, a, b) - 1e-9);
        }
    }

    #[test]
    fn unreachable_goal_gives_none() {
        let mut map = open(60, 40);
        map.fill_rect(30, 0, 31, 39, CellState::Occupied);
        let (a, b) = (Cell::new(10, 20), Cell::new(50, 20));
        let (trav, graph) = setup(&map, a);
        assert_eq!(graph.shortest_path(map.geometry(), &trav, a, b), None);
        // Off-grid and blocked goals too.
        assert_eq!(
            graph.shortest_path(map.geometry(), &trav, a, Cell::new(60, 0)),
            None
        );
        assert_eq!(
            graph.shortest_path(map.geometry(), &trav, a, Cell::new(30, 20)),
            None
        );
    }

    #[test]
    fn vertices_are_drivable_and_graph_is_symmetric() {
        let mut map = open(80, 60);
        map.fill_rect(20, 10, 30, 40, CellState::Occupied);
        map.fill_rect(45, 25, 60, 30, CellState::Occupied);
        map.fill_rect(0, 50, 40, 59, CellState::Unknown);
        let (trav, graph) = setup(&map, Cell::new(5, 5));
        assert!(!graph.vertices.is_empty());
        let g = map.geometry();
        for &v in &graph.vertices {
            assert!(trav.traversable[g.index(v)], "{v:?}");
        }
        for i in 0..graph.vertices.len() {
            for (j, d) in graph.neighbours(i) {
                assert!(graph.neighbours(j).iter().any(|&(k, e)| k == i && e == d));
                assert!(segment_clear(
                    g,
                    graph.vertices[i],
                    graph.vertices[j],
                    |k| { trav.traversable[k] }
                ));
            }
        }
    }

    #[test]
    fn build_is_deterministic() {
        let mut map = open(80, 60);
        map.fill_rect(20, 10, 30, 40, CellState::Occupied);
        map.fill_rect(45, 25, 60, 30, CellState::Occupied);
        let (_, first) = setup(&map, Cell::new(5, 5));
        for _ in 0..3 {
            assert_eq!(setup(&map, Cell::new(5, 5)).1, first);
        }
    }

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

    #[test]
    fn goal_in_a_smoothed_pocket_is_found_by_the_fallback() {
        // The goal sits in a one-cell dent of the outline that the simplification
        // removes, so it sees no vertex; the detail corners get it out.
        let mut map = open(60, 45);
        for (x, y, w, h) in [(50, 21, 4, 4), (49, 23, 4, 8), (51, 32, 3, 1)] {
            map.fill_rect(x, y, x + w, y + h, CellState::Occupied);
        }
        let (a, b) = (Cell::new(1, 1), Cell::new(54, 27));
        let (trav, graph) = setup(&map, a);
        let g = map.geometry();
        assert!(!graph
            .vertices
            .iter()
            .any(|&v| segment_clear(g, b, v, |k| trav.passable[k])));
        let path = graph.shortest_path(g, &trav, a, b).unwrap();
        check_legs(&map, &trav, &path, a, b);
        let grid = grid_metres(&map, &trav, a, b).unwrap();
        assert!(path_length(g, &path) <= grid + 1.0 * RES * path.len() as f64);
    }

    /// A random map: rectangles of Occupied (and some Unknown) cells on a Free
    /// grid.
    fn rect_map(w: usize, h: usize, rects: &[(usize, usize, usize, usize, bool)]) -> OccupancyGrid {
        let mut map = open(w, h);
        for &(x, y, rw, rh, unknown) in rects {
            let (x1, y1) = (x + rw, y + rh); // exclusive, clamped by fill_rect
            let s = if unknown {
                CellState::Unknown
            } else {
                CellState::Occupied
            };
            map.fill_rect(x, y, x1, y1, s);
        }
        map
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]
        #[test]
        fn random_rectangle_maps(
            rects in prop::collection::vec(
                (0usize..60, 0usize..45, 1usize..15, 1usize..15, prop::bool::weighted(0.2)),
                0..8,
            ),
            ends in prop::collection::vec((0usize..60, 0usize..45), 6),
        ) {
            let map = rect_map(60, 45, &rects);
            let g = *map.geometry();
            let (a, rest) = (Cell::new(ends[0].0, ends[0].1), &ends[1..]);
            let (trav, graph) = setup(&map, a);
            // Starts in the escape region may need a bend at a reflex corner of the
            // traversable region, which the graph has no vertex for (module doc).
            if !trav.traversable[g.index(a)] {
                return Ok(());
            }
            for &v in &graph.vertices {
                prop_assert!(trav.traversable[g.index(v)]);
            }
            prop_assert_eq!(&VisibilityGraph::build(&map, &trav), &graph);
            for &(x, y) in rest {
                let b = Cell::new(x, y);
                let grid = grid_metres(&map, &trav, a, b).filter(|_| trav.traversable[g.index(b)]);
                let path = graph.shortest_path(&g, &trav, a, b);
                match (&path, grid) {
                    (Some(path), Some(grid)) => {
                        check_legs(&map, &trav, path, a, b);
                        let len = path_length(&g, path);
                        prop_assert!(len >= straight(&g, a, b) - 1e-9);
                        // A cell or two of detour per bend at most.
                        let bends = path.len().saturating_sub(2) as f64;
                        prop_assert!(
                            len <= grid + (1.0 + 2.0 * bends) * RES,
                            "{} vs grid {} for {:?}", len, grid, path
                        );
                    }
                    (Some(path), None) => prop_assert!(false, "path {:?} but grid unreachable", path),
                    (None, Some(grid)) => prop_assert!(false, "no path, grid {}", grid),
                    (None, None) => {}
                }
            }
        }
    }
}
