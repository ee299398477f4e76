//! What `explore` writes beside its report: the field data of
//! `--field-data` (each scan's cloud in the scanner's frame, its readings, how
//! to start a campaign on them), the stations of `--mcap-out`, the registered
//! model of `--cloud-out`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cpsplan::mission::field_readings;
use cpsplan::model::{scanner_frame_scans, ModelPoint, RegisteredModel};
use cpsplan::Config;

use crate::formats::cloud::{encode_las_in, encode_ply, encode_stations_ply, SourceFrame};
use crate::formats::mcap_out::{clock_ns, McapOut};
use crate::formats::readings::write_readings;
use crate::report::{write_atomic, write_temp, TempFile};

/// The file name of scan `n`'s readings in `--field-data`: `readings-0007.csv`.
pub fn readings_file_name(n: usize) -> String {
    format!("readings-{n:04}.csv")
}

/// The file name of scan `n`'s cloud in `--field-data`: `scan-0007.ply`.
pub fn scan_file_name(n: usize) -> String {
    format!("scan-{n:04}.ply")
}

/// Whether `name` is a file `--field-data` writes.
pub(super) fn is_field_file(name: &str) -> bool {
    let numbered = |prefix: &str, suffix: &str| {
        name.strip_prefix(prefix)
            .and_then(|r| r.strip_suffix(suffix))
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    };
    numbered("readings-", ".csv")
        || numbered("scan-", ".ply")
        || name == FIELD_JSON
        || name == FIELD_CONFIG
}

/// The file of `--field-data` that says how to start a campaign on it.
pub const FIELD_JSON: &str = "field.json";

/// The run's configuration in `--field-data`, for `campaign init --config`.
pub const FIELD_CONFIG: &str = "config.toml";

/// `field.json`: what `campaign init` needs to replay the field data.
#[derive(Debug, serde::Serialize)]
struct FieldInit {
    /// The first scan's station, world frame.
    start: cpsplan::Point,
    /// Where the simulated instrument's zero points, degrees.
    heading_deg: f64,
    /// The map's area `[x0, y0, x1, y1]`, metres (`campaign init --area`).
    area: [f64; 4],
    /// Scans, one cloud and one readings file each.
    scans: usize,
    /// The command that starts a campaign on these data.
    init: String,
}

/// Writes `--field-data`: every scan's cloud in the scanner's frame, and its
/// readings since the scan before.
pub(super) fn write_field_data(
    dir: &Path,
    truth: &cpsplan::OccupancyGrid,
    episode: &cpsplan::Episode,
    config: &Config,
) -> Result<()> {
    let scans = field_readings(episode)
        .context("--field-data: the episode's network cannot be simulated")?;
    let g = truth.geometry();
    let (w, h) = g.extent();
    let area = [g.origin.x, g.origin.y, g.origin.x + w, g.origin.y + h];
    let start = episode.start;
    let init = FieldInit {
        start,
        heading_deg: 0.0,
        area,
        scans: scans.len(),
        init: format!(
            "cpsplan campaign init CAMPAIGN --start {:?},{:?} --area {:?},{:?},{:?},{:?} --config {}",
            start.x, start.y, area[0], area[1], area[2], area[3], FIELD_CONFIG
        ),
    };
    let mut json = serde_json::to_vec_pretty(&init)?;
    json.push(b'\n');
    write_atomic(&dir.join(FIELD_JSON), &json)?;
    let toml = toml::to_string(config).context("--field-data: the configuration as TOML")?;
    write_atomic(&dir.join(FIELD_CONFIG), toml.as_bytes())?;
    for (k, readings) in scans.iter().enumerate() {
        let text = write_readings(readings);
        write_atomic(&dir.join(readings_file_name(k + 1)), text.as_bytes())?;
    }
    let mut failed = None;
    scanner_frame_scans(truth, episode, config, |scan, points| {
        if failed.is_some() {
            return;
        }
        let name = scan_file_name(scan as usize + 1);
        let written = encode_ply(points)
            .map_err(anyhow::Error::from)
            .and_then(|bytes| write_atomic(&dir.join(&name), &bytes));
        if let Err(e) = written {
            failed = Some(e.context(format!("--field-data: {name}")));
        }
    })
    .context("--field-data")?;
    failed.map_or(Ok(()), Err)
}

/// Every scan station of `episode` (its estimate where it has one) with its
/// covariance (smoothed where the network was adjusted).
pub(super) fn write_mcap_stations(m: &mut McapOut, episode: &cpsplan::Episode) -> Result<()> {
    for step in &episode.steps {
        let at = step
            .smoothed_estimate
            .or(step.estimate)
            .map_or(step.position, |e| e.position);
        let cov = step
            .smoothed_covariance_m2
            .or(step.covariance_m2)
            .unwrap_or([[0.0; 2]; 2]);
        let heading = step
            .smoothed_heading_sigma_arcsec
            .or(step.heading_sigma_arcsec)
            .unwrap_or(0.0)
            * cpsplan::accuracy::ARCSEC;
        m.station(clock_ns(step.clock_h), at, 0.0, cov, heading * heading)?;
    }
    Ok(())
}

/// The file formats of `--cloud-out`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelFormat {
    /// LAS 1.2.
    Las,
    /// LAS compressed (LAZ).
    Laz,
    /// Binary PLY.
    Ply,
}

impl ModelFormat {
    /// The format named by `path`'s extension.
    pub fn of(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        Ok(match ext.as_str() {
            "las" => ModelFormat::Las,
            "laz" => ModelFormat::Laz,
            "ply" => ModelFormat::Ply,
            _ => bail!(
                "--cloud-out {}: the file name must end in .las, .laz or .ply",
                path.display()
            ),
        })
    }
}

/// Where the stations of the cloud at `path` go: `FILE-stations.ply` beside
/// it, `FILE` the cloud's whole file name (so `x.laz` and `x.ply` keep
/// stations of their own).
pub fn stations_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{name}-stations.ply"))
}

/// Encodes the model's points and stations into temporary files beside `path`;
/// with the `frame` of a cloud-derived map, in its source cloud's frame (the
/// points moved there in place) and, as LAS/LAZ, with its coordinate system.
pub(super) fn write_model_cloud(
    path: &Path,
    format: ModelFormat,
    points: &mut [ModelPoint],
    model: &RegisteredModel,
    frame: Option<&SourceFrame>,
) -> Result<(TempFile, TempFile)> {
    let mut stations = model.stations.clone();
    if let Some(f) = frame {
        let to_source = f.placer();
        for p in points.iter_mut() {
            p.position = to_source(p.position);
        }
        for s in &mut stations {
            s.truth = to_source(s.truth);
            s.estimate = to_source(s.estimate);
        }
    }
    let crs = frame.and_then(|f| f.crs.as_ref());
    let bytes = match format {
        ModelFormat::Las => encode_las_in(points, false, crs),
        ModelFormat::Laz => encode_las_in(points, true, crs),
        ModelFormat::Ply => encode_ply(points),
    }
    .with_context(|| format!("--cloud-out {}", path.display()))?;
    let cloud = write_temp(path, &bytes)?;
    let stations = encode_stations_ply(&stations)
        .with_context(|| format!("--cloud-out {}", path.display()))?;
    let stations = write_temp(&stations_path(path), &stations)?;
    Ok((cloud, stations))
}
