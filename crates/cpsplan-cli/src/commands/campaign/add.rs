//! `cpsplan campaign add`: one scan in, the next step out.
//!
//! Everything is read and computed before anything is written: the readings
//! (every scan's so far and the new ones) adjusted as one network, blunders
//! among the new ones found; the cloud registered at the new station's pose;
//! its walls and range image; the whole campaign replayed to the next plan.
//! A problem at any point leaves the directory as it was.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use cpsplan::accuracy::{
    adjust_readings, child_spot, reading_name, ControlPoint, Datum, Instrument, Model, Reading,
    Survey,
};
use cpsplan::config::TargetKind;
use cpsplan::mission::{run_campaign, CampaignRun, Step};
use cpsplan::{Config, OccupancyGrid, Point};

use super::next::{next_plan, NextPlan};
use super::store::{
    field_scans, register, scan_path, wall_points, CampaignFile, Change, Poses, ScanEntry,
    ScanRecord,
};
use crate::formats::cloud::{read_cloud, CloudFormat, CloudReadOptions};
use crate::formats::mcap_out::{clock_ns, McapOut, McapRecording};
use crate::formats::readings::read_readings;
use crate::formats::ros_out::{Outlet, RosOut};
use crate::formats::rosmap::{encode_map, ReadLimits};
use crate::render::{render_step, StepView};

