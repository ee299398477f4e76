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
//! 1.–3. **Vertices**: the convex corners of the outlines of the non-drivable
//!    region, simplified and pushed half a cell into free space
//!    ([`super::corners`]).
//! 4. **Edges** (`O(V·L)` per vertex, when first needed). Every pair of vertices
//!    whose straight leg (the supercover of the segment between the cell centres)
//!    consists of traversable cells is an edge, weighted by its Euclidean length in
//!    **metres** (cell centre distance × resolution). Edges are tested only
//!    when a search needs them (below); [`VisibilityGraph::neighbours`] gives a
//!    vertex's edges (in parallel over the other vertices, sorted by vertex).
//!    Testing all `V²` pairs up front took seconds per step on a
//!    275 m × 220 m campus map with thousands of vertices.
//! 5. **Queries** (`O(V·L + (V + E) log V)` at worst). [`VisibilityGraph::shortest_path`]
//!    returns the straight leg if `from` sees `to`; otherwise it links `from` and
//!    `to` to every vertex they see and runs A* over the graph plus these two
//!    nodes (binary heap, `f64` metres, ties broken by node index), in rounds
//!    restricted to the vertices inside an ellipse with foci `from` and `to`
//!    that doubles until the path found fits in it (then it is the shortest over
//!    the whole graph). The A* is *lazy* (LazySP, Dellin & Srinivasa, ICAPS
//!    2016): an expanded vertex queues its legs to every other vertex untested,
//!    and a leg is tested only when its entry is the first taken for its vertex,
//!    so most legs of a cluttered map are never tested. Each expanded vertex's
//!    legs are sorted once into a list, and the heap holds only each list's
//!    cheapest untaken entry (the same order of entries as queueing them all,
//!    with one heap entry per expanded vertex). Its bound to go is the
//!    straight-line distance, or, with travel distances from `from`
//!    ([`VisibilityGraph::shortest_path_guided`], the parent's planning round
//!    has them), those distances over [`GUIDE_FACTOR`]: consistent, far tighter
//!    in winding free space, and the search then runs from `to` back to `from`.
//!    Guided or not, the path is as short (a property test checks both against
//!    an eager Dijkstra over every edge); among equally short paths another may
//!    be returned. On the shared willow_garage map with the default team this
//!    took the episode from 22 s to 13.5 s (docs/PERFORMANCE.md). Query legs are
//!    checked over [`Traversability::passable`] (a superset of `traversable`),
//!    so a robot in its escape region can still leave.
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
//! ([`crate::grid::travel::sweep`]) plus one cell plus two cells per bend,
//! and a path was always found when the grid path existed (goal and start
//! traversable). Not guaranteed in general:
//!
//! - A start inside its escape region (passable but not traversable) may need a
//!   bend at a *reflex* corner of the traversable region, which has no vertex;
//!   the path found is then longer than needed (or, in principle, missing).
//! - The fallback is heuristic (nearest detail corners only).
//! - A goal in the inner corner of two overlapping obstacles can lack the
//!   vertex of its short way out, which the simplification removed: on a
//!   60 × 45 grid with Occupied rectangles (x, y, w, h) = (42, 22, 3, 1),
//!   (36, 7, 9, 8), (47, 32, 2, 1), (41, 10, 3, 10), radius 1.5 cells, the
//!   path from (1, 1) to (45, 17) is 7.09 m against 5.91 m on the grid. The
//!   property test `random_rectangle_maps` meets such a case about once in a
//!   few thousand.
//!
//! On the built-in office map (800 × 600 cells of 0.1 m, full knowledge, robot
//! radius 0.25 m, 2 cores, release): 480 vertices, 5 143 edges, built in about
//! 10–15 ms; a query takes 0.2–0.3 ms. Tunnel map: 950 vertices, 41 719 edges,
//! about 30 ms (its curved walls keep many corners); site map: 82 vertices.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use rayon::prelude::*;

use super::corners::{cell_distance, corners};
use crate::geom::Cell;
use crate::grid::line::segment_clear;
use crate::grid::travel::STRAIGHT;
use crate::grid::{DistanceField, GridGeometry, OccupancyGrid, Traversability, UNREACHED};

/// The guide's travel distance over-states the length of any path of straight
/// legs by at most this factor, so divided by it, it is a consistent A* bound:
/// each leg's supercover holds its Bresenham line, an 8-connected path of
/// octile length (diagonal cost 41/29 < √2), at most 1/cos 22.5° = 1.0824 times
/// the leg; the margin covers rounding.
pub const GUIDE_FACTOR: f64 = 1.0825;

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
    /// The drivable cells the graph was built on (shared with their
    /// [`Traversability`]).
    drivable: std::sync::Arc<Vec<bool>>,
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

