//! The episode picture (`map.png`): the final knowledge map cropped to what the
//! episode knows, with world axes, what the robots did, non-overlapping scan
//! numbers, and a legend of exactly what is drawn; and its larger version for maps
//! where the normal picture has to leave scan numbers out.

use cpsplan::mission::{CycleRecord, TargetOrigin};
use cpsplan::world::CoverageTracker;
use cpsplan::{CellState, Episode, GridGeometry, OccupancyGrid};

use super::axes::{draw_origin, origin_on_map, origin_radius, Axes};
use super::chrome::{Header, LegendItem, Style, Swatch};
use super::crop::crop_window;
pub(super) use super::journey::subgoals;
use super::journey::{
    child_stands, draw_children_paths, draw_children_stands, draw_ellipses,
    draw_scans_and_subgoals, draw_trajectory, drawn_children, ellipse_magnification, end_radius,
    legs, scan_positions, trim,
};
use super::layout::{check_geometry, world_to_grid_xy, Class, Frame, MapLayout};
use super::palette;
use super::placer::{label_size, Placer};
use super::scan_labels::{draw_scan_labels, place_scan_labels, ScanLabels};
use super::step::{window_info, Window};
use super::targets::{draw_sight_lines, draw_targets};
use super::team::child_look;
use super::upright::upright;
use super::RenderError;

/// Metres of map shown around what the episode knows.
const CROP_MARGIN_M: f64 = 2.0;
/// The larger picture's longer side stays below this many pixels.
const LARGE_MAX_PX: i64 = 4800;
/// Where the normal picture points for the scan numbers it leaves out.
const LARGE_NAME: &str = "map-large.png";

/// Draws a simulated episode as PNG.
///
/// `truth` is the ground truth the episode ran on, at the geometry of
/// `episode.knowledge`. The picture shows the final knowledge map (free white,
/// occupied near-black, unknown grey), cropped to the known cells, the missed ones
/// and every robot's positions and paths with a margin of 2 m; reachable free
/// cells that were never seen tinted light orange and never-seen walls bordering
/// them a darker orange; world axes with ticks at round metres (the origin marked
/// when shown, a compass when the grid is rotated); the parent's driven paths
/// with direction arrows; each child's paths in its own colour and dash pattern
/// and its standing places at the scans as its own shape; every scan position
/// (start green, last red) numbered where there is room, runs of scans close
/// together as ranges ("14–19"), the rest counted in the header; the error
/// ellipses; the intermediate subgoals of every driven move that retrieved them
/// (section IV-C) as small dark diamonds; a header with `title`, the episode's
/// summary, the note on the labels and a legend of what is drawn; and a scale
/// bar. Without a knowledge map the ground truth is drawn.
pub fn render_episode(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
) -> Result<Vec<u8>, RenderError> {
    draw_episode_figure(truth, episode, title, 1)?
        .frame
        .canvas
        .encode()
}

/// Draws the episode as [`render_episode`] does at two to four times its pixels per
/// cell (the longer side at most 4800 pixels), as large as it takes to number
/// every scan; `None` when the normal picture numbers every scan already. The
/// normal picture refers to this one as `map-large.png`.
pub fn render_episode_large(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
) -> Result<Option<Vec<u8>>, RenderError> {
    Ok(render_episode_pictures(truth, episode, title)?.1)
}

/// Both pictures of an episode: [`render_episode`]'s and
/// [`render_episode_large`]'s, the normal one drawn once, and at most one picture
/// held in memory at a time (the larger sizes are known before they are drawn).
pub fn render_episode_pictures(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
) -> Result<(Vec<u8>, Option<Vec<u8>>), RenderError> {
    let normal = draw_episode_figure(truth, episode, title, 1)?;
    let png = normal.frame.canvas.encode()?;
    if normal.labels.omitted == 0 {
        return Ok((png, None));
    }
    let view = normal.window.geometry(upright(truth).geometry());
    drop(normal);
    let mut best: Option<EpisodeFigure> = None;
    for (zoom, _) in large_layouts(&view) {
        // The new picture is larger and numbers more: the last one can go first.
        drop(best.take());
        let fig = draw_episode_figure(truth, episode, title, zoom)?;
        let done = fig.labels.omitted == 0;
        best = Some(fig);
        if done {
            break;
        }
    }
    let large = best.map(|f| f.frame.canvas.encode()).transpose()?;
    Ok((png, large))
}

