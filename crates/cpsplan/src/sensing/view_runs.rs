//! The gain estimate's sight sweep by runs (beyond the paper): the same cells
//! as [`super::visible_cells`] with Unknown treated as empty, counted a run of
//! cells at a time instead of cell by cell.
//!
//! A view of `S` (Eq. 1) looks through Unknown space, so from a candidate on the
//! border it sweeps most of its 20 m disc. Symmetric shadowcasting decides per
//! row only where the walls are: between two walls every cell whose centre lies
//! within the light is seen. [`ViewClasses`] keeps one byte per cell (free,
//! Unknown, Unknown near known free space, occupied) twice, in rows and in
//! columns, so that every quadrant's rows are contiguous; a row is then split
//! at its walls, the Unknown cells of each lit run counted and its near cells
//! listed by plain slice scans the compiler vectorises. The rows are visited in
//! the same order and split at the same slopes as the cell-by-cell sweep, so
//! the counts and the near cells, in their order, are the same (a property test
//! compares them on random maps).
//!
//! The classes live in [`super::NearField`] and are brought up to date with it
//! where a scan changed something, so keeping them costs no pass over the map.

use crate::geom::Cell;
use crate::grid::{CellState, GridGeometry};

use super::shadowcast::{isqrt, quadrants, Quadrant, Slope};

/// A cell the light passes that is known free.
const FREE: u8 = 0;
/// An Unknown cell (counted in `S`).
const UNKNOWN: u8 = 1;
/// An Unknown cell near known free space (counted in `S` and in the estimate).
const NEAR: u8 = 3;
/// A known obstacle: stops the light.
const WALL: u8 = 4;

/// The class of a cell in state `state` whose near flag is `near`.
#[inline]
fn class(state: CellState, near: bool) -> u8 {
    match state {
        CellState::Occupied => WALL,
        CellState::Unknown if near => NEAR,
        CellState::Unknown => UNKNOWN,
        CellState::Free => FREE,
    }
}

/// Per cell of a knowledge map its class for the gain views, in rows (the
/// map's own order) and in columns (transposed), kept up to date by
/// [`super::NearField`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct ViewClasses {
    rows: Vec<u8>,
    cols: Vec<u8>,
    width: usize,
    height: usize,
}

impl ViewClasses {
    /// The classes of every cell of a `geometry` grid from its states, no cell
    /// near yet (the near ones are [`Self::set`] as the gain field finds them).
    pub(super) fn new(geometry: &GridGeometry, states: &[CellState]) -> Self {
        let (width, height) = (geometry.width, geometry.height);
        let rows: Vec<u8> = states.iter().map(|&s| class(s, false)).collect();
        let mut cols = vec![FREE; rows.len()];
        for (y, row) in rows.chunks_exact(width.max(1)).enumerate() {
            for (x, &c) in row.iter().enumerate() {
                cols[x * height + y] = c;
            }
        }
        Self {
            rows,
            cols,
            width,
            height,
        }
    }

    /// Sets cell `index`'s class from its state and near flag.
    #[inline]
    pub(super) fn set(&mut self, index: usize, state: CellState, near: bool) {
        let c = class(state, near);
        self.rows[index] = c;
        let (x, y) = (index % self.width, index / self.width);
        self.cols[x * self.height + y] = c;
    }

