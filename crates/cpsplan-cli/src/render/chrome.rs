//! Everything around the map: the header strip (title, summary lines, legend), the
//! footer (scale bar, grid information), and the marks shared by the map and the
//! legend (scan markers, trajectory arrowheads).

use tiny_skia::PathBuilder;

use super::axes::draw_origin;
use super::canvas::{fit_text, text_height, text_width, Canvas, Rgb};
use super::marks::{
    draw_arrowhead, draw_cross, draw_ellipse, draw_marker, draw_ring, draw_square, draw_subgoal,
    ramp,
};
use super::palette;
use super::team::ChildLook;

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Swatch {
    /// A square of a map colour.
    Cell(Rgb),
    /// A short stroke with an arrowhead.
    Line(Rgb),
    /// A short thin dashed stroke.
    Dashed(Rgb),
    /// A scan marker.
    Dot(Rgb),
    /// A small marker (candidates that may not be chosen).
    SmallDot(Rgb),
    /// A square marker (viewpoint candidates).
    Square(Rgb),
    /// A marker of colour `.0` in a dark ring (the chosen target).
    Ring(Rgb),
    /// A marker of colour `.0` struck through (a rejected target).
    Cross(Rgb),
    /// A subgoal marker.
    Subgoal,
    /// An error ellipse.
    Ellipse(Rgb),
    /// A colour ramp, low to high, left to right.
    Ramp(&'static [Rgb]),
    /// A child's dashed path with its standing mark.
    Child(ChildLook),
    /// The world origin's mark.
    Origin,
    /// A target: filled (placed by the team) or hollow (given).
    Target(bool),
    /// A control point.
    Control,
    /// A thin translucent line (a station's measurement of a target).
    Thin(Rgb),
}

/// One legend entry.
#[derive(Debug, Clone)]
pub(crate) struct LegendItem<'a> {
    pub swatch: Swatch,
    pub label: &'a str,
}

/// Sizes derived from the text scale `g` (1 for small pictures, 2 for large).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Style {
    /// Glyph scale of body text.
    pub g: u32,
}

impl Style {
    /// Picks the text scale for a map drawn `longest_px` pixels along its longer side.
    pub fn for_map(longest_px: i64) -> Self {
        Self {
            g: if longest_px >= 1000 { 2 } else { 1 },
        }
    }

    fn gi(self) -> i64 {
        i64::from(self.g)
    }

    /// Outer margin of the picture.
    pub fn margin(self) -> i64 {
        8 * self.gi() + 4
    }

    /// Radius of a scan marker's coloured disc.
    pub fn marker_radius(self) -> f32 {
        if self.g >= 2 {
            6.5
        } else {
            4.5
        }
    }

    /// Width of the trajectory stroke.
    pub fn line_width(self) -> f32 {
        if self.g >= 2 {
            2.5
        } else {
            1.8
        }
    }

    fn legend_row_height(self) -> i64 {
        10 * self.gi() + 6
    }

    fn swatch_size(self) -> i64 {
        8 * self.gi() + 2
    }

    fn legend_item_width(self, item: &LegendItem<'_>) -> i64 {
        let swatch = match item.swatch {
            Swatch::Line(_) | Swatch::Dashed(_) | Swatch::Child(_) | Swatch::Thin(_) => {
                3 * self.swatch_size()
            }
            Swatch::Ramp(_) => 5 * self.swatch_size(),
            Swatch::Ring(_) | Swatch::Cross(_) => self.swatch_size() + 4 * self.gi(),
            _ => self.swatch_size(),
        };
        swatch + 4 * self.gi() + text_width(item.label, self.g)
    }

    fn legend_gap(self) -> i64 {
        12 * self.gi()
    }
}

/// The header strip: title, summary lines and legend.
pub(crate) struct Header<'a> {
    pub title: &'a str,
    pub lines: Vec<String>,
    pub legend: Vec<LegendItem<'a>>,
}

