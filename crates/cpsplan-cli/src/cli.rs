//! Command-line interface: the arguments of every subcommand and their parsing;
//! each subcommand's work is in [`crate::commands`].

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Parser, Subcommand, ValueEnum};
use cpsplan::config::{ChildStrategy, InstrumentModel, Planner, Preset, Scoring};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{Config, Point};

use crate::commands;
use crate::formats::cloud::LengthUnit;

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
    /// List the instrument presets with their accuracy and range.
    Instruments,
    /// Project a 3D point cloud (LAS, LAZ, E57, PLY, PCD) to a ROS map_server
    /// map (PGM + YAML) that explore and plan load.
    Grid(GridArgs),
    /// The known-map yardstick: how few scan stations cover the map when it is
    /// known beforehand (greedy set cover and an LP lower bound).
    Bound(BoundArgs),
    /// Run the episodes of an experiment file in parallel, one record each as it
    /// finishes (`experiment merge` joins the directories of its shards).
    Experiment(ExperimentArgs),
    /// Plots and tables of an experiment's records: coverage, travel, error and
    /// campaign time against the scans, per map and condition, as SVG and PNG, and
    /// the headline figures as Markdown and CSV.
    Report(ReportArgs),
    /// A real team's campaign, one scan at a time: `init` a directory, `add`
    /// each scan's cloud and total-station readings to get the next plan,
    /// `status`, `export` the registered model, the map and the page.
    Campaign(commands::campaign::CampaignArgs),
    /// A campaign as a live ROS 2 node: scans and readings in, the next plan,
    /// the map and the registered scans out (pure Rust DDS, no ROS needed).
    #[cfg(feature = "ros")]
    Ros(commands::campaign::live::RosArgs),
}

/// Options of `cpsplan report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The experiment's directory (the --out of `cpsplan experiment` or `experiment merge`).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Where the report goes [default: DIR/report]; an earlier report there is replaced.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Put every episode page of the experiment (`experiment --html`) into
    /// report.html, not only each condition's typical episode.
    #[arg(long)]
    pub all_episodes: bool,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Options of `cpsplan experiment`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct ExperimentArgs {
    /// `merge`: join the directories of an experiment's shards.
    #[command(subcommand)]
    pub command: Option<ExperimentCommand>,
    /// The experiment file: maps × starts × parameter sets × planners × child
    /// strategies × instruments × seeds (docs/USER-GUIDE.md "Experiments").
    #[arg(value_name = "FILE.toml", required = true)]
    pub file: Option<PathBuf>,
    /// Directory of the records: experiment.toml, plan.json, records/NNNNNN.json
    /// (one per episode, written as it finishes), episodes.csv.
    #[arg(long, value_name = "DIR", required = true)]
    pub out: Option<PathBuf>,
    /// Continue the experiment in --out: run only the episodes without a whole
    /// record (a damaged one is redone).
    #[arg(long)]
    pub resume: bool,
    /// Run only the K-th of N slices of the episodes (1 ≤ K ≤ N: those whose
    /// number leaves the remainder K − 1 when divided by N).
    #[arg(long, value_name = "K/N")]
    pub shard: Option<crate::experiment::Shard>,
    /// Episodes run at once [default: the number of cores].
    #[arg(long, value_name = "N", value_parser = parse_count)]
    pub jobs: Option<usize>,
    /// Also write each finished episode's page, pages/NNNNNN.html (the page of
    /// `explore --html`), before its record; `cpsplan report` shows them. With
    /// --resume, finished episodes without a page are run again.
    #[arg(long)]
    pub html: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The subcommands of `cpsplan experiment`.
#[derive(Debug, Subcommand)]
pub enum ExperimentCommand {
    /// Join the records of an experiment's shard directories into one directory;
    /// refuses duplicate or missing episodes.
    Merge(MergeArgs),
}

/// Options of `cpsplan experiment merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shards' directories (the --out of each `experiment --shard K/N`).
    #[arg(value_name = "DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// The merged directory (new or empty).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Options of `cpsplan bound`.
#[derive(Debug, Args)]
pub struct BoundArgs {
    /// Ground-truth map: a ROS map_server YAML, or a PNG/PGM image (at --resolution).
    #[arg(long, value_name = "MAP.yaml", conflicts_with = "builtin")]
    pub map: Option<PathBuf>,
    /// Built-in map (office, site, tunnel), used when no --map is given.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<BuiltinMap>,
    /// Where the team starts (only the part of the map reachable from it counts),
    /// world frame metres: X,Y.
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub start: Option<Point>,
    /// Scanner range in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Scanner range in metres", defaults().scanner.range))]
    pub range: Option<f64>,
    /// Planning resolution in metres per cell (maps are resampled to it).
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Planning resolution in metres per cell (maps are resampled to it)", defaults().resolution))]
    pub resolution: Option<f64>,
    /// Robot radius in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Robot radius in metres", defaults().robot.radius))]
    pub radius: Option<f64>,
    /// Spacing of the candidate stations' lattice, metres (default: 1 m, wider on
    /// large sites).
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real)]
    pub spacing: Option<f64>,
    /// Spacing of the cells counted for coverage, metres (default: every cell,
    /// a sub-lattice on large sites).
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real)]
    pub target_spacing: Option<f64>,
    /// TOML file with any parameters of the run (see docs/USER-GUIDE.md).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Output directory: bound.json and bound.png.
    #[arg(long, value_name = "DIR", default_value = "bound")]
    pub out: PathBuf,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Options of `cpsplan grid`.
