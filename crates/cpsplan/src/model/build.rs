//! The registered model of a whole episode: every scan's points in its estimated
//! pose, the stations, and the accuracy against the ground truth.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use thiserror::Error;

use super::accuracy::{mean_and_p95, ModelAccuracy, ScanAccuracy};
use super::points::{ModelPoint, ModelStation};
use super::scan::{scan_points, Sampling, ScanPose};
use super::walls::GroundTruthWalls;
use crate::accuracy::Instrument;
use crate::config::Config;
use crate::grid::OccupancyGrid;
use crate::mission::Episode;
use crate::sensing::seen_walls;

/// Why the model of an episode cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModelError {
    /// The model would hold more points than the limit.
    #[error(
        "the 3D model would hold {points} points, more than `limits.max_cloud_points` = {limit}; \
         raise `model.vertical_step` or the limit"
    )]
    TooManyPoints {
        /// Points the model would hold.
        points: u64,
        /// `limits.max_cloud_points`.
        limit: usize,
    },
}

/// The registered model of an episode, without its points (they go to the
/// caller scan by scan).
#[derive(Debug, Clone, PartialEq)]
pub struct RegisteredModel {
    /// Every scan's station.
    pub stations: Vec<ModelStation>,
    /// How close the points lie to the ground-truth walls.
    pub accuracy: ModelAccuracy,
}

/// Which estimate of each scan's pose a model is registered in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Registration {
    /// The whole network adjusted with every measurement
    /// ([`crate::mission::Step::smoothed_estimate`]; the filtering estimate
    /// where the episode has none).
    #[default]
    Smoothed,
    /// What the team knew when it scanned ([`crate::mission::Step::estimate`]).
    Filtering,
}

/// Builds the registered model of `episode`, run on `truth` under `config`, in
/// the smoothed poses: [`build_model_in`] with [`Registration::Smoothed`].
pub fn build_model(
    truth: &OccupancyGrid,
    episode: &Episode,
    config: &Config,
    on_scan: impl FnMut(u32, &[ModelPoint]),
) -> Result<RegisteredModel, ModelError> {
    build_model_in(truth, episode, config, Registration::Smoothed, on_scan)
}

/// Builds the registered model of `episode`, run on `truth` under `config`:
/// each scan's points go to `on_scan(scan, points)` in scan order. The points of
/// a scan are expressed in the pose the CPS estimated for it by `registration`
/// (present with a Monte Carlo check; the true pose otherwise, so that only the
/// range noise remains). Seeded by `config.seed`: the same episode gives the
/// same points.
pub fn build_model_in(
    truth: &OccupancyGrid,
    episode: &Episode,
    config: &Config,
    registration: Registration,
    mut on_scan: impl FnMut(u32, &[ModelPoint]),
) -> Result<RegisteredModel, ModelError> {
    let m = &config.model;
    let (sampling, walls) = scans_of(truth, episode, config)?;
    let total: usize = walls.iter().map(|w| w.len() * sampling.rows).sum();
    let truth_walls = GroundTruthWalls::new(truth, m.wall_height);
    let mut stations = Vec::with_capacity(episode.steps.len());
    let mut scans = Vec::with_capacity(episode.steps.len());
    let mut all = Vec::with_capacity(total);
    let mut points = Vec::new();
    let mut distances = Vec::new();
    for (k, (step, walls)) in episode.steps.iter().zip(&walls).enumerate() {
        let scan = u32::try_from(k).unwrap_or(u32::MAX);
        let estimate = match registration {
            Registration::Smoothed => step.smoothed_estimate.or(step.estimate),
            Registration::Filtering => step.estimate,
        };
        let (error, heading_error) = match &estimate {
            Some(e) => (
                [
                    e.position.x - step.position.x,
                    e.position.y - step.position.y,
                    e.height_error_m,
                ],
                e.heading_error_rad(),
            ),
            None => ([0.0; 3], 0.0),
        };
        let pose = ScanPose {
            truth: [step.position.x, step.position.y, m.scanner_height],
            error,
            heading_error,
        };
        let mut rng = scan_rng(config.seed, k);
        points.clear();
        scan_points(truth, walls, &pose, &sampling, scan, &mut rng, &mut points);
        distances.clear();
        distances.extend(
            points
                .iter()
                .map(|p| truth_walls.distance(p.position) as f32),
        );
        all.extend_from_slice(&distances);
        let (mean, p95) = mean_and_p95(&mut distances);
        let position_error = error[0].hypot(error[1]);
        scans.push(ScanAccuracy {
            scan,
            points: points.len(),
            mean_distance_m: mean,
            p95_distance_m: p95,
            position_error_m: position_error,
            heading_error_arcsec: estimate.map_or(0.0, |e| e.heading_error_arcsec),
            position_sigma_m: step.position_sigma_m,
            smoothed_sigma_m: step.smoothed_sigma_m,
        });
        stations.push(ModelStation {
            scan,
            truth: pose.truth,
            estimate: pose.estimate(),
            heading_error_rad: heading_error,
            position_sigma_m: step.position_sigma_m,
        });
        on_scan(scan, &points);
    }
    let (mean, p95) = mean_and_p95(&mut all);
    Ok(RegisteredModel {
        stations,
        accuracy: ModelAccuracy {
            points: all.len(),
            mean_distance_m: mean,
            p95_distance_m: p95,
            max_position_error_m: scans.iter().map(|s| s.position_error_m).fold(0.0, f64::max),
            scans,
        },
    })
}

