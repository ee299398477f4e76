//! First-order propagation of the CPS chain's covariance, cycle by cycle (the
//! error propagation of Kurazume & Hirose, ICRA 1998, that the paper's Fig. 10
//! uses), over the *joint* state of the parent's pose and every child's point,
//! cross-covariances kept. Derived in docs/ACCURACY.md.
//!
//! In: the parent's first pose (known exactly) and, per cycle, the parent's next
//! position and the children's points, with which children moved. Out: after
//! every cycle, the covariance of the parent's new pose ([`PoseCovariance`]).
//!
//! Per cycle, with the parent at station `k`:
//! 1. *Forward*: every child with a new point (it moved, or was never measured) is
//!    measured from station `k` (distance and direction): its point is a function
//!    of the station's pose and that measurement, so its covariance follows by
//!    first order, correlated with the station; its old point is dropped.
//! 2. *Resection*: the parent moves to station `k + 1`, whose position and circle
//!    orientation are unknown, and measures every child. The station's pose and the
//!    children's points are estimated jointly by weighted least squares: the prior
//!    information of the points (their covariance after station `k` is dropped)
//!    plus the information of the new measurements. The children's points are
//!    refined by the redundant measurements, and the station's orientation carries
//!    into the next cycle's forward step.
//!
//! A child that stays keeps its point: it was measured from station `k` at the end
//! of the previous cycle, and is not measured again. This is exactly the
//! sequential form of the batch adjustment of the whole network
//! ([`super::batch_station_covariance`]) for the last station; the tests check it.

use nalgebra::{DMatrix, DVector};
use thiserror::Error;

use super::model::Model;
use crate::geom::Point;

/// Why the chain cannot be propagated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ChainError {
    /// Fewer children than the parent's pose has unknowns to fix.
    #[error("the parent's pose needs at least two children to be fixed, got {0}")]
    TooFewChildren(usize),
    /// The measurements do not fix the parent's pose (children on one line with it,
    /// or on top of it).
    #[error("the children's geometry does not fix the parent's pose")]
    Singular,
}

/// The covariance of one parent pose: horizontal position (m²) and heading (rad²),
/// and the height in 3D.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PoseCovariance {
    /// Var(x), m².
    pub xx: f64,
    /// Cov(x, y), m².
    pub xy: f64,
    /// Var(y), m².
    pub yy: f64,
    /// Var(z), m² (0 in the planar model).
    pub zz: f64,
    /// Var(ω), the heading of the instrument's circle, rad².
    pub heading: f64,
}

impl PoseCovariance {
    /// The radial 1σ of the horizontal position, `sqrt(σx² + σy²)`, metres.
    pub fn position_sigma(&self) -> f64 {
        (self.xx + self.yy).max(0.0).sqrt()
    }

    /// The 1σ of the heading, radians.
    pub fn heading_sigma(&self) -> f64 {
        self.heading.max(0.0).sqrt()
    }

    /// The semi-axes (1σ, metres) and the direction of the major axis (radians
    /// from the x axis) of the horizontal error ellipse.
    pub fn ellipse(&self) -> (f64, f64, f64) {
        let tr = self.xx + self.yy;
        let det = self.xx * self.yy - self.xy * self.xy;
        let disc = (tr * tr / 4.0 - det).max(0.0).sqrt();
        let (l1, l2) = (tr / 2.0 + disc, (tr / 2.0 - disc).max(0.0));
        let angle = 0.5 * (2.0 * self.xy).atan2(self.xx - self.yy);
        (l1.sqrt(), l2.sqrt(), angle)
    }

    fn of(model: &Model, cov: &DMatrix<f64>) -> Self {
        let ds = model.station_dim();
        Self {
            xx: cov[(0, 0)],
            xy: cov[(0, 1)],
            yy: cov[(1, 1)],
            zz: if model.three_d() { cov[(2, 2)] } else { 0.0 },
            heading: cov[(ds - 1, ds - 1)],
        }
    }
}

/// The propagated state of a CPS team: nominal poses and points, and the joint
/// covariance `[station, child 1, …, child n]`.
#[derive(Debug, Clone)]
pub struct Chain {
    model: Model,
    station: DVector<f64>,
    points: Vec<Option<DVector<f64>>>,
    cov: DMatrix<f64>,
    /// The information of the children's points before the last resection (for
    /// the Monte Carlo estimator, which weights its prior the same way).
    prior_info: DMatrix<f64>,
}

