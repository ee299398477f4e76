//! Where a robot may stand and drive on the knowledge map.
//!
//! A cell is *traversable* when it is known Free and its clearance from every known
//! obstacle, every Unknown cell and the grid's edge is at least the robot radius.
//! Keeping clear of Unknown cells too means a later scan can never reveal a wall
//! inside the robot's footprint, so a robot is never sealed in where it stands.
//! A robot that starts in a tighter spot may still leave through its *escape
//! region*: the known-Free cells connected to it within one robot radius plus two
//! cells.
//!
//! Clearance is measured from a cell's centre to the nearest obstacle cell's centre
//! minus half a cell (the exact gap for axis-aligned neighbours).
//!
//! # How it is computed
//!
//! Only the bounding box of the known cells matters: everything outside it is
//! Unknown. No full Euclidean distance transform is needed:
//!
//! - *Traversable* is a threshold on the distance `d` to the nearest non-Free cell
//!   of the box plus a one-cell ring (the *window*), so it is a threshold `T` on the
//!   integer squared distance: a Free cell is traversable iff no non-Free cell of
//!   the window lies within `d² < T`, i.e. iff in each of the few columns `x + dx`
//!   with `dx² < T` the vertical distance to the nearest non-Free cell is at least
//!   `⌈√(T − dx²)⌉`. The vertical distances come from two linear sweeps per column
//!   (saturated at the largest threshold, so they usually fit a byte). `T` is found
//!   by evaluating the very same `f32` expression as the metric rule at the
//!   candidate distances `√n`, so the result is bit-for-bit that of the metric rule.
//! - The clearance to known Occupied cells (the `1/P` of Eq. 1) is only needed at a
//!   few candidate cells: the Occupied cells are kept as sorted rows per column, and
//!   [`Traversability::clearance_at`] walks the columns outward from the cell, taking
//!   the nearest Occupied cell of each, until no closer one can exist.

use std::sync::Arc;

use crate::geom::Cell;
use crate::grid::window::Window;
use crate::grid::{CellState, OccupancyGrid};

/// Clearances and drivable cells of one knowledge map.
///
/// The per-cell flags are shared (`Arc`): a robot with no escape region has the
/// same passable as traversable cells, and the rounds of an episode share the
/// cells its [`Drivable`] keeps.
#[derive(Debug, Clone)]
pub struct Traversability {
    /// Per cell: a robot of the given radius may stand here.
    pub traversable: Arc<Vec<bool>>,
    /// Per cell: traversable, or in the escape region of the robot.
    pub passable: Arc<Vec<bool>>,
    clearance: Arc<OccupiedColumns>,
    radius: f64,
    /// Some cell is passable without being traversable.
    escape: bool,
}

/// The known Occupied cells, by column: `columns[x]` holds the rows of the
/// Occupied cells of column `x`, ascending.
#[derive(Debug, Clone)]
struct OccupiedColumns {
    grid_width: usize,
    resolution: f64,
    /// Inclusive bounds of the known cells: outside them the clearance is infinite.
    known: Option<(usize, usize, usize, usize)>,
    columns: Vec<Vec<usize>>,
}

/// The clearance rule in metres for a centre distance of `d` cells: the centre
/// distance minus half a cell, at least 0.
#[inline]
pub(crate) fn clearance_metres(d: f32, res: f64) -> f32 {
    ((d - 0.5).max(0.0) as f64 * res) as f32
}

/// The distance in cells of a squared centre distance, as the exact Euclidean
/// distance transform gives it.
#[inline]
fn distance_of(d2: u64) -> f32 {
    (d2 as f64).sqrt() as f32
}

impl Traversability {
    /// Computes clearances for `knowledge` and the drivable cells of a robot of
    /// `radius` metres standing at `robot` (its escape region is passable).
    pub fn new(knowledge: &OccupancyGrid, radius: f64, robot: Cell) -> Self {
        Drivable::new(knowledge, radius).for_robot(knowledge, robot)
    }

