//! A Monte Carlo check of the propagation: real measurement noise drawn through
//! the same chain of cycles, the poses estimated by nonlinear least squares, the
//! errors counted.
//!
//! In: the model, the first pose, the cycles, the number of runs and a seed. Out:
//! per cycle, the mean radial error of the parent's position and the empirical
//! covariance of its pose error ([`MonteCarlo`]).
//!
//! The estimator is the sequential one the analytic propagation describes, with
//! the nonlinear model: each moving child's point from the estimated station and
//! its noisy measurement; each new station and the children's points together by
//! Gauss–Newton on the noisy measurements and the points' prior (weighted by the
//! analytic prior information, as the filter weights it). For the last station
//! this is the nonlinear counterpart of the batch adjustment. Runs are
//! independent, seeded by run number, and summed in order: the result does not
//! depend on the thread count.

use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

use super::batch::CycleGeometry;
use super::chain::{invert_spd, Chain, ChainError, PoseCovariance};
use super::model::Model;
use crate::geom::Point;

/// What the Monte Carlo runs gave.
#[derive(Debug, Clone, PartialEq)]
pub struct MonteCarlo {
    /// Number of runs.
    pub runs: usize,
    /// Per cycle: the mean over the runs of the radial error of the parent's
    /// position after the cycle, metres.
    pub mean_error: Vec<f64>,
    /// Per cycle: the empirical covariance of the parent's pose error after it.
    pub covariance: Vec<PoseCovariance>,
}

/// Gauss–Newton iterations per resection at most (from the drifted guess the noise
/// is millimetric and two or three suffice).
const ITERATIONS: usize = 8;