    /// Counts the Unknown cells visible from `origin` within `range_cells`
    /// (known obstacles stop the light, [`super::visible_cells`]'s rule) and
    /// those of them that are near known free space, calling `on_near(index)`
    /// for each of the latter in the order the sweep meets them. Counting ends
    /// after a run once `stop(unknown, near)` says so.
    pub(super) fn count(
        &self,
        geometry: &GridGeometry,
        origin: Cell,
        range_cells: f64,
        on_near: &mut dyn FnMut(usize),
        stop: &dyn Fn(usize, usize) -> bool,
    ) -> (usize, usize) {
        let (w, h) = (self.width, self.height);
        if origin.x >= w || origin.y >= h {
            return (0, 0);
        }
        let base = geometry.index(origin);
        let mut sweep = RunSweep {
            classes: self,
            origin,
            halves: Vec::new(),
            unknown: 0,
            near: 0,
            on_near,
            stop,
        };
        let c = self.rows[base];
        if c & UNKNOWN != 0 {
            sweep.unknown += 1;
            if c == NEAR {
                sweep.near += 1;
                (sweep.on_near)(base);
            }
        }
        if (sweep.stop)(sweep.unknown, sweep.near) {
            return (sweep.unknown, sweep.near);
        }
        let (r2, quadrants) = quadrants(geometry, origin, range_cells);
        // The disc's half-width at every depth, once a view rather than once a row.
        let deepest = quadrants.iter().map(|q| q.max_depth).max().unwrap_or(0);
        sweep.halves = (0..=deepest.max(0))
            .map(|d| if d * d > r2 { -1 } else { isqrt(r2 - d * d) })
            .collect();
        for q in &quadrants {
            let line = Line::of(q);
            if q.max_depth >= 1
                && sweep.row(
                    q,
                    line,
                    1,
                    Slope { num: -1, den: 1 },
                    Slope { num: 1, den: 1 },
                )
            {
                break;
            }
        }
        (sweep.unknown, sweep.near)
    }
}

/// Which layout holds a quadrant's rows contiguously, and the sign of its
/// depth step.
#[derive(Clone, Copy)]
struct Line {
    /// Rows of the map (north, south) or columns (east, west).
    in_rows: bool,
    /// +1 or −1: the direction of one step in depth.
    sign: i64,
}

impl Line {
    /// The layout of quadrant `q`: a row of the north and south quadrants
    /// (depth along y) is a row of the map, one of the east and west ones a
    /// column.
    fn of(q: &Quadrant) -> Self {
        let (dx, dy) = q.depth_step;
        let in_rows = dy != 0;
        Self {
            in_rows,
            sign: if in_rows { dy } else { dx },
        }
    }
}

/// The state of one view's sweep.
struct RunSweep<'a> {
    classes: &'a ViewClasses,
    origin: Cell,
    /// The disc's half-width in columns at each depth (`isqrt(r² − depth²)`),
    /// −1 beyond the radius.
    halves: Vec<i64>,
    unknown: usize,
    near: usize,
    on_near: &'a mut dyn FnMut(usize),
    stop: &'a dyn Fn(usize, usize) -> bool,
}

impl<'a> RunSweep<'a> {
    /// The cells of the row at `depth` from column `lo` to `hi` (both on the
    /// grid), and the map index of the row's column 0 with the index step of
    /// one column.
    fn cells(&self, line: Line, depth: i64, lo: i64, hi: i64) -> (&'a [u8], i64, i64) {
        let c: &'a ViewClasses = self.classes;
        let (w, h) = (c.width as i64, c.height as i64);
        let (ox, oy) = (self.origin.x as i64, self.origin.y as i64);
        if line.in_rows {
            let y = oy + line.sign * depth;
            let start = y * w + ox;
            let s = &c.rows[(start + lo) as usize..=(start + hi) as usize];
            (s, start, 1)
        } else {
            let x = ox + line.sign * depth;
            let start = x * h + oy;
            let s = &c.cols[(start + lo) as usize..=(start + hi) as usize];
            (s, oy * w + x, w)
        }
    }

    /// Counts the lit cells `a..=b` of a row (indices into `cells`, whose
    /// first cell is column `lo`); returns whether to stop.
    fn lit(&mut self, cells: &[u8], a: usize, b: usize, lo: i64, col0: i64, step: i64) -> bool {
        let run = &cells[a..=b];
        let unknown = count_unknown(run);
        if unknown == 0 {
            return false;
        }
        self.unknown += unknown;
        // Near cells are few: chunks without one are passed over whole.
        for (k, chunk) in run.chunks(CHUNK).enumerate() {
            if chunk.iter().fold(0, |m, &c| m | (c & NEAR & !UNKNOWN)) == 0 {
                continue;
            }
            for (j, _) in chunk.iter().enumerate().filter(|(_, &c)| c == NEAR) {
                self.near += 1;
                let col = lo + (a + k * CHUNK + j) as i64;
                (self.on_near)((col0 + col * step) as usize);
            }
        }
        (self.stop)(self.unknown, self.near)
    }

