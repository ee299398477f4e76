//! The episode overlay: the parent's trajectory with direction arrows, the scan
//! markers and their numbers, placed so that they do not hide one another.

use cpsplan::{Episode, Point};
use tiny_skia::PathBuilder;

use super::canvas::{Canvas, Rgb};
use super::chrome::{draw_arrow_midway, draw_marker, draw_subgoal, Style};
use super::placer::{draw_label, label_size, Placer};
use super::{palette, MapLayout};

/// The driven legs in canvas pixels: all points, and where each leg starts.
struct Legs {
    points: Vec<(f32, f32)>,
    starts: Vec<usize>,
}

impl Legs {
    /// Leg `i`'s points.
    fn leg(&self, i: usize) -> &[(f32, f32)] {
        let end = self.starts.get(i + 1).copied().unwrap_or(self.points.len());
        &self.points[self.starts[i]..end]
    }

    fn len(&self) -> usize {
        self.starts.len()
    }
}

/// The children's driven paths, thin, one colour per child, under the parent's.
fn draw_children(canvas: &mut Canvas, layout: &MapLayout, episode: &Episode) {
    let colours = super::palette::CHILDREN;
    for (n, colour) in (0..episode.config.children.count).zip(colours.iter().cycle()) {
        let mut pb = PathBuilder::new();
        let mut any = false;
        for cycle in episode.steps.iter().flat_map(|s| &s.movement.cycles) {
            let Some(child) = cycle.children.get(n) else {
                continue;
            };
            let pts: Vec<(f32, f32)> = child
                .path
                .iter()
                .map(|&p| layout.world_to_px(p))
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            if let Some((first, rest)) = pts.split_first() {
                pb.move_to(first.0, first.1);
                for p in rest {
                    pb.line_to(p.0, p.1);
                }
                any |= !rest.is_empty();
            }
        }
        if let (true, Some(path)) = (any, pb.finish()) {
            canvas.stroke_path(&path, *colour, 220, 1.5);
        }
    }
}

/// The intermediate subgoals of every driven move that retrieved subgoals (section
/// IV-C): where each CPS cycle but the last left the parent. The last step's move
/// is only planned, not driven, and is left out like its path.
pub(crate) fn subgoals(episode: &Episode) -> Vec<Point> {
    let n = episode.steps.len().saturating_sub(1);
    episode.steps[..n]
        .iter()
        .filter(|s| s.movement.subgoal_retrieval)
        .flat_map(|s| {
            let cycles = &s.movement.cycles;
            cycles[..cycles.len().saturating_sub(1)]
                .iter()
                .map(|c| c.parent_to)
        })
        .collect()
}

/// Every step but the last moved the parent along its driven path to the next scan
/// position; a step without a usable path is drawn as a straight move.
fn legs(layout: &MapLayout, episode: &Episode) -> Legs {
    let steps = &episode.steps;
    let n_points: usize = steps.iter().map(|s| s.plan.path.len().max(2)).sum();
    let mut legs = Legs {
        points: Vec::with_capacity(n_points),
        starts: Vec::with_capacity(steps.len()),
    };
    let finite = |p: &(f32, f32)| p.0.is_finite() && p.1.is_finite();
    for pair in steps.windows(2) {
        let start = legs.points.len();
        legs.points.extend(
            pair[0]
                .driven_path()
                .iter()
                .map(|&p| layout.world_to_px(p))
                .filter(finite),
        );
        if legs.points.len() - start < 2 {
            legs.points.truncate(start);
            for p in [pair[0].position, pair[1].position] {
                legs.points.push(layout.world_to_px(p));
            }
            if !legs.points[start..].iter().all(finite) {
                legs.points.truncate(start);
                continue;
            }
        }
        legs.starts.push(start);
    }
    legs
}

/// Draws trajectory, markers and labels over the painted map.
pub(crate) fn draw_overlay(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
) {
    let legs = legs(layout, episode);
    draw_children(canvas, layout, episode);
    draw_trajectory(canvas, style, &legs);

    let positions: Vec<Point> = if episode.steps.is_empty() {
        vec![episode.start]
    } else {
        episode.steps.iter().map(|s| s.position).collect()
    };
    let mut dots: Vec<(f32, f32)> = positions.iter().map(|&p| layout.world_to_px(p)).collect();
    let last = dots.len() - 1;
    let r = style.marker_radius();
    let big = r + 1.5;
    let color_of = |i: usize| {
        if i == 0 {
            palette::START
        } else if i == last {
            palette::END
        } else {
            palette::SCAN
        }
    };
    let radius_of = |i: usize| if i == 0 || i == last { big } else { r };
    for (i, &(x, y)) in dots.iter().enumerate().skip(1) {
        if i != last {
            draw_marker(canvas, x, y, r, palette::SCAN);
        }
    }
    // Subgoals under the start and end markers, above the others; labels avoid
    // them too.
    for p in subgoals(episode) {
        let (x, y) = layout.world_to_px(p);
        if x.is_finite() && y.is_finite() {
            draw_subgoal(canvas, style, x, y);
            dots.push((x, y));
        }
    }
    if last > 0 {
        draw_marker(canvas, dots[last].0, dots[last].1, big, palette::END);
    }
    draw_marker(canvas, dots[0].0, dots[0].1, big, palette::START);

    // Numbers, placed one by one where they hide the least.
    let mut placer = Placer::new(
        canvas,
        layout,
        (0..legs.len()).map(|i| legs.leg(i)),
        &dots,
        big + 2.5,
    );
    for (i, &dot) in dots.iter().enumerate().take(last + 1) {
        if !(dot.0.is_finite() && dot.1.is_finite()) {
            continue;
        }
        let label = (i + 1).to_string();
        let (w, h) = label_size(&label, style);
        let required = i == 0 || i == last;
        let Some((rect, far)) = placer.place(
            i,
            dot,
            radius_of(i) + 2.5,
            w as f32,
            h as f32,
            style,
            required,
        ) else {
            continue; // no room: the marker stays, unlabelled
        };
        let edge = if i == 0 || i == last {
            color_of(i)
        } else {
            palette::SWATCH_EDGE
        };
        let leader = far.then_some((dot, radius_of(i) + 1.75));
        draw_label(canvas, style, &rect, &label, edge, leader);
    }
}

/// The trajectory: a white casing, the coloured line, and an arrowhead halfway
/// along every leg long enough to carry one.
fn draw_trajectory(canvas: &mut Canvas, style: Style, legs: &Legs) {
    let mut pb = PathBuilder::new();
    for i in 0..legs.len() {
        let leg = legs.leg(i);
        pb.move_to(leg[0].0, leg[0].1);
        for p in &leg[1..] {
            pb.line_to(p.0, p.1);
        }
    }
    let Some(path) = pb.finish() else {
        return;
    };
    let lw = style.line_width();
    canvas.stroke_path(&path, Rgb::hex(0xffffff), 215, lw + 3.5);
    canvas.stroke_path(&path, palette::TRAJECTORY, 255, lw);
    for i in 0..legs.len() {
        draw_arrow_midway(canvas, style, legs.leg(i), palette::TRAJECTORY);
    }
}