impl Header<'_> {
    /// The legend flowed into rows that fit `avail` pixels: item indices per row.
    fn legend_rows(&self, style: Style, avail: i64) -> Vec<Vec<usize>> {
        let mut rows: Vec<Vec<usize>> = Vec::new();
        let mut used = 0;
        for (i, item) in self.legend.iter().enumerate() {
            let w = style.legend_item_width(item);
            match rows.last_mut() {
                Some(row) if used + style.legend_gap() + w <= avail => {
                    row.push(i);
                    used += style.legend_gap() + w;
                }
                _ => {
                    rows.push(vec![i]);
                    used = w;
                }
            }
        }
        rows
    }

    /// Height of the strip on a canvas `width` pixels wide.
    pub fn height(&self, style: Style, width: i64) -> i64 {
        let m = style.margin();
        let g = style.gi();
        let mut h = m + text_height(style.g + 1);
        h += self.lines.len() as i64 * (5 * g + text_height(style.g));
        let rows = self.legend_rows(style, width - 2 * m).len() as i64;
        if rows > 0 {
            h += 4 * g + rows * style.legend_row_height();
        }
        h + m
    }

    /// The widest line of the strip, pixels (title excluded: it is shortened to fit).
    pub fn min_width(&self, style: Style) -> i64 {
        let lines = self
            .lines
            .iter()
            .map(|l| text_width(l, style.g))
            .max()
            .unwrap_or(0);
        let legend = self
            .legend
            .iter()
            .map(|i| style.legend_item_width(i))
            .max()
            .unwrap_or(0);
        lines.max(legend) + 2 * style.margin()
    }

    /// Draws the strip at the top of the canvas; returns its height.
    pub fn draw(&self, canvas: &mut Canvas, style: Style) -> i64 {
        let width = canvas.width();
        let m = style.margin();
        let g = style.gi();
        let title = fit_text(self.title, style.g + 1, width - 2 * m);
        let mut y = m;
        canvas.text(m, y, &title, style.g + 1, palette::TEXT);
        y += text_height(style.g + 1);
        for line in &self.lines {
            y += 5 * g;
            let line = fit_text(line, style.g, width - 2 * m);
            canvas.text(m, y, &line, style.g, palette::MUTED_TEXT);
            y += text_height(style.g);
        }
        let rows = self.legend_rows(style, width - 2 * m);
        if !rows.is_empty() {
            y += 4 * g;
        }
        let row_h = style.legend_row_height();
        for row in rows {
            let mut x = m;
            let cy = y + row_h / 2;
            for i in row {
                let item = &self.legend[i];
                x += draw_swatch(canvas, style, item.swatch, x, cy);
                x += 4 * g;
                let ty = cy - text_height(style.g) / 2;
                canvas.text(x, ty, item.label, style.g, palette::TEXT);
                x += text_width(item.label, style.g) + style.legend_gap();
            }
            y += row_h;
        }
        let h = self.height(style, width);
        canvas.fill_rect(0, h - 1, width, 1, palette::RULE);
        h
    }
}

/// A legend swatch's horizontal stroke, `w` pixels wide from `x`, on row `cy`.
fn swatch_stroke(x: i64, w: i64, cy: i64) -> Option<tiny_skia::Path> {
    let mut pb = PathBuilder::new();
    pb.move_to(x as f32 + 1.0, cy as f32);
    pb.line_to((x + w) as f32 - 1.0, cy as f32);
    pb.finish()
}

