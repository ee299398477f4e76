//! What a step figure draws over the tinted map: the CPS lines of sight, the
//! Visibility Graph path, every robot's path, the candidates, the children, the
//! subgoals and the parent, and their labels.

use cpsplan::parent::CandidateOrigin;
use cpsplan::Point;
use tiny_skia::PathBuilder;

use super::super::canvas::{Canvas, Rgb};
use super::super::chrome::Style;
use super::super::layout::MapLayout;
use super::super::marks::{
    draw_arrow_midway, draw_cross, draw_marker, draw_ring, draw_square, draw_subgoal,
    subgoal_radius,
};
use super::super::palette;
use super::super::placer::{draw_label, label_size, Placer};
use super::scores::{format_score, ScoreRange};
use super::StepView;

/// Canvas pixels of world points, non-finite ones dropped.
fn to_px(layout: &MapLayout, points: &[Point]) -> Vec<(f32, f32)> {
    points
        .iter()
        .map(|&p| layout.world_to_px(p))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect()
}

fn polyline(points: &[(f32, f32)]) -> Option<tiny_skia::Path> {
    let (first, rest) = points.split_first()?;
    if rest.is_empty() {
        return None;
    }
    let mut pb = PathBuilder::new();
    pb.move_to(first.0, first.1);
    for p in rest {
        pb.line_to(p.0, p.1);
    }
    pb.finish()
}

/// A hollow marker: a white disc ringed in `c` (where a child started).
fn draw_hollow(canvas: &mut Canvas, cx: f32, cy: f32, r: f32, c: Rgb) {
    canvas.fill_circle(cx, cy, r + 2.5, palette::OCCUPIED, 110);
    canvas.fill_circle(cx, cy, r + 1.75, c, 255);
    canvas.fill_circle(cx, cy, r - 0.5, Rgb::hex(0xffffff), 255);
}

