//! The figure of one planning step, after the paper's Figs. 5–7: the knowledge map
//! the step planned on, the parent's candidates coloured by their Eq. (1) score,
//! the chosen and the rejected targets, the AND regions of the CPS cycles
//! (section IV-B), the subgoals retrieved on the Visibility Graph (section IV-C),
//! every robot's path and the lines of sight of the CPS links.

use cpsplan::mission::{cycle_and_regions, CycleRecord, MoveRecord, Step, StepPlan};
use cpsplan::planning::{Decision, ParentPlan};
use cpsplan::{CellState, Config, GridGeometry, OccupancyGrid, Point};
use tiny_skia::PathBuilder;

use super::canvas::{fit_text, text_width, Canvas, Rgb};
use super::chrome::{
    draw_arrow_midway, draw_cross, draw_marker, draw_ring, draw_subgoal, ramp, subgoal_radius,
    Header, LegendItem, Style, Swatch,
};
use super::placer::{draw_label, label_size, Placer};
use super::{
    check_geometry, palette, percent, trim_number, world_to_grid_xy, Class, Frame, MapLayout,
    RenderError,
};

/// One planning step as its figure needs it: where the team stood, the parent's
/// planning round and the move that followed. Built from an episode's [`Step`]
/// (`StepView::from(&step)`) or from a single [`StepPlan`] ([`StepView::planned`]).
#[derive(Debug, Clone, Copy)]
pub struct StepView<'a> {
    /// Scan number (from 1) when the step belongs to an episode.
    pub scan: Option<usize>,
    /// Where the parent scanned and planned from, world frame.
    pub position: Point,
    /// The children's positions during the scan, world frame.
    pub children: &'a [Point],
    /// Coverage of the reachable free space after the scan, when known (simulation).
    pub coverage: Option<f64>,
    /// The parent's planning round: candidates with their Eq. (1) terms, decision.
    pub plan: &'a ParentPlan,
    /// The move that followed: target reached, subgoal flag, CPS cycles, rejections.
    pub movement: &'a MoveRecord,
}

impl<'a> From<&'a Step> for StepView<'a> {
    fn from(step: &'a Step) -> Self {
        Self {
            scan: Some(step.scan),
            position: step.position,
            children: &step.children,
            coverage: Some(step.coverage),
            plan: &step.plan,
            movement: &step.movement,
        }
    }
}

impl<'a> StepView<'a> {
    /// The view of a step planned by [`cpsplan::mission::plan_step`] for a parent at
    /// `parent` and children at `children`.
    pub fn planned(step: &'a StepPlan, parent: Point, children: &'a [Point]) -> Self {
        Self {
            scan: None,
            position: parent,
            children,
            coverage: None,
            plan: &step.plan,
            movement: &step.movement,
        }
    }

    /// The candidate the parent moves to: the one the CPS move reached, or without
    /// children the planner's choice.
    fn target(&self) -> Option<usize> {
        self.movement.target.or(match self.plan.decision {
            Decision::Target { index } if self.children.is_empty() => Some(index),
            _ => None,
        })
    }

    /// The planner's first choice.
    fn first_choice(&self) -> Option<usize> {
        match self.plan.decision {
            Decision::Target { index } => Some(index),
            _ => None,
        }
    }

    /// The subgoals of the move: where every cycle but the last left the parent.
    fn subgoals(&self) -> Vec<Point> {
        if !self.movement.subgoal_retrieval {
            return Vec::new();
        }
        let cycles = &self.movement.cycles;
        cycles[..cycles.len().saturating_sub(1)]
            .iter()
            .map(|c| c.parent_to)
            .collect()
    }

    /// The parent's path: its CPS cycles' paths, or without cycles the planned path
    /// to the target.
    fn parent_path(&self) -> Vec<Point> {
        cpsplan::mission::parent_path(self.plan, self.movement)
    }

    /// Every point the figure draws, world frame.
    fn points(&self) -> impl Iterator<Item = Point> + '_ {
        let cycles = self.movement.cycles.iter().flat_map(|c: &CycleRecord| {
            [c.parent_from, c.parent_to]
                .into_iter()
                .chain(c.parent_path.iter().copied())
                .chain(
                    c.children
                        .iter()
                        .flat_map(|k| [k.from, k.to].into_iter().chain(k.path.iter().copied())),
                )
        });
        std::iter::once(self.position)
            .chain(self.children.iter().copied())
            .chain(self.plan.candidates.iter().map(|c| c.position))
            .chain(self.plan.path.iter().copied())
            .chain(cycles)
    }
}

