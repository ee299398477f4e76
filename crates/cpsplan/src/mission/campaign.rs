//! A real team's campaign: its recorded scans replayed through the loop of
//! [`super::run_episode`], so that it plans exactly as a simulation would on
//! the same knowledge (docs/USER-GUIDE.md "Campaigns").
//!
//! In: what the team knew before its first scan (a prior map, or nothing),
//! every scan so far ([`FieldScan`]: where the station and the children
//! stood, as the network's adjustment places them, and the walls its points
//! lie on), the configuration. Out: the episode as the loop planned it, whose
//! last step holds the next plan ([`CampaignRun`]).
//!
//! A scan records in the knowledge map what the loop's own scanner would:
//! the sweep of [`crate::sensing::scan_by`] with the scan's walls and the walls
//! known before stopping the beams, up to the returns of its range image. The
//! team stands where the adjustment put it, wherever the plan sent it; when
//! the plan stops but the team scanned again, the campaign goes on from there.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::episode::{run_loop, Episode, MissionError, Step, StopReason};
use super::source::ScanSource;
use super::team::Moved;
use crate::config::{number, Config};
use crate::geom::{Cell, Point};
use crate::grid::{CellState, OccupancyGrid};
use crate::sensing::{scan_by, RangeImage, ScanOutcome};

/// One scan of a real team, as a campaign keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FieldScan {
    /// Where the scanner stood: its station's adjusted position, world frame.
    pub station: Point,
    /// Where each child stood during the scan, adjusted (empty before the
    /// children were first measured: the first scan).
    #[serde(default)]
    pub children: Vec<Point>,
    /// The wall cells its points lie on ([`crate::sensing::observed_walls`]),
    /// indices into the campaign's grid.
    pub walls: Vec<usize>,
    /// How far it saw in every direction (`None`: up to its walls and its
    /// range everywhere).
    #[serde(default)]
    pub ranges: Option<RangeImage>,
}

/// A campaign replayed.
#[derive(Debug, Clone)]
pub struct CampaignRun {
    /// The episode as the loop planned it: one step per scan used, the last
    /// one's plan and move the next step.
    pub episode: Episode,
    /// Why the campaign is over (`None`: the team goes on as the last step
    /// plans).
    pub stop: Option<StopReason>,
    /// Scans the loop used: fewer than given when it stopped before the last.
    pub scans_used: usize,
}

/// Why a campaign cannot be replayed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CampaignError {
    /// The configuration or the start is wrong.
    #[error(transparent)]
    Mission(#[from] MissionError),
    /// No scan yet.
    #[error("the campaign has no scan yet")]
    NoScan,
    /// A station lies outside the campaign's grid.
    #[error("scan {scan}'s station ({}, {}) is outside the campaign's area", number(at.x), number(at.y))]
    OutsideArea {
        /// The scan, from 1.
        scan: usize,
        /// Its station.
        at: Point,
    },
    /// A scan's wall cell lies outside the grid.
    #[error("scan {scan} names wall cell {cell}, outside the campaign's grid")]
    BadWall {
        /// The scan, from 1.
        scan: usize,
        /// The cell index.
        cell: usize,
    },
}

/// Replays `scans` on `prior` (the campaign's grid; Unknown where nothing
/// was known) with `config`; `on_step` sees every step and the knowledge map
/// it was planned on.
pub fn run_campaign(
    prior: OccupancyGrid,
    scans: &[FieldScan],
    config: &Config,
    on_step: impl FnMut(&Step, &OccupancyGrid),
) -> Result<CampaignRun, CampaignError> {
    config.validate().map_err(MissionError::from)?;
    let g = *prior.geometry();
    g.check_limits(config).map_err(MissionError::from)?;
    let first = scans.first().ok_or(CampaignError::NoScan)?;
    let cells = prior.cells().len();
    for (k, s) in scans.iter().enumerate() {
        if g.world_to_cell(s.station).is_none() {
            return Err(CampaignError::OutsideArea {
                scan: k + 1,
                at: s.station,
            });
        }
        if let Some(&cell) = s.walls.iter().find(|&&w| w >= cells) {
            return Err(CampaignError::BadWall { scan: k + 1, cell });
        }
    }
    let start = g
        .world_to_cell(first.station)
        .ok_or(CampaignError::OutsideArea {
            scan: 1,
            at: first.station,
        })?;
    let mut source = Recorded {
        scans,
        next: 0,
        solid: Vec::new(),
    };
    let never = std::sync::atomic::AtomicBool::new(false);
    let (episode, stop) = run_loop(&mut source, prior, start, config, &never, on_step);
    Ok(CampaignRun {
        episode,
        stop,
        scans_used: source.next,
    })
}

/// The recorded scans as the loop's source.
struct Recorded<'a> {
    scans: &'a [FieldScan],
    /// The next scan to give.
    next: usize,
    /// Per cell: whether it stops the beams of the scan being recorded.
    solid: Vec<bool>,
}

