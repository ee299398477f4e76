//! The GVD against its definition, the incremental field against fresh ones.

use super::components::components;
use super::*;
use crate::geom::Cell;
use crate::geom::Point;
use crate::grid::search::search;
use proptest::prelude::*;

const RES: f64 = 0.1;
const RADIUS: f64 = 0.25;

/// A map of Free cells inside a one-cell Occupied frame, with Occupied
/// rectangles `(x, y, w, h)`.
pub(in crate::motion) fn room(
    w: usize,
    h: usize,
    rects: &[(usize, usize, usize, usize)],
) -> OccupancyGrid {
    let g = GridGeometry::new(w, h, RES, Point::new(-1.0, 2.0));
    let mut t = OccupancyGrid::filled(g, CellState::Occupied);
    t.fill_rect(1, 1, w - 1, h - 1, CellState::Free);
    for &(x, y, rw, rh) in rects {
        t.fill_rect(x % w, y % h, x % w + rw, y % h + rh, CellState::Occupied);
    }
    t
}

pub(in crate::motion) fn skeleton_of(map: &OccupancyGrid, robot: Cell) -> (Traversability, Gvd) {
    let trav = Traversability::new(map, RADIUS, robot);
    let d = gvd(map, &trav);
    (trav, d)
}

fn skeleton_rows(map: &OccupancyGrid, d: &Gvd, x: usize) -> Vec<usize> {
    let g = map.geometry();
    (0..g.height)
        .filter(|&y| d.skeleton[g.index(Cell::new(x, y))])
        .collect()
}

#[test]
fn odd_corridor_skeleton_is_the_centre_line() {
    // Free rows 1..=19: the centre row is 10.
    let map = room(60, 21, &[]);
    let (_, d) = skeleton_of(&map, Cell::new(30, 10));
    for x in 15..45 {
        assert_eq!(skeleton_rows(&map, &d, x), vec![10], "column {x}");
    }
}

