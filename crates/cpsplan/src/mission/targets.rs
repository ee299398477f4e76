//! The targets of a mission (beyond the paper; docs/ACCURACY.md "Closed
//! networks"): their records, and where the team leaves targets of its own
//! (`targets.place = "auto"`).

use serde::{Deserialize, Serialize};

use super::record::{LeftTarget, MoveRecord};
use crate::accuracy::Chain;
use crate::geom::{Cell, Point};
use crate::grid::{CellState, OccupancyGrid};
use crate::parent::ParentPlan;
use crate::sensing::LinkRule;

/// Where a target came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TargetOrigin {
    /// A control point given with its coordinates.
    Control,
    /// A free target set up before the campaign.
    Free,
    /// A target a child left during the campaign.
    Placed,
}

/// One target or control point of an episode, as `episode.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetRecord {
    /// Its name (`T1`, … for given points without one; `P1`, … for placed ones).
    pub name: String,
    /// Where it came from.
    pub origin: TargetOrigin,
    /// Where it stands, world frame.
    pub position: Point,
    /// A control point's standard deviation of each coordinate, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_mm: Option<f64>,
    /// A placed target: the scan after which it was left.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placed_at_scan: Option<usize>,
    /// A placed target: the child that left it (from 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placed_by_child: Option<usize>,
    /// A placed target: why the planner left it there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The scan whose station (or whose move's stations) first measured it.
    pub first_measured_scan: Option<usize>,
    /// How many stations measured it.
    pub measurements: usize,
    /// Its smoothed radial 1σ at the end (every measurement at once), metres.
    pub smoothed_sigma_m: Option<f64>,
}

impl TargetRecord {
    /// The record of the `ordinal`-th target left by the team (from 1, named
    /// `P{ordinal}`), left during the move after scan `scan`.
    pub fn placed(left: &LeftTarget, ordinal: usize, scan: usize) -> Self {
        Self {
            name: format!("P{ordinal}"),
            origin: TargetOrigin::Placed,
            position: left.position,
            sigma_mm: None,
            placed_at_scan: Some(scan),
            placed_by_child: Some(left.child),
            reason: Some(left.reason.clone()),
            first_measured_scan: None,
            measurements: 0,
            smoothed_sigma_m: None,
        }
    }
}

/// What the placement policy looks at after a scan, before the move.
#[derive(Debug, Clone, Copy)]
pub struct PlacementView<'a> {
    /// The knowledge map the move was planned on.
    pub knowledge: &'a OccupancyGrid,
    /// The parent's station.
    pub here: Cell,
    /// The planning round after the scan.
    pub plan: &'a ParentPlan,
    /// The CPS chain at this station.
    pub chain: &'a Chain,
    /// How stations measure targets.
    pub rule: &'a LinkRule,
    /// The scanner's range, metres.
    pub scanner_range: f64,
    /// Targets the team still carries.
    pub carried: usize,
    /// Targets it carried at the start.
    pub budget: usize,
    /// The filtering σ of the last station that measured a target (0 at the
    /// start), metres.
    pub anchor_sigma: f64,
}

/// No target is left nearer than this share of the scanner's range to another
/// (measured on the built-in and shared maps: at the whole range the team left
/// a third of what it carried and the tunnel's worst smoothed σ was 99 mm; at
/// half, 31 mm, docs/ACCURACY.md).
pub const TARGET_SPACING: f64 = 0.5;

/// The σ a station may gain over the last station that measured a target
/// before the team leaves one (the drift rule), metres.
pub const DRIFT_STEP_M: f64 = 0.01;

