//! A whole simulated episode: scan, plan the parent's next position, move the team
//! there, scan again, until no reachable frontier remains or the scan limit is
//! reached. Every step is recorded.

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::accuracy::{FitRecord, PoseAccuracy, PoseEstimate, Tracker};
use super::calibration::GainCalibration;
use super::clock::{CampaignTime, Clock};
use super::record::MoveRecord;
use super::source::{ScanSource, Simulated};
pub use super::stop::{StopReason, START_REGION_SHARE, START_REGION_SHARE_OF_MAP};
use super::targets::{choose_target, PlacementView, TargetOrigin, TargetRecord};
use super::team;
use crate::config::{number, Config, ConfigError, Planner};
use crate::geom::{Cell, Point};
use crate::grid::{CellState, Drivable, OccupancyGrid};
use crate::motion::VoronoiField;
use crate::parent::{CandidateOrigin, Decision, Frontier, Kept, ParentPlan};
use crate::sensing::{NearField, ScanOutcome};
use crate::world::CoverageTracker;

/// Why a mission could not start.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MissionError {
    /// A parameter is out of range.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The start lies outside the map.
    #[error(
        "start ({}, {}) is outside the map (x {} to {} m, y {} to {} m)",
        number(*x), number(*y), number(*x0), number(*x1), number(*y0), number(*y1)
    )]
    StartOutsideMap {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Map bounds.
        x0: f64,
        /// Map bounds.
        x1: f64,
        /// Map bounds.
        y0: f64,
        /// Map bounds.
        y1: f64,
    },
    /// The start is not in free space.
    #[error(
        "start ({}, {}) is inside an obstacle or unknown space, not free space",
        number(*x),
        number(*y)
    )]
    StartNotFree {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
    },
}

/// Whether the last step's planned target `index` came from the search of the
/// band's reachable cells (the round's own candidates expected too little).
fn is_fallback(steps: &[Step], index: usize) -> bool {
    steps
        .last()
        .and_then(|s| s.plan.candidates.get(index))
        .is_some_and(|c| c.origin == CandidateOrigin::Fallback)
}

/// One scan and the planning round that followed it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// Scan number, from 1.
    pub scan: usize,
    /// Where the parent scanned, world frame (cell centre).
    pub position: Point,
    /// The scan's cell.
    pub cell: Cell,
    /// What the scan added.
    pub outcome: ScanOutcome,
    /// Coverage after the scan.
    pub coverage: f64,
    /// Wall coverage after the scan.
    pub wall_coverage: f64,
    /// The free area the scan added, m² (`outcome.new_free` cells).
    #[serde(default)]
    pub gain_m2: f64,
    /// The gain estimate of the round that chose this position, m²
    /// (`sensing::GainEstimate`; `None` for the first scan).
    #[serde(default)]
    pub expected_gain_m2: Option<f64>,
    /// That round's `S` of Eq. (1) for this position, cells.
    #[serde(default)]
    pub expected_s_cells: Option<usize>,
    /// The gain estimate's scale in the round after this scan: `parent.gain_scale`
    /// times the episode's calibration (`mission::GainCalibration`).
    #[serde(default)]
    pub gain_scale: f64,
    /// The campaign clock when this scan ends, hours (`config.time`).
    #[serde(default)]
    pub clock_h: f64,
    /// Parent travel so far, metres.
    pub parent_travel_m: f64,
    /// The planning round after the scan.
    pub plan: ParentPlan,
    /// The children's cells during the scan.
    pub children: Vec<Point>,
    /// Predicted radial 1σ of the scan position, `sqrt(σx² + σy²)`, metres (the
    /// CPS chain, first order, from the exactly known start; `None` without at
    /// least two children).
    pub position_sigma_m: Option<f64>,
    /// The scan position's covariance `[[xx, xy], [xy, yy]]`, m².
    pub covariance_m2: Option<[[f64; 2]; 2]>,
    /// 1σ of the parent's heading (its instrument's horizontal circle) at the
    /// scan, arc seconds.
    pub heading_sigma_arcsec: Option<f64>,
    /// With a Monte Carlo check: the mean radial error of the scan position over
    /// the runs, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monte_carlo_error_m: Option<f64>,
    /// With a Monte Carlo check: the pose the CPS estimated for this scan in the
    /// first run, when it scanned (the filtering estimate).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub estimate: Option<PoseEstimate>,
    /// Predicted radial 1σ of the scan position given every measurement of the
    /// episode (the whole network adjusted at once: the *smoothed* σ), metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smoothed_sigma_m: Option<f64>,
    /// The smoothed covariance of the scan position, m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smoothed_covariance_m2: Option<[[f64; 2]; 2]>,
    /// The smoothed 1σ of the heading, arc seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smoothed_heading_sigma_arcsec: Option<f64>,
    /// With a Monte Carlo check: the mean radial error of the smoothed position
    /// over the runs, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smoothed_monte_carlo_error_m: Option<f64>,
    /// With a Monte Carlo check: the smoothed pose of this scan in the first run
    /// (the pose its points are registered in, [`crate::model`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub smoothed_estimate: Option<PoseEstimate>,
    /// Targets and control points this scan station measured (indices into the
    /// episode's `targets`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub targets: Vec<usize>,
    /// How the station's measurements are checked and, with a Monte Carlo
    /// check, fit in the adjustment of the whole network.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitRecord>,
    /// The move that followed: CPS cycles to the target (empty without children or
    /// when the mission stopped here).
    #[serde(rename = "move")]
    pub movement: MoveRecord,
}

