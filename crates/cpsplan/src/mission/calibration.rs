//! Online calibration of the gain estimate (beyond the paper): the ratio of the
//! free area the last scans actually added to what the estimate promised them,
//! applied to the next round's estimate.
//!
//! The estimate counts Unknown cells in view near known free space; how many of
//! them turn out free depends on the site (a clean floor plan delivers about
//! what it promises, a SLAM map full of laser streaks and specks a few per cent).
//! The episode measures it as it goes, so the stop rule (`parent.min_gain_m2`,
//! `parent.min_gain_share`) compares what a scan would really add.

use std::collections::VecDeque;

/// The factor is at most this.
pub const CALIBRATION_MAX: f64 = 2.0;

/// Scans needed before the factor departs from 1.
pub const CALIBRATION_MIN_SCANS: usize = 3;

/// The recent (estimated, actual) gains and their ratio.
#[derive(Debug, Clone, Default)]
pub struct GainCalibration {
    window: usize,
    floor: f64,
    pairs: VecDeque<(f64, f64)>,
}

impl GainCalibration {
    /// A calibration over the last `window` scans (0: off, the factor stays 1)
    /// whose factor is at least `floor`.
    pub fn new(window: usize, floor: f64) -> Self {
        Self {
            window,
            floor: floor.min(CALIBRATION_MAX),
            pairs: VecDeque::with_capacity(window),
        }
    }

    /// Records a scan that was expected to add `expected_m2` and added
    /// `actual_m2`.
    pub fn record(&mut self, expected_m2: f64, actual_m2: f64) {
        if self.window == 0 || !(expected_m2.is_finite() && actual_m2.is_finite()) {
            return;
        }
        if self.pairs.len() == self.window {
            self.pairs.pop_front();
        }
        self.pairs
            .push_back((expected_m2.max(0.0), actual_m2.max(0.0)));
    }

    /// Σ actual / Σ expected over the window, between the floor and
    /// [`CALIBRATION_MAX`]; 1 before [`CALIBRATION_MIN_SCANS`] scans.
    pub fn factor(&self) -> f64 {
        if self.pairs.len() < CALIBRATION_MIN_SCANS {
            return 1.0;
        }
        let (e, a) = self
            .pairs
            .iter()
            .fold((0.0, 0.0), |(e, a), p| (e + p.0, a + p.1));
        if e <= 0.0 {
            return 1.0;
        }
        (a / e).clamp(self.floor, CALIBRATION_MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_factor_is_the_windows_ratio() {
        let mut c = GainCalibration::new(3, 0.02);
        c.record(10.0, 5.0);
        c.record(10.0, 5.0);
        assert_eq!(c.factor(), 1.0);
        c.record(20.0, 2.0);
        assert!((c.factor() - 12.0 / 40.0).abs() < 1e-12);
        // The first scan leaves the window.
        c.record(10.0, 1.0);
        assert!((c.factor() - 8.0 / 40.0).abs() < 1e-12);
        // Bounded.
        for _ in 0..3 {
            c.record(100.0, 0.0);
        }
        assert_eq!(c.factor(), 0.02);
        assert_eq!(GainCalibration::new(0, 0.02).factor(), 1.0);
    }
}
