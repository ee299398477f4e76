//! Drivable cells against the metric rule, and the kept state against fresh ones.

use super::*;
use crate::geom::Point;
use crate::grid::fixtures::{paint, STATES};
use crate::grid::GridGeometry;

#[test]
fn clearance_from_unknown_and_edges() {
    let g = GridGeometry::new(20, 11, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Free);
    k.fill_rect(15, 0, 20, 11, CellState::Unknown);
    let t = Traversability::new(&k, 0.25, Cell::new(5, 5));
    // Column 11 is 4 cells from Unknown column 15: 0.35 m; column 12: 0.25 m; 13: 0.15 m.
    assert!(t.traversable[g.index(Cell::new(12, 5))]);
    assert!(!t.traversable[g.index(Cell::new(13, 5))]);
    // Rows near the grid edge are not traversable.
    assert!(!t.traversable[g.index(Cell::new(5, 1))]);
    assert!(t.traversable[g.index(Cell::new(5, 2))]);
    // No known obstacle: clearance is infinite.
    assert!(t.clearance_at(0).is_infinite());
}

#[test]
fn robot_in_a_pinch_can_escape() {
    let g = GridGeometry::new(30, 30, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Free);
    k.fill_rect(0, 14, 14, 15, CellState::Occupied);
    let robot = Cell::new(5, 15);
    let t = Traversability::new(&k, 0.25, robot);
    assert!(!t.traversable[g.index(robot)]);
    assert!(t.passable[g.index(robot)]);
    assert!(t.passable[g.index(Cell::new(5, 18))]);
    assert!(!t.passable[g.index(Cell::new(5, 13))]);
}

/// The metric rule with full Euclidean distance transforms, as it was first
/// written: `(clearance, traversable)` per cell.
fn reference(knowledge: &OccupancyGrid, radius: f64) -> (Vec<f32>, Vec<bool>) {
    use super::super::distance::transform;
    let g = *knowledge.geometry();
    let res = g.resolution;
    let k = knowledge.cells();
    let (w, h) = (g.width, g.height);
    let n = g.len();
    let to_metres = |d: f32| ((d - 0.5).max(0.0) as f64 * res) as f32;
    let mut clearance = vec![f32::INFINITY; n];
    let mut safe_clearance = vec![0.0f32; n];
    if let Some((x0, y0, x1, y1)) = knowledge.bounds_of(|c| c != CellState::Unknown) {
        let (bw, bh) = (x1 - x0 + 1, y1 - y0 + 1);
        let d = transform(bw, bh, |x, y| {
            k[(y0 + y) * w + x0 + x] == CellState::Occupied
        });
        for y in 0..bh {
            for x in 0..bw {
                clearance[(y0 + y) * w + x0 + x] = to_metres(d[y * bw + x]);
            }
        }
        let (sx0, sy0) = (x0.saturating_sub(1), y0.saturating_sub(1));
        let (sx1, sy1) = ((x1 + 1).min(w - 1), (y1 + 1).min(h - 1));
        let (sw, sh) = (sx1 - sx0 + 1, sy1 - sy0 + 1);
        let d = transform(sw, sh, |x, y| k[(sy0 + y) * w + sx0 + x] != CellState::Free);
        for y in 0..sh {
            for x in 0..sw {
                let (gx, gy) = (sx0 + x, sy0 + y);
                let edge = (gx.min(gy).min(w - 1 - gx).min(h - 1 - gy) + 1) as f32;
                safe_clearance[gy * w + gx] = to_metres(d[y * sw + x].min(edge));
            }
        }
    }
    let need = radius as f32 - 1e-6;
    let traversable = safe_clearance
        .iter()
        .zip(k)
        .map(|(&c, &s)| s == CellState::Free && c >= need)
        .collect();
    (clearance, traversable)
}

fn random_knowledge(
    w: usize,
    h: usize,
    res: f64,
    bits: &[u8],
    known: (usize, usize, usize, usize),
) -> OccupancyGrid {
    let g = GridGeometry::new(w, h, res, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Unknown);
    let (kx0, ky0, kx1, ky1) = known;
    for y in 0..h {
        for x in 0..w {
            let inside = x >= kx0 % w && x <= kx1 % w && y >= ky0 % h && y <= ky1 % h;
            let b = bits[(y * w + x) % bits.len()];
            let s = match b {
                0 => CellState::Occupied,
                1 if inside => CellState::Unknown,
                _ if inside => CellState::Free,
                _ => CellState::Unknown,
            };
            k.set(Cell::new(x, y), s);
        }
    }
    k
}

proptest::proptest! {
    #[test]
    fn matches_the_metric_rule_exactly(
        w in 1usize..40,
        h in 1usize..40,
        res in proptest::sample::select(vec![0.02, 0.05, 0.1, 0.13, 0.25, 1.0]),
        radius in proptest::sample::select(vec![0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.45, 0.5, 0.8, 1.3]),
        bits in proptest::collection::vec(0u8..40, 1..1600),
        known in (0usize..40, 0usize..40, 0usize..40, 0usize..40),
    ) {
        let k = random_knowledge(w, h, res, &bits, known);
        let robot = Cell::new(w / 2, h / 2);
        let t = Traversability::new(&k, radius, robot);
        let (clearance, traversable) = reference(&k, radius);
        for (i, c) in clearance.iter().enumerate() {
            proptest::prop_assert_eq!(t.clearance_at(i).to_bits(), c.to_bits(), "clearance at {}", i);
        }
        proptest::prop_assert_eq!(t.traversable.as_slice(), traversable.as_slice());
    }
}

