//! Tests of the pair search: exactness against exhaustive search, the node
//! bounds, the parallel scans.

mod search {
    use super::super::*;
    use crate::accuracy::{Chain, Instrument, Model, Objective};
    use crate::config::InstrumentConfig;
    use crate::geom::Point;
    use proptest::prelude::*;

    fn spot(objective: &Objective, x: usize, y: usize, from: Point) -> Spot {
        let c = Cell::new(x, y);
        let p = Point::new(x as f64 * 0.1 + 0.05, y as f64 * 0.1 + 0.05);
        Spot {
            cell: c,
            info: objective.mover_info(p),
            travel: p.distance(from),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

        /// The branch and bound finds the pair that exhaustive search finds.
        #[test]
        fn branch_and_bound_is_exact(
            to in (40usize..160, 40usize..160),
            cells_a in proptest::collection::vec((0usize..200, 0usize..200), 1..60),
            cells_b in proptest::collection::vec((0usize..200, 0usize..200), 1..60),
            lambda in proptest::sample::select(vec![0.0, 1e-5, 1e-3]),
        ) {
            let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
            let start = Point::new(10.05, 10.05);
            let mut chain = Chain::new(model, start, 2);
            chain.cycle(Point::new(5.0, 8.0), &[Point::new(7.0, 14.0), Point::new(12.0, 4.0)], &[true, true]).unwrap();
            let to = Point::new(to.0 as f64 * 0.1 + 0.05, to.1 as f64 * 0.1 + 0.05);
            let objective = Objective::new(&chain, to, &[]).unwrap();
            let near = |&(x, y): &(usize, usize)| {
                let p = Point::new(x as f64 * 0.1, y as f64 * 0.1);
                p.distance(to) < 1.5 || p.distance(chain.position()) < 1.5
            };
            let a: Vec<Spot> = cells_a.iter().filter(|c| !near(c)).map(|&(x, y)| spot(&objective, x, y, chain.position())).collect();
            let b: Vec<Spot> = cells_b.iter().filter(|c| !near(c)).map(|&(x, y)| spot(&objective, x, y, chain.position())).collect();
            prop_assume!(!a.is_empty() && !b.is_empty());
            let cost = |j: &Matrix3<f64>| objective.value(j).max(0.0).sqrt();
            let spacing = Spacing { parents: Vec::new(), radius: 2.5, marker: 1.0 };
            let mut brute: Option<f64> = None;
            for sa in &a {
                for sb in &b {
                    if spacing.ok(sa.cell, sb.cell) {
                        let v = cost(&(sa.info + sb.info)) + lambda * (sa.travel + sb.travel);
                        if v.is_finite() && brute.is_none_or(|bv| v < bv) {
                            brute = Some(v);
                        }
                    }
                }
            }
            let found = best_pair(&a, &b, lambda, &cost, &spacing, Gap { floor: 0.0, share: 0.0 })
                .filter(|r| r.2 == 0.0)
                .map(|(v, _, _)| v);
            match (brute, found) {
                (Some(x), Some(y)) => prop_assert!((x - y).abs() <= 1e-12 * x.abs().max(1e-9), "{} vs {}", x, y),
                (None, f) => prop_assert!(f.is_none_or(|v| !v.is_finite())),
                (Some(x), None) => prop_assert!(false, "missed {}", x),
            }
        }

        /// The node bound lies above every member in the Löwner order.
        #[test]
        fn node_bounds_dominate(points in proptest::collection::vec((0usize..200, 0usize..200), 1..30)) {
            let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
            let mut chain = Chain::new(model, Point::new(10.05, 10.05), 2);
            chain.cycle(Point::new(5.0, 8.0), &[Point::new(7.0, 14.0), Point::new(12.0, 4.0)], &[true, true]).unwrap();
            let objective = Objective::new(&chain, Point::new(9.0, 3.0), &[]).unwrap();
            let spots: Vec<Spot> = points.iter().map(|&(x, y)| spot(&objective, x, y, chain.position())).collect();
            let u = upper_bound(spots.iter().map(|s| &s.info));
            for s in &spots {
                let d = u - s.info;
                let e = d.symmetric_eigen();
                let scale = u.trace().abs().max(1e-300);
                prop_assert!(e.eigenvalues.min() >= -1e-9 * scale, "{:?}", e.eigenvalues);
            }
        }
    }
}

mod eig {
    use super::super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn max_eigenvalue_matches_nalgebra(v in proptest::collection::vec(-10.0f64..10.0, 9), scale in -3i32..9) {
            let a = Matrix3::from_iterator(v.into_iter());
            let m = (a * a.transpose()) * 10f64.powi(scale);
            let e = m.symmetric_eigen().eigenvalues.max();
            let got = max_eigenvalue(&m);
            prop_assert!((got - e).abs() <= 1e-6 * e.abs().max(1e-300), "{} vs {}", got, e);
        }

