//! The known-map bound: greedy cover and lower bound on maps whose answer is
//! known, their invariants on random rooms, and the exploring planners measured
//! against it.

use cpsplan::bound::{known_map_bound, BoundParams, KnownMapBound, BOUND_SHARES};
use cpsplan::config::Planner;
use cpsplan::geom::Point;
use cpsplan::grid::{CellState, GridGeometry, OccupancyGrid};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, Config};
use proptest::prelude::*;

/// `n` square rooms 4 m wide in a row, each joined to a corridor along the
/// bottom by a door, walls 0.1 m thick; 0.1 m cells. The scanner range is
/// short (3 m), so the corridor needs stations of its own.
fn rooms(n: usize) -> OccupancyGrid {
    let w = 41 * n + 1;
    let g = GridGeometry::new(w, 62, 0.1, Point::default());
    let mut t = OccupancyGrid::filled(g, CellState::Occupied);
    t.fill_rect(1, 1, w - 1, 20, CellState::Free); // corridor, 1.9 m
    for k in 0..n {
        let x0 = 41 * k + 1;
        t.fill_rect(x0, 21, x0 + 40, 61, CellState::Free); // room
        t.fill_rect(x0 + 15, 20, x0 + 25, 21, CellState::Free); // door
    }
    t
}

fn bound(truth: &OccupancyGrid, range: f64) -> KnownMapBound {
    let mut config = Config::default();
    config.scanner.range = range;
    known_map_bound(
        truth,
        Point::new(1.0, 1.0),
        &config,
        BoundParams::default(),
        None,
    )
    .expect("the bound is computed")
}

#[test]
fn every_room_needs_its_own_station() {
    let truth = rooms(4);
    let b = bound(&truth, 3.0);
    assert_eq!(b.coverable_targets, b.targets);
    let full = b.level(1.0).expect("100 % is reported");
    // No station sees into two rooms' far corners: at least one per room.
    assert!(full.greedy_stations >= 4, "{full:?}");
    assert!(full.lower_bound_stations >= 4, "{full:?}");
    assert!(full.lower_bound_stations <= full.greedy_stations);
    // The stations' gains add up to the coverable targets.
    let total: usize = b.stations.iter().map(|s| s.new_targets).sum();
    assert_eq!(total, b.coverable_targets);
    assert!((b.stations.last().map_or(0.0, |s| s.coverage) - 1.0).abs() < 1e-12);
}

#[test]
fn an_open_room_in_range_needs_one_station() {
    let g = GridGeometry::new(60, 60, 0.1, Point::default());
    let mut t = OccupancyGrid::filled(g, CellState::Occupied);
    t.fill_rect(1, 1, 59, 59, CellState::Free);
    let b = bound(&t, 20.0);
    for l in &b.levels {
        assert_eq!((l.greedy_stations, l.lower_bound_stations), (1, 1), "{l:?}");
    }
}

