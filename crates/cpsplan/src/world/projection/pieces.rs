//! How whole a projected map's free space is: a cloud too sparse for its
//! cells (an aerial scan's lines half a metre apart on half-metre cells)
//! leaves the free space in strips the robots cannot drive between, and a run
//! on it ends in one of them.

use crate::grid::region::label4;
use crate::grid::{CellState, OccupancyGrid};

/// Below this share of the free cells in its largest 4-connected piece, a
/// map's free space counts as fragmented.
pub const FRAGMENTED_SHARE: f64 = 0.5;

/// Above this share of gaps (unknown cells between free ones) among the
/// free cells and the gaps, a map's free space counts as fragmented.
pub const GAPPY_SHARE: f64 = 0.1;

/// The 4-connected pieces of a map's free space.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FreeSpacePieces {
    /// Free cells.
    pub free_cells: usize,
    /// Pieces of 4-connected free cells.
    pub pieces: usize,
    /// Free cells of the largest piece.
    pub largest: usize,
    /// Unknown cells between two free ones (free on both sides, left and right
    /// or above and below): gaps in the data, which block sight and driving
    /// as a wall would.
    pub gaps: usize,
}

impl FreeSpacePieces {
    /// The share of the free cells in the largest piece (1 without free cells).
    pub fn largest_share(&self) -> f64 {
        if self.free_cells == 0 {
            1.0
        } else {
            self.largest as f64 / self.free_cells as f64
        }
    }

    /// The share of the gaps among the free cells and the gaps.
    pub fn gap_share(&self) -> f64 {
        let all = self.free_cells + self.gaps;
        if all == 0 {
            0.0
        } else {
            self.gaps as f64 / all as f64
        }
    }

    /// Whether the largest piece holds less than [`FRAGMENTED_SHARE`] of the
    /// free cells, or more than [`GAPPY_SHARE`] of the free space is gaps.
    pub fn fragmented(&self) -> bool {
        self.largest_share() < FRAGMENTED_SHARE || self.gap_share() > GAPPY_SHARE
    }
}

/// The pieces of `grid`'s free space (4-connected, as the robots drive).
pub fn free_space_pieces(grid: &OccupancyGrid) -> FreeSpacePieces {
    let g = grid.geometry();
    let cells = grid.cells();
    let (_, sizes) = label4(g.width, g.height, |i| cells[i] == CellState::Free);
    let free = |i: usize| cells[i] == CellState::Free;
    let (w, h) = (g.width, g.height);
    let gaps = (0..w * h)
        .filter(|&i| cells[i] == CellState::Unknown)
        .filter(|&i| {
            let (x, y) = (i % w, i / w);
            let across = x > 0 && x + 1 < w && free(i - 1) && free(i + 1);
            let along = y > 0 && y + 1 < h && free(i - w) && free(i + w);
            across || along
        })
        .count();
    FreeSpacePieces {
        free_cells: sizes.iter().sum(),
        pieces: sizes.len(),
        largest: sizes.iter().copied().max().unwrap_or(0),
        gaps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;

    #[test]
    fn strips_are_fragmented_and_a_room_is_whole() {
        let g = GridGeometry::new(20, 10, 0.5, Point::default());
        let mut strips = OccupancyGrid::filled(g, CellState::Unknown);
        for y in (0..10).step_by(2) {
            strips.fill_rect(0, y, 20, y + 1, CellState::Free);
        }
        let p = free_space_pieces(&strips);
        assert_eq!(
            (p.free_cells, p.pieces, p.largest, p.gaps),
            (100, 5, 20, 80)
        );
        assert!(p.fragmented());
        let mut room = OccupancyGrid::filled(g, CellState::Occupied);
        room.fill_rect(1, 1, 19, 9, CellState::Free);
        room.fill_rect(5, 5, 6, 6, CellState::Unknown);
        let p = free_space_pieces(&room);
        assert_eq!((p.pieces, p.largest_share(), p.gaps), (1, 1.0, 1));
        assert!(!p.fragmented());
        // One free row in two: whole pieces joined at the ends, but half gaps.
        let mut comb = OccupancyGrid::filled(g, CellState::Unknown);
        for y in (0..10).step_by(2) {
            comb.fill_rect(0, y, 20, y + 1, CellState::Free);
        }
        comb.fill_rect(0, 0, 1, 10, CellState::Free);
        let p = free_space_pieces(&comb);
        assert_eq!(p.pieces, 1);
        assert!(p.fragmented(), "{p:?}");
        let none = OccupancyGrid::filled(g, CellState::Occupied);
        assert!(!free_space_pieces(&none).fragmented());
    }
}
