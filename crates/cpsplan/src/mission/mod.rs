//! The mission (pipeline stage 8, the loop of paper Fig. 3): scan, plan the
//! parent's next position, move the team there, scan again, until no reachable
//! frontier remains or the scan limit is reached. Every step is recorded.
//!
//! In: the ground truth (simulation) or a partial map (field use), the start or
//! the robots' positions, the configuration. Out: an [`Episode`] with every
//! [`Step`] and the [`Summary`] ([`run_episode`]), or one [`StepPlan`]
//! ([`plan_step`]).
//!
//! With children (the default: two) every move runs as CPS cycles (paper Fig. 1):
//! the children into the AND region ([`crate::children`]), then the parent, with
//! subgoals when one cycle cannot make the move ([`crate::subgoals`]), every robot
//! along the Voronoi edges ([`crate::motion`]); without children the parent drives
//! its shortest drivable path alone.
//!
//! An episode keeps what a scan changes only locally up to date scan by scan
//! instead of computing it again over the whole map each round (the gain
//! estimate's field, the border and band, the parent's drivable cells:
//! [`crate::parent::Kept`]; with children the GVD's obstacle side:
//! [`crate::motion::VoronoiField`]); [`plan_step`] computes them afresh.
//!
//! - `episode`: [`run_episode`] and its records.
//! - `step`: [`plan_step`].
//! - `team`: the CPS part of a step ([`Groundwork`], [`execute_move`]).
//! - `record`: [`MoveRecord`] and the cycle records.
//! - `calibration`: the gain estimate's online calibration ([`GainCalibration`]).
//! - `clock`: the campaign's time ([`Clock`], [`CampaignTime`]).
//! - `memory`: the memory an episode needs, estimated before it runs
//!   ([`MemoryEstimate`]).
//! - `field`: the readings a real instrument would have recorded
//!   ([`field_readings`]).
//! - `campaign`: a real team's recorded scans replayed through the loop
//!   ([`run_campaign`]).
//! - `source`: where the loop's scans and arrivals come from.

mod accuracy;
mod calibration;
mod campaign;
mod clock;
mod episode;
mod field;
mod memory;
mod record;
mod source;
mod step;
mod stop;
mod targets;
mod team;
mod tolerance;

pub use accuracy::{FitRecord, PoseAccuracy, PoseEstimate, ScanRealisation, Tracker};
pub use calibration::{GainCalibration, CALIBRATION_MAX, CALIBRATION_MIN_SCANS};
pub use campaign::{run_campaign, CampaignError, CampaignRun, FieldScan};
pub use clock::{CampaignTime, Clock};
pub use episode::{
    parent_path, run_episode, run_episode_until, run_episode_with, start_cell, Episode,
    MissionError, Step, StopReason, Summary, START_REGION_SHARE, START_REGION_SHARE_OF_MAP,
};
pub use field::{field_readings, network_of};
pub use memory::MemoryEstimate;
pub use record::{
    cycle_and_regions, move_and_regions, ChildMove, Closure, CycleRecord, LeftTarget, MoveRecord,
    RejectedTarget,
};
pub use step::{plan_step, plan_step_after, PlanError, StepPlan};
pub use targets::{TargetOrigin, TargetRecord, DRIFT_STEP_M, TARGET_SPACING};
pub use team::{execute_move, initial_children, plan_round, round_rng, Groundwork, Moved, Team};
pub use tolerance::{Anchor, CLOSURE_ANCHORS};
