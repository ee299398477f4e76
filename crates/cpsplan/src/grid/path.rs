//! Drivable paths for the parent: the cheapest grid path from the travel-distance
//! sweep, shortened by line-of-sight string pulling over drivable cells, as
//! world-frame waypoints in metres. (Voronoi-edge motion, paper section IV-D, will
//! replace this for the full CPS system.)

use super::line::segment_clear;
use super::travel::{descend, DistanceField};
use crate::geom::{Cell, Point};
use crate::grid::GridGeometry;

/// Waypoint cells from the source of `field` to `target`: the grid path with every
/// waypoint that a straight drivable segment can skip removed. `None` if `target`
/// was not reached.
pub fn shortcut_path(
    geometry: &GridGeometry,
    field: &DistanceField,
    passable: &[bool],
    target: Cell,
) -> Option<Vec<Cell>> {
    let cells = descend(geometry, field, passable, target)?;
    Some(pull(&cells, |a, b| {
        segment_clear(geometry, cells[a], cells[b], |i| passable[i])
    }))
}

/// String pulling: from each kept waypoint, jump to the farthest later cell with
/// `clear(anchor, j)` (indices into `cells`), else to the next cell.
pub(crate) fn pull(cells: &[Cell], clear: impl Fn(usize, usize) -> bool) -> Vec<Cell> {
    let Some(&first) = cells.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut anchor = 0;
    while anchor + 1 < cells.len() {
        let next = (anchor + 2..cells.len())
            .rev()
            .find(|&j| clear(anchor, j))
            .unwrap_or(anchor + 1);
        out.push(cells[next]);
        anchor = next;
    }
    out
}

/// World-frame centres of `cells`.
pub fn to_world(geometry: &GridGeometry, cells: &[Cell]) -> Vec<Point> {
    cells.iter().map(|&c| geometry.cell_center(c)).collect()
}

#[cfg(test)]
mod tests {
    use super::super::travel::{sweep, UNREACHED};
    use super::*;
    use crate::geom::polyline_length;

    #[test]
    fn open_space_path_is_one_straight_leg() {
        let g = GridGeometry::new(40, 40, 0.1, Point::default());
        let passable = vec![true; g.len()];
        let f = sweep(&g, &passable, &[g.index(Cell::new(1, 1))], UNREACHED);
        let p = shortcut_path(&g, &f, &passable, Cell::new(30, 17)).unwrap();
        assert_eq!(p, vec![Cell::new(1, 1), Cell::new(30, 17)]);
    }

    #[test]
    fn path_bends_around_a_wall_and_stays_clear() {
        let g = GridGeometry::new(40, 40, 0.1, Point::default());
        let mut passable = vec![true; g.len()];
        for y in 0..30 {
            passable[g.index(Cell::new(20, y))] = false;
        }
        let f = sweep(&g, &passable, &[g.index(Cell::new(5, 5))], UNREACHED);
        let p = shortcut_path(&g, &f, &passable, Cell::new(35, 5)).unwrap();
        assert!(p.len() >= 3);
        for w in p.windows(2) {
            assert!(segment_clear(&g, w[0], w[1], |i| passable[i]));
        }
        let len = polyline_length(&to_world(&g, &p));
        let grid_len = f.metres(g.index(Cell::new(35, 5))).unwrap();
        assert!(len <= grid_len + 1e-9);
    }
}
