//! The readings a real team's total station would have recorded in a simulated
//! campaign, scan by scan, with the instrument's noise (docs/USER-GUIDE.md
//! "Field data"): the same noisy values the episode's own estimates come from
//! (the first Monte Carlo run of its seed), so that adjusting them gives the
//! episode's poses back.
//!
//! In: an [`Episode`]. Out: per scan, the [`Reading`]s taken since the scan
//! before (the first scan: the start's own), named as a survey would name them:
//! - stations `S0000`, `S0001`, … in the order the parent set up (`S0000` is
//!   the start, the datum; a move of several CPS cycles sets up at each
//!   subgoal);
//! - a child's points `C<child>.<n>`: child 1's third spot is `C1.0003`;
//! - targets and control points by their names in the episode (`P<n>` for the
//!   team's own; `T<n>` where a name is not one a survey could exchange,
//!   [`Reading::valid_name`]).

use super::episode::Episode;
use crate::accuracy::{
    realisation, CycleGeometry, Event, Instrument, Model, NetworkGeometry, Reading, Role, Script,
    TargetPoint,
};

/// The network of `episode` as its records give it, and the number of cycles of
/// the move that followed each scan but the last (the move planned after the
/// last scan leads to no scan, and is left out).
pub fn network_of(episode: &Episode) -> (NetworkGeometry, Vec<usize>) {
    let given = &episode.config.targets.points;
    let targets = episode
        .targets
        .iter()
        .enumerate()
        .map(|(i, t)| TargetPoint {
            position: t.position,
            z: given.get(i).and_then(|p| p.z),
            control_sigma: t.sigma_mm.map(|mm| mm * 1e-3),
        })
        .collect();
    let mut cycles = Vec::new();
    let mut per_scan = Vec::with_capacity(episode.steps.len());
    let moves = episode.steps.len().saturating_sub(1);
    for step in &episode.steps[..moves] {
        per_scan.push(step.movement.cycles.len());
        for c in &step.movement.cycles {
            cycles.push(CycleGeometry {
                to: c.parent_to,
                children: c.children.iter().map(|k| k.to).collect(),
                moved: c.children.iter().map(|k| !k.stays).collect(),
                here: c.left_targets.iter().map(|l| l.target).collect(),
                sighted: c.targets.clone(),
            });
        }
    }
    let at_start = episode
        .steps
        .first()
        .map(|s| s.targets.clone())
        .unwrap_or_default();
    let net = NetworkGeometry {
        start: episode.start,
        targets,
        at_start,
        cycles,
    };
    (net, per_scan)
}

/// The readings of `episode`, scan by scan (see the module); `None` when the
/// team could not fix the parent's pose (fewer than two children) or the
/// network cannot be simulated.
pub fn field_readings(episode: &Episode) -> Option<Vec<Vec<Reading>>> {
    let config = &episode.config;
    if config.children.count < 2 || episode.steps.is_empty() {
        return None;
    }
    let model = Model::new(Instrument::from_config(&config.instrument));
    let (net, per_scan) = network_of(episode);
    let script = Script::of(model, &net);
    let values = realisation(&model, &net, config.seed, 0, false)
        .ok()?
        .readings;
    let names = names(&script, episode);
    // The scan each cycle's readings lead to: the moves after scans 0, 1, …
    // reach scans 1, 2, ….
    let mut scan_of_cycle = Vec::with_capacity(net.cycles.len());
    for (scan, &n) in per_scan.iter().enumerate() {
        scan_of_cycle.extend(std::iter::repeat_n(scan + 1, n));
    }
    let starts = script.cycle_starts();
    let mut out: Vec<Vec<Reading>> = vec![Vec::new(); episode.steps.len()];
    let mut value = values.iter();
    for (i, e) in script.events().iter().enumerate() {
        let Event::Observe { station, point } = *e else {
            continue;
        };
        let z = value.next()?;
        // The cycle this event belongs to (none before the first).
        let scan = match starts.partition_point(|&s| s <= i).checked_sub(1) {
            None => 0,
            Some(c) => *scan_of_cycle.get(c)?,
        };
        out.get_mut(scan)?.push(Reading::from_observation(
            &names[station],
            &names[point],
            &model,
            z.as_slice(),
        ));
    }
    Some(out)
}

