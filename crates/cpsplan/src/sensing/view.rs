//! Certain lines of sight for CPS links (DESIGN.md "Visibility"; paper section
//! IV-B): which cells a robot at one cell can measure, or be measured from, with
//! the instrument.
//!
//! In: the knowledge map, a position and the [`LinkRule`]. Out: the [`View`] from
//! it and the cells two positions both see ([`mutual_view`]), from which the AND
//! region of section IV-B is cut. A cell is seen when it is known-Free, between
//! the range limits (centre to centre), and the straight segment between the two
//! centres keeps more than the sight clearance from every cell that is not
//! known-Free, cells taken as full closed squares ([`super::sight_clear`]): a line
//! that touches a wall cell's corner is blocked. The rule is symmetric.
//!
//! Without a sight clearance (the default) one sweep finds exactly these cells
//! ([`super::certain_cells`]). With a clearance, the scanner's shadowcasting
//! sweep ([`super::visible_cells`], with every non-Free cell opaque) sees a
//! superset of them (it lets lines graze corners), so it selects the candidates
//! and each is then tested exactly ([`SightField`]).

use std::cell::Cell as StdCell;
use std::rc::Rc;

use super::sight::{LinkRule, SightField};
use super::sight_sweep::certain_cells;
use crate::geom::Cell;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};
use crate::sensing::visible_cells;

/// The cells in certain line of sight from one position within range, over the
/// range disc's bounding box (clipped to the grid): only
/// known-Free cells, by the rule of [`LinkRule`]. Without a sight clearance the
/// view is complete when made; with one, the exact sight test of a cell runs the
/// first time the cell is asked about, and its answer is kept.
#[derive(Debug, Clone)]
pub struct View<'k> {
    knowledge: &'k OccupancyGrid,
    /// The sight tests of a rule with a clearance (`None` without one: every
    /// cell's answer is known when the view is made).
    field: Option<Rc<SightField>>,
    from: Cell,
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
    /// The box's width: the states cover the box only, row by row, so that a
    /// view's memory is bounded by the link range, not by the map.
    width: usize,
    state: Vec<StdCell<u8>>,
}

/// Not seen: outside the range limits, not Free, not wanted, or behind a wall for
/// the scanner's sweep.
const UNSEEN: u8 = 0;
/// A candidate whose exact test has not run yet.
const UNTESTED: u8 = 1;
/// Seen: the exact test passed.
const SEEN: u8 = 2;
/// The exact test failed.
const BLOCKED: u8 = 3;

impl<'k> View<'k> {
    /// The view from `from` by `rule`, of every known-Free cell.
    pub fn new(knowledge: &'k OccupancyGrid, from: Cell, rule: LinkRule) -> Self {
        let field = Self::needs_field(knowledge, rule)
            .then(|| Rc::new(SightField::around(knowledge, from, rule)));
        Self::of(knowledge, from, rule, field, |_| true)
    }

    /// Whether views by `rule` on `knowledge` test their cells with a
    /// [`SightField`]: only when the rule keeps a clearance.
    pub fn needs_field(knowledge: &OccupancyGrid, rule: LinkRule) -> bool {
        rule.clearance / knowledge.resolution() > 0.0
    }