/// The most bytes the episode pictures of a grid of `geometry` take while they
/// are drawn, before the run has cropped them: the largest canvas
/// [`render_episode_pictures`] may draw (the normal one only, unless `large`),
/// with a quarter more for the header and the axes, and its PNG encoding (about
/// two fifths of the canvas again).
pub fn pictures_peak_bytes(geometry: &GridGeometry, large: bool) -> u64 {
    let canvas = |l: &MapLayout| {
        let px = (l.width_px.max(1) as u64).saturating_mul(l.height_px.max(1) as u64);
        px.saturating_mul(4).saturating_mul(5) / 4
    };
    let normal = canvas(&zoomed_layout(geometry, 1));
    let largest = large_layouts(geometry)
        .filter(|_| large)
        .map(|(_, l)| canvas(&l))
        .fold(normal, u64::max);
    largest.saturating_mul(7) / 5
}

/// The zooms the larger picture may take, with their layouts of `view`: two
/// times the normal pixels per cell always, three and four while the longer
/// side stays within [`LARGE_MAX_PX`].
fn large_layouts(view: &GridGeometry) -> impl Iterator<Item = (usize, MapLayout)> + '_ {
    (2..=4)
        .map(|zoom| (zoom, zoomed_layout(view, zoom)))
        .take_while(|(zoom, l)| *zoom == 2 || l.width_px.max(l.height_px) <= LARGE_MAX_PX)
}

/// The map's layout at `zoom` times the normal pixels per cell of `view`.
fn zoomed_layout(view: &GridGeometry, zoom: usize) -> MapLayout {
    let normal = MapLayout::new(view);
    if zoom > 1 {
        let px = normal.px_per_cell * zoom / normal.cells_per_px;
        MapLayout::at_scale(view, px.max(1))
    } else {
        normal
    }
}

/// A drawn episode picture with what the tests look at.
pub(super) struct EpisodeFigure {
    /// The picture.
    pub frame: Frame,
    /// The cells shown.
    pub window: Window,
    /// The legend's entries, in order.
    #[cfg_attr(not(test), allow(dead_code))]
    pub legend: Vec<String>,
    /// The scan numbers.
    pub labels: ScanLabels,
    /// The world axes' ticks.
    #[cfg_attr(not(test), allow(dead_code))]
    pub axes: Axes,
}

/// [`draw_episode_figure`] at the normal size, the picture only.
#[cfg(test)]
pub(super) fn draw_episode(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
) -> Result<Frame, RenderError> {
    Ok(draw_episode_figure(truth, episode, title, 1)?.frame)
}

