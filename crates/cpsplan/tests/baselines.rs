//! The baseline planners (`parent.planner = "frontier"` and `"gain"`): at every
//! step of episodes on the built-in maps they choose what their rule says, and
//! they explore the maps to the end.

use cpsplan::config::Planner;
use cpsplan::parent::{frontier_goals, CandidateOrigin, Decision};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode_with, Config};

fn config(planner: Planner) -> Config {
    let mut c = Config::default();
    c.children.count = 0;
    c.parent.planner = planner;
    c
}

#[test]
fn the_frontier_baseline_takes_the_cheapest_frontier_worth_a_scan() {
    for map in BuiltinMap::ALL {
        let truth = map.generate(0);
        let config = config(Planner::Frontier);
        let mut targets = 0;
        let episode = run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
            let plan = &step.plan;
            let Decision::Target { index } = plan.decision else {
                return;
            };
            targets += 1;
            let goals = frontier_goals(knowledge, step.cell, &config.parent);
            let g = knowledge.geometry();
            // The candidates are explore_lite's frontiers in cost order (each at
            // the drivable cell nearest its centroid; a frontier whose cell
            // another took is left out), then at most the fallback.
            let mut next = 0;
            for c in &plan.candidates {
                if c.origin == CandidateOrigin::Fallback {
                    continue;
                }
                assert_eq!(
                    c.origin,
                    CandidateOrigin::Frontier,
                    "{map:?} scan {}",
                    step.scan
                );
                let k = goals[next..]
                    .iter()
                    .position(|f| {
                        let p = g.grid_to_world(
                            f.centroid[0] * g.resolution,
                            f.centroid[1] * g.resolution,
                        );
                        p == c.centroid && f.cells == c.cluster_size
                    })
                    .unwrap_or_else(|| {
                        panic!(
                            "{map:?} scan {}: candidate {:?} is no frontier",
                            step.scan, c.cell
                        )
                    });
                next += k + 1;
            }
            // The first one worth a scan is taken.
            let first = plan.candidates.iter().position(|c| c.eligible);
            assert_eq!(first, Some(index), "{map:?} scan {}", step.scan);
        })
        .expect("the episode runs");
        assert!(targets >= 10, "{map:?}: {targets} targets");
        assert!(
            episode.summary.coverage >= 0.99,
            "{map:?}: coverage {}",
            episode.summary.coverage
        );
    }
}

#[test]
fn the_gain_baseline_takes_the_candidate_that_sees_most() {
    for map in BuiltinMap::ALL {
        let truth = map.generate(0);
        let config = config(Planner::Gain);
        let mut farther = 0;
        let episode = run_episode_with(&truth, map.default_start(), &config, |step, _| {
            let plan = &step.plan;
            let Some(t) = plan.target() else { return };
            let most = plan
                .candidates
                .iter()
                .filter(|c| c.eligible)
                .map(|c| c.s_cells)
                .max();
            assert_eq!(Some(t.s_cells), most, "{map:?} scan {}", step.scan);
            let nearest = plan
                .candidates
                .iter()
                .filter(|c| c.eligible)
                .filter_map(|c| c.l_m)
                .fold(f64::INFINITY, f64::min);
            if t.l_m.is_some_and(|l| l > nearest) {
                farther += 1;
            }
        })
        .expect("the episode runs");
        assert!(farther > 0, "{map:?}: distance never gave way to gain");
        assert!(
            episode.summary.coverage >= 0.99,
            "{map:?}: coverage {}",
            episode.summary.coverage
        );
    }
}

/// The oracle takes, at every step, the eligible candidate of most true gain per
/// unit of campaign time, its true gain the new free area a scan there does
/// reveal: checked against the next scan's outcome.
#[test]
fn the_oracle_takes_the_most_true_gain_per_unit_of_time_and_sees_what_it_expects() {
    use cpsplan::parent::oracle_rate;
    for map in BuiltinMap::ALL {
        let truth = map.generate(0);
        let config = config(Planner::Oracle);
        let mut expected: Option<f64> = None;
        let mut checked = 0;
        let episode = run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
            let res = knowledge.geometry().resolution;
            if let Some(e) = expected.take() {
                let actual = step.outcome.new_free as f64 * res * res;
                assert!(
                    (e - actual).abs() < 1e-9,
                    "{map:?} scan {}: {e} against {actual}",
                    step.scan
                );
                checked += 1;
            }
            let plan = &step.plan;
            let Some(t) = plan.target() else { return };
            let rate = |c: &cpsplan::parent::Candidate| {
                oracle_rate(c.true_gain_m2.unwrap(), c.l_m.unwrap(), &config)
            };
            let best = plan
                .candidates
                .iter()
                .filter(|c| c.eligible)
                .map(rate)
                .fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(rate(t), best, "{map:?} scan {}", step.scan);
            assert_eq!(t.oracle_rate, Some(best));
            expected = t.true_gain_m2;
        })
        .expect("the episode runs");
        assert!(checked >= 10, "{map:?}: {checked} scans checked");
        assert!(
            episode.summary.coverage >= 0.99,
            "{map:?}: coverage {}",
            episode.summary.coverage
        );
    }
}

/// With children, each move goes to the planner's own choice (the first of its
/// order of preference) unless no CPS move reaches it: the team scans where the
/// planner alone would.
#[test]
fn the_team_moves_to_each_planner_s_choice() {
    let truth = BuiltinMap::Site.generate(0);
    for planner in Planner::ALL {
        let mut team = config(planner);
        team.children.count = 2;
        team.mission.max_scans = 14;
        let mut alone = team.clone();
        alone.children.count = 0;
        // The oracle's rate counts a scan as the driving it would buy, which
        // the team shares among its robots: the same exchange rate alone.
        alone.time.scan_s = team.time.scan_s / 3.0;
        let mut moves = 0;
        let with = run_episode_with(
            &truth,
            BuiltinMap::Site.default_start(),
            &team,
            |step, _| {
                let plan = &step.plan;
                let Decision::Target { index } = plan.decision else {
                    return;
                };
                let order = plan.preference(planner);
                assert_eq!(
                    order.first(),
                    Some(&index),
                    "{planner:?} scan {}",
                    step.scan
                );
                if step.movement.rejected.is_empty() && !step.movement.cycles.is_empty() {
                    assert_eq!(
                        step.movement.target,
                        Some(index),
                        "{planner:?} scan {}",
                        step.scan
                    );
                    moves += 1;
                }
            },
        )
        .expect("the episode runs");
        assert!(moves >= 5, "{planner:?}: {moves} moves");
        let without = run_episode_with(&truth, BuiltinMap::Site.default_start(), &alone, |_, _| {})
            .expect("the episode runs");
        if with.steps.iter().all(|s| s.movement.rejected.is_empty()) {
            let cells = |e: &cpsplan::Episode| e.steps.iter().map(|s| s.cell).collect::<Vec<_>>();
            assert_eq!(
                cells(&with),
                cells(&without),
                "{planner:?}: the same scan positions"
            );
        }
    }
}