/// The name of every unknown of `script` (the module's rules).
fn names(script: &Script, episode: &Episode) -> Vec<String> {
    let mut spots = vec![0usize; episode.config.children.count];
    script
        .vars()
        .iter()
        .map(|v| match v.role {
            Role::Station(k) => format!("S{k:04}"),
            Role::Child(i) => {
                if let Some(n) = spots.get_mut(i) {
                    *n += 1;
                }
                format!("C{}.{:04}", i + 1, spots.get(i).copied().unwrap_or(0))
            }
            Role::Target(t) => episode
                .targets
                .get(t)
                .map(|r| r.name.as_str())
                .filter(|n| Reading::valid_name(n))
                .map_or_else(|| format!("T{}", t + 1), str::to_string),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::{adjust_readings, reading_name, BLUNDER_SIGMAS};
    use crate::geom::Point;
    use crate::world::builtin::BuiltinMap;
    use crate::{run_episode, Config};

    /// Where the station named `name` stands in `episode`'s network ([`network_of`];
    /// `S0000` the start), if it is one.
    fn station_position(episode: &Episode, name: &str) -> Option<Point> {
        let k: usize = name.strip_prefix('S')?.parse().ok()?;
        if k == 0 {
            return Some(episode.start);
        }
        episode
            .steps
            .iter()
            .flat_map(|s| &s.movement.cycles)
            .nth(k - 1)
            .map(|c| c.parent_to)
    }

    fn episode(monte_carlo_runs: usize, targets: usize) -> Episode {
        let map = BuiltinMap::Site;
        let mut config = Config::default();
        config.mission.max_scans = 8;
        config.accuracy.monte_carlo_runs = monte_carlo_runs;
        if targets > 0 {
            config.targets.place = crate::config::TargetPlacement::Auto;
            config.targets.max = targets;
        }
        run_episode(&map.generate(0), map.default_start(), &config, |_| {}).unwrap()
    }

    /// Resecting each scan station from its readings with the stations and
    /// points before it as the readings place them gives the episode's own
    /// filtering estimate: the field data are the values the episode used.
    #[test]
    fn the_readings_are_the_values_the_episode_estimated_from() {
        for targets in [0, 6] {
            readings_match_the_episode(&episode(1, targets), targets);
        }
    }

    fn readings_match_the_episode(e: &Episode, targets: usize) {
        let e = e.clone();
        let readings = field_readings(&e).expect("readings");
        assert_eq!(readings.len(), e.steps.len());
        let model = Model::new(Instrument::from_config(&e.config.instrument));
        // Every reading lies within a few σ of the truth it stands for.
        let (net, _) = network_of(&e);
        let script = Script::of(model, &net);
        let mut truth = std::collections::HashMap::new();
        for (name, v) in names(&script, &e).into_iter().zip(script.vars()) {
            truth.insert(name, v.truth.clone());
        }
        let mut count = 0;
        for r in readings.iter().flatten() {
            let (s, p) = (&truth[&r.station], &truth[&r.point]);
            let z = model.observe(s.as_slice(), p.as_slice());
            let got = r.observation(&model);
            let noise = model.noise(s.as_slice(), p.as_slice());
            let d = (got[0] - z[0]) / noise[(0, 0)].sqrt();
            let turn = (got[1] - z[1]).rem_euclid(std::f64::consts::TAU);
            let a = turn.min(std::f64::consts::TAU - turn) / noise[(1, 1)].sqrt();
            assert!(d.abs() < 6.0 && a < 6.0, "{r:?}: {d} σ, {a} σ");
            count += 1;
        }
        assert_eq!(
            count,
            script
                .events()
                .iter()
                .filter(|e| matches!(e, Event::Observe { .. }))
                .count()
        );
        let to_targets = readings
            .iter()
            .flatten()
            .filter(|r| !r.point.starts_with('C'));
        assert_eq!(to_targets.count() > 0, targets > 0);
        // Scan 0 has the start's own readings only; every later scan's file
        // ends with its own station's.
        assert!(readings[0].iter().all(|r| r.station == "S0000"));
        for (k, rs) in readings.iter().enumerate().skip(1) {
            let last = rs.last().expect("a scan station measures its children");
            let at = station_position(&e, &last.station).expect("a station");
            assert!(
                at.distance(e.steps[k].position) < 1e-9,
                "scan {k}: {}",
                last.station
            );
        }
        // The realisation's estimates the episode recorded come from these
        // same values: the same seed, the same network.
        let r = realisation(&model, &net, e.config.seed, 0, false).unwrap();
        let mut cycle = 0;
        for (k, step) in e.steps.iter().enumerate().skip(1) {
            cycle += e.steps[k - 1].movement.cycles.len();
            let est = step.estimate.expect("a Monte Carlo check gives estimates");
            let err = r.filtering[cycle - 1];
            assert!((est.position.x - step.position.x - err[0]).abs() < 1e-12);
            assert!((est.position.y - step.position.y - err[1]).abs() < 1e-12);
        }
    }

    fn datum(e: &Episode) -> crate::accuracy::Datum {
        crate::accuracy::Datum {
            station: "S0000".into(),
            position: e.start,
            heading_rad: 0.0,
        }
    }

    /// Adjusting the readings of the first `k` scans by name alone gives scan
    /// `k`'s station where the episode's own estimate put it (the network is
    /// the same), and all of them together its smoothed estimates.
    #[test]
    fn the_readings_adjusted_by_name_give_the_episodes_estimates() {
        for targets in [0, 6] {
            let e = episode(1, targets);
            let readings = field_readings(&e).expect("readings");
            let model = Model::new(Instrument::from_config(&e.config.instrument));
            let mut all: Vec<Reading> = Vec::new();
            for (k, rs) in readings.iter().enumerate() {
                let from = all.len();
                all.extend(rs.iter().cloned());
                let survey = adjust_readings(model, &datum(&e), &[], &all, from)
                    .expect("the readings fix the network");
                assert!(
                    survey.left_out.is_empty(),
                    "scan {k}: {:?}",
                    survey.left_out
                );
                let Some(last) = rs.last() else { continue };
                let at = survey.get(&last.station).expect("the scan's station");
                let est = e.steps[k].estimate.expect("an estimate");
                assert!(at.position().distance(est.position) < 1e-6, "scan {k}");
            }
            let survey = adjust_readings(model, &datum(&e), &[], &all, 0).unwrap();
            for step in &e.steps[1..] {
                let smoothed = step.smoothed_estimate.expect("smoothed").position;
                let near = survey
                    .stations
                    .iter()
                    .map(|s| s.position().distance(smoothed))
                    .fold(f64::INFINITY, f64::min);
                assert!(near < 1e-7, "scan {}: {near}", step.scan);
            }
        }
    }

    /// A reading 10 cm off in a scan's readings is found and named. In a CPS
    /// cycle every reading is needed to fix the new station (one redundant
    /// reading per cycle), so the add is refused rather than the reading left
    /// out; in the planar model the cycle's readings check only each other and
    /// are all named.
    #[test]
    fn a_reading_ten_centimetres_off_is_named() {
        let e = episode(1, 0);
        for three_d in [false, true] {
            let mut e = e.clone();
            e.config.instrument.three_d = three_d;
            let readings = field_readings(&e).expect("readings");
            let model = Model::new(Instrument::from_config(&e.config.instrument));
            let k = readings.len() - 1;
            let mut all: Vec<Reading> = readings[..k].iter().flatten().cloned().collect();
            let from = all.len();
            all.extend(readings[k].iter().cloned());
            let clean = adjust_readings(model, &datum(&e), &[], &all, from).unwrap();
            assert!(clean.max_standardized < BLUNDER_SIGMAS);
            for bad in from..all.len() {
                let mut off = all.clone();
                off[bad].slope_distance_m += 0.1;
                let err = adjust_readings(model, &datum(&e), &[], &off, from)
                    .expect_err("a 10 cm blunder is found");
                let message = err.to_string();
                assert!(
                    message.contains(&reading_name(&off[bad])),
                    "3D {three_d}: {message}"
                );
            }
        }
    }

    /// With targets in sight a station has readings to spare: the blunder is
    /// left out, named, and the station stays within its σ.
    #[test]
    fn a_blunder_with_readings_to_spare_is_left_out() {
        let e = episode(1, 6);
        let readings = field_readings(&e).expect("readings");
        let model = Model::new(Instrument::from_config(&e.config.instrument));
        let all: Vec<Reading> = readings.iter().flatten().cloned().collect();
        let clean = adjust_readings(model, &datum(&e), &[], &all, 0).unwrap();
        let mut left = 0;
        for bad in 0..all.len() {
            let mut off = all.clone();
            off[bad].slope_distance_m += 0.1;
            if let Ok(s) = adjust_readings(model, &datum(&e), &[], &off, 0) {
                assert_eq!(s.left_out.len(), 1, "{}", reading_name(&off[bad]));
                assert_eq!(s.left_out[0].reading, bad);
                for (a, b) in s.stations.iter().zip(&clean.stations) {
                    assert!(a.position().distance(b.position()) < 3.0 * b.sigma_m().max(1e-4));
                }
                left += 1;
            }
        }
        assert!(left > 0, "some reading has others to check it");
    }

    #[test]
    fn names_follow_the_survey_rules() {
        let e = episode(0, 6);
        let readings = field_readings(&e).expect("readings");
        for r in readings.iter().flatten() {
            assert!(Reading::valid_name(&r.station) && Reading::valid_name(&r.point));
            assert!(r.station.starts_with('S'));
            let target = e.targets.iter().any(|t| t.name == r.point);
            assert!(
                r.point.starts_with("C1.") || r.point.starts_with("C2.") || target,
                "{}",
                r.point
            );
        }
        let mut solo = e.clone();
        solo.config.children.count = 1;
        assert!(field_readings(&solo).is_none());
    }
}
