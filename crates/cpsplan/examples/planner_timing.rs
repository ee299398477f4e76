//! The parent's planning round with and without viewpoints, paper against
//! tour, on one office state (15 scans of the paper's planner, parent alone):
//! the median of 30 rounds each (docs/PERFORMANCE.md).
//!
//!     cargo run --release -p cpsplan --example planner_timing

use std::time::Instant;

use cpsplan::config::Planner;
use cpsplan::parent::plan_parent;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, Config};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let map = BuiltinMap::Office;
    for scans in [15, 60] {
        let mut state = Config::default();
        state.parent.planner = Planner::Paper;
        state.parent.viewpoints = false;
        state.children.count = 0;
        state.mission.max_scans = scans;
        let episode = run_episode(&map.generate(0), map.default_start(), &state, |_| {})?;
        let knowledge = episode.knowledge.ok_or("no knowledge map")?;
        let parent = episode.steps.last().ok_or("no step")?.cell;
        {
            let frontier = cpsplan::parent::Frontier::new(&knowledge, &state.parent);
            let trav = cpsplan::grid::Traversability::new(&knowledge, state.robot.radius, parent);
            let g = *knowledge.geometry();
            let field = cpsplan::grid::travel::sweep(
                &g,
                &trav.passable,
                &[g.index(parent)],
                cpsplan::grid::UNREACHED,
            );
            let valid = |i: usize| trav.traversable[i] && field.reached(i);
            let cost = |i: usize| field.metres(i).unwrap_or(f64::INFINITY);
            let mut times: Vec<f64> = (0..30)
                .map(|_| {
                    let t = Instant::now();
                    let v = cpsplan::parent::viewpoints(
                        &knowledge,
                        frontier.significant(),
                        state.range_cells(),
                        valid,
                        cost,
                    );
                    std::hint::black_box(v);
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            times.sort_by(f64::total_cmp);
            println!(
                "office after {scans} scans: viewpoints alone {:.2} ms",
                times[15]
            );
        }
        for (planner, viewpoints) in [
            (Planner::Paper, false),
            (Planner::Paper, true),
            (Planner::Tour, false),
            (Planner::Tour, true),
        ] {
            let mut config = state.clone();
            config.parent.planner = planner;
            config.parent.viewpoints = viewpoints;
            let mut times: Vec<f64> = (0..30)
                .map(|_| {
                    let mut rng = ChaCha8Rng::seed_from_u64(7);
                    let t = Instant::now();
                    let plan = plan_parent(&knowledge, parent, &config, &mut rng);
                    std::hint::black_box(plan);
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            times.sort_by(f64::total_cmp);
            println!(
                "office after {scans} scans: {} viewpoints {}: {:.2} ms",
                planner.name(),
                if viewpoints { "on" } else { "off" },
                times[15]
            );
        }
    }
    Ok(())
}
