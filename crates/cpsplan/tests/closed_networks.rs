//! Closed CPS networks in whole episodes: targets the team leaves, given control
//! points, the records they leave, the smoothed figures against the filtering
//! ones, and planning to a tolerance.

use cpsplan::accuracy::{Chain, Instrument, Model, TargetPoint};
use cpsplan::config::{TargetKind, TargetPlacement, TargetSpec};
use cpsplan::mission::{Episode, TargetOrigin};
use cpsplan::sensing::target_in_sight;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, Config};

fn run(map: BuiltinMap, config: &Config) -> Episode {
    run_episode(
        &map.generate(config.seed),
        map.default_start(),
        config,
        |_| {},
    )
    .expect("a valid configuration runs")
}

/// The scenario these tests were written on: the paper's choices (Eq. 1
/// greedy, Eq. 2 balanced), whose route runs along the site's southern street
/// and whose open chain grows fastest.
fn paper_route() -> Config {
    let mut c = Config::default();
    c.parent.planner = cpsplan::config::Planner::Paper;
    c.parent.viewpoints = false;
    c.children.strategy = cpsplan::config::ChildStrategy::Balanced;
    c
}

fn with_targets(max: usize) -> Config {
    let mut c = paper_route();
    c.targets.place = TargetPlacement::Auto;
    c.targets.max = max;
    c
}

/// Every smoothed σ at most the filtering one, and equal for the last scan
/// (nothing after it refines it).
fn smoothed_never_exceeds_filtering(e: &Episode) {
    for s in &e.steps {
        let (f, sm) = (s.position_sigma_m.unwrap(), s.smoothed_sigma_m.unwrap());
        assert!(sm <= f, "scan {}: smoothed {sm} > filtering {f}", s.scan);
    }
    let last = e.steps.last().unwrap();
    let (f, sm) = (
        last.position_sigma_m.unwrap(),
        last.smoothed_sigma_m.unwrap(),
    );
    assert!((f - sm).abs() <= 1e-5 * f, "last scan: {sm} against {f}");
}

/// The recorded network replayed through a fresh chain gives the recorded
/// filtering σ of every scan: the records hold every measurement the planner
/// counted, targets included.
fn records_replay(e: &Episode) {
    let model = Model::new(Instrument::from_config(&e.config.instrument));
    let mut chain = Chain::new(model, e.start, e.config.children.count);
    for t in e
        .targets
        .iter()
        .filter(|t| t.origin != TargetOrigin::Placed)
    {
        chain.add_target(TargetPoint {
            position: t.position,
            z: None,
            control_sigma: t.sigma_mm.map(|s| s * 1e-3),
        });
    }
    chain.sight_here(&e.steps[0].targets).unwrap();
    for (k, s) in e.steps.iter().enumerate().take(e.steps.len() - 1) {
        for c in &s.movement.cycles {
            let here: Vec<usize> = c
                .left_targets
                .iter()
                .map(|l| {
                    let t = chain.add_target(TargetPoint::free(l.position));
                    assert_eq!(t, l.target, "placed targets are numbered in order");
                    t
                })
                .collect();
            chain.sight_here(&here).unwrap();
            let kids: Vec<_> = c.children.iter().map(|k| k.to).collect();
            let moved: Vec<_> = c.children.iter().map(|k| !k.stays).collect();
            chain
                .cycle_sighting(c.parent_to, &kids, &moved, &c.targets)
                .unwrap();
        }
        let next = &e.steps[k + 1];
        let sigma = chain.pose().position_sigma();
        let recorded = next.position_sigma_m.unwrap();
        assert!(
            (sigma - recorded).abs() <= 1e-12 * recorded.max(1e-9),
            "scan {}: replay {sigma} against {recorded}",
            next.scan
        );
    }
}

