//! Connected parts: of the obstacle cells (step 2) and of the skeleton
//! ([`super::Gvd::edge_component`]).

use std::ops::RangeInclusive;

use super::NONE;
use crate::grid::window::Window;
use crate::grid::GridGeometry;

/// Labels of the 8-connected components of the obstacle cells, with the buffers
/// kept between calls.
#[derive(Debug, Default)]
pub(super) struct Components {
    /// Width of the window labelled last.
    pw: usize,
    /// Runs of obstacle cells: (row, first column, last column), row by row.
    runs: Vec<(usize, usize, usize)>,
    /// Per row: the index of its first run (and one past the last row: the
    /// number of runs).
    row_start: Vec<usize>,
    parent: Vec<u32>,
    /// Per cell: its component's label ([`NONE`] off the obstacles).
    pub(super) label: Vec<u32>,
}

impl Components {
    /// Labels of the 8-connected components of the obstacle cells ([`NONE`]
    /// elsewhere): a component's label is the index of its first cell in row
    /// order, shared by its cells and no other's.
    ///
    /// Union-find over the row runs of obstacle cells: a run joins every run of
    /// the row below that overlaps it or touches it diagonally. Linear in the
    /// cells, and fast where obstacles are large solid areas.
    pub(super) fn label(&mut self, pw: usize, ph: usize, obstacle: &[bool]) -> &[u32] {
        self.pw = pw;
        self.runs.clear();
        self.row_start.clear();
        for y in 0..ph {
            self.row_start.push(self.runs.len());
            push_runs(&mut self.runs, y, &obstacle[y * pw..][..pw]);
        }
        self.row_start.push(self.runs.len());
        self.join();
        self.label.clear();
        self.label.resize(pw * ph, NONE);
        for i in 0..self.runs.len() {
            self.fill_run(i);
        }
        &self.label
    }

    /// [`Self::label`] after the obstacle cells changed only in `rows` (and
    /// within `cols`) since the last labelling of this window: the runs of
    /// those rows found again, the components joined again over the runs, and
    /// the labels written where they change (every run of `rows`, and the runs
    /// elsewhere whose component's first cell moved).
    pub(super) fn relabel(
        &mut self,
        obstacle: &[bool],
        rows: RangeInclusive<usize>,
        cols: RangeInclusive<usize>,
    ) {
        let pw = self.pw;
        let (y0, y1) = (*rows.start(), *rows.end());
        let ph = self.row_start.len().saturating_sub(1);
        if y0 > y1 || y1 >= ph {
            return;
        }
        let (lo, hi) = (self.row_start[y0], self.row_start[y1 + 1]);
        let mut fresh = Vec::new();
        let mut starts = Vec::with_capacity(y1 - y0 + 1);
        for y in rows.clone() {
            starts.push(lo + fresh.len());
            push_runs(&mut fresh, y, &obstacle[y * pw..][..pw]);
        }
        let shift = fresh.len() as isize - (hi - lo) as isize;
        self.runs.splice(lo..hi, fresh.iter().copied());
        self.row_start[y0..=y1].copy_from_slice(&starts);
        for s in &mut self.row_start[y1 + 1..] {
            *s = s.wrapping_add_signed(shift);
        }
        self.join();
        // Cells of the changed rows that are no obstacle any more.
        for y in rows {
            for x in cols.clone() {
                if !obstacle[y * pw + x] {
                    self.label[y * pw + x] = NONE;
                }
            }
        }
        let changed = self.row_start[y0]..self.row_start[y1 + 1];
        for i in 0..self.runs.len() {
            let (y, a, _) = self.runs[i];
            if changed.contains(&i) || self.label[y * pw + a] != self.first_cell(i) {
                self.fill_run(i);
            }
        }
    }

