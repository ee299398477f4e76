//! One planning step for a real team on a partial map ([`plan_step`], what
//! `cpsplan plan` prints).

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::accuracy::Tracker;
use super::record::MoveRecord;
use super::team;
use crate::config::{number, Config, ConfigError};
use crate::geom::{Cell, Point};
use crate::grid::GridGeometry;
use crate::grid::{CellState, OccupancyGrid};
use crate::parent::{Decision, ParentPlan};

/// One planning step for a real team (the library's entry point for field use):
/// the parent's next target on `knowledge` (a partial map: Unknown cells are
/// unknown), and, with children, the CPS cycles that take the team there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepPlan {
    /// The parent's planning round (candidates with their Eq. 1 terms, decision).
    pub plan: ParentPlan,
    /// The move: target reached, subgoal flag, CPS cycles with every robot's path
    /// and the predicted σ after each.
    #[serde(rename = "move")]
    pub movement: MoveRecord,
    /// The parent's next scan position, world metres: the candidate the move
    /// reaches (`move.target` numbers it among `plan.candidates`); `None` when
    /// the plan stops or no move reaches a candidate.
    pub target: Option<Point>,
    /// The predicted radial 1σ of the parent's position after the move, metres:
    /// the error this move adds to a parent pose known exactly where it stands
    /// (`None` without a move or without at least two children).
    pub predicted_position_sigma_m: Option<f64>,
}

/// Why a single step cannot be planned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlanError {
    /// A parameter is out of range.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A robot stands outside the map.
    #[error("{robot} at ({}, {}) is outside the map", number(*x), number(*y))]
    OutsideMap {
        /// Which robot ("parent", "child 1", ...).
        robot: String,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// A robot stands on a cell that is not known to be free.
    #[error("{robot} at ({}, {}) is not on known free space", number(*x), number(*y))]
    NotFree {
        /// Which robot.
        robot: String,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// Two robots stand on the same cell of the planning grid.
    #[error(
        "{robot} at ({}, {}) stands on the same cell as {other}",
        number(*x),
        number(*y)
    )]
    SameCell {
        /// The later robot.
        robot: String,
        /// The robot already on that cell.
        other: String,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// A child is nearer to or farther from the parent than the CPS link range
    /// allows (`children.min_range`, `children.max_range`, the instrument's
    /// limits): the parent could not measure it.
    #[error(
        "{robot} is {} m from the parent, outside the link range of {} to {} m \
         (children.min_range, children.max_range or the instrument's limits)",
        number(*distance),
        number(*min),
        number(*max)
    )]
    OutOfLinkRange {
        /// Which child.
        robot: String,
        /// Its distance from the parent, metres (cell centres).
        distance: f64,
        /// The shortest link, metres.
        min: f64,
        /// The longest link, metres.
        max: f64,
    },
}

/// Plans one step on a partial map: the same computation as the first step of
/// [`run_episode`](super::run_episode) at that state, with `config.seed` for the random choices
/// ([`plan_step_after`] with `scan` 1).
///
/// ```
/// use cpsplan::mission::plan_step;
/// use cpsplan::world::builtin::BuiltinMap;
/// use cpsplan::{run_episode, Config};
///
/// // A partial map: the site after one scan.
/// let mut config = Config::default();
/// config.mission.max_scans = 1;
/// let truth = BuiltinMap::Site.generate(0);
/// let episode = run_episode(&truth, BuiltinMap::Site.default_start(), &config, |_| {})?;
/// let known = episode.knowledge.unwrap();
/// let step = plan_step(&known, episode.start, &[], &config)?;
/// assert!(step.plan.target().is_some());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn plan_step(
    knowledge: &OccupancyGrid,
    parent: Point,
    children: &[Point],
    config: &Config,
) -> Result<StepPlan, PlanError> {
    plan_step_after(knowledge, parent, children, config, 1)
}

