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
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::travel;
    use crate::grid::CellState;
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
        let field = travel::sweep(g, &trav.passable, &[g.index(a)], travel::UNREACHED - 1);
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
            // A corner of the square sees the two next to it, not the opposite one.
            assert_eq!((graph.vertices.len(), graph.edge_count()), (4, 4));
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

    /// The shortest path length from `a` to `b` by Dijkstra over the whole
    /// graph (every vertex's [`VisibilityGraph::neighbours`]) plus the two ends,
    /// linked to what they see over `passable`: the eager search the lazy one
    /// must match.
    fn eager_length(
        graph: &VisibilityGraph,
        g: &GridGeometry,
        trav: &Traversability,
        a: Cell,
        b: Cell,
    ) -> Option<f64> {
        let n = graph.vertices.len();
        let cell = |i: usize| match i {
            i if i < n => graph.vertices[i],
            i if i == n => a,
            _ => b,
        };
        let sees = |x: Cell, y: Cell| segment_clear(g, x, y, |k| trav.passable[k]);
        let mut dist = vec![f64::INFINITY; n + 2];
        let mut done = vec![false; n + 2];
        dist[n] = 0.0;
        loop {
            let u = (0..n + 2)
                .filter(|&i| !done[i] && dist[i].is_finite())
                .min_by(|&x, &y| dist[x].total_cmp(&dist[y]))?;
            if u == n + 1 {
                return Some(dist[u]);
            }
            done[u] = true;
            let mut next: Vec<(usize, f64)> = if u < n {
                graph.neighbours(u)
            } else {
                Vec::new()
            };
            for (v, other) in [(n, a), (n + 1, b)] {
                if v != u && sees(cell(u), other) {
                    next.push((v, cell_distance(cell(u), other) * g.resolution));
                }
            }
            if u == n {
                next.extend(
                    (0..n)
                        .filter(|&v| sees(a, graph.vertices[v]))
                        .map(|v| (v, cell_distance(a, graph.vertices[v]) * g.resolution)),
                );
            }
            for (v, d) in next {
                dist[v] = dist[v].min(dist[u] + d);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]
        /// The lazy search, guided by the travel distances from the start or
        /// not, finds paths as short as an eager Dijkstra over the whole graph,
        /// with every leg clear.
        #[test]
        fn lazy_and_guided_searches_are_shortest(
            rects in prop::collection::vec(
                (0usize..60, 0usize..45, 1usize..15, 1usize..15, prop::bool::weighted(0.2)),
                0..10,
            ),
            ends in prop::collection::vec((0usize..60, 0usize..45), 6),
        ) {
            let map = rect_map(60, 45, &rects);
            let g = *map.geometry();
            let (a, rest) = (Cell::new(ends[0].0, ends[0].1), &ends[1..]);
            let (trav, graph) = setup(&map, a);
            let guide = travel::sweep(&g, &trav.passable, &[g.index(a)], travel::UNREACHED);
            for &(x, y) in rest {
                let b = Cell::new(x, y);
                let plain = graph.shortest_path(&g, &trav, a, b);
                let guided = graph.shortest_path_guided(&g, &trav, a, b, Some(&guide));
                for p in plain.iter().chain(&guided) {
                    check_legs(&map, &trav, p, a, b);
                }
                let len = |p: &Option<Vec<Cell>>| p.as_ref().map(|p| path_length(&g, p));
                prop_assert_eq!(plain.is_some(), guided.is_some());
                // The guide's limit on the queue changes nothing but the memory.
                let unlimited = graph.shortest_path_with(&g, &trav, a, b, Some(&guide), false);
                prop_assert_eq!(&guided, &unlimited);
                if let (Some(x), Some(y)) = (len(&plain), len(&guided)) {
                    prop_assert!((x - y).abs() < 1e-9, "plain {} guided {}", x, y);
                }
                if trav.passable[g.index(a)] && trav.passable[g.index(b)] {
                    if let Some(eager) = eager_length(&graph, &g, &trav, a, b) {
                        let x = len(&plain).unwrap_or(f64::INFINITY);
                        prop_assert!((x - eager).abs() < 1e-9, "lazy {} eager {}", x, eager);
                    }
                }
            }
        }

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
