//! The figure of one planning step, after the paper's Figs. 5–7: the knowledge map
//! the step planned on, the parent's candidates coloured by their Eq. (1) score,
//! the chosen and the rejected targets, the AND regions of the CPS cycles
//! (section IV-B), the subgoals retrieved on the Visibility Graph (section IV-C),
//! every robot's path and the lines of sight of the CPS links.
//!
//! - this module: what a step figure shows ([`StepView`]) and how it is put
//!   together ([`render_step`]);
//! - `window`: the part of the map shown;
//! - `tint`: the AND regions over the map;
//! - `overlay`: paths, lines of sight, markers and labels;
//! - `scores`: the colours and printed form of the Eq. (1) scores;
//! - `legend`, `caption`: the header's legend and text lines.

mod caption;
mod legend;
mod overlay;
mod scores;
mod tint;
mod window;

use cpsplan::mission::{move_and_regions, CycleRecord, MoveRecord, Step, StepPlan};
use cpsplan::parent::{Decision, ParentPlan};
use cpsplan::{Config, OccupancyGrid, Point};

use self::caption::caption;
use self::legend::{legend, LegendTexts};
use self::overlay::draw_overlay;
use self::scores::ScoreRange;
use self::tint::tint;
use super::chrome::{Header, Style};
use super::layout::{check_geometry, world_to_grid_xy, Class, Frame, MapLayout};
use super::upright::upright;
use super::RenderError;

pub(super) use self::{caption::window_info, window::Window};
#[cfg(test)]
pub(super) use self::{scores::score_colour, tint::and_region_colour};

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
    pub(super) fn target(&self) -> Option<usize> {
        self.movement.target.or(match self.plan.decision {
            Decision::Target { index } if self.children.is_empty() => Some(index),
            _ => None,
        })
    }

    /// The planner's first choice.
    pub(super) fn first_choice(&self) -> Option<usize> {
        match self.plan.decision {
            Decision::Target { index } => Some(index),
            _ => None,
        }
    }

    /// The subgoals of the move: where every cycle but the last left the parent.
    pub(super) fn subgoals(&self) -> Vec<Point> {
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
    pub(super) fn parent_path(&self) -> Vec<Point> {
        cpsplan::mission::parent_path(self.plan, self.movement)
    }

    /// Every point the figure draws, world frame.
    fn points(&self) -> impl Iterator<Item = Point> + '_ {
        let cycles = self.movement.cycles.iter().flat_map(CycleRecord::points);
        std::iter::once(self.position)
            .chain(self.children.iter().copied())
            .chain(self.plan.candidates.iter().map(|c| c.position))
            .chain(self.plan.path.iter().copied())
            .chain(cycles)
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
    // World +x right and +y up ([`upright`]): the step's points are world points.
    let knowledge = upright(knowledge);
    let knowledge = knowledge.as_ref();
    let g = *knowledge.geometry();
    check_geometry(&g)?;

    // AND regions: per cell, the first cycle whose region (any child's) holds it.
    let mut full_levels = vec![0u8; g.len()];
    let regions = move_and_regions(knowledge, &step.movement.cycles, config);
    for (k, cycle_regions) in regions.iter().enumerate() {
        let level = u8::try_from(k + 1).unwrap_or(u8::MAX);
        for region in cycle_regions {
            for &i in &region.cells {
                if let Some(l) = full_levels.get_mut(i as usize).filter(|l| **l == 0) {
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