#[derive(Debug, Args)]
pub struct GridArgs {
    /// The point cloud: .las, .laz, .e57, .ply or .pcd.
    #[arg(long, value_name = "FILE")]
    pub cloud: PathBuf,
    /// The map to write: MAP.yaml, with its image MAP.pgm beside it.
    #[arg(long, value_name = "MAP.yaml")]
    pub out: PathBuf,
    /// Cell width of the map, metres.
    #[arg(long, value_name = "M", default_value_t = 0.1, allow_hyphen_values = true, value_parser = parse_real)]
    pub resolution: f64,
    /// Obstacle band by absolute height: lowest z, metres (with --z-max).
    #[arg(long, value_name = "Z", allow_hyphen_values = true, value_parser = parse_real,
          requires = "z_max", conflicts_with_all = ["height_above_ground", "ground"])]
    pub z_min: Option<f64>,
    /// Obstacle band by absolute height: highest z, metres (with --z-min).
    #[arg(long, value_name = "Z", allow_hyphen_values = true, value_parser = parse_real, requires = "z_min")]
    pub z_max: Option<f64>,
    /// Obstacle band by height above the estimated ground, metres: LO,HI.
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true, value_parser = parse_pair,
          help = "Obstacle band by height above the estimated ground, metres: LO,HI [default: 0.2,2.0 \
                  when no --z-min/--z-max is given]")]
    pub height_above_ground: Option<(f64, f64)>,
    /// How the ground is estimated: none (z = 0), plane (a plane under the
    /// lowest points), lowest (the lowest point within --ground-window).
    #[arg(long, value_enum, default_value = "plane")]
    pub ground: GroundArg,
    /// Half-width of the window of `--ground lowest`, metres.
    #[arg(long, value_name = "M", default_value_t = 2.0, allow_hyphen_values = true, value_parser = parse_real)]
    pub ground_window: f64,
    /// Points in the obstacle band that make a cell occupied.
    #[arg(long, value_name = "N", default_value_t = 1, allow_hyphen_values = true, value_parser = parse_count)]
    pub min_points: usize,
    /// Drop points with fewer than two others within R metres (radius outlier
    /// removal).
    #[arg(long, value_name = "R", allow_hyphen_values = true, value_parser = parse_real)]
    pub outlier_radius: Option<f64>,
    /// Move the cloud into the map frame first: shift TX,TY metres after
    /// rotating by YAW about the cloud's origin (radians; `90deg` for degrees).
    #[arg(long, value_name = "TX,TY,YAW", allow_hyphen_values = true, value_parser = parse_transform)]
    pub transform: Option<(f64, f64, f64)>,
    /// Free space along the beams from the scan origins (E57 poses, a PCD's
    /// VIEWPOINT, or --origin) instead of wherever the ground was seen.
    #[arg(long)]
    pub free_from_scans: bool,
    /// The scanner's centre X,Y,Z in the cloud's frame, for --free-from-scans
    /// (overrides the file's origins).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_triple)]
    pub origin: Option<[f64; 3]>,
    /// Length unit of the file's coordinates, overriding what the file says:
    /// m, ft or us-ft.
    #[arg(long, value_name = "UNIT", value_parser = parse_unit)]
    pub units: Option<LengthUnit>,
    /// Skip points whose coordinates are not finite numbers instead of refusing
    /// the file.
    #[arg(long)]
    pub drop_invalid: bool,
    /// Also draw the map as a PNG picture into this file.
    #[arg(long, value_name = "FILE.png")]
    pub preview: Option<PathBuf>,
    /// TOML file with the limits (`[limits]`, see docs/USER-GUIDE.md).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// `--ground` as a command-line value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum GroundArg {
    /// The ground is z = 0.
    None,
    /// A plane fitted under the lowest points.
    Plane,
    /// The lowest point within --ground-window of each cell.
    Lowest,
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
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Planning resolution in metres per cell", defaults().resolution))]
    pub resolution: Option<f64>,
    /// Seed of the planner's random choices.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = parse_seed,
          help = with_default("Seed of the planner's random choices", defaults().seed))]
    pub seed: Option<u64>,
    /// The instrument measuring the CPS links (see `cpsplan instruments`).
    #[arg(long, value_name = "NAME", value_parser = parse_instrument,
          help = with_default("The instrument measuring the CPS links (see `cpsplan instruments`)",
                              defaults().instrument.model.name()))]
    pub instrument: Option<InstrumentModel>,
    /// How the children's spots are chosen.
    #[arg(long, value_name = "STRATEGY", value_parser = parse_strategy,
          help = with_default("How the children's spots are chosen: random, balanced, angle, distance or min-error",
                              defaults().children.strategy.name()))]
    pub child_strategy: Option<ChildStrategy>,
    /// Start from a preset's choices (paper: the greedy Eq. 1, Eq. 2 with
    /// alpha_c = beta_c and the paper's stop rule, S >= min_gain_cells alone);
    /// the config file's keys and the other flags still apply.
    #[arg(long, value_name = "NAME", value_parser = parse_preset)]
    pub preset: Option<Preset>,
    /// Which planner chooses the next scan position: paper (the greedy Eq. 1),
    /// tour (the shortest route through the scan positions that see the
    /// frontier), or the baselines frontier (ROS explore_lite's nearest frontier)
    /// and gain (the most new cells, however far).
    #[arg(long, value_name = "PLANNER", value_parser = parse_planner,
          help = with_default("Which planner chooses the next scan position: paper (the greedy Eq. 1), tour \
                               (the shortest route through the scan positions that see the frontier), or the \
                               baselines frontier (ROS explore_lite's nearest frontier) and gain (the most new \
                               cells, however far)",
                              defaults().parent.planner.name()))]
    pub planner: Option<Planner>,
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
    #[arg(long, value_name = "NAME",
          help = with_default("Built-in map (office, site, tunnel), used when no --map is given",
                              BuiltinMap::DEFAULT.name()))]
    pub builtin: Option<BuiltinMap>,
    /// Start position of the parent, world frame metres: X,Y.
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub start: Option<Point>,
    /// TOML file with any parameters of the run (see docs/USER-GUIDE.md).
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
    /// NAME-stations.ply.
    #[arg(long, value_name = "FILE")]
    pub cloud_out: Option<PathBuf>,
    /// Write what a real team would have recorded: per scan, scan-NNNN.ply
    /// (the cloud in the scanner's own frame, with range noise) and
    /// readings-NNNN.csv (every total-station reading since the scan before,
    /// with the instrument's noise: the values the episode's own estimates come
    /// from). Needs two children or more.
    #[arg(long, value_name = "DIR")]
    pub field_data: Option<PathBuf>,
    /// Write the campaign as ROS 2 messages in an MCAP file: the knowledge
    /// map, the registered scans, the stations, every robot's path, the plans
    /// and tf (docs/USER-GUIDE.md "Robot software").
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

