//! The record of one finished episode of an experiment (`records/NNNNNN.json`):
//! what ran, its totals and its per-scan series, and the row it gives in
//! `episodes.csv`.

use cpsplan::bound::{BoundLevel, KnownMapBound};
use cpsplan::mission::{Episode, Summary};
use cpsplan::Point;
use serde::{Deserialize, Serialize};

use super::spec::EpisodeSpec;
use super::text::{csv_safe, csv_safe_option};

/// The format name of a record.
pub const RECORD_FORMAT: &str = "cpsplan-experiment-record/1";

/// One scan of an episode, as the experiment's plots need it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScanRecord {
    /// Scan number, from 1.
    pub scan: usize,
    /// Where the parent scanned, world frame.
    pub position: Point,
    /// Coverage of the reachable free space after the scan.
    pub coverage: f64,
    /// Coverage of the walls after the scan.
    pub wall_coverage: f64,
    /// Parent travel so far, metres.
    pub parent_travel_m: f64,
    /// The campaign clock when the scan ends, hours.
    pub clock_h: f64,
    /// Predicted radial 1σ of the scan position, metres (with two children or more).
    pub position_sigma_m: Option<f64>,
    /// The Monte Carlo mean radial error of the scan position, metres.
    pub monte_carlo_error_m: Option<f64>,
    /// CPS cycles of the move that followed the scan.
    pub cps_cycles: usize,
    /// Whether that move needed subgoals (section IV-C).
    pub subgoal_retrieval: bool,
}

/// How an episode ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Outcome {
    /// It ran to its stop rule.
    Finished {
        /// The start it used, world frame.
        start: Point,
        /// Its totals.
        summary: Box<Summary>,
        /// Every scan.
        scans: Vec<ScanRecord>,
    },
    /// It could not run (the message says why); running it again fails the same way.
    Failed {
        /// Why.
        error: String,
    },
}

/// The known-map bound of an episode's map and start (`cpsplan bound`), as the
/// report measures the planners against it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum BoundRecord {
    /// Computed.
    Computed {
        /// Targets: the reachable free cells on the target lattice.
        targets: usize,
        /// Targets some candidate station sees.
        coverable_targets: usize,
        /// Greedy stations and the LP lower bound for 90, 95, 99 and 100 % of
        /// the coverable targets.
        levels: Vec<BoundLevel>,
        /// The greedy cover's share of the coverable targets after each station.
        greedy_coverage: Vec<f64>,
    },
    /// It could not be computed (the message says why).
    Failed {
        /// Why.
        error: String,
    },
}

impl BoundRecord {
    /// The record of a computed bound.
    pub fn of(bound: &KnownMapBound) -> Self {
        BoundRecord::Computed {
            targets: bound.targets,
            coverable_targets: bound.coverable_targets,
            levels: bound.levels.clone(),
            greedy_coverage: bound.stations.iter().map(|s| s.coverage).collect(),
        }
    }

    /// The figures for `share` of the coverable targets, if computed.
    pub fn level(&self, share: f64) -> Option<&BoundLevel> {
        match self {
            BoundRecord::Computed { levels, .. } => {
                levels.iter().find(|l| (l.share - share).abs() < 1e-9)
            }
            BoundRecord::Failed { .. } => None,
        }
    }

    /// The greedy cover's coverage of the reachable free space (targets seen
    /// over all targets) after each station; empty if not computed.
    pub fn greedy_curve(&self) -> Vec<f64> {
        match self {
            BoundRecord::Computed {
                targets,
                coverable_targets,
                greedy_coverage,
                ..
            } if *targets > 0 => {
                let f = *coverable_targets as f64 / *targets as f64;
                greedy_coverage.iter().map(|c| c * f).collect()
            }
            _ => Vec::new(),
        }
    }
}

/// `records/NNNNNN.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeRecord {
    /// [`RECORD_FORMAT`].
    pub format: String,
    /// The experiment's name.
    pub experiment: String,
    /// The episode, as in `plan.json`.
    pub episode: EpisodeSpec,
    /// How it ended.
    pub outcome: Outcome,
    /// The known-map bound of its map and start, in experiments with
    /// `bound = true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bound: Option<BoundRecord>,
    /// Wall-clock time of the simulation, milliseconds (the only field that varies
    /// between identical runs).
    pub wall_ms: f64,
}

