//! What a placement of the children costs in accuracy: the predicted covariance of
//! the parent's next pose as a function of where the moving children stand, in a
//! form cheap enough to search (the children's `min-error` strategy).
//!
//! In: the chain before a cycle, the parent's next position, which children stay.
//! Out: an [`Objective`]: for each spot a moving child might take, its 3×3
//! information `J(c)` about the next pose, and for any sum of them the predicted
//! `σx² + σy² + L²·σω²` of the next pose (`L`: the cycle's leg, so that a heading
//! error counts as the position error it causes over one more such leg).
//!
//! # Why the movers add up
//!
//! A moving child's new point is measured from the current station `p`; an error
//! `δp` of that station moves the point rigidly with it, and a rigid motion of the
//! station and its points moves the next station `u` rigidly too (`δu = G·δp`)
//! without changing any measurement from it. So in the coordinates
//! `u' = u − G·p` a mover's measurements inform `u'` alone, through the noise of
//! its own two measurements: an information `J(c) = H_uᵀ N⁻¹ H_u` with
//! `N = H_c F_z R_p F_zᵀ H_cᵀ + R_u`. The staying children and the prior of
//! `(p, stayers)` give constants, and marginalising them out:
//!
//! ```text
//! Σ_u(J) = (I − D)(J + K)⁻¹(I − D)ᵀ + Q,   J = Σ over movers of J(c)
//! ```
//!
//! with `K`, `D`, `Q` fixed 3×3 matrices (docs/ACCURACY.md). The objective
//! `tr(W Σ_u)` is therefore `tr(V (J + K)⁻¹) + const`, decreasing in `J` in the
//! Löwner order, which a branch and bound can use. Planar model (in 3D mode the
//! horizontal part is what the children's placement decides).

use nalgebra::{DMatrix, Matrix2, Matrix2x3, Matrix3};

use super::chain::Chain;
use super::instrument::Instrument;
use super::model::Model;
use crate::geom::Point;

/// The cost of the next pose as a function of the movers' information.
#[derive(Debug, Clone)]
pub struct Objective {
    model: Model,
    from: Point,
    to: Point,
    k: Matrix3<f64>,
    v: Matrix3<f64>,
    constant: f64,
}

impl Objective {
    /// The objective of the cycle that takes the parent of `chain` to `to` with the
    /// children `stayers` keeping their points (each measured already) and the
    /// others moving. `None` when a stayer has no point yet.
    pub fn new(chain: &Chain, to: Point, stayers: &[usize]) -> Option<Objective> {
        Self::with_targets(chain, to, stayers, &[])
    }