/// Options of `cpsplan maps`.
#[derive(Debug, Args)]
pub struct MapsArgs {
    /// Write every built-in map as ROS map_server PGM+YAML and a PNG preview here.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// Seed of the maps' layouts.
    #[arg(long, value_name = "N", default_value_t = 0, allow_hyphen_values = true, value_parser = parse_seed)]
    pub seed: u64,
}

/// The default configuration, for the defaults shown in `--help`.
fn defaults() -> Config {
    Config::default()
}

/// A flag's help line with its default value.
fn with_default(help: &str, default: impl std::fmt::Display) -> String {
    format!("{help} [default: {default}]")
}

fn scoring_name(s: Scoring) -> &'static str {
    match s {
        Scoring::Normalized => "normalized",
        Scoring::Literal => "literal",
    }
}

/// A finite number (ranges are checked with the whole configuration).
fn parse_real(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err("expected a finite number".to_string()),
        Err(_) => Err("expected a number".to_string()),
    }
}

/// A whole number, 0 or more.
fn parse_count(s: &str) -> Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| "expected a whole number, 0 or more".to_string())
}

/// A seed: a whole number from 0 to 2^64 - 1.
fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse::<u64>()
        .map_err(|_| "expected a whole number from 0 to 18446744073709551615".to_string())
}

