//! `cpsplan explore`: one simulated episode on a map, and its report.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};
use cpsplan::config::{ChildStrategy, InstrumentModel, Planner, Preset, Scoring, TargetPlacement};
use cpsplan::mission::run_episode_until;
use cpsplan::mission::{Summary, TargetOrigin, START_REGION_SHARE};
use cpsplan::model::{build_model, build_model_in, model_point_count, Registration};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{Config, Point, StopReason};
use indicatif::{ProgressBar, ProgressStyle};

mod outputs;

use outputs::{is_field_file, write_field_data, write_mcap_stations, write_model_cloud};
pub use outputs::{
    readings_file_name, scan_file_name, stations_path, ModelFormat, FIELD_CONFIG, FIELD_JSON,
};

use super::{check_memory, load_truth, read_config, validate};
use crate::args::{
    defaults, parse_count, parse_instrument, parse_planner, parse_point, parse_preset, parse_real,
    parse_scan_number, parse_seed, parse_strategy, scoring_name, with_default,
};
use crate::formats::cloud::SourceFrame;
use crate::formats::mcap_out::{clock_ns, McapRecording};
use crate::formats::rosmap::ReadLimits;
use crate::formats::targets::read_targets;
use crate::interrupt::{CtrlC, Interrupted};
use crate::memory::check_needed;
use crate::render::{percent, render_step, share_percent, StepView};
use crate::report::{real_path, write_atomic, write_episode_outputs, ReportDir};

/// Bytes a point of `--cloud-out`'s model takes while it is written: the
/// point (32), its LAS record in a buffer that may double (2 × 34) and its
/// distance to the walls (4).
const CLOUD_BYTES_PER_POINT: f64 = 104.0;

