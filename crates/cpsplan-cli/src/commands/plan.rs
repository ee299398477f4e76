//! `cpsplan plan`: one step for a real team on a partial map, printed as JSON.

use std::io::Write as _;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use cpsplan::config::{ChildStrategy, InstrumentModel, Planner, Preset};
use cpsplan::Point;

use super::{load_planning_grid, read_config, validate};
use crate::args::{
    defaults, parse_count, parse_instrument, parse_planner, parse_point, parse_preset, parse_real,
    parse_seed, parse_strategy, with_default,
};

/// `--scan`: a whole number from 1.
fn parse_scan(s: &str) -> Result<usize, String> {
    match parse_count(s)? {
        0 => Err("the scans done so far count from 1 (the first scan is scan 1)".into()),
        n => Ok(n),
    }
}
use crate::formats::tidy::to_json_tidy;
use crate::render::{render_step, StepView};
use crate::report::write_temp;

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
    /// A child's position, world frame metres: X,Y (once per child; none: the
    /// parent moves alone).
    #[arg(long = "child", value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub children: Vec<Point>,
    /// Number of child robots, as a check: it must equal the --child positions
    /// given (0: the parent alone, no --child).
    #[arg(long = "children", value_name = "N", allow_hyphen_values = true, value_parser = parse_count)]
    pub count: Option<usize>,
    /// Scanner range in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Scanner range in metres", defaults().scanner.range))]
    pub range: Option<f64>,
    /// Robot radius in metres.
    #[arg(long, value_name = "M", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("Robot radius in metres", defaults().robot.radius))]
    pub radius: Option<f64>,
    /// The scans done so far, this one included (counted from 1): the round
    /// after scan N draws the random choices `explore` draws after its scan N.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = parse_scan)]
    pub scan: usize,
    /// The gain estimate's scale for this round (`parent.gain_scale`); to repeat
    /// an `explore` round, its step record's `gain_scale`.
    #[arg(long, value_name = "F", allow_hyphen_values = true, value_parser = parse_real,
          help = with_default("The gain estimate's scale for this round (parent.gain_scale; to repeat an \
                               explore round, its step record's gain_scale)", defaults().parent.gain_scale))]
    pub gain_scale: Option<f64>,
    /// TOML file with any parameters (`cpsplan config` prints every key with
    /// its default).
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

/// Plans the step and prints it; with `--figure`, draws it too. The figure
/// is moved into place only once the plan has been printed.
pub fn run(args: &PlanArgs) -> Result<()> {
    let file = read_config(args.config.as_deref())?;
    let mut config = file.config.clone();
    if file.sets("children.count") && config.children.count != args.children.len() {
        bail!(
            "the config file sets children.count = {}, but {} --child position{} given; \
             give one --child per child or remove children.count from the file",
            config.children.count,
            args.children.len(),
            if args.children.len() == 1 {
                " is"
            } else {
                "s are"
            }
        );
    }
    if let Some(n) = args.count.filter(|&n| n != args.children.len()) {
        bail!(
            "--children {n}, but {} --child position{} given; give one --child X,Y per child \
             (--children 0: the parent alone, no --child)",
            args.children.len(),
            if args.children.len() == 1 {
                " is"
            } else {
                "s are"
            }
        );
    }
    config.children.count = args.children.len();
    if let Some(p) = args.preset {
        p.apply(&mut config, |k| file.sets(k));
    }
    if let Some(r) = args.resolution {
        config.resolution = r;
    }
    if let Some(s) = args.seed {
        config.seed = s;
    }
    if let Some(r) = args.range {
        config.scanner.range = r;
    }
    if let Some(r) = args.radius {
        config.robot.radius = r;
    }
    if let Some(g) = args.gain_scale {
        config.parent.gain_scale = g;
    }
    if let Some(p) = args.planner {
        config.parent.planner = p;
    }
    if let Some(s) = args.child_strategy {
        config.children.strategy = s;
    }
    if let Some(m) = args.instrument {
        config.instrument.model = m;
    }
    if config.parent.planner == cpsplan::config::Planner::Oracle {
        bail!(
            "the oracle planner knows what each scan would reveal from the ground truth: \
             it is a yardstick for simulated episodes (`explore`, experiments), not a plan for a real team"
        );
    }
    validate(
        &config,
        &[
            ("resolution", "--resolution", args.resolution.is_some()),
            ("scanner.range", "--range", args.range.is_some()),
            ("robot.radius", "--radius", args.radius.is_some()),
            (
                "parent.gain_scale",
                "--gain-scale",
                args.gain_scale.is_some(),
            ),
            ("children.count", "--child", true),
        ],
    )?;
    let known = load_planning_grid(&args.known, &config)?;
    let step =
        cpsplan::mission::plan_step_after(&known, args.parent, &args.children, &config, args.scan)?;
    let figure = match &args.figure {
        Some(path) => {
            let view = StepView::planned(&step, args.parent, &args.children);
            let name = args.known.file_name().map_or_else(
                || args.known.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            let title = format!("cpsplan plan \u{2014} {name}");
            let png = render_step(&known, &view, &config, &title)?;
            Some((path, write_temp(path, &png)?))
        }
        None => None,
    };
    let mut out = to_json_tidy(&step)?;
    out.push(b'\n');
    let printed = std::io::stdout()
        .write_all(&out)
        .and_then(|()| std::io::stdout().flush())
        .context("cannot write the plan");
    match (printed, figure) {
        (Ok(()), Some((path, tmp))) => tmp.persist(path),
        (Ok(()), None) => Ok(()),
        (Err(e), _) => Err(e),
    }
}
