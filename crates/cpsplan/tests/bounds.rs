//! Every documented bound of the configuration ([`cpsplan::config::BOUNDS`])
//! holds both ways (proptest): a value just outside is refused, naming its key;
//! a value inside is accepted unless another parameter conflicts with it, and a
//! whole (small) episode then runs without panicking, within the limits.

use cpsplan::config::{Bound, ConfigError, BOUNDS};
use cpsplan::model::build_model;
use cpsplan::world::{default_start, resample_for, resampled_size};
use cpsplan::{run_episode, CellState, Config, GridGeometry, OccupancyGrid, Point};
use proptest::prelude::*;

/// A 6 m × 4 m room at 0.1 m with a wall and a door, walled all round.
fn room() -> OccupancyGrid {
    let (w, h) = (60usize, 40usize);
    let mut cells = vec![CellState::Free; w * h];
    for y in 0..h {
        for x in 0..w {
            let edge = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            let wall = x == 30 && !(18..24).contains(&y);
            if edge || wall {
                cells[y * w + x] = CellState::Occupied;
            }
        }
    }
    OccupancyGrid::from_cells(GridGeometry::new(w, h, 0.1, Point::new(0.0, 0.0)), cells)
        .expect("cell count matches")
}

/// A value of `b` at position `t` in [0, 1] of its range: linear for narrow
/// ranges, logarithmic for ranges over decades.
fn inside(b: &Bound, t: f64) -> f64 {
    let v = if b.min > 0.0 && b.max / b.min > 100.0 {
        (b.min.ln() + t * (b.max.ln() - b.min.ln())).exp()
    } else {
        b.min + t * (b.max - b.min)
    };
    let v = v.clamp(b.min, b.max);
    if b.whole {
        v.round().clamp(b.min, b.max)
    } else {
        v
    }
}

/// A value just outside `b`: below its minimum (`below`) or above its maximum.
fn outside(b: &Bound, below: bool) -> Option<f64> {
    if b.whole {
        // Whole numbers are stored unsigned: below 0 cannot be represented.
        return if below {
            (b.min >= 1.0).then_some(b.min - 1.0)
        } else {
            Some(b.max + 1.0)
        };
    }
    Some(if below {
        b.min - (b.min.abs() * 1e-6).max(1e-9)
    } else {
        b.max + (b.max.abs() * 1e-6).max(1e-9)
    })
}

/// A small episode with `config` on the room, when its planning grid stays
/// small; checks the grid limits otherwise.
fn run_small(config: &Config) {
    let truth = room();
    let (w, h) = resampled_size(truth.geometry(), config.resolution);
    if w.saturating_mul(h) > config.limits.max_grid_cells as u64 {
        let e = resample_for(&truth, config).expect_err("beyond the configured cap");
        assert_eq!(e.key(), "limits.max_grid_cells");
        return;
    }
    if w.saturating_mul(h) > 200_000 {
        // Too fine for a quick run: the limits must still decide up front.
        let _ = resample_for(
            &truth,
            &Config {
                limits: cpsplan::config::LimitsConfig {
                    max_grid_cells: 200_000,
                    ..config.limits
                },
                ..config.clone()
            },
        )
        .expect_err("beyond the test's grid cap");
        return;
    }
    let grid = resample_for(&truth, config).expect("a small grid is within the limits");
    let Some(start) = default_start(&grid) else {
        return; // so coarse that no free cell is left
    };
    let mut config = config.clone();
    config.mission.max_scans = config.mission.max_scans.min(4);
    config.accuracy.monte_carlo_runs = config.accuracy.monte_carlo_runs.min(200);
    let episode = run_episode(&grid, start, &config, |_| {}).expect("a valid configuration runs");
    assert!(!episode.steps.is_empty());
    assert!(episode.steps.len() <= config.mission.max_scans);
    // Its registered 3D model, within a small point cap.
    config.limits.max_cloud_points = config.limits.max_cloud_points.min(2_000_000);
    match build_model(&grid, &episode, &config, |_, _| {}) {
        Ok(m) => assert!(m.accuracy.mean_distance_m.is_finite()),
        Err(e) => assert!(e.to_string().contains("limits.max_cloud_points"), "{e}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn values_inside_every_bound_are_accepted_or_conflict(
        index in 0..BOUNDS.len(),
        t in prop_oneof![Just(0.0), Just(1.0), 0.0f64..=1.0],
    ) {
        let b = &BOUNDS[index];
        let mut config = Config::default();
        let v = inside(b, t);
        (b.set)(&mut config, v);
        match config.validate() {
            Ok(()) => run_small(&config),
            Err(e) => prop_assert!(
                matches!(e, ConfigError::Conflict { .. }),
                "{} = {v}: {e}", b.key
            ),
        }
    }

    #[test]
    fn values_just_outside_every_bound_are_refused_by_name(
        index in 0..BOUNDS.len(),
        below in any::<bool>(),
    ) {
        let b = &BOUNDS[index];
        if let Some(v) = outside(b, below) {
            let mut config = Config::default();
            (b.set)(&mut config, v);
            let e = config.validate().expect_err("outside the bound");
            prop_assert_eq!(e.key(), b.key, "{}", e);
            prop_assert!(e.to_string().contains(b.key), "{}", e);
        }
    }
}

#[test]
fn non_numbers_are_refused_for_every_real_parameter() {
    for b in BOUNDS.iter().filter(|b| !b.whole) {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut config = Config::default();
            (b.set)(&mut config, v);
            let e = config.validate().expect_err("not a number");
            assert_eq!(e.key(), b.key, "{e}");
        }
    }
}

#[test]
fn every_bound_is_finite_and_ordered() {
    for b in BOUNDS {
        assert!(
            b.min.is_finite() && b.max.is_finite() && b.min < b.max,
            "{}",
            b.key
        );
    }
}

#[test]
fn the_user_guide_lists_every_bound() {
    let guide = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/USER-GUIDE.md"
    ))
    .expect("docs/USER-GUIDE.md");
    for b in BOUNDS {
        let row = format!(
            "| `{}` | {} | {} |",
            b.key,
            cpsplan::config::number(b.min),
            cpsplan::config::number(b.max)
        );
        assert!(guide.contains(&row), "USER-GUIDE.md lacks `{row}`");
    }
}

/// A grid beyond any cell count (2⁴⁰ × 2⁴⁰) is refused with its true size,
/// not one saturated at 1.8e19.
#[test]
fn a_grid_beyond_any_count_states_its_true_size() {
    let c = Config::default();
    let side = 1u64 << 40;
    let e = c
        .check_grid(side, side, 0.1, (0.0, 0.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("would have 1.209e24 cells"), "{e}");
    assert!(!e.contains("e19"), "{e}");
}
