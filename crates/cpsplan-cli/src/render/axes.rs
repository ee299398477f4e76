//! World axes around a map: ticks at round metre values where the world's lines
//! x = k and y = k cross the map's bottom and left edges, labelled below and to the
//! left of the map; the world origin marked when it lies on the map; and, when the
//! grid is rotated, a compass beside the map with the world's +y and +x directions.

use cpsplan::Point;
use tiny_skia::PathBuilder;

use super::canvas::{text_height, text_width, Canvas, Rect, Rgb};
use super::chrome::Style;
use super::layout::{Gutters, MapLayout};
use super::marks::draw_arrowhead;
use super::palette;

/// A world coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Coord {
    X,
    Y,
}

impl Coord {
    fn of(self, p: Point) -> f64 {
        match self {
            Coord::X => p.x,
            Coord::Y => p.y,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Coord::X => "x (m)",
            Coord::Y => "y (m)",
        }
    }
}

/// One tick: where along its edge (pixels from the map's left, or bottom, edge)
/// the line `coord = value` crosses it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tick {
    /// Pixels from the edge's start (the map's bottom-left corner).
    pub offset: f32,
    /// The world coordinate, metres (a multiple of the step).
    pub value: f64,
    /// The printed value.
    pub label: String,
}

/// The ticks of the bottom and left edges.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Axes {
    /// Metres between ticks: 1, 2 or 5 × 10^k, at least 1.
    pub step: f64,
    /// The coordinate along the bottom edge and its ticks, left to right.
    pub bottom: (Coord, Vec<Tick>),
    /// The coordinate along the left edge and its ticks, bottom to top.
    pub left: (Coord, Vec<Tick>),
    /// Whether the grid is turned against the world (a compass is drawn).
    pub rotated: bool,
}

/// The round tick step, metres, for ticks at least `min_px` apart on a map of
/// `metres_per_px`: 1, 2 or 5 × 10^k, never below 1 m.
pub(crate) fn tick_step(metres_per_px: f64, min_px: f64) -> f64 {
    let want = (metres_per_px * min_px).max(1.0);
    if !want.is_finite() {
        return 1.0;
    }
    let decade = 10f64.powf(want.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|f| f * decade)
        .find(|&s| s >= want * (1.0 - 1e-9))
        .unwrap_or(10.0 * decade)
}

/// Whether a grid of this yaw is turned against the world (by more than a hair).
pub(crate) fn is_rotated(yaw: f64) -> bool {
    let (s, c) = yaw.sin_cos();
    s.abs() > 1e-6 || c < 0.0
}

/// Multiples of `step` in the closed range between `a` and `b`, in order from `a`.
fn multiples(a: f64, b: f64, step: f64) -> Vec<f64> {
    let (lo, hi) = (a.min(b), a.max(b));
    let (k0, k1) = ((lo / step).ceil(), (hi / step).floor());
    if !(k0.is_finite() && k1.is_finite()) || k1 - k0 > 10_000.0 {
        return Vec::new();
    }
    let mut v: Vec<f64> = (0..=(k1 - k0).max(-1.0) as i64)
        .map(|i| (k0 + i as f64) * step)
        .collect();
    if a > b {
        v.reverse();
    }
    v
}

/// "10", "-5", "0" (never "-0").
fn format_tick(v: f64) -> String {
    let r = v.round();
    if r == 0.0 {
        "0".to_owned()
    } else {
        format!("{r:.0}")
    }
}

