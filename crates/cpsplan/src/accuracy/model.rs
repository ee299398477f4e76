//! The observation model of one CPS link: what the instrument on the parent
//! measures to a child's marker, its Jacobians and its noise, and the inverse (a
//! child's point from the parent's pose and one measurement).
//!
//! In: a station pose (position and the orientation `ω` of the instrument's
//! horizontal circle) and a point. Out: the observation vector and its
//! derivatives.
//!
//! - Planar: state of a station `[x, y, ω]`, of a point `[x, y]`; observation
//!   `[d, r]` with `d = |c − p|` and `r = atan2(Δy, Δx) − ω`.
//! - 3D: station `[x, y, z, ω]` (levelled), point `[x, y, z]`; observation
//!   `[s, r, ζ]` with the slope distance `s`, the same direction `r` and the zenith
//!   angle `ζ = atan2(√(Δx² + Δy²), Δz)`.
//!
//! Noise: `σ(d) = a + b·d` for the distance (the makers' form), the angle
//! accuracy for each angle, independent.

use nalgebra::{DMatrix, DVector};

use super::instrument::Instrument;
use crate::geom::Point;

/// The observation model of an instrument.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    /// The instrument.
    pub instrument: Instrument,
}

impl Model {
    /// The model of `instrument`.
    pub fn new(instrument: Instrument) -> Self {
        Self { instrument }
    }

    /// Whether the model is 3D.
    pub fn three_d(&self) -> bool {
        self.instrument.three_d
    }

    /// Size of a station's state.
    pub fn station_dim(&self) -> usize {
        if self.three_d() {
            4
        } else {
            3
        }
    }

    /// Size of a point's state.
    pub fn point_dim(&self) -> usize {
        if self.three_d() {
            3
        } else {
            2
        }
    }

    /// Size of one link's observation.
    pub fn obs_dim(&self) -> usize {
        if self.three_d() {
            3
        } else {
            2
        }
    }

    /// The state of a station at `p` with its circle oriented at `omega`.
    pub fn station(&self, p: Point, omega: f64) -> DVector<f64> {
        if self.three_d() {
            DVector::from_vec(vec![p.x, p.y, self.instrument.instrument_height, omega])
        } else {
            DVector::from_vec(vec![p.x, p.y, omega])
        }
    }

    /// The state of a marker at `p`.
    pub fn point(&self, p: Point) -> DVector<f64> {
        if self.three_d() {
            DVector::from_vec(vec![p.x, p.y, self.instrument.marker_height])
        } else {
            DVector::from_vec(vec![p.x, p.y])
        }
    }

    /// The state of a target at `p`, `z` metres over the floor in 3D mode (the
    /// markers' height when `None`).
    pub fn point_at(&self, p: Point, z: Option<f64>) -> DVector<f64> {
        if self.three_d() {
            DVector::from_vec(vec![p.x, p.y, z.unwrap_or(self.instrument.marker_height)])
        } else {
            DVector::from_vec(vec![p.x, p.y])
        }
    }

    /// The orientation `ω` of a station state.
    fn omega(&self, s: &[f64]) -> f64 {
        s[self.station_dim() - 1]
    }

    /// The observation from station `s` to point `c`.
    pub fn observe(&self, s: &[f64], c: &[f64]) -> DVector<f64> {
        let (dx, dy) = (c[0] - s[0], c[1] - s[1]);
        let r = dy.atan2(dx) - self.omega(s);
        if self.three_d() {
            let dz = c[2] - s[2];
            let dh = (dx * dx + dy * dy).sqrt();
            let slope = (dh * dh + dz * dz).sqrt();
            DVector::from_vec(vec![slope, r, dh.atan2(dz)])
        } else {
            DVector::from_vec(vec![(dx * dx + dy * dy).sqrt(), r])
        }
    }

    /// The derivatives of [`Self::observe`] with respect to the station and to
    /// the point.
    pub fn jacobians(&self, s: &[f64], c: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let (dx, dy) = (c[0] - s[0], c[1] - s[1]);
        let h2 = dx * dx + dy * dy;
        let (m, ds, dp) = (self.obs_dim(), self.station_dim(), self.point_dim());
        let mut hc = DMatrix::zeros(m, dp);
        if self.three_d() {
            let dz = c[2] - s[2];
            let dh = h2.sqrt();
            let s2 = h2 + dz * dz;
            let sl = s2.sqrt();
            let row = [
                [dx / sl, dy / sl, dz / sl],
                [-dy / h2, dx / h2, 0.0],
                [dz * dx / (dh * s2), dz * dy / (dh * s2), -dh / s2],
            ];
            for (i, r) in row.iter().enumerate() {
                for (j, &v) in r.iter().enumerate() {
                    hc[(i, j)] = v;
                }
            }
        } else {
            let d = h2.sqrt();
            hc[(0, 0)] = dx / d;
            hc[(0, 1)] = dy / d;
            hc[(1, 0)] = -dy / h2;
            hc[(1, 1)] = dx / h2;
        }
        let mut hs = DMatrix::zeros(m, ds);
        for i in 0..m {
            for j in 0..dp {
                hs[(i, j)] = -hc[(i, j)];
            }
        }
        // The direction is read on the station's circle.
        hs[(1, ds - 1)] = -1.0;
        (hs, hc)
    }

