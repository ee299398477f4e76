//! Straight segments on the grid: the supercover of a segment between two cell
//! centres (every cell the segment touches, both cells where it passes exactly
//! through a corner), used to check that a path leg stays on drivable cells.

use crate::geom::Cell;
use crate::grid::GridGeometry;

/// Whether every cell of the supercover from `a` to `b` satisfies `ok(index)`,
/// asked in order from `a` to `b` and stopping at the first that does not.
///
/// An integer walk: the decision term `(1 + 2·ix)·ny − (1 + 2·iy)·nx` says
/// whether the segment leaves the current cell across its vertical side (< 0),
/// its horizontal side (> 0) or exactly through its corner (0, where both cells
/// beside the corner are touched too). It and the cell's index are updated by
/// additions only.
pub fn segment_clear(
    geometry: &GridGeometry,
    a: Cell,
    b: Cell,
    ok: impl Fn(usize) -> bool,
) -> bool {
    let w = geometry.width as i64;
    let (dx, dy) = (b.x as i64 - a.x as i64, b.y as i64 - a.y as i64);
    let (nx, ny) = (dx.abs(), dy.abs());
    // Index steps along x and along y.
    let (step_x, step_y) = (dx.signum(), dy.signum() * w);
    let mut i = a.y as i64 * w + a.x as i64;
    if !ok(i as usize) {
        return false;
    }
    let mut decision = ny - nx;
    let (mut ix, mut iy) = (0i64, 0i64);
    while ix < nx || iy < ny {
        if decision == 0 {
            if !ok((i + step_x) as usize) || !ok((i + step_y) as usize) {
                return false;
            }
            i += step_x + step_y;
            ix += 1;
            iy += 1;
            decision += 2 * (ny - nx);
        } else if decision < 0 {
            i += step_x;
            ix += 1;
            decision += 2 * ny;
        } else {
            i += step_y;
            iy += 1;
            decision -= 2 * nx;
        }
        if !ok(i as usize) {
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

    /// The cells whose closed square the segment between the centres of `a`
    /// and `b` touches: no side of the segment's line holds all four corners
    /// strictly, within the segment's bounding box (coordinates doubled, so
    /// exact in integers).
    fn touched(a: Cell, b: Cell) -> std::collections::BTreeSet<(usize, usize)> {
        let (ax, ay, bx, by) = (a.x as i64, a.y as i64, b.x as i64, b.y as i64);
        let mut out = std::collections::BTreeSet::new();
        for y in ay.min(by)..=ay.max(by) {
            for x in ax.min(bx)..=ax.max(bx) {
                let side = |px: i64, py: i64| {
                    ((2 * bx - 2 * ax) * (py - 2 * ay) - (2 * by - 2 * ay) * (px - 2 * ax)).signum()
                };
                let corners = [(-1, -1), (1, -1), (-1, 1), (1, 1)]
                    .map(|(ox, oy)| side(2 * x + ox, 2 * y + oy));
                if corners.iter().any(|&c| c <= 0) && corners.iter().any(|&c| c >= 0) {
                    out.insert((x as usize, y as usize));
                }
            }
        }
        out
    }

    proptest::proptest! {
        #[test]
        fn the_walk_asks_every_touched_cell_once_from_a_to_b(
            a in (0usize..20, 0usize..20),
            b in (0usize..20, 0usize..20),
        ) {
            let (a, b) = (Cell::new(a.0, a.1), Cell::new(b.0, b.1));
            let c = cover(a, b);
            let set: std::collections::BTreeSet<_> = c.iter().copied().collect();
            proptest::prop_assert_eq!(set.len(), c.len(), "a cell asked twice: {:?}", c);
            proptest::prop_assert_eq!(&set, &touched(a, b));
            proptest::prop_assert_eq!(c.first(), Some(&(a.x, a.y)));
            proptest::prop_assert_eq!(c.last(), Some(&(b.x, b.y)));
        }
    }

    #[test]
    fn blocked_cell_stops_the_segment() {
        let g = GridGeometry::new(10, 10, 1.0, Point::default());
        let blocked = g.index(Cell::new(4, 0));
        assert!(!segment_clear(&g, Cell::new(0, 0), Cell::new(9, 0), |i| i != blocked));
        assert!(segment_clear(&g, Cell::new(0, 1), Cell::new(9, 1), |i| i != blocked));
    }
}
