//! Line charts of per-scan figures (the predicted positioning error against the
//! scan number), drawn once through a small surface trait onto a PNG canvas or
//! into SVG text, so that both files show the same picture.

use std::fmt::Write as _;

use tiny_skia::PathBuilder;

use super::canvas::{text_width, Canvas, Rgb};
use super::palette;
use super::RenderError;
use crate::html::escape;

/// Colours for the series of a chart, in order (Tableau 10).
pub const SERIES_COLOURS: [(u8, u8, u8); 10] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

/// One series of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)`, in order of `x`.
    pub points: Vec<(f64, f64)>,
    /// Line colour.
    pub colour: (u8, u8, u8),
    /// Dashed line.
    pub dashed: bool,
    /// A band drawn under the line, `(x, low, high)` in order of `x` (the spread
    /// over seeds; empty: none).
    pub band: Vec<(f64, f64, f64)>,
}

/// A line chart.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Title line.
    pub title: String,
    /// Second line under the title.
    pub subtitle: String,
    /// The x axis label.
    pub x_label: String,
    /// The y axis label.
    pub y_label: String,
    /// The series.
    pub series: Vec<Series>,
}

/// What a chart is drawn on.
trait Surface {
    fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, c: Rgb);
    fn polyline(&mut self, points: &[(f64, f64)], c: Rgb, width: f64, dashed: bool);
    /// A filled polygon, `alpha` of 255 opaque.
    fn polygon(&mut self, points: &[(f64, f64)], c: Rgb, alpha: u8);
    /// `anchor`: 0 left, 1 centre, 2 right; `y` is the text's top.
    fn text(&mut self, x: f64, y: f64, text: &str, size: u32, c: Rgb, anchor: u8);
}

const WIDTH: f64 = 1200.0;
const HEIGHT: f64 = 720.0;
/// Glyph scale of body text (8-pixel glyphs).
const TEXT: u32 = 2;
/// Height of a row of the legend.
const LEGEND_ROW: f64 = 28.0;
/// Height of a line of the subtitle (one per line of [`Chart::subtitle`]).
const SUBTITLE_ROW: f64 = 24.0;

/// A small percentage with two significant digits at least (`0.0346`,
/// `0.000036`).
pub fn percent(p: f64) -> String {
    if !(p.is_finite() && p > 0.0) || p >= 1e-3 {
        return format!("{p:.4}");
    }
    let digits = (1.0 - p.log10().floor()) as usize;
    format!("{p:.digits$}")
}

/// A share in 0–1 as a percentage with one decimal that never rounds to a
/// whole it has not reached: 0.9997 is "99.9", not "100.0"; 0.0004 is "0.1",
/// not "0.0" (only 0 and 1 print as "0.0" and "100.0").
pub fn share_percent(share: f64) -> String {
    let p = 100.0 * share;
    let shown = (p * 10.0).round() / 10.0;
    let shown = if shown >= 100.0 && share < 1.0 {
        99.9
    } else if shown <= 0.0 && share > 0.0 {
        0.1
    } else {
        shown
    };
    format!("{shown:.1}")
}

/// "Nice" tick values covering `lo..hi`: about `n` steps of 1, 2 or 5 × 10^k.
fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() * step;
    let mut out = Vec::new();
    let mut v = first;
    while v <= hi + 1e-9 * step && out.len() < 50 {
        out.push(if v.abs() < 1e-12 * step { 0.0 } else { v });
        v += step;
    }
    out
}