impl VisibilityGraph {
    /// Builds the graph on `knowledge` with the drivable cells of `trav`.
    pub fn build(knowledge: &OccupancyGrid, trav: &Traversability) -> VisibilityGraph {
        let g = *knowledge.geometry();
        let drivable = &trav.traversable;
        let (vertices, mut detail) = corners(&g, drivable);
        let mut sorted = vertices.clone();
        sorted.sort_unstable();
        detail.sort_unstable();
        detail.dedup();
        detail.retain(|c| sorted.binary_search(c).is_err());
        VisibilityGraph {
            vertices,
            detail,
            drivable: std::sync::Arc::clone(drivable),
            geometry: g,
        }
    }

    /// The neighbours of vertex `v`: `(other vertex, leg length in metres)` for
    /// every vertex whose straight leg from `v` is drivable, sorted by the other
    /// vertex (`O(V·L)`, in parallel).
    pub fn neighbours(&self, v: usize) -> Vec<(usize, f64)> {
        let a = self.vertices[v];
        (0..self.vertices.len())
            .into_par_iter()
            .filter(|&j| j != v && self.leg_clear(v, j))
            .map(|j| {
                (
                    j,
                    cell_distance(a, self.vertices[j]) * self.geometry.resolution,
                )
            })
            .collect()
    }

    /// Whether the straight leg between vertices `a` and `b` is drivable.
    fn leg_clear(&self, a: usize, b: usize) -> bool {
        segment_clear(&self.geometry, self.vertices[a], self.vertices[b], |k| {
            self.drivable[k]
        })
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
        self.shortest_path_guided(geometry, trav, from, to, None)
    }

    /// [`Self::shortest_path`], with `guide` the travel distances from `from`
    /// over `trav.passable` when known (the parent's planning round has them): the
    /// search then runs from `to` back to `from` with those distances, shrunk by
    /// 1.0825 (`GUIDE_FACTOR`), as its bound to go, which leaves it consistent but far
    /// tighter than the straight line in winding free space, and never expands a
    /// vertex that cannot reach `from`. The path is as short as without the
    /// guide (among equally short ones, another may be returned).
    pub fn shortest_path_guided(
        &self,
        geometry: &GridGeometry,
        trav: &Traversability,
        from: Cell,
        to: Cell,
        guide: Option<&DistanceField>,
    ) -> Option<Vec<Cell>> {
        self.shortest_path_with(geometry, trav, from, to, guide, true)
    }

