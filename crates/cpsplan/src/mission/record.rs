//! The records of a mission's moves: every CPS cycle with the parent's two
//! positions, the children's places with their Eq. (2) terms and every robot's
//! driven path, in world metres (what `episode.json` holds).

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::children::{and_region, AndRegion, ChildReach, CycleParams};
use crate::config::Config;
use crate::geom::Point;
use crate::grid::{OccupancyGrid, Terrain};
use crate::sensing::mutual_view;

/// One child during one CPS cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChildMove {
    /// Where it stood before the cycle, world frame.
    pub from: Point,
    /// Where it stands while the parent moves.
    pub to: Point,
    /// It was already in its AND region and stayed.
    pub stays: bool,
    /// Its driven path, world frame.
    pub path: Vec<Point>,
    /// Size of its AND region, cells.
    pub and_region_cells: usize,
    /// Eq. (2): clearance `1/P` of its spot, metres (when it moved).
    pub clearance_m: Option<f64>,
    /// Eq. (2): distance `D` to the parent's target, metres (when it moved).
    pub distance_m: Option<f64>,
    /// Eq. (2): angle `θ` to its partner seen from the target, degrees.
    pub theta_deg: Option<f64>,
}

/// One CPS cycle as executed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleRecord {
    /// The parent's position while the children move, world frame.
    pub parent_from: Point,
    /// The parent's position after its move, world frame.
    pub parent_to: Point,
    /// The parent's driven path, world frame.
    pub parent_path: Vec<Point>,
    /// Every child, in order.
    pub children: Vec<ChildMove>,
    /// Predicted radial 1σ of the parent's position after the cycle, metres (the
    /// CPS chain, first order; `None` without at least two children).
    #[serde(default)]
    pub position_sigma_m: Option<f64>,
    /// Strategy `min-error`: the share of the cycle's predicted error its search
    /// left unproven (0: within 2 % of the optimum over the AND regions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub search_gap: Option<f64>,
    /// Targets and control points the parent measured from `parent_to`
    /// (indices into the episode's `targets`), besides the children.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub targets: Vec<usize>,
    /// Targets the children left where they stood before this cycle, measured
    /// from `parent_from`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_targets: Vec<LeftTarget>,
}

/// A target a child left where it stood.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LeftTarget {
    /// Its index in the episode's `targets`.
    pub target: usize,
    /// The child that left it.
    pub child: usize,
    /// Where, world frame.
    pub position: Point,
    /// Why the planner left it there.
    pub reason: String,
}

impl CycleRecord {
    /// Every point the cycle holds, world frame: the parent's two positions and
    /// driven path, then each child's two places and driven path.
    pub fn points(&self) -> impl Iterator<Item = Point> + '_ {
        [self.parent_from, self.parent_to]
            .into_iter()
            .chain(self.parent_path.iter().copied())
            .chain(
                self.children
                    .iter()
                    .flat_map(|k| [k.from, k.to].into_iter().chain(k.path.iter().copied())),
            )
    }
}

/// A target the parent could not reach by CPS cycles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RejectedTarget {
    /// Index into the step's candidates.
    pub candidate: usize,
    /// Why.
    pub reason: String,
}

/// The executed move of one step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct MoveRecord {
    /// The candidate actually reached.
    pub target: Option<usize>,
    /// Whether subgoals were retrieved.
    pub subgoal_retrieval: bool,
    /// With subgoals: the Visibility Graph's shortest path they were taken from
    /// (its corners, world frame, the parent's position first).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub graph_path: Vec<Point>,
    /// The cycles in order.
    pub cycles: Vec<CycleRecord>,
    /// Candidates tried first and given up.
    pub rejected: Vec<RejectedTarget>,
    /// With a tolerance (`mission.max_sigma_m`): the closure the move made
    /// first to keep the next station within it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closure: Option<Closure>,
}

/// A closure of the network made on the way to the next scan station, to keep
/// its predicted σ within the tolerance (`mission.max_sigma_m`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Closure {
    /// The station the parent visited first to measure targets there (`None`:
    /// the move was direct, with a target left behind).
    pub via: Option<Point>,
    /// The targets measured there.
    pub targets: Vec<usize>,
    /// The predicted σ of the next scan station without the closure, metres.
    pub sigma_without_m: f64,
    /// With it, metres.
    pub sigma_m: f64,
    /// The extra campaign time it cost, hours.
    pub extra_h: f64,
    /// What was done and why, in words.
    pub reason: String,
}

/// The AND region of every child of a recorded cycle, recomputed on the knowledge
/// map the cycle was planned on: per child, a mask over the grid's cells (row-major)
/// of where that child could have stood (section IV-B). The children drive on
/// their terrain without anyone's escape region, as the planner takes it (a child
/// off it on a terrain of its own). For pictures and checks.
pub fn cycle_and_regions(
    knowledge: &OccupancyGrid,
    cycle: &CycleRecord,
    config: &Config,
) -> Vec<Vec<bool>> {
    let len = knowledge.geometry().len();
    move_and_regions(knowledge, std::slice::from_ref(cycle), config)
        .into_iter()
        .flatten()
        .map(|r| r.to_mask(len))
        .collect()
}

/// The AND regions of [`cycle_and_regions`] of every cycle of one move, all
/// planned on `knowledge`, as cell lists: per cycle, per child. The children's
/// terrain is built once for them all.
pub fn move_and_regions(
    knowledge: &OccupancyGrid,
    cycles: &[CycleRecord],
    config: &Config,
) -> Vec<Vec<AndRegion>> {
    let params = CycleParams::from_config(config);
    let mut terrain = None;
    cycles
        .iter()
        .map(|cycle| {
            let terrain = terrain.get_or_insert_with(|| {
                Arc::new(Terrain::without_escape(knowledge, params.child_radius))
            });
            regions_on(knowledge, terrain, cycle, &params)
        })
        .collect()
}

/// The AND regions of `cycle`'s children on `terrain` (of `knowledge`).
fn regions_on(
    knowledge: &OccupancyGrid,
    terrain: &Arc<Terrain>,
    cycle: &CycleRecord,
    params: &CycleParams,
) -> Vec<AndRegion> {
    let g = knowledge.geometry();
    let empty = || AndRegion { cells: Vec::new() };
    let (Some(from), Some(to)) = (
        g.world_to_cell(cycle.parent_from),
        g.world_to_cell(cycle.parent_to),
    ) else {
        return vec![empty(); cycle.children.len()];
    };
    let drivable = &terrain.trav.traversable;
    let mutual = mutual_view(knowledge, from, to, params.link, |i| drivable[i]);
    cycle
        .children
        .iter()
        .map(|c| match g.world_to_cell(c.from) {
            Some(cell) => {
                let reach = ChildReach::on(terrain, g, cell)
                    .unwrap_or_else(|| ChildReach::new(knowledge, cell, params.child_radius));
                and_region(&mutual, &reach)
            }
            None => empty(),
        })
        .collect()
}
