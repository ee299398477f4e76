//! Safe robot motion along the edges of the Generalized Voronoi Diagram of the
//! known obstacles (paper section IV-D, "Safety robot movement along Voronoi
//! edge"): a robot first drives to the nearest Voronoi edge, follows the edges and
//! leaves them for its target, so that it keeps as far from obstacles as the map
//! allows.
//!
//! In: the knowledge map, a robot's drivable cells, the [`Gvd`] and the two ends.
//! Out: the path's waypoint cells.
//!
//! Three early-stopping searches ([`crate::grid::search`]) with the travel sweep's step
//! costs: from the start to the nearest skeleton cell (the *entry*); from the
//! target to the nearest skeleton cell of the entry's connected part (the *exit*);
//! A* along the skeleton from entry to exit (diagonal steps not cutting a
//! non-drivable corner). The path is these three legs. If the start reaches no
//! skeleton cell or the exit cannot be found, it falls back to the plain cheapest
//! drivable path (A*); `None` if the target is not drivable or not reachable.
//!
//! Each leg is then shortened by string pulling: a waypoint is skipped only if every
//! cell of the straight segment's supercover is drivable, so the clearance stays
//! above the robot radius; on the skeleton leg a shortcut must also keep a
//! clearance no smaller than the lowest clearance of the stretch of skeleton it
//! replaces, so the robot still keeps to the middle. Cost: the searches touch only
//! the cells cheaper than their goal (O(v log v) for `v` of them), and string
//! pulling O(k² · l) for a leg of `k` cells and segments of `l` cells.

use std::cell::RefCell;

use super::gvd::Gvd;
use crate::geom::Cell;
use crate::grid::line::segment_clear;
use crate::grid::path::pull;
use crate::grid::search::{octile, search};
use crate::grid::{GridGeometry, OccupancyGrid, Traversability};

/// A safe path from `from` to `to` along the Voronoi edges of `gvd` (paper section
/// IV-D): to the nearest reachable skeleton cell, along the skeleton to the
/// skeleton cell nearest `to`, then to `to`, all over `trav.passable` cells and
/// shortened where a straight segment stays drivable (see the module
/// documentation). Falls back to the plain cheapest drivable path where the
/// skeleton does not connect the two. Waypoint cells, `from` first and `to` last;
/// `None` if `to` is outside the grid or not reachable from `from`.
pub fn voronoi_path(
    knowledge: &OccupancyGrid,
    trav: &Traversability,
    gvd: &Gvd,
    from: Cell,
    to: Cell,
) -> Option<Vec<Cell>> {
    let g = knowledge.geometry();
    let passable = &trav.passable[..];
    let inside = |c: Cell| c.x < g.width && c.y < g.height;
    if !inside(from) || !inside(to) {
        return None;
    }
    if from == to {
        return Some(vec![from]);
    }
    if !passable[g.index(to)] {
        return None;
    }
    let clear = |a: Cell, b: Cell| segment_clear(g, a, b, |i| passable[i]);
    let mut out: Vec<Cell> = Vec::new();
    let mut append = |leg: Vec<Cell>| {
        for c in leg {
            if out.last() != Some(&c) {
                out.push(c);
            }
        }
    };
    match along_edges(g, passable, gvd, from, to) {
        Some([approach, edge, leave]) => {
            append(pull(&approach, |a, b| clear(approach[a], approach[b])));
            // The lowest clearance of each stretch `a..=b`: string pulling asks
            // for the stretches of one anchor `a` at a time, so their running
            // minima from `a` are computed once per anchor.
            let minima = RefCell::new((usize::MAX, Vec::new()));
            let floor = |a: usize, b: usize| {
                let mut m = minima.borrow_mut();
                let (anchor, run) = &mut *m;
                if *anchor != a {
                    *anchor = a;
                    run.clear();
                    let mut low = f32::INFINITY;
                    run.extend(edge[a..].iter().map(|&c| {
                        low = low.min(gvd.clearance(g.index(c)));
                        low
                    }));
                }
                run[b - a]
            };
            append(pull(&edge, |a, b| {
                let min = floor(a, b);
                segment_clear(g, edge[a], edge[b], |i| {
                    passable[i] && gvd.clearance(i) >= min
                })
            }));
            append(pull(&leave, |a, b| clear(leave[a], leave[b])));
        }
        None => {
            let open = |i: usize| passable[i];
            let ti = g.index(to);
            let cells = search(
                g,
                g.index(from),
                open,
                open,
                |i| i == ti,
                |i| octile(g.cell(i), to),
            )?;
            append(pull(&cells, |a, b| clear(cells[a], cells[b])));
        }
    }
    Some(out)
}

/// The three legs of the motion along the Voronoi edges (cells, each leg's first
/// cell the previous leg's last), or `None` if the skeleton does not connect.
///
/// Three early-stopping searches: from `from` to the nearest skeleton cell (the
/// entry); from `to` to the nearest skeleton cell of the entry's edge component
/// (the exit); A* along the skeleton from entry to exit.
fn along_edges(
    g: &GridGeometry,
    passable: &[bool],
    gvd: &Gvd,
    from: Cell,
    to: Cell,
) -> Option<[Vec<Cell>; 3]> {
    let open = |i: usize| passable[i];
    let on_edge = |i: usize| gvd.skeleton[i];
    let approach = search(g, g.index(from), open, open, on_edge, |_| 0)?;
    let entry = g.index(*approach.last()?);
    let part = gvd.edge_component[entry];
    let mut leave = search(
        g,
        g.index(to),
        open,
        open,
        |i| gvd.skeleton[i] && gvd.edge_component[i] == part,
        |_| 0,
    )?;
    leave.reverse();
    let exit = *leave.first()?;
    let xi = g.index(exit);
    let edge = search(
        g,
        entry,
        |i| on_edge(i) && open(i),
        open,
        |i| i == xi,
        |i| octile(g.cell(i), exit),
    )?;
    Some([approach, edge, leave])
}