/// Opacity of the AND-region tint of cycle 1, 2, 3 and later cycles.
const TINT_ALPHA: [u8; 4] = [110, 72, 50, 38];
/// Opacity of the outline of the AND region of cycle 1 and of later cycles.
const TINT_EDGE_ALPHA: [u8; 2] = [230, 150];

/// The tint of the AND region of cycle `level` (from 1) over free space.
pub(crate) fn and_region_colour(level: usize) -> Rgb {
    let alpha = TINT_ALPHA[level.clamp(1, TINT_ALPHA.len()) - 1];
    palette::AND_REGION.over(palette::FREE, alpha)
}

/// The colour of a candidate of score `g` on a ramp from `lo` to `hi`.
pub(crate) fn score_colour(g: f64, lo: f64, hi: f64) -> Rgb {
    let t = if hi - lo > 1e-12 {
        (g - lo) / (hi - lo)
    } else {
        1.0
    };
    ramp(&palette::SCORE_RAMP, t)
}

/// The cells a figure shows: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Window {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Window {
    /// Every cell of `g`.
    pub(super) fn whole_of(g: &GridGeometry) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: g.width,
            y1: g.height,
        }
    }

    fn width(&self) -> usize {
        self.x1 - self.x0
    }

    fn height(&self) -> usize {
        self.y1 - self.y0
    }

    /// The window around `points` (grid-frame cell coordinates) with a margin of
    /// `margin_m` metres or a tenth of the larger span, at least `min_side_m` on each
    /// side, widened towards a landscape shape but not further than the margin
    /// beyond the `known` part of the map; the whole grid when that would cover most
    /// of it or the grid is small.
    pub(super) fn around(
        g: &GridGeometry,
        points: impl Iterator<Item = (f64, f64)>,
        known: Option<Window>,
        margin_m: f64,
        min_side_m: f64,
    ) -> Self {
        let whole = Self::whole_of(g);
        if g.width.max(g.height) <= 200 {
            return whole;
        }
        let (mut lo, mut hi) = (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for (x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        if lo.0 > hi.0 {
            return whole;
        }
        let span = (hi.0 - lo.0).max(hi.1 - lo.1);
        let margin = (margin_m / g.resolution).max(0.1 * span);
        let min_side = min_side_m / g.resolution;
        // Sides with margins, at least `min_side`, between 1.25 and 1.8 times as
        // wide as tall (the picture's header adds height: so the whole picture
        // suits a landscape screen or page); grown about their centres, then
        // shifted back inside the limits.
        let mut w = (hi.0 - lo.0 + 2.0 * margin).max(min_side);
        let mut h = (hi.1 - lo.1 + 2.0 * margin).max(min_side);
        w = w.max(1.25 * h);
        h = h.max(w / 1.8);
        let known = known.unwrap_or(whole);
        let axis = |lo: f64, hi: f64, side: f64, known: (usize, usize), n: usize| {
            let n = n as f64;
            let limit_lo = (lo - margin).min(known.0 as f64 - margin).max(0.0);
            let limit_hi = (hi + margin).max(known.1 as f64 + margin).min(n);
            let side = side.min(limit_hi - limit_lo);
            let a = ((lo + hi) / 2.0 - side / 2.0).clamp(limit_lo, limit_hi - side);
            let (a, b) = (a.floor(), (a + side).ceil().min(n));
            (a as usize, (b as usize).max(a as usize + 1))
        };
        let (x0, x1) = axis(lo.0, hi.0, w, (known.x0, known.x1), g.width);
        let (y0, y1) = axis(lo.1, hi.1, h, (known.y0, known.y1), g.height);
        let w = Self { x0, y0, x1, y1 };
        if w.width() == 0 || w.height() == 0 {
            return whole;
        }
        if (w.width() * w.height()) as f64 >= 0.6 * g.len() as f64 {
            whole
        } else {
            w
        }
    }

    /// The smallest window holding every cell of `grid` that is not Unknown.
    fn known(grid: &OccupancyGrid) -> Option<Window> {
        let width = grid.width();
        let mut w: Option<Window> = None;
        for (i, _) in grid
            .cells()
            .iter()
            .enumerate()
            .filter(|(_, &c)| c != CellState::Unknown)
        {
            let (x, y) = (i % width, i / width);
            let k = w.get_or_insert(Window {
                x0: x,
                y0: y,
                x1: x + 1,
                y1: y + 1,
            });
            k.x0 = k.x0.min(x);
            k.y0 = k.y0.min(y);
            k.x1 = k.x1.max(x + 1);
            k.y1 = k.y1.max(y + 1);
        }
        w
    }

    /// The geometry of the window's cells (same world frame as `g`).
    fn geometry(&self, g: &GridGeometry) -> GridGeometry {
        let origin = g.grid_to_world(self.x0 as f64 * g.resolution, self.y0 as f64 * g.resolution);
        let mut w = GridGeometry::new(self.width(), self.height(), g.resolution, origin);
        w.yaw = g.yaw;
        w
    }

    /// The window's part of a row-major per-cell array of a grid `width` cells wide.
    fn crop<T: Copy>(&self, values: &[T], width: usize) -> Vec<T> {
        (self.y0..self.y1)
            .flat_map(|iy| {
                values[iy * width + self.x0..iy * width + self.x1]
                    .iter()
                    .copied()
            })
            .collect()
    }
}

/// A drawn step figure with what the tests look at.
pub(super) struct StepFigure {
    /// The picture.
    pub(super) frame: Frame,
    /// The cells shown (read by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    pub(super) window: Window,
    /// Per cell of the window, the first cycle whose AND region holds it (from 1),
    /// 0 for none (read by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    pub(super) levels: Vec<u8>,
}

/// Draws the figure of one planning step as PNG.
///
/// `knowledge` is the map the step planned on (after its scan), `config` the
/// parameters it ran with (for the AND regions). The figure shows the map (free
/// white, occupied near-black, unknown grey) cropped to the parent, its candidates,
/// the cycles and their AND regions with a margin (or the whole map when that is
/// small or mostly needed); the AND region of every CPS cycle tinted green (the
/// first cycle's strongest); every candidate as a marker coloured by its score G
/// (pale yellow low to dark red high; grey when not eligible) with the score
/// printed where there is room; the target ringed and rejected targets struck out;
/// the parent's path with arrows, and when subgoals were retrieved the Visibility
/// Graph path through them and each subgoal numbered; every child's path and its
/// place in each cycle, with dashed lines of sight to the parent's positions before
/// and after the cycle; a header with `title`, the step's summary, Eq. (2) terms and
/// a legend; and a scale bar.
pub fn render_step(
    knowledge: &OccupancyGrid,
    step: &StepView<'_>,
    config: &Config,
    title: &str,
) -> Result<Vec<u8>, RenderError> {
    draw_step(knowledge, step, config, title)?
        .frame
        .canvas
        .encode()
}

pub(super) fn draw_step(
    knowledge: &OccupancyGrid,
    step: &StepView<'_>,
    config: &Config,
    title: &str,
) -> Result<StepFigure, RenderError> {
    let g = *knowledge.geometry();
    check_geometry(&g)?;

    // AND regions: per cell, the first cycle whose region (any child's) holds it.
    let mut full_levels = vec![0u8; g.len()];
    for (k, cycle) in step.movement.cycles.iter().enumerate() {
        let level = u8::try_from(k + 1).unwrap_or(u8::MAX);
        for mask in cycle_and_regions(knowledge, cycle, config) {
            if mask.len() != full_levels.len() {
                continue;
            }
            for (l, &inside) in full_levels.iter_mut().zip(&mask) {
                if inside && *l == 0 {
                    *l = level;
                }
            }
        }
    }
    let region_corners = full_levels
        .iter()
        .enumerate()
        .filter(|(_, &l)| l > 0)
        .flat_map(|(i, _)| {
            let (x, y) = ((i % g.width) as f64, (i / g.width) as f64);
            [(x, y), (x + 1.0, y + 1.0)]
        });
    let window = Window::around(
        &g,
        step.points()
            .map(|p| {
                let (x, y) = world_to_grid_xy(&g, p);
                (x, y)
            })
            .chain(region_corners),
        Window::known(knowledge),
        4.0,
        20.0,
    );
    let view_geometry = window.geometry(&g);
    let cells = window.crop(knowledge.cells(), g.width);
    let levels = window.crop(&full_levels, g.width);

    let layout = MapLayout::new(&view_geometry);
    let style = Style::for_map(layout.width_px.max(layout.height_px));
    let text_room = (layout.width_px + 2 * style.margin()).max(400) - 2 * style.margin();
    let cycles = step.movement.cycles.len();
    let scores = ScoreRange::of(step);
    let texts = LegendTexts::new(step, &scores);
    let header = Header {
        title,
        lines: caption(step, knowledge, text_room, style),
        legend: legend(step, cycles, &levels, &texts),
    };
    let info = window_info(&g, &window);
    let mut frame = Frame::with_info(&view_geometry, &header, info)?;
    frame
        .layout
        .paint(&mut frame.canvas, |i| Class::of(cells[i]));
    tint(
        &mut frame.canvas,
        &frame.layout,
        window.width(),
        window.height(),
        &levels,
    );
    draw_overlay(&mut frame.canvas, &frame.layout, frame.style, step, &scores);
    Ok(StepFigure {
        frame,
        window,
        levels,
    })
}

/// The range of the eligible candidates' scores, for the colour ramp.
struct ScoreRange {
    lo: f64,
    hi: f64,
}

impl ScoreRange {
    fn of(step: &StepView<'_>) -> Self {
        let (lo, hi) = step
            .plan
            .candidates
            .iter()
            .filter(|c| c.eligible && c.g.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c.g), hi.max(c.g))
            });
        if lo > hi {
            Self { lo: 0.0, hi: 0.0 }
        } else {
            Self { lo, hi }
        }
    }

    fn colour(&self, g: f64) -> Rgb {
        score_colour(g, self.lo, self.hi)
    }
}