    /// The view from `from` by `rule`, of the cells with `wanted(index)` only
    /// (others are reported unseen), with the sight tests of `field` where the
    /// rule keeps a clearance ([`Self::needs_field`]; its window must hold the
    /// range disc, and its clearance must be the rule's): the AND region needs
    /// only the cells a child can stand on.
    pub fn of(
        knowledge: &'k OccupancyGrid,
        from: Cell,
        rule: LinkRule,
        field: Option<Rc<SightField>>,
        wanted: impl Fn(usize) -> bool,
    ) -> Self {
        let g = knowledge.geometry();
        let k = knowledge.cells();
        let res = g.resolution;
        // The disc's radius in whole cells, as the sweep rounds it.
        let r = (rule.max / res).max(0.0);
        let reach = ((r * r + 1e-9).floor().sqrt().floor()) as usize;
        let (x0, y0) = (from.x.saturating_sub(reach), from.y.saturating_sub(reach));
        let x1 = from.x.saturating_add(reach).min(g.width.saturating_sub(1));
        let y1 = from.y.saturating_add(reach).min(g.height.saturating_sub(1));
        let width = x1 + 1 - x0;
        let mut state = vec![UNSEEN; (y1 + 1 - y0) * width];
        let at = |c: Cell| (c.y - y0) * width + (c.x - x0);
        // Every visited cell lies in the disc, so in the box.
        let field = field.filter(|_| Self::needs_field(knowledge, rule));
        if field.is_none() {
            certain_cells(
                g,
                from,
                rule.max / res,
                |i| k[i] != CellState::Free,
                |i, c| {
                    if wanted(i) {
                        state[at(c)] = SEEN;
                    }
                },
            );
        } else {
            visible_cells(
                g,
                from,
                rule.max / res,
                |i| k[i] != CellState::Free,
                |i| {
                    if k[i] == CellState::Free && wanted(i) {
                        state[at(g.cell(i))] = UNTESTED;
                    }
                    false
                },
            );
        }
        // Closer than the minimum range: not measurable.
        let min = rule.min / res;
        let near = min.ceil() as usize;
        for y in from.y.saturating_sub(near).max(y0)..=(from.y + near).min(y1) {
            for x in from.x.saturating_sub(near).max(x0)..=(from.x + near).min(x1) {
                let (dx, dy) = (x as f64 - from.x as f64, y as f64 - from.y as f64);
                if dx * dx + dy * dy < min * min - 1e-9 {
                    state[(y - y0) * width + (x - x0)] = UNSEEN;
                }
            }
        }
        Self {
            knowledge,
            field,
            from,
            x0,
            y0,
            x1,
            y1,
            width,
            state: state.into_iter().map(StdCell::new).collect(),
        }
    }

    /// Whether the cell at state index `j` is seen, testing it if need be.
    fn seen(&self, j: usize) -> bool {
        match self.state[j].get() {
            SEEN => true,
            UNTESTED => {
                let cell = self.cell_of(j);
                // Untested cells exist only with a field.
                let clear = self
                    .field
                    .as_ref()
                    .is_some_and(|f| f.clear(self.knowledge, self.from, cell));
                self.state[j].set(if clear { SEEN } else { BLOCKED });
                clear
            }
            _ => false,
        }
    }

    /// The cell of state index `j`.
    #[inline]
    fn cell_of(&self, j: usize) -> Cell {
        Cell::new(self.x0 + j % self.width, self.y0 + j / self.width)
    }

    /// The grid index of state index `j`.
    #[inline]
    fn index_of(&self, j: usize) -> usize {
        let c = self.cell_of(j);
        c.y * self.knowledge.geometry().width + c.x
    }

    /// Whether the cell at state index `j` may be seen (not yet ruled out).
    #[inline]
    fn candidate(&self, j: usize) -> bool {
        matches!(self.state[j].get(), UNTESTED | SEEN)
    }

    /// Whether `cell` is seen.
    #[inline]
    pub fn sees(&self, cell: Cell) -> bool {
        cell.x >= self.x0
            && cell.y >= self.y0
            && cell.x <= self.x1
            && cell.y <= self.y1
            && self.seen((cell.y - self.y0) * self.width + (cell.x - self.x0))
    }

    /// The grid indices of the cells seen, ascending.
    pub fn cells(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.state.len())
            .filter(|&j| self.seen(j))
            .map(move |j| self.index_of(j))
    }

    /// Whether some cell with `pred(index)` is seen (`pred` is asked first, so
    /// that only cells it accepts are tested).
    pub fn sees_any(&self, pred: impl Fn(usize) -> bool) -> bool {
        (0..self.state.len()).any(|j| self.candidate(j) && pred(self.index_of(j)) && self.seen(j))
    }

    /// The view as a mask over all cells of a grid of `geometry`.
    pub fn to_mask(&self, geometry: &GridGeometry) -> Vec<bool> {
        let mut out = vec![false; geometry.len()];
        for j in 0..self.state.len() {
            let c = self.cell_of(j);
            out[c.y * geometry.width + c.x] = self.seen(j);
        }
        out
    }
}

/// Cells in certain line of sight from `from` by `rule`, as a mask over the grid.
pub fn certain_view(knowledge: &OccupancyGrid, from: Cell, rule: LinkRule) -> Vec<bool> {
    View::new(knowledge, from, rule).to_mask(knowledge.geometry())
}

/// The cells both views see, as ascending grid indices.
pub fn seen_by_both(geometry: &GridGeometry, a: &View, b: &View) -> Vec<u32> {
    let w = geometry.width;
    let (x0, y0) = (a.x0.max(b.x0), a.y0.max(b.y0));
    let (x1, y1) = (a.x1.min(b.x1), a.y1.min(b.y1));
    let mut out = Vec::new();
    if x0 > x1 || y0 > y1 {
        return out;
    }
    for y in y0..=y1 {
        let (ra, rb) = ((y - a.y0) * a.width, (y - b.y0) * b.width);
        for x in x0..=x1 {
            let (ja, jb) = (ra + x - a.x0, rb + x - b.x0);
            if a.candidate(ja) && b.candidate(jb) && a.seen(ja) && b.seen(jb) {
                out.push((y * w + x) as u32);
            }
        }
    }
    out
}

