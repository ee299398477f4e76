//! The report of an explored episode: `summary.json`, `episode.json`, `metrics.csv`,
//! `map.png` and the final knowledge map as ROS map_server PGM+YAML. Every file is
//! written under a temporary name and renamed into place.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use cpsplan::mission::{Episode, StopReason, Summary};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{Config, OccupancyGrid, Point};
use serde::Serialize;

use crate::formats::rosmap::save_map;
use crate::render::{error_chart, render_episode};

/// Where the ground truth came from.
#[derive(Debug, Clone)]
pub enum MapSource {
    /// A built-in procedural map.
    Builtin(BuiltinMap),
    /// A map file.
    File(PathBuf),
}

impl MapSource {
    /// A short human-readable name.
    pub fn label(&self) -> String {
        match self {
            MapSource::Builtin(m) => format!("built-in map `{}`", m.name()),
            MapSource::File(p) => p.display().to_string(),
        }
    }

    fn record(&self) -> String {
        match self {
            MapSource::Builtin(m) => format!("builtin:{}", m.name()),
            MapSource::File(p) => p.display().to_string(),
        }
    }
}

/// The snake_case name of a stop reason, as in the JSON records.
pub fn stop_label(reason: StopReason) -> &'static str {
    reason.name()
}

/// `summary.json`.
#[derive(Debug, Serialize)]
pub struct SummaryRecord<'a> {
    /// Map label (`builtin:NAME` or the file path).
    pub map: String,
    /// The episode's totals (scans, coverage, travel, stop reason, seed, CPS counts).
    #[serde(flatten)]
    pub summary: &'a Summary,
    /// Wall-clock time of the simulation, milliseconds (the only field that varies
    /// between identical runs).
    pub wall_ms: f64,
    /// The start, world frame.
    pub start: Point,
    /// Planning resolution, metres.
    pub resolution: f64,
    /// The configuration used.
    pub config: &'a Config,
}

/// Map description inside `episode.json`.
#[derive(Debug, Serialize)]
struct MapRecord {
    source: String,
    width: usize,
    height: usize,
    resolution: f64,
    origin: [f64; 3],
}

/// `episode.json`.
#[derive(Debug, Serialize)]
struct EpisodeRecord<'a> {
    map: MapRecord,
    #[serde(flatten)]
    episode: &'a Episode,
}

/// Writes `bytes` to `path` through a temporary file in the same directory.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let tmp = path.with_file_name(format!(".{name}.tmp"));
    let result = (|| -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}

/// One row of `metrics.csv`.
#[derive(Debug, Serialize)]
struct MetricsRow {
    scan: usize,
    x: f64,
    y: f64,
    new_free: usize,
    new_occupied: usize,
    coverage: f64,
    wall_coverage: f64,
    parent_travel_m: f64,
    border_cells: usize,
    band_cells: usize,
    candidates: usize,
    target_x: Option<f64>,
    target_y: Option<f64>,
    target_g: Option<f64>,
    target_s_cells: Option<usize>,
    target_l_m: Option<f64>,
    path_length_m: f64,
    position_sigma_m: Option<f64>,
    heading_sigma_arcsec: Option<f64>,
    monte_carlo_error_m: Option<f64>,
}

/// The metrics table as CSV text, one row per scan.
pub fn metrics_csv(episode: &Episode) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for s in &episode.steps {
        let t = s.plan.target();
        w.serialize(MetricsRow {
            scan: s.scan,
            x: s.position.x,
            y: s.position.y,
            new_free: s.outcome.new_free,
            new_occupied: s.outcome.new_occupied,
            coverage: s.coverage,
            wall_coverage: s.wall_coverage,
            parent_travel_m: s.parent_travel_m,
            border_cells: s.plan.border_cells,
            band_cells: s.plan.band_cells,
            candidates: s.plan.candidates.len(),
            target_x: t.map(|c| c.position.x),
            target_y: t.map(|c| c.position.y),
            target_g: t.map(|c| c.g),
            target_s_cells: t.map(|c| c.s_cells),
            target_l_m: t.and_then(|c| c.l_m),
            path_length_m: s.plan.path_length_m,
            position_sigma_m: s.position_sigma_m,
            heading_sigma_arcsec: s.heading_sigma_arcsec,
            monte_carlo_error_m: s.monte_carlo_error_m,
        })?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

/// Writes every output of an episode into `dir` (created if needed).
pub fn write_episode_outputs(
    dir: &Path,
    truth: &OccupancyGrid,
    source: &MapSource,
    episode: &Episode,
    wall_ms: f64,
) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let g = truth.geometry();
    let s = &episode.summary;
    let summary = SummaryRecord {
        map: source.record(),
        summary: s,
        wall_ms: (wall_ms * 1000.0).round() / 1000.0,
        start: episode.start,
        resolution: g.resolution,
        config: &episode.config,
    };
    let record = EpisodeRecord {
        map: MapRecord {
            source: source.record(),
            width: g.width,
            height: g.height,
            resolution: g.resolution,
            origin: [g.origin.x, g.origin.y, g.yaw],
        },
        episode,
    };
    let title = format!("cpsplan explore — {}", source.label());
    let png = render_episode(truth, episode, &title)?;
    let chart = error_chart(
        episode,
        &format!("positioning error \u{2014} {}", source.label()),
    );
    let chart_png = chart.as_ref().map(|c| c.png()).transpose()?;
    write_atomic(
        &dir.join("episode.json"),
        &serde_json::to_vec_pretty(&record)?,
    )?;
    write_atomic(&dir.join("metrics.csv"), &metrics_csv(episode)?)?;
    write_atomic(&dir.join("map.png"), &png)?;
    if let (Some(c), Some(p)) = (&chart, &chart_png) {
        write_atomic(&dir.join("error.png"), p)?;
        write_atomic(&dir.join("error.svg"), c.svg().as_bytes())?;
    }
    if let Some(k) = &episode.knowledge {
        save_map(k, &dir.join("knowledge.yaml"))?;
    }
    write_atomic(
        &dir.join("summary.json"),
        &serde_json::to_vec_pretty(&summary)?,
    )?;
    Ok(())
}