#[test]
fn targets_left_by_the_team_close_the_network() {
    let open = run(BuiltinMap::Site, &paper_route());
    let closed = run(BuiltinMap::Site, &with_targets(30));
    let s = &closed.summary;
    assert!(s.targets_placed >= 1 && s.targets_placed <= 30);
    assert_eq!(
        s.targets_placed,
        closed
            .targets
            .iter()
            .filter(|t| t.origin == TargetOrigin::Placed)
            .count()
    );
    assert!(s.closures >= 1, "{s:?}");
    // Every placement says why, and every target was measured.
    for t in &closed.targets {
        assert!(t.reason.as_deref().is_some_and(|r| !r.is_empty()), "{t:?}");
        assert!(t.measurements >= 1 && t.smoothed_sigma_m.is_some());
    }
    // Every measurement to a target was in range and in certain line of sight
    // on the knowledge map (known free space only grows).
    let k = closed.knowledge.as_ref().unwrap();
    let g = k.geometry();
    let rule = cpsplan::children::target_rule(&closed.config);
    for c in closed.steps.iter().flat_map(|s| &s.movement.cycles) {
        let at = g.world_to_cell(c.parent_to).unwrap();
        for &t in &c.targets {
            assert!(target_in_sight(k, at, closed.targets[t].position, &rule));
        }
    }
    smoothed_never_exceeds_filtering(&open);
    smoothed_never_exceeds_filtering(&closed);
    records_replay(&closed);
    // The closures bound what the open chain lets grow.
    let worst = |e: &Episode| e.summary.worst_smoothed_sigma_m.unwrap();
    assert!(
        worst(&closed) < 0.5 * worst(&open),
        "{} against {}",
        worst(&closed),
        worst(&open)
    );
}

#[test]
fn control_points_hold_a_chain_to_its_coordinates() {
    // Three control points along the site's southern street, known to 5 mm.
    let mut config = paper_route();
    config.children.strategy = cpsplan::config::ChildStrategy::MinError;
    config.mission.max_scans = 12;
    let open = run(BuiltinMap::Site, &config);
    for (i, (x, y)) in [(20.0, 3.0), (45.0, 4.0), (70.0, 4.0)]
        .into_iter()
        .enumerate()
    {
        config.targets.points.push(TargetSpec {
            name: Some(format!("C{}", i + 1)),
            x,
            y,
            z: None,
            kind: TargetKind::Control,
            sigma_mm: Some(5.0),
        });
    }
    let held = run(BuiltinMap::Site, &config);
    assert_eq!(held.targets.len(), 3);
    assert!(held
        .targets
        .iter()
        .all(|t| t.origin == TargetOrigin::Control));
    let measured: usize = held.targets.iter().map(|t| t.measurements).sum();
    assert!(measured >= 2, "{:?}", held.targets);
    assert!(held.summary.closures >= 1);
    smoothed_never_exceeds_filtering(&held);
    records_replay(&held);
    // A control point measured again pulls the station to its coordinates: no
    // scan that measured one is worse than 5 mm plus the open chain's σ there.
    for (a, b) in held.steps.iter().zip(&open.steps) {
        if !a.targets.is_empty() && a.position == b.position {
            assert!(a.position_sigma_m.unwrap() <= b.position_sigma_m.unwrap() + 5e-3);
        }
    }
}

#[test]
fn a_tolerance_is_kept_or_its_breaches_are_listed() {
    let mut config = with_targets(30);
    config.mission.max_sigma_m = Some(0.05);
    let e = run(BuiltinMap::Office, &config);
    let over: Vec<usize> = e
        .steps
        .iter()
        .filter(|s| s.position_sigma_m.unwrap() > 0.05)
        .map(|s| s.scan)
        .collect();
    assert_eq!(e.summary.sigma_violations, over);
    // On the office the tolerance holds with the team's targets.
    assert!(over.is_empty(), "{over:?}");
    smoothed_never_exceeds_filtering(&e);
    records_replay(&e);
    // Without a tolerance nothing is listed.
    let free = run(BuiltinMap::Office, &with_targets(30));
    assert!(free.summary.sigma_violations.is_empty());
    assert!(free.summary.worst_position_sigma_m.unwrap() > 0.05);
}

#[test]
fn without_targets_the_open_chain_is_recorded_as_before() {
    let e = run(BuiltinMap::Tunnel, &Config::default());
    assert!(e.targets.is_empty());
    let s = &e.summary;
    assert_eq!((s.targets_placed, s.closures, s.closure_moves), (0, 0, 0));
    assert!(e.steps.iter().all(|s| s.targets.is_empty()));
    smoothed_never_exceeds_filtering(&e);
    records_replay(&e);
    // The records keep no target fields (the JSON of an open chain is the
    // chain's).
    let json = serde_json::to_string(&e).unwrap();
    assert!(!json.contains("\"targets\"") && !json.contains("left_targets"));
}