fn label(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

impl Chart {
    fn draw(&self, s: &mut impl Surface) {
        let white = Rgb::hex(0xffffff);
        s.rect(0.0, 0.0, WIDTH, HEIGHT, white);
        s.text(40.0, 20.0, &self.title, 3, palette::TEXT, 0);
        let lines: Vec<&str> = self.subtitle.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            s.text(
                40.0,
                56.0 + SUBTITLE_ROW * i as f64,
                line,
                TEXT,
                palette::MUTED_TEXT,
                0,
            );
        }
        // Legend entries in rows under the subtitle, as many to a row as fit.
        let mut legend = Vec::with_capacity(self.series.len());
        let extra = SUBTITLE_ROW * lines.len().saturating_sub(1) as f64;
        let (mut lx, mut ly) = (40.0, 96.0 + extra);
        for series in &self.series {
            let w = 80.0 + text_width(&series.label, TEXT) as f64;
            if lx > 40.0 && lx + w - 36.0 > WIDTH - 40.0 {
                (lx, ly) = (40.0, ly + LEGEND_ROW);
            }
            legend.push((lx, ly));
            lx += w;
        }
        let (x0, y0, x1, y1) = (110.0, ly + 54.0, WIDTH - 40.0, HEIGHT - 90.0);
        let all: Vec<(f64, f64)> = self
            .series
            .iter()
            .flat_map(|s| {
                let band = s.band.iter().flat_map(|&(x, lo, hi)| [(x, lo), (x, hi)]);
                s.points.iter().copied().chain(band)
            })
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        let (mut xl, mut xh) = all
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.0), b.max(p.0))
            });
        let mut yh = all.iter().fold(0.0f64, |a, p| a.max(p.1));
        if xl.is_nan() || xh.is_nan() || xl >= xh {
            xl = 0.0;
            xh = xl + 1.0;
        }
        if yh.is_nan() || yh <= 0.0 {
            yh = 1.0;
        }
        let yticks = ticks(0.0, yh * 1.05, 6);
        let ytop = yticks.last().copied().unwrap_or(yh).max(yh);
        let px = |x: f64| x0 + (x - xl) / (xh - xl) * (x1 - x0);
        let py = |y: f64| y1 - y / ytop * (y1 - y0);
        for &t in &yticks {
            s.polyline(&[(x0, py(t)), (x1, py(t))], palette::RULE, 1.0, false);
            s.text(
                x0 - 12.0,
                py(t) - 8.0,
                &label(t),
                TEXT,
                palette::MUTED_TEXT,
                2,
            );
        }
        // An axis of whole numbers (scans) is marked at whole numbers only.
        let whole = all.iter().all(|p| p.0.fract() == 0.0);
        for t in ticks(xl, xh, 10)
            .into_iter()
            .filter(|t| !whole || t.fract() == 0.0)
        {
            s.polyline(
                &[(px(t), y1), (px(t), y1 + 8.0)],
                palette::MUTED_TEXT,
                1.0,
                false,
            );
            s.text(px(t), y1 + 14.0, &label(t), TEXT, palette::MUTED_TEXT, 1);
        }
        s.polyline(&[(x0, y0), (x0, y1), (x1, y1)], palette::TEXT, 1.5, false);
        s.text(
            (x0 + x1) / 2.0,
            HEIGHT - 44.0,
            &self.x_label,
            TEXT,
            palette::TEXT,
            1,
        );
        s.text(x0 - 70.0, y0 - 34.0, &self.y_label, TEXT, palette::TEXT, 0);
        for series in &self.series {
            let c = Rgb(series.colour.0, series.colour.1, series.colour.2);
            let finite = |&&(x, lo, hi): &&(f64, f64, f64)| {
                x.is_finite() && lo.is_finite() && hi.is_finite()
            };
            let band: Vec<&(f64, f64, f64)> = series.band.iter().filter(finite).collect();
            if band.len() >= 2 {
                let outline: Vec<(f64, f64)> = band
                    .iter()
                    .map(|&&(x, _, hi)| (px(x), py(hi)))
                    .chain(band.iter().rev().map(|&&(x, lo, _)| (px(x), py(lo))))
                    .collect();
                // Fainter the more bands overlap.
                let alpha = if self.series.len() <= 3 { 48 } else { 24 };
                s.polygon(&outline, c, alpha);
            }
        }
        for (series, &(lx, ly)) in self.series.iter().zip(&legend) {
            let c = Rgb(series.colour.0, series.colour.1, series.colour.2);
            let pts: Vec<(f64, f64)> = series
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .map(|&(x, y)| (px(x), py(y)))
                .collect();
            s.polyline(&pts, c, 3.0, series.dashed);
            s.polyline(&[(lx, ly), (lx + 36.0, ly)], c, 3.0, series.dashed);
            s.text(lx + 44.0, ly - 8.0, &series.label, TEXT, palette::TEXT, 0);
        }
    }

    /// The chart as PNG.
    pub fn png(&self) -> Result<Vec<u8>, RenderError> {
        let mut canvas = Canvas::new(WIDTH as u32, HEIGHT as u32)?;
        self.draw(&mut canvas);
        canvas.encode()
    }

    /// The chart as an SVG document.
    pub fn svg(&self) -> String {
        let mut svg = Svg(String::new());
        let _ = writeln!(
            svg.0,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" \
             viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"DejaVu Sans Mono, monospace\">"
        );
        self.draw(&mut svg);
        svg.0.push_str("</svg>\n");
        svg.0
    }
}