#[cfg(test)]
mod tests {
    use super::super::gvd::tests::{room, skeleton_of};
    use super::*;
    use crate::grid::path::shortcut_path;
    use crate::grid::travel::sweep;
    use crate::grid::{CellState, UNREACHED};
    use proptest::prelude::*;

    /// Every waypoint and every supercover cell of every leg is passable.
    fn legs_passable(g: &GridGeometry, trav: &Traversability, path: &[Cell]) -> bool {
        path.iter().all(|&c| trav.passable[g.index(c)])
            && path
                .windows(2)
                .all(|l| segment_clear(g, l[0], l[1], |i| trav.passable[i]))
    }

    /// Lowest clearance (cells) over the supercover of every leg.
    fn min_clearance(g: &GridGeometry, d: &Gvd, path: &[Cell]) -> f32 {
        let lowest = std::cell::Cell::new(f32::INFINITY);
        for l in path.windows(2) {
            segment_clear(g, l[0], l[1], |i| {
                lowest.set(lowest.get().min(d.clearance(i)));
                true
            });
        }
        lowest.get()
    }

    #[test]
    fn path_around_pillar_is_drivable_and_ends_right() {
        let map = room(60, 60, &[(25, 25, 10, 10)]);
        let from = Cell::new(5, 5);
        let to = Cell::new(55, 55);
        let (trav, d) = skeleton_of(&map, from);
        let p = voronoi_path(&map, &trav, &d, from, to).unwrap();
        assert_eq!(p.first(), Some(&from));
        assert_eq!(p.last(), Some(&to));
        assert!(legs_passable(map.geometry(), &trav, &p));
    }

    #[test]
    fn path_keeps_to_the_middle_of_a_wide_room() {
        // A wide room with a block in the middle: the shortest path grazes the
        // block's corners, the Voronoi path passes midway between block and wall.
        let map = room(100, 60, &[(40, 15, 20, 30)]);
        let from = Cell::new(15, 30);
        let to = Cell::new(85, 30);
        let (trav, d) = skeleton_of(&map, from);
        let g = map.geometry();
        let p = voronoi_path(&map, &trav, &d, from, to).unwrap();
        assert!(legs_passable(g, &trav, &p));
        let f = sweep(g, &trav.passable, &[g.index(from)], UNREACHED);
        let plain = shortcut_path(g, &f, &trav.passable, to).unwrap();
        let (cv, cp) = (min_clearance(g, &d, &p), min_clearance(g, &d, &plain));
        assert!(cv >= cp, "voronoi {cv} < plain {cp}");
        assert!(cv >= 6.0 && cp < 5.0, "voronoi {cv}, plain {cp}");
    }

    #[test]
    fn unreachable_target_gives_none() {
        // A full wall splits the room.
        let map = room(60, 30, &[(30, 0, 2, 30)]);
        let from = Cell::new(10, 15);
        let (trav, d) = skeleton_of(&map, from);
        assert!(voronoi_path(&map, &trav, &d, from, Cell::new(50, 15)).is_none());
        assert!(voronoi_path(&map, &trav, &d, from, Cell::new(20, 15)).is_some());
        assert_eq!(voronoi_path(&map, &trav, &d, from, from), Some(vec![from]));
    }

    fn map_strategy() -> impl Strategy<Value = OccupancyGrid> {
        (
            30usize..90,
            30usize..70,
            proptest::collection::vec((0usize..90, 0usize..70, 1usize..12, 1usize..12), 0..10),
        )
            .prop_map(|(w, h, rects)| room(w, h, &rects))
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        #[test]
        fn paths_are_drivable_and_none_iff_unreached(
            map in map_strategy(),
            a in any::<prop::sample::Index>(),
            b in any::<prop::sample::Index>(),
        ) {
            let g = *map.geometry();
            let free: Vec<usize> =
                (0..g.len()).filter(|&i| map.cells()[i] == CellState::Free).collect();
            prop_assume!(!free.is_empty());
            let from = g.cell(free[a.index(free.len())]);
            let to = g.cell(free[b.index(free.len())]);
            let (trav, d) = skeleton_of(&map, from);
            for i in 0..g.len() {
                prop_assert!(!d.skeleton[i] || trav.passable[i]);
            }
            let f = sweep(&g, &trav.passable, &[g.index(from)], UNREACHED);
            let p = voronoi_path(&map, &trav, &d, from, to);
            prop_assert_eq!(p.is_some(), f.reached(g.index(to)));
            if let Some(p) = p {
                prop_assert_eq!(p.first(), Some(&from));
                prop_assert_eq!(p.last(), Some(&to));
                prop_assert!(legs_passable(&g, &trav, &p), "{:?}", p);
            }
        }
    }
}
