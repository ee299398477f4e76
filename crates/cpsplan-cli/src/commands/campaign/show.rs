//! `cpsplan campaign status` and `cpsplan campaign export`.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use cpsplan::mission::run_campaign;
use cpsplan::model::ModelPoint;

use super::next::{NetworkFile, NextPlan};
use super::store::{field_scans, register, CampaignFile};
use crate::formats::cloud::{encode_las, encode_ply, read_cloud, CloudFormat, CloudReadOptions};
use crate::formats::rosmap::{load_map_with, read_text, save_map, ReadLimits};
use crate::html::{episode_page, PageRecorder};
use crate::report::write_atomic;

/// Options of `cpsplan campaign status`.
#[derive(Debug, Args)]
pub struct StatusArgs {
    /// The campaign's directory.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

/// Options of `cpsplan campaign export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// The campaign's directory.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// The registered model: every scan's points in its station's adjusted
    /// pose (LAS, LAZ or PLY by the extension).
    #[arg(long, value_name = "FILE.laz")]
    pub cloud: Option<PathBuf>,
    /// The knowledge map (ROS map_server YAML and PGM).
    #[arg(long, value_name = "FILE.yaml")]
    pub map: Option<PathBuf>,
    /// The campaign's page, as `explore --html` writes it.
    #[arg(long, value_name = "FILE.html")]
    pub html: Option<PathBuf>,
}

/// The largest JSON file read back, bytes.
const MAX_JSON_BYTES: u64 = 1 << 30;

/// Reads `name` of the campaign's directory as JSON.
fn read_json<T: serde::de::DeserializeOwned>(dir: &std::path::Path, name: &str) -> Result<T> {
    let path = dir.join(name);
    let text = read_text(&path, MAX_JSON_BYTES)
        .map_err(|e| anyhow!("{} is damaged: {e}", dir.display()))?;
    serde_json::from_str(&text).map_err(|e| anyhow!("{} is damaged: {e}", path.display()))
}

/// `cpsplan campaign status`.
pub fn status(args: &StatusArgs) -> Result<()> {
    let dir = &args.dir;
    let state = CampaignFile::load(dir)?;
    if state.scans.is_empty() {
        println!(
            "campaign {}: no scan yet; the first is taken at the start ({:.2}, {:.2})",
            dir.display(),
            state.start.x,
            state.start.y
        );
        return Ok(());
    }
    let next: NextPlan = read_json(dir, "next.json")?;
    let network: NetworkFile = read_json(dir, "network.json")?;
    println!(
        "campaign {}: {} scan{}, known area {:.0} m², {:.2} h so far",
        dir.display(),
        next.scans,
        if next.scans == 1 { "" } else { "s" },
        next.known_area_m2,
        next.campaign_time_h
    );
    println!("scan  station        x (m)       y (m)    σ (mm)");
    for s in &state.scans {
        let Some(p) = network.stations.iter().find(|p| p.name == s.station) else {
            continue;
        };
        println!(
            "{:>4}  {:<10} {:>11.3} {:>11.3} {:>9.1}",
            s.scan,
            p.name,
            p.position.x,
            p.position.y,
            p.sigma_m * 1e3
        );
    }
    if !network.left_out.is_empty() {
        println!("left out as blunders: {}", network.left_out.join(", "));
    }
    match (&next.stop, &next.next) {
        (Some(stop), _) => println!("complete: {stop}"),
        (None, Some(step)) => println!(
            "next: scan at ({:.2}, {:.2}) after {} CPS cycle{}, expected gain {:.0} m²",
            step.position.x,
            step.position.y,
            step.cycles.len(),
            if step.cycles.len() == 1 { "" } else { "s" },
            step.expected_gain_m2
        ),
        (None, None) => println!("no next step planned"),
    }
    Ok(())
}

/// `cpsplan campaign export`.
pub fn export(args: &ExportArgs) -> Result<()> {
    if args.cloud.is_none() && args.map.is_none() && args.html.is_none() {
        bail!("nothing to export: give --cloud, --map or --html");
    }
    let dir = &args.dir;
    let state = CampaignFile::load(dir)?;
    if state.scans.is_empty() {
        bail!("{}: the campaign has no scan yet", dir.display());
    }
    let limits = ReadLimits::for_config(&state.config);
    if let Some(path) = &args.cloud {
        let format = CloudFormat::from_path(path)
            .filter(|f| matches!(f, CloudFormat::Las | CloudFormat::Laz | CloudFormat::Ply))
            .with_context(|| format!("--cloud {}: write LAS, LAZ or PLY", path.display()))?;
        let network: NetworkFile = read_json(dir, "network.json")?;
        let options = CloudReadOptions::default();
        let lift = state.config.model.scanner_height;
        let mut points: Vec<ModelPoint> = Vec::new();
        for (k, s) in state.scans.iter().enumerate() {
            let station = network
                .stations
                .iter()
                .find(|p| p.name == s.station)
                .with_context(|| {
                    format!("{} is damaged: no station {}", dir.display(), s.station)
                })?;
            let cloud = read_cloud(&dir.join(&s.cloud), &options, &mut |_, _| {})?;
            let heading = station.heading_deg.unwrap_or(0.0).to_radians();
            let scan = u32::try_from(k).unwrap_or(u32::MAX);
            points.extend(
                register(&cloud.points, station.position, heading, lift)
                    .map(|position| ModelPoint { position, scan }),
            );
        }
        let bytes = match format {
            CloudFormat::Ply => encode_ply(&points)?,
            f => encode_las(&points, f == CloudFormat::Laz)?,
        };
        write_atomic(path, &bytes)?;
    }
    if let Some(path) = &args.map {
        let grid = load_map_with(&dir.join("knowledge.yaml"), &limits)
            .map_err(|e| anyhow!("{} is damaged: {e}", dir.display()))?;
        save_map(&grid, path)?;
    }
    if let Some(path) = &args.html {
        let records = state.records(dir)?;
        let network: NetworkFile = read_json(dir, "network.json")?;
        let scans = field_scans(&records, &network.poses(), &state.grid)?;
        let mut page = PageRecorder::new(state.grid);
        let config = &state.config;
        let run = run_campaign(state.prior_grid(dir)?, &scans, config, |step, knowledge| {
            page.record(step, knowledge, config);
        })?;
        let label = dir.file_name().map_or_else(
            || "campaign".to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let title = format!("cpsplan campaign \u{2014} {label}");
        let html = episode_page(&run.episode, &page, &title, &label)?;
        write_atomic(path, html.as_bytes())?;
    }
    Ok(())
}
