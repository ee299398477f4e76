//! Times the planning step with children (`mission::plan_step`: Eq. 1, then the
//! CPS cycles with AND regions, Eq. 2 placements, subgoals and Voronoi paths) on
//! every knowledge map of an episode: the episode runs first and keeps each step's
//! map and robot positions, then every step is planned again and timed.
//!
//! `cargo run --release -p cpsplan --example step_timing -- site 0 2`
//! (`VERBOSE=1` prints every step's time; `STRATEGY=min-error` sets the child
//! strategy; `PLANNER=tour` the planner; `PRESET=paper` starts from the paper's
//! choices instead of the defaults).

use std::time::Instant;

use cpsplan::mission::plan_step;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode_with, Config, OccupancyGrid, Point};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let map: BuiltinMap = args.next().unwrap_or_else(|| "site".into()).parse()?;
    let seed: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(0);
    let children: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(2);
    let verbose = std::env::var_os("VERBOSE").is_some();
    let mut config = match std::env::var("PRESET").as_deref() {
        Ok("paper") => Config::preset(cpsplan::config::Preset::Paper),
        Ok(_) => return Err("unknown PRESET (paper)".into()),
        Err(_) => Config::default(),
    };
    config.seed = seed;
    config.children.count = children;
    if let Some(p) = std::env::var_os("PLANNER") {
        config.parent.planner = match p.to_string_lossy().as_ref() {
            "tour" => cpsplan::config::Planner::Tour,
            "paper" => cpsplan::config::Planner::Paper,
            _ => return Err("unknown PLANNER (paper or tour)".into()),
        };
    }
    if let Some(s) = std::env::var_os("STRATEGY") {
        let s = s.to_string_lossy();
        config.children.strategy = cpsplan::config::ChildStrategy::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or("unknown STRATEGY")?;
    }
    let truth = map.generate(seed);
    let mut states: Vec<(OccupancyGrid, Point, Vec<Point>)> = Vec::new();
    let t0 = Instant::now();
    let episode = run_episode_with(&truth, map.default_start(), &config, |step, known| {
        states.push((known.clone(), step.position, step.children.clone()));
    })?;
    let episode_ms = t0.elapsed().as_secs_f64() * 1e3;
    let mut times: Vec<f64> = Vec::with_capacity(states.len());
    let mut retrieved = 0;
    for (known, parent, kids) in &states {
        let t = Instant::now();
        let step = plan_step(known, *parent, kids, &config)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        times.push(ms);
        retrieved += usize::from(step.movement.subgoal_retrieval);
        if verbose {
            eprintln!(
                "step {:3}: {ms:6.1} ms, {} cycles, subgoals {}, {} rejected",
                times.len(),
                step.movement.cycles.len(),
                step.movement.subgoal_retrieval,
                step.movement.rejected.len()
            );
        }
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let pick = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
    println!(
        "{} seed {seed}, {children} children: {} steps ({} with subgoals), episode {:.0} ms",
        map.name(),
        sorted.len(),
        retrieved,
        episode_ms
    );
    println!(
        "planning step: median {:.1} ms, p90 {:.1} ms, max {:.1} ms, mean {:.1} ms",
        pick(0.5),
        pick(0.9),
        pick(1.0),
        times.iter().sum::<f64>() / times.len() as f64
    );
    let _ = episode.summary;
    Ok(())
}