impl Step {
    /// The filtering accuracy of the scan position, as recorded.
    pub fn accuracy(&self) -> Option<PoseAccuracy> {
        Some(PoseAccuracy {
            position_sigma_m: self.position_sigma_m?,
            covariance_m2: self.covariance_m2?,
            heading_sigma_arcsec: self.heading_sigma_arcsec?,
        })
    }

    /// The path the parent drove after this step, world frame
    /// ([`parent_path`]).
    pub fn driven_path(&self) -> Vec<Point> {
        parent_path(&self.plan, &self.movement)
    }
}

/// The parent's path of a planning round and its move, world frame: the CPS
/// cycles' paths when it moves by cycles, else the planned path (empty without a
/// target).
pub fn parent_path(plan: &ParentPlan, movement: &MoveRecord) -> Vec<Point> {
    if movement.cycles.is_empty() {
        plan.path.clone()
    } else {
        movement
            .cycles
            .iter()
            .flat_map(|c| c.parent_path.iter().copied())
            .collect()
    }
}

/// Totals of an episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Number of scans.
    pub scans: usize,
    /// Final coverage of reachable free space.
    pub coverage: f64,
    /// Final coverage of the walls bordering it.
    pub wall_coverage: f64,
    /// Final coverage of all free space 4-connected to the start, reachable or not.
    pub connected_coverage: f64,
    /// Free cells the robots can reach from the start (the coverage denominator).
    pub reachable_free_cells: usize,
    /// Free cells 4-connected to the start, reachable or not.
    pub connected_free_cells: usize,
    /// Free cells of the whole map.
    pub map_free_cells: usize,
    /// Total length of the parent's driven paths, metres.
    pub parent_travel_m: f64,
    /// Why the episode ended.
    pub stop_reason: StopReason,
    /// The seed of every random choice.
    pub seed: u64,
    /// CPS cycles run.
    pub cps_cycles: usize,
    /// Moves that needed subgoals (section IV-C).
    pub subgoal_retrievals: usize,
    /// Total length of each child's driven paths, metres.
    pub child_travel_m: Vec<f64>,
    /// The instrument of the CPS links (its preset's name).
    pub instrument: String,
    /// Predicted radial 1σ of the last scan position, metres (`None` without at
    /// least two children).
    pub final_position_sigma_m: Option<f64>,
    /// That σ as a percentage of the parent's travel (the paper's figure of
    /// merit: 0.034–0.054 % for CPS-VII, 0.0085 % for CPS-VIII).
    pub error_percent_of_travel: Option<f64>,
    /// Monte Carlo runs through the campaign's chain (0: none).
    pub monte_carlo_runs: usize,
    /// The Monte Carlo mean radial error of the last scan position, metres.
    pub monte_carlo_mean_error_m: Option<f64>,
    /// The campaign's time by the time model (`config.time`), hours.
    #[serde(default)]
    pub campaign_time_h: f64,
    /// Its parts: scanning, CPS measurements, driving.
    #[serde(default)]
    pub campaign_time: CampaignTime,
    /// The planner that chose the scan positions.
    #[serde(default)]
    pub planner: Planner,
    /// The largest predicted filtering σ of any scan position, metres.
    #[serde(default)]
    pub worst_position_sigma_m: Option<f64>,
    /// The largest smoothed σ of any scan position, metres.
    #[serde(default)]
    pub worst_smoothed_sigma_m: Option<f64>,
    /// The smoothed σ of the last scan position, metres (equal to its
    /// filtering σ: nothing after it refines it).
    #[serde(default)]
    pub final_smoothed_sigma_m: Option<f64>,
    /// With a Monte Carlo check: the mean radial error of the last scan
    /// position's smoothed estimate, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monte_carlo_smoothed_mean_error_m: Option<f64>,
    /// Targets the team left.
    #[serde(default)]
    pub targets_placed: usize,
    /// Stations that measured a control point or a target first measured at
    /// least two scans before (the network's closures).
    #[serde(default)]
    pub closures: usize,
    /// Moves that made a closure first to keep the tolerance.
    #[serde(default)]
    pub closure_moves: usize,
    /// The scans whose predicted filtering σ was above `mission.max_sigma_m`.
    #[serde(default)]
    pub sigma_violations: Vec<usize>,
}

