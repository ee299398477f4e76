//! The episode overlay: the parent's trajectory with direction arrows, the scan
//! markers and their numbers, placed so that they do not hide one another.

use cpsplan::world::CoverageTracker;
use cpsplan::{CellState, Episode, OccupancyGrid, Point};
use tiny_skia::PathBuilder;

use super::canvas::{Canvas, Rgb};
use super::chrome::{Header, LegendItem, Style, Swatch};
use super::layout::{check_geometry, Class, Frame, MapLayout};
use super::marks::{draw_arrow_midway, draw_ellipse, draw_marker, draw_subgoal};
use super::palette;
use super::placer::{draw_label, label_size, Placer};
use super::RenderError;

/// Draws a simulated episode as PNG.
///
/// `truth` is the ground truth the episode ran on, at the geometry of
/// `episode.knowledge`. The picture shows the final knowledge map (free white,
/// occupied near-black, unknown grey) with reachable free cells that were never seen
/// tinted light orange and never-seen walls bordering them a darker orange; the
/// parent's driven paths with direction arrows; the children's paths; every scan
/// position numbered in order (start green, last red); the intermediate subgoals of
/// every driven move that retrieved them (section IV-C) as small dark diamonds; a
/// header with `title`, the episode's summary and a legend; and a scale bar. Without
/// a knowledge map the ground truth is drawn.
pub fn render_episode(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
) -> Result<Vec<u8>, RenderError> {
    draw_episode(truth, episode, title)?.canvas.encode()
}

pub(super) fn draw_episode(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
) -> Result<Frame, RenderError> {
    let g = *truth.geometry();
    check_geometry(&g)?;
    let knowledge = episode.knowledge.as_ref();
    if let Some(k) = knowledge {
        if (k.width(), k.height()) != (g.width, g.height) {
            return Err(RenderError::GeometryMismatch {
                truth_width: g.width,
                truth_height: g.height,
                knowledge_width: k.width(),
                knowledge_height: k.height(),
            });
        }
    }
    let tracker = knowledge.and_then(|k| {
        g.world_to_cell(episode.start)
            .map(|start| CoverageTracker::new(truth, start, episode.config.robot.radius, k))
    });

    let mut legend = vec![
        LegendItem {
            swatch: Swatch::Cell(palette::FREE),
            label: "free",
        },
        LegendItem {
            swatch: Swatch::Cell(palette::OCCUPIED),
            label: "occupied",
        },
        LegendItem {
            swatch: Swatch::Cell(palette::UNKNOWN),
            label: "unknown",
        },
    ];
    if tracker.is_some() {
        legend.push(LegendItem {
            swatch: Swatch::Cell(palette::MISSED),
            label: "missed",
        });
        legend.push(LegendItem {
            swatch: Swatch::Cell(palette::MISSED_WALL),
            label: "missed wall",
        });
        legend.push(LegendItem {
            swatch: Swatch::Cell(palette::OUT_OF_REACH),
            label: "out of reach",
        });
    }
    const CHILD_LABELS: [&str; 4] = ["child 1", "child 2", "child 3", "child 4"];
    let children = episode.config.children.count.min(4);
    legend.extend([LegendItem {
        swatch: Swatch::Line(palette::TRAJECTORY),
        label: if children > 0 { "parent" } else { "trajectory" },
    }]);
    for (i, label) in CHILD_LABELS.iter().enumerate().take(children) {
        legend.push(LegendItem {
            swatch: Swatch::Line(palette::CHILDREN[i]),
            label,
        });
    }
    if !subgoals(episode).is_empty() {
        legend.push(LegendItem {
            swatch: Swatch::Subgoal,
            label: "subgoal",
        });
    }
    let magnification = ellipse_magnification(episode, &g);
    let ellipse_label = magnification.map(|m| format!("error ellipse 1\u{3c3} \u{d7}{}", trim(m)));
    if let Some(l) = &ellipse_label {
        legend.push(LegendItem {
            swatch: Swatch::Ellipse(palette::ELLIPSE),
            label: l,
        });
    }
    legend.extend([
        LegendItem {
            swatch: Swatch::Dot(palette::SCAN),
            label: "scan",
        },
        LegendItem {
            swatch: Swatch::Dot(palette::START),
            label: "start",
        },
        LegendItem {
            swatch: Swatch::Dot(palette::END),
            label: "end",
        },
    ]);
    let header = Header {
        title,
        lines: vec![summary_line(episode)],
        legend,
    };
    let mut frame = Frame::new(&g, &header)?;
    let truth_cells = truth.cells();
    match (knowledge, &tracker) {
        (Some(k), Some(t)) => {
            let known = k.cells();
            frame.layout.paint(&mut frame.canvas, |i| match known[i] {
                CellState::Unknown if t.is_reachable_free(i) => Class::Missed,
                CellState::Unknown if t.is_bordering_wall(i) => Class::MissedWall,
                CellState::Unknown if t.is_connected_free(i) => Class::OutOfReach,
                s => Class::of(s),
            });
        }
        (Some(k), None) => {
            let known = k.cells();
            frame
                .layout
                .paint(&mut frame.canvas, |i| Class::of(known[i]));
        }
        (None, _) => frame
            .layout
            .paint(&mut frame.canvas, |i| Class::of(truth_cells[i])),
    }
    draw_overlay(&mut frame.canvas, &frame.layout, frame.style, episode);
    Ok(frame)
}

