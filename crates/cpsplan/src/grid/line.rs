//! Straight segments on the grid: the supercover of a segment between two cell
//! centres (every cell the segment touches, both cells where it passes exactly
//! through a corner), used to check that a path leg stays on drivable cells.

use crate::geom::Cell;
use crate::grid::GridGeometry;

/// Whether every cell of the supercover from `a` to `b` satisfies `ok(index)`.
pub fn segment_clear(
    geometry: &GridGeometry,
    a: Cell,
    b: Cell,
    ok: impl Fn(usize) -> bool,
) -> bool {
    let (mut x, mut y) = (a.x as i64, a.y as i64);
    let (dx, dy) = (b.x as i64 - x, b.y as i64 - y);
    let (nx, ny) = (dx.abs(), dy.abs());
    let (sx, sy) = (dx.signum(), dy.signum());
    let w = geometry.width as i64;
    let at = |x: i64, y: i64| (y * w + x) as usize;
    if !ok(at(x, y)) {
        return false;
    }
    let (mut ix, mut iy) = (0i64, 0i64);
    while ix < nx || iy < ny {
        let decision = (1 + 2 * ix) * ny - (1 + 2 * iy) * nx;
        if decision == 0 {
            if !ok(at(x + sx, y)) || !ok(at(x, y + sy)) {
                return false;
            }
            x += sx;
            y += sy;
            ix += 1;
            iy += 1;
        } else if decision < 0 {
            x += sx;
            ix += 1;
        } else {
            y += sy;
            iy += 1;
        }
        if !ok(at(x, y)) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use std::cell::RefCell;

    fn cover(a: Cell, b: Cell) -> Vec<(usize, usize)> {
        let g = GridGeometry::new(20, 20, 1.0, Point::default());
        let seen = RefCell::new(Vec::new());
        segment_clear(&g, a, b, |i| {
            let c = g.cell(i);
            seen.borrow_mut().push((c.x, c.y));
            true
        });
        seen.into_inner()
    }

    #[test]
    fn diagonal_through_corners_covers_both_sides() {
        let c = cover(Cell::new(0, 0), Cell::new(2, 2));
        for p in [(0, 0), (1, 0), (0, 1), (1, 1), (2, 1), (1, 2), (2, 2)] {
            assert!(c.contains(&p), "{p:?} missing from {c:?}");
        }
    }

    #[test]
    fn shallow_segment_is_four_connected() {
        let c = cover(Cell::new(1, 1), Cell::new(9, 4));
        for w in c.windows(2) {
            let d = w[0].0.abs_diff(w[1].0) + w[0].1.abs_diff(w[1].1);
            assert!(d <= 1 || (w[0].0 != w[1].0 && w[0].1 != w[1].1));
        }
        assert_eq!(c.first(), Some(&(1, 1)));
        assert_eq!(c.last(), Some(&(9, 4)));
    }

    #[test]
    fn blocked_cell_stops_the_segment() {
        let g = GridGeometry::new(10, 10, 1.0, Point::default());
        let blocked = g.index(Cell::new(4, 0));
        assert!(!segment_clear(&g, Cell::new(0, 0), Cell::new(9, 0), |i| i != blocked));
        assert!(segment_clear(&g, Cell::new(0, 1), Cell::new(9, 1), |i| i != blocked));
    }
}
