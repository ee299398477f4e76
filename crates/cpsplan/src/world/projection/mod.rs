//! From a 3D point cloud to the 2D occupancy grid the planner runs on (pipeline
//! stage 1, paper Fig. 3: "the obtained 3D geometrical data is transformed to a
//! 2D grid map at first").
//!
//! In: points in metres (and, for beams, the scan origins), the projection's
//! parameters. Out: an [`OccupancyGrid`] whose world frame is the cloud's frame
//! (after the optional planar transform), with counts of what went where
//! ([`Projection`]).
//!
//! A cell is Occupied when it holds at least `min_points` points within the
//! obstacle height band (absolute heights, or heights above the estimated
//! ground); Free when its ground was observed (a point below the band) and it
//! holds no obstacle, or, with beams, when a beam crossed it within the band;
//! Unknown otherwise.
//!
//! - `ground`: the ground's height under every cell (none, a plane, the lowest
//!   points).
//! - `outliers`: radius outlier removal.
//! - `beams`: free space along the beams from the scan origins.

mod beams;
mod ground;
mod outliers;
mod pieces;

use std::borrow::Cow;
use std::ops::Range;

use thiserror::Error;

pub use ground::{Ground, GroundModel};
pub use pieces::{free_space_pieces, FreeSpacePieces, FRAGMENTED_SHARE, GAPPY_SHARE};

use crate::config::{number, Config, ConfigError};
use crate::geom::Point;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// The heights that count as obstacles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HeightBand {
    /// Absolute `z` from `min` to `max`, metres.
    Absolute {
        /// Lowest obstacle height.
        min: f64,
        /// Highest obstacle height.
        max: f64,
    },
    /// Height above the estimated ground from `low` to `high`, metres.
    AboveGround {
        /// Lowest obstacle height above the ground.
        low: f64,
        /// Highest obstacle height above the ground.
        high: f64,
    },
}

impl HeightBand {
    /// The band's ends.
    pub fn limits(self) -> (f64, f64) {
        match self {
            HeightBand::Absolute { min, max } => (min, max),
            HeightBand::AboveGround { low, high } => (low, high),
        }
    }
}

/// A planar rigid transform applied to the cloud before projecting it: rotate
/// by `yaw` about the cloud's origin, then shift by `(tx, ty)`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanarTransform {
    /// Shift along x, metres.
    pub tx: f64,
    /// Shift along y, metres.
    pub ty: f64,
    /// Rotation, radians.
    pub yaw: f64,
}

impl PlanarTransform {
    /// The transformed point (`z` unchanged).
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.yaw.sin_cos();
        [
            c * p[0] - s * p[1] + self.tx,
            s * p[0] + c * p[1] + self.ty,
            p[2],
        ]
    }

    /// The point this transform carries to `p` (its inverse; `z` unchanged).
    pub fn unapply(&self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.yaw.sin_cos();
        let (x, y) = (p[0] - self.tx, p[1] - self.ty);
        [c * x + s * y, -s * x + c * y, p[2]]
    }
}

/// The points of one scan whose origin is known, for tracing free space.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamOrigin {
    /// The scan's points, a range of the cloud.
    pub points: Range<usize>,
    /// The scanner's centre, cloud frame (before the transform).
    pub origin: [f64; 3],
}

/// Every parameter of a projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionParams {
    /// Cell width, metres.
    pub resolution: f64,
    /// The obstacle heights.
    pub band: HeightBand,
    /// How the ground is estimated (used with [`HeightBand::AboveGround`]).
    pub ground: GroundModel,
    /// Points in the band that make a cell Occupied.
    pub min_points: u32,
    /// Radius outlier removal: points with fewer than [`OUTLIER_NEIGHBOURS`]
    /// others within this distance are dropped (`None`: keep all).
    pub outlier_radius: Option<f64>,
    /// The planar transform into the map frame.
    pub transform: PlanarTransform,
    /// Free space from the beams instead of from the observed ground.
    pub free_from_scans: bool,
}

impl Default for ProjectionParams {
    fn default() -> Self {
        Self {
            resolution: 0.1,
            band: HeightBand::AboveGround {
                low: 0.2,
                high: 2.0,
            },
            ground: GroundModel::Plane,
            min_points: 1,
            outlier_radius: None,
            transform: PlanarTransform::default(),
            free_from_scans: false,
        }
    }
}

