//! Eq. (2)'s clearance term `1/P` for the cells a cycle's children may take.
//!
//! In: the knowledge map and the candidate cells of a cycle. Out: each cell's
//! clearance in metres, capped.

use crate::grid::distance::transform;
use crate::grid::traversability::clearance_metres;
use crate::grid::{CellState, OccupancyGrid};

/// Eq. (2)'s `1/P` of every cell in `cells` (grid indices): metres to the nearest
/// known Occupied cell by the rule of
/// [`Traversability::clearance_at`](crate::grid::Traversability::clearance_at),
/// capped at `cap` metres. One exact distance transform of the cells' bounding box
/// widened by the cap: an Occupied cell nearer than the cap to any of them lies
/// inside, and farther ones only give values the cap replaces.
pub fn clearances(knowledge: &OccupancyGrid, cells: &[u32], cap: f64) -> Vec<f64> {
    let g = knowledge.geometry();
    let w = g.width;
    let Some(bounds) = g.index_bounds(cells.iter().map(|&i| i as usize)) else {
        return Vec::new();
    };
    let res = g.resolution;
    let margin = (cap / res + 0.5).ceil() as usize + 1;
    let x0 = bounds.0.saturating_sub(margin);
    let y0 = bounds.1.saturating_sub(margin);
    let x1 = (bounds.2 + margin).min(w - 1);
    let y1 = (bounds.3 + margin).min(g.height - 1);
    let bw = x1 + 1 - x0;
    let k = knowledge.cells();
    let d = transform(bw, y1 + 1 - y0, |x, y| {
        k[(y0 + y) * w + x0 + x] == CellState::Occupied
    });
    cells
        .iter()
        .map(|&i| {
            let (x, y) = (i as usize % w, i as usize / w);
            let cells_away = d[(y - y0) * bw + (x - x0)];
            clearance_metres(cells_away, res).min(cap as f32) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Cell, Point};
    use crate::grid::{GridGeometry, Traversability};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        /// The windowed transform gives every cell the capped clearance of the
        /// column walk.
        #[test]
        fn clearances_match_the_capped_walk(
            rects in proptest::collection::vec((0usize..60, 0usize..50, 1usize..8, 1usize..8), 0..10),
            unknown in (0usize..60, 0usize..50, 0usize..20, 0usize..20),
            picks in proptest::collection::vec(0usize..3000, 1..40),
            cap in proptest::sample::select(vec![1.0f64, 5.0]),
        ) {
            let g = GridGeometry::new(60, 50, 0.1, Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Free);
            for (x, y, w, h) in rects {
                k.fill_rect(x, y, x + w, y + h, CellState::Occupied);
            }
            let (ux, uy, uw, uh) = unknown;
            k.fill_rect(ux, uy, ux + uw, uy + uh, CellState::Unknown);
            let mut cells: Vec<u32> = picks.into_iter().map(|p| p as u32).collect();
            cells.sort_unstable();
            cells.dedup();
            let got = clearances(&k, &cells, cap);
            let trav = Traversability::new(&k, 0.25, Cell::new(1, 1));
            for (&c, &v) in cells.iter().zip(&got) {
                let walk = trav.clearance_at(c as usize).min(cap as f32) as f64;
                prop_assert_eq!(v.to_bits(), walk.to_bits(), "cell {}", c);
            }
        }
    }
}
