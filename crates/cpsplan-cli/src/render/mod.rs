//! Pictures of maps and episodes as PNG (DESIGN.md pipeline stage 9, "Reports").
//!
//! - [`render_episode`]: the final knowledge map of a simulated episode with what was
//!   missed tinted, the parent's trajectory, numbered scan positions, a header with
//!   title, summary and legend, and a scale bar; with children, their paths and
//!   the subgoals of every move that needed them.
//! - [`render_step`]: one planning step after the paper's Figs. 5–7 (candidates by
//!   score, AND regions, subgoals, every robot's path and the CPS lines of sight),
//!   on a window of the knowledge map the step planned on.
//! - [`render_map`]: a plain preview of an occupancy grid.
//!
//! Pictures are drawn in the grid frame (row 0 at the bottom, so north is up for an
//! unrotated map) at an integer number of pixels per cell chosen so that the longer
//! side of the map is about 1600 pixels (at most 2000, and at least one pixel per
//! cell up to 2400 cells); grids longer than 2400 cells are reduced
//! instead, one pixel showing the most salient state of a block of cells (occupied
//! over missed over free over unknown), so thin walls never vanish.

mod canvas;
mod chrome;
mod episode;
mod placer;
mod step;

pub use self::step::{render_step, StepView};

use cpsplan::world::CoverageTracker;
use cpsplan::{CellState, Episode, GridGeometry, OccupancyGrid, Point, StopReason};
use thiserror::Error;

use self::canvas::{Canvas, Rgb};
use self::chrome::{Footer, Header, LegendItem, Style, Swatch};

/// Why a picture could not be drawn.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RenderError {
    /// The grid has no cells.
    #[error("cannot draw an empty map ({width} x {height} cells)")]
    EmptyMap {
        /// Columns.
        width: usize,
        /// Rows.
        height: usize,
    },
    /// The grid's cell width is not a positive finite number.
    #[error("cannot draw a map with resolution {0} m: it must be a positive number")]
    BadResolution(f64),
    /// The episode's knowledge map and the ground truth differ in size.
    #[error(
        "the knowledge map ({knowledge_width} x {knowledge_height} cells) does not match \
         the ground truth ({truth_width} x {truth_height} cells)"
    )]
    GeometryMismatch {
        /// Ground-truth columns.
        truth_width: usize,
        /// Ground-truth rows.
        truth_height: usize,
        /// Knowledge-map columns.
        knowledge_width: usize,
        /// Knowledge-map rows.
        knowledge_height: usize,
    },
    /// The picture would be too large to allocate.
    #[error("a picture of {width} x {height} pixels is too large to draw")]
    TooLarge {
        /// Picture width in pixels.
        width: u32,
        /// Picture height in pixels.
        height: u32,
    },
    /// PNG encoding failed.
    #[error("PNG encoding failed: {0}")]
    Encode(String),
}

/// The colours of every picture.
pub(crate) mod palette {
    use super::Rgb;