    /// [`Traversability::new`], taken from `kept` when it is kept for robots of
    /// `radius` metres.
    pub fn kept_or_new(
        kept: Option<&Drivable>,
        knowledge: &OccupancyGrid,
        radius: f64,
        robot: Cell,
    ) -> Self {
        match kept {
            Some(d) if d.radius() == radius => d.for_robot(knowledge, robot),
            _ => Self::new(knowledge, radius, robot),
        }
    }

    /// The drivable cells of robots of `radius` metres with no escape region:
    /// `passable` equals `traversable`. For robots that only pass through the map
    /// another robot stands on (another robot's escape region is no way for them).
    pub fn without_escape(knowledge: &OccupancyGrid, radius: f64) -> Self {
        Drivable::new(knowledge, radius).without_escape()
    }

    /// The robot radius, metres, these cells were computed for.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Whether the robot's escape region holds any cell: some passable cell is
    /// not traversable.
    pub fn has_escape_region(&self) -> bool {
        self.escape
    }

    /// The inclusive bounds `(x0, y0, x1, y1)` of the known cells these cells
    /// were computed from; `None` when no cell is known.
    pub(crate) fn known_bounds(&self) -> Option<(usize, usize, usize, usize)> {
        self.clearance.known
    }

    /// Metres from the centre of cell `index` to the nearest known Occupied cell
    /// (centre distance minus half a cell, at least 0; the `1/P` of Eq. 1);
    /// `f32::INFINITY` if none is known or the cell lies outside the bounding box of
    /// the known cells.
    pub fn clearance_at(&self, index: usize) -> f32 {
        self.clearance.at(index)
    }
}

/// The traversable cells and clearances of robots of one radius on a knowledge
/// map, kept up to date scan by scan ([`Drivable::update`]): whether a cell is
/// traversable depends only on the cells within the robot's radius of it, so a
/// scan changes it only that close to the cells it revealed. Each round takes
/// its [`Traversability`] from here ([`Drivable::for_robot`]) instead of
/// computing one over the whole map.
#[derive(Debug, Clone)]
pub struct Drivable {
    radius: f64,
    rule: Option<SafeRule>,
    traversable: Arc<Vec<bool>>,
    clearance: Arc<OccupiedColumns>,
}

impl Drivable {
    /// The traversable cells and clearances of robots of `radius` metres on
    /// `knowledge`, from scratch.
    pub fn new(knowledge: &OccupancyGrid, radius: f64) -> Self {
        let g = *knowledge.geometry();
        let res = g.resolution;
        let k = knowledge.cells();
        let (w, h) = (g.width, g.height);
        let n = g.len();
        let known = knowledge.bounds_of(|c| c != CellState::Unknown);
        let rule = SafeRule::new(radius, res, w, h);
        let drivable = || {
            let mut traversable = vec![false; n];
            if let (Some(bounds), Some(rule)) = (known, &rule) {
                mark_traversable(k, w, h, bounds, rule, &mut traversable);
            }
            traversable
        };
        let (clearance, traversable) =
            rayon::join(|| OccupiedColumns::new(k, w, res, known), drivable);
        Self {
            radius,
            rule,
            traversable: Arc::new(traversable),
            clearance: Arc::new(clearance),
        }
    }

