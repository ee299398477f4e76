//! The text lines of a step figure's header: the scan, what the planner found and
//! chose, the move's cycles with their Eq. (2) terms, rejected targets; and the
//! footer's note on the window shown.

use cpsplan::parent::Decision;
use cpsplan::{CellState, GridGeometry, OccupancyGrid, Point};

use super::super::canvas::{fit_text, text_width};
use super::super::chrome::Style;
use super::super::layout::{percent, trim_number};
use super::scores::format_score;
use super::window::Window;
use super::StepView;

/// "x, y" of a point, one decimal.
fn xy(p: Point) -> String {
    format!("({:.1}, {:.1})", p.x, p.y)
}

/// The header's text lines: segments joined by " · " and wrapped to `room` pixels.
pub(super) fn caption(
    step: &StepView<'_>,
    knowledge: &OccupancyGrid,
    room: i64,
    style: Style,
) -> Vec<String> {
    let plan = step.plan;
    let candidates = &plan.candidates;
    let mut first = Vec::new();
    match (step.scan, step.coverage) {
        (Some(n), Some(c)) => {
            first.push(format!("scan {n}"));
            first.push(format!("coverage {} %", crate::render::share_percent(c)));
        }
        (scan, _) => {
            if let Some(n) = scan {
                first.push(format!("scan {n}"));
            }
            let n = knowledge.cells().len();
            first.push(format!(
                "known free {:.1} % \u{b7} unknown {:.1} %",
                percent(knowledge.count(CellState::Free), n),
                percent(knowledge.count(CellState::Unknown), n)
            ));
        }
    }
    let eligible = candidates.iter().filter(|c| c.eligible).count();
    first.push(format!(
        "{} candidate{} ({} eligible)",
        candidates.len(),
        if candidates.len() == 1 { "" } else { "s" },
        eligible
    ));
    let cycles = step.movement.cycles.len();
    match (plan.decision, step.target().and_then(|t| candidates.get(t))) {
        (Decision::Complete, _) => first.push("nothing left to scan".into()),
        (Decision::FrontierBelowThreshold, _) => {
            first.push("only border fragments below the threshold left".into())
        }
        (Decision::NoReachableFrontier, _) => first.push("no reachable frontier".into()),
        (Decision::Target { .. }, Some(t)) => {
            first.push(format!(
                "target G {} at {} m",
                format_score(t.g),
                xy(t.position)
            ));
            let travel: f64 = if cycles > 0 {
                step.movement
                    .cycles
                    .iter()
                    .map(|c| cpsplan::geom::polyline_length(&c.parent_path))
                    .sum()
            } else {
                plan.path_length_m
            };
            first.push(format!("parent path {travel:.1} m"));
        }
        (Decision::Target { .. }, None) => {
            first.push("no candidate reachable by CPS cycles".into());
        }
    }
    if cycles > 0 {
        first.push(format!(
            "{cycles} CPS cycle{}",
            if cycles == 1 { "" } else { "s" }
        ));
    } else if step.children.is_empty() && step.target().is_some() {
        first.push("no children: the parent moves alone".into());
    }
    if step.movement.subgoal_retrieval {
        let n = cycles.saturating_sub(1);
        first.push(format!(
            "subgoal retrieval: {n} subgoal{}",
            if n == 1 { "" } else { "s" }
        ));
    }
    let mut lines = wrap(&first, room, style);
    for r in &step.movement.rejected {
        let what = match candidates.get(r.candidate) {
            Some(c) => format!("rejected G {} at {}", format_score(c.g), xy(c.position)),
            None => format!("rejected candidate {}", r.candidate),
        };
        lines.extend(wrap(&[format!("{what}: {}", r.reason)], room, style));
    }
    for (k, cycle) in step.movement.cycles.iter().enumerate() {
        let to = if !step.movement.subgoal_retrieval {
            String::new()
        } else if k + 1 < cycles {
            format!(" to subgoal {}", k + 1)
        } else {
            " to target".to_owned()
        };
        let mut segments = vec![];
        for (j, child) in cycle.children.iter().enumerate() {
            let name = format!("child {}", j + 1);
            let mut terms = Vec::new();
            if !child.stays {
                if let Some(t) = child.theta_deg {
                    terms.push(format!("\u{3b8} {t:.0}\u{b0}"));
                }
                if let Some(d) = child.distance_m {
                    terms.push(format!("D {d:.1} m"));
                }
                if let Some(c) = child.clearance_m {
                    terms.push(format!("1/P {c:.1} m"));
                }
            }
            segments.push(if child.stays {
                format!("{name} stays")
            } else if terms.is_empty() {
                format!("{name} moves")
            } else {
                format!("{name}: {}", terms.join(", "))
            });
        }
        if let Some(s) = segments.first_mut() {
            *s = format!("cycle {}{to}: {s}", k + 1);
        }
        if let Some(sigma) = cycle.position_sigma_m {
            segments.push(format!("parent \u{3c3} after {:.1} mm", sigma * 1e3));
        }
        lines.extend(wrap(&segments, room, style));
    }
    lines
}

/// Joins `segments` with " · " into lines at most `room` pixels wide (a segment
/// too long on its own is shortened).
fn wrap(segments: &[String], room: i64, style: Style) -> Vec<String> {
    const SEP: &str = " \u{b7} ";
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for s in segments {
        if line.is_empty() {
            line = fit_text(s, style.g, room);
        } else if text_width(&line, style.g) + text_width(SEP, style.g) + text_width(s, style.g)
            <= room
        {
            line.push_str(SEP);
            line.push_str(s);
        } else {
            lines.push(std::mem::take(&mut line));
            line = fit_text(s, style.g, room);
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// "window 40 × 32 m of 80 × 60 m · 0.1 m cells", or the grid's size when whole.
pub(in crate::render) fn window_info(g: &GridGeometry, w: &Window) -> String {
    let (ex, ey) = g.extent();
    let res = g.resolution;
    if *w == Window::whole_of(g) {
        format!(
            "{} \u{d7} {} m \u{b7} {} m cells",
            trim_number(ex, 1),
            trim_number(ey, 1),
            trim_number(res, 3)
        )
    } else {
        format!(
            "window {} \u{d7} {} m of {} \u{d7} {} m \u{b7} {} m cells",
            trim_number(w.width() as f64 * res, 1),
            trim_number(w.height() as f64 * res, 1),
            trim_number(ex, 1),
            trim_number(ey, 1),
            trim_number(res, 3)
        )
    }
}
