//! Planning to a tolerance (beyond the paper; docs/ACCURACY.md "Planning to a
//! tolerance"): with `mission.max_sigma_m`, no station may scan with a predicted
//! filtering σ above it. When the move to the next scan station would break it,
//! the planner closes the network first, by whichever of these keeps the
//! tolerance in the least campaign time:
//!
//! - the same move with the children placed for accuracy (strategy `min-error`
//!   on this move only), when the configured strategy is another;
//! - a target left behind: a child sets one down at its spot of the move's
//!   first cycle, measured from the station the move starts at, which the
//!   move's later stations measure again (while the team carries targets);
//! - a detour through an earlier station whose targets it measures again (a
//!   re-sight: the parent goes there by CPS cycles, measures the targets, and
//!   continues to the scan station), with either placement.
//!
//! When no option keeps the tolerance, the one with the least σ is taken and the
//! scan is reported as a violation (`Summary::sigma_violations`).

use super::record::{Closure, LeftTarget};
use crate::accuracy::{Chain, TargetPoint};
use crate::config::{ChildStrategy, TimeConfig};
use crate::geom::{Cell, Point};
use crate::grid::OccupancyGrid;
use crate::sensing::LinkRule;
use crate::subgoals::{MoveError, MovePlan};

/// An earlier station where the parent measured targets: a place a closure can
/// return to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// Where it stood, world frame.
    pub position: Point,
    /// Its filtering σ then, metres.
    pub sigma_m: f64,
    /// The targets and control points it measured.
    pub targets: usize,
}

/// How many earlier stations a closure search tries, nearest first.
pub const CLOSURE_ANCHORS: usize = 3;

/// What the tolerance needs to know of the step.
pub(super) struct Tolerance<'a> {
    /// The tolerance, metres.
    pub max: f64,
    /// Earlier stations to return to.
    pub anchors: &'a [Anchor],
    /// The campaign's time model.
    pub time: TimeConfig,
    /// How stations measure targets.
    pub rule: LinkRule,
    /// The configured child strategy.
    pub strategy: ChildStrategy,
    /// Targets the team still carries.
    pub carried: usize,
}

/// The predicted filtering σ at the end of move `m` from `chain`, with the
/// targets each station measures on `knowledge`; `None` when the chain cannot
/// follow it.
pub(super) fn predict(
    knowledge: &OccupancyGrid,
    rule: &LinkRule,
    chain: &Chain,
    m: &MovePlan,
) -> Option<(f64, Chain)> {
    let g = knowledge.geometry();
    let mut c = chain.clone();
    for cycle in &m.cycles {
        let kids: Vec<Point> = cycle.children.iter().map(|k| g.cell_center(k.to)).collect();
        let moved: Vec<bool> = cycle.children.iter().map(|k| !k.stays).collect();
        c.cycle_on(knowledge, rule, cycle.parent_to, &kids, &moved)
            .ok()?;
    }
    Some((c.pose().position_sigma(), c))
}

/// The time move `m` takes, hours: every robot's driving (straight legs for the
/// parent, the planned paths for the children) and the CPS measurements.
fn move_time(knowledge: &OccupancyGrid, m: &MovePlan, time: &TimeConfig) -> f64 {
    let g = knowledge.geometry();
    let res = g.resolution;
    let cell_dist =
        |a: Cell, b: Cell| (a.x as f64 - b.x as f64).hypot(a.y as f64 - b.y as f64) * res;
    let mut metres = 0.0;
    let mut measurements = 0usize;
    for c in &m.cycles {
        metres += cell_dist(c.parent_from, c.parent_to);
        for k in &c.children {
            metres += k
                .path
                .windows(2)
                .map(|w| cell_dist(w[0], w[1]))
                .sum::<f64>();
        }
        measurements += 2 * c.children.len();
    }
    (metres / time.speed_m_s + measurements as f64 * time.measure_s) / 3600.0
}

/// Plans a move on the step's maps: `(from, to, children, chain, strategy)`.
pub(super) type PlanMove<'p> =
    dyn Fn(Cell, Cell, &[Cell], &Chain, ChildStrategy) -> Result<MovePlan, MoveError> + 'p;

/// One way to reach the scan station.
struct Option_ {
    plan: MovePlan,
    sigma: f64,
    hours: f64,
    via: Option<(Point, Vec<usize>)>,
    accuracy_placement: bool,
    left: Option<LeftTarget>,
}

/// A move that keeps the tolerance, or comes nearest to it.
pub(super) struct Held {
    /// The move to take.
    pub plan: MovePlan,
    /// The closure made, when the move differs from the one asked.
    pub closure: Option<Closure>,
    /// A target to leave at the start of the move.
    pub left: Option<LeftTarget>,
}