/// The episode picture at `zoom` times the normal pixels per cell.
pub(super) fn draw_episode_figure(
    truth: &OccupancyGrid,
    episode: &Episode,
    title: &str,
    zoom: usize,
) -> Result<EpisodeFigure, RenderError> {
    // Drawn with world +x right and +y up (a grid turned by quarter turns is
    // re-indexed; every overlay is in world coordinates).
    let truth = upright(truth);
    let knowledge = episode.knowledge.as_ref().map(upright);
    let g = *truth.geometry();
    check_geometry(&g)?;
    let classes = classes(&truth, knowledge.as_deref(), episode)?;
    let window = crop_window(
        &g,
        classes
            .iter()
            .enumerate()
            .filter(|(_, c)| !matches!(c, Class::Unknown | Class::OutOfReach))
            .map(|(i, _)| i),
        episode_points(episode).map(|p| world_to_grid_xy(&g, p)),
        CROP_MARGIN_M,
    );
    let view = window.geometry(&g);
    let shown = window.crop(&classes, g.width);

    let normal = MapLayout::new(&view);
    let layout = zoomed_layout(&view, zoom);
    let style = Style::for_map(normal.width_px.max(normal.height_px));
    let (ex, ey) = view.extent();
    let magnification = ellipse_magnification(episode, ex.max(ey));
    let origin = origin_on_map(&layout, style).is_some();

    // The legend: only what the picture shows.
    let mut entries: Vec<(Swatch, String)> = Vec::new();
    for (class, name) in [
        (Class::Free, "free"),
        (Class::Occupied, "occupied"),
        (Class::Unknown, "unknown"),
        (Class::Missed, "missed"),
        (Class::MissedWall, "missed wall"),
        (Class::OutOfReach, "out of reach"),
    ] {
        if shown.contains(&class) {
            entries.push((Swatch::Cell(class.color()), name.to_owned()));
        }
    }
    let children = drawn_children(episode);
    if episode.steps.len() >= 2 {
        let name = if children.is_empty() {
            "trajectory"
        } else {
            "parent"
        };
        entries.push((Swatch::Line(palette::TRAJECTORY), name.to_owned()));
    }
    for &n in &children {
        let stood = if child_stands(episode, n).is_empty() {
            ""
        } else {
            " and stands"
        };
        let name = format!("child {} path{stood}", n + 1);
        entries.push((Swatch::Child(child_look(n)), name));
    }
    if !subgoals(episode).is_empty() {
        entries.push((Swatch::Subgoal, "subgoal".to_owned()));
    }
    if let Some(m) = magnification {
        let label = format!("error ellipse 1\u{3c3} \u{d7}{}", trim(m));
        entries.push((Swatch::Ellipse(palette::ELLIPSE), label));
    }
    let scans = scan_positions(episode).len();
    if scans > 2 {
        entries.push((Swatch::Dot(palette::SCAN), "scan".to_owned()));
    }
    entries.push((Swatch::Dot(palette::START), "start".to_owned()));
    if scans > 1 {
        entries.push((Swatch::Dot(palette::END), "end".to_owned()));
    }
    let origins = |o: TargetOrigin| episode.targets.iter().filter(|t| t.origin == o).count();
    for (o, swatch, name) in [
        (TargetOrigin::Control, Swatch::Control, "control point"),
        (TargetOrigin::Free, Swatch::Target(false), "target (given)"),
        (
            TargetOrigin::Placed,
            Swatch::Target(true),
            "target (left by the team)",
        ),
    ] {
        match origins(o) {
            0 => {}
            n => entries.push((swatch, format!("{name} \u{d7}{n}"))),
        }
    }
    if !super::targets::sight_lines(episode).is_empty() {
        entries.push((
            Swatch::Thin(palette::SIGHT),
            "a station's measurement of a target".to_owned(),
        ));
    }
    if origin {
        entries.push((Swatch::Origin, "world origin (0, 0)".to_owned()));
    }
    let mut header = Header {
        title,
        lines: vec![summary_line(episode), String::new()],
        legend: entries
            .iter()
            .map(|(swatch, label)| LegendItem {
                swatch: *swatch,
                label,
            })
            .collect(),
    };

    let axes = Axes::of(&layout, style);
    let info = window_info(&g, &window);
    let mut frame = Frame::unheaded(layout, style, &header, info, axes.gutters(style))?;
    frame.layout.paint(&mut frame.canvas, |i| shown[i]);
    axes.draw(&mut frame.canvas, style, &frame.layout);

    let labels = draw_overlay(&mut frame, episode, magnification);
    let elsewhere = format!("more in {LARGE_NAME}");
    header.lines[1] = labels.note((zoom == 1).then_some(elsewhere.as_str()));
    header.draw(&mut frame.canvas, style);
    Ok(EpisodeFigure {
        frame,
        window,
        legend: entries.into_iter().map(|(_, l)| l).collect(),
        labels,
        axes,
    })
}