/// Draws a legend swatch with its left edge at `x`, centred on row `cy`; returns its width.
fn draw_swatch(canvas: &mut Canvas, style: Style, swatch: Swatch, x: i64, cy: i64) -> i64 {
    let s = style.swatch_size();
    match swatch {
        Swatch::Cell(c) => {
            let y = cy - s / 2;
            canvas.fill_rect(x, y, s, s, c);
            canvas.outline_rect(x, y, s, s, palette::SWATCH_EDGE);
            s
        }
        Swatch::Line(c) => {
            let w = 3 * s;
            let (x0, x1, yc) = (x as f32 + 2.0, (x + w) as f32 - 2.0, cy as f32);
            let mut pb = PathBuilder::new();
            pb.move_to(x0, yc);
            pb.line_to(x1, yc);
            if let Some(path) = pb.finish() {
                canvas.stroke_path(&path, c, 255, style.line_width());
            }
            draw_arrowhead(canvas, style, ((x0 + x1) / 2.0 + 4.0, yc), (1.0, 0.0), c);
            w
        }
        Swatch::Dashed(c) => {
            let w = 3 * s;
            if let Some(path) = swatch_stroke(x, w, cy) {
                canvas.stroke_dashed(&path, c, 255, 1.5, 5.0 * style.g as f32);
            }
            w
        }
        Swatch::Dot(c) => {
            let r = style.marker_radius();
            draw_marker(canvas, x as f32 + s as f32 / 2.0, cy as f32, r, c);
            s
        }
        Swatch::Square(c) => {
            let r = style.marker_radius() * 0.85;
            draw_square(canvas, x as f32 + s as f32 / 2.0, cy as f32, r, c);
            s
        }
        Swatch::SmallDot(c) => {
            let r = style.marker_radius() * 0.6;
            draw_marker(canvas, x as f32 + s as f32 / 2.0, cy as f32, r, c);
            s
        }
        Swatch::Ring(c) => {
            let w = s + 4 * style.gi();
            let (mx, my) = (x as f32 + w as f32 / 2.0, cy as f32);
            let r = style.marker_radius();
            draw_marker(canvas, mx, my, r, c);
            draw_ring(canvas, style, mx, my, r);
            w
        }
        Swatch::Cross(c) => {
            let w = s + 4 * style.gi();
            let (mx, my) = (x as f32 + w as f32 / 2.0, cy as f32);
            let r = style.marker_radius();
            draw_marker(canvas, mx, my, r, c);
            draw_cross(canvas, style, mx, my, r);
            w
        }
        Swatch::Subgoal => {
            draw_subgoal(canvas, style, x as f32 + s as f32 / 2.0, cy as f32);
            s
        }
        Swatch::Ellipse(c) => {
            let w = 2 * s;
            draw_ellipse(
                canvas,
                style,
                (x as f32 + w as f32 / 2.0, cy as f32),
                (w as f32 / 2.0 - 1.0, s as f32 / 3.0),
                0.3,
                c,
            );
            w
        }
        Swatch::Child(look) => {
            let w = 3 * s;
            if let Some(path) = swatch_stroke(x, w, cy) {
                look.stroke(canvas, style, &path);
            }
            look.draw_mark(canvas, style, x as f32 + w as f32 / 2.0, cy as f32);
            w
        }
        Swatch::Origin => {
            draw_origin(canvas, style, (x as f32 + s as f32 / 2.0, cy as f32));
            s
        }
        Swatch::Target(filled) => {
            let r = style.marker_radius();
            super::targets::draw_target(
                canvas,
                style,
                x as f32 + s as f32 / 2.0,
                cy as f32,
                r,
                filled,
            );
            s
        }
        Swatch::Thin(c) => {
            let w = 3 * s;
            if let Some(path) = swatch_stroke(x, w, cy) {
                canvas.stroke_path(&path, c, 160, 0.8 * style.line_width());
            }
            w
        }
        Swatch::Control => {
            let r = style.marker_radius();
            super::targets::draw_control(canvas, style, x as f32 + s as f32 / 2.0, cy as f32, r);
            s
        }
        Swatch::Ramp(stops) => {
            let w = 5 * s;
            let h = s * 3 / 4;
            let y = cy - h / 2;
            for i in 0..w {
                let t = i as f64 / (w - 1).max(1) as f64;
                canvas.fill_rect(x + i, y, 1, h, ramp(stops, t));
            }
            canvas.outline_rect(x, y, w, h, palette::SWATCH_EDGE);
            w
        }
    }
}

/// The footer: a scale bar bottom left and grid information bottom right.
pub(crate) struct Footer {
    /// Metres per pixel of the map.
    pub metres_per_px: f64,
    /// Map width in pixels.
    pub map_width_px: i64,
    /// Right-aligned information text.
    pub info: String,
}

