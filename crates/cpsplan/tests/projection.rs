//! Point clouds to grids across random clouds and parameters: the counts add
//! up, every cell's class follows from the points in it, and a cloud shifted by
//! whole cells gives the same map shifted. And the registered model of an
//! episode projects back onto the ground truth's walls.

use cpsplan::model::build_model;
use cpsplan::sensing::seen_walls;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::world::projection::{
    project, BeamOrigin, GroundModel, HeightBand, PlanarTransform, ProjectionParams,
};
use cpsplan::{run_episode, CellState, Config, Point};
use proptest::prelude::*;

fn cloud() -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec((-5.0f64..5.0, -4.0f64..4.0, -1.5f64..2.5), 1..400)
        .prop_map(|v| v.into_iter().map(|(x, y, z)| [x, y, z]).collect())
}

fn params() -> impl Strategy<Value = ProjectionParams> {
    (
        prop::sample::select(vec![0.05, 0.1, 0.25, 1.0]),
        any::<bool>(),
        -1.0f64..0.5,
        0.1f64..2.0,
        0usize..3,
        1u32..4,
        prop::option::of(0.05f64..1.0),
        any::<bool>(),
    )
        .prop_map(
            |(resolution, absolute, lo, span, ground, min_points, outlier_radius, beams)| {
                ProjectionParams {
                    resolution,
                    band: if absolute {
                        HeightBand::Absolute {
                            min: lo,
                            max: lo + span,
                        }
                    } else {
                        HeightBand::AboveGround {
                            low: lo.abs(),
                            high: lo.abs() + span,
                        }
                    },
                    ground: [
                        GroundModel::None,
                        GroundModel::Plane,
                        GroundModel::Lowest { window: 0.5 },
                    ][ground],
                    min_points,
                    outlier_radius,
                    transform: PlanarTransform::default(),
                    free_from_scans: beams,
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn every_cell_follows_from_its_points(pts in cloud(), p in params()) {
        let origins = [BeamOrigin { points: 0..pts.len(), origin: [0.0, 0.0, 0.5] }];
        let config = Config::default();
        let out = project(&pts, &origins, &p, &config, |_, _| {});
        let Ok(out) = out else {
            // Only outlier removal may leave nothing.
            prop_assert!(p.outlier_radius.is_some());
            return Ok(());
        };
        let s = out.stats;
        let g = *out.grid.geometry();
        prop_assert_eq!(s.points_kept + s.outliers, pts.len());
        prop_assert_eq!(s.obstacle_points + s.ground_points + s.above_points, s.points_kept);
        prop_assert_eq!(s.free_cells + s.occupied_cells + s.unknown_cells, g.len());
        // Recount: band points and ground points per cell, over all points (the
        // kept ones are those the stats count; with outliers removed the
        // occupied cells can only have fewer).
        let (low, high) = p.band.limits();
        let mut band = vec![0u32; g.len()];
        let mut ground = vec![false; g.len()];
        for q in &pts {
            let c = g.world_to_cell(Point::new(q[0], q[1]));
            // Every kept point lies in the map (outliers may lie beyond it).
            prop_assert!(c.is_some() || p.outlier_radius.is_some(), "a point beyond the map");
            let Some(c) = c else { continue };
            let i = g.index(c);
            let h = q[2] - out.ground.height(i);
            if h < low { ground[i] = true } else if h <= high { band[i] += 1 }
        }
        for (i, &state) in out.grid.cells().iter().enumerate() {
            match state {
                CellState::Occupied => prop_assert!(band[i] >= p.min_points),
                CellState::Free => {
                    prop_assert!(p.outlier_radius.is_some() || band[i] < p.min_points);
                    if !p.free_from_scans {
                        prop_assert!(ground[i]);
                    }
                }
                CellState::Unknown => {
                    prop_assert!(p.outlier_radius.is_some() || band[i] < p.min_points);
                }
            }
        }
    }

    #[test]
    fn a_shift_by_whole_cells_shifts_the_map(pts in cloud(), p in params(), kx in -20i32..20, ky in -20i32..20) {
        let p = ProjectionParams { free_from_scans: false, outlier_radius: None, ..p };
        let config = Config::default();
        let a = project(&pts, &[], &p, &config, |_, _| {}).unwrap();
        let (tx, ty) = (f64::from(kx) * p.resolution, f64::from(ky) * p.resolution);
        let moved = ProjectionParams { transform: PlanarTransform { tx, ty, yaw: 0.0 }, ..p };
        let b = project(&pts, &[], &moved, &config, |_, _| {}).unwrap();
        let (ga, gb) = (a.grid.geometry(), b.grid.geometry());
        // Floating-point rounding at a cell boundary may move the corner by one
        // cell; the cells must agree where both grids hold them.
        prop_assert!((gb.origin.x - ga.origin.x - tx).abs() <= p.resolution * 1.000_001);
        prop_assert!((gb.origin.y - ga.origin.y - ty).abs() <= p.resolution * 1.000_001);
        if (gb.origin.x - ga.origin.x - tx).abs() < 1e-6 && (gb.origin.y - ga.origin.y - ty).abs() < 1e-6 {
            prop_assert_eq!(a.grid.cells(), b.grid.cells());
        }
    }
}

/// The registered model of the default episode (true poses, the instrument's
/// range noise) projected back: every occupied cell is a ground-truth wall or
/// touches one (a point on a wall's face falls into the free cell in front of it
/// for half the noise draws, one at a corner into the diagonal cell), and at
/// least 95 % of the wall cells the scans saw come back.
#[test]
fn the_registered_model_projects_back_onto_the_walls() {
    let truth = BuiltinMap::Site.generate(0);
    let config = Config::default();
    let episode = run_episode(&truth, BuiltinMap::Site.default_start(), &config, |_| {}).unwrap();
    let mut points = Vec::new();
    build_model(&truth, &episode, &config, |_, p| {
        points.extend(p.iter().map(|q| q.position))
    })
    .unwrap();
    let params = ProjectionParams {
        band: HeightBand::Absolute { min: 0.0, max: 2.0 },
        ..ProjectionParams::default()
    };
    let map = project(&points, &[], &params, &config, |_, _| {})
        .unwrap()
        .grid;
    let (g, t) = (*map.geometry(), *truth.geometry());
    let solid = |p: Point| {
        t.world_to_cell(p)
            .is_none_or(|c| truth.get(c) != CellState::Free)
    };
    for (i, &state) in map.cells().iter().enumerate() {
        if state != CellState::Occupied {
            continue;
        }
        let c = g.cell_center(g.cell(i));
        let r = t.resolution;
        let near = (-1..=1)
            .flat_map(|dx| (-1..=1).map(move |dy| (f64::from(dx) * r, f64::from(dy) * r)))
            .any(|(dx, dy)| solid(Point::new(c.x + dx, c.y + dy)));
        assert!(near, "occupied cell at {c:?} is not at a wall");
    }
    // And the walls come back: almost every wall cell a scan saw has an
    // occupied cell of the projected model within a cell of it.
    let occupied = |p: Point| {
        g.world_to_cell(p)
            .is_some_and(|c| map.get(c) == CellState::Occupied)
    };
    let mut seen: Vec<usize> = episode
        .steps
        .iter()
        .flat_map(|s| seen_walls(&truth, s.cell, config.range_cells()))
        .collect();
    seen.sort_unstable();
    seen.dedup();
    let back = seen
        .iter()
        .filter(|&&i| {
            let c = t.cell_center(t.cell(i));
            let r = t.resolution;
            (-1..=1)
                .flat_map(|dx| (-1..=1).map(move |dy| (f64::from(dx) * r, f64::from(dy) * r)))
                .any(|(dx, dy)| occupied(Point::new(c.x + dx, c.y + dy)))
        })
        .count();
    assert!(
        back as f64 >= 0.95 * seen.len() as f64,
        "{back} of {} seen walls come back",
        seen.len()
    );
}
