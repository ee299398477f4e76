//! A deterministic default start for maps that do not name one.

use crate::geom::Point;
use crate::grid::distance::distance_transform;
use crate::grid::region::label4;
use crate::grid::{CellState, OccupancyGrid};

/// The free cell with the largest clearance in the largest 4-connected free region
/// (ties: lowest index), as a world point; `None` if the map has no free cell.
pub fn default_start(truth: &OccupancyGrid) -> Option<Point> {
    let g = truth.geometry();
    let t = truth.cells();
    let (w, h) = (g.width, g.height);
    let (label, sizes) = label4(w, h, |i| t[i] == CellState::Free);
    let (region, _) = sizes
        .iter()
        .enumerate()
        .fold((u32::MAX, 0usize), |best, (id, &n)| {
            if n > best.1 {
                (id as u32, n)
            } else {
                best
            }
        });
    if region == u32::MAX {
        return None;
    }
    let d = distance_transform(g, |i| t[i] != CellState::Free);
    let mut best: Option<(f32, usize)> = None;
    for i in 0..g.len() {
        if label[i] == region {
            let edge = ((i % w).min(i / w).min(w - 1 - i % w).min(h - 1 - i / w) + 1) as f32;
            let c = d[i].min(edge);
            if best.is_none_or(|(b, _)| c > b) {
                best = Some((c, i));
            }
        }
    }
    best.map(|(_, i)| g.cell_center(g.cell(i)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::GridGeometry;

    #[test]
    fn picks_the_middle_of_the_biggest_room() {
        let g = GridGeometry::new(30, 10, 1.0, Point::default());
        let mut t = OccupancyGrid::filled(g, CellState::Occupied);
        t.fill_rect(1, 1, 4, 9, CellState::Free);
        t.fill_rect(10, 1, 29, 9, CellState::Free);
        let p = default_start(&t).unwrap();
        let c = g.world_to_cell(p).unwrap();
        assert!(c.x >= 13 && c.x <= 25, "{c:?}");
        assert!(c.y >= 3 && c.y <= 6);
        assert_eq!(t.get(c), CellState::Free);
        let none = OccupancyGrid::filled(g, CellState::Occupied);
        assert!(default_start(&none).is_none());
    }
}