    /// Known free space.
    pub const FREE: Rgb = Rgb::hex(0xffffff);
    /// Known obstacles.
    pub const OCCUPIED: Rgb = Rgb::hex(0x2b2b2b);
    /// Never observed, not part of the reachable space.
    pub const UNKNOWN: Rgb = Rgb::hex(0xd5dae1);
    /// Reachable free space that was never observed.
    pub const MISSED: Rgb = Rgb::hex(0xf6c9a0);
    /// Walls bordering the reachable space that were never observed.
    pub const MISSED_WALL: Rgb = Rgb::hex(0xd08a4e);
    /// Free space connected to the start but out of the robot's reach (behind
    /// gaps narrower than the robot), never observed.
    pub const OUT_OF_REACH: Rgb = Rgb::hex(0xd8c6ea);
    /// The parent's path.
    pub const TRAJECTORY: Rgb = Rgb::hex(0x1f77b4);
    /// The children's paths, child 1 first (repeats for more children).
    pub const CHILDREN: [Rgb; 4] = [
        Rgb::hex(0x9467bd),
        Rgb::hex(0x17becf),
        Rgb::hex(0x8c564b),
        Rgb::hex(0xe377c2),
    ];
    /// Scan positions.
    pub const SCAN: Rgb = Rgb::hex(0xff7f0e);
    /// The first scan (the start).
    pub const START: Rgb = Rgb::hex(0x2ca02c);
    /// The last scan.
    pub const END: Rgb = Rgb::hex(0xd62728);
    /// Body text.
    pub const TEXT: Rgb = Rgb::hex(0x1a1a1a);
    /// Secondary text.
    pub const MUTED_TEXT: Rgb = Rgb::hex(0x4a5360);
    /// Thin separators and the map frame.
    pub const RULE: Rgb = Rgb::hex(0xc4cad2);
    /// Outline of legend swatches and label boxes.
    pub const SWATCH_EDGE: Rgb = Rgb::hex(0x8a939e);
    /// Subgoals retrieved on the Visibility Graph, and the graph path through them.
    pub const SUBGOAL: Rgb = Rgb::hex(0x0b2e59);
    /// AND regions (section IV-B), blended over the map.
    pub const AND_REGION: Rgb = Rgb::hex(0x2ca02c);
    /// Targets the CPS move gave up.
    pub const REJECTED: Rgb = Rgb::hex(0xd62728);
    /// Candidates that may not be chosen.
    pub const INELIGIBLE: Rgb = Rgb::hex(0x9aa3ad);
    /// The ramp of candidate scores `G`, low to high.
    pub const SCORE_RAMP: [Rgb; 5] = [
        Rgb::hex(0xfee391),
        Rgb::hex(0xfdb14f),
        Rgb::hex(0xf2712b),
        Rgb::hex(0xcf3a1c),
        Rgb::hex(0x8c1a0f),
    ];
}

/// What a map pixel shows, in increasing order of salience.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Class {
    Unknown,
    Free,
    OutOfReach,
    Missed,
    MissedWall,
    Occupied,
}

impl Class {
    fn color(self) -> Rgb {
        match self {
            Class::Unknown => palette::UNKNOWN,
            Class::Free => palette::FREE,
            Class::OutOfReach => palette::OUT_OF_REACH,
            Class::Missed => palette::MISSED,
            Class::MissedWall => palette::MISSED_WALL,
            Class::Occupied => palette::OCCUPIED,
        }
    }

    fn of(state: CellState) -> Self {
        match state {
            CellState::Unknown => Class::Unknown,
            CellState::Free => Class::Free,
            CellState::Occupied => Class::Occupied,
        }
    }
}

/// Grid-frame coordinates of a world point, in cells: cell (ix, iy) covers
/// `[ix, ix + 1) × [iy, iy + 1)` (the origin's yaw undone).
pub(crate) fn world_to_grid_xy(geometry: &GridGeometry, p: Point) -> (f64, f64) {
    let (dx, dy) = (p.x - geometry.origin.x, p.y - geometry.origin.y);
    let (s, c) = geometry.yaw.sin_cos();
    (
        (c * dx + s * dy) / geometry.resolution,
        (-s * dx + c * dy) / geometry.resolution,
    )
}

/// Where the map lies on the canvas and how cells map to pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MapLayout {
    geometry: GridGeometry,
    /// Cells per pixel along each axis (1 unless the grid is very large).
    cells_per_px: usize,
    /// Pixels per cell along each axis (1 when reducing).
    px_per_cell: usize,
    /// Canvas position of the map's top-left pixel.
    pub x0: i64,
    /// Canvas position of the map's top-left pixel.
    pub y0: i64,
    /// Map size in pixels.
    pub width_px: i64,
    /// Map size in pixels.
    pub height_px: i64,
}

