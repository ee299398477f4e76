//! The `config_parse` fuzz target's body.
use std::path::Path;
use std::sync::OnceLock;

use cpsplan::{CellState, GridGeometry, OccupancyGrid, Point};
use cpsplan_cli::formats::config::parse_config;

/// A 60 × 40 room of 0.1 m cells: walls around it and one inner wall with a
/// door, so the episode needs more than one scan; plus its default start.
fn map() -> &'static (OccupancyGrid, Point) {
    static MAP: OnceLock<(OccupancyGrid, Point)> = OnceLock::new();
    MAP.get_or_init(|| {
        let (w, h) = (60, 40);
        let mut cells = vec![CellState::Free; w * h];
        for y in 0..h {
            for x in 0..w {
                let border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
                let inner = x == 30 && !(15..25).contains(&y);
                if border || inner {
                    cells[y * w + x] = CellState::Occupied;
                }
            }
        }
        let grid =
            OccupancyGrid::from_cells(GridGeometry::new(w, h, 0.1, Point::new(0.0, 0.0)), cells)
                .expect("cell count");
        let start = cpsplan::world::default_start(&grid).expect("a free cell");
        (grid, start)
    })
}

/// TOML configuration files: parse, validate, check a grid against the limits
/// and, for a valid configuration made small (at most 2 scans, 2 children, 10
/// Monte Carlo runs, 0.1 m cells), run a whole episode on a small fixed map.
/// Asserts: no panic; an episode under a validated configuration either runs or
/// returns an error; runs stay within the scan cap.
pub fn run(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(file) = parse_config(text, Path::new("fuzz.toml")) else {
        return;
    };
    let mut config = file.config;
    if config.validate().is_err() {
        return;
    }
    // The limits on a small grid and on one at the configured resolution.
    let _ = config.check_grid(60, 40, config.resolution, (0.0, 0.0));
    let _ = config.check_grid(60, 40, 0.1, (-5.0, 1e3));

    config.mission.max_scans = config.mission.max_scans.min(2);
    config.children.count = config.children.count.min(2);
    config.accuracy.monte_carlo_runs = config.accuracy.monte_carlo_runs.min(10);
    config.resolution = 0.1;
    if config.validate().is_err() {
        return;
    }
    let (truth, start) = map();
    if let Ok(episode) = cpsplan::run_episode(truth, *start, &config, |_| {}) {
        assert!(episode.summary.scans <= config.mission.max_scans);
    }
}
