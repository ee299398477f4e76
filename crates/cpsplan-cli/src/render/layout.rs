//! How a map is laid out in a picture: the scale (pixels per cell, or cells per
//! pixel for huge grids), the map's place on the canvas, the painting of cells by
//! class, and the frame of header, map and footer around it.

use cpsplan::{CellState, GridGeometry, Point};

use super::axes::Axes;
use super::canvas::{Canvas, Rect, Rgb};
use super::chrome::{Footer, Header, Style};
use super::palette;
use super::RenderError;

/// What a map pixel shows, in increasing order of salience.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Class {
    Unknown,
    Free,
    OutOfReach,
    Missed,
    MissedWall,
    Occupied,
}

impl Class {
    pub(crate) fn color(self) -> Rgb {
        match self {
            Class::Unknown => palette::UNKNOWN,
            Class::Free => palette::FREE,
            Class::OutOfReach => palette::OUT_OF_REACH,
            Class::Missed => palette::MISSED,
            Class::MissedWall => palette::MISSED_WALL,
            Class::Occupied => palette::OCCUPIED,
        }
    }

    /// The class of a cell of the knowledge map.
    pub(crate) fn of(state: CellState) -> Self {
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
    pub cells_per_px: usize,
    /// Pixels per cell along each axis (1 when reducing).
    pub px_per_cell: usize,
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
    pub fn new(geometry: &GridGeometry) -> Self {
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

    /// `geometry` at `px_per_cell` pixels per cell (at least 1), placed at the canvas
    /// origin.
    pub fn at_scale(geometry: &GridGeometry, px_per_cell: usize) -> Self {
        let px_per_cell = px_per_cell.max(1);
        Self {
            geometry: *geometry,
            cells_per_px: 1,
            px_per_cell,
            x0: 0,
            y0: 0,
            width_px: (geometry.width * px_per_cell) as i64,
            height_px: (geometry.height * px_per_cell) as i64,
        }
    }

    /// Pixels per cell (fractional when reducing).
    fn scale(&self) -> f64 {
        self.px_per_cell as f64 / self.cells_per_px as f64
    }

    /// The geometry of the map drawn.
    pub fn geometry(&self) -> GridGeometry {
        self.geometry
    }

    /// Metres per pixel.
    pub fn metres_per_px(&self) -> f64 {
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

    /// The world point at a canvas position (the inverse of [`Self::world_to_px`]).
    pub fn px_to_world(&self, x: f64, y: f64) -> Point {
        let s = self.scale();
        let g = &self.geometry;
        let gx = (x - self.x0 as f64) / s * g.resolution;
        let gy = (g.height as f64 - (y - self.y0 as f64) / s) * g.resolution;
        g.grid_to_world(gx, gy)
    }

    /// The map's pixel rectangle.
    pub fn rect(&self) -> Rect {
        Rect::new(
            self.x0 as f32,
            self.y0 as f32,
            self.width_px as f32,
            self.height_px as f32,
        )
    }

    /// Paints every cell with the colour of its class, top row first.
    pub fn paint(&self, canvas: &mut Canvas, class_of: impl Fn(usize) -> Class) {
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

/// Whether a grid can be drawn: cells, and a positive finite resolution.
pub(crate) fn check_geometry(g: &GridGeometry) -> Result<(), RenderError> {
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
pub(crate) struct Frame {
    /// The picture.
    pub canvas: Canvas,
    /// Where the map lies on it.
    pub layout: MapLayout,
    /// Sizes of text, lines and markers.
    pub style: Style,
}

impl Frame {
    /// Lays the picture out around a map of `geometry` and draws header, world
    /// axes and footer.
    pub fn new(geometry: &GridGeometry, header: &Header<'_>) -> Result<Self, RenderError> {
        Self::with_info(geometry, header, geometry_info(geometry))
    }

    /// [`Frame::new`] with `info` right-aligned in the footer instead of the grid's
    /// size.
    pub fn with_info(
        geometry: &GridGeometry,
        header: &Header<'_>,
        info: String,
    ) -> Result<Self, RenderError> {
        let layout = MapLayout::new(geometry);
        let style = Style::for_map(layout.width_px.max(layout.height_px));
        // World axes in metres around the map, as on the episode's picture.
        let axes = Axes::of(&layout, style);
        let mut frame = Self::unheaded(layout, style, header, info, axes.gutters(style))?;
        axes.draw(&mut frame.canvas, style, &frame.layout);
        header.draw(&mut frame.canvas, style);
        Ok(frame)
    }

    /// Lays the picture out around the map of `layout` with `gutters` of room on its
    /// sides and draws the footer; leaves the header's room (as `header` needs it)
    /// blank for the caller to draw, with [`Header::draw`], once its lines are known.
    pub fn unheaded(
        mut layout: MapLayout,
        style: Style,
        header: &Header<'_>,
        info: String,
        gutters: Gutters,
    ) -> Result<Self, RenderError> {
        let m = style.margin();
        let width = (layout.width_px + gutters.left + gutters.right + 2 * m)
            .max(header.min_width(style))
            .max(400);
        let header_h = header.height(style, width);
        let footer = Footer {
            metres_per_px: layout.metres_per_px(),
            map_width_px: layout.width_px,
            info,
        };
        let height =
            header_h + m + gutters.top + layout.height_px + gutters.bottom + footer.height(style);
        let too_large = || RenderError::TooLarge {
            width: u32::try_from(width).unwrap_or(u32::MAX),
            height: u32::try_from(height).unwrap_or(u32::MAX),
        };
        let (w32, h32) = (
            u32::try_from(width).map_err(|_| too_large())?,
            u32::try_from(height).map_err(|_| too_large())?,
        );
        let mut canvas = Canvas::new(w32, h32)?;
        let spare = width - layout.width_px - gutters.left - gutters.right;
        layout.x0 = gutters.left + spare / 2;
        layout.y0 = header_h + m + gutters.top;
        footer.draw(
            &mut canvas,
            style,
            layout.x0,
            layout.y0 + layout.height_px + gutters.bottom,
        );
        Ok(Self {
            canvas,
            layout,
            style,
        })
    }
}

/// Room around the map, pixels (for axis ticks and labels).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Gutters {
    /// Left of the map.
    pub left: i64,
    /// Right of the map.
    pub right: i64,
    /// Above the map.
    pub top: i64,
    /// Below the map.
    pub bottom: i64,
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

/// `v` with `decimals` decimals, trailing zeros dropped.
pub(crate) fn trim_number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// `part` as a percentage of `total` (0 for none).
pub(crate) fn percent(part: usize, total: usize) -> f64 {
    if total == 0 {
        0.0
    } else {
        100.0 * part as f64 / total as f64
    }
}
