//! The report of an explored episode: `summary.json`, `episode.json`, `metrics.csv`,
//! `model.csv` (the registered 3D model's accuracy per scan), `map.png` and the
//! final knowledge map as ROS map_server PGM+YAML. The report
//! is written whole into a temporary directory beside `--out` ([`ReportDir`])
//! and moved into place at the end: a failed run leaves nothing behind.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use cpsplan::mission::{Episode, MemoryEstimate, StopReason, Summary};
use cpsplan::model::{ModelAccuracy, RegisteredModel};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{Config, GridGeometry, OccupancyGrid, Point};
use serde::Serialize;

use crate::formats::rosmap::save_map;
use crate::formats::tidy::{tidy, tidy_opt, to_json_tidy};
use crate::render::{error_chart, pictures_peak_bytes, render_episode_pictures};

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
    /// Wall-clock time of the simulation, milliseconds (with `peak_memory_mb`,
    /// the only fields that vary between identical runs).
    pub wall_ms: f64,
    /// The process's peak resident memory when the report was written (the
    /// simulation, the 3D model and the pictures), MB: `VmHWM` of
    /// `/proc/self/status`; `null` where the system does not report it.
    pub peak_memory_mb: Option<f64>,
    /// The peak memory as estimated before the run ([`MemoryEstimate`]), at the
    /// scans the run took and with the pictures it drew, MB.
    pub estimated_memory_mb: f64,
    /// The start, world frame.
    pub start: Point,
    /// Planning resolution, metres.
    pub resolution: f64,
    /// The registered 3D model's accuracy against the ground-truth walls
    /// (`null` when the model would exceed `limits.max_cloud_points`).
    pub model: Option<ModelSummary>,
    /// The configuration used.
    pub config: &'a Config,
}

/// The registered 3D model in `summary.json`.
#[derive(Debug, Serialize)]
pub struct ModelSummary {
    /// Points of the model.
    pub points: usize,
    /// Mean distance of the points to the ground-truth walls, metres.
    pub mean_distance_m: f64,
    /// 95th percentile of that distance, metres.
    pub p95_distance_m: f64,
    /// Largest horizontal error of a pose a scan was registered in, metres.
    pub max_position_error_m: f64,
    /// The poses the scans were registered in: `smoothed` (one Monte Carlo
    /// realisation of the CPS network, every station adjusted with every
    /// measurement), `filtering` (the realisation's estimates when each scan was
    /// taken, where no smoothed ones exist) or `true` (no Monte Carlo: range
    /// noise only).
    pub poses: &'static str,
    /// With smoothed poses: the same model registered in the filtering poses.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub filtering: Option<ModelFit>,
}

/// How close a registered model lies to the ground-truth walls.
#[derive(Debug, Serialize)]
pub struct ModelFit {
    /// Mean distance of the points to the ground-truth walls, metres.
    pub mean_distance_m: f64,
    /// 95th percentile of that distance, metres.
    pub p95_distance_m: f64,
    /// Largest horizontal error of a pose a scan was registered in, metres.
    pub max_position_error_m: f64,
}

impl ModelSummary {
    /// The summary of the model of `episode` with `accuracy` (registered in the
    /// smoothed poses where the episode has them), and `filtering`, its accuracy
    /// in the filtering poses.
    pub fn new(
        accuracy: &ModelAccuracy,
        episode: &Episode,
        filtering: Option<&ModelAccuracy>,
    ) -> Self {
        let smoothed = episode.steps.iter().any(|s| s.smoothed_estimate.is_some());
        let estimated = episode.steps.iter().any(|s| s.estimate.is_some());
        Self {
            points: accuracy.points,
            mean_distance_m: accuracy.mean_distance_m,
            p95_distance_m: accuracy.p95_distance_m,
            max_position_error_m: accuracy.max_position_error_m,
            poses: match (smoothed, estimated) {
                (true, _) => "smoothed",
                (false, true) => "filtering",
                (false, false) => "true",
            },
            filtering: filtering.filter(|_| smoothed).map(|f| ModelFit {
                mean_distance_m: f.mean_distance_m,
                p95_distance_m: f.p95_distance_m,
                max_position_error_m: f.max_position_error_m,
            }),
        }
    }
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
    write_temp(path, bytes)?.persist(path)
}

/// A file written under a temporary name beside its destination, removed
/// unless [`TempFile::persist`] moves it into place.
#[derive(Debug)]
pub struct TempFile {
    tmp: PathBuf,
    persisted: bool,
}

