//! The accuracy of a mission's poses: the CPS chain ([`crate::accuracy::Chain`])
//! carried along the executed cycles, its figures written into the records, and
//! the Monte Carlo check of the whole campaign.

use serde::{Deserialize, Serialize};

use super::record::{CycleRecord, MoveRecord};
use crate::accuracy::{
    monte_carlo, realisation, Chain, CycleGeometry, Instrument, Model, PoseCovariance, ARCSEC,
};
use crate::config::Config;
use crate::geom::Point;

/// The predicted accuracy of one parent pose (first order, 1σ).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseAccuracy {
    /// Radial 1σ of the horizontal position, `sqrt(σx² + σy²)`, metres.
    pub position_sigma_m: f64,
    /// The horizontal position's covariance `[[xx, xy], [xy, yy]]`, m².
    pub covariance_m2: [[f64; 2]; 2],
    /// 1σ of the heading of the instrument's horizontal circle, arc seconds.
    pub heading_sigma_arcsec: f64,
}

impl From<PoseCovariance> for PoseAccuracy {
    fn from(p: PoseCovariance) -> Self {
        Self {
            position_sigma_m: p.position_sigma(),
            covariance_m2: [[p.xx, p.xy], [p.xy, p.yy]],
            heading_sigma_arcsec: p.heading_sigma() / ARCSEC,
        }
    }
}

/// The parent's pose at one scan as the CPS estimated it in one noisy
/// realisation of the campaign (the first Monte Carlo run): the pose the scan's
/// points are expressed in ([`crate::model`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseEstimate {
    /// The estimated scan position, world frame.
    pub position: Point,
    /// Radial error of that position, metres.
    pub position_error_m: f64,
    /// Error of the estimated height, metres (0 in 2D).
    pub height_error_m: f64,
    /// Error of the estimated heading, arc seconds.
    pub heading_error_arcsec: f64,
}

impl PoseEstimate {
    /// The estimate of a pose truly at `truth` with error `[x, y, z, ω]` (metres,
    /// radians).
    pub fn new(truth: Point, error: [f64; 4]) -> Self {
        Self {
            position: Point::new(truth.x + error[0], truth.y + error[1]),
            position_error_m: error[0].hypot(error[1]),
            height_error_m: error[2],
            heading_error_arcsec: error[3] / ARCSEC,
        }
    }

    /// The heading error, radians.
    pub fn heading_error_rad(&self) -> f64 {
        self.heading_error_arcsec * ARCSEC
    }
}

/// The CPS chain of a mission, with the geometry of every cycle run so far (for
/// the Monte Carlo check). `None` inside when the team cannot fix the parent's
/// pose (fewer than two children).
#[derive(Debug, Clone)]
pub struct Tracker {
    chain: Option<Chain>,
    start: Point,
    cycles: Vec<CycleGeometry>,
    /// Index of the last cycle of each executed move, in order.
    move_ends: Vec<usize>,
}

impl Tracker {
    /// The chain of a team of `config.children.count` children, the parent's
    /// pose at `start` known exactly.
    pub fn new(config: &Config, start: Point) -> Self {
        let model = Model::new(Instrument::from_config(&config.instrument));
        let n = config.children.count;
        Self {
            chain: (n >= 2).then(|| Chain::new(model, start, n)),
            start,
            cycles: Vec::new(),
            move_ends: Vec::new(),
        }
    }

    /// The CPS chain where the team stands now.
    pub fn chain(&self) -> Option<&Chain> {
        self.chain.as_ref()
    }

    /// The predicted accuracy of the parent's current pose.
    pub fn current(&self) -> Option<PoseAccuracy> {
        self.chain.as_ref().map(|c| c.pose().into())
    }

    /// Writes into `movement` the predicted σ after each of its cycles, carrying
    /// the chain along them when `execute` (a move planned at the scan limit is
    /// only recorded). A geometry the chain cannot handle ends the prediction.
    pub fn follow(&mut self, movement: &mut MoveRecord, execute: bool) {
        let Some(chain) = self.chain.as_ref() else {
            return;
        };
        let mut next = chain.clone();
        let mut ok = true;
        let mut geometry = Vec::with_capacity(movement.cycles.len());
        for cycle in &mut movement.cycles {
            let g = geometry_of(cycle);
            match next.cycle(g.to, &g.children, &g.moved) {
                Ok(p) => cycle.position_sigma_m = Some(p.position_sigma()),
                Err(_) => {
                    ok = false;
                    break;
                }
            }
            geometry.push(g);
        }
        if !execute {
            return;
        }
        if !ok {
            self.chain = None;
            return;
        }
        if !geometry.is_empty() {
            self.cycles.extend(geometry);
            self.move_ends.push(self.cycles.len() - 1);
        }
        self.chain = Some(next);
    }

    /// The pose error `[x, y, z, ω]` at every scan after the first (one per
    /// executed move) in the first Monte Carlo run seeded by `seed`; `None`
    /// without a chain.
    pub fn realisation(&self, seed: u64) -> Option<Vec<[f64; 4]>> {
        let chain = self.chain.as_ref()?;
        let errors = realisation(chain.model(), self.start, &self.cycles, seed, 0).ok()?;
        Some(self.move_ends.iter().map(|&c| errors[c]).collect())
    }

    /// The Monte Carlo mean radial error at every scan after the first (one per
    /// executed move), with `runs` runs seeded by `seed`; `None` without a chain.
    pub fn monte_carlo(&self, runs: usize, seed: u64) -> Option<Vec<f64>> {
        let chain = self.chain.as_ref()?;
        if runs == 0 {
            return None;
        }
        let mc = monte_carlo(chain.model(), self.start, &self.cycles, runs, seed).ok()?;
        Some(self.move_ends.iter().map(|&c| mc.mean_error[c]).collect())
    }
}

/// The chain's view of a recorded cycle.
fn geometry_of(cycle: &CycleRecord) -> CycleGeometry {
    CycleGeometry {
        to: cycle.parent_to,
        children: cycle.children.iter().map(|c| c.to).collect(),
        moved: cycle.children.iter().map(|c| !c.stays).collect(),
    }
}