/// Neighbours within the outlier radius a point needs to be kept.
pub const OUTLIER_NEIGHBOURS: usize = 2;

/// Why a cloud cannot be projected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ProjectionError {
    /// A parameter outside its valid range.
    #[error("{flag}: {what}")]
    Parameter {
        /// The command-line flag.
        flag: &'static str,
        /// The problem.
        what: String,
    },
    /// No point to project.
    #[error("the cloud holds no points{0}")]
    Empty(&'static str),
    /// A coordinate that is not a finite number.
    #[error("point {0} has a coordinate that is not a finite number")]
    NotFinite(usize),
    /// Beams asked for, but no origin known.
    #[error(
        "--free-from-scans needs the scan origins, and the cloud records none; give --origin X,Y,Z"
    )]
    NoOrigins,
    /// The grid would exceed the limits.
    #[error(transparent)]
    Grid(#[from] ConfigError),
}

/// What went where.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProjectionStats {
    /// Points given.
    pub points_in: usize,
    /// Points dropped as outliers.
    pub outliers: usize,
    /// Points kept.
    pub points_kept: usize,
    /// Kept points in the obstacle band.
    pub obstacle_points: usize,
    /// Kept points below the band (ground observed).
    pub ground_points: usize,
    /// Kept points above the band (ignored).
    pub above_points: usize,
    /// Beams traced (with `free_from_scans`).
    pub beams: usize,
    /// Cells of each state: Free, Occupied, Unknown.
    pub free_cells: usize,
    /// Occupied cells.
    pub occupied_cells: usize,
    /// Unknown cells.
    pub unknown_cells: usize,
}

/// A projected cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// The map, world frame = the (transformed) cloud frame.
    pub grid: OccupancyGrid,
    /// The ground as estimated.
    pub ground: Ground,
    /// What went where.
    pub stats: ProjectionStats,
}

/// Validates the parameters, naming the flag that sets each.
pub fn check_params(p: &ProjectionParams) -> Result<(), ProjectionError> {
    let bad = |flag, what: String| Err(ProjectionError::Parameter { flag, what });
    if !(p.resolution.is_finite() && (0.001..=100.0).contains(&p.resolution)) {
        return bad(
            "--resolution",
            format!(
                "must be a number from 0.001 to 100 m (got {})",
                number(p.resolution)
            ),
        );
    }
    let (lo, hi) = p.band.limits();
    let flag = match p.band {
        HeightBand::Absolute { .. } => "--z-min/--z-max",
        HeightBand::AboveGround { .. } => "--height-above-ground",
    };
    if !(lo.is_finite() && hi.is_finite() && lo.abs() <= 1e6 && hi.abs() <= 1e6) {
        return bad(flag, "the band's ends must be numbers within ±1e6 m".into());
    }
    if lo >= hi {
        return bad(
            flag,
            format!(
                "the band's low end ({}) must be below its high end ({})",
                number(lo),
                number(hi)
            ),
        );
    }
    if p.min_points == 0 {
        return bad("--min-points", "must be at least 1".into());
    }
    if let Some(r) = p.outlier_radius {
        if !(r.is_finite() && r > 0.0 && r <= 1000.0) {
            return bad(
                "--outlier-radius",
                format!(
                    "must be a number above 0 and at most 1000 m (got {})",
                    number(r)
                ),
            );
        }
    }
    let t = p.transform;
    if !(t.tx.is_finite() && t.ty.is_finite() && t.yaw.is_finite())
        || t.tx.abs() > 1e8
        || t.ty.abs() > 1e8
    {
        return bad(
            "--transform",
            "must be finite, with shifts within ±1e8 m".into(),
        );
    }
    if let GroundModel::Lowest { window } = p.ground {
        if !(window.is_finite() && (0.0..=1000.0).contains(&window)) {
            return bad(
                "--ground-window",
                format!("must be a number from 0 to 1000 m (got {})", number(window)),
            );
        }
    }
    Ok(())
}