impl Chain {
    /// A team of `children` children with the parent at `start`, its pose known
    /// exactly (the first pose of the campaign).
    pub fn new(model: Model, start: Point, children: usize) -> Self {
        let n = model.station_dim() + children * model.point_dim();
        Self {
            model,
            station: model.station(start, 0.0),
            points: vec![None; children],
            cov: DMatrix::zeros(n, n),
            prior_info: DMatrix::zeros(0, 0),
        }
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The covariance of the parent's current pose.
    pub fn pose(&self) -> PoseCovariance {
        PoseCovariance::of(&self.model, &self.cov)
    }

    /// The joint covariance `[station, child 1, …]` (children never measured have
    /// zero blocks).
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.cov
    }

    /// The parent's current position.
    pub fn position(&self) -> Point {
        Point::new(self.station[0], self.station[1])
    }

    /// The children's current points (`None`: not measured yet).
    pub fn points(&self) -> Vec<Option<Point>> {
        self.points
            .iter()
            .map(|p| p.as_ref().map(|v| Point::new(v[0], v[1])))
            .collect()
    }

    /// The information matrix of the children's points that the last resection
    /// started from.
    pub(crate) fn prior_info(&self) -> &DMatrix<f64> {
        &self.prior_info
    }

    fn child_offset(&self, i: usize) -> usize {
        self.model.station_dim() + i * self.model.point_dim()
    }

    /// One CPS cycle: the children `moved` (or never measured) get new points at
    /// `children` measured from the parent's current station, then the parent
    /// moves to `to` and is fixed by resection on every child. Returns the new
    /// pose's covariance.
    pub fn cycle(
        &mut self,
        to: Point,
        children: &[Point],
        moved: &[bool],
    ) -> Result<PoseCovariance, ChainError> {
        let n = self.points.len();
        debug_assert_eq!(children.len(), n);
        if n < 2 {
            return Err(ChainError::TooFewChildren(n));
        }
        for (i, &c) in children.iter().enumerate() {
            if moved.get(i).copied().unwrap_or(true) || self.points[i].is_none() {
                self.forward(i, self.model.point(c));
            }
        }
        self.resect(self.model.station(to, 0.0))?;
        Ok(self.pose())
    }

    /// Step 1 for child `i`: its point `c` measured from the current station.
    fn forward(&mut self, i: usize, c: DVector<f64>) {
        let m = &self.model;
        let (ds, dp) = (m.station_dim(), m.point_dim());
        let s = self.station.as_slice();
        let z = m.observe(s, c.as_slice());
        let r = m.noise(s, c.as_slice());
        let (fs, fz) = m.forward_jacobians(s, z.as_slice());
        let o = self.child_offset(i);
        let total = self.cov.nrows();
        // Cross-covariance of the new point with everything: F_s · P[station, ·].
        let p_s = self.cov.rows(0, ds).into_owned();
        let cross = &fs * &p_s;
        let own = &fs * p_s.columns(0, ds) * fs.transpose() + &fz * r * fz.transpose();
        for j in 0..total {
            for a in 0..dp {
                self.cov[(o + a, j)] = cross[(a, j)];
                self.cov[(j, o + a)] = cross[(a, j)];
            }
        }
        for a in 0..dp {
            for b in 0..dp {
                self.cov[(o + a, o + b)] = own[(a, b)];
            }
        }
        self.points[i] = Some(c);
    }

