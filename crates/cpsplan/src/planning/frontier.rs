//! The border between known-Free and Unknown space and the band of known-Free
//! cells along it (section IV-A-1, steps 1–2).

use super::reach::{sweep, DistanceField, UNREACHED};
use crate::world::{CellState, OccupancyGrid};

/// Known-Free cells with an Unknown 4-neighbour: the border lines of Fig. 4.
pub fn border_cells(knowledge: &OccupancyGrid) -> Vec<usize> {
    let g = knowledge.geometry();
    let (w, h) = (g.width, g.height);
    let k = knowledge.cells();
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if k[i] != CellState::Free {
                continue;
            }
            let unknown = (x > 0 && k[i - 1] == CellState::Unknown)
                || (x + 1 < w && k[i + 1] == CellState::Unknown)
                || (y > 0 && k[i - w] == CellState::Unknown)
                || (y + 1 < h && k[i + w] == CellState::Unknown);
            if unknown {
                out.push(i);
            }
        }
    }
    out
}

/// The band: known-Free cells whose travel distance through known-Free space to the
/// nearest border cell is at most `width` metres. Returns the band's cells in
/// index order and the distance field from the border.
pub fn band(
    knowledge: &OccupancyGrid,
    border: &[usize],
    width: f64,
) -> (Vec<usize>, DistanceField) {
    let g = knowledge.geometry();
    let free: Vec<bool> = knowledge
        .cells()
        .iter()
        .map(|&c| c == CellState::Free)
        .collect();
    let field = sweep(
        g,
        &free,
        border,
        DistanceField::cost_of(width, g.resolution),
    );
    let cells = (0..g.len())
        .filter(|&i| field.cost[i] != UNREACHED)
        .collect();
    (cells, field)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Cell, Point};
    use crate::world::GridGeometry;

    #[test]
    fn border_and_band_of_a_half_known_strip() {
        let g = GridGeometry::new(40, 5, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        k.fill_rect(0, 0, 20, 5, CellState::Free);
        let b = border_cells(&k);
        assert_eq!(b.len(), 5);
        assert!(b.iter().all(|&i| g.cell(i).x == 19));
        let (cells, _) = band(&k, &b, 0.5);
        // Columns 14..=19 are within 0.5 m of column 19.
        assert_eq!(cells.len(), 6 * 5);
        assert!(cells.iter().all(|&i| g.cell(i).x >= 14));
        assert!(!cells.contains(&g.index(Cell::new(13, 2))));
    }

    #[test]
    fn occupied_cells_are_never_border() {
        let g = GridGeometry::new(3, 1, 1.0, Point::default());
        let k = OccupancyGrid::from_cells(
            g,
            vec![CellState::Occupied, CellState::Unknown, CellState::Occupied],
        )
        .unwrap();
        assert!(border_cells(&k).is_empty());
    }
}