/// The path through `points`, closed if `close`; `None` for fewer than two.
fn path_through(points: &[(f64, f64)], close: bool) -> Option<tiny_skia::Path> {
    let (first, rest) = points.split_first()?;
    let mut pb = PathBuilder::new();
    pb.move_to(first.0 as f32, first.1 as f32);
    for p in rest {
        pb.line_to(p.0 as f32, p.1 as f32);
    }
    if close {
        pb.close();
    }
    pb.finish()
}

impl Surface for Canvas {
    fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, c: Rgb) {
        self.fill_rect(x as i64, y as i64, w as i64, h as i64, c);
    }

    fn polyline(&mut self, points: &[(f64, f64)], c: Rgb, width: f64, dashed: bool) {
        if let Some(path) = path_through(points, false) {
            if dashed {
                self.stroke_dashed(&path, c, 255, width as f32, 10.0);
            } else {
                self.stroke_path(&path, c, 255, width as f32);
            }
        }
    }

    fn polygon(&mut self, points: &[(f64, f64)], c: Rgb, alpha: u8) {
        if let Some(path) = path_through(points, true) {
            self.fill_path(&path, c, alpha);
        }
    }

    fn text(&mut self, x: f64, y: f64, text: &str, size: u32, c: Rgb, anchor: u8) {
        let w = text_width(text, size);
        let x = match anchor {
            1 => x as i64 - w / 2,
            2 => x as i64 - w,
            _ => x as i64,
        };
        Canvas::text(self, x, y as i64, text, size, c);
    }
}

/// An SVG document being written.
struct Svg(String);

impl Surface for Svg {
    fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, c: Rgb) {
        let _ = writeln!(
            self.0,
            "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{w:.1}\" height=\"{h:.1}\" fill=\"{}\"/>",
            c.css()
        );
    }

    fn polyline(&mut self, points: &[(f64, f64)], c: Rgb, width: f64, dashed: bool) {
        if points.len() < 2 {
            return;
        }
        let pts: Vec<String> = points
            .iter()
            .map(|p| format!("{:.1},{:.1}", p.0, p.1))
            .collect();
        let dash = if dashed {
            " stroke-dasharray=\"10 10\""
        } else {
            ""
        };
        let _ = writeln!(
            self.0,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{width}\" \
             stroke-linejoin=\"round\"{dash}/>",
            pts.join(" "),
            c.css()
        );
    }

    fn polygon(&mut self, points: &[(f64, f64)], c: Rgb, alpha: u8) {
        if points.len() < 3 {
            return;
        }
        let pts: Vec<String> = points
            .iter()
            .map(|p| format!("{:.1},{:.1}", p.0, p.1))
            .collect();
        let _ = writeln!(
            self.0,
            "<polygon points=\"{}\" fill=\"{}\" fill-opacity=\"{:.3}\" stroke=\"none\"/>",
            pts.join(" "),
            c.css(),
            f64::from(alpha) / 255.0
        );
    }

    fn text(&mut self, x: f64, y: f64, text: &str, size: u32, c: Rgb, anchor: u8) {
        let anchor = ["start", "middle", "end"][usize::from(anchor.min(2))];
        // Bitmap glyphs are 8 px tall at scale 1; the baseline sits near 7/8.
        let px = 8 * size;
        let _ = writeln!(
            self.0,
            "<text x=\"{x:.1}\" y=\"{:.1}\" font-size=\"{px}\" fill=\"{}\" text-anchor=\"{anchor}\">{}</text>",
            y + 0.85 * px as f64,
            c.css(),
            escape(text)
        );
    }
}

