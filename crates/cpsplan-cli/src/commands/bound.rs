//! `cpsplan bound`: the known-map yardstick of a map (greedy set cover and LP
//! lower bound), as JSON and a picture.

use std::time::Instant;

use anyhow::{anyhow, Result};
use cpsplan::bound::{known_map_bound, BoundError, BoundParams, KnownMapBound};
use serde::Serialize;

use super::{load_truth, read_config, validate};
use crate::cli::BoundArgs;
use crate::render::render_bound;
use crate::report::{MapSource, ReportDir};

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
    let bound = known_map_bound(&truth, start, &config, params).map_err(|e| match e {
        BoundError::Start(e) => anyhow!("--start: {e}"),
        e => anyhow!(e),
    })?;
    let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    let label = source.label();
    let json = serde_json::to_vec_pretty(&BoundReport {
        map: match &source {
            MapSource::File(p) => p.display().to_string(),
            MapSource::Builtin(m) => format!("builtin:{}", m.name()),
        },
        wall_ms,
        bound: &bound,
    })?;
    std::fs::write(report.path().join("bound.json"), json)?;
    let png = render_bound(&truth, &bound, &format!("cpsplan bound \u{2014} {label}"))
        .map_err(|e| anyhow!("cannot draw bound.png: {e}"))?;
    std::fs::write(report.path().join("bound.png"), png)?;
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
