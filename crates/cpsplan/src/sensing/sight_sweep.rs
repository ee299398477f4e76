//! Certain lines of sight from one cell to every cell of a disc in one sweep:
//! exactly the cells `b` with [`super::sight_clear`]`(a, b, 0)`, the rule of CPS
//! links without a sight clearance (DESIGN.md "Visibility", *certain*).
//!
//! In: the grid, the origin, a range in cells and which cells block. Out: a call
//! for every cell in certain line of sight within the range.
//!
//! # Method
//!
//! A segment between two cell centres is clear when it touches no blocking cell's
//! closed square. In each quadrant (depth along one axis, column along the
//! other, as [`super::visible_cells`] sweeps) the segment from the origin to the
//! centre of cell (`D`, `C`) crosses every row `1 ≤ d < D` over its whole height,
//! so a blocking square of such a row touches it exactly when the slope `C / D`
//! lies in the square's closed interval of slopes (the least and greatest slope
//! of its corners). The sweep therefore keeps, row by row, the *lit* open
//! intervals of slopes that no blocking square of a nearer row covers; a cell of
//! row `D` is seen when its slope lies in one. The square of a row touches the
//! segment in the origin's row and in the target's row only on the diagonal
//! (`|C| = D`), through a lattice corner: those two squares are tested apart.
//! Squares outside the grid never touch a segment between two centres. Slopes
//! are fractions of small integers compared by cross-multiplication, so the
//! answers are exact. Cost: the cells of the disc and the few columns beyond
//! the lit intervals, one blocking test each; no square roots.

use super::shadowcast::{isqrt, quadrants};
use crate::geom::Cell;
use crate::grid::GridGeometry;

/// A slope `num / den` (`den > 0`), or ±∞ (`den == 0`, `num` = ±1).
#[derive(Debug, Clone, Copy)]
struct Slope {
    num: i64,
    den: i64,
}

impl Slope {
    const NEG_INF: Self = Self { num: -1, den: 0 };
    const POS_INF: Self = Self { num: 1, den: 0 };

    /// `self < other`, exactly.
    #[inline]
    fn lt(self, other: Self) -> bool {
        match (self.den, other.den) {
            (0, 0) => self.num < other.num,
            (0, _) => self.num < 0,
            (_, 0) => other.num > 0,
            _ => self.num * other.den < other.num * self.den,
        }
    }

    #[inline]
    fn max(self, other: Self) -> Self {
        if self.lt(other) {
            other
        } else {
            self
        }
    }

    /// The slope as a float (±∞ for the infinite ones).
    fn value(self) -> f64 {
        if self.den == 0 {
            self.num as f64 * f64::INFINITY
        } else {
            self.num as f64 / self.den as f64
        }
    }
}

/// The closed interval of slopes of the square of the cell at `depth ≥ 1`,
/// `col` (doubled coordinates: corners at odd multiples of one half).
#[inline]
fn square_slopes(depth: i64, col: i64) -> (Slope, Slope) {
    let (near, far) = (2 * depth - 1, 2 * depth + 1);
    let low = if col >= 1 {
        Slope {
            num: 2 * col - 1,
            den: far,
        }
    } else {
        Slope {
            num: 2 * col - 1,
            den: near,
        }
    };
    let high = if col >= 0 {
        Slope {
            num: 2 * col + 1,
            den: near,
        }
    } else {
        Slope {
            num: 2 * col + 1,
            den: far,
        }
    };
    (low, high)
}