/// Options of `cpsplan campaign add`.
#[derive(Debug, Args)]
pub struct AddArgs {
    /// The campaign's directory.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The scan's point cloud in the scanner's own frame (LAS, LAZ, E57, PLY,
    /// PCD): origin at the scanner's centre, x along the total station's zero.
    #[arg(long, value_name = "FILE")]
    pub scan: PathBuf,
    /// The total station's readings since the scan before (CSV: station,
    /// point, slope_distance_m, hz_direction_gon, zenith_angle_gon; the user
    /// guide's "Readings"); the first scan's may hold only a header.
    #[arg(long, value_name = "FILE.csv")]
    pub readings: PathBuf,
    /// Also write the campaign so far as ROS 2 messages in an MCAP file (the
    /// user guide's "Robot software").
    #[arg(long, value_name = "FILE.mcap")]
    pub mcap_out: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The instrument's model of a configuration.
pub(super) fn model_of(config: &Config) -> Model {
    Model::new(Instrument::from_config(&config.instrument))
}

/// The datum of a campaign.
pub(super) fn datum_of(state: &CampaignFile) -> Datum {
    Datum {
        station: state.datum.clone(),
        position: state.start,
        heading_rad: state.heading_deg.to_radians(),
    }
}

/// The control points of a configuration, by their names in the readings.
pub(super) fn controls_of(config: &Config) -> Vec<ControlPoint> {
    config
        .targets
        .points
        .iter()
        .enumerate()
        .filter(|(_, t)| t.kind == TargetKind::Control)
        .map(|(i, t)| ControlPoint {
            name: target_name(t.name.as_deref(), i),
            position: Point::new(t.x, t.y),
            z: t.z,
            sigma_m: t.sigma_mm.unwrap_or(0.0) * 1e-3,
        })
        .collect()
}

/// A given target's name: its own, or `T<n>`.
fn target_name(name: Option<&str>, i: usize) -> String {
    name.map_or_else(|| format!("T{}", i + 1), str::to_string)
}

/// Every reading of the campaign's scans so far, in order.
pub(super) fn earlier_readings(state: &CampaignFile, dir: &Path) -> Result<Vec<Reading>> {
    let max = ReadLimits::for_config(&state.config).max_text_bytes;
    let mut all = Vec::new();
    for s in &state.scans {
        let path = dir.join(&s.readings);
        all.extend(
            read_readings(&path, max).with_context(|| format!("{} is damaged", dir.display()))?,
        );
    }
    Ok(all)
}

/// Refuses a reading to a point the campaign cannot know: not a child's
/// marker, not a given target or control point, not one of the team's own
/// targets (`P<n>`), not measured before.
fn check_points(config: &Config, earlier: &[Reading], new: &[Reading], path: &Path) -> Result<()> {
    let children = config.children.count;
    let given: Vec<String> = config
        .targets
        .points
        .iter()
        .enumerate()
        .map(|(i, t)| target_name(t.name.as_deref(), i))
        .collect();
    let own = |p: &str| {
        p.strip_prefix('P')
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
            && config.targets.team_targets() > 0
    };
    for (k, r) in new.iter().enumerate() {
        let p = r.point.as_str();
        let known = child_spot(p).is_some_and(|(c, _)| c < children)
            || given.iter().any(|g| g == p)
            || own(p)
            || earlier.iter().any(|e| e.point == p);
        if !known {
            bail!(
                "{}: reading {} ({}) names an unknown point `{p}`: not a child's marker \
                 (C1.<n> to C{children}.<n>), a given target or control point, or a point measured before",
                path.display(),
                k + 1,
                reading_name(r)
            );
        }
    }
    Ok(())
}

/// A scan and its readings, however they arrived (files or a ROS 2 topic).
pub struct ScanInput {
    /// The cloud's points in the scanner's frame.
    pub cloud: Vec<[f64; 3]>,
    /// The cloud as it is kept in the directory: its bytes and extension.
    pub cloud_file: (Vec<u8>, String),
    /// The readings.
    pub readings: Vec<Reading>,
    /// The readings as they are kept in the directory (CSV).
    pub readings_csv: Vec<u8>,
    /// Where the readings came from, for messages.
    pub readings_from: PathBuf,
}

impl ScanInput {
    /// A scan and its readings from files.
    pub fn from_files(scan: &Path, readings: &Path, config: &Config) -> Result<Self> {
        let max_text = ReadLimits::for_config(config).max_text_bytes;
        let parsed = read_readings(readings, max_text)?;
        let format = CloudFormat::from_path(scan).with_context(|| {
            format!(
                "{}: not a point cloud (LAS, LAZ, E57, PLY or PCD by its extension)",
                scan.display()
            )
        })?;
        let options = CloudReadOptions {
            max_points: config.limits.max_cloud_points as u64,
            ..CloudReadOptions::default()
        };
        let cloud = read_cloud(scan, &options, &mut |_, _| {})?;
        let ext = scan.extension().map_or_else(
            || format.name().to_ascii_lowercase(),
            |e| e.to_string_lossy().to_ascii_lowercase(),
        );
        let cloud_bytes =
            std::fs::read(scan).with_context(|| format!("cannot read {}", scan.display()))?;
        let readings_csv = std::fs::read(readings)
            .with_context(|| format!("cannot read {}", readings.display()))?;
        Ok(Self {
            cloud: cloud.points,
            cloud_file: (cloud_bytes, ext),
            readings: parsed,
            readings_csv,
            readings_from: readings.to_path_buf(),
        })
    }
}

/// One scan added, computed and not yet written ([`Prepared::commit`]).
pub struct Prepared {
    /// The scan's number, from 1.
    pub n: usize,
    /// The station it was taken from.
    pub station: String,
    /// Every scan's record, the new one last.
    pub records: Vec<ScanRecord>,
    /// The new scan's points in the scanner's frame.
    pub cloud: Vec<[f64; 3]>,
    /// The network adjusted with the new readings.
    pub survey: Survey,
    /// Every station's and point's adjusted pose.
    pub poses: Poses,
    /// The campaign replayed to the next plan.
    pub run: CampaignRun,
    /// The next plan, as `next.json` holds it.
    pub next: NextPlan,
    /// The readings left out as blunders, named with their standardized residuals.
    pub left_out: Vec<String>,
    change: Change,
    state: CampaignFile,
}

/// Adds a scan to the campaign in `dir`, in memory: the network adjusted,
/// the cloud registered, the campaign replayed (`on_step` sees every step
/// and the knowledge map it planned on) and every file to write prepared.
pub fn prepare(
    dir: &Path,
    input: ScanInput,
    on_step: impl FnMut(&Step, &OccupancyGrid),
) -> Result<Prepared> {
    let mut state = CampaignFile::load(dir)?;
    let mut records = state.records(dir)?;
    let config = state.config.clone();
    let n = state.scans.len() + 1;
    let new = input.readings;
    let earlier = earlier_readings(&state, dir)?;
    check_points(&config, &earlier, &new, &input.readings_from)?;

    // The network: every reading so far, the new ones checked.
    let mut all = earlier.clone();
    all.extend(new.iter().cloned());
    let model = model_of(&config);
    let survey = adjust_readings(
        model,
        &datum_of(&state),
        &controls_of(&config),
        &all,
        earlier.len(),
    )?;
    let station = scan_station(&state, &new, n)?;
    let at = survey
        .get(&station)
        .with_context(|| format!("station {station} is not in the network"))?;
    let heading = at.value[at.value.len() - 1];
    let position = at.position();
    if state.grid.world_to_cell(position).is_none() {
        bail!(
            "station {station} at ({:.2}, {:.2}) is outside the campaign's area",
            position.x,
            position.y
        );
    }
    let left_out: Vec<String> = survey
        .left_out
        .iter()
        .map(|b| format!("{} ({:.1}σ)", reading_name(&all[b.reading]), b.standardized))
        .collect();
    records.push(ScanRecord {
        name: station.clone(),
        children: children_at(&survey, config.children.count),
        sigma_m: at.sigma_m(),
        left_out: left_out.clone(),
        walls: wall_points(&input.cloud, config.model.scanner_height, state.wall_band_m),
    });

    // The campaign replayed to the next step, every scan at its latest pose.
    let prior = state.prior_grid(dir)?;
    let poses = poses_of(&survey);
    let scans = field_scans(&records, &poses, &state.grid)?;
    let run = run_campaign(prior, &scans, &config, on_step)?;
    // The loop ends right after its last step: the map that step planned on.
    let knowledge = run
        .episode
        .knowledge
        .as_ref()
        .context("the replay keeps its knowledge map")?;
    let next = next_plan(&run, &records, &config, position, heading);

    // Everything computed: the files to write.
    let mut change = Change::default();
    let (cloud_bytes, ext) = input.cloud_file;
    let cloud_name = scan_path("cloud", n, &ext);
    let readings_name = scan_path("readings", n, "csv");
    let record_name = scan_path("scan", n, "json");
    change.put(&cloud_name, cloud_bytes);
    change.put(&readings_name, input.readings_csv);
    let mut record = serde_json::to_vec(records.last().context("the new scan")?)?;
    record.push(b'\n');
    change.put(&record_name, record);
    let encoded = encode_map(
        knowledge,
        Path::new("knowledge.yaml"),
        &[format!("knowledge after scan {n}")],
    )?;
    change.put("knowledge.yaml", encoded.yaml.into_bytes());
    change.put("knowledge.pgm", encoded.pgm);
    change.put("network.json", super::next::network_json(&survey, &all)?);
    let mut next_json = serde_json::to_vec_pretty(&next)?;
    next_json.push(b'\n');
    change.put("next.json", next_json);
    if let Some(step) = run.episode.steps.last() {
        let title = format!("cpsplan campaign \u{2014} after scan {n}");
        // A real campaign knows no ground truth to state a coverage against.
        let mut view = StepView::from(step);
        view.coverage = None;
        let png = render_step(knowledge, &view, &config, &title)?;
        change.put("next.png", png);
    }
    state.scans.push(ScanEntry {
        scan: n,
        cloud: cloud_name,
        readings: readings_name,
        record: record_name,
        station: station.clone(),
    });
    Ok(Prepared {
        n,
        station,
        records,
        cloud: input.cloud,
        survey,
        poses,
        run,
        next,
        left_out,
        change,
        state,
    })
}

impl Prepared {
    /// Writes every file of the new scan into `dir`, the state file last
    /// (once: the files are given up to the write).
    pub fn commit(&mut self, dir: &Path) -> Result<()> {
        std::mem::take(&mut self.change).commit(dir, &self.state)
    }

