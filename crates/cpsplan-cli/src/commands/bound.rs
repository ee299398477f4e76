//! `cpsplan bound`: the known-map yardstick of a map (greedy set cover and LP
//! lower bound), as JSON and a picture.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{anyhow, Result};
use clap::Args;
use cpsplan::bound::{known_map_bound, BoundError, BoundParams, KnownMapBound};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::Point;
use serde::Serialize;

use super::{load_truth, read_config, validate};
use crate::args::{defaults, parse_point, parse_real, with_default};
use crate::formats::tidy::to_json_tidy;
use crate::memory::memory_budget;
use crate::render::render_bound;
use crate::report::{write_atomic, MapSource, ReportDir};

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
    /// TOML file with any parameters of the run (`cpsplan config` prints every
    /// key with its default).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Output directory: bound.json and bound.png.
    #[arg(long, value_name = "DIR", default_value = "bound")]
    pub out: PathBuf,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// `bound.json`: the bound and what it was computed on.
#[derive(Debug, Serialize)]
struct BoundReport<'a> {
    /// The map (file path or `builtin:NAME`).
    map: String,
    /// Wall-clock time, milliseconds.
    wall_ms: f64,
    #[serde(flatten)]
    bound: &'a KnownMapBound,
}

/// Computes the bound and writes `bound.json` and `bound.png` into `--out`.
pub fn run(args: &BoundArgs) -> Result<()> {
    let mut config = read_config(args.config.as_deref())?.config;
    if let Some(r) = args.range {
        config.scanner.range = r;
    }
    if let Some(r) = args.resolution {
        config.resolution = r;
    }
    if let Some(r) = args.radius {
        config.robot.radius = r;
    }
    validate(
        &config,
        &[
            ("scanner.range", "--range", args.range.is_some()),
            ("resolution", "--resolution", args.resolution.is_some()),
            ("robot.radius", "--radius", args.radius.is_some()),
        ],
    )?;
    let report = ReportDir::create(&args.out)?;
    let (truth, source, start) =
        load_truth(args.map.as_deref(), args.builtin, args.start, &config)?;
    let params = BoundParams {
        spacing_m: args.spacing,
        target_spacing_m: args.target_spacing,
    };
    let t0 = Instant::now();
    let available = memory_budget().map(|b| (b.mb, b.source));
    let bound =
        known_map_bound(&truth, start, &config, params, available).map_err(|e| match e {
            BoundError::Start(e) => anyhow!("--start: {e}"),
            e => anyhow!(e),
        })?;
    let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    let label = source.label();
    let json = to_json_tidy(&BoundReport {
        map: match &source {
            MapSource::File(p) => p.display().to_string(),
            MapSource::Builtin(m) => format!("builtin:{}", m.name()),
        },
        wall_ms,
        bound: &bound,
    })?;
    write_atomic(&report.path().join("bound.json"), &json)?;
    let png = render_bound(&truth, &bound, &format!("cpsplan bound \u{2014} {label}"))
        .map_err(|e| anyhow!("cannot draw bound.png: {e}"))?;
    write_atomic(&report.path().join("bound.png"), &png)?;
    report.commit()?;
    if !args.quiet {
        println!(
            "{label}: {} candidate stations ({} lattice at {} m, {} at corners), {} of {} targets coverable, {:.1} s",
            bound.lattice_stations + bound.corner_stations,
            bound.lattice_stations,
            bound.spacing_m,
            bound.corner_stations,
            bound.coverable_targets,
            bound.targets,
            wall_ms / 1e3
        );
        println!("coverage  greedy stations  lower bound");
        for l in &bound.levels {
            println!(
                "{:>7.0} %  {:>15}  {:>11} ({:.2})",
                100.0 * l.share,
                l.greedy_stations,
                l.lower_bound_stations,
                l.lower_bound
            );
        }
        println!("wrote {}/bound.json and bound.png", args.out.display());
    }
    Ok(())
}