        /// The trigonometric form errs by under 1e-7 of the matrix's norm (the
        /// margin of the bound's skip is 1e-6), double largest eigenvalues
        /// (where `acos` amplifies rounding most) included.
        #[test]
        fn max_eigenvalue_errs_by_under_a_ten_millionth_of_the_norm(
            angles in (0.0f64..6.3, 0.0f64..6.3, 0.0f64..6.3),
            top in 1e-3f64..1e3,
            low in 0.0f64..1.0,
            double in any::<bool>(),
        ) {
            let r = nalgebra::Rotation3::from_euler_angles(angles.0, angles.1, angles.2);
            let second = if double { top } else { top * low };
            let d = Matrix3::from_diagonal(&nalgebra::Vector3::new(top, second, top * low * low));
            let m = r.matrix() * d * r.matrix().transpose();
            let m = (m + m.transpose()) / 2.0;
            let (_, norm) = gershgorin(&m);
            let want = m.symmetric_eigen().eigenvalues.max();
            prop_assert!((max_eigenvalue(&m) - want).abs() <= 1e-7 * norm, "{} vs {}", max_eigenvalue(&m), want);
        }

        /// The node bound with its pruned passes is, bit for bit, the bound of
        /// the plain passes (every ridge scored over every member, every
        /// member's largest eigenvalue), on rank-two members like a mover's.
        #[test]
        fn pruned_bound_equals_the_plain_one(
            members in proptest::collection::vec((proptest::collection::vec(-10.0f64..10.0, 6), -4i32..4), 1..40),
        ) {
            let infos: Vec<Matrix3<f64>> = members
                .iter()
                .map(|(v, e)| {
                    let a = nalgebra::Matrix2x3::from_iterator(v.iter().copied());
                    (a.transpose() * a) * 10f64.powi(*e)
                })
                .collect();
            let got = upper_bound(infos.iter());
            let want = plain_upper_bound(infos.iter());
            prop_assert_eq!(got, want);
        }

        /// Scanned in parallel chunks, a large set gives the plain scan's
        /// spot: the first of the least value.
        #[test]
        fn best_single_in_chunks_is_the_plain_scan(
            values in proptest::collection::vec(0u8..40, PARALLEL_SPOTS..3 * PARALLEL_SPOTS),
        ) {
            // The value of a spot is its `info[(0, 0)]`: few distinct values, many ties.
            let spots: Vec<Spot> = values
                .iter()
                .enumerate()
                .map(|(k, &v)| Spot {
                    cell: Cell::new(k, 0),
                    info: Matrix3::identity() * f64::from(v),
                    travel: 0.0,
                })
                .collect();
            let spacing = Spacing { parents: Vec::new(), radius: 0.0, marker: 0.0 };
            let cost = |j: &Matrix3<f64>| j[(0, 0)];
            let got = best_single(&spots, &Matrix3::zeros(), 0.0, &cost, &[], &spacing);
            let least = values.iter().copied().min().map(f64::from);
            let want = values.iter().position(|&v| Some(f64::from(v)) == least);
            prop_assert_eq!(got, least.zip(want));
        }
    }

    /// The node bound's passes as first written (the same whitening): every
    /// ridge scored over every member, the scale from every member's largest
    /// eigenvalue.
    fn plain_upper_bound<'a>(
        infos: impl Iterator<Item = &'a Matrix3<f64>> + Clone,
    ) -> Matrix3<f64> {
        let whitening = Whitening::of(infos.clone()).expect("members");
        let mut chosen: Option<(f64, Matrix3<f64>, Matrix3<f64>)> = None;
        for ridge in BOUND_RIDGES {
            let Some((q, li)) = whitening.at(ridge) else {
                continue;
            };
            let rough = infos
                .clone()
                .map(|j| gershgorin(&(li * j * li.transpose())).0)
                .fold(0.0, f64::max);
            let score = rough * (1.0 + ridge);
            if chosen.as_ref().is_none_or(|(b, _, _)| score < *b) {
                chosen = Some((score, q, li));
            }
        }
        let (_, q, li) = chosen.expect("a ridge whitens");
        let scale = infos
            .clone()
            .map(|j| max_eigenvalue(&(li * j * li.transpose())))
            .fold(0.0, f64::max);
        q * (scale * (1.0 + 1e-9) + 1e-12)
    }
}

mod bound {
    use super::super::*;
    use crate::accuracy::{Chain, Instrument, Model, Objective};
    use crate::config::InstrumentConfig;
    use crate::geom::Point;

    #[test]
    fn single_member_bound_is_tight() {
        let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
        let mut chain = Chain::new(model, Point::new(10.05, 10.05), 2);
        chain
            .cycle(
                Point::new(5.0, 8.0),
                &[Point::new(7.0, 14.0), Point::new(12.0, 4.0)],
                &[true, true],
            )
            .unwrap();
        let objective = Objective::new(&chain, Point::new(9.0, 3.0), &[]).unwrap();
        let ja = objective.mover_info(Point::new(15.0, 9.0));
        let jb = objective.mover_info(Point::new(3.0, 12.0));
        let u = upper_bound([ja].iter());
        let exact = objective.value(&(ja + jb));
        let bound = objective.value(&(u + jb));
        assert!(bound / exact > 0.99, "{bound} vs {exact}");
    }
}