    /// The configuration of the campaign.
    pub fn config(&self) -> &Config {
        &self.state.config
    }

    /// The new station's registered points (world frame).
    pub fn registered(&self) -> Result<Vec<[f64; 3]>> {
        let &(at, heading) = self
            .poses
            .get(&self.station)
            .with_context(|| format!("station {} is not in the network", self.station))?;
        let lift = self.state.config.model.scanner_height;
        Ok(register(&self.cloud, at, heading, lift).collect())
    }

    /// Station `name`'s adjusted pose and covariance into `m` at `ns`.
    pub fn send_station<O: Outlet>(&self, m: &mut RosOut<O>, ns: u64, name: &str) -> Result<()> {
        let &(at, heading) = self
            .poses
            .get(name)
            .with_context(|| format!("station {name} is not in the network"))?;
        let a = self.survey.get(name).context("a station of the network")?;
        let n = a.value.len();
        m.station(
            ns,
            at,
            heading,
            a.covariance_2d(),
            a.covariance[(n - 1, n - 1)],
        )
    }

    /// What the scan gave and what comes next, in two lines.
    pub fn summary(&self) -> String {
        summary(self.n, &self.station, &self.records, &self.next)
    }
}

/// `cpsplan campaign add`.
pub fn run(args: &AddArgs) -> Result<()> {
    let dir = &args.dir;
    let config = CampaignFile::load(dir)?.config;
    let input = ScanInput::from_files(&args.scan, &args.readings, &config)?;
    let mut mcap = McapRecording::new(args.mcap_out.as_deref(), config.children.count)?;
    let mut prepared = prepare(dir, input, |step, k| mcap.record(step, k))?;
    mcap.check()?;
    mcap.with(|m| write_mcap_scans(m, &prepared, dir));
    let mcap = mcap.finish()?;
    prepared.commit(dir)?;
    if let Some(m) = mcap {
        m.persist()?;
    }
    if !args.quiet {
        for l in &prepared.left_out {
            eprintln!("warning: left out as a blunder: {l}");
        }
        println!("{}", prepared.summary());
    }
    Ok(())
}

/// The station scan `n` was taken from: the start for the first, else the
/// last station the new readings set up.
fn scan_station(state: &CampaignFile, new: &[Reading], n: usize) -> Result<String> {
    let known: Vec<&str> = state.scans.iter().map(|s| s.station.as_str()).collect();
    if n == 1 {
        if let Some(r) = new.iter().find(|r| r.station != state.datum) {
            bail!(
                "the first scan is taken at the start, station {}; its readings name station {}",
                state.datum,
                r.station
            );
        }
        return Ok(state.datum.clone());
    }
    match new.iter().rev().find(|r| r.station != state.datum && !known.contains(&r.station.as_str())) {
        Some(r) => Ok(r.station.clone()),
        None => bail!(
            "scan {n}'s readings set up no new station: the parent's readings at the station it scanned from are needed"
        ),
    }
}

/// The markers the children stand at now: each child's latest spot
/// `C<child>.<n>` in the network (none until every child was measured).
fn children_at(survey: &Survey, count: usize) -> Vec<String> {
    let mut latest: Vec<Option<(usize, &str)>> = vec![None; count];
    for p in &survey.points {
        if let Some((c, spot)) = child_spot(&p.name) {
            if let Some(slot) = latest.get_mut(c) {
                if slot.is_none_or(|(s, _)| spot > s) {
                    *slot = Some((spot, &p.name));
                }
            }
        }
    }
    if latest.iter().any(Option::is_none) {
        return Vec::new();
    }
    latest
        .into_iter()
        .flatten()
        .map(|(_, n)| n.to_string())
        .collect()
}

/// Every station's and point's adjusted pose.
pub(super) fn poses_of(survey: &Survey) -> Poses {
    let station = survey
        .stations
        .iter()
        .map(|a| (a.name.clone(), (a.position(), a.value[a.value.len() - 1])));
    let points = survey
        .points
        .iter()
        .map(|a| (a.name.clone(), (a.position(), 0.0)));
    station.chain(points).collect()
}

/// Every scan's registered cloud and station into `m`, stamped with the
/// replay's clock: the earlier scans' clouds read from `dir`, the new one's
/// from memory.
fn write_mcap_scans(m: &mut McapOut, p: &Prepared, dir: &Path) -> Result<()> {
    let options = CloudReadOptions::default();
    let lift = p.config().model.scanner_height;
    for (k, r) in p.records.iter().enumerate() {
        let ns = p
            .run
            .episode
            .steps
            .get(k)
            .map_or(0, |s| clock_ns(s.clock_h));
        let &(at, heading) = p
            .poses
            .get(&r.name)
            .with_context(|| format!("station {} is not in the network", r.name))?;
        let points: Vec<[f64; 3]> = match p.state.scans.get(k) {
            Some(entry) if k + 1 < p.n => {
                let cloud = read_cloud(&dir.join(&entry.cloud), &options, &mut |_, _| {})?;
                register(&cloud.points, at, heading, lift).collect()
            }
            _ => p.registered()?,
        };
        m.scan(ns, &points)?;
        p.send_station(m, ns, &r.name)?;
    }
    Ok(())
}

/// The summary `add` prints.
fn summary(n: usize, station: &str, records: &[ScanRecord], next: &NextPlan) -> String {
    let sigma = records.last().map_or(0.0, |r| r.sigma_m * 1e3);
    let at = next.station.position;
    let first = format!(
        "scan {n}: station {station} at ({:.3}, {:.3}) ± {sigma:.1} mm; known area {:.0} m²",
        at.x, at.y, next.known_area_m2
    );
    let second = match (&next.stop, &next.next) {
        (Some(stop), _) => format!("the campaign is complete: {stop}"),
        (None, Some(step)) => format!(
            "next: scan at ({:.2}, {:.2}) after {} CPS cycle{}, expected gain {:.0} m², predicted σ {}",
            step.position.x,
            step.position.y,
            step.cycles.len(),
            if step.cycles.len() == 1 { "" } else { "s" },
            step.expected_gain_m2,
            step.predicted_sigma_m
                .map_or_else(|| "–".to_string(), |s| format!("{:.1} mm", s * 1e3))
        ),
        (None, None) => "no next step planned".to_string(),
    };
    format!("{first}\n{second}")
}