/// The chart of an episode's positioning error against the scan number: the
/// predicted radial 1σ of every scan position and, when run, the Monte Carlo mean
/// error; `None` without predictions (fewer than two children).
pub fn error_chart(episode: &cpsplan::Episode, title: &str) -> Option<Chart> {
    let predicted: Vec<(f64, f64)> = episode
        .steps
        .iter()
        .filter_map(|s| s.position_sigma_m.map(|v| (s.scan as f64, v * 1e3)))
        .collect();
    if predicted.len() < 2 {
        return None;
    }
    let mut series = vec![Series {
        label: "predicted 1\u{3c3} when scanned (filtering)".into(),
        points: predicted,
        colour: (0x6a, 0x3d, 0x9a),
        dashed: false,
        band: Vec::new(),
    }];
    let per_scan = |f: fn(&cpsplan::mission::Step) -> Option<f64>| -> Vec<(f64, f64)> {
        episode
            .steps
            .iter()
            .filter_map(|s| f(s).map(|v| (s.scan as f64, v * 1e3)))
            .collect()
    };
    let smoothed = per_scan(|s| s.smoothed_sigma_m);
    if !smoothed.is_empty() {
        series.push(Series {
            label: "predicted 1\u{3c3} after the whole network (smoothed)".into(),
            points: smoothed,
            colour: (
                palette::SMOOTHED.0,
                palette::SMOOTHED.1,
                palette::SMOOTHED.2,
            ),
            dashed: false,
            band: Vec::new(),
        });
    }
    let mc = per_scan(|s| s.monte_carlo_error_m);
    let s = &episode.summary;
    if !mc.is_empty() {
        series.push(Series {
            label: format!("Monte Carlo mean error ({} runs)", s.monte_carlo_runs),
            points: mc,
            colour: (0xd6, 0x27, 0x28),
            dashed: true,
            band: Vec::new(),
        });
    }
    let mc_smoothed = per_scan(|s| s.smoothed_monte_carlo_error_m);
    if !mc_smoothed.is_empty() {
        series.push(Series {
            label: "Monte Carlo mean error, smoothed".into(),
            points: mc_smoothed,
            colour: (0x66, 0xa6, 0x1e),
            dashed: true,
            band: Vec::new(),
        });
    }
    if let (Some(max), Some(first), Some(last)) = (
        episode.config.mission.max_sigma_m,
        episode.steps.first(),
        episode.steps.last(),
    ) {
        series.push(Series {
            label: format!("tolerance {:.1} mm", max * 1e3),
            points: vec![
                (first.scan as f64, max * 1e3),
                (last.scan as f64, max * 1e3),
            ],
            colour: (0x7f, 0x7f, 0x7f),
            dashed: true,
            band: Vec::new(),
        });
    }
    let c = &episode.config.children;
    let mut subtitle = format!(
        "{} \u{b7} strategy {} \u{b7} final {:.1} mm after {:.0} m \u{b7} {} % of travel",
        s.instrument,
        c.strategy.name(),
        s.final_position_sigma_m.unwrap_or(f64::NAN) * 1e3,
        s.parent_travel_m,
        percent(s.error_percent_of_travel.unwrap_or(f64::NAN))
    );
    if let (Some(w), Some(ws)) = (s.worst_position_sigma_m, s.worst_smoothed_sigma_m) {
        subtitle.push_str(&format!(
            "\nworst scan {:.1} mm when scanned, {:.1} mm smoothed",
            w * 1e3,
            ws * 1e3
        ));
        if !episode.targets.is_empty() {
            subtitle.push_str(&format!(
                " \u{b7} {} target{}, {} closures",
                episode.targets.len(),
                if episode.targets.len() == 1 { "" } else { "s" },
                s.closures
            ));
        }
    }
    Some(Chart {
        title: title.to_string(),
        subtitle,
        x_label: "scan".into(),
        y_label: "position error of the scan, mm".into(),
        series,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_never_round_to_a_whole_they_did_not_reach() {
        assert_eq!(share_percent(0.9997), "99.9");
        assert_eq!(share_percent(1.0), "100.0");
        assert_eq!(share_percent(0.0004), "0.1");
        assert_eq!(share_percent(0.0), "0.0");
        assert_eq!(share_percent(0.4567), "45.7");
    }

    fn chart() -> Chart {
        Chart {
            title: "error <test> & more".into(),
            subtitle: "sub".into(),
            x_label: "scan".into(),
            y_label: "mm".into(),
            series: vec![Series {
                label: "predicted".into(),
                points: (1..=10).map(|i| (i as f64, (i as f64).sqrt())).collect(),
                colour: (31, 119, 180),
                dashed: false,
                band: Vec::new(),
            }],
        }
    }

    #[test]
    fn small_percentages_keep_two_significant_digits() {
        assert_eq!(percent(0.0346), "0.0346");
        assert_eq!(percent(0.0085), "0.0085");
        assert_eq!(percent(0.000036), "0.000036");
        assert_eq!(percent(0.00012), "0.00012");
        assert_eq!(percent(0.0), "0.0000");
    }

    #[test]
    fn png_and_svg_are_well_formed() {
        let png = chart().png().unwrap();
        let pic = tiny_skia::Pixmap::decode_png(&png).unwrap();
        assert_eq!((pic.width(), pic.height()), (1200, 720));
        let svg = chart().svg();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("&lt;test&gt; &amp; more"));
        assert!(svg.contains("<polyline"));
    }

    /// Where a drawing put its texts.
    #[derive(Default)]
    struct Texts(Vec<(f64, f64, String, u32, u8)>);

    impl Surface for Texts {
        fn rect(&mut self, _: f64, _: f64, _: f64, _: f64, _: Rgb) {}
        fn polyline(&mut self, _: &[(f64, f64)], _: Rgb, _: f64, _: bool) {}
        fn polygon(&mut self, _: &[(f64, f64)], _: Rgb, _: u8) {}
        fn text(&mut self, x: f64, y: f64, text: &str, size: u32, _: Rgb, anchor: u8) {
            self.0.push((x, y, text.to_string(), size, anchor));
        }
    }

    #[test]
    fn a_long_legend_wraps_into_rows_above_the_plot() {
        let mut c = chart();
        c.series = (0..8)
            .map(|k| Series {
                label: format!("series number {k} with a long label"),
                points: vec![(0.0, k as f64), (1.0, 1.0)],
                colour: (0, 0, 0),
                dashed: k % 2 == 0,
                band: Vec::new(),
            })
            .collect();
        let mut texts = Texts::default();
        c.draw(&mut texts);
        let legend: Vec<_> = texts
            .0
            .iter()
            .filter(|t| t.2.starts_with("series"))
            .collect();
        assert_eq!(legend.len(), 8);
        for (x, _, text, size, _) in &legend {
            assert!(
                x + text_width(text, *size) as f64 <= WIDTH - 40.0,
                "{text} at {x}"
            );
        }
        let rows: std::collections::BTreeSet<i64> = legend.iter().map(|t| t.1 as i64).collect();
        assert!(rows.len() >= 3, "{rows:?}");
        // The y axis label sits below the last legend row.
        let last_row = legend.iter().map(|t| t.1).fold(0.0, f64::max);
        let axis = texts.0.iter().find(|t| t.2 == "mm").unwrap();
        assert!(axis.1 > last_row + 10.0);
    }

    /// Four scans are marked 1, 2, 3, 4, never 1.5; a continuous axis keeps
    /// its halves.
    #[test]
    fn an_axis_of_scans_is_marked_at_whole_scans() {
        let marks = |xs: &[f64]| {
            let mut c = chart();
            c.series[0].points = xs.iter().map(|&x| (x, x)).collect();
            let mut texts = Texts::default();
            c.draw(&mut texts);
            texts.0.iter().map(|t| t.2.clone()).collect::<Vec<String>>()
        };
        let scans = marks(&[1.0, 2.0, 3.0, 4.0]);
        assert!(scans.iter().any(|t| t == "3"), "{scans:?}");
        assert!(!scans.iter().any(|t| t == "1.5" || t == "2.5"), "{scans:?}");
        let hours = marks(&[1.0, 2.25, 4.0]);
        assert!(hours.iter().any(|t| t == "1.5"), "{hours:?}");
    }

    #[test]
    fn ticks_are_round() {
        assert_eq!(ticks(0.0, 10.0, 5), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(label(0.30000000000000004), "0.3");
    }
}
