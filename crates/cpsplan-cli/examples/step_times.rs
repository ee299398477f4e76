//! Times every step of an episode against the size of the known map, and draws
//! the timings of several runs as one chart (docs/PERFORMANCE.md "Per-step time
//! against the known map").
//!
//! ```sh
//! # One episode: scan, known cells, known free cells, the step's milliseconds.
//! cargo run --release -p cpsplan-cli --example step_times -- run MAP CHILDREN OUT.csv
//! # MAP: a built-in map's name (site, office, tunnel) or a ROS map YAML.
//! # The chart of several runs (SVG and PNG beside it):
//! cargo run --release -p cpsplan-cli --example step_times -- plot OUT.svg "TITLE" LABEL=CSV...
//! ```
//!
//! A step is what happens between two calls of the episode's step callback: the
//! scan, the planning round and the move (with children the CPS cycles and their
//! subgoals); the known cells are counted outside the timed part.

use std::error::Error;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use cpsplan::world::builtin::BuiltinMap;
use cpsplan::world::{default_start, resample_for};
use cpsplan::{run_episode_with, CellState, Config, OccupancyGrid};
use cpsplan_cli::render::{Chart, Series, SERIES_COLOURS as COLOURS};

const USAGE: &str = "usage: run MAP CHILDREN OUT.csv | plot OUT.svg TITLE LABEL=CSV...";

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("run") if args.len() == 4 => run(&args[1], args[2].parse()?, Path::new(&args[3])),
        Some("plot") if args.len() >= 4 => plot(Path::new(&args[1]), &args[2], &args[3..]),
        _ => Err(USAGE.into()),
    }
}

/// The ground truth and its start: a built-in map by name, or a ROS map file.
fn truth(map: &str, config: &Config) -> Result<(OccupancyGrid, cpsplan::Point), Box<dyn Error>> {
    if let Some(m) = BuiltinMap::ALL.iter().find(|m| m.name() == map) {
        return Ok((m.generate(config.seed), m.default_start()));
    }
    let grid = cpsplan_cli::formats::rosmap::load_map(Path::new(map))?;
    let truth = resample_for(&grid, config)?;
    let start = default_start(&truth).ok_or("no free cell to start from")?;
    Ok((truth, start))
}

fn run(map: &str, children: usize, out: &Path) -> Result<(), Box<dyn Error>> {
    let mut config = Config::default();
    config.children.count = children;
    config.mission.max_scans = 5000;
    let (truth, start) = truth(map, &config)?;
    let mut csv = String::from("scan,known_cells,known_free_cells,step_ms\n");
    let mut last = Instant::now();
    let t0 = last;
    run_episode_with(&truth, start, &config, |step, knowledge| {
        let ms = last.elapsed().as_secs_f64() * 1e3;
        let cells = knowledge.cells();
        let known = cells.iter().filter(|&&c| c != CellState::Unknown).count();
        let free = cells.iter().filter(|&&c| c == CellState::Free).count();
        let _ = writeln!(csv, "{},{known},{free},{ms:.3}", step.scan);
        last = Instant::now();
    })?;
    std::fs::write(out, csv)?;
    eprintln!("{map}: {:.2} s", t0.elapsed().as_secs_f64());
    Ok(())
}

fn plot(out: &Path, title: &str, specs: &[String]) -> Result<(), Box<dyn Error>> {
    let mut series = Vec::new();
    for (k, spec) in specs.iter().enumerate() {
        let (label, path) = spec.split_once('=').ok_or("each series is LABEL=CSV")?;
        let mut reader = csv::Reader::from_path(path)?;
        let mut points = Vec::new();
        let mut total = 0.0;
        for row in reader.records() {
            let row = row?;
            let known: f64 = row.get(1).ok_or("short row")?.parse()?;
            let ms: f64 = row.get(3).ok_or("short row")?.parse()?;
            total += ms;
            points.push((known / 1e6, ms));
        }
        let steps = points.len().max(1);
        series.push(Series {
            label: format!(
                "{label}: {steps} steps, mean {:.0} ms",
                total / steps as f64
            ),
            points: rolling_median(&points, 9),
            colour: COLOURS[(k / 2) % COLOURS.len()],
            dashed: k % 2 == 0,
            band: Vec::new(),
        });
    }
    let chart = Chart {
        title: title.to_string(),
        subtitle: "a step: scan, planning round, move (median of 9 steps); dashed: before".into(),
        x_label: "known cells (millions)".into(),
        y_label: "step time (ms)".into(),
        series,
    };
    std::fs::write(out, chart.svg())?;
    std::fs::write(out.with_extension("png"), chart.png()?)?;
    Ok(())
}

/// Each point's y replaced by the median of the `window` points around it (fewer
/// at the ends), so that single slow steps do not hide the trend.
fn rolling_median(points: &[(f64, f64)], window: usize) -> Vec<(f64, f64)> {
    let half = window / 2;
    (0..points.len())
        .map(|i| {
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(points.len());
            let mut ys: Vec<f64> = points[lo..hi].iter().map(|p| p.1).collect();
            ys.sort_by(f64::total_cmp);
            (points[i].0, ys[ys.len() / 2])
        })
        .collect()
}