/// Calls `visit(index, b)` once for every cell `b` within `range_cells` of `origin`
/// (centre to centre) such that the segment between the two centres touches the
/// closed square of no cell with `blocks(index)`: the cells that
/// [`super::sight_clear`] with no clearance accepts (the origin included, when it
/// does not block). Nothing is visited when the origin blocks.
pub fn certain_cells(
    geometry: &GridGeometry,
    origin: Cell,
    range_cells: f64,
    blocks: impl Fn(usize) -> bool,
    mut visit: impl FnMut(usize, Cell),
) {
    if origin.x >= geometry.width || origin.y >= geometry.height {
        return;
    }
    let base = geometry.index(origin);
    if blocks(base) {
        return;
    }
    visit(base, origin);
    let (r2, quadrants) = quadrants(geometry, origin, range_cells);
    let mut stack: Vec<(i64, Slope, Slope)> = Vec::new();
    for q in &quadrants {
        let at = |depth: i64, col: i64| {
            (base as isize + depth as isize * q.d_depth + col as isize * q.d_col) as usize
        };
        // The origin row's squares beside the origin, on each side.
        let side_blocks = |col: i64| (q.col_lo..=q.col_hi).contains(&col) && blocks(at(0, col));
        let origin_side = [side_blocks(-1), side_blocks(1)];
        stack.push((1, Slope::NEG_INF, Slope::POS_INF));
        while let Some((d, lo, hi)) = stack.pop() {
            if d > q.max_depth {
                continue;
            }
            // The cells of this row whose slope lies strictly inside (lo, hi).
            let reach = if q.owns_diagonals { d } else { d - 1 };
            let half = isqrt(r2 - d * d);
            let first = if lo.den == 0 {
                i64::MIN
            } else {
                (lo.num * d).div_euclid(lo.den) + 1
            };
            let last = if hi.den == 0 {
                i64::MAX
            } else {
                -(-hi.num * d).div_euclid(hi.den) - 1
            };
            let first = first.max(-reach).max(-half).max(q.col_lo);
            let last = last.min(reach).min(half).min(q.col_hi);
            for col in first..=last {
                let i = at(d, col);
                if blocks(i) {
                    continue;
                }
                if col.abs() == d {
                    // The diagonal passes the corners of the origin row's square
                    // and of this row's square on the axis side.
                    let s = col.signum();
                    if origin_side[usize::from(s > 0)] || blocks(at(d, col - s)) {
                        continue;
                    }
                }
                let (dx, dy) = (
                    d * q.depth_step.0 + col * q.col_step.0,
                    d * q.depth_step.1 + col * q.col_step.1,
                );
                // Inside the grid, so the coordinates are non-negative.
                let cell = Cell::new(
                    (origin.x as i64 + dx) as usize,
                    (origin.y as i64 + dy) as usize,
                );
                visit(i, cell);
            }
            if d == q.max_depth {
                continue;
            }
            // The blocking squares of this row split (lo, hi) for the rows behind.
            let (lo_f, hi_f) = (lo.value(), hi.value());
            let from = if lo_f.is_finite() {
                ((lo_f * (d as f64 - 0.5)).min(lo_f * (d as f64 + 0.5)) - 0.5).floor() as i64 - 1
            } else {
                i64::MIN
            };
            let to = if hi_f.is_finite() {
                ((hi_f * (d as f64 - 0.5)).max(hi_f * (d as f64 + 0.5)) + 0.5).ceil() as i64 + 1
            } else {
                i64::MAX
            };
            let from = from.max(-(d + 1)).max(q.col_lo);
            let to = to.min(d + 1).min(q.col_hi);
            let mut open = lo;
            for col in from..=to {
                if !blocks(at(d, col)) {
                    continue;
                }
                let (low, high) = square_slopes(d, col);
                if !lo.lt(high) {
                    continue;
                }
                if !low.lt(hi) {
                    break;
                }
                if open.lt(low) {
                    stack.push((d + 1, open, low));
                }
                open = open.max(high);
            }
            if open.lt(hi) {
                stack.push((d + 1, open, hi));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{CellState, OccupancyGrid};
    use crate::sensing::sight_clear;
    use proptest::prelude::*;

    use crate::grid::fixtures::coded as grid;

    fn seen(k: &OccupancyGrid, a: Cell, range: f64) -> Vec<bool> {
        let g = k.geometry();
        let mut out = vec![false; g.len()];
        let cells = k.cells();
        certain_cells(
            g,
            a,
            range,
            |i| cells[i] != CellState::Free,
            |i, c| {
                assert!(!out[i], "cell {i} visited twice");
                assert_eq!(g.index(c), i);
                out[i] = true;
            },
        );
        out
    }

    proptest! {
        /// The sweep sees exactly the cells the supercover test accepts, within
        /// the range, on random grids with walls and unknown cells.
        #[test]
        fn the_sweep_is_exactly_the_supercover_rule(
            w in 1usize..36,
            h in 1usize..36,
            cells in proptest::collection::vec(0u8..9, 1296),
            from in (0usize..36, 0usize..36),
            range in proptest::sample::select(vec![0.0, 1.0, 1.5, 4.2, 9.0, 17.5, 60.0]),
        ) {
            let k = grid(w, h, &cells);
            let g = *k.geometry();
            let a = Cell::new(from.0 % w, from.1 % h);
            let got = seen(&k, a, range);
            let r2 = (range * range + 1e-9).floor() as i64;
            for (i, &seen) in got.iter().enumerate() {
                let b = g.cell(i);
                let (dx, dy) = (b.x as i64 - a.x as i64, b.y as i64 - a.y as i64);
                let want = dx * dx + dy * dy <= r2 && sight_clear(&k, a, b, 0.0);
                prop_assert_eq!(seen, want, "{:?} -> {:?}", a, b);
            }
        }
    }

    #[test]
    fn corners_block_the_diagonal_and_open_grids_see_the_disc() {
        // A wall cell beside the diagonal's first corner, in the origin's row.
        let mut k = grid(9, 9, &[]);
        let a = Cell::new(4, 4);
        k.set(Cell::new(5, 4), CellState::Occupied);
        let got = seen(&k, a, 10.0);
        let g = *k.geometry();
        assert!(!got[g.index(Cell::new(7, 7))]);
        assert!(!got[g.index(Cell::new(6, 6))]);
        assert!(got[g.index(Cell::new(3, 3))]);
        assert!(got[g.index(Cell::new(7, 8))]);
        // Without walls: every cell of the disc, once.
        let open = grid(21, 21, &[]);
        let got = seen(&open, Cell::new(10, 10), 6.5);
        let expected = (0..21 * 21)
            .filter(|&i| {
                let (x, y) = ((i % 21) as i64 - 10, (i / 21) as i64 - 10);
                x * x + y * y <= 42
            })
            .count();
        assert_eq!(got.iter().filter(|&&s| s).count(), expected);
        // A blocked origin sees nothing.
        let mut k = grid(5, 5, &[]);
        k.set(Cell::new(2, 2), CellState::Unknown);
        assert!(seen(&k, Cell::new(2, 2), 5.0).iter().all(|&s| !s));
    }
}