impl TempFile {
    /// Renames the file to `path`.
    pub fn persist(mut self, path: &Path) -> Result<()> {
        std::fs::rename(&self.tmp, path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        self.persisted = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.persisted {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `bytes` to a temporary file beside `path` (`.NAME.PID.tmp`).
pub fn write_temp(path: &Path, bytes: &[u8]) -> Result<TempFile> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    let file = TempFile {
        tmp,
        persisted: false,
    };
    (|| -> std::io::Result<()> {
        let mut f = std::fs::File::create(&file.tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })()
    .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(file)
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
    gain_m2: f64,
    expected_gain_m2: Option<f64>,
    expected_s_cells: Option<usize>,
    target_gain_m2: Option<f64>,
    clock_h: f64,
}

/// The metrics table as CSV text, one row per scan.
pub fn metrics_csv(episode: &Episode) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for s in &episode.steps {
        let t = s.plan.target();
        w.serialize(MetricsRow {
            scan: s.scan,
            x: tidy(s.position.x),
            y: tidy(s.position.y),
            new_free: s.outcome.new_free,
            new_occupied: s.outcome.new_occupied,
            coverage: tidy(s.coverage),
            wall_coverage: tidy(s.wall_coverage),
            parent_travel_m: tidy(s.parent_travel_m),
            border_cells: s.plan.border_cells,
            band_cells: s.plan.band_cells,
            candidates: s.plan.candidates.len(),
            target_x: t.map(|c| tidy(c.position.x)),
            target_y: t.map(|c| tidy(c.position.y)),
            target_g: t.map(|c| tidy(c.g)),
            target_s_cells: t.map(|c| c.s_cells),
            target_l_m: tidy_opt(t.and_then(|c| c.l_m)),
            path_length_m: tidy(s.plan.path_length_m),
            position_sigma_m: tidy_opt(s.position_sigma_m),
            heading_sigma_arcsec: tidy_opt(s.heading_sigma_arcsec),
            monte_carlo_error_m: tidy_opt(s.monte_carlo_error_m),
            gain_m2: tidy(s.gain_m2),
            expected_gain_m2: tidy_opt(s.expected_gain_m2),
            expected_s_cells: s.expected_s_cells,
            target_gain_m2: t.map(|c| tidy(c.gain_m2)),
            clock_h: tidy(s.clock_h),
        })?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

/// The model's accuracy as CSV text, one row per scan, scans numbered from 1
/// as in every other file of the report.
pub fn model_csv(accuracy: &ModelAccuracy) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for s in &accuracy.scans {
        w.serialize(ModelRow {
            scan: s.scan.saturating_add(1),
            points: s.points,
            mean_distance_m: tidy(s.mean_distance_m),
            p95_distance_m: tidy(s.p95_distance_m),
            position_error_m: tidy(s.position_error_m),
            heading_error_arcsec: tidy(s.heading_error_arcsec),
            position_sigma_m: tidy_opt(s.position_sigma_m),
            smoothed_sigma_m: tidy_opt(s.smoothed_sigma_m),
        })?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

/// One row of `model.csv` (the fields of [`cpsplan::model::ScanAccuracy`]).
#[derive(Serialize)]
struct ModelRow {
    scan: u32,
    points: usize,
    mean_distance_m: f64,
    p95_distance_m: f64,
    position_error_m: f64,
    heading_error_arcsec: f64,
    position_sigma_m: Option<f64>,
    smoothed_sigma_m: Option<f64>,
}

/// Every file name a report may hold (besides `step-NNN.png`).
pub const REPORT_FILES: [&str; 13] = [
    "summary.json",
    "episode.json",
    "metrics.csv",
    "model.csv",
    "map.png",
    "map-large.png",
    "error.png",
    "error.svg",
    "knowledge.pgm",
    "knowledge.yaml",
    "bound.json",
    "bound.png",
    "report.html",
];

/// Whether `name` is a file a report may hold.
pub fn is_report_file(name: &str) -> bool {
    REPORT_FILES.contains(&name)
        || name
            .strip_prefix("step-")
            .and_then(|n| n.strip_suffix(".png"))
            .is_some_and(|n| n.len() >= 3 && n.bytes().all(|b| b.is_ascii_digit()))
}

/// A report being written: a temporary directory beside its destination
/// (`.NAME.cpsplan-tmp-PID`), moved into place by [`ReportDir::commit`] and
/// removed if dropped before.
///
/// An existing destination is replaced whole, but only if it is empty or holds
/// nothing but report files (an earlier report): any other file makes
/// [`ReportDir::create`] refuse, so a mistyped `--out` never deletes a user's
/// files.
#[derive(Debug)]
pub struct ReportDir {
    out: PathBuf,
    tmp: PathBuf,
    committed: bool,
    ours: fn(&str) -> bool,
}

impl ReportDir {
    /// Checks the destination `out` and creates the temporary directory.
    pub fn create(out: &Path) -> Result<Self> {
        Self::create_for(out, is_report_file)
    }

    /// [`ReportDir::create`] for a directory whose own files are those with
    /// `ours(name)`: an existing `out` holding anything else is refused.
    pub fn create_for(out: &Path, ours: fn(&str) -> bool) -> Result<Self> {
        check_replaceable(out, ours)?;
        let name = out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .filter(|n| n != "..")
            .with_context(|| {
                format!(
                    "--out {}: needs a directory name, e.g. out/run1",
                    out.display()
                )
            })?;
        let parent = match out.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .with_context(|| format!("cannot create directory {}", parent.display()))?;
        remove_stale(&parent, &name);
        let tmp = parent.join(format!(".{name}.cpsplan-tmp-{}", std::process::id()));
        if tmp.exists() {
            let _ = std::fs::remove_dir_all(&tmp);
        }
        std::fs::create_dir(&tmp)
            .with_context(|| format!("cannot create directory {}", tmp.display()))?;
        Ok(Self {
            out: out.to_path_buf(),
            tmp,
            committed: false,
            ours,
        })
    }

    /// Where the files go until the commit.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// Moves the finished report to its destination, replacing an earlier
    /// report there.
    pub fn commit(mut self) -> Result<()> {
        check_replaceable(&self.out, self.ours)?;
        let old = self.tmp.with_file_name(
            self.tmp
                .file_name()
                .map(|n| n.to_string_lossy().replace("cpsplan-tmp", "cpsplan-old"))
                .unwrap_or_default(),
        );
        let had_old = self.out.exists();
        if had_old {
            std::fs::rename(&self.out, &old)
                .with_context(|| format!("cannot replace {}", self.out.display()))?;
        }
        if let Err(e) = std::fs::rename(&self.tmp, &self.out) {
            if had_old {
                let _ = std::fs::rename(&old, &self.out);
            }
            return Err(e).with_context(|| format!("cannot write {}", self.out.display()));
        }
        self.committed = true;
        if had_old {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }
}

impl Drop for ReportDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

/// `path` with its symbolic links and `..` resolved as far as it exists (the
/// rest appended as given).
pub fn real_path(path: &Path) -> PathBuf {
    let mut missing = Vec::new();
    let mut at = path.to_path_buf();
    loop {
        if let Ok(real) = std::fs::canonicalize(&at) {
            return missing.iter().rev().fold(real, |p, part| p.join(part));
        }
        match (at.file_name().map(|n| n.to_os_string()), at.parent()) {
            (Some(name), Some(parent)) => {
                missing.push(name);
                at = if parent.as_os_str().is_empty() {
                    PathBuf::from(".")
                } else {
                    parent.to_path_buf()
                };
            }
            _ => return path.to_path_buf(),
        }
    }
}

/// Refuses a destination that is not a directory, or a directory holding
/// anything but report files.
fn check_replaceable(out: &Path, ours: fn(&str) -> bool) -> Result<()> {
    let meta = match std::fs::symlink_metadata(out) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", out.display())),
    };
    if !meta.is_dir() {
        anyhow::bail!(
            "--out {} exists and is not a directory; choose another --out",
            out.display()
        );
    }
    // The report replaces the directory whole: only one the caller may
    // write into (an empty directory of another owner would be swapped for
    // the caller's own).
    let probe = out.join(format!(".cpsplan-probe-{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) => anyhow::bail!(
            "--out {}: cannot write there ({e}); choose another --out",
            out.display()
        ),
    }
    let entries =
        std::fs::read_dir(out).with_context(|| format!("cannot read {}", out.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("cannot read {}", out.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let file = entry.file_type().is_ok_and(|t| t.is_file());
        if !(file && ours(&name)) {
            anyhow::bail!(
                "--out {} holds `{name}`, which is not part of a cpsplan report; \
                 choose an empty or new directory (an earlier report there is replaced whole)",
                out.display()
            );
        }
    }
    Ok(())
}

/// Removes temporary directories of `name` left by runs that no longer exist
/// (killed before they could clean up).
fn remove_stale(parent: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let proc = Path::new("/proc");
    if !proc.is_dir() {
        return;
    }
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let pid = file
            .strip_prefix(&format!(".{name}.cpsplan-tmp-"))
            .or_else(|| file.strip_prefix(&format!(".{name}.cpsplan-old-")));
        if let Some(pid) = pid.filter(|p| p.bytes().all(|b| b.is_ascii_digit())) {
            if !proc.join(pid).exists() {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
}

/// The process's peak resident memory so far, MB (`VmHWM` of
/// `/proc/self/status`; `None` where there is no such file or line).
pub fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    parse_peak_kb(&status).map(|kb| (kb as f64 / 1024.0 * 10.0).round() / 10.0)
}

/// The estimated peak memory of `episode`'s run on a grid of `geometry`, MB,
/// as [`MemoryEstimate`] gives it before the run, at the scans it took and with
/// the pictures it drew (`large`: `map-large.png` too).
pub fn estimated_memory_mb(geometry: &GridGeometry, episode: &Episode, large: bool) -> f64 {
    let e = MemoryEstimate::for_grid(geometry.width, geometry.height, &episode.config)
        .with_pictures(pictures_peak_bytes(geometry, large));
    (e.mb(episode.steps.len()) * 10.0).round() / 10.0
}

/// The `VmHWM` line of a `/proc/PID/status` text, kB.
fn parse_peak_kb(status: &str) -> Option<u64> {
    crate::memory::kb_of(status, "VmHWM:")
}

/// Writes every output of an episode into `dir` (created if needed).
pub fn write_episode_outputs(
    dir: &Path,
    truth: &OccupancyGrid,
    source: &MapSource,
    episode: &Episode,
    model: Option<&RegisteredModel>,
    filtering: Option<&ModelAccuracy>,
    wall_ms: f64,
) -> Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory {}", dir.display()))?;
    let g = truth.geometry();
    let s = &episode.summary;
    let mut summary = SummaryRecord {
        map: source.record(),
        summary: s,
        wall_ms: (wall_ms * 1000.0).round() / 1000.0,
        peak_memory_mb: None,
        estimated_memory_mb: 0.0,
        start: episode.start,
        resolution: g.resolution,
        model: model.map(|m| ModelSummary::new(&m.accuracy, episode, filtering)),
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
    let (png, large) = render_episode_pictures(truth, episode, &title)?;
    summary.estimated_memory_mb = estimated_memory_mb(g, episode, large.is_some());
    let chart = error_chart(
        episode,
        &format!("positioning error \u{2014} {}", source.label()),
    );
    let chart_png = chart.as_ref().map(|c| c.png()).transpose()?;
    write_atomic(&dir.join("episode.json"), &to_json_tidy(&record)?)?;
    write_atomic(&dir.join("metrics.csv"), &metrics_csv(episode)?)?;
    if let Some(m) = model {
        write_atomic(&dir.join("model.csv"), &model_csv(&m.accuracy)?)?;
    }
    write_atomic(&dir.join("map.png"), &png)?;
    if let Some(large) = &large {
        write_atomic(&dir.join("map-large.png"), large)?;
    }
    if let (Some(c), Some(p)) = (&chart, &chart_png) {
        write_atomic(&dir.join("error.png"), p)?;
        write_atomic(&dir.join("error.svg"), c.svg().as_bytes())?;
    }
    if let Some(k) = &episode.knowledge {
        save_map(k, &dir.join("knowledge.yaml"))?;
    }
    // Last, when everything else has been drawn and written.
    summary.peak_memory_mb = peak_memory_mb();
    write_atomic(&dir.join("summary.json"), &to_json_tidy(&summary)?)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_peak_is_read_from_the_vmhwm_line() {
        let status =
            "Name:\tcpsplan\nVmPeak:\t  300000 kB\nVmHWM:\t  150976 kB\nVmRSS:\t 1000 kB\n";
        assert_eq!(parse_peak_kb(status), Some(150_976));
        assert_eq!(parse_peak_kb("Name:\tx\nVmRSS:\t 1000 kB\n"), None);
        assert_eq!(parse_peak_kb("VmHWM:\t  12 MB\n"), None);
        assert_eq!(parse_peak_kb("VmHWM:\t  lots kB\n"), None);
    }
}