/// A score as printed: three significant digits for ordinary magnitudes.
fn format_score(g: f64) -> String {
    let a = g.abs();
    if a >= 100.0 {
        format!("{g:.0}")
    } else if a >= 10.0 {
        format!("{g:.1}")
    } else if a >= 1.0 {
        format!("{g:.2}")
    } else {
        format!("{g:.3}")
    }
}

/// Legend labels that depend on the step.
struct LegendTexts {
    ramp: String,
}

impl LegendTexts {
    fn new(step: &StepView<'_>, scores: &ScoreRange) -> Self {
        let any = step.plan.candidates.iter().any(|c| c.eligible);
        let ramp = if !any {
            "candidate score G".to_owned()
        } else if scores.hi - scores.lo > 1e-12 {
            format!(
                "candidate G {} to {}",
                format_score(scores.lo),
                format_score(scores.hi)
            )
        } else {
            format!("candidate G {}", format_score(scores.hi))
        };
        Self { ramp }
    }
}

fn legend<'a>(
    step: &StepView<'_>,
    cycles: usize,
    levels: &[u8],
    texts: &'a LegendTexts,
) -> Vec<LegendItem<'a>> {
    const CHILD_LABELS: [&str; 4] = ["child 1", "child 2", "child 3", "child 4"];
    let item = |swatch, label| LegendItem { swatch, label };
    let mut legend = vec![
        item(Swatch::Cell(palette::FREE), "free"),
        item(Swatch::Cell(palette::OCCUPIED), "occupied"),
        item(Swatch::Cell(palette::UNKNOWN), "unknown"),
    ];
    if levels.contains(&1) {
        let label = if cycles > 1 {
            "AND region, cycle 1"
        } else {
            "AND region"
        };
        legend.push(item(Swatch::Cell(and_region_colour(1)), label));
    }
    if levels.iter().any(|&l| l > 1) {
        legend.push(item(Swatch::Cell(and_region_colour(2)), "later cycles"));
    }
    if step.parent_path().len() >= 2 {
        legend.push(item(Swatch::Line(palette::TRAJECTORY), "parent path"));
    }
    if step.movement.subgoal_retrieval {
        legend.push(item(
            Swatch::Dashed(palette::SUBGOAL),
            "Visibility Graph path",
        ));
        legend.push(item(Swatch::Subgoal, "subgoal"));
    }
    let children = step
        .children
        .len()
        .max(step.movement.cycles.first().map_or(0, |c| c.children.len()));
    for (i, label) in CHILD_LABELS.iter().enumerate().take(children) {
        legend.push(item(Swatch::Line(palette::CHILDREN[i]), label));
    }
    if cycles > 0 {
        legend.push(item(Swatch::Dashed(palette::MUTED_TEXT), "line of sight"));
    }
    legend.push(item(Swatch::Dot(palette::TRAJECTORY), "parent"));
    if !step.plan.candidates.is_empty() {
        legend.push(item(Swatch::Ramp(&palette::SCORE_RAMP), &texts.ramp));
    }
    if step.plan.candidates.iter().any(|c| !c.eligible) {
        legend.push(item(Swatch::SmallDot(palette::INELIGIBLE), "not eligible"));
    }
    if step.target().is_some() {
        legend.push(item(
            Swatch::Ring(ramp(&palette::SCORE_RAMP, 1.0)),
            "target",
        ));
    }
    if !step.movement.rejected.is_empty() {
        legend.push(item(
            Swatch::Cross(ramp(&palette::SCORE_RAMP, 1.0)),
            "rejected",
        ));
    }
    legend
}