    /// [`Self::new`] for a next station that also measures the `targets` (indices
    /// into the chain's targets; those not measured yet add nothing: a free
    /// target's first measurement fixes only its own point, and a control point
    /// not yet in the state is left out, a small underestimate of the
    /// information).
    pub fn with_targets(
        chain: &Chain,
        to: Point,
        stayers: &[usize],
        targets: &[usize],
    ) -> Option<Objective> {
        let mut inst: Instrument = chain.model().instrument;
        inst.three_d = false;
        let model = Model::new(inst);
        let cm = chain.model();
        let (ds, dp) = (cm.station_dim(), cm.point_dim());
        let from = chain.position();
        let points = chain.points();
        let full = chain.covariance();
        // The planar prior of (p, stayers): station x, y, ω and each stayer's x, y.
        let mut index = vec![0, 1, ds - 1];
        // Every point the next station measures besides the movers: the
        // stayers', then the measured targets'.
        let mut fixed: Vec<Point> = Vec::with_capacity(stayers.len() + targets.len());
        for &s in stayers {
            fixed.push(points.get(s).copied().flatten()?);
            let o = ds + s * dp;
            index.extend([o, o + 1]);
        }
        let positions: Vec<Point> = chain.targets().map(|t| t.position).collect();
        for &t in targets {
            if let Some(o) = chain.target_offset(t) {
                fixed.push(positions[t]);
                index.extend([o, o + 1]);
            }
        }
        let dr = index.len();
        let prior = DMatrix::from_fn(dr, dr, |i, j| full[(index[i], index[j])]);
        let g = rigid(from, to);
        // The stayers' information on (u', r').
        let u = [to.x, to.y, 0.0];
        let mut s = DMatrix::zeros(3 + dr, 3 + dr);
        for (k, &c) in fixed.iter().enumerate() {
            let (hu, hc) = model.jacobians(&u, &[c.x, c.y]);
            let w = model.noise(&u, &[c.x, c.y]).try_inverse()?;
            let mut row = DMatrix::zeros(2, 3 + dr);
            row.view_mut((0, 0), (2, 3)).copy_from(&hu);
            let hug = &hu * dm3(&g);
            row.view_mut((0, 3), (2, 3)).copy_from(&hug);
            row.view_mut((0, 3 + 3 + 2 * k), (2, 2)).copy_from(&hc);
            s += row.transpose() * w * row;
        }
        let a = m3(&s.view((0, 0), (3, 3)).into_owned());
        let b = s.view((0, 3), (3, dr)).into_owned();
        let srr = s.view((3, 3), (dr, dr)).into_owned();
        // C⁻¹ = P (I + S_rr P)⁻¹, no inverse of the (possibly exact) prior.
        let c_inv = &prior * (DMatrix::identity(dr, dr) + &srr * &prior).try_inverse()?;
        let mut t = DMatrix::zeros(3, dr);
        t.view_mut((0, 0), (3, 3)).copy_from(&dm3(&g));
        let k = a - m3(&(&b * &c_inv * b.transpose()));
        let d = m3(&(&t * &c_inv * b.transpose()));
        let q = m3(&(&t * &c_inv * t.transpose()));
        let leg2 = (to.x - from.x).powi(2) + (to.y - from.y).powi(2);
        let w = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 1.0, leg2));
        let i_d = Matrix3::identity() - d;
        let v = i_d.transpose() * w * i_d;
        Some(Objective {
            model,
            from,
            to,
            k,
            v,
            constant: (w * q).trace(),
        })
    }

    /// The information about the next pose of a moving child at `c`: its point
    /// measured from the current station, then measured from the next.
    ///
    /// The planar model's observation, Jacobians and noise (the objective's
    /// model is planar), written out in fixed-size matrices: the search asks
    /// for thousands of spots a cycle.
    pub fn mover_info(&self, c: Point) -> Matrix3<f64> {
        let i = &self.model.instrument;
        let sa2 = i.angle_sigma * i.angle_sigma;
        // The station's circle reads 0 at both stations.
        let omega = 0.0;
        // From the current station: the point as measured, `F_z` and `R`.
        let (dx, dy) = (c.x - self.from.x, c.y - self.from.y);
        let d = (dx * dx + dy * dy).sqrt();
        let theta = omega + (dy.atan2(dx) - omega);
        let (st, ct) = theta.sin_cos();
        let fz = Matrix2::new(ct, -d * st, st, d * ct);
        let sd = i.distance_sigma_at(d);
        let rp = Matrix2::new(sd * sd, 0.0, 0.0, sa2);
        // From the next station: `H_c`, `H_u` and `R`.
        let (ex, ey) = (c.x - self.to.x, c.y - self.to.y);
        let h2 = ex * ex + ey * ey;
        let e = h2.sqrt();
        let hc = Matrix2::new(ex / e, ey / e, -ey / h2, ex / h2);
        let hu = Matrix2x3::new(
            -hc[(0, 0)],
            -hc[(0, 1)],
            0.0,
            -hc[(1, 0)],
            -hc[(1, 1)],
            -1.0,
        );
        let su = i.distance_sigma_at(e);
        let ru = Matrix2::new(su * su, 0.0, 0.0, sa2);
        let n = hc * fz * rp * fz.transpose() * hc.transpose() + ru;
        match n.try_inverse() {
            Some(ni) => hu.transpose() * ni * hu,
            None => Matrix3::zeros(),
        }
    }

    /// The square root of what no placement can remove: the value with infinitely
    /// informative movers (the error the pose inherits), metres.
    pub fn floor(&self) -> f64 {
        self.constant.max(0.0).sqrt()
    }

    /// The predicted `σx² + σy² + L²·σω²` of the next pose when the movers'
    /// information adds up to `j` (`+∞` when it does not fix the pose).
    pub fn value(&self, j: &Matrix3<f64>) -> f64 {
        let m = j + self.k;
        // Scaled to a unit diagonal, the information must be safely definite: a
        // geometry that nearly fails to fix the pose is as good as failing.
        let d = m
            .diagonal()
            .map(|x| if x > 0.0 { 1.0 / x.sqrt() } else { 0.0 });
        let s = |a: usize, b: usize| m[(a, b)] * d[a] * d[b];
        // Cholesky factor of the scaled matrix, written out (the search's hot
        // loop): a NaN or a pivot under 1e-7 means not safely definite.
        let l00 = s(0, 0).sqrt();
        let l10 = s(1, 0) / l00;
        let l20 = s(2, 0) / l00;
        let l11 = (s(1, 1) - l10 * l10).sqrt();
        let l21 = (s(2, 1) - l20 * l10) / l11;
        let l22 = (s(2, 2) - l20 * l20 - l21 * l21).sqrt();
        // (`p > 1e-7` is false for a NaN pivot too.)
        if ![l00, l11, l22].iter().all(|&p| p > 1e-7) {
            return f64::INFINITY;
        }
        // L⁻¹ (lower triangular), then the scaled inverse (L⁻¹)ᵀ L⁻¹.
        let (i00, i11, i22) = (1.0 / l00, 1.0 / l11, 1.0 / l22);
        let i10 = -l10 * i00 * i11;
        let i21 = -l21 * i11 * i22;
        let i20 = -(l20 * i00 + l21 * i10) * i22;
        let inv = [
            [
                i00 * i00 + i10 * i10 + i20 * i20,
                i10 * i11 + i20 * i21,
                i20 * i22,
            ],
            [0.0, i11 * i11 + i21 * i21, i21 * i22],
            [0.0, 0.0, i22 * i22],
        ];
        let mut v = self.constant;
        for a in 0..3 {
            for b in 0..3 {
                let x = if a <= b { inv[a][b] } else { inv[b][a] };
                v += self.v[(b, a)] * x * d[a] * d[b];
            }
        }
        if v.is_finite() && v >= 0.0 {
            v
        } else {
            f64::INFINITY
        }
    }
}