/// `X,Y` in metres.
pub(crate) fn parse_point(s: &str) -> Result<Point, String> {
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

/// Numbers separated by commas, each finite.
fn parse_list(s: &str, n: usize, what: &str) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != n {
        return Err(format!("expected {what}, got `{s}`"));
    }
    parts
        .iter()
        .map(|t| {
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("`{t}` is not a number in `{s}`"))
        })
        .collect()
}

/// `LOW,HIGH` heights in metres, `LOW < HIGH`.
pub(crate) fn parse_wall_band(s: &str) -> Result<[f64; 2], String> {
    let v = parse_list(s, 2, "LOW,HIGH in metres")?;
    if v[0] >= v[1] {
        return Err(format!("`{s}`: LOW must be below HIGH"));
    }
    Ok([v[0], v[1]])
}

fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let v = parse_list(s, 2, "LO,HI in metres")?;
    Ok((v[0], v[1]))
}

fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let v = parse_list(s, 3, "X,Y,Z in metres")?;
    Ok([v[0], v[1], v[2]])
}

/// TX,TY,YAW: metres, metres, radians (or degrees with a `deg` suffix).
fn parse_transform(s: &str) -> Result<(f64, f64, f64), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [tx, ty, yaw] = parts.as_slice() else {
        return Err(format!(
            "expected TX,TY,YAW (metres, metres, radians), got `{s}`"
        ));
    };
    let num = |t: &str| {
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{t}` is not a number in `{s}`"))
    };
    let yaw = match yaw
        .strip_suffix("deg")
        .or_else(|| yaw.strip_suffix('\u{b0}'))
    {
        Some(d) => num(d.trim())?.to_radians(),
        None => num(yaw)?,
    };
    Ok((num(tx)?, num(ty)?, yaw))
}

fn parse_unit(s: &str) -> Result<LengthUnit, String> {
    LengthUnit::parse(s.trim()).ok_or_else(|| format!("unknown unit `{s}` (one of: m, ft, us-ft)"))
}

fn parse_instrument(s: &str) -> Result<InstrumentModel, String> {
    InstrumentModel::ALL
        .into_iter()
        .find(|m| m.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = InstrumentModel::ALL.iter().map(|m| m.name()).collect();
            format!("unknown instrument `{s}` (one of: {})", names.join(", "))
        })
}

fn parse_strategy(s: &str) -> Result<ChildStrategy, String> {
    ChildStrategy::ALL
        .into_iter()
        .find(|m| m.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = ChildStrategy::ALL.iter().map(|m| m.name()).collect();
            format!(
                "unknown child strategy `{s}` (one of: {})",
                names.join(", ")
            )
        })
}

fn parse_preset(s: &str) -> Result<Preset, String> {
    Preset::ALL
        .into_iter()
        .find(|p| p.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
            format!("unknown preset `{s}` (one of: {})", names.join(", "))
        })
}

fn parse_planner(s: &str) -> Result<Planner, String> {
    Planner::ALL
        .into_iter()
        .find(|p| p.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = Planner::ALL.iter().map(|p| p.name()).collect();
            format!("unknown planner `{s}` (one of: {})", names.join(", "))
        })
}

fn parse_scan_number(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("expected a scan number (1, 2, ...), got `{s}`")),
    }
}

/// A command line that could not be parsed, in one line.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Parses `args` (the program name first); help and version requests print
/// and exit, every other problem becomes a one-line [`UsageError`].
pub fn parse<I, T>(args: I) -> Result<Cli>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    use clap::error::ErrorKind;
    let args: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    let command = args
        .iter()
        .skip(1)
        .filter_map(|a| a.to_str())
        .find(|a| {
            [
                "explore",
                "plan",
                "maps",
                "instruments",
                "grid",
                "bound",
                "experiment",
                "report",
                "campaign",
            ]
            .contains(a)
        })
        .map_or_else(|| "cpsplan".to_string(), |c| format!("cpsplan {c}"));
    match Cli::try_parse_from(args) {
        Ok(cli) => Ok(cli),
        Err(e) => match e.kind() {
            ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
            _ => Err(UsageError(usage_line(&e.render().to_string(), &command)).into()),
        },
    }
}

/// Clap's several-line message as one line: the error, and where to find help.
fn usage_line(rendered: &str, command: &str) -> String {
    // The message is everything before the first blank line (a list of missing
    // arguments follows its first line).
    let message: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| !l.is_empty())
        .collect();
    let first = message.join(" ");
    let first = first.strip_prefix("error: ").unwrap_or(&first);
    let first = if first.is_empty() {
        "bad arguments"
    } else {
        first
    };
    let tip = rendered
        .lines()
        .map(str::trim)
        .find_map(|l| l.strip_prefix("tip: "))
        .map(|t| format!(" ({t})"))
        .unwrap_or_default();
    format!("{first}{tip}; see `{command} --help`")
}

/// An error and its causes on one line, each cause once: a cause whose text the
/// message already holds (many errors repeat their source) is left out.
pub fn one_line(error: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        let text = text.trim();
        if text.is_empty() || line.contains(text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(text);
    }
    line.replace('\n', " ")
}

/// Parses the process arguments and runs the command.
pub fn run() -> Result<()> {
    run_args(std::env::args_os())
}

/// Runs the command line `args` (the program's name first) as `cpsplan`
/// does: the entry point of the Python package.
pub fn run_args<I, T>(args: I) -> Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    match parse(args)?.command {
        Command::Explore(args) => commands::explore::run(&args),
        Command::Maps(args) => commands::maps::run(&args),
        Command::Plan(args) => commands::plan::run(&args),
        Command::Instruments => commands::instruments::run(),
        Command::Grid(args) => commands::grid::run(&args),
        Command::Bound(args) => commands::bound::run(&args),
        Command::Experiment(args) => commands::experiment::run(&args),
        Command::Report(args) => commands::report::run(&args),
        Command::Campaign(args) => commands::campaign::run(&args),
        #[cfg(feature = "ros")]
        Command::Ros(args) => commands::campaign::live::run(&args),
    }
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