/// How many points the registered model of `episode` holds: every wall cell
/// each scan sees, sampled `model.wall_height / model.vertical_step` times up
/// the wall (known before any point is made, to check the memory it needs).
pub fn model_point_count(truth: &OccupancyGrid, episode: &Episode, config: &Config) -> u64 {
    let range = config.range_cells();
    let rows = wall_rows(config) as u64;
    episode
        .steps
        .iter()
        .map(|s| seen_walls(truth, s.cell, range).len() as u64 * rows)
        .sum()
}

/// Points of one wall column.
fn wall_rows(config: &Config) -> usize {
    let m = &config.model;
    ((m.wall_height / m.vertical_step).round() as usize).max(1)
}

/// How the points of every scan are sampled, and the wall cells each scan of
/// `episode` sees; refused when the model would exceed the points limit.
fn scans_of(
    truth: &OccupancyGrid,
    episode: &Episode,
    config: &Config,
) -> Result<(Sampling, Vec<Vec<usize>>), ModelError> {
    let m = &config.model;
    let rows = wall_rows(config);
    let instrument = Instrument::from_config(&config.instrument);
    let sampling = Sampling {
        rows,
        wall_height: m.wall_height,
        range_sigma: match m.range_sigma_mm {
            Some(mm) => [mm / 1000.0, 0.0],
            None => [instrument.distance_sigma, instrument.distance_ppm],
        },
    };
    let range = config.range_cells();
    let walls: Vec<Vec<usize>> = episode
        .steps
        .iter()
        .map(|s| seen_walls(truth, s.cell, range))
        .collect();
    let total: u64 = walls.iter().map(|w| w.len() as u64 * rows as u64).sum();
    if total > config.limits.max_cloud_points as u64 {
        return Err(ModelError::TooManyPoints {
            points: total,
            limit: config.limits.max_cloud_points,
        });
    }
    Ok((sampling, walls))
}

/// The range noise of scan `k` of a run seeded by `seed`.
fn scan_rng(seed: u64, k: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed ^ (k as u64 + 1).wrapping_mul(0xd1b5_4a32_d192_ed03))
}

/// Every scan of `episode` as the scanner itself records it: its points in the
/// scanner's frame (origin at the scanner's centre, axes along the world's: the
/// simulated instrument's circle is oriented at 0), with the same range noise
/// as [`build_model_in`]'s, to `on_scan(scan, points)` in scan order.
pub fn scanner_frame_scans(
    truth: &OccupancyGrid,
    episode: &Episode,
    config: &Config,
    mut on_scan: impl FnMut(u32, &[ModelPoint]),
) -> Result<(), ModelError> {
    let (sampling, walls) = scans_of(truth, episode, config)?;
    let mut points = Vec::new();
    for (k, (step, walls)) in episode.steps.iter().zip(&walls).enumerate() {
        let scan = u32::try_from(k).unwrap_or(u32::MAX);
        let truth_centre = [
            step.position.x,
            step.position.y,
            config.model.scanner_height,
        ];
        // Expressed in an "estimate" at the origin: the scanner's own frame.
        let pose = ScanPose {
            truth: truth_centre,
            error: truth_centre.map(|v| -v),
            heading_error: 0.0,
        };
        points.clear();
        scan_points(
            truth,
            walls,
            &pose,
            &sampling,
            scan,
            &mut scan_rng(config.seed, k),
            &mut points,
        );
        on_scan(scan, &points);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run_episode;
    use crate::world::builtin::BuiltinMap;

    /// A scan in the scanner's frame, moved to the scanner's true centre, is
    /// the registered model's scan where no pose was estimated (the true poses):
    /// the same points and the same noise.
    #[test]
    fn scanner_frames_are_the_model_moved_to_the_origin() {
        let map = BuiltinMap::Site;
        let mut config = Config::default();
        config.mission.max_scans = 3;
        let truth = map.generate(0);
        let episode = run_episode(&truth, map.default_start(), &config, |_| {}).unwrap();
        let mut registered: Vec<Vec<ModelPoint>> = Vec::new();
        build_model(&truth, &episode, &config, |_, p| {
            registered.push(p.to_vec())
        })
        .unwrap();
        let mut local: Vec<Vec<ModelPoint>> = Vec::new();
        scanner_frame_scans(&truth, &episode, &config, |_, p| local.push(p.to_vec())).unwrap();
        assert_eq!(local.len(), episode.steps.len());
        let range = config.scanner.range;
        for ((step, r), l) in episode.steps.iter().zip(&registered).zip(&local) {
            assert_eq!(r.len(), l.len());
            assert!(!l.is_empty());
            let centre = [
                step.position.x,
                step.position.y,
                config.model.scanner_height,
            ];
            for (a, b) in r.iter().zip(l) {
                assert_eq!(a.scan, b.scan);
                for ((r, c), l) in a.position.iter().zip(centre).zip(b.position) {
                    assert!((r - c - l).abs() < 1e-9);
                }
                let d = b.position.iter().map(|v| v * v).sum::<f64>().sqrt();
                assert!(d < range + 1.0, "{d}");
            }
        }
    }
}