    /// Scans the row at `depth` between the two slopes, recursing into the
    /// rows behind it exactly where the cell-by-cell sweep does; returns `true`
    /// if counting should stop.
    fn row(&mut self, q: &Quadrant, line: Line, depth: i64, mut start: Slope, end: Slope) -> bool {
        if depth > q.max_depth {
            return false;
        }
        let half = self.halves[depth as usize];
        if half < 0 {
            return false;
        }
        // One division a slope: `depth · slope = whole + rest / den`. The row
        // runs from the start slope's column rounded (ties up) to the end
        // slope's rounded (ties down); transparent cells are seen where their
        // centre is lit, from the start's column rounded up to the end's
        // rounded down; off this quadrant's diagonals when it does not own them.
        let (sw, sr) = whole_and_rest(depth, start);
        let (ew, er) = whole_and_rest(depth, end);
        let lo = (sw + i64::from(2 * sr >= start.den))
            .max(-half)
            .max(q.col_lo);
        let hi = (ew + i64::from(2 * er > end.den)).min(half).min(q.col_hi);
        if lo > hi {
            return false;
        }
        let mut lit_lo = sw + i64::from(sr > 0);
        let mut lit_hi = ew;
        if !q.owns_diagonals {
            lit_lo = lit_lo.max(1 - depth);
            lit_hi = lit_hi.min(depth - 1);
        }
        let (cells, col0, step) = self.cells(line, depth, lo, hi);
        let n = cells.len();
        let mut i = 0;
        let mut after_wall = false;
        while i < n {
            if cells[i] == WALL {
                let run = cells[i..].iter().position(|&c| c != WALL).unwrap_or(n - i);
                let col = lo + i as i64;
                if i > 0 && self.row(q, line, depth + 1, start, Slope::of_tile(depth, col)) {
                    return true;
                }
                after_wall = true;
                i += run;
            } else {
                let run = first_wall(&cells[i..]);
                let col = lo + i as i64;
                if after_wall {
                    // The light starts again at this tile's left edge: from here
                    // on every centre is lit from below. (The cell-by-cell sweep
                    // tests this first tile against the old slope, which lights
                    // it as well: the old slope's column, rounded up, is at most
                    // one past the row's first column, and a wall lies between.)
                    start = Slope::of_tile(depth, col);
                    lit_lo = lit_lo.max(col);
                }
                let a = (lit_lo - lo).max(i as i64);
                let b = (lit_hi - lo).min((i + run) as i64 - 1);
                if a <= b && self.lit(cells, a as usize, b as usize, lo, col0, step) {
                    return true;
                }
                i += run;
                if i == n {
                    return self.row(q, line, depth + 1, start, end);
                }
            }
        }
        false
    }
}

/// Cells scanned at once for a wall or a near cell (branch-free within).
const CHUNK: usize = 32;

/// The Unknown cells among `cells`, summed in bytes a chunk at a time (a
/// chunk of at most 255 cells cannot overflow its byte).
#[inline]
fn count_unknown(cells: &[u8]) -> usize {
    cells
        .chunks(128)
        .map(|chunk| usize::from(chunk.iter().fold(0u8, |n, &c| n + (c & UNKNOWN))))
        .sum()
}

/// The index of the first wall in `cells`, or its length: whole chunks
/// without a wall are passed over at once.
#[inline]
fn first_wall(cells: &[u8]) -> usize {
    let mut at = 0;
    for chunk in cells.chunks(CHUNK) {
        if chunk.iter().fold(0, |m, &c| m | (c & WALL)) != 0 {
            return at + chunk.iter().position(|&c| c == WALL).unwrap_or(chunk.len());
        }
        at += chunk.len();
    }
    at
}