    /// The robot radius, metres, these cells are kept for.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Brings the cells up to date with `knowledge` after the cells `changed` (any
    /// changes, in any order, repeats allowed) took new states.
    pub fn update(&mut self, knowledge: &OccupancyGrid, changed: &[usize]) {
        let g = *knowledge.geometry();
        let (w, h) = (g.width, g.height);
        let k = knowledge.cells();
        let Some(changes) = Window::bounding(&g, changed) else {
            return;
        };
        let known = if changed.iter().all(|&i| k[i] != CellState::Unknown) {
            Some(match self.clearance.known {
                Some((x0, y0, x1, y1)) => (
                    x0.min(changes.x0),
                    y0.min(changes.y0),
                    x1.max(changes.x1),
                    y1.max(changes.y1),
                ),
                None => (changes.x0, changes.y0, changes.x1, changes.y1),
            })
        } else {
            knowledge.bounds_of(|c| c != CellState::Unknown)
        };
        Arc::make_mut(&mut self.clearance).update(k, changes, known);
        let Some(rule) = &self.rule else {
            return;
        };
        // The cells within reach of a change, and the window whose cells decide them.
        let reach = rule.reach();
        let cells = changes.grow(reach, &g);
        let window = cells.grow(reach, &g);
        let e = rule.min_edge - 1;
        if w <= 2 * e || h <= 2 * e {
            return;
        }
        let (cx0, cx1) = (cells.x0.max(e), cells.x1.min(w - 1 - e));
        let (cy0, cy1) = (cells.y0.max(e), cells.y1.min(h - 1 - e));
        if cx0 > cx1 || cy0 > cy1 {
            return;
        }
        let traversable = Arc::make_mut(&mut self.traversable);
        let frame = (
            window.x0,
            window.y0,
            window.x1 - window.x0 + 1,
            window.y1 - window.y0 + 1,
        );
        mark_cells(k, w, frame, (cx0, cy0, cx1, cy1), rule, traversable);
    }

    /// The drivable cells of a robot standing at `robot`: the traversable cells
    /// and its escape region (see [`Traversability`]).
    pub fn for_robot(&self, knowledge: &OccupancyGrid, robot: Cell) -> Traversability {
        let start = knowledge.geometry().index(robot);
        if self.traversable[start] {
            // A robot on a traversable cell needs no escape region.
            return self.without_escape();
        }
        let mut passable = Vec::clone(&self.traversable);
        let escape = mark_escape_region(knowledge, robot, self.radius, &mut passable);
        Traversability {
            traversable: Arc::clone(&self.traversable),
            passable: Arc::new(passable),
            clearance: Arc::clone(&self.clearance),
            radius: self.radius,
            escape,
        }
    }

    /// The drivable cells of robots with no escape region
    /// ([`Traversability::without_escape`]).
    pub fn without_escape(&self) -> Traversability {
        Traversability {
            traversable: Arc::clone(&self.traversable),
            passable: Arc::clone(&self.traversable),
            clearance: Arc::clone(&self.clearance),
            radius: self.radius,
            escape: false,
        }
    }
}

impl OccupiedColumns {
    fn new(
        k: &[CellState],
        w: usize,
        resolution: f64,
        known: Option<(usize, usize, usize, usize)>,
    ) -> Self {
        let mut columns = Self {
            grid_width: w,
            resolution,
            known,
            columns: vec![Vec::new(); w],
        };
        if let Some((x0, y0, x1, y1)) = known {
            columns.fill(k, (x0, y0, x1, y1));
        }
        columns
    }

    /// Appends the Occupied cells of the window `(x0, y0, x1, y1)` to their
    /// columns, row by row.
    fn fill(&mut self, k: &[CellState], (x0, y0, x1, y1): (usize, usize, usize, usize)) {
        let w = self.grid_width;
        for y in y0..=y1 {
            let row = &k[y * w + x0..=y * w + x1];
            for (column, &s) in self.columns[x0..=x1].iter_mut().zip(row) {
                if s == CellState::Occupied {
                    column.push(y);
                }
            }
        }
    }

    /// Takes the Occupied cells of `window` from `k` again, with the known cells'
    /// bounds `known`.
    fn update(
        &mut self,
        k: &[CellState],
        window: Window,
        known: Option<(usize, usize, usize, usize)>,
    ) {
        let w = self.grid_width;
        self.known = known;
        for x in window.x0..=window.x1 {
            let column = &mut self.columns[x];
            let a = column.partition_point(|&r| r < window.y0);
            let b = column.partition_point(|&r| r <= window.y1);
            let rows = (window.y0..=window.y1).filter(|&y| k[y * w + x] == CellState::Occupied);
            column.splice(a..b, rows);
        }
    }