impl Footer {
    /// Height of the footer.
    pub fn height(&self, style: Style) -> i64 {
        let g = style.gi();
        4 * g + text_height(style.g) + 3 * g + 4 * g + style.margin()
    }

    /// Draws the footer with its top at `y`, its left edge aligned with the map at `x0`.
    pub fn draw(&self, canvas: &mut Canvas, style: Style, x0: i64, y: i64) {
        let g = style.gi();
        let width = canvas.width();
        let m = style.margin();
        let text_y = y + 4 * g;
        let bar_y = text_y + text_height(style.g) + 3 * g;
        let bar_h = 4 * g;
        let mut bar_end = x0;
        if let Some((metres, segments)) = scale_bar_length(self.metres_per_px, self.map_width_px) {
            let len = (metres / self.metres_per_px).round() as i64;
            // Alternating dark and white segments in a dark frame.
            canvas.fill_rect(x0, bar_y, len + 1, bar_h, palette::OCCUPIED);
            for k in 0..segments {
                if k % 2 == 1 {
                    let a = x0 + 1 + len * k / segments;
                    let b = x0 + len * (k + 1) / segments;
                    canvas.fill_rect(a, bar_y + 1, b - a, bar_h - 2, Rgb::hex(0xffffff));
                }
            }
            canvas.text(x0, text_y, "0", style.g, palette::TEXT);
            let label = format_metres(metres);
            let lw = text_width(&label, style.g);
            canvas.text(
                x0 + len - lw / 2 + g,
                text_y,
                &label,
                style.g,
                palette::TEXT,
            );
            bar_end = x0 + len + lw / 2 + g;
        }
        let info_w = text_width(&self.info, style.g);
        let right = (x0 + self.map_width_px)
            .min(width - m)
            .max(bar_end + 4 * g + info_w);
        if right <= width {
            let ty = text_y + (bar_y + bar_h - text_y - text_height(style.g)) / 2;
            canvas.text(right - info_w, ty, &self.info, style.g, palette::MUTED_TEXT);
        }
    }
}

/// A round scale-bar length (1, 2 or 5 × 10^k metres) near 15 % of the map width,
/// with its number of segments; `None` for degenerate scales.
pub(crate) fn scale_bar_length(metres_per_px: f64, map_width_px: i64) -> Option<(f64, i64)> {
    let target = 0.15 * metres_per_px * map_width_px as f64;
    if !(target.is_finite() && target > 0.0) {
        return None;
    }
    let decade = 10f64.powf(target.log10().floor());
    let (metres, segments) = [(1.0, 5), (2.0, 4), (5.0, 5), (10.0, 5)]
        .into_iter()
        .map(|(f, s)| (f * decade, s))
        .min_by(|a, b| {
            let da = (a.0 / target).ln().abs();
            let db = (b.0 / target).ln().abs();
            da.total_cmp(&db)
        })?;
    (metres / metres_per_px >= 8.0).then_some((metres, segments))
}

/// "10 m", "2.5 m", "500 m", "0.5 m", "2 km".
fn format_metres(m: f64) -> String {
    if m >= 1000.0 {
        format!("{} km", trim(m / 1000.0))
    } else {
        format!("{} m", trim(m))
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_bar_is_round_and_near_fifteen_percent() {
        // 80 m drawn over 1600 px.
        let (m, _) = scale_bar_length(0.05, 1600).unwrap();
        assert_eq!(m, 10.0);
        let (m, _) = scale_bar_length(0.1 / 13.0, 1560).unwrap();
        assert_eq!(m, 2.0);
        assert!(scale_bar_length(0.0, 100).is_none());
        assert!(scale_bar_length(f64::NAN, 100).is_none());
    }

    #[test]
    fn metres_are_formatted_plainly() {
        assert_eq!(format_metres(10.0), "10 m");
        assert_eq!(format_metres(0.5), "0.5 m");
        assert_eq!(format_metres(2000.0), "2 km");
    }
}
