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
use cpsplan::mission::run_campaign;
use cpsplan::{Config, Point};

use super::next::{next_plan, NextPlan};
use super::store::{
    field_scans, register, scan_path, wall_points, CampaignFile, Change, Poses, ScanEntry,
    ScanRecord,
};
use crate::formats::cloud::{read_cloud, CloudFormat, CloudReadOptions};
use crate::formats::mcap_out::{clock_ns, McapOut};
use crate::formats::readings::read_readings;
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
    /// The total station's readings since the scan before (CSV,
    /// docs/USER-GUIDE.md "Readings"); the first scan's may hold only a header.
    #[arg(long, value_name = "FILE.csv")]
    pub readings: PathBuf,
    /// Also write the campaign so far as ROS 2 messages in an MCAP file
    /// (docs/USER-GUIDE.md "Robot software").
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

/// `cpsplan campaign add`.
pub fn run(args: &AddArgs) -> Result<()> {
    let dir = &args.dir;
    let mut state = CampaignFile::load(dir)?;
    let mut records = state.records(dir)?;
    let config = state.config.clone();
    let n = state.scans.len() + 1;
    let max_text = ReadLimits::for_config(&config).max_text_bytes;
    let new = read_readings(&args.readings, max_text)?;
    let earlier = earlier_readings(&state, dir)?;
    check_points(&config, &earlier, &new, &args.readings)?;
    let format = CloudFormat::from_path(&args.scan).with_context(|| {
        format!(
            "{}: not a point cloud (LAS, LAZ, E57, PLY or PCD by its extension)",
            args.scan.display()
        )
    })?;
    let options = CloudReadOptions {
        max_points: config.limits.max_cloud_points as u64,
        ..CloudReadOptions::default()
    };
    let cloud = read_cloud(&args.scan, &options, &mut |_, _| {})?;

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
        walls: wall_points(
            &cloud.points,
            config.model.scanner_height,
            state.wall_band_m,
        ),
    });

    // The campaign replayed to the next step, every scan at its latest pose.
    let prior = state.prior_grid(dir)?;
    let poses = poses_of(&survey);
    let scans = field_scans(&records, &poses, &state.grid)?;
    let mut mcap = args
        .mcap_out
        .as_ref()
        .map(|_| McapOut::new(config.children.count))
        .transpose()?;
    let mut mcap_error = None;
    let run = run_campaign(prior, &scans, &config, |step, k| {
        if let (Some(m), None) = (mcap.as_mut(), mcap_error.as_ref()) {
            mcap_error = m.record(step, k).err();
        }
    })?;
    if let Some(e) = mcap_error {
        return Err(e.context("--mcap-out"));
    }
    if let Some(m) = mcap.as_mut() {
        let clouds: Vec<PathBuf> = state
            .scans
            .iter()
            .map(|s| dir.join(&s.cloud))
            .chain(std::iter::once(args.scan.clone()))
            .collect();
        write_mcap_scans(m, &run, &records, &clouds, &poses, &survey, &config)
            .context("--mcap-out")?;
    }
    // The loop ends right after its last step: the map that step planned on.
    let knowledge = run
        .episode
        .knowledge
        .as_ref()
        .context("the replay keeps its knowledge map")?;
    let next = next_plan(&run, &records, &config, position, heading);

    // Everything computed: write it.
    let mut change = Change::default();
    let ext = args.scan.extension().map_or_else(
        || format.name().to_ascii_lowercase(),
        |e| e.to_string_lossy().to_ascii_lowercase(),
    );
    let cloud_name = scan_path("cloud", n, &ext);
    let readings_name = scan_path("readings", n, "csv");
    let record_name = scan_path("scan", n, "json");
    change.put(
        &cloud_name,
        std::fs::read(&args.scan)
            .with_context(|| format!("cannot read {}", args.scan.display()))?,
    );
    change.put(
        &readings_name,
        std::fs::read(&args.readings)
            .with_context(|| format!("cannot read {}", args.readings.display()))?,
    );
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
    let mcap = match (&args.mcap_out, mcap) {
        (Some(path), Some(m)) => Some((path, m.finish(path).context("--mcap-out")?)),
        _ => None,
    };
    change.commit(dir, &state)?;
    if let Some((path, tmp)) = mcap {
        tmp.persist(path)?;
    }
    if !args.quiet {
        for l in &left_out {
            eprintln!("warning: left out as a blunder: {l}");
        }
        print_summary(n, &station, &records, &next);
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
/// replay's clock.
fn write_mcap_scans(
    m: &mut McapOut,
    run: &cpsplan::mission::CampaignRun,
    records: &[ScanRecord],
    clouds: &[PathBuf],
    poses: &Poses,
    survey: &Survey,
    config: &Config,
) -> Result<()> {
    let options = CloudReadOptions::default();
    let lift = config.model.scanner_height;
    for (k, (r, path)) in records.iter().zip(clouds).enumerate() {
        let ns = run.episode.steps.get(k).map_or(0, |s| clock_ns(s.clock_h));
        let &(at, heading) = poses
            .get(&r.name)
            .with_context(|| format!("station {} is not in the network", r.name))?;
        let cloud = read_cloud(path, &options, &mut |_, _| {})?;
        let points: Vec<[f64; 3]> = register(&cloud.points, at, heading, lift).collect();
        m.scan(ns, &points)?;
        let a = survey.get(&r.name).context("a station of the network")?;
        let n = a.value.len();
        m.station(
            ns,
            at,
            heading,
            a.covariance_2d(),
            a.covariance[(n - 1, n - 1)],
        )?;
    }
    Ok(())
}

/// The lines `add` prints.
fn print_summary(n: usize, station: &str, records: &[ScanRecord], next: &NextPlan) {
    let sigma = records.last().map_or(0.0, |r| r.sigma_m * 1e3);
    let at = next.station.position;
    println!(
        "scan {n}: station {station} at ({:.3}, {:.3}) ± {sigma:.1} mm; known area {:.0} m²",
        at.x, at.y, next.known_area_m2
    );
    match (&next.stop, &next.next) {
        (Some(stop), _) => println!("the campaign is complete: {stop}"),
        (None, Some(step)) => println!(
            "next: scan at ({:.2}, {:.2}) after {} CPS cycle{}, expected gain {:.0} m², predicted σ {}",
            step.position.x,
            step.position.y,
            step.cycles.len(),
            if step.cycles.len() == 1 { "" } else { "s" },
            step.expected_gain_m2,
            step.predicted_sigma_m
                .map_or_else(|| "–".to_string(), |s| format!("{:.1} mm", s * 1e3))
        ),
        (None, None) => println!("no next step planned"),
    }
}