/// Cells in certain line of sight from both parent positions by `rule`, among the
/// cells with `wanted(index)`, as ascending grid indices.
pub fn mutual_view(
    knowledge: &OccupancyGrid,
    parent_from: Cell,
    parent_to: Cell,
    rule: LinkRule,
    wanted: impl Fn(usize) -> bool + Copy,
) -> Vec<u32> {
    let field = View::needs_field(knowledge, rule).then(|| {
        Rc::new(SightField::new(
            knowledge,
            (
                parent_from.x.min(parent_to.x),
                parent_from.y.min(parent_to.y),
                parent_from.x.max(parent_to.x),
                parent_from.y.max(parent_to.y),
            ),
            rule.max / knowledge.resolution(),
            rule.clearance / knowledge.resolution(),
        ))
    });
    let a = View::of(knowledge, parent_from, rule, field.clone(), wanted);
    let b = View::of(knowledge, parent_to, rule, field, wanted);
    seen_by_both(knowledge.geometry(), &a, &b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::fixtures::l_corridor;
    use crate::sensing::sight_clear;

    const RANGE: LinkRule = LinkRule {
        min: 1.3,
        max: 20.0,
        clearance: 0.0,
    };

    proptest::proptest! {
        /// The view is exactly the rule, cell by cell: known-Free, between the
        /// range limits, and a clear line of sight by the full-square test (no
        /// shadowcasting in this reference, so the sweep's candidates are checked
        /// to include every cell the rule admits).
        #[test]
        fn view_is_the_rule(
            w in 3usize..60,
            h in 3usize..60,
            cells in proptest::collection::vec(0u8..5, 3600),
            ox in 0usize..60,
            oy in 0usize..60,
            min in 0.0f64..1.5,
            max in 0.5f64..4.0,
            clearance in proptest::sample::select(vec![0.0, 0.05, 0.1, 0.25]),
        ) {
            let g = GridGeometry::new(w, h, 0.1, crate::Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Free);
            for (i, &v) in cells.iter().enumerate().take(g.len()) {
                let c = g.cell(i);
                match v {
                    0 => k.fill_rect(c.x, c.y, c.x + 1, c.y + 1, CellState::Occupied),
                    1 => k.fill_rect(c.x, c.y, c.x + 1, c.y + 1, CellState::Unknown),
                    _ => {}
                }
            }
            let from = Cell::new(ox % w, oy % h);
            let rule = LinkRule { min, max, clearance };
            let kc = k.cells();
            let plain: Vec<bool> = (0..g.len())
                .map(|i| {
                    let c = g.cell(i);
                    let (dx, dy) = (c.x as f64 - from.x as f64, c.y as f64 - from.y as f64);
                    let d2 = dx * dx + dy * dy;
                    kc[i] == CellState::Free
                        && d2 >= (min / 0.1).powi(2) - 1e-9
                        && d2 <= (max / 0.1).powi(2) + 1e-9
                        && kc[g.index(from)] == CellState::Free
                        && sight_clear(&k, from, c, clearance / 0.1)
                })
                .collect();
            let view = View::new(&k, from, rule);
            let got = view.to_mask(&g);
            for i in 0..g.len() {
                proptest::prop_assert_eq!(got[i], plain[i], "cell {:?}", g.cell(i));
                proptest::prop_assert_eq!(view.sees(g.cell(i)), plain[i]);
            }
        }
    }

    #[test]
    fn certain_view_respects_unknown_and_range() {
        let mut k = l_corridor();
        let from = Cell::new(10, 15);
        let v = certain_view(&k, from, RANGE);
        let g = *k.geometry();
        assert!(
            !v[g.index(Cell::new(12, 15))],
            "closer than the minimum range"
        );
        assert!(v[g.index(Cell::new(40, 15))]);
        assert!(!v[g.index(Cell::new(105, 80))], "around the corner");
        // An Unknown band across the corridor blocks certain sight.
        k.fill_rect(50, 5, 52, 25, CellState::Unknown);
        let v = certain_view(&k, from, RANGE);
        assert!(!v[g.index(Cell::new(60, 15))]);
        assert!(v[g.index(Cell::new(40, 15))]);
    }
}