#[test]
fn every_planner_against_the_bound_on_the_site() {
    let truth = BuiltinMap::Site.generate(0);
    let start = BuiltinMap::Site.default_start();
    let b = known_map_bound(
        &truth,
        start,
        &Config::default(),
        BoundParams::default(),
        None,
    )
    .expect("the site's bound");
    let g99 = b.level(0.99).map(|l| l.greedy_stations).unwrap_or(0);
    assert!(g99 >= 1);
    for planner in Planner::ALL {
        let mut config = Config::default();
        config.parent.planner = planner;
        let ep = run_episode(&truth, start, &config, |_| {}).expect("episode runs");
        let s99 = ep
            .steps
            .iter()
            .position(|s| s.coverage >= 0.99)
            .map(|k| k + 1)
            .expect("99 % is reached");
        // No explorer beats the known-map lower bound.
        let lb = b.level(0.99).map(|l| l.lower_bound_stations).unwrap_or(0);
        assert!(
            s99 >= lb,
            "{planner:?}: {s99} scans to 99 % under the bound {lb}"
        );
        // Every planner stays within twice the greedy cover on this open site.
        assert!(
            s99 <= 2 * g99,
            "{planner:?}: {s99} scans to 99 %, greedy {g99}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// On random rooms with pillars: the levels grow with the share, the lower
    /// bound never exceeds the greedy cover, and the cover's coverage rises to 1.
    #[test]
    fn levels_are_ordered_and_bounded(
        pillars in prop::collection::vec((2usize..36, 2usize..26, 1usize..5, 1usize..5), 0..6),
        range in 1.0f64..6.0,
    ) {
        let g = GridGeometry::new(40, 30, 0.1, Point::default());
        let mut t = OccupancyGrid::filled(g, CellState::Occupied);
        t.fill_rect(1, 1, 39, 29, CellState::Free);
        for (x, y, w, h) in pillars {
            if x <= 12 && y <= 12 { continue; }
            t.fill_rect(x, y, (x + w).min(39), (y + h).min(29), CellState::Occupied);
        }
        let b = bound(&t, range);
        prop_assert_eq!(b.levels.len(), BOUND_SHARES.len());
        for w in b.levels.windows(2) {
            prop_assert!(w[0].greedy_stations <= w[1].greedy_stations);
        }
        for l in &b.levels {
            prop_assert!(l.lower_bound <= l.greedy_stations as f64 + 1e-9, "{:?}", l);
            prop_assert!(l.lower_bound_stations >= 1);
        }
        let mut last = 0.0;
        for s in &b.stations {
            prop_assert!(s.coverage > last);
            last = s.coverage;
        }
        prop_assert!((last - 1.0).abs() < 1e-12);
    }
}

/// With the m² rule and the calibration off, the paper's stop (`S ≥
/// min_gain_cells` alone) is back: the site is explored until no border is left,
/// where the default rule stops earlier, at a position worth no scan.
#[test]
fn the_paper_stop_rule_is_kept_behind_its_settings() {
    let truth = BuiltinMap::Site.generate(0);
    let start = BuiltinMap::Site.default_start();
    let mut paper = Config::default();
    paper.parent.min_gain_m2 = 0.0;
    paper.parent.min_gain_share = 0.0;
    paper.parent.calibration_window = 0;
    let old = run_episode(&truth, start, &paper, |_| {}).expect("episode runs");
    let new = run_episode(&truth, start, &Config::default(), |_| {}).expect("episode runs");
    assert_eq!(old.summary.stop_reason, cpsplan::StopReason::Complete);
    assert_eq!(
        new.summary.stop_reason,
        cpsplan::StopReason::NoReachableFrontier
    );
    assert!(new.summary.scans < old.summary.scans);
    assert!(new.summary.coverage >= 0.99);
    // Every scan of the paper's rule expected at least min_gain_cells.
    for s in &old.steps[1..] {
        assert!(s.expected_s_cells.unwrap_or(0) >= paper.parent.min_gain_cells);
    }
}

/// Spacings outside one cell to the map's longer side are refused with that
/// range; a bound whose views exceed `limits.max_memory_mb` is refused with the
/// estimate before the views are made, and the same bound within the limit runs.
#[test]
fn spacings_out_of_range_and_views_beyond_the_memory_are_refused() {
    use cpsplan::bound::BoundError;
    let truth = rooms(1); // 4.2 m × 6.2 m at 0.1 m
    let start = Point::new(1.0, 1.0);
    let config = Config::default();
    for bad in [0.05, 6.3, 0.0, -1.0, f64::NAN, 1e9] {
        let params = BoundParams {
            spacing_m: Some(bad),
            ..BoundParams::default()
        };
        match known_map_bound(&truth, start, &config, params, None) {
            Err(e @ BoundError::Spacing { .. }) => {
                let text = e.to_string();
                assert!(
                    text.contains("from 0.1 m (one cell) to 6.2 m"),
                    "{bad}: {text}"
                );
            }
            other => panic!("--spacing {bad}: {other:?}"),
        }
    }
    // Every cell a station: some 1,700 stations seeing some 1,000 targets
    // each, about 13 MB of views; the maps take 0.08 MB.
    let every_cell = BoundParams {
        spacing_m: Some(0.1),
        ..BoundParams::default()
    };
    let mut tight = config.clone();
    tight.limits.max_memory_mb = 1.0;
    match known_map_bound(&truth, start, &tight, every_cell, None) {
        Err(e @ BoundError::Memory { .. }) => {
            let text = e.to_string();
            assert!(text.contains("views of"), "{text}");
            assert!(text.contains("`limits.max_memory_mb` (1 MB)"), "{text}");
        }
        other => panic!("{other:?}"),
    }
    // What the caller says the machine has counts the same way.
    match known_map_bound(&truth, start, &config, every_cell, Some((1.0, "test"))) {
        Err(BoundError::Memory { limit_by, .. }) => assert_eq!(limit_by, "test"),
        other => panic!("{other:?}"),
    }
    let b = known_map_bound(&truth, start, &config, every_cell, Some((100.0, "test")))
        .expect("within 100 MB");
    assert_eq!(b.spacing_m, 0.1);
    assert!(b.lattice_stations > 1000, "{}", b.lattice_stations);
}
