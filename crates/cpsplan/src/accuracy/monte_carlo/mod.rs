//! A Monte Carlo check of the propagation: real measurement noise drawn through
//! the same network, the poses estimated by nonlinear least squares, the errors
//! counted.
//!
//! In: the model, the network's geometry, the number of runs and a seed. Out:
//! per cycle, the mean radial error of the parent's position and the empirical
//! covariance of its pose error ([`MonteCarlo`]), for the filtering estimates and,
//! when asked, the smoothed ones.
//!
//! The filtering estimator is the sequential one the analytic propagation
//! describes, with the nonlinear model: each moving child's point from the
//! estimated station and its noisy measurement; each new station and the points
//! together by Gauss–Newton on the noisy measurements and the points' prior
//! (weighted by the analytic prior information, as the filter weights it). The
//! smoothed estimator adjusts the whole network from the same readings by
//! Gauss–Newton ([`super::Network::adjust`]). Runs are independent, seeded by run
//! number, and summed in order: the result does not depend on the thread count.

mod run;

use nalgebra::DVector;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use self::run::{one_run, priors};
use super::chain::{ChainError, PoseCovariance};
use super::geometry::NetworkGeometry;
use super::model::Model;
use super::network::StationFit;
use super::script::Script;

/// What the Monte Carlo runs gave.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarlo {
    /// Number of runs.
    pub runs: usize,
    /// Per cycle: the mean over the runs of the radial error of the parent's
    /// filtering position after the cycle, metres.
    pub mean_error: Vec<f64>,
    /// Per cycle: the empirical covariance of the parent's filtering pose error
    /// after it.
    pub covariance: Vec<PoseCovariance>,
    /// Per cycle, with smoothing: the mean radial error of the smoothed position.
    pub smoothed_mean_error: Option<Vec<f64>>,
    /// Per cycle, with smoothing: the empirical covariance of the smoothed pose
    /// error.
    pub smoothed_covariance: Option<Vec<PoseCovariance>>,
}

/// The errors of one realisation: per cycle, the error `[x, y, z, ω]` (metres
/// and radians; `z` is 0 in 2D) of the filtering estimate of the station it
/// reached, and of its smoothed estimate when asked.
#[derive(Debug, Clone, PartialEq)]
pub struct Realisation {
    /// Filtering errors, one per cycle.
    pub filtering: Vec<[f64; 4]>,
    /// Smoothed errors, one per cycle.
    pub smoothed: Option<Vec<[f64; 4]>>,
    /// With smoothing: how every station's readings fit the adjusted network
    /// (by station number, the first included).
    pub fits: Option<Vec<Option<StationFit>>>,
    /// Every noisy reading the estimates come from, in the order of the
    /// script's Observe events ([`Script::of`] the same network).
    pub readings: Vec<DVector<f64>>,
}

/// Runs `runs` noisy realisations of the network `net`; `smooth`: adjust each
/// realisation's whole network too.
pub fn monte_carlo(
    model: &Model,
    net: &NetworkGeometry,
    runs: usize,
    seed: u64,
    smooth: bool,
) -> Result<MonteCarlo, ChainError> {
    let priors = priors(model, net)?;
    let script = Script::of(*model, net);
    let errors: Vec<run::RunErrors> = (0..runs)
        .into_par_iter()
        .map(|r| {
            let mut e = one_run(
                model,
                net,
                &script,
                &priors,
                &mut run_rng(seed, r),
                smooth,
                false,
            );
            // The statistics need the errors only.
            e.readings = Vec::new();
            e
        })
        .collect();
    let k = net.cycles.len();
    let (mean_error, covariance) = summarise(k, runs, errors.iter().map(|e| &e.filtering[..]));
    let smoothed = smooth.then(|| {
        summarise(
            k,
            runs,
            errors.iter().map(|e| e.smoothed.as_deref().unwrap_or(&[])),
        )
    });
    Ok(MonteCarlo {
        runs,
        mean_error,
        covariance,
        smoothed_mean_error: smoothed.as_ref().map(|s| s.0.clone()),
        smoothed_covariance: smoothed.map(|s| s.1),
    })
}

