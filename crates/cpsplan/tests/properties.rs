//! Invariants of the simulation across random maps (proptest): the knowledge map
//! never contradicts the ground truth, driven paths never cross an obstacle,
//! coverage never decreases, and `S` equals a brute-force count.

use cpsplan::geom::{Cell, Point};
use cpsplan::grid::line::segment_clear;
use cpsplan::sensing::{expected_gain, scan};
use cpsplan::world::{CellState, GridGeometry, OccupancyGrid};
use cpsplan::{run_episode, run_episode_with, Config};
use proptest::prelude::*;

/// A random map: solid border, random rectangles of wall, free elsewhere.
fn random_map(w: usize, h: usize, rects: &[(usize, usize, usize, usize)]) -> OccupancyGrid {
    let g = GridGeometry::new(w, h, 0.1, Point::new(-1.0, 2.0));
    let mut t = OccupancyGrid::filled(g, CellState::Occupied);
    t.fill_rect(1, 1, w - 1, h - 1, CellState::Free);
    for &(x, y, rw, rh) in rects {
        t.fill_rect(x % w, y % h, x % w + rw, y % h + rh, CellState::Occupied);
    }
    t
}

fn map_strategy() -> impl Strategy<Value = OccupancyGrid> {
    (
        30usize..90,
        30usize..70,
        proptest::collection::vec((0usize..90, 0usize..70, 1usize..12, 1usize..12), 0..10),
    )
        .prop_map(|(w, h, rects)| random_map(w, h, &rects))
}

/// Free cells of the map, deterministic order.
fn free_cells(t: &OccupancyGrid) -> Vec<Cell> {
    let g = t.geometry();
    (0..g.len())
        .filter(|&i| t.cells()[i] == CellState::Free)
        .map(|i| g.cell(i))
        .collect()
}

fn small_config(seed: u64) -> Config {
    let mut c = Config {
        seed,
        ..Config::default()
    };
    c.scanner.range = 2.5;
    c.mission.max_scans = 60;
    c
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn episodes_keep_their_invariants(truth in map_strategy(), pick in 0usize..10_000, seed in 0u64..1000) {
        let free = free_cells(&truth);
        prop_assume!(!free.is_empty());
        let g = *truth.geometry();
        let start = g.cell_center(free[pick % free.len()]);
        let config = small_config(seed);
        let mut last = (0.0, 0.0);
        let mut steps = Vec::new();
        let episode = run_episode(&truth, start, &config, |s| {
            steps.push((s.coverage, s.wall_coverage));
        }).unwrap();
        // Coverage never decreases.
        for &(c, w) in &steps {
            prop_assert!(c >= last.0 && w >= last.1);
            last = (c, w);
        }
        // The knowledge map never contradicts the ground truth.
        let k = episode.knowledge.as_ref().unwrap();
        for (kc, tc) in k.cells().iter().zip(truth.cells()) {
            prop_assert!(*kc == CellState::Unknown || kc == tc);
        }
        // Every planned and driven leg stays on known-Free cells (thus truth-free
        // cells).
        for s in &episode.steps {
            for leg in s.plan.path.windows(2).chain(s.driven_path().windows(2)) {
                let a = g.world_to_cell(leg[0]).unwrap();
                let b = g.world_to_cell(leg[1]).unwrap();
                prop_assert!(segment_clear(&g, a, b, |i| k.cells()[i] == CellState::Free
                    && truth.cells()[i] == CellState::Free));
            }
            // Scan positions are free in the ground truth.
            prop_assert_eq!(truth.get(s.cell), CellState::Free);
        }
        // Each step's driven path ends where the next scan happened.
        for pair in episode.steps.windows(2) {
            if let Some(end) = pair[0].driven_path().last() {
                prop_assert_eq!(g.world_to_cell(*end), Some(pair[1].cell));
            }
        }
        // Stopping means no reachable candidate expects anything new.
        prop_assert!(episode.summary.scans <= config.mission.max_scans);
        // Same inputs and seed give the same record.
        let again = run_episode(&truth, start, &config, |_| {}).unwrap();
        prop_assert_eq!(&again.steps, &episode.steps);
    }

    #[test]
    fn expected_gain_equals_brute_force(truth in map_strategy(), pick in 0usize..10_000, range in 0.3f64..4.0) {
        // A knowledge map from one scan, then S at another free cell checked cell
        // by cell against the closed-form visibility rule (`visible_in_quadrant`).
        let free = free_cells(&truth);
        prop_assume!(free.len() > 2);
        let g = *truth.geometry();
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        let rc = range / g.resolution;
        scan(&truth, &mut k, free[pick % free.len()], rc, |_| {});
        let at = free[(pick / 7) % free.len()];
        let s = expected_gain(&k, at, rc, usize::MAX);
        let mut swept = std::collections::HashSet::new();
        cpsplan::sensing::visible_cells(&g, at, rc, |i| k.cells()[i] == CellState::Occupied, |i| {
            swept.insert(i);
            false
        });
        let r2 = (rc * rc + 1e-9).floor() as i64;
        let (mut sure, mut ties) = (0usize, 0usize);
        for i in 0..g.len() {
            if k.cells()[i] != CellState::Unknown {
                continue;
            }
            let c = g.cell(i);
            let (dx, dy) = (c.x as i64 - at.x as i64, c.y as i64 - at.y as i64);
            if dx * dx + dy * dy > r2 {
                prop_assert!(!swept.contains(&i), "out of range but counted: {:?}", c);
                continue;
            }
            let (visible, tie) = visible_in_quadrant(&k, at, dx, dy, r2);
            if tie {
                // A line exactly through a tile edge: the sweep may side either way,
                // but never sees what the permissive rule does not.
                prop_assert!(visible || !swept.contains(&i));
                ties += usize::from(swept.contains(&i));
            } else {
                prop_assert_eq!(visible, swept.contains(&i), "target {:?} from {:?}", c, at);
                sure += usize::from(visible);
            }
        }
        prop_assert_eq!(s, sure + ties);
    }
}

