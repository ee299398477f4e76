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

use super::geometry::TargetPoint;
use super::model::Model;
use crate::geom::{Cell, Point};
use crate::grid::OccupancyGrid;
use crate::sensing::{target_in_sight, LinkRule};

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

    /// The pose covariance of a station's block (its first `station_dim` rows
    /// and columns) of `cov`.
    pub fn from_matrix(model: &Model, cov: &DMatrix<f64>) -> Self {
        Self::of(model, cov)
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
/// covariance `[station, child 1, …, child n, target …]` (targets in the order
/// the team first measured them).
#[derive(Debug, Clone)]
pub struct Chain {
    model: Model,
    station: DVector<f64>,
    points: Vec<Option<DVector<f64>>>,
    /// Every target the team knows of, measured or not.
    targets: Vec<Target>,
    /// The targets in the joint state, in its order.
    order: Vec<usize>,
    cov: DMatrix<f64>,
    /// The information of the points (children, then targets) before the last
    /// resection (for the Monte Carlo estimator, which weights its prior the same
    /// way).
    prior_info: DMatrix<f64>,
}

/// A target as the chain holds it.
#[derive(Debug, Clone)]
struct Target {
    /// Where it stands, the model's point state.
    point: DVector<f64>,
    /// The given point.
    given: TargetPoint,
    /// Its place in [`Chain::order`] once measured.
    slot: Option<usize>,
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
            targets: Vec::new(),
            order: Vec::new(),
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

    /// The joint covariance `[station, child 1, …, measured targets …]` (children
    /// never measured have zero blocks).
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

    /// The information matrix of the points (children, then measured targets)
    /// that the last resection started from.
    pub(crate) fn prior_info(&self) -> &DMatrix<f64> {
        &self.prior_info
    }

    /// The measured targets in the joint state's order.
    pub fn target_order(&self) -> &[usize] {
        &self.order
    }

    /// The registered targets (measured or not) that a station at `at` measures:
    /// within the instrument's range `rule` and in certain line of sight on
    /// `knowledge` ([`target_in_sight`]).
    pub fn in_sight(&self, knowledge: &OccupancyGrid, at: Cell, rule: &LinkRule) -> Vec<usize> {
        if self.targets.is_empty() {
            return Vec::new();
        }
        self.targets
            .iter()
            .enumerate()
            .filter(|(_, t)| target_in_sight(knowledge, at, t.given.position, rule))
            .map(|(i, _)| i)
            .collect()
    }

    /// Registers a target or control point, not measured yet; returns its index.
    pub fn add_target(&mut self, target: TargetPoint) -> usize {
        self.targets.push(Target {
            point: self.model.point_at(target.position, target.z),
            given: target,
            slot: None,
        });
        self.targets.len() - 1
    }

    /// Every target registered, in the order of [`Self::add_target`].
    pub fn targets(&self) -> impl Iterator<Item = &TargetPoint> + '_ {
        self.targets.iter().map(|t| &t.given)
    }

    /// Number of targets registered.
    pub fn target_count(&self) -> usize {
        self.targets.len()
    }

    /// Whether target `t` has been measured (is in the joint state).
    pub fn measured(&self, t: usize) -> bool {
        self.targets.get(t).is_some_and(|t| t.slot.is_some())
    }

    /// The offset of target `t` in the joint state, once measured.
    pub fn target_offset(&self, t: usize) -> Option<usize> {
        let slot = self.targets.get(t)?.slot?;
        Some(self.points_end() + slot * self.model.point_dim())
    }

    /// The covariance block of target `t`'s point, once measured.
    pub fn target_covariance(&self, t: usize) -> Option<DMatrix<f64>> {
        let o = self.target_offset(t)?;
        let dp = self.model.point_dim();
        Some(self.cov.view((o, o), (dp, dp)).into_owned())
    }

    fn child_offset(&self, i: usize) -> usize {
        self.model.station_dim() + i * self.model.point_dim()
    }

    /// Where the children's blocks end and the targets' begin.
    fn points_end(&self) -> usize {
        self.child_offset(self.points.len())
    }

    /// One CPS cycle without targets: [`Self::cycle_sighting`] with none in
    /// sight.
    pub fn cycle(
        &mut self,
        to: Point,
        children: &[Point],
        moved: &[bool],
    ) -> Result<PoseCovariance, ChainError> {
        self.cycle_sighting(to, children, moved, &[])
    }

    /// One CPS cycle: the children `moved` (or never measured) get new points at
    /// `children` measured from the parent's current station, then the parent
    /// moves to `to` and is fixed by resection on every child and on the targets
    /// `sighted` that are measured already (a control point seen for the first
    /// time enters with its known coordinates); the free targets it sees for the
    /// first time are then measured from the new station. Returns the new pose's
    /// covariance.
    pub fn cycle_sighting(
        &mut self,
        to: Point,
        children: &[Point],
        moved: &[bool],
        sighted: &[usize],
    ) -> Result<PoseCovariance, ChainError> {
        let n = self.points.len();
        debug_assert_eq!(children.len(), n);
        if n < 2 {
            return Err(ChainError::TooFewChildren(n));
        }
        for (i, &c) in children.iter().enumerate() {
            if moved.get(i).copied().unwrap_or(true) || self.points[i].is_none() {
                let o = self.child_offset(i);
                self.forward(o, self.model.point(c));
                self.points[i] = Some(self.model.point(c));
            }
        }
        let known = self.enter_sighted(sighted);
        self.resect(self.model.station(to, 0.0), &known)?;
        self.forward_new(sighted);
        Ok(self.pose())
    }

    /// [`Self::cycle_sighting`] to the centre of cell `to`, with the targets a
    /// station there measures on `knowledge` under `rule` ([`Self::in_sight`]).
    pub fn cycle_on(
        &mut self,
        knowledge: &OccupancyGrid,
        rule: &LinkRule,
        to: Cell,
        children: &[Point],
        moved: &[bool],
    ) -> Result<PoseCovariance, ChainError> {
        let sighted = self.in_sight(knowledge, to, rule);
        let p = knowledge.geometry().cell_center(to);
        self.cycle_sighting(p, children, moved, &sighted)
    }

    /// The targets `sighted` measured from the parent's current station: a free
    /// target seen for the first time gets its point from this measurement (a
    /// target left here by a child), a control point or a target measured before
    /// refines the joint state (first order, the Kalman update).
    pub fn sight_here(&mut self, sighted: &[usize]) -> Result<(), ChainError> {
        let new: Vec<usize> = sighted
            .iter()
            .copied()
            .filter(|&t| {
                self.targets
                    .get(t)
                    .is_some_and(|x| x.slot.is_none() && x.given.control_sigma.is_none())
            })
            .collect();
        let known = self.enter_sighted(sighted);
        self.update_here(&known)?;
        self.forward_new(&new);
        Ok(())
    }

    /// The control points in `sighted` enter the joint state ([`Self::enter_controls`]);
    /// returns the targets of `sighted` in it (measured before, or control).
    fn enter_sighted(&mut self, sighted: &[usize]) -> Vec<usize> {
        self.enter_controls(sighted);
        sighted
            .iter()
            .copied()
            .filter(|&t| self.measured(t))
            .collect()
    }

    /// Control points in `sighted` not in the joint state yet enter it with their
    /// known coordinates' covariance, uncorrelated with everything.
    fn enter_controls(&mut self, sighted: &[usize]) {
        let dp = self.model.point_dim();
        for &t in sighted {
            let Some(target) = self.targets.get(t) else {
                continue;
            };
            let (None, Some(sigma)) = (target.slot, target.given.control_sigma) else {
                continue;
            };
            let o = self.grow(t);
            for a in 0..dp {
                self.cov[(o + a, o + a)] = sigma * sigma;
            }
        }
    }

    /// Free targets in `sighted` not in the joint state yet: measured from the
    /// current station.
    fn forward_new(&mut self, sighted: &[usize]) {
        for &t in sighted {
            let Some(target) = self.targets.get(t) else {
                continue;
            };
            if target.slot.is_some() || target.given.control_sigma.is_some() {
                continue;
            }
            let c = target.point.clone();
            let o = self.grow(t);
            self.forward(o, c);
        }
    }

    /// Appends target `t` to the joint state with zero blocks; returns its offset.
    fn grow(&mut self, t: usize) -> usize {
        let dp = self.model.point_dim();
        let old = self.cov.nrows();
        self.cov = self.cov.clone().resize(old + dp, old + dp, 0.0);
        self.targets[t].slot = Some(self.order.len());
        self.order.push(t);
        old
    }

    /// Step 1 for the point at offset `o`: the point `c` measured from the
    /// current station.
    fn forward(&mut self, o: usize, c: DVector<f64>) {
        let m = &self.model;
        let (ds, dp) = (m.station_dim(), m.point_dim());
        let s = self.station.as_slice();
        let z = m.observe(s, c.as_slice());
        let r = m.noise(s, c.as_slice());
        let (fs, fz) = m.forward_jacobians(s, z.as_slice());
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
    }

    /// The points in the joint state after the station, with their offsets: the
    /// children's, then the `targets` given (measured ones).
    fn observed(&self, targets: &[usize]) -> Result<Vec<(usize, DVector<f64>)>, ChainError> {
        let mut out = Vec::with_capacity(self.points.len() + targets.len());
        for (i, p) in self.points.iter().enumerate() {
            let c = p.as_ref().ok_or(ChainError::Singular)?;
            out.push((self.child_offset(i), c.clone()));
        }
        for &t in targets {
            let o = self.target_offset(t).ok_or(ChainError::Singular)?;
            out.push((o, self.targets[t].point.clone()));
        }
        Ok(out)
    }

    /// Step 2: the parent at the new station `u` (nominal pose), estimated with
    /// every child's point and the measured `targets` it sees.
    fn resect(&mut self, u: DVector<f64>, targets: &[usize]) -> Result<(), ChainError> {
        let m = &self.model;
        let (ds, dp) = (m.station_dim(), m.point_dim());
        let nc = self.cov.nrows() - ds;
        // The points' prior after the old station is dropped.
        let pc = self.cov.view((ds, ds), (nc, nc)).into_owned();
        let info_c = invert_spd(&pc).ok_or(ChainError::Singular)?;
        let mut info = DMatrix::zeros(ds + nc, ds + nc);
        info.view_mut((ds, ds), (nc, nc)).copy_from(&info_c);
        for (o, c) in self.observed(targets)? {
            let (hs, hc) = m.jacobians(u.as_slice(), c.as_slice());
            let w = invert_spd(&m.noise(u.as_slice(), c.as_slice())).ok_or(ChainError::Singular)?;
            let ss = hs.transpose() * &w * &hs;
            let sc = hs.transpose() * &w * &hc;
            let cc = hc.transpose() * &w * &hc;
            add(&mut info, 0, 0, &ss);
            add(&mut info, 0, o, &sc);
            add(&mut info, o, 0, &sc.transpose());
            add(&mut info, o, o, &cc);
        }
        let _ = dp;
        let cov = invert_spd(&info).ok_or(ChainError::Singular)?;
        self.cov = symmetrize(cov);
        self.station = u;
        self.prior_info = info_c;
        Ok(())
    }

    /// The measured `targets` observed from the current station: the Kalman
    /// update of the joint state, `P − P Hᵀ (H P Hᵀ + R)⁻¹ H P` (no inverse of
    /// `P`, which is singular while the station is known exactly).
    fn update_here(&mut self, targets: &[usize]) -> Result<(), ChainError> {
        if targets.is_empty() {
            return Ok(());
        }
        let m = &self.model;
        let (ds, dp, k) = (m.station_dim(), m.point_dim(), m.obs_dim());
        let total = self.cov.nrows();
        let rows = k * targets.len();
        let mut h = DMatrix::zeros(rows, total);
        let mut r = DMatrix::zeros(rows, rows);
        let s = self.station.clone();
        for (j, &t) in targets.iter().enumerate() {
            let o = self.target_offset(t).ok_or(ChainError::Singular)?;
            let c = &self.targets[t].point;
            let (hs, hc) = m.jacobians(s.as_slice(), c.as_slice());
            h.view_mut((j * k, 0), (k, ds)).copy_from(&hs);
            h.view_mut((j * k, o), (k, dp)).copy_from(&hc);
            r.view_mut((j * k, j * k), (k, k))
                .copy_from(&m.noise(s.as_slice(), c.as_slice()));
        }
        let ph = &self.cov * h.transpose();
        let innovation = &h * &ph + r;
        let inv = invert_spd(&innovation).ok_or(ChainError::Singular)?;
        let cov = &self.cov - &ph * inv * ph.transpose();
        self.cov = symmetrize(cov);
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
