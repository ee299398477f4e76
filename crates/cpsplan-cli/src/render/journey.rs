//! What the robots did, drawn over the episode's map: the parent's driven legs with
//! direction arrows, each child's paths in its own colour and dash pattern and its
//! standing places at every scan, the error ellipses, the subgoals and the scan
//! markers (start green, last red).

use cpsplan::{Episode, Point};
use tiny_skia::PathBuilder;

use super::canvas::{Canvas, Rgb};
use super::chrome::Style;
use super::layout::MapLayout;
use super::marks::{draw_arrow_midway, draw_ellipse, draw_marker, draw_subgoal};
use super::palette;
use super::team::{child_look, ChildLook};

/// The driven legs in canvas pixels: all points, and where each leg starts.
pub(crate) struct Legs {
    points: Vec<(f32, f32)>,
    starts: Vec<usize>,
}

impl Legs {
    /// Leg `i`'s points.
    pub fn leg(&self, i: usize) -> &[(f32, f32)] {
        let end = self.starts.get(i + 1).copied().unwrap_or(self.points.len());
        &self.points[self.starts[i]..end]
    }

    /// Number of legs.
    pub fn len(&self) -> usize {
        self.starts.len()
    }
}

fn finite(p: &(f32, f32)) -> bool {
    p.0.is_finite() && p.1.is_finite()
}