    /// [`Self::shortest_path_guided`]; `limited`: whether a guided search first
    /// keeps only the entries no longer than the guide's travel distance (the
    /// path is the same either way).
    fn shortest_path_with(
        &self,
        geometry: &GridGeometry,
        trav: &Traversability,
        from: Cell,
        to: Cell,
        guide: Option<&DistanceField>,
        limited: bool,
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
        self.search(g, &ok, vec![from, to], guide, limited)
            .or_else(|| {
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
                self.search(g, &ok, overlay, guide, limited)
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
        guide: Option<&DistanceField>,
        limited: bool,
    ) -> Option<Vec<Cell>> {
        let n = self.vertices.len();
        let res = g.resolution;
        let (from, to) = (overlay[0], overlay[1]);
        let sum = |c: Cell| (cell_distance(c, from) + cell_distance(c, to)) * res;
        let mut bound = 1.2 * sum(from) + 10.0;
        // With a guide, the parent's travel distance between the two ends is the
        // length of a drivable path: the search first keeps only the entries no
        // longer than that, which leaves the order of everything it takes until
        // the goal unchanged when the shortest path is no longer (the bound is
        // consistent, so every entry taken before the goal costs no more than
        // the path); otherwise it searches again within the widest limit the
        // round can use.
        let travel = guide
            .filter(|_| limited)
            .and_then(|f| f.metres(g.index(to)))
            .unwrap_or(f64::INFINITY);
        loop {
            let among: Vec<usize> = (0..n).filter(|&v| sum(self.vertices[v]) <= bound).collect();
            let last = among.len() == n;
            // A round other than the last takes only a path no longer than its
            // bound, so no search of it needs a wider limit than that.
            let widest = if last { f64::INFINITY } else { bound };
            let first = travel.min(widest);
            let found = self
                .search_among(g, ok, &overlay, &among, guide, first)
                .or_else(|| {
                    (first < widest)
                        .then(|| self.search_among(g, ok, &overlay, &among, guide, widest))?
                });
            match found {
                Some((path, length)) if last || length <= bound => return Some(path),
                None if last => return None,
                _ => bound *= 2.0,
            }
        }
    }

    /// A* from `overlay[0]` to `overlay[1]` over the vertices `among` and the
    /// overlay cells: the path's cells and its length in metres. With a `guide`
    /// (travel distances from `overlay[0]`) the search runs backwards, bounded
    /// by them. Entries whose cost with the bound exceeds `limit` metres are not
    /// queued: a path longer than that is not found.
    fn search_among(
        &self,
        g: &GridGeometry,
        ok: &(impl Fn(usize) -> bool + Sync),
        overlay: &[Cell],
        among: &[usize],
        guide: Option<&DistanceField>,
        limit: f64,
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
        let (src, dst) = if guide.is_some() {
            (n + 1, n)
        } else {
            (n, n + 1)
        };
        // A*: the straight-line distance to the goal is a consistent bound; so is
        // the guide's travel distance shrunk by GUIDE_FACTOR (docs of the const).
        let goal = cell_of(dst);
        let per_cost = res / STRAIGHT as f64 / GUIDE_FACTOR;
        let h = |node: usize| {
            let c = cell_of(node);
            match guide {
                Some(f) => match f.cost[g.index(c)] {
                    UNREACHED => f64::INFINITY,
                    cost => cost as f64 * per_cost,
                },
                None => cell_distance(c, goal) * res,
            }
        };
        // Lazy A* (edges tested when their entry is taken, as in LazySP, Dellin &
        // Srinivasa, ICAPS 2016): a vertex's legs to the others are queued
        // untested, and only a leg whose entry comes first for its vertex is
        // tested. The first valid entry of a vertex has its least cost, as in
        // plain A* with a consistent bound, so the path is as short; most legs
        // of a cluttered map, blocked or too long, are never tested.
        // The bound of every node taking part, looked up once.
        let mut bound = vec![f64::INFINITY; all];
        for &v in among {
            bound[v] = h(v);
        }
        for (node, b) in bound.iter_mut().enumerate().skip(n) {
            *b = h(node);
        }
        let mut dist = vec![f64::INFINITY; all];
        let mut prev = vec![usize::MAX; all];
        let mut done = vec![false; all];
        // Each expanded node's successors are sorted once, cheapest last, and
        // only the cheapest not yet taken of each node is in the heap: the heap
        // then hands out every entry in the same order as if all had been
        // queued at once (the order of entries is total: no two share their
        // node and the node they come from), while it holds one entry per
        // expanded node instead of one per leg. The lists keep only the nodes
        // (4 bytes an entry); an entry's costs are computed again, by the same
        // operations, when it is taken.
        let entry = |owner: usize, g_owner: f64, next: u32| {
            let tested = next & TESTED != 0;
            let next = (next & !TESTED) as usize;
            let g = g_owner + cell_distance(cell_of(owner), cell_of(next)) * res;
            State::new(g + bound[next], g, next, owner as u32, tested)
        };
        let mut successors = Successors::default();
        let mut heap = BinaryHeap::new();
        heap.push(Head {
            state: State::new(bound[src], 0.0, src, START, true),
            list: None,
        });
        while let Some(Head { state: e, list }) = heap.pop() {
            if let Some(l) = list {
                if let Some((owner, g, next)) = successors.take(l, &done) {
                    let state = entry(owner, g, next);
                    heap.push(Head { state, list });
                }
            }
            let node = e.node();
            if done[node] {
                continue;
            }
            if !e.tested() && !self.leg_clear(e.from(), node) {
                continue;
            }
            done[node] = true;
            dist[node] = e.g;
            prev[node] = e.from();
            if node == dst {
                break;
            }
            let mut queue = |next: usize, d: f64, tested: bool| {
                if done[next] {
                    return;
                }
                let b = bound[next];
                if b.is_infinite() || e.g + d + b > limit {
                    return;
                }
                successors.push(e.g + d + b, next, tested);
            };
            if node < n {
                let a = self.vertices[node];
                for &j in among {
                    if j != node {
                        queue(j, cell_distance(a, self.vertices[j]) * res, false);
                    }
                }
            }
            for &(next, d) in &extra[node] {
                queue(next, d, true);
            }
            if let Some((l, next)) = successors.close(node, e.g, &done) {
                heap.push(Head {
                    state: entry(node, e.g, next),
                    list: Some(l),
                });
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
        if guide.is_none() {
            path.reverse();
        }
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

/// An A* queue entry: smallest cost first, ties by node, then by the vertex
/// it is reached from. 24 bytes; the successor lists keep only the node.
#[derive(Debug, Clone, Copy, PartialEq)]
struct State {
    /// Cost so far plus the bound to go, metres.
    cost: f64,
    /// Cost so far, metres.
    g: f64,
    /// The node, with [`TESTED`] set when the leg from `from` is known to be
    /// clear.
    node: u32,
    /// The node it is reached from ([`START`] for the start).
    from: u32,
}

/// The flag of [`State::node`] for a leg known to be clear.
const TESTED: u32 = 1 << 31;
/// [`State::from`] of the start.
const START: u32 = u32::MAX;

impl State {
    fn new(cost: f64, g: f64, node: usize, from: u32, tested: bool) -> Self {
        debug_assert!(node < TESTED as usize);
        Self {
            cost,
            g,
            node: node as u32 | if tested { TESTED } else { 0 },
            from,
        }
    }

    fn node(&self) -> usize {
        (self.node & !TESTED) as usize
    }

    fn tested(&self) -> bool {
        self.node & TESTED != 0
    }

    /// The node it is reached from, `usize::MAX` for the start.
    fn from(&self) -> usize {
        if self.from == START {
            usize::MAX
        } else {
            self.from as usize
        }
    }
}

/// The successors of the expanded nodes of one search, each node's sorted with
/// its cheapest last, in one buffer of nodes (with [`TESTED`] set for a leg
/// known to be clear).
#[derive(Default)]
struct Successors {
    /// The entries of the node being expanded, before they are sorted: the
    /// cost with the bound (its bits: costs are finite and not negative, so
    /// they order as their values) and the node with its [`TESTED`] flag.
    open: Vec<(u64, u32)>,
    nodes: Vec<u32>,
    lists: Vec<List>,
}

/// One expanded node's successors in [`Successors::nodes`].
struct List {
    /// Where the list starts.
    start: usize,
    /// Where its untaken entries end.
    end: usize,
    /// The expanded node.
    owner: usize,
    /// Its cost from the start, metres.
    g: f64,
}

impl Successors {
    /// Adds an entry to the list of the node being expanded: `next` at `cost`
    /// (metres, with the bound).
    fn push(&mut self, cost: f64, next: usize, tested: bool) {
        debug_assert!(cost >= 0.0 && next < TESTED as usize);
        let flag = if tested { TESTED } else { 0 };
        self.open.push((cost.to_bits(), next as u32 | flag));
    }

    /// Sorts the entries pushed since the last call into the list of `owner`,
    /// reached at cost `g`: the list's index and its cheapest entry to a node
    /// not `done`.
    fn close(&mut self, owner: usize, g: f64, done: &[bool]) -> Option<(usize, u32)> {
        // The order of the heap's entries ([`State`]'s, whose node they all
        // come from here), reversed: by cost, then by node, the first last.
        self.open
            .sort_unstable_by_key(|&(cost, node)| Reverse((cost, node & !TESTED)));
        let start = self.nodes.len();
        self.nodes.extend(self.open.drain(..).map(|(_, node)| node));
        self.lists.push(List {
            start,
            end: self.nodes.len(),
            owner,
            g,
        });
        let l = self.lists.len() - 1;
        self.take(l, done).map(|(_, _, next)| (l, next))
    }

    /// The cheapest untaken entry of list `l` to a node not `done` yet; the
    /// entries to done nodes before it are dropped, as the search would skip
    /// them.
    /// Returns the list's owner and its cost with the entry.
    fn take(&mut self, l: usize, done: &[bool]) -> Option<(usize, f64, u32)> {
        let list = &mut self.lists[l];
        while list.end > list.start {
            list.end -= 1;
            let next = self.nodes[list.end];
            if !done[(next & !TESTED) as usize] {
                return Some((list.owner, list.g, next));
            }
        }
        None
    }
}

/// A heap entry: the cheapest untaken successor of an expanded node (`list`),
/// or the start.
struct Head {
    state: State,
    list: Option<usize>,
}

impl PartialEq for Head {
    fn eq(&self, other: &Self) -> bool {
        self.state == other.state
    }
}

impl Eq for Head {}

impl Ord for Head {
    fn cmp(&self, other: &Self) -> Ordering {
        self.state.cmp(&other.state)
    }
}

impl PartialOrd for Head {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Eq for State {}

impl Ord for State {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.node().cmp(&self.node()))
            .then_with(|| other.from().cmp(&self.from()))
    }
}

impl PartialOrd for State {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

#[cfg(test)]
mod tests;