    /// Joins the runs into components (union-find; each root is the first
    /// run of its component).
    fn join(&mut self) {
        let Self {
            runs,
            row_start,
            parent,
            ..
        } = self;
        parent.clear();
        parent.extend(0..runs.len() as u32);
        let ph = row_start.len().saturating_sub(1);
        for y in 1..ph {
            let below = row_start[y - 1]..row_start[y];
            let mut j = below.start;
            for i in row_start[y]..row_start[y + 1] {
                let (_, a0, a1) = runs[i];
                // Runs of the row below that end before this run starts (diagonal
                // contact allowed) cannot touch later runs either.
                while j < below.end && runs[j].2 + 1 < a0 {
                    j += 1;
                }
                let mut k = j;
                while k < below.end && runs[k].1 <= a1 + 1 {
                    unite(parent, i as u32, k as u32);
                    k += 1;
                }
            }
        }
    }

    /// The label of run `i`'s component: the index of its first cell.
    fn first_cell(&mut self, i: usize) -> u32 {
        let r = root(&mut self.parent, i as u32) as usize;
        let (y, a, _) = self.runs[r];
        (y * self.pw + a) as u32
    }

    /// Writes run `i`'s label into its cells.
    fn fill_run(&mut self, i: usize) {
        let l = self.first_cell(i);
        let (y, a, b) = self.runs[i];
        let row = y * self.pw;
        self.label[row + a..=row + b].fill(l);
    }
}

