//! `parent.travel_jitter`: every candidate's `L` in an episode's plans lies within
//! the stated bound above the exact travel distance (a sweep of its own from the
//! step's position), off it by a spread of factors, and exactly on it without
//! the jitter.

use cpsplan::grid::travel::{sweep, UNREACHED};
use cpsplan::grid::traversability::Traversability;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode_with, Config};

/// Per candidate with a finite `L`: `L` over the exact travel distance.
fn ratios(map: BuiltinMap, jitter: f64) -> (Vec<f64>, f64) {
    let mut config = Config::default();
    config.children.count = 0;
    config.parent.travel_jitter = jitter;
    let truth = map.generate(0);
    let mut out = Vec::new();
    let episode = run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
        let g = knowledge.geometry();
        let trav = Traversability::new(knowledge, config.robot.radius, step.cell);
        let field = sweep(g, &trav.passable, &[g.index(step.cell)], UNREACHED);
        for c in &step.plan.candidates {
            let (Some(l), Some(exact)) = (c.l_m, field.metres(g.index(c.cell))) else {
                continue;
            };
            if exact > 0.0 {
                out.push(l / exact);
            }
        }
    })
    .expect("the episode runs");
    (out, episode.summary.coverage)
}

#[test]
fn the_jittered_travel_lies_within_its_bound_above_the_exact_one() {
    let (exact, _) = ratios(BuiltinMap::Site, 0.0);
    assert!(exact.len() > 50, "{} candidates", exact.len());
    assert!(exact.iter().all(|&r| r == 1.0), "exact L is the sweep's");

    let (jittered, coverage) = ratios(BuiltinMap::Site, 0.05);
    assert!(jittered.len() > 50, "{} candidates", jittered.len());
    for &r in &jittered {
        // Up to the division's rounding.
        assert!((1.0 - 1e-6..=1.05 + 1e-6).contains(&r), "ratio {r}");
    }
    // Spread over the bound: some near each end.
    assert!(jittered.iter().any(|&r| r < 1.01));
    assert!(jittered.iter().any(|&r| r > 1.04));
    assert!(coverage >= 0.99, "coverage {coverage}");
}
