//! The marks drawn on maps: markers, the target's ring, the cross of a rejected
//! target, subgoal diamonds, arrows along paths, and the colour ramp of scores.

use tiny_skia::PathBuilder;

use super::canvas::{Canvas, Rgb};
use super::chrome::Style;
use super::palette;

/// The colour at `t` in [0, 1] along a ramp of evenly spaced `stops` (linear
/// interpolation in sRGB; `t` is clamped, NaN gives the first stop).
pub(crate) fn ramp(stops: &[Rgb], t: f64) -> Rgb {
    let Some(&first) = stops.first() else {
        return palette::TEXT;
    };
    if stops.len() == 1 || t.is_nan() {
        return first;
    }
    let x = t.clamp(0.0, 1.0) * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    let (a, b) = (stops[i], stops[i + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + (f64::from(q) - f64::from(p)) * f).round() as u8;
    Rgb(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The dark ring around the chosen target's marker of radius `r`.
pub(crate) fn draw_ring(canvas: &mut Canvas, style: Style, cx: f32, cy: f32, r: f32) {
    if let Some(path) = PathBuilder::from_circle(cx, cy, r + 2.5 + style.line_width()) {
        canvas.stroke_path(&path, Rgb::hex(0xffffff), 255, style.line_width() + 2.0);
        canvas.stroke_path(&path, palette::TEXT, 255, style.line_width());
    }
}

/// A cross over a marker of radius `r` (a rejected target).
pub(crate) fn draw_cross(canvas: &mut Canvas, style: Style, cx: f32, cy: f32, r: f32) {
    let d = r + 2.5;
    let mut pb = PathBuilder::new();
    pb.move_to(cx - d, cy - d);
    pb.line_to(cx + d, cy + d);
    pb.move_to(cx - d, cy + d);
    pb.line_to(cx + d, cy - d);
    if let Some(path) = pb.finish() {
        canvas.stroke_path(&path, Rgb::hex(0xffffff), 255, style.line_width() + 2.0);
        canvas.stroke_path(&path, palette::REJECTED, 255, style.line_width());
    }
}

/// Half the width of a subgoal marker.
pub(crate) fn subgoal_radius(style: Style) -> f32 {
    style.marker_radius()
}

/// A subgoal marker: a diamond with a white rim.
pub(crate) fn draw_subgoal(canvas: &mut Canvas, style: Style, cx: f32, cy: f32) {
    let diamond = |r: f32| {
        let mut pb = PathBuilder::new();
        pb.move_to(cx, cy - r);
        pb.line_to(cx + r, cy);
        pb.line_to(cx, cy + r);
        pb.line_to(cx - r, cy);
        pb.close();
        pb.finish()
    };
    let r = subgoal_radius(style);
    if let Some(path) = diamond(r + 3.2) {
        canvas.fill_path(&path, palette::OCCUPIED, 110);
    }
    if let Some(path) = diamond(r + 2.2) {
        canvas.fill_path(&path, Rgb::hex(0xffffff), 255);
    }
    if let Some(path) = diamond(r) {
        canvas.fill_path(&path, palette::SUBGOAL, 255);
    }
}

/// A scan marker: a disc of colour `c` and radius `r` with a white rim and a faint
/// dark outline, so it stands out on white, grey and black alike.
pub(crate) fn draw_marker(canvas: &mut Canvas, cx: f32, cy: f32, r: f32, c: Rgb) {
    canvas.fill_circle(cx, cy, r + 2.5, palette::OCCUPIED, 110);
    canvas.fill_circle(cx, cy, r + 1.75, Rgb::hex(0xffffff), 255);
    canvas.fill_circle(cx, cy, r, c, 255);
}

/// A viewpoint candidate's marker: a square of colour `c` and half-width `r`
/// with the scan marker's white rim and faint outline.
pub(crate) fn draw_square(canvas: &mut Canvas, cx: f32, cy: f32, r: f32, c: Rgb) {
    for (grow, colour, alpha) in [
        (2.5, palette::OCCUPIED, 110),
        (1.75, Rgb::hex(0xffffff), 255),
        (0.0, c, 255),
    ] {
        let h = r + grow;
        if let Some(rect) = tiny_skia::Rect::from_xywh(cx - h, cy - h, 2.0 * h, 2.0 * h) {
            canvas.fill_path(&PathBuilder::from_rect(rect), colour, alpha);
        }
    }
}

/// A filled arrowhead centred at `at`, pointing along the unit vector `dir`.
pub(crate) fn draw_arrowhead(
    canvas: &mut Canvas,
    style: Style,
    at: (f32, f32),
    dir: (f32, f32),
    c: Rgb,
) {
    let len = 3.2 * style.line_width();
    let half = 2.0 * style.line_width();
    let (dx, dy) = dir;
    let (px, py) = (-dy, dx);
    let tip = (at.0 + dx * len * 0.6, at.1 + dy * len * 0.6);
    let back = (at.0 - dx * len * 0.4, at.1 - dy * len * 0.4);
    let mut pb = PathBuilder::new();
    pb.move_to(tip.0, tip.1);
    pb.line_to(back.0 + px * half, back.1 + py * half);
    pb.line_to(back.0 + dx * len * 0.15, back.1 + dy * len * 0.15);
    pb.line_to(back.0 - px * half, back.1 - py * half);
    pb.close();
    if let Some(path) = pb.finish() {
        canvas.stroke_path(&path, Rgb::hex(0xffffff), 200, 1.5);
        canvas.fill_path(&path, c, 255);
    }
}

/// An arrowhead of colour `c` halfway along the polyline `leg` (canvas pixels), if
/// the leg is long enough to carry one.
pub(crate) fn draw_arrow_midway(canvas: &mut Canvas, style: Style, leg: &[(f32, f32)], c: Rgb) {
    let lw = style.line_width();
    let seg_len = |w: &[(f32, f32)]| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1);
    let total: f32 = leg.windows(2).map(seg_len).sum();
    if total.is_nan() || total < 16.0 * lw {
        return;
    }
    let mut rest = total / 2.0;
    for w in leg.windows(2) {
        let l = seg_len(w);
        if l <= 0.0 {
            continue;
        }
        if rest <= l {
            let (dx, dy) = ((w[1].0 - w[0].0) / l, (w[1].1 - w[0].1) / l);
            let at = (w[0].0 + dx * rest, w[0].1 + dy * rest);
            draw_arrowhead(canvas, style, at, (dx, dy), c);
            return;
        }
        rest -= l;
    }
}

/// An error ellipse centred at `c` with semi-axes `axes` (pixels) and the major
/// axis at `angle` radians from the canvas x axis (counter-clockwise on the map):
/// a light fill and a thin outline.
pub(crate) fn draw_ellipse(
    canvas: &mut Canvas,
    style: Style,
    c: (f32, f32),
    axes: (f32, f32),
    angle: f32,
    colour: Rgb,
) {
    let (a, b) = (axes.0.max(0.75), axes.1.max(0.75));
    let (s, co) = angle.sin_cos();
    let mut pb = PathBuilder::new();
    for k in 0..=48 {
        let t = k as f32 / 48.0 * std::f32::consts::TAU;
        let (ex, ey) = (a * t.cos(), b * t.sin());
        // The map's y axis points up, the canvas's down.
        let (px, py) = (c.0 + ex * co - ey * s, c.1 - (ex * s + ey * co));
        if k == 0 {
            pb.move_to(px, py);
        } else {
            pb.line_to(px, py);
        }
    }
    pb.close();
    if let Some(path) = pb.finish() {
        canvas.fill_path(&path, colour, 60);
        canvas.stroke_path(&path, colour, 255, (style.line_width() * 0.5).max(1.0));
    }
}