/// Paths, lines of sight, markers and labels over the tinted map.
pub(super) fn draw_overlay(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    step: &StepView<'_>,
    scores: &ScoreRange,
) {
    let cycles = &step.movement.cycles;
    let lw = style.line_width();
    let r = style.marker_radius();
    let big = r + 1.5;
    let child_colour = |j: usize| palette::CHILDREN[j % palette::CHILDREN.len()];
    let px = |p: Point| layout.world_to_px(p);
    let finite = |p: (f32, f32)| p.0.is_finite() && p.1.is_finite();

    // Lines of sight of the CPS links, thin and dashed, under everything else.
    for cycle in cycles {
        for (j, child) in cycle.children.iter().enumerate() {
            for parent in [cycle.parent_from, cycle.parent_to] {
                if let Some(path) = polyline(&to_px(layout, &[child.to, parent])) {
                    canvas.stroke_dashed(&path, child_colour(j), 230, 1.5, 4.0 * style.g as f32);
                }
            }
        }
    }

    // The Visibility Graph path the subgoals were taken from (or, in records
    // without it, the path through the subgoals).
    let subgoals = step.subgoals();
    let mut paths: Vec<Vec<(f32, f32)>> = Vec::new();
    if step.movement.subgoal_retrieval {
        let mut vg: Vec<Point> = step.movement.graph_path.clone();
        if vg.is_empty() {
            vg.extend(cycles.first().map(|c| c.parent_from));
            vg.extend(cycles.iter().map(|c| c.parent_to));
        }
        let vg = to_px(layout, &vg);
        if let Some(path) = polyline(&vg) {
            canvas.stroke_dashed(
                &path,
                Rgb::hex(0xffffff),
                200,
                lw + 2.5,
                7.0 * style.g as f32,
            );
            canvas.stroke_dashed(&path, palette::SUBGOAL, 255, lw * 0.8, 7.0 * style.g as f32);
        }
        paths.push(vg);
    }

    // The children's paths, cycle by cycle, with an arrow on every long leg.
    for cycle in cycles {
        for (j, child) in cycle.children.iter().enumerate() {
            let pts = to_px(layout, &child.path);
            if let Some(path) = polyline(&pts) {
                canvas.stroke_path(&path, Rgb::hex(0xffffff), 200, lw + 2.0);
                canvas.stroke_path(&path, child_colour(j), 255, lw * 0.75);
                draw_arrow_midway(canvas, style, &pts, child_colour(j));
            }
            paths.push(pts);
        }
    }

    // The parent's path: casing, line, an arrow per cycle.
    let parent_legs: Vec<Vec<(f32, f32)>> = if cycles.is_empty() {
        vec![to_px(layout, &step.parent_path())]
    } else {
        cycles
            .iter()
            .map(|c| to_px(layout, &c.parent_path))
            .collect()
    };
    let all: Vec<(f32, f32)> = parent_legs.iter().flatten().copied().collect();
    if let Some(path) = polyline(&all) {
        canvas.stroke_path(&path, Rgb::hex(0xffffff), 215, lw + 3.5);
        canvas.stroke_path(&path, palette::TRAJECTORY, 255, lw);
        for leg in &parent_legs {
            draw_arrow_midway(canvas, style, leg, palette::TRAJECTORY);
        }
    }
    paths.extend(parent_legs);

    // Candidates: eligible ones coloured by G, the others small and grey; the best
    // drawn last, on top.
    let candidates = &step.plan.candidates;
    let target = step.target();
    let mut order: Vec<usize> = (0..candidates.len()).collect();
    order.sort_by(|&a, &b| {
        let key = |i: usize| {
            let c = &candidates[i];
            (c.eligible, if c.g.is_finite() { c.g } else { f64::MIN })
        };
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let mut dots: Vec<(f32, f32)> = candidates.iter().map(|c| px(c.position)).collect();
    for &i in &order {
        let c = &candidates[i];
        let (x, y) = dots[i];
        if !finite((x, y)) {
            continue;
        }
        if c.eligible && c.origin == CandidateOrigin::Viewpoint {
            draw_square(canvas, x, y, r * 0.85, scores.colour(c.g));
        } else if c.eligible {
            draw_marker(canvas, x, y, r, scores.colour(c.g));
        } else {
            draw_marker(canvas, x, y, r * 0.6, palette::INELIGIBLE);
        }
    }
    for rejected in &step.movement.rejected {
        if let Some(&(x, y)) = dots.get(rejected.candidate).filter(|&&d| finite(d)) {
            draw_cross(canvas, style, x, y, r);
        }
    }
    if let Some(&(x, y)) = target.and_then(|t| dots.get(t)).filter(|&&d| finite(d)) {
        draw_ring(canvas, style, x, y, r);
    }

    // The children: where they started (hollow) and where each cycle put them.
    let starts: Vec<Point> = match cycles.first() {
        Some(c) => c.children.iter().map(|k| k.from).collect(),
        None => step.children.to_vec(),
    };
    for (j, &p) in starts.iter().enumerate() {
        let (x, y) = px(p);
        if finite((x, y)) {
            draw_hollow(canvas, x, y, r * 0.8, child_colour(j));
            dots.push((x, y));
        }
    }
    for cycle in cycles {
        for (j, child) in cycle.children.iter().enumerate() {
            let (x, y) = px(child.to);
            if finite((x, y)) {
                draw_marker(canvas, x, y, r * 0.8, child_colour(j));
                dots.push((x, y));
            }
        }
    }

    // Subgoals, then the parent on top.
    let first_subgoal = dots.len();
    for &p in &subgoals {
        let (x, y) = px(p);
        draw_subgoal(canvas, style, x, y);
        dots.push((x, y));
    }
    let parent_dot = px(step.position);
    if finite(parent_dot) {
        draw_marker(canvas, parent_dot.0, parent_dot.1, big, palette::TRAJECTORY);
    }
    let parent_index = dots.len();
    dots.push(parent_dot);

    // Labels: the parent, the subgoals' numbers, the target's and first choice's
    // scores, then the others' from the best down where there is room.
    let mut placer = Placer::new(
        canvas,
        layout,
        paths.iter().map(Vec::as_slice),
        &dots,
        big + 2.5,
    );
    let label = |placer: &mut Placer,
                 canvas: &mut Canvas,
                 index: usize,
                 radius: f32,
                 text: &str,
                 edge: Rgb,
                 required: bool| {
        let dot = dots[index];
        if !finite(dot) {
            return;
        }
        let (w, h) = label_size(text, style);
        if let Some((rect, far)) =
            placer.place(index, dot, radius, w as f32, h as f32, style, required)
        {
            draw_label(
                canvas,
                style,
                &rect,
                text,
                edge,
                far.then_some((dot, radius)),
            );
        }
    };
    let parent_text = match step.scan {
        Some(n) => format!("scan {n}"),
        None => "parent".to_owned(),
    };
    label(
        &mut placer,
        canvas,
        parent_index,
        big + 2.5,
        &parent_text,
        palette::TRAJECTORY,
        true,
    );
    for k in 0..subgoals.len() {
        label(
            &mut placer,
            canvas,
            first_subgoal + k,
            subgoal_radius(style) + 3.0,
            &(k + 1).to_string(),
            palette::SUBGOAL,
            true,
        );
    }
    let first_choice = step.first_choice();
    let mut labelled: Vec<usize> = target.into_iter().collect();
    labelled.extend(first_choice.filter(|&f| Some(f) != target));
    let required = labelled.len();
    labelled.extend(
        order
            .iter()
            .rev()
            .copied()
            .filter(|&i| candidates[i].eligible && Some(i) != target && Some(i) != first_choice),
    );
    for (n, i) in labelled.into_iter().enumerate() {
        let Some(c) = candidates.get(i) else {
            continue;
        };
        let ringed = Some(i) == target;
        let edge = if ringed {
            palette::TEXT
        } else {
            palette::SWATCH_EDGE
        };
        let radius = if ringed { r + 3.0 + 2.0 * lw } else { r + 2.5 };
        label(
            &mut placer,
            canvas,
            i,
            radius,
            &format_score(c.g),
            edge,
            n < required,
        );
    }
}