impl Axes {
    /// The ticks of a map laid out as `layout` (its placement on the canvas does not
    /// matter), at least `8 × style.g` glyph widths apart.
    pub fn of(layout: &MapLayout, style: Style) -> Self {
        let step = tick_step(layout.metres_per_px(), 44.0 * style.g as f64);
        let (w, h) = (layout.width_px as f64, layout.height_px as f64);
        let (x0, y0) = (layout.x0 as f64, layout.y0 as f64);
        let corner = layout.px_to_world(x0, y0 + h);
        let right = layout.px_to_world(x0 + w, y0 + h);
        let top = layout.px_to_world(x0, y0);
        // The bottom edge carries the world coordinate that changes most along it.
        let along_x = (right.x - corner.x).abs() >= (right.y - corner.y).abs();
        let (bottom_coord, left_coord) = if along_x {
            (Coord::X, Coord::Y)
        } else {
            (Coord::Y, Coord::X)
        };
        let ticks = |coord: Coord, end: Point, len: f64| {
            let (a, b) = (coord.of(corner), coord.of(end));
            multiples(a, b, step)
                .into_iter()
                .map(|value| Tick {
                    offset: ((value - a) / (b - a) * len) as f32,
                    value,
                    label: format_tick(value),
                })
                .collect::<Vec<_>>()
        };
        Self {
            step,
            bottom: (bottom_coord, ticks(bottom_coord, right, w)),
            left: (left_coord, ticks(left_coord, top, h)),
            rotated: is_rotated(layout.geometry().yaw),
        }
    }

    /// The room the axes need around the map.
    pub fn gutters(&self, style: Style) -> Gutters {
        let g = i64::from(style.g);
        let widest = self
            .left
            .1
            .iter()
            .map(|t| text_width(&t.label, style.g))
            .chain([text_width(self.left.0.name(), style.g)])
            .max()
            .unwrap_or(0);
        Gutters {
            left: tick_len(style) + 3 * g + widest,
            right: if self.rotated { compass_size(style) } else { 0 },
            top: text_height(style.g) + 3 * g,
            bottom: tick_len(style) + 3 * g + text_height(style.g) + 2 * g,
        }
    }

    /// Draws ticks and labels around the map of `layout` (placed on the canvas), and
    /// the compass when the grid is rotated.
    pub fn draw(&self, canvas: &mut Canvas, style: Style, layout: &MapLayout) {
        let g = i64::from(style.g);
        let (x0, y0) = (layout.x0, layout.y0);
        let (w, h) = (layout.width_px, layout.height_px);
        let len = tick_len(style);
        let th = text_height(style.g);
        let colour = palette::MUTED_TEXT;

        // Bottom: the coordinate's name right-aligned under the map's right end,
        // tick labels centred on their ticks where they fit.
        let label_y = y0 + h + 1 + len + 2 * g;
        let name = self.bottom.0.name();
        let name_x = x0 + w - text_width(name, style.g);
        canvas.text(name_x, label_y, name, style.g, palette::TEXT);
        let mut free_from = i64::MIN;
        for t in &self.bottom.1 {
            let x = x0 + t.offset.round() as i64;
            canvas.fill_rect(x, y0 + h + 1, g, len, colour);
            let tw = text_width(&t.label, style.g);
            let lx = x - tw / 2;
            if lx >= free_from && lx + tw + 4 * g <= name_x {
                canvas.text(lx, label_y, &t.label, style.g, colour);
                free_from = lx + tw + 4 * g;
            }
        }

        // Left: the name above the map's top-left corner, labels right-aligned
        // beside their ticks.
        let name = self.left.0.name();
        canvas.text(
            x0 - len - g - text_width(name, style.g),
            y0 - th - 2 * g,
            name,
            style.g,
            palette::TEXT,
        );
        let mut free_below = i64::MAX;
        for t in &self.left.1 {
            let y = y0 + h - t.offset.round() as i64;
            canvas.fill_rect(x0 - 1 - len, y, len, g, colour);
            let ty = y - th / 2;
            if ty + th + 2 * g <= free_below && ty >= y0 - th / 2 {
                let tw = text_width(&t.label, style.g);
                canvas.text(x0 - len - 2 * g - tw, ty, &t.label, style.g, colour);
                free_below = ty;
            }
        }

        if self.rotated {
            let s = compass_size(style) as f32;
            let centre = ((x0 + w) as f32 + s / 2.0, y0 as f32 + s / 2.0);
            draw_compass(canvas, style, layout, centre);
        }
    }
}

