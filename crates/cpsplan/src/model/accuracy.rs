//! The model's accuracy: how far its points lie from the ground-truth walls, per
//! scan and overall, next to the error of the pose each scan was registered in.

use serde::{Deserialize, Serialize};

/// The accuracy of one scan's points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScanAccuracy {
    /// Index of the scan, from 0.
    pub scan: u32,
    /// Its points.
    pub points: usize,
    /// Mean distance of its points to the ground-truth walls, metres.
    pub mean_distance_m: f64,
    /// 95th percentile of that distance, metres.
    pub p95_distance_m: f64,
    /// Horizontal error of the pose the scan was registered in, metres.
    pub position_error_m: f64,
    /// Heading error of that pose, arc seconds.
    pub heading_error_arcsec: f64,
    /// The predicted radial 1σ of the scan position when it scanned
    /// (filtering), metres.
    pub position_sigma_m: Option<f64>,
    /// Its predicted radial 1σ after the whole network (smoothed), metres.
    #[serde(default)]
    pub smoothed_sigma_m: Option<f64>,
}

/// The accuracy of the whole model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelAccuracy {
    /// Points of the model.
    pub points: usize,
    /// Mean distance of all points to the ground-truth walls, metres.
    pub mean_distance_m: f64,
    /// 95th percentile of that distance, metres.
    pub p95_distance_m: f64,
    /// Largest horizontal pose error of any scan, metres.
    pub max_position_error_m: f64,
    /// Every scan.
    pub scans: Vec<ScanAccuracy>,
}

/// Mean and 95th percentile of `d` (reordered); zeros when empty. The
/// percentile is the nearest-rank one: the smallest value with at least 95 % of
/// the values at or below it.
pub fn mean_and_p95(d: &mut [f32]) -> (f64, f64) {
    if d.is_empty() {
        return (0.0, 0.0);
    }
    let mean = d.iter().map(|&v| f64::from(v)).sum::<f64>() / d.len() as f64;
    let rank = (0.95 * d.len() as f64).ceil() as usize;
    let k = rank.clamp(1, d.len()) - 1;
    let (_, p, _) = d.select_nth_unstable_by(k, f32::total_cmp);
    (mean, f64::from(*p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentile() {
        let mut d: Vec<f32> = (1..=100).map(|v| v as f32).collect();
        d.reverse();
        assert_eq!(mean_and_p95(&mut d), (50.5, 95.0));
        let mut one = vec![3.0_f32];
        assert_eq!(mean_and_p95(&mut one), (3.0, 3.0));
        assert_eq!(mean_and_p95(&mut []), (0.0, 0.0));
    }
}
