//! The network adjustment against the sequential chain and the dense batch
//! adjustment, on random networks with loops (targets and control points seen
//! again from later stations).

use nalgebra::DMatrix;
use proptest::prelude::*;

use super::*;
use crate::accuracy::{
    batch_covariances, Chain, CycleGeometry, Instrument, NetworkGeometry, PoseCovariance,
    TargetPoint,
};
use crate::config::InstrumentConfig;
use crate::geom::Point;

fn model(three_d: bool) -> Model {
    let mut inst = Instrument::from_config(&InstrumentConfig::default());
    inst.three_d = three_d;
    Model::new(inst)
}

/// A random network: `k` cycles of 2–4 children along a wandering route, and
/// targets (free and control) that random stations measure, so that later
/// stations see again what earlier ones measured.
fn network_strategy() -> impl Strategy<Value = (bool, NetworkGeometry)> {
    (any::<bool>(), 2usize..5, 1usize..9, 0usize..4).prop_flat_map(|(three_d, n, k, t)| {
        let cycle = (
            (-25.0f64..25.0, -25.0f64..25.0),
            proptest::collection::vec((-25.0f64..25.0, -25.0f64..25.0, any::<bool>()), n),
            proptest::collection::vec(any::<bool>(), t),
        );
        let target = (
            (-40.0f64..40.0, -40.0f64..40.0),
            prop::option::of(0.001f64..0.05),
        );
        (
            Just(three_d),
            proptest::collection::vec(target, t),
            proptest::collection::vec(any::<bool>(), t),
            proptest::collection::vec(cycle, k),
        )
            .prop_map(move |(three_d, targets, at_start, cycles)| {
                let targets: Vec<TargetPoint> = targets
                    .into_iter()
                    .map(|((x, y), s)| TargetPoint {
                        position: Point::new(x, y),
                        z: None,
                        control_sigma: s,
                    })
                    .collect();
                let pick = |m: &[bool]| (0..m.len()).filter(|&i| m[i]).collect::<Vec<usize>>();
                let mut held: Option<Vec<Point>> = None;
                let cycles = cycles
                    .into_iter()
                    .map(|((tx, ty), kids, seen)| {
                        let mut children: Vec<Point> =
                            kids.iter().map(|&(x, y, _)| Point::new(x, y)).collect();
                        let moved: Vec<bool> = kids.iter().map(|&(_, _, m)| m).collect();
                        // A child that stays keeps its point.
                        if let Some(h) = &held {
                            for i in 0..children.len() {
                                if !moved[i] {
                                    children[i] = h[i];
                                }
                            }
                        }
                        held = Some(children.clone());
                        CycleGeometry {
                            to: Point::new(tx, ty),
                            children,
                            moved,
                            here: Vec::new(),
                            sighted: pick(&seen),
                        }
                    })
                    .collect();
                (
                    three_d,
                    NetworkGeometry {
                        start: Point::new(0.0, 0.0),
                        targets,
                        at_start: pick(&at_start),
                        cycles,
                    },
                )
            })
    })
}

/// Every link at least 1.5 m long and some two points at least 5° apart seen
/// from every station (a network a survey would measure; see
/// `batch::tests::well_posed`).
fn well_posed(net: &NetworkGeometry) -> bool {
    let min = 5f64.to_radians();
    let spread = crate::accuracy::batch::tests::spread;
    let near = |a: Point, b: Point| a.distance(b) < 1.5;
    let mut from = net.start;
    for t in &net.at_start {
        if near(net.targets[*t].position, from) {
            return false;
        }
    }
    for c in &net.cycles {
        let seen: Vec<Point> = c.sighted.iter().map(|&t| net.targets[t].position).collect();
        if c.children
            .iter()
            .chain(&seen)
            .any(|&p| near(p, from) || near(p, c.to))
        {
            return false;
        }
        if spread(from, &c.children) < min || spread(c.to, &c.children) < min {
            return false;
        }
        from = c.to;
    }
    true
}

/// The chain of a network, cycle by cycle: the filtering covariance of every
/// station after the first.
fn chain_of(model: Model, net: &NetworkGeometry) -> Option<Vec<DMatrix<f64>>> {
    let mut chain = Chain::new(model, net.start, net.children());
    for &t in &net.targets {
        chain.add_target(t);
    }
    chain.sight_here(&net.at_start).ok()?;
    let ds = model.station_dim();
    let mut out = Vec::new();
    for c in &net.cycles {
        chain.sight_here(&c.here).ok()?;
        chain
            .cycle_sighting(c.to, &c.children, &c.moved, &c.sighted)
            .ok()?;
        out.push(chain.covariance().view((0, 0), (ds, ds)).into_owned());
    }
    Some(out)
}

fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).abs().max() / b.abs().max().max(1e-300)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Cycle by cycle, the network's filtering covariance of the new station
    /// equals the chain's; at the end, the network's smoothed covariance of
    /// every unknown equals the dense batch adjustment's; and no station's
    /// smoothed covariance exceeds its filtering one.
    #[test]
    fn network_equals_chain_and_batch((three_d, net) in network_strategy()) {
        prop_assume!(well_posed(&net));
        let model = model(three_d);
        let filtering = chain_of(model, &net);
        prop_assume!(filtering.is_some());
        let filtering = filtering.expect("assumed");
        let mut network = Network::new(Script::new(model, net.start, net.children(), &net.targets));
        network.script_mut().sight_here(&net.at_start);
        network.extend_nominal().expect("well posed");
        for (k, c) in net.cycles.iter().enumerate() {
            network.script_mut().cycle(c);
            network.extend_nominal().expect("well posed");
            let v = network.script().stations()[k + 1];
            let cov = network.current_covariance(v).expect("solvable").expect("current");
            let ds = model.station_dim();
            let d = rel(&cov.view((0, 0), (ds, ds)).into_owned(), &filtering[k]);
            prop_assert!(d < 1e-7, "cycle {k}: filtering differs by {d:e}");
        }
        let smoothed = network.smooth().expect("solvable");
        let batch = batch_covariances(network.script()).expect("solvable");
        for (v, (s, b)) in smoothed.iter().zip(&batch).enumerate() {
            match (s, b) {
                (Some(s), Some(b)) => {
                    let d = rel(s, b);
                    prop_assert!(d < 1e-7, "unknown {v}: smoothed differs from batch by {d:e}");
                }
                (None, None) => {}
                _ => prop_assert!(false, "unknown {v} solved by one and not the other"),
            }
        }
        for (k, f) in filtering.iter().enumerate() {
            let v = network.script().stations()[k + 1];
            let s = smoothed[v].as_ref().expect("a station");
            let (fp, sp) = (PoseCovariance::from_matrix(&model, f), PoseCovariance::from_matrix(&model, s));
            prop_assert!(
                sp.position_sigma() <= fp.position_sigma() * (1.0 + 1e-9),
                "station {}: smoothed {} > filtering {}", k + 1, sp.position_sigma(), fp.position_sigma()
            );
        }
    }
}

/// Without targets the last station's smoothed covariance is the chain's.
#[test]
fn an_open_chain_ends_where_the_chain_does() {
    let model = model(false);
    let cycles: Vec<CycleGeometry> = (0..12)
        .map(|c| {
            let x = 8.0 * c as f64;
            CycleGeometry::plain(
                Point::new(x + 8.0, 0.5 * (c % 2) as f64),
                vec![Point::new(x + 3.0, 4.0), Point::new(x + 5.0, -3.5)],
                vec![true, true],
            )
        })
        .collect();
    let net = NetworkGeometry::chain(Point::new(0.0, 0.0), cycles);
    let chain = chain_of(model, &net).expect("a chain");
    let network = Network::nominal(Script::of(model, &net)).expect("solvable");
    let smoothed = network.smooth().expect("solvable");
    let last = *network.script().stations().last().expect("stations");
    let d = rel(
        smoothed[last].as_ref().expect("a station"),
        chain.last().expect("cycles"),
    );
    assert!(d < 1e-9, "{d:e}");
}

/// The whitened empirical covariance of `errors` (x, y) by the analytic `cov`:
/// the largest deviation of its variances from 1 and of its covariance from 0.
fn whitened(errors: &[[f64; 2]], cov: &DMatrix<f64>) -> (f64, f64) {
    let a = nalgebra::Matrix2::new(cov[(0, 0)], cov[(0, 1)], cov[(1, 0)], cov[(1, 1)]);
    let li = a
        .cholesky()
        .expect("a covariance")
        .l()
        .try_inverse()
        .expect("invertible");
    let n = errors.len() as f64;
    let mut e = nalgebra::Matrix2::zeros();
    for v in errors {
        let w = li * nalgebra::Vector2::new(v[0], v[1]);
        e += w * w.transpose();
    }
    e /= n;
    (
        (e[(0, 0)] - 1.0).abs().max((e[(1, 1)] - 1.0).abs()),
        e[(0, 1)].abs(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    /// Noise drawn through random networks with loops: the filtering estimates
    /// (sequential Gauss–Newton) scatter as the chain predicts, and the
    /// smoothed ones (Gauss–Newton on the whole network) as the network
    /// adjustment predicts, at the last station and at the middle one; each
    /// whitened variance within 5 standard errors of 1 (√(2/N)), the covariance
    /// within 5/√N of 0.
    #[test]
    fn monte_carlo_agrees_with_chain_and_network((_, net) in network_strategy()) {
        prop_assume!(well_posed(&net) && net.cycles.len() >= 2);
        let model = model(false);
        let filtering = chain_of(model, &net);
        prop_assume!(filtering.is_some());
        let filtering = filtering.expect("assumed");
        let network = Network::nominal(Script::of(model, &net)).expect("well posed");
        let smoothed = network.smooth().expect("solvable");
        let runs = 1500;
        let mc: Vec<_> = (0..runs)
            .map(|r| crate::accuracy::realisation(&model, &net, 11, r, true).expect("runs"))
            .collect();
        let (tol_var, tol_cov) = (5.0 * (2.0 / runs as f64).sqrt(), 5.0 / (runs as f64).sqrt());
        let k = net.cycles.len();
        for c in [k / 2, k - 1] {
            let f: Vec<[f64; 2]> = mc.iter().map(|r| [r.filtering[c][0], r.filtering[c][1]]).collect();
            let (dv, dc) = whitened(&f, &filtering[c]);
            prop_assert!(dv < tol_var && dc < tol_cov, "filtering, cycle {c}: {dv}, {dc}");
            let s: Vec<[f64; 2]> = mc
                .iter()
                .map(|r| {
                    let e = r.smoothed.as_ref().expect("smoothed")[c];
                    [e[0], e[1]]
                })
                .collect();
            let v = network.script().stations()[c + 1];
            let (dv, dc) = whitened(&s, smoothed[v].as_ref().expect("a station"));
            prop_assert!(dv < tol_var && dc < tol_cov, "smoothed, cycle {c}: {dv}, {dc}");
        }
    }
}
