//! The picture of the known-map bound: the ground truth with the greedy cover's
//! stations numbered in the order chosen.

use cpsplan::bound::KnownMapBound;
use cpsplan::OccupancyGrid;

use super::chrome::{Header, LegendItem, Swatch};
use super::layout::{check_geometry, Class, Frame};
use super::marks::draw_marker;
use super::palette;
use super::placer::Placer;
use super::scan_labels::{draw_scan_labels, place_scan_labels};
use super::upright::upright;
use super::RenderError;

/// Draws `bound`'s greedy stations on `truth` as PNG, numbered in greedy order,
/// those that reach 99 % in the scan colour and the rest (up to 100 %) grey.
pub fn render_bound(
    truth: &OccupancyGrid,
    bound: &KnownMapBound,
    title: &str,
) -> Result<Vec<u8>, RenderError> {
    // World +x right and +y up ([`upright`]); the stations are world points.
    let truth = upright(truth);
    let truth = truth.as_ref();
    let g = *truth.geometry();
    check_geometry(&g)?;
    let levels: Vec<String> = bound
        .levels
        .iter()
        .map(|l| {
            format!(
                "{:.0} %: {} (LB {})",
                100.0 * l.share,
                l.greedy_stations,
                l.lower_bound_stations
            )
        })
        .collect();
    let line = format!(
        "greedy stations (lower bound) \u{b7} {}",
        levels.join(" \u{b7} ")
    );
    let setup = format!(
        "range {} m \u{b7} {} candidates ({} lattice at {} m, {} at corners) \u{b7} targets every {} m",
        trim(bound.range_m),
        bound.lattice_stations + bound.corner_stations,
        bound.lattice_stations,
        trim(bound.spacing_m),
        bound.corner_stations,
        trim(bound.target_spacing_m),
    );
    let header = Header {
        title,
        lines: vec![line, setup],
        legend: vec![
            LegendItem {
                swatch: Swatch::Dot(palette::SCAN),
                label: "station to 99 %",
            },
            LegendItem {
                swatch: Swatch::Dot(palette::INELIGIBLE),
                label: "station to 100 %",
            },
            LegendItem {
                swatch: Swatch::Dot(palette::START),
                label: "start",
            },
        ],
    };
    let mut frame = Frame::new(&g, &header)?;
    let cells = truth.cells();
    frame
        .layout
        .paint(&mut frame.canvas, |i| Class::of(cells[i]));
    let (canvas, layout, style) = (&mut frame.canvas, &frame.layout, frame.style);
    let to99 = bound.level(0.99).map_or(0, |l| l.greedy_stations);
    let r = style.marker_radius();
    let dots: Vec<(f32, f32)> = bound
        .stations
        .iter()
        .map(|s| layout.world_to_px(s.position))
        .collect();
    let start = layout.world_to_px(bound.start);
    for (k, &(x, y)) in dots.iter().enumerate() {
        let c = if k < to99 {
            palette::SCAN
        } else {
            palette::INELIGIBLE
        };
        draw_marker(canvas, x, y, r, c);
    }
    draw_marker(canvas, start.0, start.1, r, palette::START);
    let mut obstacles = dots.clone();
    obstacles.push(start);
    let mut placer = Placer::new(canvas, layout, std::iter::empty(), &obstacles, r + 2.5);
    let labels = place_scan_labels(&mut placer, style, &dots, r, r);
    draw_scan_labels(canvas, style, &labels, usize::MAX);
    frame.canvas.encode()
}

fn trim(v: f64) -> String {
    super::layout::trim_number(v, 2)
}
