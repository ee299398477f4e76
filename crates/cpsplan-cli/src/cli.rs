//! Command-line interface: argument parsing and the `explore`, `maps` and `plan`
//! commands.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use cpsplan::config::Scoring;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::world::{default_start, resample_conservative};
use cpsplan::{run_episode_with, Config, OccupancyGrid, Point};
use indicatif::{ProgressBar, ProgressStyle};

use crate::formats::rosmap::{load_any, save_map};
use crate::render::{render_map, render_step, StepView};
use crate::report::{write_atomic, write_episode_outputs, MapSource};

/// Scan planning for a cooperative multi-robot laser-scanning team (CPS-SLAM).
#[derive(Debug, Parser)]
#[command(name = "cpsplan", version, about, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a whole scanning campaign on a map and write its report.
    Explore(ExploreArgs),
    /// List the built-in maps, or export them as ROS maps and previews.
    Maps(MapsArgs),
    /// Plan one step for a real team on a partial map; prints the plan as JSON.
    Plan(PlanArgs),
}

/// Options of `cpsplan plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The partial knowledge map: a ROS map_server YAML (trinary: the unknown grey
    /// is unknown), or a PNG/PGM image (at --resolution).
    #[arg(long, value_name = "FILE")]
    pub known: PathBuf,
    /// The parent's position, world frame metres: X,Y.
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub parent: Point,
    /// A child's position, world frame metres: X,Y (once per child).
    #[arg(long = "child", value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true, required = true)]
    pub children: Vec<Point>,
    /// TOML file with any parameters (see docs/USER-GUIDE.md).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Planning resolution in metres per cell.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub resolution: Option<f64>,
    /// Seed of the planner's random choices.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Also draw the planned step as a PNG figure (map, candidates, AND regions,
    /// subgoals, every robot's path) into this file.
    #[arg(long, value_name = "FILE.png")]
    pub figure: Option<PathBuf>,
}

