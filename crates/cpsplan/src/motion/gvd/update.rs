//! The GVD's obstacle side kept across scans and updated where a scan
//! changed the knowledge map ([`VoronoiField`]).

use std::sync::Arc;

use super::components::Components;
use super::{clearance_of, Field, Gvd, PairTest};
use crate::grid::window::Window;
use crate::grid::{CellState, GridGeometry, OccupancyGrid, Traversability};

/// The GVD's obstacle side kept across scans: the feature transform, the
/// components and the straddling pairs of the whole grid (steps 1–3), brought up
/// to date where a scan changed the knowledge map, from which the diagram of any
/// robot's drivable cells follows ([`Self::diagram`]). The frame is the whole
/// grid, so that it never moves; outside the Free cells' bounding box every cell
/// is an obstacle, and the result equals [`gvd`](super::gvd())'s.
///
/// [`Self::update`] redoes:
/// - the obstacles in the bounding box `W` of the changed cells;
/// - the column pass in `W`'s columns, the row pass in the rows where the column
///   pass changed;
/// - the components, all of them (a removed cell can split a wall far away);
/// - the pairs of the cells whose feature changed; if the partition into
///   components changed on the cells that stayed obstacles, also those of the
///   cells whose feature lies in a piece split off (a split), or every pair (a
///   merge). It suffices to compare the partitions on those cells in `W` + 1: a
///   path of obstacle cells that enters `W` does so through one of them.
#[derive(Debug)]
pub struct VoronoiField {
    pub(super) field: Field,
}

impl VoronoiField {
    /// The field of `knowledge` computed afresh.
    pub fn new(knowledge: &OccupancyGrid) -> Self {
        let g = knowledge.geometry();
        let mut field = Field::default();
        field.compute(knowledge, (0, 0, g.width, g.height));
        Self { field }
    }

    /// Brings the field up to date after the cells `changed` of `knowledge`
    /// changed state (any other cell is as before).
    pub fn update(&mut self, knowledge: &OccupancyGrid, changed: &[usize]) {
        let g = knowledge.geometry();
        let f = &mut self.field;
        let (w, pw, ph) = (g.width, f.pw(), f.bh + 2);
        let k = knowledge.cells();
        // The cells that turned obstacle or stopped being one, in padded indices.
        let pad = |i: usize| (i / w + 1) * pw + i % w + 1;
        let mut flipped: Vec<usize> = changed
            .iter()
            .filter(|&&i| i < k.len() && f.obstacle[pad(i)] != (k[i] != CellState::Free))
            .map(|&i| pad(i))
            .collect();
        flipped.sort_unstable();
        flipped.dedup();
        let padded = GridGeometry::new(pw, ph, 1.0, crate::geom::Point::default());
        let Some(flips) = Window::bounding(&padded, &flipped) else {
            return;
        };
        // The cells of `W` + 1 that were obstacles before, and their components.
        let around = flips.grow(1, &padded);
        let old_label = window_of(&f.components.label, around, pw);
        let old = window_of(&f.obstacle, around, pw);
        for &p in &flipped {
            f.obstacle[p] = !f.obstacle[p];
        }
        let mut changes = Vec::new();
        f.features.update(
            pw,
            ph,
            &f.obstacle,
            (flips.x0..=flips.x1, flips.y0..=flips.y1),
            &mut changes,
        );
        let clearance = Arc::make_mut(&mut f.clearance);
        for &(py, a, b) in &changes {
            let row = py * pw;
            for (c, &d) in clearance[row + a..=row + b]
                .iter_mut()
                .zip(&f.features.d2[row + a..=row + b])
            {
                *c = clearance_of(d);
            }
        }
        f.components
            .relabel(&f.obstacle, flips.y0..=flips.y1, flips.x0..=flips.x1);
        let new_label = window_of(&f.components.label, around, pw);
        let kept: Vec<(u32, u32)> = old
            .iter()
            .zip(old_label.iter().zip(&new_label))
            .enumerate()
            .filter(|&(j, (&was, _))| {
                was && f.obstacle
                    [(around.y0 + j / around.width()) * pw + around.x0 + j % around.width()]
            })
            .map(|(_, (_, (&a, &b)))| (a, b))
            .collect();
        let regrouping = regrouping(kept, &f.components);
        if regrouping == Regrouping::Merged {
            f.all_pairs();
            return;
        }
        let Field {
            obstacle,
            features,
            components,
            right,
            up,
            bw,
            bh,
            ..
        } = f;
        let (bw, bh) = (*bw, *bh);
        let tester = PairTest::new(pw, obstacle, features, &components.label);
        let mut retest = |x: usize, y: usize| {
            if (1..=bw).contains(&x) && (1..=bh).contains(&y) {
                (right[y * pw + x], up[y * pw + x]) = tester.pairs(x, y);
            }
        };
        // The pairs of a cell read its own feature and those of its right and
        // upper neighbours: the changed cells and their left and lower
        // neighbours are tested again, each once. A changed row is tested over
        // its span merged with the span of the changed row above it (its cells'
        // upper neighbours); the row below a changed row is tested on its own
        // only when it did not change itself.
        let span = |&(_, a, b): &(usize, usize, usize)| (a.saturating_sub(1), b);
        let mut retest_row = |y: usize, (lo, hi): (usize, usize)| {
            for x in lo..=hi {
                retest(x, y);
            }
        };
        for (i, change) in changes.iter().enumerate() {
            let (py, here) = (change.0, span(change));
            if py > 0 && (i == 0 || changes[i - 1].0 + 1 != py) {
                retest_row(py - 1, here);
            }
            match changes.get(i + 1).filter(|next| next.0 == py + 1).map(span) {
                Some(above) if above.0 <= here.1 + 1 && here.0 <= above.1 + 1 => {
                    retest_row(py, (here.0.min(above.0), here.1.max(above.1)));
                }
                Some(above) => {
                    retest_row(py, here);
                    retest_row(py, above);
                }
                None => retest_row(py, here),
            }
        }
        if let Regrouping::Split(minor) = regrouping {
            // A pair whose test changed has the feature of one of its cells in
            // a minor piece, within the cell's clearance of it.
            let Some(b) = components.bounds_of(&minor) else {
                return;
            };
            let row_max = &features.row_max;
            let reach = largest(row_max);
            let reach = (reach as f64).sqrt() as usize + 1;
            let rows = b.y0.saturating_sub(reach)..=(b.y1 + reach).min(ph - 1);
            let reached = row_max.iter().enumerate().take(rows.end() + 1);
            for (y, &room) in reached.skip(*rows.start()) {
                let dy = b.y0.saturating_sub(y).max(y.saturating_sub(b.y1)) as u64;
                let room = room as u64;
                if dy * dy > room {
                    continue;
                }
                let r = ((room - dy * dy) as f64).sqrt() as usize + 1;
                for x in b.x0.saturating_sub(r)..=(b.x1 + r).min(pw - 1) {
                    let i = y * pw + x;
                    let (fx, fy) = features.feature[i];
                    let (fx, fy) = (fx as usize, fy as usize);
                    if obstacle[i]
                        || !b.holds(fx, fy)
                        || minor
                            .binary_search(&components.label[fy * pw + fx])
                            .is_err()
                    {
                        continue;
                    }
                    retest(x, y);
                    retest(x.wrapping_sub(1), y);
                    retest(x, y.wrapping_sub(1));
                }
            }
        }
    }