    fn at(&self, index: usize) -> f32 {
        let (x, y) = (index % self.grid_width, index / self.grid_width);
        let Some((x0, y0, x1, y1)) = self.known else {
            return f32::INFINITY;
        };
        if x < x0 || x > x1 || y < y0 || y > y1 {
            return f32::INFINITY;
        }
        let bw = x1 - x0 + 1;
        let bx = x - x0;
        // Vertical distance from row y to the nearest Occupied cell of column c.
        let vertical = |c: usize| -> Option<u64> {
            let rows = &self.columns[x0 + c];
            let p = rows.partition_point(|&r| r < y);
            let below = p.checked_sub(1).map(|q| y - rows[q]);
            let above = rows.get(p).map(|&r| r - y);
            below.into_iter().chain(above).min().map(|v| v as u64)
        };
        // Walk the columns outward; a column dx away cannot beat `best` once
        // dx² ≥ best.
        let mut best = u64::MAX;
        for dx in 0..bw {
            let dx2 = (dx * dx) as u64;
            if dx2 >= best || (dx > bx && bx + dx >= bw) {
                break;
            }
            for c in [bx.checked_sub(dx), Some(bx + dx).filter(|_| dx > 0)] {
                if let Some(g) = c.filter(|&c| c < bw).and_then(vertical) {
                    best = best.min(dx2 + g * g);
                }
            }
        }
        if best == u64::MAX {
            f32::INFINITY
        } else {
            clearance_metres(distance_of(best), self.resolution)
        }
    }
}

/// The traversability rule `clearance_metres(min(d, edge)) ≥ radius − 1e-6` turned into
/// integer thresholds: the squared distance `d²` to the nearest non-Free cell at
/// least some `T`, and `edge ≥ min_edge`.
#[derive(Debug, Clone)]
struct SafeRule {
    /// Smallest distance to the grid's edge (1 for the outermost cells) that passes.
    min_edge: usize,
    /// `need[dx]`: the vertical distance column `x ± dx` must keep, for every `dx`
    /// with `dx² < T` (`dx² + need[dx]² ≥ T`); non-increasing.
    need: Vec<u32>,
}

impl SafeRule {
    /// How many cells away a non-Free cell can still make a cell fail the rule:
    /// a change decides the cells at most this far from it.
    fn reach(&self) -> usize {
        // A cell fails on a non-Free cell dx columns away (dx < need.len()) closer
        // than need[dx] rows.
        let vertical = self.need.first().map_or(0, |&v| v as usize);
        vertical.max(self.need.len()).saturating_sub(1)
    }

    /// `None` if no cell of a `w × h` grid can pass.
    fn new(radius: f64, res: f64, w: usize, h: usize) -> Option<Self> {
        let need_m = radius as f32 - 1e-6;
        // The rule is monotone in the distance: find its thresholds by bisection on
        // the exact f32 values the metric rule compares.
        let passes = |d: f32| clearance_metres(d, res) >= need_m;
        let max_edge = (w.min(h).max(1) - 1) / 2 + 1;
        let edge_passes = |e: usize| passes(e as f32);
        if !edge_passes(max_edge) {
            return None;
        }
        let (mut lo, mut hi) = (1usize, max_edge); // hi passes
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if edge_passes(mid) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        let min_edge = lo;
        // min_edge² passes (its square root is exact), so T is at most that.
        let (mut lo, mut hi) = (0u64, (min_edge as u64) * (min_edge as u64));
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if passes(distance_of(mid)) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        let t = lo;
        let mut need = Vec::new();
        let mut dx = 0u64;
        while dx * dx < t {
            let rest = t - dx * dx;
            let mut v = (rest as f64).sqrt() as u64;
            while v * v < rest {
                v += 1;
            }
            while v > 0 && (v - 1) * (v - 1) >= rest {
                v -= 1;
            }
            need.push(v.min(u32::MAX as u64) as u32);
            dx += 1;
        }
        Some(Self { min_edge, need })
    }
}

/// Unsigned vertical distances, saturating at the type's maximum.
trait Vertical: Copy + Ord + 'static {
    const ZERO: Self;
    const FAR: Self;
    fn step(self) -> Self;
    fn from_need(need: u32) -> Self;
    /// Runs `f` with a buffer of this type, reused across calls where it pays.
    fn with_buffer<R>(f: impl FnOnce(&mut Vec<Self>) -> R) -> R {
        f(&mut Vec::new())
    }
}