/// The root of `i` in the union-find forest `parent`, halving the path.
fn root(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// Joins the trees of `a` and `b` in the union-find forest `parent`: the
/// smaller root stays a root, so every root is its tree's least element.
fn unite(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    parent[ra.max(rb) as usize] = ra.min(rb);
}

/// Appends the runs of obstacle cells of row `y`.
fn push_runs(runs: &mut Vec<(usize, usize, usize)>, y: usize, row: &[bool]) {
    let mut x = 0;
    while x < row.len() {
        if row[x] {
            let first = x;
            while x < row.len() && row[x] {
                x += 1;
            }
            runs.push((y, first, x - 1));
        } else {
            x += 1;
        }
    }
}

impl Components {
    /// The label of a run.
    pub(super) fn run_label(&self, (y, a, _): (usize, usize, usize)) -> u32 {
        self.label[y * self.pw + a]
    }

    /// The number of cells of each component of `labels` (sorted).
    pub(super) fn sizes_of(&self, labels: &[u32]) -> Vec<usize> {
        let mut size = vec![0; labels.len()];
        for &run in &self.runs {
            if let Ok(j) = labels.binary_search(&self.run_label(run)) {
                size[j] += run.2 - run.1 + 1;
            }
        }
        size
    }

    /// The bounding box of the components `labels` (sorted), padded
    /// coordinates; `None` if there are none.
    pub(super) fn bounds_of(&self, labels: &[u32]) -> Option<Window> {
        let mut b: Option<Window> = None;
        for &run in &self.runs {
            if labels.binary_search(&self.run_label(run)).is_err() {
                continue;
            }
            let (y, x0, x1) = run;
            b = Some(match b {
                None => Window {
                    x0,
                    y0: y,
                    x1,
                    y1: y,
                },
                Some(w) => Window {
                    x0: w.x0.min(x0),
                    y0: w.y0.min(y),
                    x1: w.x1.max(x1),
                    y1: w.y1.max(y),
                },
            });
        }
        b
    }
}

/// [`Components::label`] with fresh buffers.
#[cfg(test)]
pub(super) fn components(pw: usize, ph: usize, obstacle: &[bool]) -> Vec<u32> {
    Components::default().label(pw, ph, obstacle).to_vec()
}

/// Labels of the connected parts of the skeleton: 8-neighbouring skeleton cells
/// are connected where a diagonal step has both cells beside it passable (the
/// steps the path search takes), written into `label` ([`NONE`] everywhere
/// before, and left so off the skeleton); `cells`: the skeleton's cells in
/// increasing index, which number the parts in the order of their first cell.
///
/// One pass in raster order joins each cell with its neighbours already
/// passed (west, and the three of the row before), in a union-find over the
/// cells' positions in `cells` whose roots are the parts' first cells; a
/// second pass numbers the roots in order and labels every cell. Both passes
/// read the map row by row, where a search from each part's first cell
/// jumped along the skeleton.
pub(super) fn edge_components(
    g: &GridGeometry,
    passable: &[bool],
    skeleton: &[bool],
    label: &mut [u32],
    cells: &[usize],
) {
    let w = g.width;
    // Per position in `cells`: a smaller position of its part (itself at the
    // root, the part's first cell).
    let mut parent: Vec<u32> = Vec::with_capacity(cells.len());
    for (k, &i) in cells.iter().enumerate() {
        // Positions fit: a grid has fewer than 2³² cells.
        let k = k as u32;
        parent.push(k);
        // While labelling, a passed skeleton cell's label holds its position.
        label[i] = k;
        let (x, y) = (i % w, i / w);
        let join = |j: usize, parent: &mut [u32]| {
            if skeleton[j] && label[j] != NONE {
                unite(parent, label[j], k);
            }
        };
        if x > 0 {
            join(i - 1, &mut parent);
        }
        if y > 0 {
            let above = i - w;
            join(above, &mut parent);
            // A diagonal step needs both cells beside it passable.
            if x > 0 && passable[i - 1] && passable[above] {
                join(above - 1, &mut parent);
            }
            if x + 1 < w && passable[i + 1] && passable[above] {
                join(above + 1, &mut parent);
            }
        }
    }
    // The parts numbered in the order of their first cells.
    let mut number = vec![NONE; cells.len()];
    let mut next = 0u32;
    for (k, &i) in cells.iter().enumerate() {
        let r = root(&mut parent, k as u32) as usize;
        if r == k {
            number[k] = next;
            next += 1;
        }
        label[i] = number[r];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use proptest::prelude::*;

    /// The parts found by a search from each part's first cell.
    fn by_search(
        g: &GridGeometry,
        passable: &[bool],
        skeleton: &[bool],
        cells: &[usize],
    ) -> Vec<u32> {
        let (w, h) = (g.width as i64, g.height as i64);
        let mut label = vec![NONE; g.len()];
        let mut next = 0u32;
        for &start in cells {
            if label[start] != NONE {
                continue;
            }
            label[start] = next;
            let mut stack = vec![start];
            while let Some(i) = stack.pop() {
                let (x, y) = ((i as i64) % w, (i as i64) / w);
                for dy in -1..=1i64 {
                    for dx in -1..=1i64 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= w || ny >= h {
                            continue;
                        }
                        let j = (ny * w + nx) as usize;
                        if !skeleton[j] || label[j] != NONE {
                            continue;
                        }
                        if dx != 0
                            && dy != 0
                            && (!passable[(y * w + nx) as usize]
                                || !passable[(ny * w + x) as usize])
                        {
                            continue;
                        }
                        label[j] = next;
                        stack.push(j);
                    }
                }
            }
            next += 1;
        }
        label
    }

    proptest! {
        /// Random skeletons over random passable cells (skeleton cells need
        /// not be passable, as the rule does not ask): the raster labels are
        /// the search's, part numbers included.
        #[test]
        fn raster_parts_are_the_searchs(
            w in 1usize..20,
            h in 1usize..20,
            bits in prop::collection::vec(0u8..16, 400),
            open in prop::collection::vec(0u8..4, 400),
            skeleton_share in 2u8..12,
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let skeleton: Vec<bool> = bits[..w * h].iter().map(|&b| b < skeleton_share).collect();
            let passable: Vec<bool> = open[..w * h].iter().map(|&b| b != 0).collect();
            let cells: Vec<usize> = (0..w * h).filter(|&i| skeleton[i]).collect();
            let mut label = vec![NONE; w * h];
            edge_components(&g, &passable, &skeleton, &mut label, &cells);
            prop_assert_eq!(label, by_search(&g, &passable, &skeleton, &cells));
        }
    }
}