    /// Step 2: the parent at the new station `u` (nominal pose), estimated with
    /// every child's point.
    fn resect(&mut self, u: DVector<f64>) -> Result<(), ChainError> {
        let m = &self.model;
        let (ds, dp) = (m.station_dim(), m.point_dim());
        let n = self.points.len();
        let nc = n * dp;
        // The points' prior after the old station is dropped.
        let pc = self.cov.view((ds, ds), (nc, nc)).into_owned();
        let info_c = invert_spd(&pc).ok_or(ChainError::Singular)?;
        let mut info = DMatrix::zeros(ds + nc, ds + nc);
        info.view_mut((ds, ds), (nc, nc)).copy_from(&info_c);
        for (i, p) in self.points.iter().enumerate() {
            let c = p.as_ref().ok_or(ChainError::Singular)?;
            let (hs, hc) = m.jacobians(u.as_slice(), c.as_slice());
            let w = invert_spd(&m.noise(u.as_slice(), c.as_slice())).ok_or(ChainError::Singular)?;
            let o = ds + i * dp;
            let ss = hs.transpose() * &w * &hs;
            let sc = hs.transpose() * &w * &hc;
            let cc = hc.transpose() * &w * &hc;
            add(&mut info, 0, 0, &ss);
            add(&mut info, 0, o, &sc);
            add(&mut info, o, 0, &sc.transpose());
            add(&mut info, o, o, &cc);
        }
        let cov = invert_spd(&info).ok_or(ChainError::Singular)?;
        self.cov = symmetrize(cov);
        self.station = u;
        self.prior_info = info_c;
        Ok(())
    }
}

fn add(m: &mut DMatrix<f64>, r: usize, c: usize, block: &DMatrix<f64>) {
    let mut v = m.view_mut((r, c), (block.nrows(), block.ncols()));
    v += block;
}

/// The inverse of a symmetric positive definite matrix (Cholesky), `None` if it
/// is not.
pub(crate) fn invert_spd(m: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let sym = symmetrize(m.clone());
    sym.cholesky().map(|c| c.inverse())
}

fn symmetrize(m: DMatrix<f64>) -> DMatrix<f64> {
    (&m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::Instrument;
    use crate::config::InstrumentConfig;

    fn model() -> Model {
        Model::new(Instrument::from_config(&InstrumentConfig::default()))
    }

    #[test]
    fn one_cycle_with_children_at_right_angles_is_millimetric() {
        let mut chain = Chain::new(model(), Point::new(0.0, 0.0), 2);
        let to = Point::new(10.0, 0.0);
        let kids = [Point::new(5.0, 5.0), Point::new(5.0, -5.0)];
        let p = chain.cycle(to, &kids, &[true, true]).unwrap();
        let s = p.position_sigma();
        assert!(s > 1e-3 && s < 5e-3, "σ {s}");
    }

    #[test]
    fn children_close_together_seen_from_far_cost_accuracy() {
        // Children 1.5 m behind the start, 4 degrees apart seen from the parent
        // 18 m away.
        let mut near = Chain::new(model(), Point::new(0.0, 0.0), 2);
        let to = Point::new(18.0, 0.0);
        let bad = [Point::new(-1.3, 0.75), Point::new(-1.3, -0.55)];
        let p_bad = near.cycle(to, &bad, &[true, true]).unwrap();
        let mut good = Chain::new(model(), Point::new(0.0, 0.0), 2);
        let p_good = good
            .cycle(
                to,
                &[Point::new(9.0, 9.0), Point::new(9.0, -9.0)],
                &[true, true],
            )
            .unwrap();
        assert!(
            p_bad.position_sigma() > 5.0 * p_good.position_sigma(),
            "{} vs {}",
            p_bad.position_sigma(),
            p_good.position_sigma()
        );
    }

    #[test]
    fn one_child_cannot_fix_the_pose() {
        let mut chain = Chain::new(model(), Point::new(0.0, 0.0), 1);
        let r = chain.cycle(Point::new(5.0, 0.0), &[Point::new(2.0, 3.0)], &[true]);
        assert_eq!(r, Err(ChainError::TooFewChildren(1)));
    }

    #[test]
    fn error_grows_along_a_chain() {
        let mut chain = Chain::new(model(), Point::new(0.0, 0.0), 2);
        let mut last = 0.0;
        for k in 0..6 {
            let x = 10.0 * k as f64;
            let kids = [Point::new(x + 5.0, 4.0), Point::new(x + 5.0, -4.0)];
            let p = chain
                .cycle(Point::new(x + 10.0, 0.0), &kids, &[true, true])
                .unwrap();
            assert!(p.position_sigma() > last);
            last = p.position_sigma();
        }
        let (a, b, _) = chain.pose().ellipse();
        assert!(a >= b && (a * a + b * b - chain.pose().position_sigma().powi(2)).abs() < 1e-15);
    }
}
