//! The campaign clock (beyond the paper): how long the scans, the CPS
//! measurements and the driving take, by the time model of `config.time`.
//!
//! CPS moves one robot at a time while the others stand as landmarks (paper
//! Fig. 1), so driving time is the team's whole travel over the speed. Each CPS
//! cycle measures every child twice: from the parent's old station after the
//! children moved, and from its new one after it moved.

use serde::{Deserialize, Serialize};

use crate::config::TimeConfig;

/// A campaign's time and its parts, hours.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CampaignTime {
    /// Scanning.
    pub scan_h: f64,
    /// CPS measurements.
    pub measure_h: f64,
    /// Driving, every robot in turn.
    pub drive_h: f64,
}

impl CampaignTime {
    /// The whole campaign, hours.
    pub fn total_h(&self) -> f64 {
        self.scan_h + self.measure_h + self.drive_h
    }
}

/// Accumulates a campaign's time as it runs.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    model: TimeConfig,
    children: usize,
    seconds: [f64; 3],
}

impl Clock {
    /// A clock at zero for a team of `children` children.
    pub fn new(model: TimeConfig, children: usize) -> Self {
        Self {
            model,
            children,
            seconds: [0.0; 3],
        }
    }

    /// One scan.
    pub fn scan(&mut self) {
        self.seconds[0] += self.model.scan_s;
    }

    /// A move of `cycles` CPS cycles in which the robots drove `travel_m` metres
    /// in all.
    pub fn moved(&mut self, cycles: usize, travel_m: f64) {
        self.seconds[1] += (2 * cycles * self.children) as f64 * self.model.measure_s;
        self.seconds[2] += travel_m / self.model.speed_m_s;
    }

    /// `count` measurements to targets or control points.
    pub fn measured(&mut self, count: usize) {
        self.seconds[1] += count as f64 * self.model.measure_s;
    }

    /// The time so far.
    pub fn time(&self) -> CampaignTime {
        let h = |s: f64| s / 3600.0;
        CampaignTime {
            scan_h: h(self.seconds[0]),
            measure_h: h(self.seconds[1]),
            drive_h: h(self.seconds[2]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn adds_scans_measurements_and_driving() {
        let model = TimeConfig {
            scan_s: 180.0,
            measure_s: 15.0,
            speed_m_s: 0.5,
        };
        let mut c = Clock::new(model, 2);
        c.scan();
        c.moved(3, 90.0);
        c.scan();
        let t = c.time();
        assert!((t.scan_h - 0.1).abs() < 1e-12);
        // 3 cycles × 2 children × 2 measurements × 15 s = 180 s.
        assert!((t.measure_h - 0.05).abs() < 1e-12);
        assert!((t.drive_h - 0.05).abs() < 1e-12);
        assert!((t.total_h() - 0.2).abs() < 1e-12);
    }
}