/// `depth · s` as a whole number and a rest in `0..s.den` of `s.den`ths.
#[inline]
fn whole_and_rest(depth: i64, s: Slope) -> (i64, i64) {
    let n = depth * s.num;
    (n.div_euclid(s.den), n.rem_euclid(s.den))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::sensing::visible_cells;

    /// The cell-by-cell sweep's answer: Unknown cells in view, and the near
    /// ones in the order it meets them.
    fn by_cells(
        g: &GridGeometry,
        states: &[CellState],
        near: &[bool],
        origin: Cell,
        range: f64,
    ) -> (usize, Vec<usize>) {
        let (mut unknown, mut seen) = (0, Vec::new());
        visible_cells(
            g,
            origin,
            range,
            |i| states[i] == CellState::Occupied,
            |i| {
                if states[i] == CellState::Unknown {
                    unknown += 1;
                    if near[i] {
                        seen.push(i);
                    }
                }
                false
            },
        );
        (unknown, seen)
    }

    proptest::proptest! {
        /// On random maps, from any cell and at any range, the sweep by runs
        /// counts what the cell-by-cell sweep counts and meets the near cells
        /// in the same order; with a stop it ends once the full count would
        /// satisfy it, and only then.
        #[test]
        fn runs_count_what_the_cells_count(
            w in 1usize..40,
            h in 1usize..30,
            cells in proptest::collection::vec((0u8..6, proptest::bool::ANY), 40 * 30),
            at in (0usize..40, 0usize..30),
            range in 0.0f64..45.0,
            need in 0usize..60,
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let pick = |c: u8| match c {
                0 | 1 => CellState::Unknown,
                2 | 3 => CellState::Free,
                _ => CellState::Occupied,
            };
            let states: Vec<CellState> = cells[..w * h].iter().map(|&(c, _)| pick(c)).collect();
            let near: Vec<bool> = cells[..w * h]
                .iter()
                .zip(&states)
                .map(|(&(_, n), &s)| n && s == CellState::Unknown)
                .collect();
            let origin = Cell::new(at.0 % w, at.1 % h);
            let mut classes = ViewClasses::new(&g, &states);
            for (i, &n) in near.iter().enumerate().filter(|(_, &n)| n) {
                classes.set(i, states[i], n);
            }
            let (unknown, seen) = by_cells(&g, &states, &near, origin, range);
            let mut listed = Vec::new();
            let counted = classes.count(&g, origin, range, &mut |i| listed.push(i), &|_, _| false);
            proptest::prop_assert_eq!(counted, (unknown, seen.len()));
            proptest::prop_assert_eq!(&listed, &seen);
            let enough = move |_: usize, n: usize| n >= need;
            let (_, n) = classes.count(&g, origin, range, &mut |_| {}, &enough);
            proptest::prop_assert_eq!(n >= need, seen.len() >= need);
            proptest::prop_assert!(n <= seen.len());
        }
    }

    #[test]
    fn one_division_rounds_as_the_cell_sweep_does() {
        use crate::sensing::shadowcast::{round_ties_down, round_ties_up};
        for depth in 1..40 {
            for den in 1..30 {
                for num in -2 * den..=2 * den {
                    let s = Slope { num, den };
                    let (w, r) = whole_and_rest(depth, s);
                    let x = (depth * num) as f64 / den as f64;
                    assert_eq!(w + i64::from(2 * r >= den), round_ties_up(depth, s));
                    assert_eq!(w + i64::from(2 * r > den), round_ties_down(depth, s));
                    assert_eq!(w + i64::from(r > 0), x.ceil() as i64);
                    assert_eq!(w, x.floor() as i64);
                }
            }
        }
    }

    #[test]
    fn classes_follow_their_cells() {
        let g = GridGeometry::new(3, 2, 0.1, Point::default());
        let states = vec![CellState::Unknown; 6];
        let mut c = ViewClasses::new(&g, &states);
        c.set(5, CellState::Occupied, false);
        c.set(1, CellState::Unknown, true);
        assert_eq!(c.rows, [UNKNOWN, NEAR, UNKNOWN, UNKNOWN, UNKNOWN, WALL]);
        // Column-major: (x, y) at x * 2 + y.
        assert_eq!(c.cols, [UNKNOWN, UNKNOWN, NEAR, UNKNOWN, UNKNOWN, WALL]);
    }
}
