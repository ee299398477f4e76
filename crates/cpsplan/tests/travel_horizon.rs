//! `parent.horizon`: a round weighs only the candidates within the horizon's
//! travel and plans the whole known map only when none of them is worth a scan.
//! Read from an episode's plans: the candidates a round found worth a scan lie
//! all within the horizon or, when it planned the whole map, all beyond it.

use cpsplan::parent::{CandidateOrigin, Decision};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode_with, Config};

/// Rounds of an episode on `map` with the horizon `h` metres: (bounded,
/// whole-map) rounds and the episode's coverage.
fn rounds(map: BuiltinMap, h: f64) -> (usize, usize, f64) {
    let mut config = Config::default();
    config.children.count = 0;
    config.parent.horizon = h;
    let truth = map.generate(0);
    // The costs' rounding to whole units of the sweep, in metres, with room.
    let slack = config.resolution;
    let (mut bounded, mut whole) = (0, 0);
    let episode = run_episode_with(&truth, map.default_start(), &config, |step, _| {
        let plan = &step.plan;
        let Decision::Target { index } = plan.decision else {
            return;
        };
        // The candidates found worth a scan, but the chosen one (it may have
        // climbed since) and a fallback (found only over the whole map).
        let worth: Vec<f64> = plan
            .candidates
            .iter()
            .enumerate()
            .filter(|&(i, c)| i != index && c.eligible && c.origin != CandidateOrigin::Fallback)
            .map(|(_, c)| c.l_m.expect("a candidate worth a scan is reached"))
            .collect();
        let within = worth.iter().filter(|&&l| l <= h + slack).count();
        if within > 0 {
            bounded += 1;
            assert_eq!(
                within,
                worth.len(),
                "scan {}: worth a scan within and beyond the {h} m horizon: {worth:?}",
                step.scan
            );
            let l = plan.candidates[index].l_m.expect("the target is reached");
            assert!(l <= 2.0 * h + slack, "scan {}: target at {l} m", step.scan);
        } else if plan
            .candidates
            .iter()
            .any(|c| c.l_m.is_some_and(|l| l > 2.0 * h + slack))
        {
            // Beyond the bounded sweep: a round over the whole map.
            whole += 1;
        }
    })
    .expect("the episode runs");
    (bounded, whole, episode.summary.coverage)
}

#[test]
fn a_round_chooses_within_the_horizon_or_finds_nothing_there() {
    let (bounded, whole, coverage) = rounds(BuiltinMap::Site, 10.0);
    assert!(bounded >= 5, "{bounded} rounds within the horizon");
    assert!(whole >= 1, "{whole} rounds over the whole map");
    assert!(coverage >= 0.99, "coverage {coverage}");
}

#[test]
fn without_a_horizon_every_round_weighs_the_whole_map() {
    let mut config = Config::default();
    config.children.count = 0;
    let map = BuiltinMap::Office;
    let truth = map.generate(0);
    let mut far = 0;
    run_episode_with(&truth, map.default_start(), &config, |step, _| {
        if step
            .plan
            .candidates
            .iter()
            .any(|c| c.l_m.is_some_and(|l| l > 20.0))
        {
            far += 1;
        }
    })
    .expect("the episode runs");
    assert!(far > 10, "{far} rounds reached candidates beyond 20 m");
}