/// Projects `points` (metres) to an occupancy grid under `params`; `origins`
/// give the scans whose origins are known (for `free_from_scans`). The grid's
/// size is checked against `limits` (`limits.max_grid_cells`) before it is
/// allocated. `progress(done, total)` sees the work advance, from the calling
/// thread.
pub fn project(
    points: &[[f64; 3]],
    origins: &[BeamOrigin],
    params: &ProjectionParams,
    limits: &Config,
    mut progress: impl FnMut(u64, u64),
) -> Result<Projection, ProjectionError> {
    check_params(params)?;
    if points.is_empty() {
        return Err(ProjectionError::Empty(""));
    }
    if let Some(i) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        return Err(ProjectionError::NotFinite(i));
    }
    if params.free_from_scans && origins.is_empty() {
        return Err(ProjectionError::NoOrigins);
    }
    let t = params.transform;
    // The cloud in the map frame (borrowed when there is no transform).
    let moved: Cow<[[f64; 3]]> = if t == PlanarTransform::default() {
        Cow::Borrowed(points)
    } else {
        Cow::Owned(points.iter().map(|&p| t.apply(p)).collect())
    };
    let keep = match params.outlier_radius {
        Some(r) => outliers::inliers(&moved, r, OUTLIER_NEIGHBOURS),
        None => vec![true; moved.len()],
    };
    let kept = keep.iter().filter(|&&k| k).count();
    if kept == 0 {
        return Err(ProjectionError::Empty(" left after outlier removal"));
    }
    // Origins matter only for beams (and then widen the grid to hold them).
    let origins: Vec<BeamOrigin> = origins
        .iter()
        .filter(|_| params.free_from_scans)
        .filter(|o| o.origin.iter().all(|v| v.is_finite()))
        .map(|o| BeamOrigin {
            points: o.points.start.min(points.len())..o.points.end.min(points.len()),
            origin: t.apply(o.origin),
        })
        .collect();
    let geometry = geometry_of(&moved, &keep, &origins, params.resolution, limits)?;
    let ground = Ground::estimate(params.ground, params.band, &moved, &keep, &geometry);
    let (low, high) = params.band.limits();
    let n = geometry.len();
    let mut counts = vec![0u32; n];
    let mut ground_seen = vec![false; n];
    let mut stats = ProjectionStats {
        points_in: points.len(),
        outliers: points.len() - kept,
        points_kept: kept,
        ..ProjectionStats::default()
    };
    let total = (points.len() as u64).saturating_mul(if params.free_from_scans { 2 } else { 1 });
    for (i, p) in moved.iter().enumerate() {
        if i % (1 << 16) == 0 {
            progress(i as u64, total);
        }
        if !keep[i] {
            continue;
        }
        let Some(cell) = geometry.world_to_cell(Point::new(p[0], p[1])) else {
            continue;
        };
        let c = geometry.index(cell);
        let h = p[2] - ground.height(c);
        if h < low {
            stats.ground_points += 1;
            ground_seen[c] = true;
        } else if h <= high {
            stats.obstacle_points += 1;
            counts[c] = counts[c].saturating_add(1);
        } else {
            stats.above_points += 1;
        }
    }
    let free = if params.free_from_scans {
        let mut done = points.len() as u64;
        let cleared = beams::cleared(
            &moved,
            &keep,
            &origins,
            &geometry,
            &ground,
            (low, high),
            |d| {
                done = done.saturating_add(d);
                progress(done, total);
            },
        );
        stats.beams = origins
            .iter()
            .map(|o| keep[o.points.clone()].iter().filter(|&&k| k).count())
            .sum();
        cleared
    } else {
        ground_seen
    };
    let cells: Vec<CellState> = (0..n)
        .map(|c| {
            if counts[c] >= params.min_points {
                CellState::Occupied
            } else if free[c] {
                CellState::Free
            } else {
                CellState::Unknown
            }
        })
        .collect();
    let grid = OccupancyGrid::from_cells(geometry, cells).expect("one state per cell");
    stats.free_cells = grid.count(CellState::Free);
    stats.occupied_cells = grid.count(CellState::Occupied);
    stats.unknown_cells = grid.count(CellState::Unknown);
    progress(total, total);
    Ok(Projection {
        grid,
        ground,
        stats,
    })
}