impl MapLayout {
    /// The scale for `geometry`, placed at the canvas origin.
    fn new(geometry: &GridGeometry) -> Self {
        let longest = geometry.width.max(geometry.height).max(1);
        let (cells_per_px, px_per_cell) = if longest <= 2400 {
            let near = (1600.0 / longest as f64).round() as usize;
            (1, near.min(2000 / longest).max(1))
        } else {
            (longest.div_ceil(1800), 1)
        };
        Self {
            geometry: *geometry,
            cells_per_px,
            px_per_cell,
            x0: 0,
            y0: 0,
            width_px: (geometry.width.div_ceil(cells_per_px) * px_per_cell) as i64,
            height_px: (geometry.height.div_ceil(cells_per_px) * px_per_cell) as i64,
        }
    }

    /// Pixels per cell (fractional when reducing).
    fn scale(&self) -> f64 {
        self.px_per_cell as f64 / self.cells_per_px as f64
    }

    /// Metres per pixel.
    fn metres_per_px(&self) -> f64 {
        self.geometry.resolution / self.scale()
    }

    /// Canvas position of a world point.
    pub fn world_to_px(&self, p: Point) -> (f32, f32) {
        let (gx, gy) = world_to_grid_xy(&self.geometry, p);
        let s = self.scale();
        (
            (self.x0 as f64 + gx * s) as f32,
            (self.y0 as f64 + (self.geometry.height as f64 - gy) * s) as f32,
        )
    }

    /// The map's pixel rectangle.
    pub fn rect(&self) -> canvas::Rect {
        canvas::Rect::new(
            self.x0 as f32,
            self.y0 as f32,
            self.width_px as f32,
            self.height_px as f32,
        )
    }

    /// Paints every cell with the colour of its class, top row first.
    fn paint(&self, canvas: &mut Canvas, class_of: impl Fn(usize) -> Class) {
        let (w, h) = (self.geometry.width, self.geometry.height);
        let (k, s) = (self.cells_per_px, self.px_per_cell);
        let out_w = w.div_ceil(k);
        let mut classes = vec![Class::Unknown; out_w];
        let mut row = vec![0u8; out_w * s * 4];
        for r in 0..h.div_ceil(k) {
            let top = h - r * k;
            classes.fill(Class::Unknown);
            for iy in top.saturating_sub(k)..top {
                for ix in 0..w {
                    let c = class_of(iy * w + ix);
                    let o = &mut classes[ix / k];
                    if c > *o {
                        *o = c;
                    }
                }
            }
            for (px, c) in row.chunks_exact_mut(4 * s).zip(&classes) {
                let Rgb(red, green, blue) = c.color();
                for p in px.chunks_exact_mut(4) {
                    p.copy_from_slice(&[red, green, blue, 255]);
                }
            }
            for j in 0..s {
                let y = self.y0 + (r * s + j) as i64;
                canvas.put_row(self.x0 as usize, y as usize, &row);
            }
        }
        canvas.outline_rect(
            self.x0 - 1,
            self.y0 - 1,
            self.width_px + 2,
            self.height_px + 2,
            palette::RULE,
        );
    }
}

fn check_geometry(g: &GridGeometry) -> Result<(), RenderError> {
    if g.is_empty() {
        return Err(RenderError::EmptyMap {
            width: g.width,
            height: g.height,
        });
    }
    if !(g.resolution.is_finite() && g.resolution > 0.0) {
        return Err(RenderError::BadResolution(g.resolution));
    }
    Ok(())
}

/// A whole picture: header, map, footer.
struct Frame {
    canvas: Canvas,
    layout: MapLayout,
    style: Style,
}

impl Frame {
    /// Lays the picture out around a map of `geometry` and draws header and footer.
    fn new(geometry: &GridGeometry, header: &Header<'_>) -> Result<Self, RenderError> {
        Self::with_info(geometry, header, geometry_info(geometry))
    }