#[test]
fn even_corridor_skeleton_is_one_row() {
    // Free rows 1..=18: the centre line lies between rows 9 and 10.
    let map = room(60, 20, &[]);
    let (_, d) = skeleton_of(&map, Cell::new(30, 10));
    for x in 15..45 {
        assert_eq!(skeleton_rows(&map, &d, x), vec![9], "column {x}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The run-based labelling groups cells exactly as a flood fill does.
    #[test]
    fn components_match_a_flood_fill(
        w in 1usize..30,
        h in 1usize..30,
        cells in proptest::collection::vec(any::<bool>(), 900),
    ) {
        let obstacle = &cells[..w * h];
        let label = components(w, h, obstacle);
        let mut flood = vec![NONE; w * h];
        let mut next = 0;
        for s in 0..w * h {
            if !obstacle[s] || flood[s] != NONE {
                continue;
            }
            let mut stack = vec![s];
            flood[s] = next;
            while let Some(i) = stack.pop() {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let j = (ny * w as i64 + nx) as usize;
                    if obstacle[j] && flood[j] == NONE {
                        flood[j] = next;
                        stack.push(j);
                    }
                }
            }
            next += 1;
        }
        for i in 0..w * h {
            prop_assert_eq!(label[i] == NONE, !obstacle[i]);
            for j in 0..w * h {
                if obstacle[i] && obstacle[j] {
                    prop_assert_eq!(label[i] == label[j], flood[i] == flood[j]);
                }
            }
        }
    }
}

/// The kept field equals one computed afresh, buffer by buffer, and its
/// diagram equals [`gvd`]'s.
fn assert_fresh(kept: &VoronoiField, knowledge: &OccupancyGrid, radius: f64, robot: Cell) {
    let fresh = VoronoiField::new(knowledge);
    let (a, b) = (&kept.field, &fresh.field);
    assert_eq!(a.obstacle, b.obstacle, "obstacles");
    assert_eq!(a.features.feature, b.features.feature, "features");
    assert_eq!(a.features.d2, b.features.d2, "squared distances");
    assert_eq!(a.clearance, b.clearance, "clearances");
    assert!(a.right == b.right && a.up == b.up, "straddling pairs");
    // A component's label is its first cell: relabelled in place, the
    // labels are those of a fresh labelling.
    assert!(a.components.label == b.components.label, "component labels");
    let trav = Traversability::new(knowledge, radius, robot);
    let (d, e) = (kept.diagram(knowledge, &trav), gvd(knowledge, &trav));
    assert_eq!(d.skeleton, e.skeleton, "skeleton");
    assert_eq!(d.clearances(), e.clearances(), "clearance");
    assert_eq!(d.edge_component, e.edge_component, "edge components");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Scans of a random map from random stops: after every scan the kept
    /// field and its diagram equal fresh ones.
    #[test]
    fn scans_keep_the_field_of_a_fresh_computation(
        w in 4usize..70,
        h in 4usize..70,
        walls in proptest::collection::vec((0usize..70, 0usize..70, 1usize..14, 1usize..14), 0..12),
        stops in proptest::collection::vec((0usize..70, 0usize..70), 1..8),
        range in 3.0f64..40.0,
        radius in proptest::sample::select(vec![0.0, 0.1, 0.25]),
    ) {
        let g = GridGeometry::new(w, h, RES, Point::default());
        let mut truth = OccupancyGrid::filled(g, CellState::Free);
        for &(x, y, rw, rh) in &walls {
            let (x, y) = (x % w, y % h);
            truth.fill_rect(x, y, (x + rw).min(w), (y + rh).min(h), CellState::Occupied);
        }
        let mut knowledge = OccupancyGrid::filled(g, CellState::Unknown);
        let mut kept = VoronoiField::new(&knowledge);
        for &(x, y) in &stops {
            let at = Cell::new(x % w, y % h);
            let mut changed = Vec::new();
            crate::sensing::scan(&truth, &mut knowledge, at, range, |i| changed.push(i));
            kept.update(&knowledge, &changed);
            assert_fresh(&kept, &knowledge, radius, at);
        }
    }

    /// Arbitrary changes, obstacles appearing as well as vanishing.
    #[test]
    fn any_changes_keep_the_field_of_a_fresh_computation(
        w in 1usize..40,
        h in 1usize..40,
        start in proptest::collection::vec(0usize..3, 1600),
        edits in proptest::collection::vec((0usize..40, 0usize..40, 1usize..15, 1usize..15, 0usize..3), 1..8),
    ) {
        let g = GridGeometry::new(w, h, RES, Point::default());
        let cells = (0..g.len()).map(|i| crate::grid::fixtures::STATES[start[i]]).collect();
        let mut knowledge = OccupancyGrid::from_cells(g, cells).unwrap();
        let mut kept = VoronoiField::new(&knowledge);
        for &(x, y, rw, rh, s) in &edits {
            let state = crate::grid::fixtures::STATES[s];
            let changed = crate::grid::fixtures::paint(&mut knowledge, (x, y, rw, rh), state);
            kept.update(&knowledge, &changed);
            assert_fresh(&kept, &knowledge, RADIUS, Cell::new(x % w, y % h));
        }
    }
}

#[test]
fn diagrams_in_recycled_buffers_equal_fresh_ones() {
    // A diagram over the whole map leaves skeleton and parts where the next
    // one, over a map known only in its lower half, has none.
    let whole = room(60, 50, &[(20, 10, 5, 30)]);
    let (_, old) = skeleton_of(&whole, Cell::new(5, 5));
    let mut half = whole.clone();
    half.fill_rect(0, 20, 60, 50, CellState::Unknown);
    let trav = Traversability::new(&half, RADIUS, Cell::new(5, 5));
    let g = half.geometry();
    let bounds = half.bounds_of(|c| c == CellState::Free).unwrap();
    let (x0, y0, x1, y1) = bounds;
    let mut field = Field::default();
    field.compute(&half, (x0, y0, x1 - x0 + 1, y1 - y0 + 1));
    let (rows, cols) = (0..field.bh, 0..field.bw);
    assert!(old.cells().iter().any(|&i| g.cell(i).y > y1));
    let mut old = old;
    let reused = Gvd::reuse(old.recycle());
    let reused = field.draw(g, &trav.passable, rows.clone(), cols.clone(), reused);
    let fresh = Gvd::fresh(g.len());
    let fresh = field.draw(g, &trav.passable, rows, cols, fresh);
    assert!(fresh.count() > 0);
    assert_eq!(reused.skeleton, fresh.skeleton);
    assert_eq!(reused.cells(), fresh.cells());
    assert_eq!(reused.clearances(), fresh.clearances());
    assert_eq!(reused.edge_component, fresh.edge_component);
    let listed: Vec<usize> = (0..g.len()).filter(|&i| fresh.skeleton[i]).collect();
    assert_eq!(fresh.cells(), &listed[..]);
}

#[test]
fn separate_corridors_have_separate_edge_components() {
    // A full wall splits the room into two corridors.
    let map = room(60, 30, &[(30, 0, 2, 30)]);
    let (_, d) = skeleton_of(&map, Cell::new(10, 15));
    let g = map.geometry();
    let parts = |xs: std::ops::Range<usize>| -> std::collections::BTreeSet<u32> {
        (0..g.len())
            .filter(|&i| d.skeleton[i] && xs.contains(&g.cell(i).x))
            .map(|i| d.edge_component[i])
            .collect()
    };
    let (left, right) = (parts(0..30), parts(32..60));
    assert!(!left.is_empty() && !right.is_empty());
    assert!(left.is_disjoint(&right), "{left:?} {right:?}");
    assert!(!left.contains(&u32::MAX));
}

#[test]
fn skeleton_passes_on_both_sides_of_a_pillar() {
    let map = room(60, 60, &[(25, 25, 10, 10)]);
    let (trav, d) = skeleton_of(&map, Cell::new(5, 5));
    let g = map.geometry();
    let col = skeleton_rows(&map, &d, 30);
    assert!(col.iter().any(|&y| y < 25), "{col:?}");
    assert!(col.iter().any(|&y| y > 35), "{col:?}");
    let row: Vec<usize> = (0..60)
        .filter(|&x| d.skeleton[g.index(Cell::new(x, 30))])
        .collect();
    assert!(row.iter().any(|&x| x < 25), "{row:?}");
    assert!(row.iter().any(|&x| x > 35), "{row:?}");
    // Midway between pillar and wall, one cell wide.
    assert!(col
        .iter()
        .all(|&y| (12..=13).contains(&y) || (46..=47).contains(&y)));
    // The ring around the pillar is connected, by the steps a path takes.
    let part = d.edge_component[g.index(Cell::new(30, col[0]))];
    for c in [
        Cell::new(30, *col.last().unwrap()),
        Cell::new(row[0], 30),
        Cell::new(*row.last().unwrap(), 30),
    ] {
        assert_eq!(d.edge_component[g.index(c)], part, "{c:?}");
        let open = |i: usize| trav.passable[i];
        let ci = g.index(c);
        let along = search(
            g,
            g.index(Cell::new(30, col[0])),
            |i| d.skeleton[i],
            open,
            |i| i == ci,
            |_| 0,
        );
        assert!(along.is_some(), "{c:?}");
    }
}
