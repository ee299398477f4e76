//! The band of section IV-A-1, step 2: the known-Free cells within a threshold of
//! the border, where the candidate samples are scattered.
//!
//! In: the knowledge map and its border cells ([`super::border`]). Out: the band's
//! cells.

use crate::grid::travel::reached_within;
use crate::grid::{CellState, DistanceField, OccupancyGrid};

/// The band: known-Free cells whose travel distance through known-Free space to the
/// nearest border cell is at most `width` metres, in index order. The search
/// touches only the band and the cells beside it, not the whole map.
pub fn band(knowledge: &OccupancyGrid, border: &[usize], width: f64) -> Vec<usize> {
    let cost = DistanceField::cost_of(width, knowledge.resolution());
    band_within(knowledge, border, cost)
}

/// The known-Free cells within the travel cost `cost` through known-Free space of
/// the cells `sources`, in index order: [`band()`] in the sweep's cost units.
pub(super) fn band_within(knowledge: &OccupancyGrid, sources: &[usize], cost: u32) -> Vec<usize> {
    reached_within(
        knowledge.geometry(),
        knowledge.cells(),
        |c| c == CellState::Free,
        sources,
        cost,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Cell, Point};
    use crate::grid::GridGeometry;
    use crate::parent::border::border_cells;

    #[test]
    fn band_of_a_half_known_strip() {
        let g = GridGeometry::new(40, 5, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        k.fill_rect(0, 0, 20, 5, CellState::Free);
        let b = border_cells(&k);
        let cells = band(&k, &b, 0.5);
        // Columns 14..=19 are within 0.5 m of column 19.
        assert_eq!(cells.len(), 6 * 5);
        assert!(cells.iter().all(|&i| g.cell(i).x >= 14));
        assert!(!cells.contains(&g.index(Cell::new(13, 2))));
    }
}