/// The grid holding every kept point and every origin, one cell of margin
/// around them, its corner on a multiple of the resolution; checked against the
/// limits before anything is allocated.
fn geometry_of(
    points: &[[f64; 3]],
    keep: &[bool],
    origins: &[BeamOrigin],
    resolution: f64,
    limits: &Config,
) -> Result<GridGeometry, ProjectionError> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let kept = points.iter().zip(keep).filter(|(_, &k)| k).map(|(p, _)| p);
    for p in kept.chain(origins.iter().map(|o| &o.origin)) {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let x0 = (lo[0] / resolution).floor() - 1.0;
    let y0 = (lo[1] / resolution).floor() - 1.0;
    let w = ((hi[0] / resolution).floor() - x0 + 2.0).max(1.0);
    let h = ((hi[1] / resolution).floor() - y0 + 2.0).max(1.0);
    let origin = (x0 * resolution, y0 * resolution);
    // Sizes beyond u64 saturate and are refused by the check.
    limits.check_grid(w as u64, h as u64, resolution, origin)?;
    Ok(GridGeometry::new(
        w as usize,
        h as usize,
        resolution,
        Point::new(origin.0, origin.1),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 m × 3 m room seen from (1, 1, 0): its floor at z = −1.2 (points every
    /// 5 cm, but none in the strip 3.0 < x < 3.5), walls 2 m tall on its edges, a
    /// table top at z = −0.5 over 0.5 m × 0.5 m in a corner, a ceiling at 1.3.
    fn room() -> Vec<[f64; 3]> {
        let mut p = Vec::new();
        let step = 0.05;
        for i in 0..=80 {
            for j in 0..=60 {
                let (x, y) = (i as f64 * step, j as f64 * step);
                if !(3.0 < x && x < 3.5) {
                    p.push([x, y, -1.2]);
                }
                p.push([x, y, 1.3]);
                if (0.2..0.7).contains(&x) && (2.2..2.7).contains(&y) {
                    p.push([x, y, -0.5]);
                }
            }
        }
        for k in 0..=40 {
            let z = -1.2 + k as f64 * step;
            for i in 0..=80 {
                let x = i as f64 * step;
                p.push([x, -0.02, z]);
                p.push([x, 3.02, z]);
            }
            for j in 0..=60 {
                let y = j as f64 * step;
                p.push([-0.02, y, z]);
                p.push([4.02, y, z]);
            }
        }
        p
    }

    fn state(p: &Projection, x: f64, y: f64) -> CellState {
        let g = p.grid.geometry();
        p.grid
            .get(g.world_to_cell(Point::new(x, y)).expect("inside"))
    }

    #[test]
    fn unapply_undoes_apply() {
        let t = PlanarTransform {
            tx: 12.5,
            ty: -3.0,
            yaw: 2.1,
        };
        for p in [[0.0, 0.0, 1.0], [3.0, -4.0, 0.0], [-1e5, 2e5, -7.0]] {
            let back = t.unapply(t.apply(p));
            for k in 0..3 {
                assert!(
                    (back[k] - p[k]).abs() < 1e-9 * (1.0 + p[k].abs()),
                    "{p:?} {back:?}"
                );
            }
        }
        // A quarter turn carries x to y.
        let q = PlanarTransform {
            tx: 0.0,
            ty: 0.0,
            yaw: std::f64::consts::FRAC_PI_2,
        };
        let r = q.apply([1.0, 0.0, 0.0]);
        assert!(r[0].abs() < 1e-12 && (r[1] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn walls_and_furniture_are_occupied_the_seen_floor_free() {
        let pts = room();
        let p = project(
            &pts,
            &[],
            &ProjectionParams::default(),
            &Config::default(),
            |_, _| {},
        )
        .unwrap();
        assert!(matches!(p.ground, Ground::Plane { .. }));
        assert!(
            (p.ground.height(0) + 1.2).abs() < 1e-6,
            "{}",
            p.ground.describe()
        );
        assert_eq!(state(&p, 2.0, 1.5), CellState::Free);
        assert_eq!(state(&p, 0.45, 2.45), CellState::Occupied, "the table");
        assert_eq!(state(&p, -0.02, 1.5), CellState::Occupied, "a wall");
        assert_eq!(state(&p, 3.25, 1.5), CellState::Unknown, "floor never seen");
        let s = p.stats;
        assert_eq!(s.points_kept, pts.len());
        assert_eq!(
            s.obstacle_points + s.ground_points + s.above_points,
            pts.len()
        );
        assert_eq!(
            s.free_cells + s.occupied_cells + s.unknown_cells,
            p.grid.geometry().len()
        );
        // The map's frame is the cloud's: its corner one cell beyond the cell of
        // the lowest points (x, y = −0.02 lie in the cell from −0.1).
        let g = p.grid.geometry();
        assert!(
            (g.origin.x + 0.2).abs() < 1e-9 && (g.origin.y + 0.2).abs() < 1e-9,
            "{g:?}"
        );
    }

    #[test]
    fn beams_clear_the_band_where_the_floor_was_never_seen() {
        let pts = room();
        let params = ProjectionParams {
            free_from_scans: true,
            ..ProjectionParams::default()
        };
        let origins = [BeamOrigin {
            points: 0..pts.len(),
            origin: [1.0, 1.0, 0.0],
        }];
        let p = project(&pts, &origins, &params, &Config::default(), |_, _| {}).unwrap();
        assert_eq!(state(&p, 3.25, 1.0), CellState::Free);
        assert_eq!(state(&p, 2.0, 1.5), CellState::Free);
        assert_eq!(state(&p, 4.02, 1.5), CellState::Occupied);
        assert_eq!(p.stats.beams, pts.len());
        let none = project(&pts, &[], &params, &Config::default(), |_, _| {}).unwrap_err();
        assert_eq!(none, ProjectionError::NoOrigins);
    }

    #[test]
    fn origins_far_away_matter_only_with_beams() {
        let pts = room();
        let origins = [BeamOrigin {
            points: 0..pts.len(),
            origin: [-500.0, 0.0, 0.0],
        }];
        let d = ProjectionParams::default();
        let p = project(&pts, &origins, &d, &Config::default(), |_, _| {}).unwrap();
        assert!(p.grid.width() < 50);
        let beams = ProjectionParams {
            free_from_scans: true,
            ..d
        };
        let p = project(&pts, &origins, &beams, &Config::default(), |_, _| {}).unwrap();
        assert!(p.grid.width() > 5000, "the grid holds the origin");
    }

    #[test]
    fn an_absolute_band_and_a_transform() {
        let pts = room();
        let params = ProjectionParams {
            band: HeightBand::Absolute {
                min: -1.0,
                max: 0.8,
            },
            transform: PlanarTransform {
                tx: 100.0,
                ty: -50.0,
                yaw: std::f64::consts::FRAC_PI_2,
            },
            ..ProjectionParams::default()
        };
        let p = project(&pts, &[], &params, &Config::default(), |_, _| {}).unwrap();
        assert_eq!(p.ground, Ground::Flat);
        // (2, 1.5) turned a quarter and shifted: (98.5, −48).
        assert_eq!(state(&p, 98.5, -48.0), CellState::Free);
        // The table at (0.45, 2.45) is now at (97.55, −49.55).
        assert_eq!(state(&p, 97.55, -49.55), CellState::Occupied);
    }

    #[test]
    fn outliers_go_before_the_grid_is_sized() {
        let mut pts = room();
        pts.push([5_000.0, 5_000.0, 0.0]);
        let params = ProjectionParams {
            outlier_radius: Some(0.2),
            ..ProjectionParams::default()
        };
        let p = project(&pts, &[], &params, &Config::default(), |_, _| {}).unwrap();
        assert_eq!(p.stats.outliers, 1);
        assert!(p.grid.width() < 50, "{}", p.grid.width());
    }

    #[test]
    fn bad_inputs_are_named() {
        let c = Config::default();
        let e = |pts: &[[f64; 3]], p: ProjectionParams| {
            project(pts, &[], &p, &c, |_, _| {})
                .unwrap_err()
                .to_string()
        };
        let d = ProjectionParams::default();
        assert!(e(&[], d).contains("no points"));
        assert!(e(&[[0.0, f64::NAN, 0.0]], d).contains("point 0"));
        for r in [0.0, -1.0, f64::NAN] {
            let msg = e(&room(), ProjectionParams { resolution: r, ..d });
            assert!(msg.starts_with("--resolution"), "{msg}");
        }
        // Fine enough to need more cells than the limit: refused before allocating.
        let msg = e(
            &[[0.0, 0.0, 0.0], [1000.0, 1000.0, 1.0]],
            ProjectionParams {
                resolution: 0.001,
                ..d
            },
        );
        assert!(msg.contains("limits.max_grid_cells"), "{msg}");
        let msg = e(&room(), ProjectionParams { min_points: 0, ..d });
        assert!(msg.starts_with("--min-points"), "{msg}");
        let band = HeightBand::AboveGround {
            low: 2.0,
            high: 1.0,
        };
        let msg = e(&room(), ProjectionParams { band, ..d });
        assert!(msg.starts_with("--height-above-ground"), "{msg}");
    }
}