/// Plans the step after scan `scan` (counted from 1) on a partial map: the
/// round [`run_episode`](super::run_episode) plans after that scan, with the same
/// random stream ([`round_rng`](super::round_rng)). To repeat an episode's
/// choice, give its knowledge after that scan, its positions, and the gain
/// scale the round used (`parent.gain_scale` = the step record's `gain_scale`).
pub fn plan_step_after(
    knowledge: &OccupancyGrid,
    parent: Point,
    children: &[Point],
    config: &Config,
    scan: usize,
) -> Result<StepPlan, PlanError> {
    let mut config = config.clone();
    config.children.count = children.len();
    config.validate()?;
    let g = *knowledge.geometry();
    g.check_limits(&config)?;
    let locate = |robot: String, p: Point| -> Result<Cell, PlanError> {
        let cell = g.world_to_cell(p).ok_or(PlanError::OutsideMap {
            robot: robot.clone(),
            x: p.x,
            y: p.y,
        })?;
        if knowledge.get(cell) != CellState::Free {
            return Err(PlanError::NotFree {
                robot,
                x: p.x,
                y: p.y,
            });
        }
        Ok(cell)
    };
    let here = locate("parent".into(), parent)?;
    let kids: Vec<Cell> = children
        .iter()
        .enumerate()
        .map(|(i, &p)| locate(format!("child {}", i + 1), p))
        .collect::<Result<_, _>>()?;
    check_team(&g, here, &kids, children, &config)?;
    let mut rng = team::round_rng(config.seed, scan);
    let (mut plan, reach, groundwork) =
        team::plan_round(knowledge, here, &config, &mut rng, None, None);
    let mut tracker = Tracker::new(&config, g.cell_center(here));
    tracker.sight_start(knowledge, here);
    let mut movement = match plan.decision {
        Decision::Target { index } if kids.is_empty() => MoveRecord {
            target: Some(index),
            ..MoveRecord::default()
        },
        Decision::Target { .. } => {
            let team = team::Team {
                parent: here,
                children: &kids,
                chain: tracker.chain(),
                anchors: tracker.anchors(),
                carried: config.targets.team_targets(),
            };
            team::execute_move(knowledge, team, &mut plan, reach, groundwork, &config).0
        }
        _ => MoveRecord::default(),
    };
    tracker.follow(knowledge, &mut movement, true, 1);
    let predicted_position_sigma_m = movement.cycles.last().and_then(|c| c.position_sigma_m);
    let target = movement
        .target
        .and_then(|i| plan.candidates.get(i))
        .map(|c| c.position);
    Ok(StepPlan {
        plan,
        movement,
        target,
        predicted_position_sigma_m,
    })
}

/// Checks that no two robots share a cell and that every child is within the
/// link range of the parent (cell centres), so the parent can measure it.
fn check_team(
    g: &GridGeometry,
    parent: Cell,
    kids: &[Cell],
    positions: &[Point],
    config: &Config,
) -> Result<(), PlanError> {
    let (min, max) = config.link_range();
    let name = |i: usize| format!("child {}", i + 1);
    for (i, (&cell, &p)) in kids.iter().zip(positions).enumerate() {
        let same = |other: String| PlanError::SameCell {
            robot: name(i),
            other,
            x: p.x,
            y: p.y,
        };
        if cell == parent {
            return Err(same("the parent".into()));
        }
        if let Some(j) = kids[..i].iter().position(|&k| k == cell) {
            return Err(same(name(j)));
        }
        let distance = g.cell_center(cell).distance(g.cell_center(parent));
        // Cell centres in world metres carry rounding (13 cells of 0.1 m come
        // out as 1.2999999999999994 m): a team the planner itself placed at the
        // shortest link must pass.
        const TOLERANCE_M: f64 = 1e-9;
        if distance < min - TOLERANCE_M || distance > max + TOLERANCE_M {
            return Err(PlanError::OutOfLinkRange {
                robot: name(i),
                distance,
                min,
                max,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{CellState, GridGeometry};

    #[test]
    fn a_child_at_exactly_the_shortest_link_is_accepted() {
        // 13 cells of 0.1 m: 1.2999999999999994 m between the cell centres.
        let g = GridGeometry::new(100, 100, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Occupied);
        k.fill_rect(1, 1, 99, 99, CellState::Free);
        let c = |x: usize, y: usize| g.cell_center(crate::geom::Cell::new(x, y));
        // A column where the rounding falls short of 1.3 m.
        let x = (1..80)
            .find(|&x| c(x, 50).distance(c(x + 13, 50)) < 1.3)
            .expect("some pair of centres 13 cells apart rounds below 1.3 m");
        let (parent, kids) = (c(x, 50), [c(x + 13, 50), c(x, 70)]);
        let config = Config::default();
        assert!(
            !matches!(
                plan_step(&k, parent, &kids, &config),
                Err(PlanError::OutOfLinkRange { .. })
            ),
            "refused at the shortest link"
        );
        // One cell nearer is refused.
        let near = [c(x + 12, 50), c(x, 70)];
        assert!(matches!(
            plan_step(&k, parent, &near, &config),
            Err(PlanError::OutOfLinkRange { .. })
        ));
    }
}
