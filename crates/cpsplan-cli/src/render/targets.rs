//! Targets and control points on the pictures: the fixed points of a closed CPS
//! network (docs/ACCURACY.md "Closed networks"), and the lines along which
//! stations measured them.
//!
//! A control point is drawn as the surveyor's triangle, a target as a circled
//! cross (a placed target filled, a given free target hollow); each measurement
//! from a station to a target as a thin line, so that the network's closures show
//! as lines converging on targets from stations far apart.

use cpsplan::mission::TargetOrigin;
use cpsplan::{Episode, Point};
use tiny_skia::PathBuilder;

use super::canvas::{Canvas, Rgb};
use super::chrome::Style;
use super::layout::MapLayout;
use super::palette;

/// Every measurement to a target: (station, target position).
pub(crate) fn sight_lines(episode: &Episode) -> Vec<(Point, Point)> {
    let at = |t: usize| episode.targets.get(t).map(|r| r.position);
    let mut out = Vec::new();
    if let Some(first) = episode.steps.first() {
        out.extend(
            first
                .targets
                .iter()
                .filter_map(|&t| Some((first.position, at(t)?))),
        );
    }
    for step in &episode.steps {
        for c in &step.movement.cycles {
            out.extend(c.left_targets.iter().map(|l| (c.parent_from, l.position)));
            out.extend(
                c.targets
                    .iter()
                    .filter_map(|&t| Some((c.parent_to, at(t)?))),
            );
        }
    }
    out
}

/// Draws every measurement to a target as a thin translucent line.
pub(crate) fn draw_sight_lines(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
) {
    let lines = sight_lines(episode);
    if lines.is_empty() {
        return;
    }
    let mut pb = PathBuilder::new();
    for (a, b) in lines {
        let (ax, ay) = layout.world_to_px(a);
        let (bx, by) = layout.world_to_px(b);
        pb.move_to(ax, ay);
        pb.line_to(bx, by);
    }
    if let Some(path) = pb.finish() {
        canvas.stroke_path(&path, palette::SIGHT, 110, 0.5 * style.line_width());
    }
}

/// Draws every target and control point; returns their pixel positions (for
/// the labels to avoid).
pub(crate) fn draw_targets(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
) -> Vec<(f32, f32)> {
    let r = style.marker_radius();
    episode
        .targets
        .iter()
        .map(|t| {
            let (x, y) = layout.world_to_px(t.position);
            match t.origin {
                TargetOrigin::Control => draw_control(canvas, style, x, y, r),
                TargetOrigin::Placed => draw_target(canvas, style, x, y, r, true),
                TargetOrigin::Free => draw_target(canvas, style, x, y, r, false),
            }
            (x, y)
        })
        .collect()
}

/// A control point: a triangle with a dot, white-rimmed.
pub(crate) fn draw_control(canvas: &mut Canvas, style: Style, cx: f32, cy: f32, r: f32) {
    let r = r * 1.35;
    let mut pb = PathBuilder::new();
    pb.move_to(cx, cy - r);
    pb.line_to(cx + 0.87 * r, cy + 0.5 * r);
    pb.line_to(cx - 0.87 * r, cy + 0.5 * r);
    pb.close();
    if let Some(path) = pb.finish() {
        canvas.stroke_path(&path, Rgb::hex(0xffffff), 255, style.line_width() + 2.0);
        canvas.fill_path(&path, palette::CONTROL, 255);
    }
    canvas.fill_circle(cx, cy, 0.25 * r, Rgb::hex(0xffffff), 255);
}

/// A target: a circled cross, filled when the team placed it.
pub(crate) fn draw_target(
    canvas: &mut Canvas,
    style: Style,
    cx: f32,
    cy: f32,
    r: f32,
    filled: bool,
) {
    let w = style.line_width();
    canvas.fill_circle(cx, cy, r + 1.5, Rgb::hex(0xffffff), 255);
    if filled {
        canvas.fill_circle(cx, cy, r, palette::TARGET, 255);
    }
    let Some(ring) = PathBuilder::from_circle(cx, cy, r) else {
        return;
    };
    canvas.stroke_path(&ring, palette::TARGET, 255, w);
    let mut pb = PathBuilder::new();
    pb.move_to(cx - r, cy);
    pb.line_to(cx + r, cy);
    pb.move_to(cx, cy - r);
    pb.line_to(cx, cy + r);
    if let Some(cross) = pb.finish() {
        let c = if filled {
            Rgb::hex(0xffffff)
        } else {
            palette::TARGET
        };
        canvas.stroke_path(&cross, c, 255, 0.7 * w);
    }
}
