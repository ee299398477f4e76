//! What `campaign add` writes besides the scan: `next.json` (the next step
//! for the team) and `network.json` (every station and point adjusted).

use anyhow::Result;
use cpsplan::accuracy::{reading_name, Reading, Survey};
use cpsplan::grid::CellState;
use cpsplan::mission::{CampaignRun, MoveRecord};
use cpsplan::parent::Decision;
use cpsplan::{Config, Point};
use serde::{Deserialize, Serialize};

use super::store::{Poses, ScanRecord};

/// `next.json`: where the campaign stands and what the team does next.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NextPlan {
    /// Scans so far.
    pub scans: usize,
    /// The station of the last scan.
    pub station: StationNow,
    /// The known free area, m².
    pub known_area_m2: f64,
    /// The campaign's time so far by the time model, hours.
    pub campaign_time_h: f64,
    /// Why the campaign is complete (`None`: it goes on with `next`).
    pub stop: Option<String>,
    /// The next scan and the CPS cycles that take the team there.
    pub next: Option<NextStep>,
    /// The planning round's full record of the move (every robot's path,
    /// the AND regions' sizes, the predicted σ after each cycle).
    #[serde(rename = "move", skip_serializing_if = "Option::is_none")]
    pub movement: Option<MoveRecord>,
}

/// The last scan's station.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StationNow {
    /// Its name in the readings.
    pub name: String,
    /// Where it stands, world frame (adjusted).
    pub position: Point,
    /// Its radial 1σ, metres (filtering: the readings up to this scan).
    pub sigma_m: f64,
    /// Where its instrument's zero points, degrees counter-clockwise from x.
    pub heading_deg: f64,
}

/// The next scan.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NextStep {
    /// Where the parent scans next, world frame.
    pub position: Point,
    /// The new free area expected there, m².
    pub expected_gain_m2: f64,
    /// The predicted radial 1σ of the next station, metres.
    pub predicted_sigma_m: Option<f64>,
    /// Every CPS cycle in order.
    pub cycles: Vec<NextCycle>,
}

/// One CPS cycle: the children move (or stay), then the parent.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NextCycle {
    /// Where the parent sets up at the end of the cycle.
    pub parent_to: Point,
    /// The parent's path, world metres.
    pub parent_path: Vec<Point>,
    /// Every child's spot and path.
    pub children: Vec<NextChild>,
}

/// One child in a CPS cycle.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NextChild {
    /// The child, from 1 (its markers are `C<child>.<n>`).
    pub child: usize,
    /// Its spot for the cycle.
    pub to: Point,
    /// Whether it stays where it is.
    pub stays: bool,
    /// Its path, world metres.
    pub path: Vec<Point>,
}

/// The next plan of a replayed campaign.
pub fn next_plan(
    run: &CampaignRun,
    records: &[ScanRecord],
    config: &Config,
    position: Point,
    heading_rad: f64,
) -> NextPlan {
    let knowledge = run.episode.knowledge.as_ref();
    let cell_m2 = config.resolution * config.resolution;
    let known_area_m2 = knowledge.map_or(0.0, |k| {
        k.cells().iter().filter(|&&c| c == CellState::Free).count() as f64 * cell_m2
    });
    let last = run.episode.steps.last();
    let record = records.last();
    let station = StationNow {
        name: record.map_or_else(String::new, |r| r.name.clone()),
        position,
        sigma_m: record.map_or(0.0, |r| r.sigma_m),
        heading_deg: heading_rad.to_degrees(),
    };
    let stop = run.stop.map(|r| r.name().to_string()).or_else(|| {
        (run.scans_used < records.len()).then(|| "stopped before the last scan".to_string())
    });
    let next = match (stop.is_none(), last) {
        (true, Some(step)) => match (step.plan.decision, step.movement.target) {
            (Decision::Target { .. }, Some(t)) => step.plan.candidates.get(t).map(|c| NextStep {
                position: c.position,
                expected_gain_m2: c.gain_m2,
                predicted_sigma_m: predicted_sigma(step, record.map_or(0.0, |r| r.sigma_m)),
                cycles: step
                    .movement
                    .cycles
                    .iter()
                    .map(|c| NextCycle {
                        parent_to: c.parent_to,
                        parent_path: c.parent_path.clone(),
                        children: c
                            .children
                            .iter()
                            .enumerate()
                            .map(|(i, k)| NextChild {
                                child: i + 1,
                                to: k.to,
                                stays: k.stays,
                                path: k.path.clone(),
                            })
                            .collect(),
                    })
                    .collect(),
            }),
            _ => None,
        },
        _ => None,
    };
    NextPlan {
        scans: records.len(),
        station,
        known_area_m2,
        campaign_time_h: last.map_or(0.0, |s| s.clock_h),
        stop,
        movement: next.as_ref().and(last.map(|s| s.movement.clone())),
        next,
    }
}