impl EpisodeRecord {
    /// Whether the record's figures are ones an episode of its spec can give:
    /// a forged or corrupted record (a coverage of 10³⁰⁸, more scans than the
    /// scan limit, a finished episode without scans) is named, not averaged.
    pub fn plausible(&self) -> Result<(), String> {
        let Outcome::Finished { summary, scans, .. } = &self.outcome else {
            return Ok(());
        };
        let share = |what: &str, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(format!("{what} {v} is not a share within 0–1"))
            }
        };
        let length = |what: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(format!("{what} {v} is not a finite length or time"))
            }
        };
        let optional = |what: &str, v: Option<f64>| v.map_or(Ok(()), |v| length(what, v));
        let limit = self.episode.config.mission.max_scans;
        if scans.is_empty() || scans.len() > limit || summary.scans != scans.len() {
            return Err(format!(
                "{} scans listed, {} counted (the limit is {limit})",
                scans.len(),
                summary.scans
            ));
        }
        share("coverage", summary.coverage)?;
        share("wall coverage", summary.wall_coverage)?;
        share("connected coverage", summary.connected_coverage)?;
        length("parent travel", summary.parent_travel_m)?;
        length("campaign time", summary.campaign_time_h)?;
        optional("final σ", summary.final_position_sigma_m)?;
        for t in &summary.child_travel_m {
            length("child travel", *t)?;
        }
        for (k, s) in scans.iter().enumerate() {
            if s.scan != k + 1 {
                return Err(format!("scan {} listed as number {}", k + 1, s.scan));
            }
            share("coverage", s.coverage)?;
            share("wall coverage", s.wall_coverage)?;
            length("parent travel", s.parent_travel_m)?;
            length("campaign clock", s.clock_h)?;
            optional("σ", s.position_sigma_m)?;
            optional("Monte Carlo error", s.monte_carlo_error_m)?;
        }
        Ok(())
    }

    /// The record of a finished episode.
    pub fn finished(
        experiment: &str,
        spec: &EpisodeSpec,
        start: Point,
        episode: &Episode,
        wall_ms: f64,
    ) -> Self {
        let scans = episode
            .steps
            .iter()
            .map(|s| ScanRecord {
                scan: s.scan,
                position: s.position,
                coverage: s.coverage,
                wall_coverage: s.wall_coverage,
                parent_travel_m: s.parent_travel_m,
                clock_h: s.clock_h,
                position_sigma_m: s.position_sigma_m,
                monte_carlo_error_m: s.monte_carlo_error_m,
                cps_cycles: s.movement.cycles.len(),
                subgoal_retrieval: s.movement.subgoal_retrieval,
            })
            .collect();
        Self {
            format: RECORD_FORMAT.into(),
            experiment: experiment.into(),
            episode: spec.clone(),
            outcome: Outcome::Finished {
                start,
                summary: Box::new(episode.summary.clone()),
                scans,
            },
            bound: None,
            wall_ms,
        }
    }

    /// The record of an episode that could not run.
    pub fn failed(experiment: &str, spec: &EpisodeSpec, error: String, wall_ms: f64) -> Self {
        Self {
            format: RECORD_FORMAT.into(),
            experiment: experiment.into(),
            episode: spec.clone(),
            outcome: Outcome::Failed { error },
            bound: None,
            wall_ms,
        }
    }

    /// The episode's row of `episodes.csv`.
    pub fn row(&self) -> CsvRow {
        let e = &self.episode;
        let mut row = CsvRow {
            index: e.index,
            label: e.label.clone(),
            map: e.map.clone(),
            parameters: e.parameters.clone(),
            planner: e.planner.name().into(),
            child_strategy: e.child_strategy.name().into(),
            instrument: e.instrument.name().into(),
            seed: e.seed,
            children: e.config.children.count,
            status: "finished".into(),
            ..CsvRow::default()
        };
        match &self.outcome {
            Outcome::Finished {
                start, summary: s, ..
            } => {
                row.start_x = Some(start.x);
                row.start_y = Some(start.y);
                row.scans = Some(s.scans);
                row.coverage = Some(s.coverage);
                row.wall_coverage = Some(s.wall_coverage);
                row.parent_travel_m = Some(s.parent_travel_m);
                row.child_travel_m = (!s.child_travel_m.is_empty())
                    .then(|| s.child_travel_m.iter().fold(0.0, |a, b| a + b));
                row.cps_cycles = Some(s.cps_cycles);
                row.subgoal_retrievals = Some(s.subgoal_retrievals);
                row.final_position_sigma_m = s.final_position_sigma_m;
                row.error_percent_of_travel = s.error_percent_of_travel;
                row.campaign_time_h = Some(s.campaign_time_h);
                row.stop_reason = Some(s.stop_reason.name().into());
            }
            Outcome::Failed { error } => {
                row.status = "failed".into();
                row.error = Some(error.clone());
            }
        }
        row.wall_ms = self.wall_ms;
        row
    }
}

/// One row of `episodes.csv`: an episode's axes and headline figures.
#[derive(Debug, Clone, Default, Serialize)]
pub struct CsvRow {
    index: usize,
    #[serde(serialize_with = "csv_safe")]
    label: String,
    #[serde(serialize_with = "csv_safe")]
    map: String,
    start_x: Option<f64>,
    start_y: Option<f64>,
    #[serde(serialize_with = "csv_safe")]
    parameters: String,
    planner: String,
    child_strategy: String,
    instrument: String,
    seed: u64,
    children: usize,
    status: String,
    scans: Option<usize>,
    coverage: Option<f64>,
    wall_coverage: Option<f64>,
    parent_travel_m: Option<f64>,
    /// The children's travel, summed.
    child_travel_m: Option<f64>,
    cps_cycles: Option<usize>,
    subgoal_retrievals: Option<usize>,
    final_position_sigma_m: Option<f64>,
    error_percent_of_travel: Option<f64>,
    campaign_time_h: Option<f64>,
    #[serde(serialize_with = "csv_safe_option")]
    stop_reason: Option<String>,
    wall_ms: f64,
    #[serde(serialize_with = "csv_safe_option")]
    error: Option<String>,
}

/// `episodes.csv` of `records`, in their order.
pub fn episodes_csv<'a>(
    records: impl IntoIterator<Item = &'a EpisodeRecord>,
) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in records {
        w.serialize(r.row())?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}