/// What every cell of the grid shows: the knowledge map's state, with never-seen
/// cells split by the coverage tracker into missed, missed wall and out of reach;
/// the ground truth without a knowledge map.
fn classes(
    truth: &OccupancyGrid,
    knowledge: Option<&OccupancyGrid>,
    episode: &Episode,
) -> Result<Vec<Class>, RenderError> {
    let g = *truth.geometry();
    let Some(k) = knowledge else {
        return Ok(truth.cells().iter().map(|&s| Class::of(s)).collect());
    };
    if (k.width(), k.height()) != (g.width, g.height) {
        return Err(RenderError::GeometryMismatch {
            truth_width: g.width,
            truth_height: g.height,
            knowledge_width: k.width(),
            knowledge_height: k.height(),
        });
    }
    let tracker = g
        .world_to_cell(episode.start)
        .map(|start| CoverageTracker::new(truth, start, episode.config.robot.radius, k));
    let known = k.cells();
    Ok((0..known.len())
        .map(|i| match (known[i], &tracker) {
            (CellState::Unknown, Some(t)) if t.is_reachable_free(i) => Class::Missed,
            (CellState::Unknown, Some(t)) if t.is_bordering_wall(i) => Class::MissedWall,
            (CellState::Unknown, Some(t)) if t.is_connected_free(i) => Class::OutOfReach,
            (s, _) => Class::of(s),
        })
        .collect())
}

/// Every point the picture draws: scan positions, the parent's and the children's
/// paths and places.
fn episode_points(episode: &Episode) -> impl Iterator<Item = cpsplan::Point> + '_ {
    let steps = episode.steps.iter().flat_map(|s| {
        let cycles = s.movement.cycles.iter().flat_map(CycleRecord::points);
        std::iter::once(s.position)
            .chain(s.children.iter().copied())
            .chain(s.driven_path())
            .chain(cycles)
    });
    let targets = episode.targets.iter().map(|t| t.position);
    std::iter::once(episode.start).chain(steps).chain(targets)
}

/// Draws paths, marks and labels over the painted map; returns the scan labels.
fn draw_overlay(frame: &mut Frame, episode: &Episode, magnification: Option<f64>) -> ScanLabels {
    let (canvas, layout, style) = (&mut frame.canvas, &frame.layout, frame.style);
    let legs = legs(layout, episode);
    draw_sight_lines(canvas, layout, style, episode);
    draw_children_paths(canvas, layout, style, episode);
    draw_trajectory(canvas, style, &legs);
    if let Some(m) = magnification {
        draw_ellipses(canvas, layout, style, episode, m);
    }
    let stands = draw_children_stands(canvas, layout, style, episode);
    let dots: Vec<(f32, f32)> = scan_positions(episode)
        .iter()
        .map(|&p| layout.world_to_px(p))
        .collect();
    let targets = draw_targets(canvas, layout, style, episode);
    let diamonds = draw_scans_and_subgoals(canvas, layout, style, episode, &dots);
    let origin = origin_on_map(layout, style);
    if let Some(o) = origin {
        draw_origin(canvas, style, o);
    }

    // Labels avoid every mark: scans first (their indices are the scan numbers).
    let obstacles: Vec<(f32, f32)> = dots
        .iter()
        .chain(&diamonds)
        .chain(&stands)
        .chain(&targets)
        .chain(&origin)
        .copied()
        .collect();
    let paths = (0..legs.len()).map(|i| legs.leg(i));
    let big = end_radius(style);
    let mut placer = Placer::new(canvas, layout, paths, &obstacles, big + 2.5);
    if let Some(o) = origin {
        let text = "0,0";
        let (w, h) = label_size(text, style);
        let r = origin_radius(style) + 2.0;
        let index = obstacles.len() - 1;
        if let Some((rect, _)) = placer.place(index, o, r, w as f32, h as f32, style, true) {
            super::placer::draw_label(canvas, style, &rect, text, palette::TEXT, None);
        }
    }
    let labels = place_scan_labels(&mut placer, style, &dots, style.marker_radius(), big);
    draw_scan_labels(canvas, style, &labels, dots.len().saturating_sub(1));
    labels
}

/// "31 scans · coverage 99.6 % · walls 98.1 % · parent travel 512.3 m · stop: complete ·
/// planner seed 0".
fn summary_line(episode: &Episode) -> String {
    let s = &episode.summary;
    let stop = s.stop_reason.describe();
    format!(
        "{} scan{} \u{b7} coverage {} % \u{b7} walls {} % \u{b7} parent travel {:.1} m \
         \u{b7} stop: {} \u{b7} planner seed {}",
        s.scans,
        if s.scans == 1 { "" } else { "s" },
        super::share_percent(s.coverage),
        super::share_percent(s.wall_coverage),
        s.parent_travel_m,
        stop,
        s.seed
    )
}