/// A whole simulated episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Episode {
    /// The parameters used.
    pub config: Config,
    /// The start, world frame (cell centre).
    pub start: Point,
    /// Every scan in order.
    pub steps: Vec<Step>,
    /// Totals.
    pub summary: Summary,
    /// The targets and control points, given and placed (absent when none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub targets: Vec<TargetRecord>,
    /// The final knowledge map.
    #[serde(skip)]
    pub knowledge: Option<OccupancyGrid>,
}

/// The cell of `start` on `truth`, which must be Free there.
pub fn start_cell(truth: &OccupancyGrid, start: Point) -> Result<Cell, MissionError> {
    let g = truth.geometry();
    let cell = g.world_to_cell(start).ok_or_else(|| {
        let (ex, ey) = g.extent();
        MissionError::StartOutsideMap {
            x: start.x,
            y: start.y,
            x0: g.origin.x,
            x1: g.origin.x + ex,
            y0: g.origin.y,
            y1: g.origin.y + ey,
        }
    })?;
    if truth.get(cell) != CellState::Free {
        return Err(MissionError::StartNotFree {
            x: start.x,
            y: start.y,
        });
    }
    Ok(cell)
}

/// Runs a whole episode on the ground truth `truth` (planning resolution already
/// applied; anything not Free is solid) from `start`. `on_step` sees every step as
/// it is recorded (for progress display).
pub fn run_episode(
    truth: &OccupancyGrid,
    start: Point,
    config: &Config,
    mut on_step: impl FnMut(&Step),
) -> Result<Episode, MissionError> {
    run_episode_with(truth, start, config, |step, _| on_step(step))
}

/// Frees the buffers the planning keeps between steps when dropped.
struct ReleaseBuffers;

impl Drop for ReleaseBuffers {
    fn drop(&mut self) {
        crate::motion::release_buffers();
        crate::grid::travel::release_buffers();
    }
}

/// [`run_episode`], with `on_step` also seeing the knowledge map the step planned
/// on (after its scan), e.g. to draw that step.
pub fn run_episode_with(
    truth: &OccupancyGrid,
    start: Point,
    config: &Config,
    on_step: impl FnMut(&Step, &OccupancyGrid),
) -> Result<Episode, MissionError> {
    run_episode_until(truth, start, config, &AtomicBool::new(false), on_step)
}