/// The predicted radial σ of the next station: the adjusted σ of the station
/// now, with what the planned move adds (the planning chain's σ after the
/// move against its σ at this scan).
fn predicted_sigma(step: &cpsplan::mission::Step, now_m: f64) -> Option<f64> {
    let after = step.movement.cycles.last()?.position_sigma_m?;
    let before = step.position_sigma_m.unwrap_or(0.0);
    let added = (after * after - before * before).max(0.0);
    Some((now_m * now_m + added).sqrt())
}

/// One station or point of `network.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NetworkPoint {
    /// Its name in the readings.
    pub name: String,
    /// Its adjusted position, world frame.
    pub position: Point,
    /// Its adjusted height (3D model).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    /// A station's heading: where its instrument's zero points, degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_deg: Option<f64>,
    /// Radial 1σ, metres (every reading so far).
    pub sigma_m: f64,
    /// Covariance of the position, m².
    pub covariance_m2: [[f64; 2]; 2],
}

/// `network.json`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NetworkFile {
    /// Every station in the order it was set up.
    pub stations: Vec<NetworkPoint>,
    /// Every point in the order it was first measured.
    pub points: Vec<NetworkPoint>,
    /// Readings left out as blunders, `station → point (wσ)`.
    pub left_out: Vec<String>,
    /// The largest standardized residual of the last scan's readings.
    pub max_standardized_residual: f64,
}

impl NetworkFile {
    /// Every station's and point's pose.
    pub fn poses(&self) -> Poses {
        let stations = self.stations.iter().map(|p| {
            let heading = p.heading_deg.unwrap_or(0.0).to_radians();
            (p.name.clone(), (p.position, heading))
        });
        let points = self
            .points
            .iter()
            .map(|p| (p.name.clone(), (p.position, 0.0)));
        stations.chain(points).collect()
    }
}

/// `network.json` of `survey` (adjusted from `readings`).
pub fn network_json(survey: &Survey, readings: &[Reading]) -> Result<Vec<u8>> {
    // 3D: a station holds [x, y, z, ω], a point [x, y, z].
    let three_d = |len: usize, station: bool| len == if station { 4 } else { 3 };
    let point = |a: &cpsplan::accuracy::Adjusted, station: bool| NetworkPoint {
        name: a.name.clone(),
        position: a.position(),
        z: three_d(a.value.len(), station).then(|| a.value[2]),
        heading_deg: station.then(|| a.value[a.value.len() - 1].to_degrees()),
        sigma_m: a.sigma_m(),
        covariance_m2: a.covariance_2d(),
    };
    let file = NetworkFile {
        stations: survey.stations.iter().map(|a| point(a, true)).collect(),
        points: survey.points.iter().map(|a| point(a, false)).collect(),
        left_out: survey
            .left_out
            .iter()
            .map(|b| {
                format!(
                    "{} ({:.1}σ)",
                    reading_name(&readings[b.reading]),
                    b.standardized
                )
            })
            .collect(),
        max_standardized_residual: survey.max_standardized,
    };
    let mut bytes = serde_json::to_vec_pretty(&file)?;
    bytes.push(b'\n');
    Ok(bytes)
}
