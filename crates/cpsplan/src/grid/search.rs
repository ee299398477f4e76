//! Early-stopping best-first search on the grid (Dijkstra, or A* with a
//! heuristic), with the step costs of [`super::travel`]: straight 29, diagonal 41,
//! a diagonal step only where both cells beside it are open.
//!
//! A full [`super::travel::sweep`] settles every reachable cell; the searches of a
//! CPS cycle (to the nearest Voronoi edge, along it, off it) settle only the cells
//! cheaper than their goal, usually a small part of the map. The working buffers
//! are kept per thread and only the cells a search touched are reset, so a search
//! costs O(visited · log visited), independent of the map's size.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::travel::{DIAGONAL, STRAIGHT, UNREACHED};
use crate::geom::Cell;
use crate::grid::GridGeometry;

/// No parent.
const NONE: u32 = u32::MAX;

/// Per-thread working buffers: costs and parents over the whole grid (all
/// [`UNREACHED`] / [`NONE`] between searches) and the cells touched.
#[derive(Default)]
struct Scratch {
    cost: Vec<u32>,
    parent: Vec<u32>,
    touched: Vec<u32>,
    heap: BinaryHeap<Reverse<(u32, u32)>>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

/// The octile distance between two cells in step-cost units: a consistent A*
/// heuristic for [`search`].
pub fn octile(a: Cell, b: Cell) -> u32 {
    let (dx, dy) = (a.x.abs_diff(b.x) as u32, a.y.abs_diff(b.y) as u32);
    let (lo, hi) = (dx.min(dy), dx.max(dy));
    STRAIGHT * (hi - lo) + DIAGONAL * lo
}

/// The cheapest path from `source` to the first cell with `goal(index)` that the
/// search settles, over cells with `open(index)` (the source need not be open);
/// a diagonal step needs both cells beside it to satisfy `corner(index)`.
/// `heuristic(index)` must be a consistent lower bound on the cost to the goal
/// (0 for plain Dijkstra). Cells, source first; `None` when no goal is reachable.
pub fn search(
    geometry: &GridGeometry,
    source: usize,
    open: impl Fn(usize) -> bool,
    corner: impl Fn(usize) -> bool,
    goal: impl Fn(usize) -> bool,
    heuristic: impl Fn(usize) -> u32,
) -> Option<Vec<Cell>> {
    let n = geometry.len();
    if source >= n {
        return None;
    }
    SCRATCH.with(|s| {
        let s = &mut *s.borrow_mut();
        if s.cost.len() != n {
            s.cost = vec![UNREACHED; n];
            s.parent = vec![NONE; n];
        }
        let found = run(geometry, s, source, &open, &corner, &goal, &heuristic);
        let path = found.map(|end| {
            let mut path = vec![geometry.cell(end)];
            let mut i = end;
            while s.parent[i] != NONE {
                i = s.parent[i] as usize;
                path.push(geometry.cell(i));
            }
            path.reverse();
            path
        });
        for &i in &s.touched {
            s.cost[i as usize] = UNREACHED;
            s.parent[i as usize] = NONE;
        }
        s.touched.clear();
        s.heap.clear();
        path
    })
}

/// The search proper: the goal cell settled first, if any.
fn run(
    geometry: &GridGeometry,
    s: &mut Scratch,
    source: usize,
    open: &impl Fn(usize) -> bool,
    corner: &impl Fn(usize) -> bool,
    goal: &impl Fn(usize) -> bool,
    heuristic: &impl Fn(usize) -> u32,
) -> Option<usize> {
    let (w, h) = (geometry.width as i64, geometry.height as i64);
    s.cost[source] = 0;
    s.touched.push(source as u32);
    s.heap.push(Reverse((heuristic(source), source as u32)));
    while let Some(Reverse((f, p))) = s.heap.pop() {
        let i = p as usize;
        let c = s.cost[i];
        if f != c.saturating_add(heuristic(i)) {
            continue; // stale entry
        }
        if goal(i) {
            return Some(i);
        }
        let (x, y) = ((i as i64) % w, (i as i64) / w);
        for (dx, dy) in [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (-1, 1),
            (1, -1),
            (-1, -1),
        ] {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w || ny >= h {
                continue;
            }
            let j = (ny * w + nx) as usize;
            if !open(j) {
                continue;
            }
            let step = if dx != 0 && dy != 0 {
                if !corner((y * w + nx) as usize) || !corner((ny * w + x) as usize) {
                    continue;
                }
                DIAGONAL
            } else {
                STRAIGHT
            };
            let nc = c + step;
            if nc < s.cost[j] {
                if s.cost[j] == UNREACHED {
                    s.touched.push(j as u32);
                }
                s.cost[j] = nc;
                s.parent[j] = i as u32;
                s.heap
                    .push(Reverse((nc.saturating_add(heuristic(j)), j as u32)));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::travel::sweep;
    use proptest::prelude::*;

    fn cost_of(path: &[Cell]) -> u32 {
        path.windows(2)
            .map(|l| {
                if l[0].x != l[1].x && l[0].y != l[1].y {
                    DIAGONAL
                } else {
                    STRAIGHT
                }
            })
            .sum()
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

        /// Dijkstra and A* find paths exactly as cheap as the full sweep says,
        /// made of legal steps, and none where the sweep reaches nothing.
        #[test]
        fn matches_the_full_sweep(
            w in 2usize..40,
            h in 2usize..40,
            blocked in proptest::collection::vec(any::<bool>(), 1600),
            a in any::<prop::sample::Index>(),
            b in any::<prop::sample::Index>(),
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let passable: Vec<bool> = (0..g.len()).map(|i| !blocked[i] || i % 3 == 0).collect();
            let (s, t) = (a.index(g.len()), b.index(g.len()));
            let field = sweep(&g, &passable, &[s], UNREACHED);
            let target = g.cell(t);
            let open = |i: usize| passable[i];
            let dijkstra = search(&g, s, open, open, |i| i == t, |_| 0);
            let astar = search(&g, s, open, open, |i| i == t, |i| octile(g.cell(i), target));
            let reached = field.reached(t) && (passable[t] || t == s);
            for p in [dijkstra, astar] {
                prop_assert_eq!(p.is_some(), reached);
                if let Some(p) = p {
                    prop_assert_eq!(p.first(), Some(&g.cell(s)));
                    prop_assert_eq!(p.last(), Some(&target));
                    prop_assert_eq!(cost_of(&p), field.cost[t]);
                    for l in p.windows(2) {
                        prop_assert!(l[0].x.abs_diff(l[1].x) <= 1 && l[0].y.abs_diff(l[1].y) <= 1);
                        prop_assert!(passable[g.index(l[1])]);
                        if l[0].x != l[1].x && l[0].y != l[1].y {
                            prop_assert!(passable[g.index(Cell::new(l[1].x, l[0].y))]);
                            prop_assert!(passable[g.index(Cell::new(l[0].x, l[1].y))]);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn stops_at_the_nearest_goal() {
        let g = GridGeometry::new(30, 1, 0.1, Point::default());
        let p = search(&g, 10, |_| true, |_| true, |i| i == 2 || i == 25, |_| 0).unwrap();
        assert_eq!(p.last(), Some(&Cell::new(2, 0)));
        assert_eq!(p.len(), 9);
    }
}