/// Every step but the last moved the parent along its driven path to the next scan
/// position; a step without a usable path is drawn as a straight move.
pub(crate) fn legs(layout: &MapLayout, episode: &Episode) -> Legs {
    let steps = &episode.steps;
    let mut legs = Legs {
        points: Vec::new(),
        starts: Vec::with_capacity(steps.len()),
    };
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

/// Child `n`'s driven paths, world frame, one per cycle it moved in.
fn child_paths(episode: &Episode, n: usize) -> impl Iterator<Item = &[Point]> {
    episode
        .steps
        .iter()
        .flat_map(|s| &s.movement.cycles)
        .filter_map(move |c| c.children.get(n))
        .map(|c| c.path.as_slice())
        .filter(|p| p.len() >= 2)
}

/// Where child `n` stood at each scan, world frame, each place once.
pub(crate) fn child_stands(episode: &Episode, n: usize) -> Vec<Point> {
    let mut places: Vec<Point> = Vec::new();
    for p in episode.steps.iter().filter_map(|s| s.children.get(n)) {
        if places.last() != Some(p) && !places.contains(p) {
            places.push(*p);
        }
    }
    places
}

/// The children that left a trace to draw (a path or a standing place), from 0.
pub(crate) fn drawn_children(episode: &Episode) -> Vec<usize> {
    let most = episode
        .steps
        .iter()
        .map(|s| s.children.len())
        .chain(
            episode
                .steps
                .iter()
                .flat_map(|s| &s.movement.cycles)
                .map(|c| c.children.len()),
        )
        .max()
        .unwrap_or(0);
    (0..most)
        .filter(|&n| {
            child_paths(episode, n).next().is_some() || !child_stands(episode, n).is_empty()
        })
        .collect()
}

/// The children's paths, each in its colour and dash pattern, under the parent's.
pub(crate) fn draw_children_paths(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
) {
    for n in drawn_children(episode) {
        let mut pb = PathBuilder::new();
        for path in child_paths(episode, n) {
            let pts: Vec<(f32, f32)> = path
                .iter()
                .map(|&p| layout.world_to_px(p))
                .filter(finite)
                .collect();
            if let Some((first, rest)) = pts.split_first() {
                pb.move_to(first.0, first.1);
                for p in rest {
                    pb.line_to(p.0, p.1);
                }
            }
        }
        if let Some(path) = pb.finish() {
            child_look(n).stroke(canvas, style, &path);
        }
    }
}

/// Every child's standing places as its marks; returns their canvas positions.
pub(crate) fn draw_children_stands(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
) -> Vec<(f32, f32)> {
    let mut marks = Vec::new();
    for n in drawn_children(episode) {
        let look: ChildLook = child_look(n);
        for p in child_stands(episode, n) {
            let (x, y) = layout.world_to_px(p);
            if finite(&(x, y)) {
                look.draw_mark(canvas, style, x, y);
                marks.push((x, y));
            }
        }
    }
    marks
}

/// The parent's trajectory: a white casing, the coloured line, and an arrowhead
/// halfway along every leg long enough to carry one.
pub(crate) fn draw_trajectory(canvas: &mut Canvas, style: Style, legs: &Legs) {
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

/// The scan positions in scan order (the start alone without steps).
pub(crate) fn scan_positions(episode: &Episode) -> Vec<Point> {
    if episode.steps.is_empty() {
        vec![episode.start]
    } else {
        episode.steps.iter().map(|s| s.position).collect()
    }
}

/// The subgoals and over them the scan markers (intermediate ones first, then the
/// last red, the start green on top); returns the subgoals' canvas positions.
pub(crate) fn draw_scans_and_subgoals(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
    dots: &[(f32, f32)],
) -> Vec<(f32, f32)> {
    let Some(last) = dots.len().checked_sub(1) else {
        return Vec::new();
    };
    let r = style.marker_radius();
    let big = end_radius(style);
    // Subgoals under the scan markers: every scan's place stays visible.
    let mut diamonds = Vec::new();
    for p in subgoals(episode) {
        let (x, y) = layout.world_to_px(p);
        if finite(&(x, y)) {
            draw_subgoal(canvas, style, x, y);
            diamonds.push((x, y));
        }
    }
    for &(x, y) in dots.iter().take(last).skip(1).filter(|d| finite(d)) {
        draw_marker(canvas, x, y, r, palette::SCAN);
    }
    if last > 0 && finite(&dots[last]) {
        draw_marker(canvas, dots[last].0, dots[last].1, big, palette::END);
    }
    if finite(&dots[0]) {
        draw_marker(canvas, dots[0].0, dots[0].1, big, palette::START);
    }
    diamonds
}

/// Radius of the start's and the last scan's markers.
pub(crate) fn end_radius(style: Style) -> f32 {
    style.marker_radius() + 1.5
}

/// How much the scan positions' error ellipses are magnified: the largest major
/// semi-axis drawn about 3 % of the shown map's longer side (`extent_m`), rounded
/// down to 1, 2 or 5 times a power of ten; `None` without predicted errors.
pub(crate) fn ellipse_magnification(episode: &Episode, extent_m: f64) -> Option<f64> {
    let biggest = episode
        .steps
        .iter()
        .filter_map(|s| s.covariance_m2)
        .map(|c| ellipse_of(&c).0)
        .fold(0.0f64, f64::max);
    if biggest.is_nan() || biggest <= 0.0 {
        return None;
    }
    let want = 0.03 * extent_m / biggest;
    let mag = 10f64.powf(want.log10().floor());
    let m = [5.0, 2.0, 1.0]
        .iter()
        .map(|k| k * mag)
        .find(|&m| m <= want)
        .unwrap_or(mag);
    m.is_finite().then_some(m)
}

/// The semi-axes (1σ, metres) and the major axis's angle of a 2×2 covariance.
fn ellipse_of(c: &[[f64; 2]; 2]) -> (f64, f64, f64) {
    let (xx, xy, yy) = (c[0][0], c[0][1], c[1][1]);
    let tr = xx + yy;
    let disc = ((xx - yy).powi(2) / 4.0 + xy * xy).max(0.0).sqrt();
    let (l1, l2) = (tr / 2.0 + disc, (tr / 2.0 - disc).max(0.0));
    (
        l1.max(0.0).sqrt(),
        l2.sqrt(),
        0.5 * (2.0 * xy).atan2(xx - yy),
    )
}

/// Every scan position's 1σ error ellipse, magnified `m` times.
pub(crate) fn draw_ellipses(
    canvas: &mut Canvas,
    layout: &MapLayout,
    style: Style,
    episode: &Episode,
    m: f64,
) {
    let px_per_m = 1.0 / layout.metres_per_px();
    // The map's yaw turns the ellipse with it.
    let yaw = layout.geometry().yaw;
    for s in &episode.steps {
        let Some(c) = s.covariance_m2 else { continue };
        let (a, b, angle) = ellipse_of(&c);
        let centre = layout.world_to_px(s.position);
        if !finite(&centre) {
            continue;
        }
        draw_ellipse(
            canvas,
            style,
            centre,
            ((a * m * px_per_m) as f32, (b * m * px_per_m) as f32),
            (angle - yaw) as f32,
            palette::ELLIPSE,
        );
    }
}

/// `v` without trailing zeros ("0.5", "20").
pub(crate) fn trim(v: f64) -> String {
    let s = format!("{v:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