fn tick_len(style: Style) -> i64 {
    4 * i64::from(style.g)
}

/// Width of the compass column beside a rotated map.
fn compass_size(style: Style) -> i64 {
    48 * i64::from(style.g)
}

/// The canvas direction (unit vector) of a world direction `d` on `layout`.
fn canvas_direction(layout: &MapLayout, d: (f64, f64)) -> (f32, f32) {
    let g = layout.geometry();
    let a = layout.world_to_px(g.origin);
    let b = layout.world_to_px(Point::new(g.origin.x + d.0, g.origin.y + d.1));
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let n = dx.hypot(dy).max(f32::MIN_POSITIVE);
    (dx / n, dy / n)
}

/// The compass: an arrow to the world's +y ("N +y") and a thinner one to +x.
fn draw_compass(canvas: &mut Canvas, style: Style, layout: &MapLayout, c: (f32, f32)) {
    let l = 15.0 * style.g as f32;
    for (d, label, colour, width) in [
        ((1.0, 0.0), "+x", palette::MUTED_TEXT, 1.0),
        ((0.0, 1.0), "N +y", palette::TEXT, 1.6),
    ] {
        let (ux, uy) = canvas_direction(layout, d);
        let tip = (c.0 + ux * l, c.1 + uy * l);
        let mut pb = PathBuilder::new();
        pb.move_to(c.0, c.1);
        pb.line_to(tip.0, tip.1);
        if let Some(path) = pb.finish() {
            canvas.stroke_path(&path, colour, 255, width * style.g as f32);
        }
        draw_arrowhead(canvas, style, tip, (ux, uy), colour);
        let tw = text_width(label, style.g) as f32;
        let th = text_height(style.g) as f32;
        let at = (
            c.0 + ux * (l + 8.0 * style.g as f32),
            c.1 + uy * (l + 7.0 * style.g as f32),
        );
        // Keep the text beside the tip and on the canvas.
        let x = (at.0 - tw / 2.0).clamp(0.0, (canvas.width() as f32 - tw).max(0.0));
        canvas.text(x as i64, (at.1 - th / 2.0) as i64, label, style.g, colour);
    }
}

/// Where the world origin lies on the map, if it does and is not so near the map's
/// edge that the axes' zero ticks already show it (and a mark would hide cells
/// there).
pub(crate) fn origin_on_map(layout: &MapLayout, style: Style) -> Option<(f32, f32)> {
    let (x, y) = layout.world_to_px(Point::new(0.0, 0.0));
    let r = layout.rect();
    let keep = 3.0 * origin_radius(style);
    let inner = Rect::new(r.x + keep, r.y + keep, r.w - 2.0 * keep, r.h - 2.0 * keep);
    let at = Rect::new(x, y, 0.0, 0.0);
    (x.is_finite() && y.is_finite() && inner.contains(&at)).then_some((x, y))
}

/// Radius of the origin mark.
pub(crate) fn origin_radius(style: Style) -> f32 {
    4.0 * style.g as f32
}

/// The world origin's mark: a ringed cross.
pub(crate) fn draw_origin(canvas: &mut Canvas, style: Style, (x, y): (f32, f32)) {
    let r = origin_radius(style);
    let mut pb = PathBuilder::new();
    pb.move_to(x - r * 1.6, y);
    pb.line_to(x + r * 1.6, y);
    pb.move_to(x, y - r * 1.6);
    pb.line_to(x, y + r * 1.6);
    if let Some(path) = pb.finish() {
        canvas.stroke_path(&path, Rgb::hex(0xffffff), 255, 3.0 * style.g as f32);
        canvas.stroke_path(&path, palette::TEXT, 255, 1.0 * style.g as f32);
    }
    if let Some(path) = PathBuilder::from_circle(x, y, r) {
        canvas.stroke_path(&path, palette::TEXT, 255, 1.0 * style.g as f32);
    }
}