/// The mean radial error and the empirical covariance per cycle of `runs` runs'
/// errors (a run that failed adds nothing but counts).
fn summarise<'a>(
    k: usize,
    runs: usize,
    errors: impl Iterator<Item = &'a [[f64; 4]]>,
) -> (Vec<f64>, Vec<PoseCovariance>) {
    let mut mean_error = vec![0.0; k];
    let mut covariance = vec![PoseCovariance::default(); k];
    for e in errors {
        for (c, v) in e.iter().enumerate().take(k) {
            mean_error[c] += (v[0] * v[0] + v[1] * v[1]).sqrt();
            let p = &mut covariance[c];
            p.xx += v[0] * v[0];
            p.xy += v[0] * v[1];
            p.yy += v[1] * v[1];
            p.zz += v[2] * v[2];
            p.heading += v[3] * v[3];
        }
    }
    let r = runs.max(1) as f64;
    for c in 0..k {
        mean_error[c] /= r;
        let p = &mut covariance[c];
        p.xx /= r;
        p.xy /= r;
        p.yy /= r;
        p.zz /= r;
        p.heading /= r;
    }
    (mean_error, covariance)
}

/// One noisy realisation of the network, run `run` of [`monte_carlo`] with the
/// same `seed`. The registered 3D model expresses each scan in the pose this
/// estimate gives.
pub fn realisation(
    model: &Model,
    net: &NetworkGeometry,
    seed: u64,
    run: usize,
    smooth: bool,
) -> Result<Realisation, ChainError> {
    let priors = priors(model, net)?;
    let script = Script::of(*model, net);
    let e = one_run(
        model,
        net,
        &script,
        &priors,
        &mut run_rng(seed, run),
        smooth,
        smooth,
    );
    Ok(Realisation {
        filtering: e.filtering,
        smoothed: e.smoothed,
        fits: e.fits,
        readings: e.readings,
    })
}

