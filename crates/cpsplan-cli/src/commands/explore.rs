//! `cpsplan explore`: one simulated episode on a map, and its report.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cpsplan::config::{Scoring, TargetPlacement};
use cpsplan::mission::{field_readings, Summary, TargetOrigin, START_REGION_SHARE};
use cpsplan::model::{
    build_model, build_model_in, scanner_frame_scans, ModelPoint, RegisteredModel, Registration,
};
use cpsplan::{run_episode_with, Config, StopReason};
use indicatif::{ProgressBar, ProgressStyle};

use super::{check_memory, load_truth, read_config, validate};
use crate::cli::{ExploreArgs, ScoringArg};
use crate::formats::cloud::{encode_las, encode_ply, encode_stations_ply};
use crate::formats::mcap_out::{clock_ns, McapOut};
use crate::formats::readings::write_readings;
use crate::formats::rosmap::ReadLimits;
use crate::formats::targets::read_targets;
use crate::render::{percent, render_step, StepView};
use crate::report::{write_atomic, write_episode_outputs, write_temp, ReportDir, TempFile};

/// The file name of the figure of the step after scan `n`: `step-007.png`.
pub fn step_figure_name(n: usize) -> String {
    format!("step-{n:03}.png")
}

/// The file name of scan `n`'s readings in `--field-data`: `readings-0007.csv`.
pub fn readings_file_name(n: usize) -> String {
    format!("readings-{n:04}.csv")
}

/// The file name of scan `n`'s cloud in `--field-data`: `scan-0007.ply`.
pub fn scan_file_name(n: usize) -> String {
    format!("scan-{n:04}.ply")
}