/// The closed-form visibility rule of the sweep for a transparent target at offset
/// (dx, dy): in the target's quadrant, at (depth, col), it is visible iff for every
/// nearer row d the line from the viewer's centre to the target's centre does not
/// pass strictly inside the centre-line span (col ± ½) of an in-range wall tile of
/// that row (a run of walls in one row blocks its whole span). Returns
/// (visible, tie): `tie` when the line passes exactly through a tile edge of a
/// wall, where the sweep's rounding decides.
/// Maps (depth, col) of a quadrant back to an offset from the viewer.
type QuadrantMap = fn(i64, i64) -> (i64, i64);

fn visible_in_quadrant(k: &OccupancyGrid, at: Cell, dx: i64, dy: i64, r2: i64) -> (bool, bool) {
    if dx == 0 && dy == 0 {
        return (true, false);
    }
    // Quadrant: (depth, col) and the map from (depth, col) back to offsets.
    let (depth, col, to_xy): (i64, i64, QuadrantMap) = if dy >= dx.abs() {
        (dy, dx, |d, c| (c, d))
    } else if -dy >= dx.abs() {
        (-dy, dx, |d, c| (c, -d))
    } else if dx > 0 {
        (dx, dy, |d, c| (d, c))
    } else {
        (-dx, dy, |d, c| (-d, c))
    };
    let g = k.geometry();
    let wall = |d: i64, c: i64| {
        if c * c + d * d > r2 {
            return false;
        }
        let (ox, oy) = to_xy(d, c);
        g.checked_cell(at.x as i64 + ox, at.y as i64 + oy)
            .map(|cell| k.get(cell) == CellState::Occupied)
            .unwrap_or(false)
    };
    let mut tie = false;
    for d in 1..depth {
        // x·depth = d·col; walls at floor and ceil of x may block.
        let num = d * col;
        let lo = num.div_euclid(depth);
        for c in [lo, lo + 1] {
            let inside = (2 * c - 1) * depth < 2 * num && 2 * num < (2 * c + 1) * depth;
            if inside && wall(d, c) {
                return (false, false);
            }
            if 2 * num == (2 * c + 1) * depth {
                // On the shared edge of two walls of one row: no gap between them.
                if wall(d, c) && wall(d, c + 1) {
                    return (false, false);
                }
                tie |= wall(d, c) || wall(d, c + 1);
            }
        }
    }
    (true, tie)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// With children, every CPS cycle keeps each child in certain line of sight of
    /// both parent positions, within the link's range limits and sight clearance,
    /// on the knowledge map the cycle was planned on, and on the ground truth no
    /// line of sight touches a cell that is not free (full squares); each child stands in its
    /// AND region (so every subgoal leg has one); every robot's path keeps the
    /// robot's radius clear of true obstacles (outside the escape region of its
    /// start).
    #[test]
    fn cps_cycles_keep_their_links(truth in map_strategy(), pick in 0usize..10_000, seed in 0u64..1000) {
        use cpsplan::mission::cycle_and_regions;
        use cpsplan::children::CycleParams;
        use cpsplan::sensing::certain_view;
        use cpsplan::grid::Traversability;
        let free = free_cells(&truth);
        prop_assume!(!free.is_empty());
        let g = *truth.geometry();
        let start = g.cell_center(free[pick % free.len()]);
        let mut config = small_config(seed);
        config.scanner.range = 4.0;
        // Two to four children, every strategy.
        config.children.count = 2 + (seed as usize / 2) % 3;
        config.children.strategy = cpsplan::config::ChildStrategy::ALL[(seed as usize / 6) % 5];
        config.mission.max_scans = 20;
        // A short link range in half the cases, so that long moves need subgoals.
        if seed % 2 == 0 {
            config.children.max_range = Some(2.5);
        }
        let mut known = Vec::new();
        let episode = run_episode_with(&truth, start, &config, |_, k| known.push(k.clone())).unwrap();
        let link = CycleParams::from_config(&config).link;
        let cell = |p: Point| g.world_to_cell(p).unwrap();
        let metres = |a: Point, b: Point| (a.x - b.x).hypot(a.y - b.y);
        // Every move between two scans ran as at least one CPS cycle.
        prop_assert!(episode.summary.cps_cycles + 1 >= episode.summary.scans);
        let clear_of_truth = |path: &[Point], radius: f64| {
            let Some(&first) = path.first() else { return true };
            let trav = Traversability::new(&truth, radius, cell(first));
            path.windows(2).all(|l| segment_clear(&g, cell(l[0]), cell(l[1]), |i| trav.passable[i]))
        };
        for (step, k) in episode.steps.iter().zip(&known) {
            for cycle in &step.movement.cycles {
                let (from, to) = (cell(cycle.parent_from), cell(cycle.parent_to));
                let regions = cycle_and_regions(k, cycle, &config);
                for (child, region) in cycle.children.iter().zip(&regions) {
                    let c = cell(child.to);
                    prop_assert!(region[g.index(c)], "child at {:?} outside its AND region", c);
                    prop_assert!(child.stays || child.and_region_cells > 0);
                    for p in [cycle.parent_from, cycle.parent_to] {
                        let d = metres(g.cell_center(c), p);
                        prop_assert!(d >= link.min - 1e-9 && d <= link.max + 1e-9, "link {} m", d);
                    }
                    let view = certain_view(k, c, link);
                    prop_assert!(view[g.index(from)] && view[g.index(to)],
                        "child at {:?} does not see {:?} and {:?}", c, from, to);
                    // On the ground truth, by the plain supercover: no cell whose
                    // full square the line touches is anything but free.
                    for p in [from, to] {
                        prop_assert!(segment_clear(&g, c, p, |i| truth.cells()[i] == CellState::Free),
                            "the line of sight {:?} -> {:?} touches a wall", c, p);
                    }
                    prop_assert!(clear_of_truth(&child.path, config.children.radius),
                        "child path {:?}", child.path);
                }
                prop_assert!(clear_of_truth(&cycle.parent_path, config.robot.radius),
                    "parent path {:?}", cycle.parent_path);
                // No child hides another from the parent.
                let r = config.children.radius / g.resolution;
                let m = config.children.marker_radius / g.resolution;
                for (a, ca) in cycle.children.iter().enumerate() {
                    for cb in &cycle.children[a + 1..] {
                        prop_assert!(cpsplan::children::apart(cell(ca.to), cell(cb.to), &[from, to], r, m),
                            "children at {:?} and {:?} in line with the parent", ca.to, cb.to);
                    }
                }
                // No two children share a spot.
                prop_assert_eq!(cycle.children.len(), config.children.count);
                for (a, ca) in cycle.children.iter().enumerate() {
                    for cb in &cycle.children[a + 1..] {
                        if !(ca.stays && cb.stays) {
                            let d = metres(ca.to, cb.to);
                            prop_assert!(d >= 2.0 * config.children.radius - 1e-9, "children {} m apart", d);
                        }
                    }
                }
            }
        }
    }
}