#[cfg(test)]
mod tests {
    use cpsplan::GridGeometry;

    use super::*;

    #[test]
    fn tick_steps_are_round_metres() {
        assert_eq!(tick_step(0.001, 80.0), 1.0);
        assert_eq!(tick_step(1.0 / 30.0, 88.0), 5.0);
        assert_eq!(tick_step(0.05, 40.0), 2.0);
        assert_eq!(tick_step(0.1, 100.0), 10.0);
        assert_eq!(tick_step(f64::NAN, 10.0), 1.0);
    }

    #[test]
    fn ticks_sit_at_round_values_where_the_lines_cross() {
        // 40 × 30 m at 0.1 m, origin (-12.3, -4.2), 4 px per cell.
        let g = GridGeometry::new(400, 300, 0.1, Point::new(-12.3, -4.2));
        let layout = MapLayout::at_scale(&g, 4);
        let axes = Axes::of(&layout, Style { g: 2 });
        assert!(!axes.rotated);
        assert_eq!(axes.bottom.0, Coord::X);
        assert_eq!(axes.left.0, Coord::Y);
        let step = axes.step;
        assert!(
            step >= 1.0 && [1.0, 2.0, 5.0].contains(&(step / 10f64.powf(step.log10().floor())))
        );
        for (coord, ticks, horizontal) in [
            (axes.bottom.0, &axes.bottom.1, true),
            (axes.left.0, &axes.left.1, false),
        ] {
            assert!(ticks.len() >= 3, "{ticks:?}");
            for t in ticks {
                assert_eq!(t.value % step, 0.0, "{t:?}");
                assert_eq!(t.label, format_tick(t.value));
                let (x, y) = if horizontal {
                    (t.offset as f64, layout.height_px as f64)
                } else {
                    (0.0, layout.height_px as f64 - t.offset as f64)
                };
                let p = layout.px_to_world(x, y);
                assert!((coord.of(p) - t.value).abs() < 1e-3, "{t:?} at {p:?}");
            }
        }
        // The origin: x = 0 is 123 cells from the left edge.
        let zero = axes.bottom.1.iter().find(|t| t.value == 0.0).unwrap();
        assert!((zero.offset - 123.0 * 4.0).abs() < 1e-3);
        assert_eq!(zero.label, "0");
        let (ox, oy) = origin_on_map(&layout, Style { g: 2 }).unwrap();
        assert!((ox - 492.0).abs() < 1e-3 && (oy - (300.0 - 42.0) * 4.0).abs() < 1e-3);
    }

    #[test]
    fn a_half_turned_grid_counts_down_and_gets_a_compass() {
        let mut g = GridGeometry::new(200, 100, 0.1, Point::new(10.0, 5.0));
        g.yaw = std::f64::consts::PI;
        let layout = MapLayout::at_scale(&g, 8);
        let axes = Axes::of(&layout, Style { g: 2 });
        assert!(axes.rotated);
        assert_eq!(axes.bottom.0, Coord::X);
        let values: Vec<f64> = axes.bottom.1.iter().map(|t| t.value).collect();
        assert!(values.windows(2).all(|w| w[1] < w[0]), "{values:?}");
        assert!(axes.gutters(Style { g: 2 }).right > 0);
        // World +y points down the picture.
        let (ux, uy) = canvas_direction(&layout, (0.0, 1.0));
        assert!(ux.abs() < 1e-3 && (uy - 1.0).abs() < 1e-3);
    }

    #[test]
    fn a_quarter_turned_grid_shows_y_along_the_bottom() {
        let mut g = GridGeometry::new(200, 100, 0.1, Point::new(0.0, 0.0));
        g.yaw = std::f64::consts::FRAC_PI_2;
        let axes = Axes::of(&MapLayout::at_scale(&g, 8), Style { g: 2 });
        assert_eq!((axes.bottom.0, axes.left.0), (Coord::Y, Coord::X));
    }
}