/// Whether `name` is a file `--field-data` writes.
fn is_field_file(name: &str) -> bool {
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
fn write_field_data(
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
fn write_mcap_stations(m: &mut McapOut, episode: &cpsplan::Episode) -> Result<()> {
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

/// Builds the run's configuration: defaults, then the TOML file, then flags.
pub fn build_config(args: &ExploreArgs) -> Result<Config> {
    let file = read_config(args.config.as_deref())?;
    let mut config = file.config.clone();
    if let Some(p) = args.preset {
        p.apply(&mut config, |k| file.sets(k));
    }
    if let Some(a) = args.alpha {
        config.parent.alpha = a;
    }
    if let Some(b) = args.beta {
        config.parent.beta = b;
    }
    if let Some(s) = args.scoring {
        config.parent.scoring = match s {
            ScoringArg::Normalized => Scoring::Normalized,
            ScoringArg::Literal => Scoring::Literal,
        };
    }
    if let Some(r) = args.range {
        config.scanner.range = r;
    }
    if let Some(r) = args.resolution {
        config.resolution = r;
    }
    if let Some(r) = args.radius {
        config.robot.radius = r;
    }
    if let Some(n) = args.max_scans {
        config.mission.max_scans = n;
    }
    if let Some(n) = args.children {
        config.children.count = n;
    }
    if let Some(s) = args.child_strategy {
        config.children.strategy = s;
    }
    if let Some(p) = args.planner {
        config.parent.planner = p;
    }
    if let Some(m) = args.instrument {
        config.instrument.model = m;
    }
    if let Some(n) = args.monte_carlo {
        config.accuracy.monte_carlo_runs = n;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    if let Some(h) = args.wall_height {
        config.model.wall_height = h;
    }
    if let Some(v) = args.vertical_step {
        config.model.vertical_step = v;
    }
    if let Some(path) = &args.targets {
        config.targets.points = read_targets(path, ReadLimits::default().max_text_bytes)?;
    }
    if let Some(n) = args.place_targets {
        config.targets.place = if n > 0 {
            TargetPlacement::Auto
        } else {
            TargetPlacement::None
        };
        config.targets.max = n;
    }
    if let Some(m) = args.max_sigma {
        config.mission.max_sigma_m = Some(m);
    }
    validate(
        &config,
        &[
            ("parent.alpha", "--alpha", args.alpha.is_some()),
            ("parent.beta", "--beta", args.beta.is_some()),
            ("scanner.range", "--range", args.range.is_some()),
            ("resolution", "--resolution", args.resolution.is_some()),
            ("robot.radius", "--radius", args.radius.is_some()),
            ("mission.max_scans", "--max-scans", args.max_scans.is_some()),
            ("children.count", "--children", args.children.is_some()),
            (
                "accuracy.monte_carlo_runs",
                "--monte-carlo",
                args.monte_carlo.is_some(),
            ),
            (
                "model.wall_height",
                "--wall-height",
                args.wall_height.is_some(),
            ),
            (
                "model.vertical_step",
                "--vertical-step",
                args.vertical_step.is_some(),
            ),
            (
                "targets.max",
                "--place-targets",
                args.place_targets.is_some(),
            ),
            ("targets", "--targets", args.targets.is_some()),
            (
                "mission.max_sigma_m",
                "--max-sigma",
                args.max_sigma.is_some(),
            ),
        ],
    )?;
    Ok(config)
}

/// Runs the episode and writes its report.
pub fn run(args: &ExploreArgs) -> Result<()> {
    let config = build_config(args)?;
    let cloud_format = args.cloud_out.as_deref().map(ModelFormat::of).transpose()?;
    if args.field_data.is_some() && config.children.count < 2 {
        bail!(
            "--field-data: the readings fix the parent's pose from two children or more (--children {})",
            config.children.count
        );
    }
    // Refuses an unusable --out (and --field-data) before the run, not after it.
    let report = ReportDir::create(&args.out)?;
    let field = args
        .field_data
        .as_deref()
        .map(|dir| ReportDir::create_for(dir, is_field_file))
        .transpose()?;
    let (truth, source, start) =
        load_truth(args.map.as_deref(), args.builtin, args.start, &config)?;
    check_memory(&truth, &config)?;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new_spinner();
        if let Ok(style) = ProgressStyle::with_template("{spinner} {elapsed} {msg}") {
            bar.set_style(style);
        }
        bar
    };
    let t0 = Instant::now();
    let mut figures: Vec<(usize, Vec<u8>)> = Vec::new();
    let mut figure_error = None;
    let mut page = args
        .html
        .then(|| crate::html::PageRecorder::new(*truth.geometry()));
    let mut mcap = args
        .mcap_out
        .as_ref()
        .map(|_| McapOut::new(config.children.count))
        .transpose()?;
    let mut mcap_error = None;
    let episode = run_episode_with(&truth, start, &config, |step, knowledge| {
        if let (Some(m), None) = (mcap.as_mut(), mcap_error.as_ref()) {
            mcap_error = m.record(step, knowledge).err();
        }
        if let Some(page) = page.as_mut() {
            page.record(step, knowledge, &config);
        }
        bar.set_message(format!(
            "scan {} · coverage {:.1} % · walls {:.1} %",
            step.scan,
            step.coverage * 100.0,
            step.wall_coverage * 100.0
        ));
        bar.tick();
        if figure_error.is_none() && args.step_figure.contains(&step.scan) {
            let title = format!("cpsplan step {} \u{2014} {}", step.scan, source.label());
            match render_step(knowledge, &StepView::from(step), &config, &title) {
                Ok(png) => figures.push((step.scan, png)),
                Err(e) => figure_error = Some((step.scan, e)),
            }
        }
    })?;
    let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    bar.finish_and_clear();
    if let Some((scan, e)) = figure_error {
        bail!("cannot draw the figure of step {scan}: {e}");
    }
    if let Some(e) = mcap_error {
        return Err(e.context("--mcap-out"));
    }
    let mut points = Vec::new();
    let mut model_warning = None;
    let mut scan_error = None;
    let model = match build_model(&truth, &episode, &config, |k, p| {
        if cloud_format.is_some() {
            points.extend_from_slice(p);
        }
        if let (Some(m), Some(step)) = (mcap.as_mut(), episode.steps.get(k as usize)) {
            let xyz: Vec<[f64; 3]> = p.iter().map(|q| q.position).collect();
            if let Err(e) = m.scan(clock_ns(step.clock_h), &xyz) {
                scan_error.get_or_insert(e);
            }
        }
    }) {
        Ok(m) => Some(m),
        Err(e) if args.cloud_out.is_none() => {
            model_warning = Some(format!("{e}: the report states no 3D model accuracy"));
            None
        }
        Err(e) => bail!("--cloud-out: {e}"),
    };
    if let Some(e) = scan_error {
        return Err(e.context("--mcap-out"));
    }
    if let Some(m) = mcap.as_mut() {
        write_mcap_stations(m, &episode).context("--mcap-out")?;
    }
    // The model in the filtering poses too, for its accuracy, where the episode
    // has smoothed ones.
    let filtering = match &model {
        Some(_) if episode.steps.iter().any(|s| s.smoothed_estimate.is_some()) => build_model_in(
            &truth,
            &episode,
            &config,
            Registration::Filtering,
            |_, _| {},
        )
        .ok()
        .map(|m| m.accuracy),
        _ => None,
    };
    // The cloud and its stations under temporary names until the report is in.
    let cloud = match (&args.cloud_out, cloud_format, &model) {
        (Some(path), Some(format), Some(model)) => {
            Some(write_model_cloud(path, format, &points, model)?)
        }
        _ => None,
    };
    drop(points);
    write_episode_outputs(
        report.path(),
        &truth,
        &source,
        &episode,
        model.as_ref(),
        filtering.as_ref(),
        wall_ms,
    )?;
    for (scan, png) in &figures {
        write_atomic(&report.path().join(step_figure_name(*scan)), png)?;
    }
    if let Some(page) = &page {
        let title = format!("cpsplan explore \u{2014} {}", source.label());
        let html = crate::html::episode_page(&episode, page, &title, &source.label())?;
        write_atomic(&report.path().join("report.html"), html.as_bytes())?;
    }
    if let Some(field) = &field {
        write_field_data(field.path(), &truth, &episode, &config)?;
    }
    let mcap = match (&args.mcap_out, mcap) {
        (Some(path), Some(m)) => Some((path, m.finish(path).context("--mcap-out")?)),
        _ => None,
    };
    report.commit()?;
    if let Some(field) = field {
        field.commit()?;
    }
    if let (Some(path), Some((cloud, stations))) = (&args.cloud_out, cloud) {
        cloud.persist(path)?;
        stations.persist(&stations_path(path))?;
    }
    if let Some((path, tmp)) = mcap {
        tmp.persist(path)?;
    }
    let scans = episode.steps.len();
    let mut missing: Vec<usize> = args
        .step_figure
        .iter()
        .copied()
        .filter(|&n| n > scans)
        .collect();
    missing.sort_unstable();
    missing.dedup();
    for n in missing {
        eprintln!(
            "warning: --step-figure {n}: the episode has {scans} scan{}, no {} written",
            if scans == 1 { "" } else { "s" },
            step_figure_name(n)
        );
    }
    if !args.quiet {
        let s = &episode.summary;
        println!(
            "{}: {} scans, coverage {:.1} %, walls {:.1} %, parent travel {:.1} m, stop: {} ({:.0} ms)",
            source.label(),
            s.scans,
            s.coverage * 100.0,
            s.wall_coverage * 100.0,
            s.parent_travel_m,
            crate::report::stop_label(s.stop_reason),
            wall_ms
        );
        let t = &s.campaign_time;
        println!(
            "campaign time {:.1} h ({} planner): scanning {:.1} h, CPS measurements {:.1} h, driving {:.1} h",
            s.campaign_time_h,
            s.planner.name(),
            t.scan_h,
            t.measure_h,
            t.drive_h
        );
        if let (Some(sigma), Some(p)) = (s.final_position_sigma_m, s.error_percent_of_travel) {
            let mc = s
                .monte_carlo_mean_error_m
                .map(|e| format!(", Monte Carlo mean error {:.1} mm", e * 1e3))
                .unwrap_or_default();
            println!(
                "predicted error of the last scan position: {:.1} mm (1\u{3c3}, {} % of the parent's travel, {}){mc}",
                sigma * 1e3,
                percent(p),
                s.instrument
            );
        }
        if let (Some(w), Some(ws)) = (s.worst_position_sigma_m, s.worst_smoothed_sigma_m) {
            println!(
                "worst scan position: {:.1} mm when scanned, {:.1} mm after the whole network (smoothed)",
                w * 1e3,
                ws * 1e3
            );
        }
        if !episode.targets.is_empty() {
            let count = |o: TargetOrigin| episode.targets.iter().filter(|t| t.origin == o).count();
            println!(
                "targets: {} left by the team, {} given, {} control points; {} closures, {} closure move{}",
                count(TargetOrigin::Placed),
                count(TargetOrigin::Free),
                count(TargetOrigin::Control),
                s.closures,
                s.closure_moves,
                if s.closure_moves == 1 { "" } else { "s" }
            );
        }
        if let Some(a) = model.as_ref().map(|m| &m.accuracy) {
            let filtering = filtering
                .as_ref()
                .map(|f| {
                    format!(
                        "; in the poses known when each scan was taken: {:.1} mm and {:.1} mm",
                        f.mean_distance_m * 1e3,
                        f.p95_distance_m * 1e3
                    )
                })
                .unwrap_or_default();
            println!(
                "3D model: {} points, {:.1} mm mean and {:.1} mm 95th-percentile distance to the walls ({}){filtering}",
                a.points,
                a.mean_distance_m * 1e3,
                a.p95_distance_m * 1e3,
                if episode.steps.iter().any(|s| s.smoothed_estimate.is_some()) {
                    "registered in the smoothed poses of one noisy realisation"
                } else if episode.steps.iter().any(|s| s.estimate.is_some()) {
                    "registered in the estimated poses"
                } else if s.final_position_sigma_m.is_some() {
                    "true poses, range noise only; --monte-carlo N registers it in estimated ones"
                } else {
                    "true poses, range noise only"
                }
            );
        }
        println!("report written to {}", args.out.display());
        if let Some(path) = &args.cloud_out {
            println!(
                "3D model written to {} (stations: {})",
                path.display(),
                stations_path(path).display()
            );
        }
    }
    if let Some(w) = coverage_warning(&episode.summary) {
        eprintln!("warning: {w}");
    }
    if let Some(w) = tolerance_warning(&episode) {
        eprintln!("warning: {w}");
    }
    let c = &episode.config;
    if c.children.count < 2 && (!c.targets.is_unset() || c.mission.max_sigma_m.is_some()) {
        eprintln!(
            "warning: targets, control points and --max-sigma act on the CPS network, which needs \
             two children or more (--children {}): ignored",
            c.children.count
        );
    }
    if let Some(w) = model_warning {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// The warning for scans above the tolerance (`--max-sigma`): how many, which,
/// and by how much.
pub fn tolerance_warning(episode: &cpsplan::Episode) -> Option<String> {
    let max = episode.config.mission.max_sigma_m?;
    let v = &episode.summary.sigma_violations;
    if v.is_empty() {
        return None;
    }
    let worst = episode.summary.worst_position_sigma_m.unwrap_or(f64::NAN);
    let list: Vec<String> = v.iter().take(20).map(|n| n.to_string()).collect();
    let more = if v.len() > 20 { ", …" } else { "" };
    Some(format!(
        "{} scan{} above the tolerance of {:.1} mm (the worst {:.1} mm): scan{} {}{more}; \
         no closure within reach kept them (summary.json: sigma_violations)",
        v.len(),
        if v.len() == 1 { "" } else { "s" },
        max * 1e3,
        worst * 1e3,
        if v.len() == 1 { "" } else { "s" },
        list.join(", ")
    ))
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

/// Where the stations of the cloud at `path` go: `NAME-stations.ply` beside it.
pub fn stations_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{stem}-stations.ply"))
}

/// Encodes the model's points and stations into temporary files beside `path`.
fn write_model_cloud(
    path: &Path,
    format: ModelFormat,
    points: &[ModelPoint],
    model: &RegisteredModel,
) -> Result<(TempFile, TempFile)> {
    let bytes = match format {
        ModelFormat::Las => encode_las(points, false),
        ModelFormat::Laz => encode_las(points, true),
        ModelFormat::Ply => encode_ply(points),
    }
    .with_context(|| format!("--cloud-out {}", path.display()))?;
    let cloud = write_temp(path, &bytes)?;
    let stations = encode_stations_ply(&model.stations)
        .with_context(|| format!("--cloud-out {}", path.display()))?;
    let stations = write_temp(&stations_path(path), &stations)?;
    Ok((cloud, stations))
}

/// The warning for an episode whose scans cover less than 90 % of the free
/// space connected to the start, with what the stop reason says about it.
pub fn coverage_warning(s: &Summary) -> Option<String> {
    if s.connected_coverage >= 0.9 && s.stop_reason != StopReason::StartRegionTooSmall {
        return None;
    }
    let why = match s.stop_reason {
        StopReason::StartRegionTooSmall => {
            let (part, whole, of) = if (s.reachable_free_cells as f64)
                < START_REGION_SHARE * s.connected_free_cells as f64
            {
                (
                    s.reachable_free_cells,
                    s.connected_free_cells,
                    "connected to the start",
                )
            } else {
                (s.reachable_free_cells, s.map_free_cells, "of the whole map")
            };
            format!(
                "the robots can reach only {part} of the {whole} free cells {of}; \
                 check --start, --radius and the map"
            )
        }
        StopReason::ScanLimit => "the scan limit ended the episode (--max-scans)".into(),
        StopReason::DiminishingReturns => {
            "the last scans added almost nothing (mission.stop_window, mission.stop_share)".into()
        }
        StopReason::FrontierBelowThreshold => {
            "only border fragments below parent.min_frontier_cells were left".into()
        }
        StopReason::NoCpsMove => {
            "no target could be reached by CPS cycles (see the children's link range)".into()
        }
        StopReason::NoReachableFrontier => {
            "no reachable position would see anything new (narrow passages for --radius?)".into()
        }
        StopReason::Complete => "the rest lies beyond what the robots can reach".into(),
    };
    let stop = if s.connected_coverage < 0.9 {
        format!("less than 90 %, stop: {}", s.stop_reason.name())
    } else {
        format!("stop: {}", s.stop_reason.name())
    };
    Some(format!(
        "the scans cover {:.1} % of the free space connected to the start ({stop}): {why}",
        s.connected_coverage * 100.0
    ))
}