#[test]
fn matches_the_metric_rule_on_an_open_map() {
    // Large clearances and distant obstacles, at many radii and resolutions.
    let g = GridGeometry::new(120, 90, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Unknown);
    k.fill_rect(10, 5, 115, 80, CellState::Free);
    k.fill_rect(50, 30, 53, 33, CellState::Occupied);
    k.set(Cell::new(100, 70), CellState::Occupied);
    for res in [0.01, 0.05, 0.1, 0.3] {
        let k = OccupancyGrid::from_cells(
            GridGeometry::new(120, 90, res, Point::default()),
            k.cells().to_vec(),
        )
        .unwrap();
        for r in 0..60 {
            let radius = r as f64 * 0.037;
            let t = Traversability::new(&k, radius, Cell::new(60, 40));
            let (clearance, traversable) = reference(&k, radius);
            for (i, c) in clearance.iter().enumerate() {
                assert_eq!(t.clearance_at(i).to_bits(), c.to_bits());
            }
            assert_eq!(*t.traversable, traversable, "radius {radius} res {res}");
        }
    }
}

/// The kept cells against cells computed from scratch: flags, known bounds
/// and the Occupied cells of every column.
fn assert_fresh(kept: &Drivable, knowledge: &OccupancyGrid) {
    let fresh = Drivable::new(knowledge, kept.radius());
    assert_eq!(kept.traversable, fresh.traversable, "traversable");
    assert_eq!(kept.clearance.known, fresh.clearance.known, "known bounds");
    assert_eq!(
        kept.clearance.columns, fresh.clearance.columns,
        "occupied columns"
    );
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 96, ..Default::default() })]

    /// Scans of a random map from random cells (discs of ground truth): after
    /// every scan the kept cells equal cells computed from scratch.
    #[test]
    fn scans_keep_the_cells_of_a_fresh_computation(
        w in 4usize..60,
        h in 4usize..60,
        res in proptest::sample::select(vec![0.05, 0.1, 0.13, 0.25]),
        radius in proptest::sample::select(vec![0.0, 0.1, 0.15, 0.25, 0.35, 0.5, 1.3]),
        walls in proptest::collection::vec((0usize..60, 0usize..60, 1usize..12, 1usize..12), 0..10),
        stops in proptest::collection::vec((0usize..60, 0usize..60), 1..8),
        range in 3.0f64..25.0,
    ) {
        let g = GridGeometry::new(w, h, res, Point::default());
        let mut truth = OccupancyGrid::filled(g, CellState::Free);
        for &(x, y, rw, rh) in &walls {
            let (x, y) = (x % w, y % h);
            truth.fill_rect(x, y, (x + rw).min(w), (y + rh).min(h), CellState::Occupied);
        }
        let mut knowledge = OccupancyGrid::filled(g, CellState::Unknown);
        let mut kept = Drivable::new(&knowledge, radius);
        for &(x, y) in &stops {
            // A scan without occlusion: the ground truth of the disc around the stop.
            let (cx, cy) = ((x % w) as f64, (y % h) as f64);
            let mut changed = Vec::new();
            for i in 0..g.len() {
                let (px, py) = ((i % w) as f64, (i / w) as f64);
                if knowledge.cells()[i] == CellState::Unknown && (px - cx).hypot(py - cy) <= range {
                    knowledge.cells_mut()[i] = truth.cells()[i];
                    changed.push(i);
                }
            }
            kept.update(&knowledge, &changed);
            assert_fresh(&kept, &knowledge);
            // What a round takes from it is what it would compute itself.
            let robot = Cell::new(x % w, y % h);
            let t = kept.for_robot(&knowledge, robot);
            let f = Traversability::new(&knowledge, radius, robot);
            proptest::prop_assert_eq!(&t.passable, &f.passable);
            proptest::prop_assert_eq!(t.has_escape_region(), f.has_escape_region());
        }
    }

    /// Arbitrary changes, including known cells turning Unknown again.
    #[test]
    fn any_changes_keep_the_cells_of_a_fresh_computation(
        w in 1usize..40,
        h in 1usize..40,
        radius in proptest::sample::select(vec![0.0, 0.05, 0.15, 0.25, 0.45]),
        start in proptest::collection::vec(0usize..3, 1600),
        edits in proptest::collection::vec((0usize..40, 0usize..40, 1usize..15, 1usize..15, 0usize..3), 1..8),
    ) {
        let g = GridGeometry::new(w, h, 0.1, Point::default());
        let cells = (0..g.len()).map(|i| STATES[start[i]]).collect();
        let mut knowledge = OccupancyGrid::from_cells(g, cells).unwrap();
        let mut kept = Drivable::new(&knowledge, radius);
        for &(x, y, rw, rh, s) in &edits {
            let changed = paint(&mut knowledge, (x, y, rw, rh), STATES[s]);
            kept.update(&knowledge, &changed);
            assert_fresh(&kept, &knowledge);
        }
    }
}

#[test]
fn no_one_way_valve_through_a_pinch() {
    // Two open areas joined by a 0.3 m gap, too narrow for a 0.25 m robot. A
    // robot standing on a traversable cell beside the gap must not be allowed
    // through it (it could never come back).
    let g = GridGeometry::new(60, 30, 0.1, Point::default());
    let mut k = OccupancyGrid::filled(g, CellState::Free);
    k.fill_rect(29, 0, 31, 30, CellState::Occupied);
    k.fill_rect(29, 14, 31, 17, CellState::Free);
    let robot = Cell::new(25, 15);
    let t = Traversability::new(&k, 0.25, robot);
    assert!(t.traversable[g.index(robot)]);
    assert!(!t.passable[g.index(Cell::new(30, 15))]);
}