/// "31 scans · coverage 99.6 % · walls 98.1 % · parent travel 512.3 m · stop: complete ·
/// planner seed 0".
fn summary_line(episode: &Episode) -> String {
    let s = &episode.summary;
    let stop = s.stop_reason.describe();
    format!(
        "{} scan{} \u{b7} coverage {:.1} % \u{b7} walls {:.1} % \u{b7} parent travel {:.1} m \
         \u{b7} stop: {} \u{b7} planner seed {}",
        s.scans,
        if s.scans == 1 { "" } else { "s" },
        100.0 * s.coverage,
        100.0 * s.wall_coverage,
        s.parent_travel_m,
        stop,
        s.seed
    )
}

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
    let colours = palette::CHILDREN;
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
    if let Some(m) = ellipse_magnification(episode, &layout.geometry()) {
        draw_ellipses(canvas, layout, style, episode, m);
    }

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

/// How much the scan positions' error ellipses are magnified: the largest major
/// semi-axis drawn about 3 % of the map's longer side, rounded down to 1, 2 or 5
/// times a power of ten; `None` without predicted errors.
fn ellipse_magnification(episode: &Episode, g: &cpsplan::GridGeometry) -> Option<f64> {
    let biggest = episode
        .steps
        .iter()
        .filter_map(|s| s.covariance_m2)
        .map(|c| major_axis(&c))
        .fold(0.0f64, f64::max);
    if biggest.is_nan() || biggest <= 0.0 {
        return None;
    }
    let (ex, ey) = g.extent();
    let want = 0.03 * ex.max(ey) / biggest;
    let mag = 10f64.powf(want.log10().floor());
    let m = [5.0, 2.0, 1.0]
        .iter()
        .map(|k| k * mag)
        .find(|&m| m <= want)
        .unwrap_or(mag);
    Some(m)
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

fn major_axis(c: &[[f64; 2]; 2]) -> f64 {
    ellipse_of(c).0
}

fn trim(v: f64) -> String {
    let s = format!("{v:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Every scan position's 1σ error ellipse, magnified `m` times.
fn draw_ellipses(canvas: &mut Canvas, layout: &MapLayout, style: Style, episode: &Episode, m: f64) {
    let px_per_m = 1.0 / layout.metres_per_px();
    for s in &episode.steps {
        let Some(c) = s.covariance_m2 else { continue };
        let (a, b, angle) = ellipse_of(&c);
        let centre = layout.world_to_px(s.position);
        if !(centre.0.is_finite() && centre.1.is_finite()) {
            continue;
        }
        // The map's yaw turns the ellipse with it.
        let yaw = layout.geometry().yaw;
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
