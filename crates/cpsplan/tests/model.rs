//! The registered 3D model of a simulated episode against its ground truth: the
//! points lie on the walls exactly without noise, within the range noise's
//! spread with it, and within the pose error's reach when the CPS estimate
//! registers them.

use std::sync::OnceLock;

use cpsplan::model::{build_model, build_model_in, ModelPoint, Registration};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, Config, Episode, OccupancyGrid};

/// The default site with 20 Monte Carlo runs (so every scan has an estimate).
fn episode() -> &'static (OccupancyGrid, Episode) {
    static EP: OnceLock<(OccupancyGrid, Episode)> = OnceLock::new();
    EP.get_or_init(|| {
        let truth = BuiltinMap::Site.generate(0);
        let mut config = Config::default();
        config.accuracy.monte_carlo_runs = 20;
        let ep = run_episode(&truth, BuiltinMap::Site.default_start(), &config, |_| {})
            .expect("the default episode runs");
        (truth, ep)
    })
}

/// The episode with every estimate removed, filtering and smoothed (the points
/// in the true poses).
fn exact_poses(ep: &Episode) -> Episode {
    let mut ep = ep.clone();
    for s in &mut ep.steps {
        s.estimate = None;
        s.smoothed_estimate = None;
    }
    ep
}

#[test]
fn without_noise_every_point_lies_on_a_ground_truth_wall() {
    let (truth, ep) = episode();
    let mut config = ep.config.clone();
    config.model.range_sigma_mm = Some(0.0);
    let ep = exact_poses(ep);
    let mut points: Vec<ModelPoint> = Vec::new();
    let model = build_model(truth, &ep, &config, |_, p| points.extend_from_slice(p)).unwrap();
    assert_eq!(model.accuracy.points, points.len());
    assert!(points.len() > 100_000, "{} points", points.len());
    assert!(
        model.accuracy.p95_distance_m < 1e-9,
        "{:?}",
        model.accuracy.p95_distance_m
    );
    assert!(model.accuracy.mean_distance_m < 1e-9);
    // Twenty rows per wall column, from 0.05 m to 1.95 m.
    let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        (lo.min(p.position[2]), hi.max(p.position[2]))
    });
    assert!(
        (lo - 0.05).abs() < 1e-12 && (hi - 1.95).abs() < 1e-12,
        "{lo} {hi}"
    );
    // Every scan contributes, in order.
    assert_eq!(model.stations.len(), ep.steps.len());
    let mut last = 0;
    for p in &points {
        assert!(p.scan >= last);
        last = p.scan;
    }
    assert_eq!(last as usize, ep.steps.len() - 1);
}

#[test]
fn range_noise_alone_spreads_the_points_by_its_sigma() {
    let (truth, ep) = episode();
    let mut config = ep.config.clone();
    config.model.range_sigma_mm = Some(5.0);
    let model = build_model(truth, &exact_poses(ep), &config, |_, _| {}).unwrap();
    let a = &model.accuracy;
    // |N(0, σ)| has mean 0.80 σ and 95th percentile 1.96 σ; oblique beams see
    // less of the noise across the wall.
    assert!(
        a.mean_distance_m > 0.002 && a.mean_distance_m < 0.8 * 0.005,
        "{a:?}"
    );
    assert!(
        a.p95_distance_m > 0.005 && a.p95_distance_m < 1.02 * 1.96 * 0.005,
        "{a:?}"
    );
}

#[test]
fn the_estimated_poses_move_each_scan_by_at_most_their_error() {
    let (truth, ep) = episode();
    let config = ep.config.clone();
    let model = build_model(truth, ep, &config, |_, _| {}).unwrap();
    let a = &model.accuracy;
    assert!(a.max_position_error_m > 0.0);
    let sigma = 0.002 + 2e-6 * config.scanner.range;
    for s in &a.scans {
        let heading = s.heading_error_arcsec.abs() * std::f64::consts::PI / 648_000.0;
        // A point at most the scanner range (and the wall height) away moves by
        // the position error plus the heading error's arc, plus the noise.
        let reach = s.position_error_m + heading * (config.scanner.range + 2.0) + 4.0 * sigma;
        assert!(
            s.p95_distance_m <= reach,
            "scan {}: {s:?} reach {reach}",
            s.scan
        );
    }
    // The first scan is the exactly known start.
    assert_eq!(a.scans[0].position_error_m, 0.0);
    // The registered model is worse than the noise alone, and the same when
    // built again.
    let again = build_model(truth, ep, &config, |_, _| {}).unwrap();
    assert_eq!(again, model);
    let noise_only = build_model(truth, &exact_poses(ep), &config, |_, _| {}).unwrap();
    assert!(a.mean_distance_m > 2.0 * noise_only.accuracy.mean_distance_m);
    // By default the scans stand in their smoothed poses; in the filtering
    // poses the model differs, each scan again within its pose's error.
    assert!(ep.steps.iter().all(|s| s.smoothed_estimate.is_some()));
    let filtering = build_model_in(truth, ep, &config, Registration::Filtering, |_, _| {}).unwrap();
    assert_ne!(filtering.accuracy, model.accuracy);
    for (s, step) in filtering.accuracy.scans.iter().zip(&ep.steps) {
        let e = step.estimate.unwrap();
        assert!((s.position_error_m - e.position_error_m).abs() < 1e-12);
    }
}

#[test]
fn the_point_limit_is_checked_before_the_points_are_made() {
    let (truth, ep) = episode();
    let mut config = ep.config.clone();
    config.limits.max_cloud_points = 1000;
    let mut called = false;
    let e = build_model(truth, ep, &config, |_, _| called = true).unwrap_err();
    assert!(e.to_string().contains("limits.max_cloud_points"), "{e}");
    assert!(!called);
}