/// Options of `cpsplan explore`.
#[derive(Debug, Args)]
pub struct ExploreArgs {
    /// Ground-truth map: a ROS map_server YAML, or a PNG/PGM image (at --resolution).
    #[arg(long, value_name = "FILE", conflicts_with = "builtin")]
    pub map: Option<PathBuf>,
    /// Built-in map (office, site, tunnel); the default when no --map is given.
    #[arg(long, value_name = "NAME",
          help = with_default("Built-in map (office, site, tunnel), used when no --map is given",
                              BuiltinMap::DEFAULT.name()))]
    pub builtin: Option<BuiltinMap>,
    /// Start position of the parent, world frame metres: X,Y.
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub start: Option<Point>,
    /// TOML file with any parameters of the run (`cpsplan config` prints every
    /// key with its default).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Weight α of the travel term of Eq. (1).
    #[arg(long, value_name = "A", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Weight \u{3b1} of the travel term of Eq. (1)", defaults().parent.alpha))]
    pub alpha: Option<f64>,
    /// Weight β of the expected-gain term of Eq. (1).
    #[arg(long, value_name = "B", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Weight \u{3b2} of the expected-gain term of Eq. (1)", defaults().parent.beta))]
    pub beta: Option<f64>,
    /// How Eq. (1) combines its terms.
    #[arg(long, value_enum,
          help = with_default("How Eq. (1) combines its terms", scoring_name(defaults().parent.scoring)))]
    pub scoring: Option<ScoringArg>,
    /// Scanner range in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Scanner range in metres", defaults().scanner.range))]
    pub range: Option<f64>,
    /// Planning resolution in metres per cell (maps are resampled to it).
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Planning resolution in metres per cell (maps are resampled to it)",
                              defaults().resolution))]
    pub resolution: Option<f64>,
    /// Robot radius in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Robot radius in metres", defaults().robot.radius))]
    pub radius: Option<f64>,
    /// Stop after this many scans.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = parse_count,
          help = with_default("Stop after this many scans", defaults().mission.max_scans))]
    pub max_scans: Option<usize>,
    /// Number of child robots; every move runs as CPS cycles with them, 0 lets
    /// the parent move alone.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = parse_count,
          help = with_default("Number of child robots; every move runs as CPS cycles with them, 0 lets the parent move alone",
                              defaults().children.count))]
    pub children: Option<usize>,
    /// How the children's spots are chosen: random, balanced (Eq. 2, αc = βc, the
    /// default), angle (αc ≫ βc), distance (αc ≪ βc), or min-error (the spots
    /// that minimise the predicted error of the parent's next pose).
    #[arg(long, value_name = "STRATEGY", value_parser = parse_strategy,
          help = with_default("How the children's spots are chosen: random, balanced (Eq. 2, \u{3b1}c = \u{3b2}c), \
                               angle (\u{3b1}c \u{226b} \u{3b2}c), distance (\u{3b1}c \u{226a} \u{3b2}c), or min-error \
                               (the spots that minimise the predicted error of the parent's next pose)",
                              defaults().children.strategy.name()))]
    pub child_strategy: Option<ChildStrategy>,
    /// Start from a preset's choices (paper: the greedy Eq. 1, Eq. 2 with
    /// alpha_c = beta_c and the paper's stop rule, S >= min_gain_cells alone);
    /// the config file's keys and the other flags still apply.
    #[arg(long, value_name = "NAME", value_parser = parse_preset)]
    pub preset: Option<Preset>,
    /// Which planner chooses the next scan position: paper (the greedy Eq. 1),
    /// tour (the shortest route through the scan positions that see the
    /// frontier), the baselines frontier (ROS explore_lite's nearest frontier)
    /// and gain (the most new cells, however far), or the yardstick oracle (the
    /// true gain from the ground truth).
    #[arg(long, value_name = "PLANNER", value_parser = parse_planner,
          help = with_default("Which planner chooses the next scan position: paper (the greedy Eq. 1), tour \
                               (the shortest route through the scan positions that see the frontier), the \
                               baselines frontier (ROS explore_lite's nearest frontier) and gain (the most new \
                               cells, however far), or the yardstick oracle (each scan's true gain, read from \
                               the ground truth)",
                              defaults().parent.planner.name()))]
    pub planner: Option<Planner>,
    /// The instrument measuring the CPS links (see `cpsplan instruments`).
    #[arg(long, value_name = "NAME", value_parser = parse_instrument,
          help = with_default("The instrument measuring the CPS links (see `cpsplan instruments`)",
                              defaults().instrument.model.name()))]
    pub instrument: Option<InstrumentModel>,
    /// Monte Carlo runs of the campaign's CPS chain with real measurement noise
    /// (mean error per scan in the records; 0: none).
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = parse_count,
          help = with_default("Monte Carlo runs of the campaign's CPS chain with real measurement noise \
                               (mean error per scan in the records; 0: none)",
                              defaults().accuracy.monte_carlo_runs))]
    pub monte_carlo: Option<usize>,
    /// Seed of every random choice (and of the built-in map's layout).
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = parse_seed,
          help = with_default("Seed of every random choice (and of the built-in map's layout)", defaults().seed))]
    pub seed: Option<u64>,
    /// Draw the planning step after scan N as `step-NNN.png` in the output
    /// directory (repeat the flag or give a comma list: 2,5,9).
    #[arg(long, value_name = "N", value_delimiter = ',', value_parser = parse_scan_number, allow_hyphen_values = true)]
    pub step_figure: Vec<usize>,
    /// Also write `report.html`: one self-contained page that steps through the
    /// scans (map, robots, paths, AND regions, candidates, error ellipses, plots
    /// and the summary), viewable offline in any browser.
    #[arg(long)]
    pub html: bool,
    /// Write the registered 3D model: every scan's points in the pose the CPS
    /// estimated (.las, .laz or .ply), with its stations beside it as
    /// FILE-stations.ply (e.g. model.laz-stations.ply). On a map `grid` made
    /// from a cloud (MAP.frame.json beside it), in that cloud's frame: its
    /// units, its heights and its coordinate system.
    #[arg(long, value_name = "FILE")]
    pub cloud_out: Option<PathBuf>,
    /// Replace an existing --cloud-out file and its stations file (without
    /// it, either existing is refused before the run).
    #[arg(long, requires = "cloud_out")]
    pub force: bool,
    /// Write what a real team would have recorded: per scan, scan-NNNN.ply
    /// (the cloud in the scanner's own frame, with range noise) and
    /// readings-NNNN.csv (every total-station reading since the scan before,
    /// with the instrument's noise: the values the episode's own estimates come
    /// from). Needs two children or more.
    #[arg(long, value_name = "DIR")]
    pub field_data: Option<PathBuf>,
    /// Write the campaign as ROS 2 messages in an MCAP file: the knowledge
    /// map, the registered scans, the stations, every robot's path, the plans
    /// and tf (the user guide's "Robot software").
    #[arg(long, value_name = "FILE.mcap")]
    pub mcap_out: Option<PathBuf>,
    /// Height of the walls of the 3D model, metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Height of the walls of the 3D model, metres", defaults().model.wall_height))]
    pub wall_height: Option<f64>,
    /// Vertical spacing of the 3D model's points on a wall, metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Vertical spacing of the 3D model's points on a wall, metres",
                              defaults().model.vertical_step))]
    pub vertical_step: Option<f64>,
    /// Targets and control points set up before the campaign, as CSV (columns
    /// name, x, y, kind = control|free, sigma_mm; replaces the config's
    /// `[[targets]]`).
    #[arg(long, value_name = "FILE.csv")]
    pub targets: Option<PathBuf>,
    /// The team carries N targets and leaves them where the planner judges
    /// best (targets.place = "auto", targets.max = N).
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = parse_count)]
    pub place_targets: Option<usize>,
    /// No station scans with a predicted 1σ above M metres: the planner closes
    /// the network first (mission.max_sigma_m).
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real)]
    pub max_sigma: Option<f64>,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Eq. (1) scoring as a command-line value.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ScoringArg {
    /// Terms scaled to [0, 1], weights in units of the paper's defaults.
    Normalized,
    /// The printed formula with metres and cells.
    Literal,
}