/// The largest byte buffer a thread keeps for the next call.
const KEEP_BYTES: usize = 1 << 24;

thread_local! {
    /// The byte buffer of [`mark_traversable`], kept per thread so that repeated
    /// calls reuse its memory instead of faulting in fresh pages.
    static BYTES: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

macro_rules! vertical {
    ($t:ty $(, $with:item)?) => {
        impl Vertical for $t {
            $($with)?
            const ZERO: Self = 0;
            const FAR: Self = <$t>::MAX;
            #[inline]
            fn step(self) -> Self {
                self.saturating_add(1)
            }
            #[inline]
            fn from_need(need: u32) -> Self {
                // Callers pick a type whose maximum exceeds every need.
                need as $t
            }
        }
    };
}
vertical!(
    u8,
    fn with_buffer<R>(f: impl FnOnce(&mut Vec<Self>) -> R) -> R {
        let mut buffer = BYTES.with(|b| std::mem::take(&mut *b.borrow_mut()));
        let result = f(&mut buffer);
        if buffer.capacity() <= KEEP_BYTES {
            BYTES.with(|b| *b.borrow_mut() = buffer);
        }
        result
    }
);
vertical!(u16);
vertical!(u32);

/// Marks the traversable cells of the known box `(x0, y0, x1, y1)` of a `w × h`
/// grid. Vertical distances to non-Free cells are taken over the window (the box
/// plus a one-cell ring: everything beyond it is Unknown).
fn mark_traversable(
    k: &[CellState],
    w: usize,
    h: usize,
    (x0, y0, x1, y1): (usize, usize, usize, usize),
    rule: &SafeRule,
    traversable: &mut [bool],
) {
    let e = rule.min_edge - 1;
    // Cells at least `e` cells from every edge (edge distance min_edge or more).
    if w <= 2 * e || h <= 2 * e {
        return;
    }
    let (cx0, cx1) = (x0.max(e), x1.min(w - 1 - e));
    let (cy0, cy1) = (y0.max(e), y1.min(h - 1 - e));
    if cx0 > cx1 || cy0 > cy1 {
        return;
    }
    // The window.
    let (sx0, sy0) = (x0.saturating_sub(1), y0.saturating_sub(1));
    let (sx1, sy1) = ((x1 + 1).min(w - 1), (y1 + 1).min(h - 1));
    let (sw, sh) = (sx1 - sx0 + 1, sy1 - sy0 + 1);
    mark_cells(
        k,
        w,
        (sx0, sy0, sw, sh),
        (cx0, cy0, cx1, cy1),
        rule,
        traversable,
    );
}

/// [`mark_window`] with vertical distances in the smallest type that holds every
/// `need` (saturated at its maximum, which exceeds every `need`).
fn mark_cells(
    k: &[CellState],
    w: usize,
    frame: (usize, usize, usize, usize),
    cells: (usize, usize, usize, usize),
    rule: &SafeRule,
    traversable: &mut [bool],
) {
    let max_need = rule.need.first().copied().unwrap_or(0);
    if max_need < u8::MAX as u32 {
        u8::with_buffer(|g| mark_window(k, w, frame, cells, rule, g, traversable));
    } else if max_need < u16::MAX as u32 {
        u16::with_buffer(|g| mark_window(k, w, frame, cells, rule, g, traversable));
    } else {
        u32::with_buffer(|g| mark_window(k, w, frame, cells, rule, g, traversable));
    }
}

/// Marks the traversable cells `(cx0, cy0)..=(cx1, cy1)` from the non-Free cells
/// of the window `(sx0, sy0, sw, sh)`, with `g` as the buffer of vertical
/// distances: every cell of the window that could make one of them fail the rule
/// must lie in the window (the grid's edges apart, which `min_edge` rules).
fn mark_window<T: Vertical>(
    k: &[CellState],
    w: usize,
    (sx0, sy0, sw, sh): (usize, usize, usize, usize),
    (cx0, cy0, cx1, cy1): (usize, usize, usize, usize),
    rule: &SafeRule,
    g: &mut Vec<T>,
    traversable: &mut [bool],
) {
    // Vertical distance to the nearest non-Free cell of the window, same column:
    // down the rows, then up.
    g.clear();
    g.resize(sw * sh, T::FAR);
    for y in 0..sh {
        let krow = &k[(sy0 + y) * w + sx0..][..sw];
        let (done, rest) = g.split_at_mut(y * sw);
        let row = &mut rest[..sw];
        if y == 0 {
            for (v, &c) in row.iter_mut().zip(krow) {
                *v = if c != CellState::Free {
                    T::ZERO
                } else {
                    T::FAR
                };
            }
        } else {
            let prev = &done[(y - 1) * sw..];
            for ((v, &c), &p) in row.iter_mut().zip(krow).zip(prev) {
                *v = if c != CellState::Free {
                    T::ZERO
                } else {
                    p.step()
                };
            }
        }
    }
    for y in (0..sh.saturating_sub(1)).rev() {
        let (row, below) = g[y * sw..].split_at_mut(sw);
        for (a, &b) in row.iter_mut().zip(&below[..sw]) {
            *a = (*a).min(b.step());
        }
    }
    let need: Vec<T> = rule.need.iter().map(|&v| T::from_need(v)).collect();
    let wx0 = cx0 - sx0;
    let len = cx1 - cx0 + 1;
    for y in cy0..=cy1 {
        let grow = &g[(y - sy0) * sw..][..sw];
        let out = &mut traversable[y * w + cx0..][..len];
        let krow = &k[y * w + cx0..][..len];
        for (o, &c) in out.iter_mut().zip(krow) {
            *o = c == CellState::Free;
        }
        for (dx, &need) in need.iter().enumerate() {
            // Column wx0 + i + dx, for the i that stay inside the window.
            if wx0 + dx < sw {
                for (o, &b) in out.iter_mut().zip(&grow[wx0 + dx..]) {
                    *o &= b >= need;
                }
            }
            if dx == 0 {
                continue;
            }
            // Column wx0 + i − dx: i starts where it is inside the window.
            let skip = dx.saturating_sub(wx0);
            if skip < len {
                for (o, &b) in out[skip..].iter_mut().zip(&grow[wx0 + skip - dx..]) {
                    *o &= b >= need;
                }
            }
        }
    }
}

/// Marks the known-Free cells connected to `robot` within `radius` plus two cells;
/// whether any cell was marked.
fn mark_escape_region(
    knowledge: &OccupancyGrid,
    robot: Cell,
    radius: f64,
    passable: &mut [bool],
) -> bool {
    let g = knowledge.geometry();
    let reach = radius / g.resolution + 2.0;
    let reach2 = reach * reach;
    let start = g.index(robot);
    // A robot on a traversable cell needs no escape: a region that let it cross a
    // pinch between two traversable regions would be a one-way valve.
    if passable[start] {
        return false;
    }
    if knowledge.get(robot) != CellState::Free {
        passable[start] = true;
        return true;
    }
    passable[start] = true;
    let mut stack = vec![robot];
    let mut seen = std::collections::HashSet::new();
    seen.insert(start);
    while let Some(c) = stack.pop() {
        for (dx, dy) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
            let Some(n) = g.checked_cell(c.x as i64 + dx, c.y as i64 + dy) else {
                continue;
            };
            let (ex, ey) = (n.x as f64 - robot.x as f64, n.y as f64 - robot.y as f64);
            let j = g.index(n);
            // Stop at traversable cells: the escape leads to them, not through them.
            if passable[j]
                || ex * ex + ey * ey > reach2
                || knowledge.get(n) != CellState::Free
                || !seen.insert(j)
            {
                continue;
            }
            passable[j] = true;
            stack.push(n);
        }
    }
    true
}

#[cfg(test)]
mod tests;
