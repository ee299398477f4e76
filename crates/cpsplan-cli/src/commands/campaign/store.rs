//! The campaign directory (docs/USER-GUIDE.md "Campaigns"): what it holds,
//! how it is read back, and how a change is written whole.
//!
//! - `campaign.json`: the format and its version, the datum, the grid, the
//!   configuration and the list of scans. Written last: it is what makes a
//!   change part of the campaign.
//! - `scans/`: every scan's cloud and readings as given (`cloud-0001.laz`,
//!   `readings-0001.csv`), and what the campaign took from them
//!   (`scan-0001.json`: the station, the children, the walls, the range image).
//! - `prior.yaml` / `prior.pgm`: the prior map, when one was given.
//! - `network.json`: every station and point adjusted, with its σ, and the
//!   readings left out.
//! - `knowledge.yaml` / `knowledge.pgm`: the knowledge map after the last scan.
//! - `next.json`, `next.png`: the next step.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use cpsplan::grid::{CellState, GridGeometry};
use cpsplan::mission::FieldScan;
use cpsplan::sensing::{observed_walls, RangeImage};
use cpsplan::{Config, OccupancyGrid, Point};
use serde::{Deserialize, Serialize};

use crate::formats::rosmap::{load_map_with, read_text, ReadLimits};
use crate::report::write_temp;

/// The name `campaign.json` carries in its `format` field.
pub const FORMAT: &str = "cpsplan-campaign";

/// The version of the directory this build reads and writes.
pub const VERSION: u32 = 1;

/// The state file's name.
pub const STATE: &str = "campaign.json";

/// The largest state or scan file read, bytes.
const MAX_STATE_BYTES: u64 = 1 << 30;

/// `campaign.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CampaignFile {
    /// [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// Where the first scan stands (the datum), world frame.
    pub start: Point,
    /// Where the instrument's zero points at the datum, degrees
    /// counter-clockwise from the world's x axis.
    pub heading_deg: f64,
    /// The datum station's name in the readings.
    pub datum: String,
    /// The heights above the floor whose points are walls, metres.
    pub wall_band_m: [f64; 2],
    /// The planning grid.
    pub grid: GridGeometry,
    /// Whether `prior.yaml` holds what was known before the first scan.
    pub prior: bool,
    /// Every parameter of the planning.
    pub config: Config,
    /// Every scan, in order.
    pub scans: Vec<ScanEntry>,
}

/// One scan of `campaign.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ScanEntry {
    /// The scan's number, from 1.
    pub scan: usize,
    /// Its cloud, relative to the directory.
    pub cloud: String,
    /// Its readings, relative to the directory.
    pub readings: String,
    /// What the campaign took from it, relative to the directory.
    pub record: String,
    /// The station the parent scanned from.
    pub station: String,
}

/// `scans/scan-NNNN.json`: what the campaign keeps of a scan. Its pose is
/// not: every replay registers the scan at its station's latest adjusted
/// pose, so the knowledge map gains from every reading added since.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ScanRecord {
    /// The name of the station it was scanned from.
    pub name: String,
    /// The child markers measured at that station, child by child (empty
    /// before the children were first measured).
    #[serde(default)]
    pub children: Vec<String>,
    /// The station's filtering σ when the scan was added, metres.
    pub sigma_m: f64,
    /// Readings left out as blunders when it was added, `station → point`.
    #[serde(default)]
    pub left_out: Vec<String>,
    /// Its points in the wall band, in the scanner's frame `[x, y]`, metres:
    /// one per centimetre square.
    pub walls: Vec<[f32; 2]>,
}

/// Where every station and point stands: position and, for a station, the
/// direction of its instrument's zero (radians).
pub type Poses = HashMap<String, (Point, f64)>;

/// Every scan registered at `poses`, as the loop replays it on `grid`.
pub fn field_scans(
    records: &[ScanRecord],
    poses: &Poses,
    grid: &GridGeometry,
) -> Result<Vec<FieldScan>> {
    records
        .iter()
        .map(|r| {
            let &(at, heading) = poses
                .get(&r.name)
                .ok_or_else(|| anyhow!("station {} is not in the network", r.name))?;
            let children = r
                .children
                .iter()
                .map(|c| poses.get(c).map(|p| p.0))
                .collect::<Option<Vec<Point>>>()
                .unwrap_or_default();
            let (s, c) = heading.sin_cos();
            let world: Vec<[f64; 3]> = r
                .walls
                .iter()
                .map(|q| {
                    let (x, y) = (f64::from(q[0]), f64::from(q[1]));
                    [at.x + c * x - s * y, at.y + s * x + c * y, 0.0]
                })
                .collect();
            let band = (-1.0, 1.0);
            Ok(FieldScan {
                station: at,
                children,
                walls: observed_walls(grid, at, world.iter().copied(), band),
                ranges: Some(RangeImage::new(at, world.iter().copied(), band)),
            })
        })
        .collect()
}

/// `points` of a cloud in the scanner's frame registered at a station `at`
/// whose instrument's zero points `heading` (radians), `z` lifted by the
/// scanner's height over the floor.
pub fn register(
    points: &[[f64; 3]],
    at: Point,
    heading: f64,
    lift: f64,
) -> impl Iterator<Item = [f64; 3]> + '_ {
    let (s, c) = heading.sin_cos();
    points.iter().map(move |q| {
        [
            at.x + c * q[0] - s * q[1],
            at.y + s * q[0] + c * q[1],
            q[2] + lift,
        ]
    })
}

