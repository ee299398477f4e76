//! The visibility graph's paths against the grid's, on maps built for each case.

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