    /// The covariance of the observation from `s` to `c` (diagonal).
    pub fn noise(&self, s: &[f64], c: &[f64]) -> DMatrix<f64> {
        let z = self.observe(s, c);
        let i = &self.instrument;
        let sd = i.distance_sigma_at(z[0]);
        let sa2 = i.angle_sigma * i.angle_sigma;
        let mut r = DMatrix::from_diagonal_element(self.obs_dim(), self.obs_dim(), sa2);
        r[(0, 0)] = sd * sd;
        r
    }

    /// The covariance of a measurement that read `z` (diagonal; the distance's
    /// σ at the distance read, as survey software weights it).
    pub fn noise_of(&self, z: &[f64]) -> DMatrix<f64> {
        let i = &self.instrument;
        let sd = i.distance_sigma_at(z[0]);
        let sa2 = i.angle_sigma * i.angle_sigma;
        let mut r = DMatrix::from_diagonal_element(self.obs_dim(), self.obs_dim(), sa2);
        r[(0, 0)] = sd * sd;
        r
    }

    /// The point that station `s` measures with observation `z`.
    pub fn forward(&self, s: &[f64], z: &[f64]) -> DVector<f64> {
        let theta = self.omega(s) + z[1];
        if self.three_d() {
            let dh = z[0] * z[2].sin();
            DVector::from_vec(vec![
                s[0] + dh * theta.cos(),
                s[1] + dh * theta.sin(),
                s[2] + z[0] * z[2].cos(),
            ])
        } else {
            DVector::from_vec(vec![s[0] + z[0] * theta.cos(), s[1] + z[0] * theta.sin()])
        }
    }

    /// The derivatives of [`Self::forward`] with respect to the station and to the
    /// observation.
    pub fn forward_jacobians(&self, s: &[f64], z: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
        let theta = self.omega(s) + z[1];
        let (st, ct) = theta.sin_cos();
        let (ds, dp, m) = (self.station_dim(), self.point_dim(), self.obs_dim());
        let mut fs = DMatrix::zeros(dp, ds);
        for i in 0..dp {
            fs[(i, i)] = 1.0;
        }
        let mut fz = DMatrix::zeros(dp, m);
        if self.three_d() {
            let (sz, cz) = z[2].sin_cos();
            let dh = z[0] * sz;
            fs[(0, 3)] = -dh * st;
            fs[(1, 3)] = dh * ct;
            let cols = [
                [sz * ct, sz * st, cz],
                [-dh * st, dh * ct, 0.0],
                [z[0] * cz * ct, z[0] * cz * st, -z[0] * sz],
            ];
            for (j, col) in cols.iter().enumerate() {
                for (i, &v) in col.iter().enumerate() {
                    fz[(i, j)] = v;
                }
            }
        } else {
            let d = z[0];
            fs[(0, 2)] = -d * st;
            fs[(1, 2)] = d * ct;
            fz[(0, 0)] = ct;
            fz[(1, 0)] = st;
            fz[(0, 1)] = -d * st;
            fz[(1, 1)] = d * ct;
        }
        (fs, fz)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::config::InstrumentConfig;

    /// A planar and a 3D model of the default instrument.
    pub(in crate::accuracy) fn models() -> [Model; 2] {
        let planar = Model::new(Instrument::from_config(&InstrumentConfig::default()));
        let mut i = planar.instrument;
        i.three_d = true;
        [planar, Model::new(i)]
    }

    /// Central differences of `f` at `x`.
    fn numeric(f: impl Fn(&[f64]) -> DVector<f64>, x: &[f64], rows: usize) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(rows, x.len());
        for k in 0..x.len() {
            let (mut a, mut b) = (x.to_vec(), x.to_vec());
            a[k] += 1e-6;
            b[k] -= 1e-6;
            let d = (f(&a) - f(&b)) / 2e-6;
            for i in 0..rows {
                j[(i, k)] = d[i];
            }
        }
        j
    }

    #[test]
    fn jacobians_match_central_differences() {
        for m in models() {
            let s = m.station(Point::new(1.0, 2.0), 0.3);
            let c = m.point(Point::new(7.5, -3.0));
            let (hs, hc) = m.jacobians(s.as_slice(), c.as_slice());
            let ns = numeric(|x| m.observe(x, c.as_slice()), s.as_slice(), m.obs_dim());
            let nc = numeric(|x| m.observe(s.as_slice(), x), c.as_slice(), m.obs_dim());
            assert!((hs - ns).abs().max() < 1e-6);
            assert!((hc - nc).abs().max() < 1e-6);
            let z = m.observe(s.as_slice(), c.as_slice());
            let back = m.forward(s.as_slice(), z.as_slice());
            assert!((back - &c).abs().max() < 1e-12);
            let (fs, fz) = m.forward_jacobians(s.as_slice(), z.as_slice());
            let nfs = numeric(|x| m.forward(x, z.as_slice()), s.as_slice(), m.point_dim());
            let nfz = numeric(|x| m.forward(s.as_slice(), x), z.as_slice(), m.point_dim());
            assert!((fs - nfs).abs().max() < 1e-6);
            assert!((fz - nfz).abs().max() < 1e-6);
        }
    }
}