/// `δu = G·δp`: how the next station moves with a rigid motion of the current one.
fn rigid(from: Point, to: Point) -> Matrix3<f64> {
    Matrix3::new(
        1.0,
        0.0,
        -(to.y - from.y),
        0.0,
        1.0,
        to.x - from.x,
        0.0,
        0.0,
        1.0,
    )
}

fn m3(m: &DMatrix<f64>) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[(i, j)])
}

fn dm3(m: &Matrix3<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(3, 3, |i, j| m[(i, j)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::InstrumentConfig;
    use proptest::prelude::*;

    fn model() -> Model {
        Model::new(Instrument::from_config(&InstrumentConfig::default()))
    }

    /// `σx² + σy² + L²·σω²` of the chain's pose after a leg from `from`.
    fn cost(chain: &Chain, from: Point) -> f64 {
        let p = chain.pose();
        let to = chain.position();
        let leg2 = (to.x - from.x).powi(2) + (to.y - from.y).powi(2);
        p.xx + p.yy + leg2 * p.heading
    }

    /// The mover's information through the model's general (dynamic-size)
    /// observation, Jacobians and noise, as first written.
    fn mover_info_by_the_model(o: &Objective, c: Point) -> Matrix3<f64> {
        let m2 = |m: &DMatrix<f64>| Matrix2::from_fn(|i, j| m[(i, j)]);
        let m = &o.model;
        let p = [o.from.x, o.from.y, 0.0];
        let u = [o.to.x, o.to.y, 0.0];
        let cc = [c.x, c.y];
        let zp = m.observe(&p, &cc);
        let (_, fz) = m.forward_jacobians(&p, zp.as_slice());
        let rp = m2(&m.noise(&p, &cc));
        let (hu, hc) = m.jacobians(&u, &cc);
        let hu = Matrix2x3::from_fn(|i, j| hu[(i, j)]);
        let (hc, fz) = (m2(&hc), m2(&fz));
        let ru = m2(&m.noise(&u, &cc));
        let n = hc * fz * rp * fz.transpose() * hc.transpose() + ru;
        match n.try_inverse() {
            Some(ni) => hu.transpose() * ni * hu,
            None => Matrix3::zeros(),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 100, ..ProptestConfig::default() })]

        /// The written-out information is the model's, bit for bit.
        #[test]
        fn mover_info_is_the_models(
            from in (-50.0f64..50.0, -50.0f64..50.0),
            to in (-50.0f64..50.0, -50.0f64..50.0),
            spots in proptest::collection::vec((-60.0f64..60.0, -60.0f64..60.0), 1..20),
        ) {
            let start = Point::new(from.0, from.1);
            let chain = Chain::new(model(), start, 2);
            let objective = Objective::new(&chain, Point::new(to.0, to.1), &[]).unwrap();
            for (x, y) in spots {
                let c = Point::new(x, y);
                prop_assert_eq!(objective.mover_info(c), mover_info_by_the_model(&objective, c));
            }
        }

        /// The objective equals the propagated chain, whatever stays and moves.
        #[test]
        fn objective_equals_the_chain(
            first in proptest::collection::vec((-15.0f64..15.0, -15.0f64..15.0), 3),
            to1 in (-15.0f64..15.0, -15.0f64..15.0),
            to2 in (-15.0f64..15.0, -15.0f64..15.0),
            next in proptest::collection::vec((-15.0f64..15.0, -15.0f64..15.0), 3),
            stay in proptest::collection::vec(any::<bool>(), 3),
        ) {
            let pt = |p: (f64, f64)| Point::new(p.0, p.1);
            let start = Point::new(0.0, 0.0);
            let kids: Vec<Point> = first.iter().map(|&p| pt(p)).collect();
            let (to1, to2) = (pt(to1), pt(to2));
            let far = |c: &Point, s: Point| c.distance(s) > 1.5;
            prop_assume!(kids.iter().all(|c| far(c, start) && far(c, to1) && far(c, to2)));
            let mut chain = Chain::new(model(), start, 3);
            prop_assume!(chain.cycle(to1, &kids, &[true; 3]).is_ok());
            let stayers: Vec<usize> = (0..3).filter(|&i| stay[i]).collect();
            let moved: Vec<bool> = stay.iter().map(|s| !s).collect();
            let spots: Vec<Point> = (0..3).map(|i| if stay[i] { kids[i] } else { pt(next[i]) }).collect();
            prop_assume!(spots.iter().all(|c| far(c, to1) && far(c, to2)));
            let objective = Objective::new(&chain, to2, &stayers).unwrap();
            let mut j = Matrix3::zeros();
            for i in 0..3 {
                if !stay[i] {
                    j += objective.mover_info(spots[i]);
                }
            }
            let predicted = objective.value(&j);
            let mut after = chain.clone();
            prop_assume!(after.cycle(to2, &spots, &moved).is_ok());
            let exact = cost(&after, to1);
            if predicted.is_infinite() {
                // The objective calls a geometry that nearly fails to fix the pose
                // failed (`Objective::value`); the chain's exact inversion still
                // succeeds there, with an error of tens of metres or more.
                prop_assert!(exact > 1e3, "{} vs {}", predicted, exact);
            } else {
                // Both sides invert the chain's covariance: their rounding grows
                // with its condition number κ (measured over 2,000 cases: at most
                // 381 κ ε), so they must agree within 1000 κ ε — 2e-10 for a
                // well-conditioned chain (κ ≈ 1e3), 4e-6 for κ ≈ 1.7e7.
                let e = chain.covariance().symmetric_eigenvalues();
                let tolerance = 1e3 * (e.max() / e.min()) * f64::EPSILON;
                prop_assert!(
                    ((predicted - exact) / exact).abs() < tolerance,
                    "{} vs {} (tolerance {})", predicted, exact, tolerance
                );
            }
        }
    }
}