/// "x, y" of a point, one decimal.
fn xy(p: Point) -> String {
    format!("({:.1}, {:.1})", p.x, p.y)
}

/// The header's text lines: segments joined by " · " and wrapped to `room` pixels.
fn caption(step: &StepView<'_>, knowledge: &OccupancyGrid, room: i64, style: Style) -> Vec<String> {
    let plan = step.plan;
    let candidates = &plan.candidates;
    let mut first = Vec::new();
    match (step.scan, step.coverage) {
        (Some(n), Some(c)) => {
            first.push(format!("scan {n}"));
            first.push(format!("coverage {:.1} %", 100.0 * c));
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
fn window_info(g: &GridGeometry, w: &Window) -> String {
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

/// Tints the AND regions over the painted map: every pixel of a cell of level `l`
/// blended with the tint of cycle `l`, with a thin darker outline where the region
/// ends.
fn tint(canvas: &mut Canvas, layout: &MapLayout, width: usize, height: usize, levels: &[u8]) {
    if levels.iter().all(|&l| l == 0) {
        return;
    }
    let (k, s) = (layout.cells_per_px, layout.px_per_cell);
    let cell_of = |px: usize| if k == 1 { px / s } else { px * k };
    let (wp, hp) = (layout.width_px as usize, layout.height_px as usize);
    let cols: Vec<usize> = (0..wp).map(|px| cell_of(px).min(width - 1)).collect();
    let rows: Vec<usize> = (0..hp)
        .map(|py| height - 1 - cell_of(py).min(height - 1))
        .collect();
    let level_at = |px: usize, py: usize| levels[rows[py] * width + cols[px]];
    let stride = canvas.pixmap.width() as usize;
    let (x0, y0) = (layout.x0.max(0) as usize, layout.y0.max(0) as usize);
    let data = canvas.pixmap.data_mut();
    for py in 0..hp {
        for px in 0..wp {
            let l = level_at(px, py);
            if l == 0 {
                continue;
            }
            let outside = |nl: u8| nl == 0 || nl > l;
            let edge = (px > 0 && outside(level_at(px - 1, py)))
                || (px + 1 < wp && outside(level_at(px + 1, py)))
                || (py > 0 && outside(level_at(px, py - 1)))
                || (py + 1 < hp && outside(level_at(px, py + 1)));
            let alpha = if edge {
                TINT_EDGE_ALPHA[usize::from(l > 1)]
            } else {
                TINT_ALPHA[usize::from(l).min(TINT_ALPHA.len()) - 1]
            };
            let i = ((y0 + py) * stride + x0 + px) * 4;
            let Some(p) = data.get_mut(i..i + 3) else {
                continue;
            };
            let under = Rgb(p[0], p[1], p[2]);
            let Rgb(r, g, b) = palette::AND_REGION.over(under, alpha);
            p.copy_from_slice(&[r, g, b]);
        }
    }
}

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
fn draw_overlay(
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
        if c.eligible {
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