/// [`run_episode_with`] that ends early once `interrupt` is set (a user's
/// Ctrl-C): the scan under way is recorded, its planned move is not made, and
/// the summary's stop reason is [`StopReason::Interrupted`]. The episode so
/// far is whole: every figure of a report can be drawn from it.
pub fn run_episode_until(
    truth: &OccupancyGrid,
    start: Point,
    config: &Config,
    interrupt: &AtomicBool,
    on_step: impl FnMut(&Step, &OccupancyGrid),
) -> Result<Episode, MissionError> {
    config.validate()?;
    let g = *truth.geometry();
    g.check_limits(config)?;
    let truth = truth.solidified();
    let cell = start_cell(&truth, start)?;
    let knowledge = OccupancyGrid::filled(g, CellState::Unknown);
    let mut source = Simulated { truth: &truth };
    let (episode, _) = run_loop(&mut source, knowledge, cell, config, interrupt, on_step);
    Ok(episode)
}

/// The loop of an episode from `cell` on `knowledge` (what the team knows
/// before its first scan), its scans and arrivals from `source`; `config`
/// valid and within the limits for the map. Returns the episode and why it
/// stopped (`None`: `source` had no further scan, a campaign waiting for its
/// next one; the summary's stop reason is then [`StopReason::ScanLimit`]).
pub(crate) fn run_loop<S: ScanSource>(
    source: &mut S,
    mut knowledge: OccupancyGrid,
    cell: Cell,
    config: &Config,
    interrupt: &AtomicBool,
    mut on_step: impl FnMut(&Step, &OccupancyGrid),
) -> (Episode, Option<StopReason>) {
    // The working buffers of the GVD and of the band's search are kept from step
    // to step, and freed when the episode ends, however it ends.
    let _buffers = ReleaseBuffers;
    let g = *knowledge.geometry();
    let mut chain = Tracker::new(config, g.cell_center(cell));
    let mut tracker = source
        .truth()
        .map(|t| CoverageTracker::new(t, cell, config.robot.radius, &knowledge));
    let mut here = cell;
    let mut travel = 0.0;
    let mut children: Vec<Cell> = Vec::new();
    let mut child_travel = vec![0.0; config.children.count];
    let (mut cycles, mut retrievals) = (0usize, 0usize);
    let mut steps: Vec<Step> = Vec::new();
    let mut clock = Clock::new(config.time, config.children.count);
    let mut expected: Option<(f64, usize)> = None;
    let mut calibration = GainCalibration::new(
        config.parent.calibration_window,
        config.parent.calibration_floor,
    );
    let cell_m2 = g.resolution * g.resolution;
    // The gain estimate's field, the border and band, the parent's drivable
    // cells and, with children, the GVD's obstacle side, kept up to date scan by
    // scan.
    let mut near = NearField::new(&knowledge, config);
    let mut frontier = Frontier::new(&knowledge, &config.parent);
    let mut drivable = Drivable::new(&knowledge, config.robot.radius);
    let mut voronoi = (config.children.count > 0).then(|| VoronoiField::new(&knowledge));
    let mut changed: Vec<usize> = Vec::new();
    let stop_reason = loop {
        changed.clear();
        let outcome = source.scan(&mut knowledge, here, config.range_cells(), &mut |i| {
            if let Some(t) = tracker.as_mut() {
                t.note_seen(i);
            }
            changed.push(i);
        });
        rayon::join(
            || {
                rayon::join(
                    || near.update(&knowledge, &changed),
                    || {
                        if let Some(v) = voronoi.as_mut() {
                            v.update(&knowledge, &changed);
                        }
                    },
                )
            },
            || {
                rayon::join(
                    || frontier.update(&knowledge, &changed),
                    || drivable.update(&knowledge, &changed),
                )
            },
        );
        clock.scan();
        if steps.is_empty() && config.children.count > 0 {
            children = team::initial_children(&knowledge, here, config);
        }
        // The targets this station measures: at the start those in sight now,
        // later those the move's last cycle measured on arrival.
        let sighted_here = match steps.last() {
            None => {
                let s = chain.sight_start(&knowledge, here);
                clock.measured(s.len());
                s
            }
            Some(last) => last
                .movement
                .cycles
                .last()
                .map(|c| c.targets.clone())
                .unwrap_or_default(),
        };
        let gain_m2 = outcome.new_free as f64 * cell_m2;
        if let Some((e, _)) = expected {
            calibration.record(e, gain_m2);
        }
        let mut round = config.clone();
        round.parent.gain_scale *= calibration.factor();
        let kept = Kept {
            near: &near,
            frontier: &frontier,
            drivable: &drivable,
            truth: source.truth(),
        };
        let (mut plan, reach, groundwork) = team::plan_round(
            &knowledge,
            here,
            &round,
            &mut team::round_rng(config.seed, steps.len() + 1),
            Some(kept),
            voronoi.as_ref(),
        );
        // Read once: the round ends as at the scan limit, under its own name.
        let interrupted = interrupt.load(Ordering::Relaxed);
        let at_limit = interrupted || steps.len() + 1 >= config.mission.max_scans;
        // Diminishing returns: what the last scans added against the known area.
        let window = config.mission.stop_window;
        let diminishing = window > 0 && steps.len() + 1 >= window && {
            let recent = gain_m2
                + steps
                    .iter()
                    .rev()
                    .take(window - 1)
                    .map(|s| s.gain_m2)
                    .sum::<f64>();
            let known_free = near.free_cells() as f64 * cell_m2;
            recent < config.mission.stop_share * known_free
        };
        let (movement, moved) = match plan.decision {
            Decision::Target { index } => {
                if config.children.count == 0 {
                    let record = MoveRecord {
                        target: Some(index),
                        ..MoveRecord::default()
                    };
                    let moved = team::Moved {
                        parent: plan.candidates[index].cell,
                        children: Vec::new(),
                        parent_length: plan.path_length_m,
                        child_lengths: Vec::new(),
                    };
                    (record, Some(moved))
                } else {
                    let team = team::Team {
                        parent: here,
                        children: &children,
                        chain: chain.chain(),
                        anchors: chain.anchors(),
                        carried: config.targets.team_targets().saturating_sub(chain.placed()),
                    };
                    team::execute_move(&knowledge, team, &mut plan, reach, groundwork, &round)
                }
            }
            _ => (MoveRecord::default(), None),
        };
        let accuracy = chain.current();
        let (mut movement, moved) = (movement, moved);
        let executes = !at_limit && !diminishing && moved.is_some();
        let carried = config.targets.team_targets().saturating_sub(chain.placed());
        let placed_already = movement
            .cycles
            .first()
            .is_some_and(|c| !c.left_targets.is_empty());
        if let (true, Some(c)) = (executes && carried > 0 && !placed_already, chain.chain()) {
            let view = PlacementView {
                knowledge: &knowledge,
                here,
                plan: &plan,
                chain: c,
                rule: chain.rule(),
                scanner_range: config.scanner.range,
                carried,
                budget: config.targets.team_targets(),
                anchor_sigma: chain.anchor_sigma(),
            };
            if let (Some(left), Some(first)) =
                (choose_target(&view, &movement), movement.cycles.first_mut())
            {
                first.left_targets.push(left);
            }
        }
        chain.follow(&knowledge, &mut movement, executes, steps.len() + 1);
        let step = Step {
            scan: steps.len() + 1,
            position: g.cell_center(here),
            cell: here,
            outcome,
            coverage: tracker.as_ref().map_or(0.0, CoverageTracker::coverage),
            wall_coverage: tracker.as_ref().map_or(0.0, CoverageTracker::wall_coverage),
            gain_m2,
            gain_scale: round.parent.gain_scale,
            expected_gain_m2: expected.map(|e| e.0),
            expected_s_cells: expected.map(|e| e.1),
            clock_h: clock.time().total_h(),
            parent_travel_m: travel,
            children: children.iter().map(|&c| g.cell_center(c)).collect(),
            position_sigma_m: accuracy.map(|a| a.position_sigma_m),
            covariance_m2: accuracy.map(|a| a.covariance_m2),
            heading_sigma_arcsec: accuracy.map(|a| a.heading_sigma_arcsec),
            monte_carlo_error_m: None,
            estimate: None,
            smoothed_sigma_m: None,
            smoothed_covariance_m2: None,
            smoothed_heading_sigma_arcsec: None,
            smoothed_monte_carlo_error_m: None,
            smoothed_estimate: None,
            fit: None,
            targets: sighted_here,
            plan,
            movement,
        };
        on_step(&step, &knowledge);
        let decision = step.plan.decision;
        if !at_limit && !diminishing {
            cycles += step.movement.cycles.len();
            retrievals += usize::from(step.movement.subgoal_retrieval);
        }
        steps.push(step);
        let stop = match (decision, &moved) {
            (Decision::Complete, _) => Some(StopReason::Complete),
            (Decision::FrontierBelowThreshold, _) => Some(StopReason::FrontierBelowThreshold),
            (Decision::NoReachableFrontier, _) => Some(StopReason::NoReachableFrontier),
            (Decision::Target { .. }, _) if interrupted => Some(StopReason::Interrupted),
            (Decision::Target { .. }, _) if at_limit => Some(StopReason::ScanLimit),
            (Decision::Target { .. }, _) if diminishing => Some(StopReason::DiminishingReturns),
            (Decision::Target { index }, None) if is_fallback(&steps, index) => {
                Some(StopReason::NoReachableFrontier)
            }
            (Decision::Target { .. }, None) => Some(StopReason::NoCpsMove),
            (Decision::Target { .. }, Some(_)) => None,
        };
        let arrived = match (stop, moved) {
            (None, Some(planned)) => source.arrive(planned, &knowledge),
            // The plan stops, but a real team may have scanned again.
            (Some(_), _) => source.forced(here, &children, &knowledge),
            (None, None) => None,
        };
        let Some(moved) = arrived else {
            break stop;
        };
        // The planned move, unless the plan stopped and the team moved anyway.
        let last = steps.last().filter(|_| stop.is_none());
        expected = last
            .and_then(|s| s.movement.target.and_then(|t| s.plan.candidates.get(t)))
            .map(|c| (c.gain_m2, c.s_cells));
        let cycles = last.map_or(0, |s| s.movement.cycles.len());
        clock.moved(
            cycles,
            moved.parent_length + moved.child_lengths.iter().sum::<f64>(),
        );
        clock.measured(last.map_or(0, |s| {
            s.movement
                .cycles
                .iter()
                .map(|c| c.targets.len() + c.left_targets.len())
                .sum()
        }));
        here = moved.parent;
        travel += moved.parent_length;
        if !moved.children.is_empty() {
            children = moved.children;
        }
        for (t, l) in child_travel.iter_mut().zip(moved.child_lengths) {
            *t += l;
        }
    };
    let all_free = source.truth().map_or(0, |t| {
        t.cells().iter().filter(|&&c| c == CellState::Free).count()
    });
    let small_region = tracker.as_ref().is_some_and(|t| {
        let region = t.free_total() as f64;
        region < START_REGION_SHARE * t.connected_total() as f64
            || region < START_REGION_SHARE_OF_MAP * all_free as f64
    });
    let stop_reason = match stop_reason {
        Some(r) if small_region && r != StopReason::ScanLimit => {
            Some(StopReason::StartRegionTooSmall)
        }
        r => r,
    };
    let final_sigma = steps.last().and_then(|s| s.position_sigma_m);
    if let Some(smoothed) = chain.smooth() {
        let first = steps[0].position_sigma_m.map(|_| PoseAccuracy::exact());
        for (step, a) in steps.iter_mut().zip(first.into_iter().chain(smoothed)) {
            // Later measurements only add information: where the network finds
            // a σ above the chain's filtering one, the two differ by the chain's
            // rounding (docs/ACCURACY.md), and the filtering figures stand.
            let a = match step.accuracy() {
                Some(f) if a.position_sigma_m > f.position_sigma_m => f,
                _ => a,
            };
            step.smoothed_sigma_m = Some(a.position_sigma_m);
            step.smoothed_covariance_m2 = Some(a.covariance_m2);
            step.smoothed_heading_sigma_arcsec = Some(a.heading_sigma_arcsec);
        }
    }
    let runs = config.accuracy.monte_carlo_runs;
    let mc = chain.monte_carlo(runs, config.seed);
    if let Some((errors, smoothed)) = &mc {
        steps[0].monte_carlo_error_m = Some(0.0);
        for (step, &e) in steps[1..].iter_mut().zip(errors) {
            step.monte_carlo_error_m = Some(e);
        }
        if let Some(smoothed) = smoothed {
            steps[0].smoothed_monte_carlo_error_m = Some(0.0);
            for (step, &e) in steps[1..].iter_mut().zip(smoothed) {
                step.smoothed_monte_carlo_error_m = Some(e);
            }
        }
    }
    if let Some(checks) = chain.checks() {
        for (step, fit) in steps.iter_mut().zip(checks) {
            step.fit = fit;
        }
    }
    if let Some(r) = mc.as_ref().and_then(|_| chain.realisation(config.seed)) {
        steps[0].estimate = Some(PoseEstimate::new(steps[0].position, [0.0; 4]));
        for (step, e) in steps[1..].iter_mut().zip(r.filtering) {
            step.estimate = Some(PoseEstimate::new(step.position, e));
        }
        if let Some(smoothed) = r.smoothed {
            steps[0].smoothed_estimate = steps[0].estimate;
            for (step, e) in steps[1..].iter_mut().zip(smoothed) {
                step.smoothed_estimate = Some(PoseEstimate::new(step.position, e));
            }
        }
        for (step, worst) in steps.iter_mut().zip(r.worst) {
            if let (Some(fit), Some((v, name))) = (step.fit.as_mut(), worst) {
                fit.max_standardized_residual = Some(v);
                fit.worst_fitting = Some(name);
            }
        }
    }
    let worst = |f: fn(&Step) -> Option<f64>| {
        steps
            .iter()
            .filter_map(f)
            .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))
    };
    let sigma_violations: Vec<usize> = match config.mission.max_sigma_m {
        Some(max) => steps
            .iter()
            .filter(|s| s.position_sigma_m.is_some_and(|v| v > max))
            .map(|s| s.scan)
            .collect(),
        None => Vec::new(),
    };
    let targets = chain.targets().to_vec();
    let summary = Summary {
        scans: steps.len(),
        coverage: tracker.as_ref().map_or(0.0, CoverageTracker::coverage),
        wall_coverage: tracker.as_ref().map_or(0.0, CoverageTracker::wall_coverage),
        connected_coverage: tracker
            .as_ref()
            .map_or(0.0, CoverageTracker::connected_coverage),
        reachable_free_cells: tracker.as_ref().map_or(0, CoverageTracker::free_total),
        connected_free_cells: tracker.as_ref().map_or(0, CoverageTracker::connected_total),
        map_free_cells: all_free,
        parent_travel_m: travel,
        stop_reason: stop_reason.unwrap_or(StopReason::ScanLimit),
        seed: config.seed,
        cps_cycles: cycles,
        subgoal_retrievals: retrievals,
        child_travel_m: child_travel,
        instrument: config.instrument.model.name().to_string(),
        final_position_sigma_m: final_sigma,
        error_percent_of_travel: final_sigma
            .filter(|_| travel > 0.0)
            .map(|s| 100.0 * s / travel),
        monte_carlo_runs: if mc.is_some() { runs } else { 0 },
        monte_carlo_mean_error_m: mc.as_ref().and_then(|e| e.0.last().copied()),
        campaign_time_h: clock.time().total_h(),
        campaign_time: clock.time(),
        planner: config.parent.planner,
        worst_position_sigma_m: worst(|s| s.position_sigma_m),
        worst_smoothed_sigma_m: worst(|s| s.smoothed_sigma_m),
        final_smoothed_sigma_m: steps.last().and_then(|s| s.smoothed_sigma_m),
        monte_carlo_smoothed_mean_error_m: mc
            .as_ref()
            .and_then(|e| e.1.as_ref())
            .and_then(|e| e.last().copied()),
        targets_placed: targets
            .iter()
            .filter(|t| t.origin == TargetOrigin::Placed)
            .count(),
        closures: chain.closures(),
        closure_moves: steps
            .iter()
            .filter(|s| s.movement.closure.is_some())
            .count(),
        sigma_violations,
    };
    let episode = Episode {
        config: config.clone(),
        start: g.cell_center(cell),
        steps,
        summary,
        targets,
        knowledge: Some(knowledge),
    };
    (episode, stop_reason)
}