    /// [`Frame::new`] with `info` right-aligned in the footer instead of the grid's
    /// size.
    fn with_info(
        geometry: &GridGeometry,
        header: &Header<'_>,
        info: String,
    ) -> Result<Self, RenderError> {
        let mut layout = MapLayout::new(geometry);
        let style = Style::for_map(layout.width_px.max(layout.height_px));
        let m = style.margin();
        let width = (layout.width_px + 2 * m)
            .max(header.min_width(style))
            .max(400);
        let header_h = header.height(style, width);
        let footer = Footer {
            metres_per_px: layout.metres_per_px(),
            map_width_px: layout.width_px,
            info,
        };
        let height = header_h + m + layout.height_px + footer.height(style);
        let too_large = || RenderError::TooLarge {
            width: u32::try_from(width).unwrap_or(u32::MAX),
            height: u32::try_from(height).unwrap_or(u32::MAX),
        };
        let (w32, h32) = (
            u32::try_from(width).map_err(|_| too_large())?,
            u32::try_from(height).map_err(|_| too_large())?,
        );
        let mut canvas = Canvas::new(w32, h32)?;
        header.draw(&mut canvas, style);
        layout.x0 = (width - layout.width_px) / 2;
        layout.y0 = header_h + m;
        footer.draw(&mut canvas, style, layout.x0, layout.y0 + layout.height_px);
        Ok(Self {
            canvas,
            layout,
            style,
        })
    }
}

/// "800 × 600 cells of 0.1 m · 80 × 60 m".
fn geometry_info(g: &GridGeometry) -> String {
    let (ex, ey) = g.extent();
    format!(
        "{} \u{d7} {} cells of {} m \u{b7} {} \u{d7} {} m",
        g.width,
        g.height,
        trim_number(g.resolution, 3),
        trim_number(ex, 1),
        trim_number(ey, 1)
    )
}

fn trim_number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

fn percent(part: usize, total: usize) -> f64 {
    if total == 0 {
        0.0
    } else {
        100.0 * part as f64 / total as f64
    }
}

/// Draws a plain preview of `grid` as PNG: free white, occupied near-black, unknown
/// grey, with a title strip (title, cell counts, legend) and a scale bar.
pub fn render_map(grid: &OccupancyGrid, title: &str) -> Result<Vec<u8>, RenderError> {
    draw_map(grid, title)?.canvas.encode()
}

fn draw_map(grid: &OccupancyGrid, title: &str) -> Result<Frame, RenderError> {
    let g = *grid.geometry();
    check_geometry(&g)?;
    let n = g.len();
    let line = format!(
        "free {:.1} % \u{b7} occupied {:.1} % \u{b7} unknown {:.1} %",
        percent(grid.count(CellState::Free), n),
        percent(grid.count(CellState::Occupied), n),
        percent(grid.count(CellState::Unknown), n),
    );
    let header = Header {
        title,
        lines: vec![line],
        legend: vec![
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
        ],
    };
    let mut frame = Frame::new(&g, &header)?;
    let cells = grid.cells();
    frame
        .layout
        .paint(&mut frame.canvas, |i| Class::of(cells[i]));
    Ok(frame)
}

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

fn draw_episode(
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
    if !episode::subgoals(episode).is_empty() {
        legend.push(LegendItem {
            swatch: Swatch::Subgoal,
            label: "subgoal",
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
    episode::draw_overlay(&mut frame.canvas, &frame.layout, frame.style, episode);
    Ok(frame)
}

/// "31 scans · coverage 99.6 % · walls 98.1 % · parent travel 512.3 m · stop: complete ·
/// planner seed 0".
fn summary_line(episode: &Episode) -> String {
    let s = &episode.summary;
    let stop = match s.stop_reason {
        StopReason::Complete => "complete",
        StopReason::NoReachableFrontier => "no reachable frontier",
        StopReason::ScanLimit => "scan limit",
        StopReason::NoCpsMove => "no CPS move",
    };
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

#[cfg(test)]
mod tests;
