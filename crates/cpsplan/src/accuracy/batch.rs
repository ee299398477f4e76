//! The batch weighted least-squares adjustment of a whole CPS network: every
//! station after the first and every child point unknown, every measurement at
//! once. The reference for [`super::Chain`]: for the last station the two agree.
//!
//! In: the first pose and the cycles ([`CycleGeometry`]). Out: the covariance of
//! the last station's pose, `(AᵀWA)⁻¹` restricted to it, with the Jacobian `A`
//! of every observation at the nominal geometry and `W` the inverse noise.

use nalgebra::DMatrix;

use super::chain::{invert_spd, ChainError};
use super::model::Model;
use crate::geom::Point;

/// One cycle of a network: where the parent goes, where every child stands, and
/// which children moved to stand there.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleGeometry {
    /// The parent's position after the cycle.
    pub to: Point,
    /// Every child's point during the cycle.
    pub children: Vec<Point>,
    /// Whether each child moved (got a new point) in this cycle.
    pub moved: Vec<bool>,
}

/// The covariance of the last station's pose (`station_dim` square, in the model's
/// station order) by the batch adjustment of the network that starts with the
/// parent exactly at `start` and runs `cycles`.
pub fn batch_station_covariance(
    model: &Model,
    start: Point,
    cycles: &[CycleGeometry],
) -> Result<DMatrix<f64>, ChainError> {
    let (ds, dp, m) = (model.station_dim(), model.point_dim(), model.obs_dim());
    let Some(first) = cycles.first() else {
        return Ok(DMatrix::zeros(ds, ds));
    };
    let n = first.children.len();
    if n < 2 {
        return Err(ChainError::TooFewChildren(n));
    }
    // Unknowns: stations 1..=K, then one point per forward measurement.
    let k = cycles.len();
    let mut point_of = vec![usize::MAX; n];
    let mut points: Vec<(usize, Point)> = Vec::new(); // (child, where)
                                                      // (station index 0..=K, point index) observation pairs.
    let mut links: Vec<(usize, usize)> = Vec::new();
    for (c, cycle) in cycles.iter().enumerate() {
        for (i, slot) in point_of.iter_mut().enumerate() {
            if cycle.moved[i] || *slot == usize::MAX {
                *slot = points.len();
                points.push((i, cycle.children[i]));
                links.push((c, *slot));
            }
        }
        for &p in &point_of {
            links.push((c + 1, p));
        }
    }
    let unknowns = k * ds + points.len() * dp;
    let station_state = |s: usize| {
        let p = if s == 0 { start } else { cycles[s - 1].to };
        model.station(p, 0.0)
    };
    let mut normal = DMatrix::zeros(unknowns, unknowns);
    for &(s, p) in &links {
        let st = station_state(s);
        let pt = model.point(points[p].1);
        let (hs, hc) = model.jacobians(st.as_slice(), pt.as_slice());
        let w =
            invert_spd(&model.noise(st.as_slice(), pt.as_slice())).ok_or(ChainError::Singular)?;
        // The row block of this observation over the unknowns.
        let mut a = DMatrix::zeros(m, unknowns);
        if s > 0 {
            a.view_mut((0, (s - 1) * ds), (m, ds)).copy_from(&hs);
        }
        a.view_mut((0, k * ds + p * dp), (m, dp)).copy_from(&hc);
        normal += a.transpose() * w * a;
    }
    let cov = invert_spd(&normal).ok_or(ChainError::Singular)?;
    Ok(cov
        .view(((k - 1) * ds, (k - 1) * ds), (ds, ds))
        .into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::{Chain, Instrument};
    use crate::config::InstrumentConfig;
    use proptest::prelude::*;

    fn chain_strategy() -> impl Strategy<Value = (bool, usize, Vec<CycleGeometry>)> {
        (any::<bool>(), 2usize..5, 1usize..7).prop_flat_map(|(three_d, n, k)| {
            let cycle = (
                (-30.0f64..30.0, -30.0f64..30.0),
                proptest::collection::vec((-30.0f64..30.0, -30.0f64..30.0, any::<bool>()), n),
            );
            (Just(three_d), Just(n), proptest::collection::vec(cycle, k)).prop_map(
                |(three_d, n, cs)| {
                    let cycles = cs
                        .into_iter()
                        .map(|((tx, ty), kids)| CycleGeometry {
                            to: Point::new(tx, ty),
                            children: kids.iter().map(|&(x, y, _)| Point::new(x, y)).collect(),
                            moved: kids.iter().map(|&(_, _, m)| m).collect(),
                        })
                        .collect();
                    (three_d, n, cycles)
                },
            )
        })
    }

    /// A network a survey would measure: every link at least 1.5 m long (no child
    /// on top of a station), and from every station some two children at least
    /// 5° apart (children in line with a station leave its pose nearly
    /// undetermined, and both adjustments then agree only to the rounding of an
    /// ill-conditioned system).
    fn well_posed(start: Point, cycles: &[CycleGeometry]) -> bool {
        let spread = |s: Point, kids: &[Point]| {
            let b: Vec<f64> = kids.iter().map(|k| (k.y - s.y).atan2(k.x - s.x)).collect();
            let mut best: f64 = 0.0;
            for (i, x) in b.iter().enumerate() {
                for y in &b[i + 1..] {
                    let d = (x - y).abs() % std::f64::consts::TAU;
                    best = best.max(d.min(std::f64::consts::TAU - d));
                }
            }
            best
        };
        let min = 5f64.to_radians();
        let mut from = start;
        for c in cycles {
            if c.children
                .iter()
                .any(|p| p.distance(from) < 1.5 || p.distance(c.to) < 1.5)
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

    proptest! {
        #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

        /// The sequential propagation gives the batch adjustment's covariance of
        /// the last station, to 1e-9 relative.
        #[test]
        fn sequential_equals_batch((three_d, n, mut cycles) in chain_strategy()) {
            let start = Point::new(0.0, 0.0);
            // A child that stays keeps its point: its later entries repeat it.
            let mut held = cycles[0].children.clone();
            for c in cycles.iter_mut() {
                for (i, h) in held.iter_mut().enumerate() {
                    if c.moved[i] { *h = c.children[i]; } else { c.children[i] = *h; }
                }
            }
            prop_assume!(well_posed(start, &cycles));
            let mut inst = Instrument::from_config(&InstrumentConfig::default());
            inst.three_d = three_d;
            let model = Model::new(inst);
            let mut chain = Chain::new(model, start, n);
            let mut ok = true;
            for c in &cycles {
                if chain.cycle(c.to, &c.children, &c.moved).is_err() {
                    ok = false;
                    break;
                }
            }
            prop_assume!(ok);
            let batch = batch_station_covariance(&model, start, &cycles).unwrap();
            let ds = model.station_dim();
            let seq = chain.covariance().view((0, 0), (ds, ds)).into_owned();
            let scale = batch.abs().max();
            let diff = (&seq - &batch).abs().max();
            prop_assert!(diff <= 1e-9 * scale, "relative difference {}", diff / scale);
        }
    }
}
