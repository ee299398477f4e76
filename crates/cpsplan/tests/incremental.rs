//! The state an episode keeps across scans instead of recomputing it gives the
//! planner exactly what a from-scratch computation gives: on every built-in
//! map, at every step, each candidate's gain estimate equals the estimate of
//! the step's knowledge map computed afresh.

use cpsplan::config::Planner;
use cpsplan::sensing::GainEstimate;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode_with, Config};

#[test]
fn kept_gain_field_equals_a_fresh_one_on_the_builtin_maps() {
    for map in BuiltinMap::ALL {
        for planner in [Planner::Paper, Planner::Tour] {
            let truth = map.generate(0);
            let mut config = Config::default();
            config.children.count = 0;
            config.mission.max_scans = 60;
            config.parent.planner = planner;
            let range = config.range_cells();
            let mut checked = 0usize;
            run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
                let mut round = config;
                round.parent.gain_scale = step.gain_scale;
                let fresh = GainEstimate::new(knowledge, &round);
                for c in step.plan.candidates.iter().filter(|c| c.r == 1) {
                    let want = fresh.at(knowledge, c.cell, range);
                    assert_eq!(
                        (c.s_cells, c.gain_m2),
                        (want.s_cells, want.m2),
                        "{map:?} {planner:?} scan {} candidate at {:?}",
                        step.scan,
                        c.cell
                    );
                    checked += 1;
                }
            })
            .expect("the episode runs");
            assert!(
                checked > 50,
                "{map:?} {planner:?}: only {checked} candidates"
            );
        }
    }
}