impl ScanSource for Recorded<'_> {
    fn truth(&self) -> Option<&OccupancyGrid> {
        None
    }

    fn scan(
        &mut self,
        knowledge: &mut OccupancyGrid,
        at: Cell,
        range_cells: f64,
        on_new: &mut dyn FnMut(usize),
    ) -> ScanOutcome {
        let Some(s) = self.scans.get(self.next) else {
            return ScanOutcome::default();
        };
        self.next += 1;
        self.solid.clear();
        self.solid
            .extend(knowledge.cells().iter().map(|&c| c == CellState::Occupied));
        for &w in &s.walls {
            if let Some(c) = self.solid.get_mut(w) {
                *c = true;
            }
        }
        let solid = std::mem::take(&mut self.solid);
        let g = *knowledge.geometry();
        let image = s.ranges.as_ref().map(|r| (r, r.neighbours()));
        let origin = s.station;
        // A free cell is kept up to a cell beyond the returns around its
        // direction.
        let keep = |i: usize| {
            let Some((ranges, near)) = &image else {
                return true;
            };
            let c = g.cell_center(g.cell(i));
            let (dx, dy) = (c.x - origin.x, c.y - origin.y);
            ranges
                .depth(near, dy.atan2(dx), g.resolution)
                .is_none_or(|d| dx.hypot(dy) <= d + g.resolution)
        };
        let out = scan_by(|i| solid[i], keep, knowledge, at, range_cells, on_new);
        self.solid = solid;
        out
    }

    fn arrive(&mut self, planned: Moved, knowledge: &OccupancyGrid) -> Option<Moved> {
        let s = self.scans.get(self.next)?;
        let g = knowledge.geometry();
        // The team scanned where it stood, whatever the map knew there.
        let parent = g.world_to_cell(s.station).unwrap_or(planned.parent);
        let mut children: Vec<Cell> = Vec::with_capacity(planned.children.len());
        for (i, &plan) in planned.children.iter().enumerate() {
            let at = s
                .children
                .get(i)
                .and_then(|&p| g.world_to_cell(p))
                .filter(|c| *c != parent && !children.contains(c));
            children.push(at.unwrap_or(plan));
        }
        Some(Moved {
            parent,
            children,
            ..planned
        })
    }

    fn forced(
        &mut self,
        parent: Cell,
        children: &[Cell],
        knowledge: &OccupancyGrid,
    ) -> Option<Moved> {
        let s = self.scans.get(self.next)?;
        let g = knowledge.geometry();
        let to = g.world_to_cell(s.station)?;
        let cells: Vec<Cell> = if s.children.len() == children.len() {
            s.children
                .iter()
                .zip(children)
                .map(|(&p, &c)| g.world_to_cell(p).unwrap_or(c))
                .collect()
        } else {
            children.to_vec()
        };
        // Not planned: the straight lines stand for the paths driven.
        let length = |a: Cell, b: Cell| g.cell_center(a).distance(g.cell_center(b));
        Some(Moved {
            parent: to,
            child_lengths: children
                .iter()
                .zip(&cells)
                .map(|(&a, &b)| length(a, b))
                .collect(),
            children: cells,
            parent_length: length(parent, to),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sensing::seen_walls;
    use crate::world::builtin::BuiltinMap;
    use crate::{run_episode, Config};

    /// The scans of `steps` as the simulation's scanner saw them: its walls,
    /// the team where the simulation put it, no range image.
    fn simulated_scans(truth: &OccupancyGrid, steps: &[Step], config: &Config) -> Vec<FieldScan> {
        let solid = truth.solidified();
        steps
            .iter()
            .map(|s| FieldScan {
                station: s.position,
                children: s.children.clone(),
                walls: seen_walls(&solid, s.cell, config.range_cells()),
                ranges: None,
            })
            .collect()
    }

    /// Scans that record the walls the simulation's scanner saw, with the
    /// team where the simulation put it, give the simulation's decisions:
    /// the campaign plans through the same loop.
    #[test]
    fn a_campaign_of_the_simulations_scans_makes_its_decisions() {
        for map in [BuiltinMap::Site, BuiltinMap::Tunnel] {
            let config = Config::default();
            let truth = map.generate(0);
            let episode = run_episode(&truth, map.default_start(), &config, |_| {}).unwrap();
            let scans = simulated_scans(&truth, &episode.steps, &config);
            let prior = OccupancyGrid::filled(*truth.geometry(), CellState::Unknown);
            let run = run_campaign(prior, &scans, &config, |_, _| {}).unwrap();
            assert_eq!(run.scans_used, scans.len());
            assert_eq!(run.stop, Some(episode.summary.stop_reason), "{map:?}");
            assert_eq!(run.episode.steps.len(), episode.steps.len());
            for (a, b) in episode.steps.iter().zip(&run.episode.steps) {
                assert_eq!(a.cell, b.cell, "{map:?} scan {}", a.scan);
                assert_eq!(a.children, b.children, "{map:?} scan {}", a.scan);
                assert_eq!(a.plan, b.plan, "{map:?} scan {}", a.scan);
                assert_eq!(a.movement, b.movement, "{map:?} scan {}", a.scan);
                assert_eq!(a.outcome, b.outcome, "{map:?} scan {}", a.scan);
            }
            assert_eq!(run.episode.knowledge, episode.knowledge);
        }
    }

    /// A campaign whose last scan the plan goes on from: no stop, and the
    /// last step holds the next move.
    #[test]
    fn a_campaign_waits_for_its_next_scan() {
        let map = BuiltinMap::Site;
        let config = Config::default();
        let truth = map.generate(0);
        let episode = run_episode(&truth, map.default_start(), &config, |_| {}).unwrap();
        let scans = simulated_scans(&truth, &episode.steps[..3], &config);
        let prior = OccupancyGrid::filled(*truth.geometry(), CellState::Unknown);
        let run = run_campaign(prior, &scans, &config, |_, _| {}).unwrap();
        assert_eq!(run.stop, None);
        assert_eq!(run.episode.steps.len(), 3);
        let last = &run.episode.steps[2];
        assert_eq!(last.movement, episode.steps[2].movement);
        assert!(!last.movement.cycles.is_empty());
    }
}