/// The file name of the figure of the step after scan `n`: `step-007.png`.
pub fn step_figure_name(n: usize) -> String {
    format!("step-{n:03}.png")
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
    if let Some(path) = &args.cloud_out {
        check_cloud_out(path, &args.out, args.force)?;
    }
    let frame = match (&args.cloud_out, &args.map) {
        (Some(_), Some(map)) => SourceFrame::load_beside(map)?.filter(|f| !f.is_identity()),
        _ => None,
    };
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
    let mut mcap = McapRecording::new(args.mcap_out.as_deref(), config.children.count)?;
    let ctrl_c = CtrlC::install();
    let episode = run_episode_until(&truth, start, &config, ctrl_c.flag(), |step, knowledge| {
        mcap.record(step, knowledge);
        if let Some(page) = page.as_mut() {
            page.record(step, knowledge, &config);
        }
        bar.set_message(format!(
            "scan {} · coverage {} % · walls {} %{}",
            step.scan,
            share_percent(step.coverage),
            share_percent(step.wall_coverage),
            if ctrl_c.pressed() {
                " · Ctrl-C: stopping after this scan (again: quit at once)"
            } else {
                ""
            }
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
    mcap.check()?;
    let mut points = Vec::new();
    if cloud_format.is_some() {
        // The points, their encoding and their distances to the walls, known
        // before the first is made.
        let count = model_point_count(&truth, &episode, &config);
        if count <= config.limits.max_cloud_points as u64 {
            check_needed(
                &format!("--cloud-out: the 3D model of {count} points"),
                count as f64 * CLOUD_BYTES_PER_POINT / (1024.0 * 1024.0),
                config.limits.max_memory_mb,
                "raise `model.vertical_step`, lower `model.wall_height` or set `limits.max_memory_mb`",
            )?;
            points
                .try_reserve_exact(usize::try_from(count).unwrap_or(usize::MAX))
                .map_err(|_| {
                    anyhow!("--cloud-out: no memory for the {count} points of the 3D model")
                })?;
        }
    }
    let mut model_warning = None;
    let model = match build_model(&truth, &episode, &config, |k, p| {
        if cloud_format.is_some() {
            points.extend_from_slice(p);
        }
        if let Some(step) = episode.steps.get(k as usize) {
            mcap.with(|m| {
                let xyz: Vec<[f64; 3]> = p.iter().map(|q| q.position).collect();
                m.scan(clock_ns(step.clock_h), &xyz)
            });
        }
    }) {
        Ok(m) => Some(m),
        Err(e) if args.cloud_out.is_none() => {
            model_warning = Some(format!("{e}: the report states no 3D model accuracy"));
            None
        }
        Err(e) => bail!("--cloud-out: {e}"),
    };
    mcap.with(|m| write_mcap_stations(m, &episode));
    mcap.check()?;
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
        (Some(path), Some(format), Some(model)) => Some(write_model_cloud(
            path,
            format,
            &mut points,
            model,
            frame.as_ref(),
        )?),
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
    let mcap = mcap.finish()?;
    report.commit()?;
    if let Some(field) = field {
        field.commit()?;
    }
    if let (Some(path), Some((cloud, stations))) = (&args.cloud_out, cloud) {
        cloud.persist(path)?;
        stations.persist(&stations_path(path))?;
    }
    if let Some(m) = mcap {
        m.persist()?;
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
            "{}: {} scans, coverage {} %, walls {} %, parent travel {:.1} m, stop: {} ({:.0} ms)",
            source.label(),
            s.scans,
            share_percent(s.coverage),
            share_percent(s.wall_coverage),
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
    if c.children.count == 1 {
        eprintln!(
            "warning: with one child the parent's new pose is not fixed (a CPS cycle measures \
             two children, each link a distance and a direction, to resect it): the report has \
             no predicted error (σ null in summary.json, no error.png); --children 2 or more \
             predicts it"
        );
    }
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
    if episode.summary.stop_reason == StopReason::Interrupted {
        return Err(Interrupted(format!(
            "the run stopped after scan {} on Ctrl-C; the report of its scans is in {} \
             (stop reason `interrupted`)",
            episode.steps.len(),
            args.out.display()
        ))
        .into());
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
        StopReason::Interrupted => "the run was interrupted (Ctrl-C)".into(),
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
        "the scans cover {} % of the free space connected to the start ({stop}): {why}",
        share_percent(s.connected_coverage)
    ))
}

/// Refuses a `--cloud-out` that names a directory, that lies inside `--out`
/// (the report replaces that directory whole) or, without `--force`, whose
/// file or stations file exists, before the run.
fn check_cloud_out(path: &Path, out: &Path, force: bool) -> Result<()> {
    if path.is_dir() {
        bail!(
            "--cloud-out {} is a directory; name the file, e.g. {}",
            path.display(),
            path.join("model.las").display()
        );
    }
    let (cloud, report) = (real_path(path), real_path(out));
    if cloud.starts_with(&report) {
        bail!(
            "--cloud-out {} lies inside --out {}, which the report replaces whole; write it beside",
            path.display(),
            out.display()
        );
    }
    let stations = stations_path(path);
    for file in [path, stations.as_path()] {
        match std::fs::symlink_metadata(file) {
            Ok(m) if m.is_dir() => bail!(
                "--cloud-out: {} is a directory, which the model's files cannot replace",
                file.display()
            ),
            Ok(_) if !force => bail!(
                "--cloud-out: {} already exists; --force replaces it (and {})",
                file.display(),
                if file == path {
                    stations.display()
                } else {
                    path.display()
                }
            ),
            _ => {}
        }
    }
    Ok(())
}