/// The points of a cloud in the scanner's frame whose height over the floor
/// (`z + lift`) lies in `band`, one per centimetre square.
pub fn wall_points(points: &[[f64; 3]], lift: f64, band: [f64; 2]) -> Vec<[f32; 2]> {
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for p in points {
        let h = p[2] + lift;
        if !(p.iter().all(|v| v.is_finite()) && h >= band[0] && h <= band[1]) {
            continue;
        }
        let key = ((p[0] * 100.0).round() as i64, (p[1] * 100.0).round() as i64);
        if seen.insert(key) {
            out.push([p[0] as f32, p[1] as f32]);
        }
    }
    out
}

/// The file of scan `n` in `scans/`.
pub fn scan_path(kind: &str, n: usize, ext: &str) -> String {
    format!("scans/{kind}-{n:04}.{ext}")
}

impl CampaignFile {
    /// Reads the campaign in `dir`, refusing a directory that is not one, is
    /// damaged, or was written by another version.
    pub fn load(dir: &Path) -> Result<Self> {
        let path = dir.join(STATE);
        if !path.is_file() {
            bail!(
                "{} is not a cpsplan campaign (no {STATE}); create one with `cpsplan campaign init`",
                dir.display()
            );
        }
        let text = read_text(&path, MAX_STATE_BYTES)?;
        let head: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| anyhow!("{} is damaged: {e}", path.display()))?;
        if head.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
            bail!(
                "{} is not a cpsplan campaign ({STATE} has no \"format\": \"{FORMAT}\")",
                dir.display()
            );
        }
        match head.get("version").and_then(serde_json::Value::as_u64) {
            Some(v) if v == u64::from(VERSION) => {}
            Some(v) => bail!(
                "{} is a campaign of format version {v}; this cpsplan reads version {VERSION}",
                dir.display()
            ),
            None => bail!("{} is damaged: no format version", path.display()),
        }
        let file: Self = serde_json::from_value(head)
            .map_err(|e| anyhow!("{} is damaged: {e}", path.display()))?;
        file.config
            .validate()
            .map_err(|e| anyhow!("{} is damaged: {e}", path.display()))?;
        let g = &file.grid;
        let sane = g.width > 0
            && g.height > 0
            && g.resolution.is_finite()
            && g.resolution > 0.0
            && g.origin.x.is_finite()
            && g.origin.y.is_finite()
            && g.yaw.is_finite();
        if !sane {
            bail!("{} is damaged: its grid is not usable", path.display());
        }
        g.check_limits(&file.config)
            .map_err(|e| anyhow!("{} is damaged: {e}", path.display()))?;
        for (k, s) in file.scans.iter().enumerate() {
            if s.scan != k + 1 {
                bail!(
                    "{} is damaged: scan {} is listed as {}",
                    path.display(),
                    k + 1,
                    s.scan
                );
            }
            for f in [&s.cloud, &s.readings, &s.record] {
                if !is_inside(f) || !dir.join(f).is_file() {
                    bail!("{} is damaged: {f} is missing", dir.display());
                }
            }
        }
        Ok(file)
    }

    /// What the team knew before its first scan: the prior map, or nothing.
    pub fn prior_grid(&self, dir: &Path) -> Result<OccupancyGrid> {
        if !self.prior {
            return Ok(OccupancyGrid::filled(self.grid, CellState::Unknown));
        }
        let path = dir.join("prior.yaml");
        let grid = load_map_with(&path, &ReadLimits::for_config(&self.config))
            .map_err(|e| anyhow!("{} is damaged: {e}", dir.display()))?;
        if *grid.geometry() != self.grid {
            bail!(
                "{} is damaged: prior.yaml is not the campaign's grid",
                dir.display()
            );
        }
        Ok(grid)
    }

    /// Every scan as the loop replays it.
    pub fn records(&self, dir: &Path) -> Result<Vec<ScanRecord>> {
        self.scans
            .iter()
            .map(|s| {
                let path = dir.join(&s.record);
                let text = read_text(&path, MAX_STATE_BYTES)?;
                serde_json::from_str(&text)
                    .map_err(|e| anyhow!("{} is damaged: {e}", path.display()))
            })
            .collect()
    }
}

/// Whether `name` is a plain relative path that stays inside the directory.
fn is_inside(name: &str) -> bool {
    let p = Path::new(name);
    !p.is_absolute()
        && p.components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
}

/// A change to a campaign directory, gathered in memory and written whole:
/// every file under a temporary name first, then each moved into place, the
/// state file last.
#[derive(Debug, Default)]
pub struct Change {
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl Change {
    /// Adds `bytes` as `name` (relative to the directory).
    pub fn put(&mut self, name: impl Into<PathBuf>, bytes: Vec<u8>) {
        self.files.push((name.into(), bytes));
    }

    /// Writes every file into `dir`, then `state` as [`STATE`].
    pub fn commit(self, dir: &Path, state: &CampaignFile) -> Result<()> {
        let mut state_bytes = serde_json::to_vec_pretty(state)?;
        state_bytes.push(b'\n');
        std::fs::create_dir_all(dir.join("scans"))
            .with_context(|| format!("cannot write {}", dir.display()))?;
        let mut staged = Vec::with_capacity(self.files.len() + 1);
        for (name, bytes) in self.files {
            let path = dir.join(&name);
            staged.push((write_temp(&path, &bytes)?, path));
        }
        let path = dir.join(STATE);
        staged.push((write_temp(&path, &state_bytes)?, path));
        for (tmp, path) in staged {
            tmp.persist(&path)?;
        }
        Ok(())
    }
}
