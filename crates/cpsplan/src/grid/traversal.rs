//! The cells a straight segment crosses, in order, with where it enters each:
//! the grid traversal of Amanatides and Woo (1987). Unlike the supercover of
//! [`mod@super::line`], it runs on real coordinates and gives the segment's
//! parameter at every cell boundary (for beams whose height changes along
//! them, and for the point where a beam first enters a wall).

/// The traversal from the cell holding `from` towards the cell holding `to`
/// (grid-frame metres, [`super::GridGeometry::to_local`]): each item is a cell
/// `(x, y)` entered and the parameter `t` of the segment `from + t·(to − from)`
/// where it is entered. There are exactly as many items as the two end cells
/// are apart in x plus in y; the start cell is [`Traversal::start`].
#[derive(Debug, Clone)]
pub struct Traversal {
    cell: (i64, i64),
    step: (i64, i64),
    next: (f64, f64),
    delta: (f64, f64),
    remaining: u64,
}

impl Traversal {
    /// The traversal of the segment from `from` to `to` over cells of
    /// `resolution` metres.
    pub fn new(resolution: f64, from: (f64, f64), to: (f64, f64)) -> Self {
        let r = resolution;
        let (dx, dy) = (to.0 - from.0, to.1 - from.1);
        let cell = ((from.0 / r).floor() as i64, (from.1 / r).floor() as i64);
        let end = ((to.0 / r).floor() as i64, (to.1 / r).floor() as i64);
        // Per axis: the step, the parameter of the next cell boundary, and the
        // parameter between boundaries.
        let axis = |s: f64, d: f64, c: i64| -> (i64, f64, f64) {
            if d > 0.0 {
                (1, ((c + 1) as f64 * r - s) / d, r / d)
            } else if d < 0.0 {
                (-1, (c as f64 * r - s) / d, -r / d)
            } else {
                (0, f64::INFINITY, f64::INFINITY)
            }
        };
        let (sx, nx, ddx) = axis(from.0, dx, cell.0);
        let (sy, ny, ddy) = axis(from.1, dy, cell.1);
        Self {
            cell,
            step: (sx, sy),
            next: (nx, ny),
            delta: (ddx, ddy),
            remaining: (end.0 - cell.0)
                .unsigned_abs()
                .saturating_add((end.1 - cell.1).unsigned_abs()),
        }
    }

    /// The cell the segment starts in.
    pub fn start(&self) -> (i64, i64) {
        self.cell
    }
}

impl Iterator for Traversal {
    type Item = (i64, i64, f64);

    fn next(&mut self) -> Option<Self::Item> {
        if self.remaining == 0 {
            return None;
        }
        self.remaining -= 1;
        let t;
        if self.next.0 < self.next.1 {
            t = self.next.0;
            self.next.0 += self.delta.0;
            self.cell.0 += self.step.0;
        } else {
            t = self.next.1;
            self.next.1 += self.delta.1;
            self.cell.1 += self.step.1;
        }
        Some((self.cell.0, self.cell.1, t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_and_entry_parameters_of_a_diagonal() {
        // From (0.05, 0.05) to (0.35, 0.12) over 0.1 m cells.
        let t = Traversal::new(0.1, (0.05, 0.05), (0.35, 0.12));
        assert_eq!(t.start(), (0, 0));
        let items: Vec<_> = t.collect();
        let cells: Vec<_> = items.iter().map(|&(x, y, _)| (x, y)).collect();
        assert_eq!(cells, vec![(1, 0), (2, 0), (2, 1), (3, 1)]);
        // x = 0.1 at t = 1/6, x = 0.2 at t = 1/2, y = 0.1 at t = 5/7, x = 0.3
        // at t = 5/6.
        let ts: Vec<f64> = items.iter().map(|i| i.2).collect();
        for (got, want) in ts.iter().zip([1.0 / 6.0, 0.5, 5.0 / 7.0, 5.0 / 6.0]) {
            assert!((got - want).abs() < 1e-12, "{ts:?}");
        }
    }

    #[test]
    fn within_one_cell_there_is_nothing_to_cross() {
        assert_eq!(Traversal::new(0.1, (0.01, 0.01), (0.09, 0.02)).count(), 0);
    }
}