/// Whether and where a child leaves a target as the team leaves this station
/// (`targets.place = "auto"`). A target is left, when no target in sight here is
/// known about as well as the station (within [`DRIFT_STEP_M`]) and none stands
/// within [`TARGET_SPACING`] of the scanner's range of the spot, in one of these
/// cases:
/// - *first*: no target has been measured yet;
/// - *branch*: the frontier lies in two directions at least 90° apart and more
///   than twice the scanner's range from each other, so the team will pass here
///   again and see it (the closure of the loop out and back);
/// - *drift*: the predicted σ has grown by [`DRIFT_STEP_M`] since the last
///   station that measured a target, so stations ahead can measure one left
///   here instead of leaning on the children alone.
///
/// It is left by the child that moves first whose spot sees farthest (the sum
/// over 64 rays of the known-free distance in line of sight), so that later
/// stations find it.
pub fn choose_target(view: &PlacementView, movement: &MoveRecord) -> Option<LeftTarget> {
    if view.carried == 0 {
        return None;
    }
    let cycle = movement.cycles.first()?;
    let g = view.knowledge.geometry();
    let chain = view.chain;
    let sigma = chain.pose().position_sigma();
    let anchored = chain
        .in_sight(view.knowledge, view.here, view.rule)
        .into_iter()
        .filter_map(|t| chain.target_covariance(t))
        .any(|c| (c[(0, 0)] + c[(1, 1)]).max(0.0).sqrt() <= sigma + DRIFT_STEP_M);
    if anchored {
        return None;
    }
    let existing: Vec<Point> = chain.targets().map(|t| t.position).collect();
    let spacing =
        TARGET_SPACING * view.scanner_range * (view.budget as f64 / view.carried as f64).sqrt();
    let spaced = |p: Point| existing.iter().all(|t| t.distance(p) >= spacing);
    let here = g.cell_center(view.here);
    let first = !(0..chain.target_count()).any(|t| chain.measured(t));
    let reason = if first {
        format!(
            "first: no target measured yet; the station's σ is {:.1} mm",
            sigma * 1e3
        )
    } else if let Some(why) = branch(view, here) {
        why
    } else if sigma >= view.anchor_sigma + DRIFT_STEP_M {
        format!(
            "drift: the predicted σ grew from {:.1} to {:.1} mm since the last station that measured a target",
            view.anchor_sigma * 1e3,
            sigma * 1e3
        )
    } else {
        return None;
    };
    let (child, position) = cycle
        .children
        .iter()
        .enumerate()
        .filter(|(_, c)| !c.stays && c.to.distance(here) >= view.rule.min && spaced(c.to))
        .map(|(i, c)| (i, c.to, sight_reach(view.knowledge, c.to, view.rule.max)))
        .max_by(|a, b| a.2.total_cmp(&b.2).then(b.0.cmp(&a.0)))
        .map(|(i, p, _)| (i, p))?;
    Some(LeftTarget {
        target: 0,
        child,
        position,
        reason,
    })
}

/// The branch rule of [`choose_target`]: a reason when the frontier lies in
/// two directions from `here`.
fn branch(view: &PlacementView, here: Point) -> Option<String> {
    let target = view.plan.target()?.position;
    let far = 2.0 * view.scanner_range;
    let dir = |p: Point| (p.y - here.y).atan2(p.x - here.x);
    let t = dir(target);
    let other = view.plan.candidates.iter().find(|c| {
        if !c.eligible || c.position.distance(target) <= far {
            return false;
        }
        let d = (dir(c.position) - t).rem_euclid(std::f64::consts::TAU);
        d.min(std::f64::consts::TAU - d) >= std::f64::consts::FRAC_PI_2
    })?;
    Some(format!(
        "branch: frontier ahead toward ({:.1}, {:.1}) and also toward ({:.1}, {:.1}); the team will pass here again",
        target.x, target.y, other.position.x, other.position.y
    ))
}

/// How far a target at `p` is seen: the known-free distance in line of sight
/// along 64 rays, each up to `max` metres, summed (metres).
pub fn sight_reach(knowledge: &OccupancyGrid, p: Point, max: f64) -> f64 {
    let g = knowledge.geometry();
    let res = g.resolution;
    let limit = max.min(g.width.max(g.height) as f64 * res);
    let mut total = 0.0;
    for k in 0..64 {
        let a = k as f64 * std::f64::consts::TAU / 64.0;
        let (s, c) = a.sin_cos();
        let mut d = 0.0;
        while d < limit {
            let q = Point::new(p.x + c * (d + res), p.y + s * (d + res));
            match g.world_to_cell(q) {
                Some(cell) if knowledge.get(cell) == CellState::Free => d += res,
                _ => break,
            }
        }
        total += d;
    }
    total
}