/// Options of `cpsplan explore`.
#[derive(Debug, Args)]
pub struct ExploreArgs {
    /// Ground-truth map: a ROS map_server YAML, or a PNG/PGM image (at --resolution).
    #[arg(long, value_name = "FILE", conflicts_with = "builtin")]
    pub map: Option<PathBuf>,
    /// Built-in map (office, site, tunnel); the default when no --map is given.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<BuiltinMap>,
    /// Start position of the parent, world frame metres: X,Y.
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub start: Option<Point>,
    /// TOML file with any parameters of the run (see docs/USER-GUIDE.md).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Weight α of the travel term of Eq. (1).
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    pub alpha: Option<f64>,
    /// Weight β of the expected-gain term of Eq. (1).
    #[arg(long, value_name = "B", allow_hyphen_values = true)]
    pub beta: Option<f64>,
    /// How Eq. (1) combines its terms.
    #[arg(long, value_enum)]
    pub scoring: Option<ScoringArg>,
    /// Scanner range in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub range: Option<f64>,
    /// Planning resolution in metres per cell (maps are resampled to it).
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub resolution: Option<f64>,
    /// Robot radius in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub radius: Option<f64>,
    /// Stop after this many scans.
    #[arg(long, value_name = "N")]
    pub max_scans: Option<usize>,
    /// Number of child robots (default 2); every move runs as CPS cycles with them, 0 lets the parent move alone.
    #[arg(long, value_name = "N")]
    pub children: Option<usize>,
    /// Seed of every random choice (and of the built-in map's layout).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Draw the planning step after scan N as `step-NNN.png` in the output
    /// directory (repeat the flag or give a comma list: 2,5,9).
    #[arg(long, value_name = "N", value_delimiter = ',', value_parser = parse_scan_number)]
    pub step_figure: Vec<usize>,
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

/// Options of `cpsplan maps`.
#[derive(Debug, Args)]
pub struct MapsArgs {
    /// Write every built-in map as ROS map_server PGM+YAML and a PNG preview here.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// Seed of the maps' layouts.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub seed: u64,
}

fn parse_point(s: &str) -> Result<Point, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y] = parts.as_slice() else {
        return Err(format!("expected X,Y in metres, got `{s}`"));
    };
    let num = |t: &str| {
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{t}` is not a number in `{s}`"))
    };
    Ok(Point::new(num(x)?, num(y)?))
}

fn parse_scan_number(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("expected a scan number (1, 2, ...), got `{s}`")),
    }
}

/// The file name of the figure of the step after scan `n`: `step-007.png`.
pub fn step_figure_name(n: usize) -> String {
    format!("step-{n:03}.png")
}

/// Parses the process arguments and runs the command.
pub fn run() -> Result<()> {
    match Cli::parse().command {
        Command::Explore(args) => explore(&args),
        Command::Maps(args) => maps(&args),
        Command::Plan(args) => plan(&args),
    }
}

/// Reads a TOML configuration file, or the defaults.
fn read_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read config file {}", path.display()))?;
            toml::from_str::<Config>(&text)
                .map_err(|e| anyhow::anyhow!("config file {}: {}", path.display(), e.message()))
        }
        None => Ok(Config::default()),
    }
}

fn plan(args: &PlanArgs) -> Result<()> {
    let mut config = read_config(args.config.as_deref())?;
    if let Some(r) = args.resolution {
        config.resolution = r;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    config.validate()?;
    let grid = load_any(&args.known, config.resolution)?;
    let known = resample_conservative(&grid, config.resolution);
    let step = cpsplan::mission::plan_step(&known, args.parent, &args.children, &config)?;
    if let Some(path) = &args.figure {
        let view = StepView::planned(&step, args.parent, &args.children);
        let name = args.known.file_name().map_or_else(
            || args.known.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let title = format!("cpsplan plan \u{2014} {name}");
        let png = render_step(&known, &view, &config, &title)?;
        write_atomic(path, &png)?;
    }
    let mut out = serde_json::to_string_pretty(&step)?;
    out.push('\n');
    use std::io::Write as _;
    std::io::stdout()
        .write_all(out.as_bytes())
        .context("cannot write the plan")?;
    Ok(())
}

/// Builds the run's configuration: defaults, then the TOML file, then flags.
pub fn build_config(args: &ExploreArgs) -> Result<Config> {
    let mut config = read_config(args.config.as_deref())?;
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
    if let Some(s) = args.seed {
        config.seed = s;
    }
    config.validate()?;
    Ok(config)
}

/// Loads the ground truth at the planning resolution, with its default start.
fn load_truth(
    args: &ExploreArgs,
    config: &Config,
) -> Result<(OccupancyGrid, MapSource, Option<Point>)> {
    match &args.map {
        Some(path) => {
            let grid = load_any(path, config.resolution)?;
            let truth = resample_conservative(&grid, config.resolution);
            Ok((truth, MapSource::File(path.clone()), None))
        }
        None => {
            let map = args.builtin.unwrap_or(BuiltinMap::DEFAULT);
            let grid = map.generate(config.seed);
            let truth = resample_conservative(&grid, config.resolution);
            Ok((truth, MapSource::Builtin(map), Some(map.default_start())))
        }
    }
}

fn explore(args: &ExploreArgs) -> Result<()> {
    let config = build_config(args)?;
    let (truth, source, builtin_start) = load_truth(args, &config)?;
    let start = match args.start.or(builtin_start) {
        Some(p) => p,
        None => match default_start(&truth) {
            Some(p) => p,
            None => bail!("map {} has no free cell to start from", source.label()),
        },
    };
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
    let episode = run_episode_with(&truth, start, &config, |step, knowledge| {
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
    write_episode_outputs(&args.out, &truth, &source, &episode, wall_ms)?;
    for (scan, png) in &figures {
        write_atomic(&args.out.join(step_figure_name(*scan)), png)?;
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
        println!("report written to {}", args.out.display());
    }
    Ok(())
}

fn maps(args: &MapsArgs) -> Result<()> {
    match &args.export {
        None => {
            for map in BuiltinMap::ALL {
                let p = map.default_start();
                println!(
                    "{:8} {} (start {:.1},{:.1})",
                    map.name(),
                    map.description(),
                    p.x,
                    p.y
                );
            }
        }
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create directory {}", dir.display()))?;
            for map in BuiltinMap::ALL {
                let grid = map.generate(args.seed);
                export_map(&grid, dir, map.name(), args.seed)?;
                println!(
                    "wrote {}",
                    dir.join(format!("{}.yaml", map.name())).display()
                );
            }
        }
    }
    Ok(())
}

fn export_map(grid: &OccupancyGrid, dir: &Path, name: &str, seed: u64) -> Result<()> {
    save_map(grid, &dir.join(format!("{name}.yaml")))?;
    let png = render_map(
        grid,
        &format!("cpsplan built-in map `{name}` (seed {seed})"),
    )?;
    write_atomic(&dir.join(format!("{name}.png")), &png)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_with_signs_and_spaces() {
        assert_eq!(parse_point("1.5,-2").unwrap(), Point::new(1.5, -2.0));
        assert_eq!(parse_point(" 3 , 4 ").unwrap(), Point::new(3.0, 4.0));
        assert!(parse_point("1").is_err());
        assert!(parse_point("1,2,3").is_err());
        assert!(parse_point("a,2").is_err());
        assert!(parse_point("nan,2").is_err());
    }
}