/// The random numbers of run `run`.
fn run_rng(seed: u64, run: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ (run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// The chain's covariance of the last station of `cycles` from the origin
/// (two children), and `runs` Monte Carlo runs of the same chain.
#[cfg(test)]
pub(crate) fn analytic_and_simulated(
    model: Model,
    cycles: &[super::geometry::CycleGeometry],
    runs: usize,
    seed: u64,
) -> (PoseCovariance, MonteCarlo) {
    let start = crate::geom::Point::new(0.0, 0.0);
    let mut chain = super::Chain::new(model, start, 2);
    for c in cycles {
        chain.cycle(c.to, &c.children, &c.moved).unwrap();
    }
    let net = NetworkGeometry::chain(start, cycles.to_vec());
    (
        chain.pose(),
        monte_carlo(&model, &net, runs, seed, false).unwrap(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::{Chain, CycleGeometry, Instrument};
    use crate::config::InstrumentConfig;
    use crate::geom::Point;

    /// A chain of `k` cycles along a street, children leapfrogging.
    fn street(k: usize) -> Vec<CycleGeometry> {
        (0..k)
            .map(|c| {
                let x = 8.0 * c as f64;
                CycleGeometry::plain(
                    Point::new(x + 8.0, 0.5 * (c % 2) as f64),
                    vec![Point::new(x + 3.0, 4.0), Point::new(x + 5.0, -3.5)],
                    vec![true, true],
                )
            })
            .collect()
    }

    /// The whitened errors of the last station have unit covariance: over N runs
    /// each variance of the whitened error is 1 within 5 standard errors
    /// (√(2/N) for a variance, 1/√N for a covariance of independent unit
    /// variables), and the mean squared Mahalanobis distance is the dimension.
    #[test]
    fn monte_carlo_agrees_with_the_analytic_covariance() {
        for three_d in [false, true] {
            let mut inst = Instrument::from_config(&InstrumentConfig::default());
            inst.three_d = three_d;
            let model = Model::new(inst);
            let cycles = street(6);
            let start = Point::new(0.0, 0.0);
            let runs = 4000;
            let mut chain = Chain::new(model, start, 2);
            for c in &cycles {
                chain.cycle(c.to, &c.children, &c.moved).unwrap();
            }
            let analytic = chain.pose();
            let mc = monte_carlo(
                &model,
                &NetworkGeometry::chain(start, cycles.clone()),
                runs,
                7,
                false,
            )
            .unwrap();
            let emp = mc.covariance.last().unwrap();
            // Position 2×2 block, whitened by the analytic covariance.
            let a = nalgebra::Matrix2::new(analytic.xx, analytic.xy, analytic.xy, analytic.yy);
            let e = nalgebra::Matrix2::new(emp.xx, emp.xy, emp.xy, emp.yy);
            let l = a.cholesky().unwrap().l();
            let li = l.try_inverse().unwrap();
            let w = li * e * li.transpose();
            let tol_var = 5.0 * (2.0 / runs as f64).sqrt();
            let tol_cov = 5.0 / (runs as f64).sqrt();
            assert!((w[(0, 0)] - 1.0).abs() < tol_var, "{w}");
            assert!((w[(1, 1)] - 1.0).abs() < tol_var, "{w}");
            assert!(w[(0, 1)].abs() < tol_cov, "{w}");
            let heading = emp.heading / analytic.heading;
            assert!((heading - 1.0).abs() < tol_var, "heading ratio {heading}");
            // The mean radial error is near its expectation for the analytic
            // covariance (between the two axes' contributions).
            let m = *mc.mean_error.last().unwrap();
            let (s1, s2, _) = analytic.ellipse();
            assert!(
                m > 0.8 * s1.max(s2) && m < 1.3 * (s1 * s1 + s2 * s2).sqrt(),
                "{m}"
            );
        }
    }

    #[test]
    fn runs_do_not_depend_on_threads_or_order() {
        let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
        let cycles = street(3);
        let net = NetworkGeometry::chain(Point::new(0.0, 0.0), cycles);
        let a = monte_carlo(&model, &net, 50, 1, true).unwrap();
        let b = monte_carlo(&model, &net, 50, 1, true).unwrap();
        assert_eq!(a, b);
    }
}

#[cfg(test)]
mod stay_tests {
    use super::*;
    use crate::accuracy::{CycleGeometry, Instrument};
    use crate::config::InstrumentConfig;
    use crate::geom::Point;

    /// Children leapfrog: one stays while the other moves.
    fn leapfrog(k: usize) -> Vec<CycleGeometry> {
        let mut kids = [Point::new(3.0, 4.0), Point::new(5.0, -3.5)];
        (0..k)
            .map(|c| {
                let x = 6.0 * c as f64;
                let mover = c % 2;
                if c > 0 {
                    kids[mover] = Point::new(x + 6.0, if mover == 0 { 4.0 } else { -3.5 });
                }
                CycleGeometry::plain(
                    Point::new(x + 6.0, 0.3 * (c % 3) as f64),
                    kids.to_vec(),
                    vec![c == 0 || mover == 0, c == 0 || mover == 1],
                )
            })
            .collect()
    }

    #[test]
    fn monte_carlo_agrees_when_children_stay() {
        let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
        let cycles = leapfrog(12);
        let (a, mc) = analytic_and_simulated(model, &cycles, 4000, 3);
        let e = mc.covariance.last().unwrap();
        let ratio = (e.xx + e.yy) / (a.xx + a.yy);
        assert!(
            (ratio - 1.0).abs() < 0.12,
            "ratio {ratio}, analytic σ {}",
            a.position_sigma()
        );
    }
}

#[cfg(test)]
mod long_chain_tests {
    use super::*;
    use crate::accuracy::{CycleGeometry, Instrument};
    use crate::config::InstrumentConfig;
    use crate::geom::Point;

    /// A long chain of poor geometry (children close together): its heading
    /// error grows like a random walk. With noise small enough that the heading
    /// errors stay within tens of arc seconds, first order holds all along (with
    /// the instrument's real noise the heading reaches degrees here and the
    /// simulated errors outgrow the first-order σ: docs/ACCURACY.md).
    #[test]
    fn first_order_holds_along_a_long_chain_of_small_errors() {
        let mut inst = Instrument::from_config(&InstrumentConfig::default());
        inst.distance_sigma *= 0.01;
        inst.distance_ppm *= 0.01;
        inst.angle_sigma *= 0.01;
        let model = Model::new(inst);
        let cycles: Vec<CycleGeometry> = (0..100)
            .map(|c| {
                let x = 10.0 * c as f64;
                CycleGeometry::plain(
                    Point::new(x + 10.0, 0.0),
                    vec![Point::new(x + 5.0, 1.6), Point::new(x + 5.2, 2.4)],
                    vec![true, true],
                )
            })
            .collect();
        let (a, mc) = analytic_and_simulated(model, &cycles, 1000, 5);
        let e = mc.covariance.last().unwrap();
        let ratio = ((e.xx + e.yy) / (a.xx + a.yy)).sqrt();
        // 1000 runs: the standard error of an RMS is about 1/√(2·1000) ≈ 2 %.
        assert!((ratio - 1.0).abs() < 0.1, "ratio {ratio}");
    }
}