/// Runs `runs` noisy realisations of the chain from `start` through `cycles`.
pub fn monte_carlo(
    model: &Model,
    start: Point,
    cycles: &[CycleGeometry],
    runs: usize,
    seed: u64,
) -> Result<MonteCarlo, ChainError> {
    let priors = priors(model, start, cycles)?;
    let errors: Vec<Vec<[f64; 4]>> = (0..runs)
        .into_par_iter()
        .map(|run| one_run(model, start, cycles, &priors, &mut run_rng(seed, run)))
        .collect();
    let k = cycles.len();
    let mut mean_error = vec![0.0; k];
    let mut covariance = vec![PoseCovariance::default(); k];
    for e in &errors {
        for (c, v) in e.iter().enumerate() {
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
    Ok(MonteCarlo {
        runs,
        mean_error,
        covariance,
    })
}

/// One noisy realisation of the chain, run `run` of [`monte_carlo`] with the same
/// `seed`: per cycle, the error `[x, y, z, ω]` of the estimated station (metres
/// and radians; `z` is 0 in 2D). The registered 3D model expresses each scan in
/// the pose this estimate gives.
pub fn realisation(
    model: &Model,
    start: Point,
    cycles: &[CycleGeometry],
    seed: u64,
    run: usize,
) -> Result<Vec<[f64; 4]>, ChainError> {
    let priors = priors(model, start, cycles)?;
    Ok(one_run(
        model,
        start,
        cycles,
        &priors,
        &mut run_rng(seed, run),
    ))
}

/// The analytic priors of every resection, shared by all runs.
fn priors(
    model: &Model,
    start: Point,
    cycles: &[CycleGeometry],
) -> Result<Vec<DMatrix<f64>>, ChainError> {
    let n = cycles.first().map_or(0, |c| c.children.len());
    let mut chain = Chain::new(*model, start, n);
    let mut priors = Vec::with_capacity(cycles.len());
    for c in cycles {
        chain.cycle(c.to, &c.children, &c.moved)?;
        priors.push(chain.prior_info().clone());
    }
    Ok(priors)
}

/// The random numbers of run `run`.
fn run_rng(seed: u64, run: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ (run as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// One realisation: per cycle, the error `[x, y, z, ω]` of the estimated station.
fn one_run(
    model: &Model,
    start: Point,
    cycles: &[CycleGeometry],
    priors: &[DMatrix<f64>],
    rng: &mut ChaCha8Rng,
) -> Vec<[f64; 4]> {
    let (ds, dp) = (model.station_dim(), model.point_dim());
    let n = cycles.first().map_or(0, |c| c.children.len());
    let mut truth_station = model.station(start, 0.0);
    let mut station = truth_station.clone();
    let mut truth_points: Vec<Option<DVector<f64>>> = vec![None; n];
    let mut points: Vec<Option<DVector<f64>>> = vec![None; n];
    let mut out = Vec::with_capacity(cycles.len());
    let noisy = |s: &DVector<f64>, c: &DVector<f64>, rng: &mut ChaCha8Rng| {
        let mut z = model.observe(s.as_slice(), c.as_slice());
        let r = model.noise(s.as_slice(), c.as_slice());
        for i in 0..z.len() {
            let e: f64 = StandardNormal.sample(rng);
            z[i] += e * r[(i, i)].sqrt();
        }
        z
    };
    for (cycle, prior) in cycles.iter().zip(priors) {
        for i in 0..n {
            if cycle.moved[i] || truth_points[i].is_none() {
                let t = model.point(cycle.children[i]);
                let z = noisy(&truth_station, &t, rng);
                points[i] = Some(model.forward(station.as_slice(), z.as_slice()));
                truth_points[i] = Some(t);
            }
        }
        let truth_before = truth_station.clone();
        truth_station = model.station(cycle.to, 0.0);
        let obs: Vec<DVector<f64>> = truth_points
            .iter()
            .map(|t| {
                noisy(
                    &truth_station,
                    t.as_ref().expect("every child measured"),
                    rng,
                )
            })
            .collect();
        let prior_points: Vec<DVector<f64>> = points
            .iter()
            .map(|p| p.clone().expect("every child measured"))
            .collect();
        // Start from where the estimate's drift puts the new station: the rigid
        // motion that takes the true previous station to its estimate.
        let guess = drifted(model, &truth_before, &station, &truth_station);
        let (u, refined) = resect(model, &guess, &prior_points, prior, &obs);
        station = u;
        for (p, r) in points.iter_mut().zip(refined) {
            *p = Some(r);
        }
        let mut e = &station - &truth_station;
        e[ds - 1] = wrap(e[ds - 1]);
        out.push(if model.three_d() {
            [e[0], e[1], e[2], e[ds - 1]]
        } else {
            [e[0], e[1], 0.0, e[ds - 1]]
        });
        let _ = dp;
    }
    out
}

/// `truth_new` moved by the rigid motion that takes `truth_old` to `estimate_old`.
fn drifted(
    model: &Model,
    truth_old: &DVector<f64>,
    estimate_old: &DVector<f64>,
    truth_new: &DVector<f64>,
) -> DVector<f64> {
    let ds = model.station_dim();
    let dw = estimate_old[ds - 1] - truth_old[ds - 1];
    let (s, c) = dw.sin_cos();
    let (dx, dy) = (truth_new[0] - truth_old[0], truth_new[1] - truth_old[1]);
    let mut u = truth_new.clone();
    u[0] = estimate_old[0] + c * dx - s * dy;
    u[1] = estimate_old[1] + s * dx + c * dy;
    if model.three_d() {
        u[2] = truth_new[2] + estimate_old[2] - truth_old[2];
    }
    u[ds - 1] = truth_new[ds - 1] + dw;
    u
}

/// Gauss–Newton on the new station `u` and the points `c`: the observations `obs`
/// and the points' prior `prior_points` with information `prior`; starts from
/// `guess` for the station.
fn resect(
    model: &Model,
    guess: &DVector<f64>,
    prior_points: &[DVector<f64>],
    prior: &DMatrix<f64>,
    obs: &[DVector<f64>],
) -> (DVector<f64>, Vec<DVector<f64>>) {
    let (ds, dp, m) = (model.station_dim(), model.point_dim(), model.obs_dim());
    let n = prior_points.len();
    let size = ds + n * dp;
    let mut x = DVector::zeros(size);
    x.rows_mut(0, ds).copy_from(guess);
    for (i, p) in prior_points.iter().enumerate() {
        x.rows_mut(ds + i * dp, dp).copy_from(p);
    }
    let mut c0 = DVector::zeros(n * dp);
    for (i, p) in prior_points.iter().enumerate() {
        c0.rows_mut(i * dp, dp).copy_from(p);
    }
    for _ in 0..ITERATIONS {
        let mut info = DMatrix::zeros(size, size);
        let mut rhs = DVector::zeros(size);
        info.view_mut((ds, ds), (n * dp, n * dp)).copy_from(prior);
        let dc = &c0 - x.rows(ds, n * dp);
        let prior_rhs = prior * dc;
        let mut r = rhs.rows_mut(ds, n * dp);
        r += prior_rhs;
        let u = x.rows(0, ds).into_owned();
        for (i, z) in obs.iter().enumerate() {
            let o = ds + i * dp;
            let c = x.rows(o, dp).into_owned();
            let (hs, hc) = model.jacobians(u.as_slice(), c.as_slice());
            let w = invert_spd(&model.noise(u.as_slice(), c.as_slice()))
                .unwrap_or_else(|| DMatrix::identity(m, m));
            let mut res = z - model.observe(u.as_slice(), c.as_slice());
            for a in 1..m {
                res[a] = wrap(res[a]);
            }
            let mut h = DMatrix::zeros(m, size);
            h.view_mut((0, 0), (m, ds)).copy_from(&hs);
            h.view_mut((0, o), (m, dp)).copy_from(&hc);
            let ht_w = h.transpose() * &w;
            info += &ht_w * &h;
            rhs += ht_w * res;
        }
        let Some(step) = info.cholesky().map(|c| c.solve(&rhs)) else {
            break;
        };
        x += &step;
        if step.amax() < 1e-12 {
            break;
        }
    }
    let points = (0..n)
        .map(|i| x.rows(ds + i * dp, dp).into_owned())
        .collect();
    (x.rows(0, ds).into_owned(), points)
}

/// An angle difference in (−π, π].
fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = a.rem_euclid(t);
    if r > std::f64::consts::PI {
        r - t
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::Instrument;
    use crate::config::InstrumentConfig;

    /// A chain of `k` cycles along a street, children leapfrogging.
    fn street(k: usize) -> Vec<CycleGeometry> {
        (0..k)
            .map(|c| {
                let x = 8.0 * c as f64;
                CycleGeometry {
                    to: Point::new(x + 8.0, 0.5 * (c % 2) as f64),
                    children: vec![Point::new(x + 3.0, 4.0), Point::new(x + 5.0, -3.5)],
                    moved: vec![true, true],
                }
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
            let mc = monte_carlo(&model, start, &cycles, runs, 7).unwrap();
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
        let a = monte_carlo(&model, Point::new(0.0, 0.0), &cycles, 50, 1).unwrap();
        let b = monte_carlo(&model, Point::new(0.0, 0.0), &cycles, 50, 1).unwrap();
        assert_eq!(a, b);
        assert_eq!(
            wrap(3.5 * std::f64::consts::PI),
            -0.5 * std::f64::consts::PI
        );
    }
}

#[cfg(test)]
mod stay_tests {
    use super::*;
    use crate::accuracy::Instrument;
    use crate::config::InstrumentConfig;

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
                CycleGeometry {
                    to: Point::new(x + 6.0, 0.3 * (c % 3) as f64),
                    children: kids.to_vec(),
                    moved: vec![c == 0 || mover == 0, c == 0 || mover == 1],
                }
            })
            .collect()
    }

    #[test]
    fn monte_carlo_agrees_when_children_stay() {
        let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
        let cycles = leapfrog(12);
        let start = Point::new(0.0, 0.0);
        let mut chain = Chain::new(model, start, 2);
        for c in &cycles {
            chain.cycle(c.to, &c.children, &c.moved).unwrap();
        }
        let a = chain.pose();
        let mc = monte_carlo(&model, start, &cycles, 4000, 3).unwrap();
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
    use crate::accuracy::Instrument;
    use crate::config::InstrumentConfig;

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
                CycleGeometry {
                    to: Point::new(x + 10.0, 0.0),
                    children: vec![Point::new(x + 5.0, 1.6), Point::new(x + 5.2, 2.4)],
                    moved: vec![true, true],
                }
            })
            .collect();
        let start = Point::new(0.0, 0.0);
        let mut chain = Chain::new(model, start, 2);
        for c in &cycles {
            chain.cycle(c.to, &c.children, &c.moved).unwrap();
        }
        let a = chain.pose();
        let mc = monte_carlo(&model, start, &cycles, 1000, 5).unwrap();
        let e = mc.covariance.last().unwrap();
        let ratio = ((e.xx + e.yy) / (a.xx + a.yy)).sqrt();
        // 1000 runs: the standard error of an RMS is about 1/√(2·1000) ≈ 2 %.
        assert!((ratio - 1.0).abs() < 0.1, "ratio {ratio}");
    }
}
