//! The plain preview of an occupancy grid.

use cpsplan::{CellState, OccupancyGrid};

use super::chrome::{Header, LegendItem, Swatch};
use super::layout::{check_geometry, percent, Class, Frame};
use super::palette;
use super::upright::upright;
use super::RenderError;

/// Draws a plain preview of `grid` as PNG: free white, occupied near-black, unknown
/// grey, with a title strip (title, cell counts, legend) and a scale bar.
pub fn render_map(grid: &OccupancyGrid, title: &str) -> Result<Vec<u8>, RenderError> {
    draw_map(grid, title)?.canvas.encode()
}

pub(super) fn draw_map(grid: &OccupancyGrid, title: &str) -> Result<Frame, RenderError> {
    // World +x right and +y up ([`upright`]).
    let grid = upright(grid);
    let grid = grid.as_ref();
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