/// Keeps the tolerance on the move `m` from `here` to `target` (module doc):
/// `plan(from, to, children, chain, strategy)` plans a move on the step's maps.
/// Returns the move to take and, when it differs from `m`, the closure made.
#[allow(clippy::too_many_arguments)]
pub(super) fn hold(
    knowledge: &OccupancyGrid,
    tol: &Tolerance,
    chain: &Chain,
    here: Cell,
    target: Cell,
    children: &[Cell],
    m: MovePlan,
    plan: &PlanMove,
) -> Held {
    let g = knowledge.geometry();
    let unchanged = |m: MovePlan| Held {
        plan: m,
        closure: None,
        left: None,
    };
    let Some((sigma0, _)) = predict(knowledge, &tol.rule, chain, &m) else {
        return unchanged(m);
    };
    if sigma0 <= tol.max {
        return unchanged(m);
    }
    let hours0 = move_time(knowledge, &m, &tol.time);
    let mut options: Vec<Option_> = Vec::new();
    let strategies: Vec<ChildStrategy> = if tol.strategy == ChildStrategy::MinError {
        vec![ChildStrategy::MinError]
    } else {
        vec![tol.strategy, ChildStrategy::MinError]
    };
    let option = |p: MovePlan, via: Option<(Point, Vec<usize>)>, accurate: bool| {
        let (sigma, _) = predict(knowledge, &tol.rule, chain, &p)?;
        let hours = move_time(knowledge, &p, &tol.time);
        Some(Option_ {
            plan: p,
            sigma,
            hours,
            via,
            accuracy_placement: accurate,
            left: None,
        })
    };
    // A target left at a moving child's spot of the first cycle.
    if tol.carried > 0 {
        let hp = g.cell_center(here);
        let best = m
            .cycles
            .first()
            .into_iter()
            .flat_map(|c| c.children.iter().enumerate())
            .filter(|(_, k)| !k.stays && g.cell_center(k.to).distance(hp) >= tol.rule.min)
            .filter_map(|(i, k)| {
                let spot = g.cell_center(k.to);
                let mut c = chain.clone();
                let t = c.add_target(TargetPoint::free(spot));
                c.sight_here(&[t]).ok()?;
                let (sigma, _) = predict(knowledge, &tol.rule, &c, &m)?;
                Some((i, spot, sigma))
            })
            .min_by(|a, b| a.2.total_cmp(&b.2));
        if let Some((child, position, sigma)) = best {
            options.push(Option_ {
                plan: m.clone(),
                sigma,
                hours: hours0 + tol.time.measure_s / 3600.0,
                via: None,
                accuracy_placement: false,
                left: Some(LeftTarget {
                    target: 0,
                    child,
                    position,
                    reason: format!(
                        "tolerance: the next scan station's predicted σ is {:.1} mm, {:.1} mm with a target left here",
                        sigma0 * 1e3,
                        sigma * 1e3
                    ),
                }),
            });
        }
    }
    if tol.strategy != ChildStrategy::MinError {
        if let Ok(p) = plan(here, target, children, chain, ChildStrategy::MinError) {
            options.extend(option(p, None, true));
        }
    }
    // Re-sights: earlier stations that measured targets, nearest (by the
    // straight detour) first.
    let (hp, tp) = (g.cell_center(here), g.cell_center(target));
    let mut anchors: Vec<&Anchor> = tol
        .anchors
        .iter()
        .filter(|a| a.sigma_m < tol.max && a.position.distance(hp) > 1.0)
        .collect();
    let detour = |a: &Anchor| a.position.distance(hp) + a.position.distance(tp);
    anchors.sort_by(|a, b| detour(a).total_cmp(&detour(b)));
    for a in anchors.into_iter().take(CLOSURE_ANCHORS) {
        let Some(via) = g.world_to_cell(a.position) else {
            continue;
        };
        for &s in &strategies {
            let Ok(leg1) = plan(here, via, children, chain, s) else {
                continue;
            };
            let Some((_, at_via)) = predict(knowledge, &tol.rule, chain, &leg1) else {
                continue;
            };
            let kids: Vec<Cell> = leg1
                .cycles
                .last()
                .map(|c| c.children.iter().map(|k| k.to).collect())
                .unwrap_or_else(|| children.to_vec());
            let Ok(leg2) = plan(via, target, &kids, &at_via, s) else {
                continue;
            };
            let seen = at_via.in_sight(knowledge, via, &tol.rule);
            let mut both = leg1;
            both.retrieved |= leg2.retrieved;
            both.graph_path.extend(leg2.graph_path);
            both.cycles.extend(leg2.cycles);
            options.extend(option(
                both,
                Some((a.position, seen)),
                s == ChildStrategy::MinError && tol.strategy != ChildStrategy::MinError,
            ));
        }
    }
    let within = options
        .iter()
        .enumerate()
        .filter(|(_, o)| o.sigma <= tol.max)
        .min_by(|a, b| a.1.hours.total_cmp(&b.1.hours))
        .map(|(i, _)| i);
    let best = within.or_else(|| {
        options
            .iter()
            .enumerate()
            .filter(|(_, o)| o.sigma < sigma0)
            .min_by(|a, b| a.1.sigma.total_cmp(&b.1.sigma))
            .map(|(i, _)| i)
    });
    let Some(best) = best else {
        return unchanged(m);
    };
    let o = options.swap_remove(best);
    let mut reason = match &o.via {
        _ if o.left.is_some() => String::from("a target left behind for the move's stations"),
        Some((p, seen)) => format!(
            "re-sight: the parent returns to the station at ({:.1}, {:.1}) to measure {} target{} again",
            p.x,
            p.y,
            seen.len(),
            if seen.len() == 1 { "" } else { "s" }
        ),
        None => String::from("the children placed for accuracy (min-error) on this move"),
    };
    if o.via.is_some() && o.accuracy_placement {
        reason.push_str(", the children placed for accuracy (min-error)");
    }
    if o.sigma > tol.max {
        reason.push_str(&format!(
            "; the tolerance of {:.1} mm cannot be held (no closure within reach)",
            tol.max * 1e3
        ));
    }
    let closure = Closure {
        via: o.via.as_ref().map(|v| v.0),
        targets: o.via.as_ref().map(|v| v.1.clone()).unwrap_or_default(),
        sigma_without_m: sigma0,
        sigma_m: o.sigma,
        extra_h: (o.hours - hours0).max(0.0),
        reason,
    };
    Held {
        plan: o.plan,
        closure: Some(closure),
        left: o.left,
    }
}
