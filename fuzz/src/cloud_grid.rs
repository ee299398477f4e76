//! The `cloud_grid` fuzz target's body.
use cpsplan::world::projection::{project, BeamOrigin, GroundModel, HeightBand, ProjectionParams};
use cpsplan::Config;
use cpsplan_cli::formats::cloud::{parse_cloud, CloudFormat, CloudReadOptions};

const FORMATS: [CloudFormat; 5] = [
    CloudFormat::Las,
    CloudFormat::Laz,
    CloudFormat::E57,
    CloudFormat::Ply,
    CloudFormat::Pcd,
];

const RESOLUTIONS: [f64; 4] = [0.1, 0.05, 0.5, 2.0];

/// Bytes to a grid: a point cloud parsed from memory in one of the five
/// formats, then projected. Asserts: no panic, at most the small point and cell
/// limits below, and a projection whose counts add up.
///
/// Input layout:
/// - byte 0: format (`% 5`: LAS, LAZ, E57, PLY, PCD);
/// - byte 1: resolution (`% 4`: 0.1, 0.05, 0.5, 2 m) and options (bit 2: ground
///   `lowest` instead of `plane`, bit 3: an absolute band, bit 4: outlier removal,
///   bit 5: beams from the origin, bit 6: drop invalid points);
/// - the rest: the file's bytes.
pub fn run(data: &[u8]) {
    if data.len() < 2 {
        return;
    }
    let format = FORMATS[usize::from(data[0]) % FORMATS.len()];
    let flags = data[1];
    let options = CloudReadOptions {
        max_points: 1 << 16,
        max_bytes: 1 << 20,
        drop_invalid: flags & 64 != 0,
        units: None,
    };
    let Ok(cloud) = parse_cloud(&data[2..], format, &options) else {
        return;
    };
    assert!(!cloud.points.is_empty(), "an empty cloud is an error");
    assert!(cloud.points.len() as u64 <= options.max_points);
    assert!(cloud.points.iter().all(|p| p.iter().all(|v| v.is_finite())));
    for s in &cloud.scans {
        assert!(s.points.start <= s.points.end && s.points.end <= cloud.points.len());
    }
    let mut config = Config::default();
    config.limits.max_grid_cells = 1 << 18;
    let params = ProjectionParams {
        resolution: RESOLUTIONS[usize::from(flags) % RESOLUTIONS.len()],
        ground: if flags & 4 != 0 {
            GroundModel::Lowest { window: 1.0 }
        } else {
            GroundModel::Plane
        },
        band: if flags & 8 != 0 {
            HeightBand::Absolute {
                min: -1.0,
                max: 1.0,
            }
        } else {
            ProjectionParams::default().band
        },
        outlier_radius: (flags & 16 != 0).then_some(0.5),
        free_from_scans: flags & 32 != 0,
        ..ProjectionParams::default()
    };
    let origins: Vec<BeamOrigin> = cloud
        .scans
        .iter()
        .map(|s| BeamOrigin {
            points: s.points.clone(),
            origin: s.origin.unwrap_or([0.0; 3]),
        })
        .collect();
    let Ok(p) = project(&cloud.points, &origins, &params, &config, |_, _| {}) else {
        return;
    };
    let g = p.grid.geometry();
    assert!((g.len() as u64) <= config.limits.max_grid_cells as u64);
    let s = p.stats;
    assert_eq!(s.points_kept + s.outliers, cloud.points.len());
    assert!(s.obstacle_points + s.ground_points + s.above_points <= s.points_kept);
    assert_eq!(s.free_cells + s.occupied_cells + s.unknown_cells, g.len());
}