    /// The diagram for the drivable cells of `trav`: what [`gvd`](super::gvd()) computes.
    pub fn diagram(&self, knowledge: &OccupancyGrid, trav: &Traversability) -> Gvd {
        // Rows of obstacle cells only have no skeleton and no clearance; the
        // padded rows with a positive distance are the frame's rows + 1.
        let row_max = &self.field.features.row_max;
        let open = |y: &usize| row_max[*y] > 0;
        let rows = match (
            (0..row_max.len()).find(open),
            (0..row_max.len()).rfind(open),
        ) {
            (Some(a), Some(b)) => a - 1..b,
            _ => 0..0,
        };
        // Columns outside the known cells' bounds hold obstacles only (the
        // frame starts at the grid's first column).
        let cols = match trav.known_bounds() {
            Some((x0, _, x1, _)) => x0..x1 + 1,
            None => 0..0,
        };
        self.field
            .diagram(knowledge.geometry(), &trav.passable, rows, cols)
    }
}

/// The cells of `window` (padded coordinates of a window `pw` wide) of `v`, row
/// by row.
fn window_of<T: Copy>(v: &[T], window: Window, pw: usize) -> Vec<T> {
    (window.y0..=window.y1)
        .flat_map(|y| v[y * pw + window.x0..=y * pw + window.x1].iter().copied())
        .collect()
}

/// The largest value of a row (0 for none).
fn largest(row: &[u32]) -> u32 {
    row.iter().copied().max().unwrap_or(0)
}

/// How the partition into components changed on the cells that stayed
/// obstacles.
#[derive(Debug, PartialEq)]
enum Regrouping {
    /// Not at all.
    Same,
    /// Components split and none merged: the new labels of every piece but the
    /// largest (ties: the lowest label) of each component that split, sorted.
    Split(Vec<u32>),
    /// Components merged.
    Merged,
}

/// The [`Regrouping`] from the old and new labels of the cells that stayed
/// obstacles around the change (which suffice: see [`VoronoiField`]), and the
/// new components.
fn regrouping(mut pairs: Vec<(u32, u32)>, new: &Components) -> Regrouping {
    pairs.sort_unstable();
    pairs.dedup();
    let mut by_new: Vec<(u32, u32)> = pairs.iter().map(|&(a, b)| (b, a)).collect();
    by_new.sort_unstable();
    if by_new.windows(2).any(|w| w[0].0 == w[1].0) {
        return Regrouping::Merged;
    }
    // Pieces of the components that split: old label, new label.
    let split: Vec<(u32, u32)> = pairs
        .chunk_by(|a, b| a.0 == b.0)
        .filter(|group| group.len() > 1)
        .flatten()
        .copied()
        .collect();
    if split.is_empty() {
        return Regrouping::Same;
    }
    let mut pieces: Vec<u32> = split.iter().map(|&(_, b)| b).collect();
    pieces.sort_unstable();
    let size = new.sizes_of(&pieces);
    let mut minor = Vec::new();
    for group in split.chunk_by(|a, b| a.0 == b.0) {
        let size_of = |b: u32| size[pieces.binary_search(&b).unwrap_or(0)];
        let largest = group
            .iter()
            .map(|&(_, b)| b)
            .max_by(|&x, &y| size_of(x).cmp(&size_of(y)).then(y.cmp(&x)));
        minor.extend(
            group
                .iter()
                .map(|&(_, b)| b)
                .filter(|&b| Some(b) != largest),
        );
    }
    minor.sort_unstable();
    Regrouping::Split(minor)
}
