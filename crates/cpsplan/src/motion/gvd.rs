//! The Generalized Voronoi Diagram (GVD) of the known obstacles (paper section
//! IV-D, "Safety robot movement along Voronoi edge"), as a one-cell-wide skeleton
//! of drivable cells that robots drive along ([`super::voronoi_path()`]).
//!
//! In: the knowledge map and a robot's drivable cells. Out: the [`Gvd`]: skeleton,
//! clearance, connected parts of the skeleton.
//!
//! *Obstacles* are all non-Free cells of the knowledge map (Unknown is as solid as
//! Occupied) plus the grid's edge. Everything outside the bounding box of the Free
//! cells is an obstacle, so the diagram is computed in that box plus a one-cell
//! ring of obstacle cells (the *window*).
//!
//! 1. An exact Euclidean *feature transform* gives every cell its nearest obstacle
//!    cell: per column the nearest obstacle row (two linear sweeps, Meijster et al.
//!    2000), then per row the lower envelope of parabolas (Felzenszwalb &
//!    Huttenlocher 2012, breakpoints compared exactly in integers), rows in
//!    parallel ([`crate::grid::distance`]). The ring puts an obstacle in every column, so
//!    every cell has a feature.
//! 2. The obstacles are labelled by their 8-connected components (union-find over
//!    the row runs of obstacle cells).
//! 3. Two 4-neighbouring non-obstacle cells `p`, `q` *straddle* a Voronoi edge when
//!    their nearest obstacle cells `f(p)`, `f(q)` are not 8-adjacent and either lie
//!    in different components or are seen in directions `f(p) − p`, `f(q) − q` at
//!    least [`MIN_EDGE_ANGLE_DEG`] apart. The angle test is what finds the edges
//!    between two faces of one connected wall system (a corridor whose walls meet
//!    at its ends, a room), which the component test alone would miss; the
//!    adjacency test keeps the two sides of one straight wall from making an edge.
//!    Concave corners of at least `180° − MIN_EDGE_ANGLE_DEG` interior angle get
//!    their bisector spur, as in the exact GVD. Each pair is tested once.
//! 4. Of a straddling pair only the cell nearer to equidistance is marked: the one
//!    with the smaller excess `|p − f(q)| − |p − f(p)|` (ties: the lower index).
//!    The result is a one-cell-wide, 8-connected skeleton. Only drivable cells
//!    (`Traversability::passable`) are kept, and their connected parts are
//!    labelled ([`Gvd::edge_component`]).
//!
//! Parameters: [`MIN_EDGE_ANGLE_DEG`]; the robot radius enters through the
//! [`Traversability`] masks. Cost: O(cells of the window) time and a handful of
//! buffers of that size, no per-cell allocation; an 800 × 600 map takes about 5 ms
//! (docs/PERFORMANCE.md).
//!

use rayon::prelude::*;

use std::ops::Range;
use std::sync::Mutex;

use crate::grid::distance::{feature_transform_into, FeatureBuffers};
use crate::grid::window::{Spans, Window};
use crate::grid::{CellState, GridGeometry, OccupancyGrid, Traversability};

/// Smallest angle, degrees, between the directions to the nearest obstacle cells of
/// two neighbouring cells for them to straddle a Voronoi edge when both obstacle
/// cells belong to the same connected obstacle.
pub const MIN_EDGE_ANGLE_DEG: f64 = 60.0;

/// No index.
const NONE: u32 = u32::MAX;

/// The Generalized Voronoi Diagram of a knowledge map's obstacles, as a skeleton of
/// drivable cells.
#[derive(Debug, Clone)]
pub struct Gvd {
    /// Per cell (row-major, row 0 at the bottom): the cell lies on a Voronoi edge
    /// and is drivable. One cell wide, 8-connected along an edge.
    pub skeleton: Vec<bool>,
    /// Per cell: distance in cells from the cell's centre to the centre of the
    /// nearest non-Free cell or of the ring of cells just outside the grid (0 on
    /// non-Free cells).
    pub clearance: Vec<f32>,
    /// Per cell: the connected part of the skeleton it belongs to (`u32::MAX` off
    /// the skeleton).
    pub edge_component: Vec<u32>,
    /// The cells outside which every cell is off the skeleton with no
    /// clearance: what a recycled diagram has to reset.
    written: Spans,
}

impl Gvd {
    /// Number of skeleton cells.
    pub fn count(&self) -> usize {
        self.skeleton.iter().filter(|&&s| s).count()
    }

    /// A diagram of `n` cells with no skeleton and no clearance, whose cells
    /// are to be written in `written`: the buffers of a dropped diagram of the
    /// same size when one is kept, else fresh ones.
    fn blank(n: usize, written: Spans) -> Self {
        let kept = RECYCLED.lock().ok().and_then(|mut kept| {
            let at = kept.iter().position(|d| d.skeleton.len() == n)?;
            Some(kept.swap_remove(at))
        });
        match kept {
            Some(d) => Self::reuse(d, written),
            None => Self::fresh(n, written),
        }
    }

    /// [`Self::blank`] in fresh buffers.
    fn fresh(n: usize, written: Spans) -> Self {
        Self {
            skeleton: vec![false; n],
            clearance: vec![0.0; n],
            edge_component: vec![NONE; n],
            written,
        }
    }

    /// [`Self::blank`] in the buffers of a dropped diagram, reset where it
    /// wrote.
    fn reuse(mut d: Recycled, written: Spans) -> Self {
        for &(lo, hi) in d.written.ranges() {
            d.skeleton[lo..=hi].fill(false);
            d.edge_component[lo..=hi].fill(NONE);
            d.clearance[lo..=hi].fill(0.0);
        }
        Self {
            skeleton: d.skeleton,
            clearance: d.clearance,
            edge_component: d.edge_component,
            written,
        }
    }

    /// Moves the buffers out, for [`RECYCLED`].
    fn recycle(&mut self) -> Recycled {
        Recycled {
            skeleton: std::mem::take(&mut self.skeleton),
            clearance: std::mem::take(&mut self.clearance),
            edge_component: std::mem::take(&mut self.edge_component),
            written: std::mem::take(&mut self.written),
        }
    }
}

/// The buffers of a dropped [`Gvd`], and the cells it wrote.
struct Recycled {
    skeleton: Vec<bool>,
    clearance: Vec<f32>,
    edge_component: Vec<u32>,
    written: Spans,
}

/// Dropped diagrams' buffers kept for the next diagrams of their size (at most
/// [`RECYCLE_KEEP`]: a step draws one diagram, or two when the parent and the
/// children differ in radius), until [`release_buffers`]. A diagram is drawn on
/// every step of an episode with children; fresh whole-grid buffers cost their
/// page faults and zeroing each time.
static RECYCLED: Mutex<Vec<Recycled>> = Mutex::new(Vec::new());

/// How many dropped diagrams [`RECYCLED`] keeps.
const RECYCLE_KEEP: usize = 2;

impl Drop for Gvd {
    fn drop(&mut self) {
        if self.skeleton.is_empty() {
            return;
        }
        if let Ok(mut kept) = RECYCLED.lock() {
            if kept.len() < RECYCLE_KEEP {
                kept.push(self.recycle());
            }
        }
    }
}

/// The part of a diagram that does not depend on a robot's drivable cells, over a
/// *frame* of grid cells plus a one-cell ring of obstacle cells (the padded
/// window): the obstacles, their feature transform and components, and the
/// straddling pairs (steps 1–3 of the module documentation).
#[derive(Debug, Default)]
struct Field {
    /// First column and row of the frame on the grid.
    x0: usize,
    y0: usize,
    /// Columns and rows of the frame.
    bw: usize,
    bh: usize,
    obstacle: Vec<bool>,
    features: FeatureBuffers,
    components: Components,
    /// Per padded cell: whether it straddles an edge with its right neighbour,
    /// and which of the two wins ([`PAIR_NONE`], [`PAIR_FIRST`], [`PAIR_SECOND`]).
    right: Vec<u8>,
    /// The same with its upper neighbour.
    up: Vec<u8>,
}

impl Field {
    /// Width of the padded window.
    fn pw(&self) -> usize {
        self.bw + 2
    }

    /// Computes everything afresh for the frame of `bw × bh` grid cells from
    /// `(x0, y0)`.
    fn compute(
        &mut self,
        knowledge: &OccupancyGrid,
        (x0, y0, bw, bh): (usize, usize, usize, usize),
    ) {
        (self.x0, self.y0, self.bw, self.bh) = (x0, y0, bw, bh);
        let (pw, ph) = (bw + 2, bh + 2);
        let w = knowledge.geometry().width;
        let k = knowledge.cells();
        // Obstacles of the window: the ring and every non-Free cell.
        let obstacle = &mut self.obstacle;
        obstacle.clear();
        obstacle.resize(pw * ph, true);
        for y in 0..bh {
            let row = &k[(y0 + y) * w + x0..][..bw];
            let out = &mut obstacle[(y + 1) * pw + 1..][..bw];
            for (o, &s) in out.iter_mut().zip(row) {
                *o = s != CellState::Free;
            }
        }
        feature_transform_into(pw, ph, &self.obstacle, &mut self.features);
        self.components.label(pw, ph, &self.obstacle);
        for pairs in [&mut self.right, &mut self.up] {
            pairs.clear();
            pairs.resize(pw * ph, PAIR_NONE);
        }
        self.all_pairs();
    }

    /// Tests every pair of the frame (rows in parallel).
    fn all_pairs(&mut self) {
        let (pw, bw, bh) = (self.pw(), self.bw, self.bh);
        let Self {
            obstacle,
            features,
            components,
            right,
            up,
            ..
        } = self;
        let tester = PairTest::new(pw, obstacle, features, &components.label);
        right
            .par_chunks_mut(pw)
            .zip(up.par_chunks_mut(pw))
            .enumerate()
            .skip(1)
            .take(bh)
            .for_each(|(py, (right_row, up_row))| {
                for px in 1..=bw {
                    (right_row[px], up_row[px]) = tester.pairs(px, py);
                }
            });
    }

    /// The diagram restricted to the drivable cells `passable` of the grid
    /// `g` (steps 4–5); `rows` and `cols`: the frame's rows and columns outside
    /// which every cell is an obstacle.
    fn diagram(
        &self,
        g: &GridGeometry,
        passable: &[bool],
        rows: Range<usize>,
        cols: Range<usize>,
    ) -> Gvd {
        let out = Gvd::blank(g.len(), self.written(g, &rows, &cols));
        self.draw(g, passable, rows, cols, out)
    }

    /// The grid cells that [`Self::diagram`] of the frame's `rows` and `cols`
    /// writes.
    fn written(&self, g: &GridGeometry, rows: &Range<usize>, cols: &Range<usize>) -> Spans {
        if rows.is_empty() || cols.is_empty() {
            return Spans::default();
        }
        let window = Window {
            x0: self.x0 + cols.start,
            y0: self.y0 + rows.start,
            x1: self.x0 + cols.end - 1,
            y1: self.y0 + rows.end - 1,
        };
        Spans::of(&[window], g.width)
    }

    /// [`Self::diagram`] drawn into `out`, a [`Gvd::blank`] for the cells
    /// [`Self::written`].
    fn draw(
        &self,
        g: &GridGeometry,
        passable: &[bool],
        rows: Range<usize>,
        cols: Range<usize>,
        mut out: Gvd,
    ) -> Gvd {
        if out.written.ranges().is_empty() {
            return out;
        }
        let w = g.width;
        let pw = self.pw();
        let (x0, x1) = (self.x0 + cols.start, self.x0 + cols.end);
        let (y0, y1) = (self.y0 + rows.start, self.y0 + rows.end);
        let (right, up, d2) = (&self.right, &self.up, &self.features.d2);
        out.skeleton[y0 * w..y1 * w]
            .par_chunks_mut(w)
            .zip(out.clearance[y0 * w..y1 * w].par_chunks_mut(w))
            .enumerate()
            .for_each(|(ry, (row, clear_row))| {
                let (by, y) = (rows.start + ry, y0 + ry);
                let src = &d2[(by + 1) * pw + 1 + cols.start..][..cols.len()];
                for (c, &d) in clear_row[x0..x1].iter_mut().zip(src) {
                    *c = (d as f64).sqrt() as f32;
                }
                for (bx, s) in cols.clone().zip(&mut row[x0..x1]) {
                    if !passable[y * w + self.x0 + bx] {
                        continue;
                    }
                    let i = (by + 1) * pw + bx + 1;
                    *s = right[i] == PAIR_FIRST
                        || right[i - 1] == PAIR_SECOND
                        || up[i] == PAIR_FIRST
                        || up[i - pw] == PAIR_SECOND;
                }
            });
        let label = &mut out.edge_component;
        edge_components(g, passable, &out.skeleton, label, &out.written);
        out
    }
}

/// The buffers kept for the next diagram: one set for the whole process (a
/// diagram computed while another runs gets fresh buffers), until
/// [`release_buffers`].
static SCRATCH: Mutex<Option<Field>> = Mutex::new(None);

/// Frees the buffers [`gvd`] keeps between diagrams and those of dropped
/// diagrams (an episode calls it when it ends, so that they do not add to what
/// comes after).
pub(crate) fn release_buffers() {
    if let Ok(mut kept) = SCRATCH.lock() {
        *kept = None;
    }
    if let Ok(mut kept) = RECYCLED.lock() {
        kept.clear();
    }
}

/// The GVD of the non-Free cells of `knowledge` (and the grid's edge), restricted
/// to the cells with `trav.passable`. See the module documentation for the method.
pub fn gvd(knowledge: &OccupancyGrid, trav: &Traversability) -> Gvd {
    let g = knowledge.geometry();
    // Everything outside the bounding box of the Free cells is an obstacle, so the
    // box plus a one-cell ring (the window) is all that matters.
    let Some((x0, y0, x1, y1)) = knowledge.bounds_of(|c| c == CellState::Free) else {
        return Gvd::blank(g.len(), Spans::default());
    };
    let kept = SCRATCH.lock().ok().and_then(|mut k| k.take());
    let mut field = kept.unwrap_or_default();
    field.compute(knowledge, (x0, y0, x1 - x0 + 1, y1 - y0 + 1));
    let out = field.diagram(g, &trav.passable, 0..field.bh, 0..field.bw);
    if let Ok(mut kept) = SCRATCH.lock() {
        let larger = kept
            .as_ref()
            .is_none_or(|k| k.features.capacity() < field.features.capacity());
        if larger {
            *kept = Some(field);
        }
    }
    out
}

/// The GVD's obstacle side kept across scans: the feature transform, the
/// components and the straddling pairs of the whole grid (steps 1–3), brought up
/// to date where a scan changed the knowledge map, from which the diagram of any
/// robot's drivable cells follows ([`Self::diagram`]). The frame is the whole
/// grid, so that it never moves; outside the Free cells' bounding box every cell
/// is an obstacle, and the result equals [`gvd`]'s.
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
    field: Field,
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
        f.components.label(pw, ph, &f.obstacle);
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
        for &(py, a, b) in &changes {
            for y in py.saturating_sub(1)..=py {
                for x in a.saturating_sub(1)..=b {
                    retest(x, y);
                }
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

    /// The diagram for the drivable cells of `trav`: what [`gvd`] computes.
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

/// The straddling-pair test of step 3 over a padded window.
struct PairTest<'a> {
    pw: usize,
    obstacle: &'a [bool],
    feature: &'a [(u32, u32)],
    d2: &'a [u32],
    component: &'a [u32],
    cos2_min: f64,
}

impl<'a> PairTest<'a> {
    fn new(
        pw: usize,
        obstacle: &'a [bool],
        features: &'a FeatureBuffers,
        component: &'a [u32],
    ) -> Self {
        let cos_min = MIN_EDGE_ANGLE_DEG.to_radians().cos();
        Self {
            pw,
            obstacle,
            feature: &features.feature,
            d2: &features.d2,
            component,
            cos2_min: cos_min * cos_min,
        }
    }

    /// The pairs of the window cell `(px, py)` (not on the ring) with its right
    /// and with its upper neighbour.
    #[inline]
    fn pairs(&self, px: usize, py: usize) -> (u8, u8) {
        let pw = self.pw;
        let p = Site::new(pw, px, py);
        if self.obstacle[p.i] {
            return (PAIR_NONE, PAIR_NONE);
        }
        let pair = |q: Site| {
            if self.obstacle[q.i]
                || !straddles(
                    pw,
                    p,
                    q,
                    self.feature,
                    self.d2,
                    self.component,
                    self.cos2_min,
                )
            {
                PAIR_NONE
            } else if wins(p, q, self.feature, self.d2) {
                PAIR_FIRST
            } else {
                PAIR_SECOND
            }
        };
        (
            pair(Site::new(pw, px + 1, py)),
            pair(Site::new(pw, px, py + 1)),
        )
    }
}

/// A cell of the padded window: index and coordinates.
#[derive(Clone, Copy)]
struct Site {
    i: usize,
    x: i64,
    y: i64,
}

impl Site {
    #[inline]
    fn new(pw: usize, x: usize, y: usize) -> Self {
        Self {
            i: y * pw + x,
            x: x as i64,
            y: y as i64,
        }
    }
}

/// Squared distance from `c` to the obstacle cell `f`.
#[inline]
fn dist2(c: Site, f: (u32, u32)) -> i64 {
    (c.x - f.0 as i64).pow(2) + (c.y - f.1 as i64).pow(2)
}

/// A pair of neighbours that straddles no edge.
const PAIR_NONE: u8 = 0;
/// The pair straddles an edge and its first cell (left or lower) wins.
const PAIR_FIRST: u8 = 1;
/// The pair straddles an edge and its second cell wins.
const PAIR_SECOND: u8 = 2;

/// Whether neighbours `p` and `q` lie on different sides of a Voronoi edge (a
/// symmetric relation); `cos2_min` is the squared cosine of
/// [`MIN_EDGE_ANGLE_DEG`].
#[inline]
fn straddles(
    pw: usize,
    p: Site,
    q: Site,
    feature: &[(u32, u32)],
    d2: &[u32],
    component: &[u32],
    cos2_min: f64,
) -> bool {
    let (fp, fq) = (feature[p.i], feature[q.i]);
    if fp.0.abs_diff(fq.0) <= 1 && fp.1.abs_diff(fq.1) <= 1 {
        return false; // same or touching obstacle cells: one side of one wall
    }
    let index = |f: (u32, u32)| f.1 as usize * pw + f.0 as usize;
    if component[index(fp)] != component[index(fq)] {
        return true;
    }
    let vp = (fp.0 as i64 - p.x, fp.1 as i64 - p.y);
    let vq = (fq.0 as i64 - q.x, fq.1 as i64 - q.y);
    // The angle between the two directions is at least the minimum:
    // dot ≤ cos_min · |vp| · |vq|, squared (cos_min > 0).
    let dot = vp.0 * vq.0 + vp.1 * vq.1;
    dot <= 0 || (dot as f64).powi(2) <= cos2_min * (d2[p.i] as f64) * (d2[q.i] as f64)
}

/// Whether `p` rather than its straddling neighbour `q` is the skeleton cell: the
/// one nearer to equidistance from the two obstacle cells.
#[inline]
fn wins(p: Site, q: Site, feature: &[(u32, u32)], d2: &[u32]) -> bool {
    let excess =
        |c: Site, other: (u32, u32)| (dist2(c, other) as f64).sqrt() - (d2[c.i] as f64).sqrt();
    let (ep, eq) = (excess(p, feature[q.i]), excess(q, feature[p.i]));
    ep < eq || (ep == eq && p.i < q.i)
}

/// Labels of the 8-connected components of the obstacle cells, with the buffers
/// kept between calls.
#[derive(Debug, Default)]
struct Components {
    /// Width of the window labelled last.
    pw: usize,
    /// Runs of obstacle cells: (row, first column, last column), row by row.
    runs: Vec<(usize, usize, usize)>,
    row_start: Vec<usize>,
    parent: Vec<u32>,
    label: Vec<u32>,
}

impl Components {
    /// Labels of the 8-connected components of the obstacle cells ([`NONE`]
    /// elsewhere; a component's label is some number shared by its cells and no
    /// other's).
    ///
    /// Union-find over the row runs of obstacle cells: a run joins every run of
    /// the row below that overlaps it or touches it diagonally. Linear in the
    /// cells, and fast where obstacles are large solid areas.
    fn label(&mut self, pw: usize, ph: usize, obstacle: &[bool]) -> &[u32] {
        self.pw = pw;
        let Self {
            runs,
            row_start,
            parent,
            label,
            ..
        } = self;
        runs.clear();
        row_start.clear();
        for y in 0..ph {
            row_start.push(runs.len());
            let row = &obstacle[y * pw..][..pw];
            let mut x = 0;
            while x < pw {
                if row[x] {
                    let first = x;
                    while x < pw && row[x] {
                        x += 1;
                    }
                    runs.push((y, first, x - 1));
                } else {
                    x += 1;
                }
            }
        }
        row_start.push(runs.len());
        parent.clear();
        parent.extend(0..runs.len() as u32);
        fn root(parent: &mut [u32], mut i: u32) -> u32 {
            while parent[i as usize] != i {
                let up = parent[parent[i as usize] as usize];
                parent[i as usize] = up;
                i = up;
            }
            i
        }
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
                    let (ra, rb) = (root(parent, i as u32), root(parent, k as u32));
                    if ra != rb {
                        parent[ra.max(rb) as usize] = ra.min(rb);
                    }
                    k += 1;
                }
            }
        }
        label.clear();
        label.resize(pw * ph, NONE);
        for (i, &(y, a, b)) in runs.iter().enumerate() {
            let r = root(parent, i as u32);
            label[y * pw + a..=y * pw + b].fill(r);
        }
        label
    }
}

impl Components {
    /// The label of a run.
    fn run_label(&self, (y, a, _): (usize, usize, usize)) -> u32 {
        self.label[y * self.pw + a]
    }

    /// The number of cells of each component of `labels` (sorted).
    fn sizes_of(&self, labels: &[u32]) -> Vec<usize> {
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
    fn bounds_of(&self, labels: &[u32]) -> Option<Window> {
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
fn components(pw: usize, ph: usize, obstacle: &[bool]) -> Vec<u32> {
    Components::default().label(pw, ph, obstacle).to_vec()
}

/// Labels of the connected parts of the skeleton: 8-neighbouring skeleton cells
/// are connected where a diagonal step has both cells beside it passable (the
/// steps the path search takes), written into `label` ([`NONE`] everywhere
/// before, and left so off the skeleton) for a skeleton within the cells
/// `within`.
fn edge_components(
    g: &GridGeometry,
    passable: &[bool],
    skeleton: &[bool],
    label: &mut [u32],
    within: &Spans,
) {
    let (w, h) = (g.width as i64, g.height as i64);
    let mut stack = Vec::new();
    let mut next = 0u32;
    for start in within.ranges().iter().flat_map(|&(lo, hi)| lo..=hi) {
        if !skeleton[start] || label[start] != NONE {
            continue;
        }
        label[start] = next;
        stack.push(start);
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
                        && (!passable[(y * w + nx) as usize] || !passable[(ny * w + x) as usize])
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
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geom::Cell;
    use crate::geom::Point;
    use crate::grid::search::search;
    use proptest::prelude::*;

    const RES: f64 = 0.1;
    const RADIUS: f64 = 0.25;

    /// A map of Free cells inside a one-cell Occupied frame, with Occupied
    /// rectangles `(x, y, w, h)`.
    pub(in crate::motion) fn room(
        w: usize,
        h: usize,
        rects: &[(usize, usize, usize, usize)],
    ) -> OccupancyGrid {
        let g = GridGeometry::new(w, h, RES, Point::new(-1.0, 2.0));
        let mut t = OccupancyGrid::filled(g, CellState::Occupied);
        t.fill_rect(1, 1, w - 1, h - 1, CellState::Free);
        for &(x, y, rw, rh) in rects {
            t.fill_rect(x % w, y % h, x % w + rw, y % h + rh, CellState::Occupied);
        }
        t
    }

    pub(in crate::motion) fn skeleton_of(
        map: &OccupancyGrid,
        robot: Cell,
    ) -> (Traversability, Gvd) {
        let trav = Traversability::new(map, RADIUS, robot);
        let d = gvd(map, &trav);
        (trav, d)
    }

    fn skeleton_rows(map: &OccupancyGrid, d: &Gvd, x: usize) -> Vec<usize> {
        let g = map.geometry();
        (0..g.height)
            .filter(|&y| d.skeleton[g.index(Cell::new(x, y))])
            .collect()
    }

    #[test]
    fn odd_corridor_skeleton_is_the_centre_line() {
        // Free rows 1..=19: the centre row is 10.
        let map = room(60, 21, &[]);
        let (_, d) = skeleton_of(&map, Cell::new(30, 10));
        for x in 15..45 {
            assert_eq!(skeleton_rows(&map, &d, x), vec![10], "column {x}");
        }
    }

    #[test]
    fn even_corridor_skeleton_is_one_row() {
        // Free rows 1..=18: the centre line lies between rows 9 and 10.
        let map = room(60, 20, &[]);
        let (_, d) = skeleton_of(&map, Cell::new(30, 10));
        for x in 15..45 {
            assert_eq!(skeleton_rows(&map, &d, x), vec![9], "column {x}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// The run-based labelling groups cells exactly as a flood fill does.
        #[test]
        fn components_match_a_flood_fill(
            w in 1usize..30,
            h in 1usize..30,
            cells in proptest::collection::vec(any::<bool>(), 900),
        ) {
            let obstacle = &cells[..w * h];
            let label = components(w, h, obstacle);
            let mut flood = vec![NONE; w * h];
            let mut next = 0;
            for s in 0..w * h {
                if !obstacle[s] || flood[s] != NONE {
                    continue;
                }
                let mut stack = vec![s];
                flood[s] = next;
                while let Some(i) = stack.pop() {
                    let (x, y) = ((i % w) as i64, (i / w) as i64);
                    for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                            continue;
                        }
                        let j = (ny * w as i64 + nx) as usize;
                        if obstacle[j] && flood[j] == NONE {
                            flood[j] = next;
                            stack.push(j);
                        }
                    }
                }
                next += 1;
            }
            for i in 0..w * h {
                prop_assert_eq!(label[i] == NONE, !obstacle[i]);
                for j in 0..w * h {
                    if obstacle[i] && obstacle[j] {
                        prop_assert_eq!(label[i] == label[j], flood[i] == flood[j]);
                    }
                }
            }
        }
    }

    /// The kept field equals one computed afresh, buffer by buffer (the
    /// component labels up to renaming), and its diagram equals [`gvd`]'s.
    fn assert_fresh(kept: &VoronoiField, knowledge: &OccupancyGrid, radius: f64, robot: Cell) {
        let fresh = VoronoiField::new(knowledge);
        let (a, b) = (&kept.field, &fresh.field);
        assert_eq!(a.obstacle, b.obstacle, "obstacles");
        assert_eq!(a.features.feature, b.features.feature, "features");
        assert_eq!(a.features.d2, b.features.d2, "squared distances");
        assert!(a.right == b.right && a.up == b.up, "straddling pairs");
        let labels: Vec<(u32, u32)> = (0..a.obstacle.len())
            .filter(|&p| a.obstacle[p])
            .map(|p| (a.components.label[p], b.components.label[p]))
            .collect();
        assert_eq!(
            regrouping(labels, &b.components),
            Regrouping::Same,
            "components"
        );
        let trav = Traversability::new(knowledge, radius, robot);
        let (d, e) = (kept.diagram(knowledge, &trav), gvd(knowledge, &trav));
        assert_eq!(d.skeleton, e.skeleton, "skeleton");
        assert_eq!(d.clearance, e.clearance, "clearance");
        assert_eq!(d.edge_component, e.edge_component, "edge components");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// Scans of a random map from random stops: after every scan the kept
        /// field and its diagram equal fresh ones.
        #[test]
        fn scans_keep_the_field_of_a_fresh_computation(
            w in 4usize..70,
            h in 4usize..70,
            walls in proptest::collection::vec((0usize..70, 0usize..70, 1usize..14, 1usize..14), 0..12),
            stops in proptest::collection::vec((0usize..70, 0usize..70), 1..8),
            range in 3.0f64..40.0,
            radius in proptest::sample::select(vec![0.0, 0.1, 0.25]),
        ) {
            let g = GridGeometry::new(w, h, RES, Point::default());
            let mut truth = OccupancyGrid::filled(g, CellState::Free);
            for &(x, y, rw, rh) in &walls {
                let (x, y) = (x % w, y % h);
                truth.fill_rect(x, y, (x + rw).min(w), (y + rh).min(h), CellState::Occupied);
            }
            let mut knowledge = OccupancyGrid::filled(g, CellState::Unknown);
            let mut kept = VoronoiField::new(&knowledge);
            for &(x, y) in &stops {
                let at = Cell::new(x % w, y % h);
                let mut changed = Vec::new();
                crate::sensing::scan(&truth, &mut knowledge, at, range, |i| changed.push(i));
                kept.update(&knowledge, &changed);
                assert_fresh(&kept, &knowledge, radius, at);
            }
        }

        /// Arbitrary changes, obstacles appearing as well as vanishing.
        #[test]
        fn any_changes_keep_the_field_of_a_fresh_computation(
            w in 1usize..40,
            h in 1usize..40,
            start in proptest::collection::vec(0usize..3, 1600),
            edits in proptest::collection::vec((0usize..40, 0usize..40, 1usize..15, 1usize..15, 0usize..3), 1..8),
        ) {
            let g = GridGeometry::new(w, h, RES, Point::default());
            let cells = (0..g.len()).map(|i| crate::grid::fixtures::STATES[start[i]]).collect();
            let mut knowledge = OccupancyGrid::from_cells(g, cells).unwrap();
            let mut kept = VoronoiField::new(&knowledge);
            for &(x, y, rw, rh, s) in &edits {
                let state = crate::grid::fixtures::STATES[s];
                let changed = crate::grid::fixtures::paint(&mut knowledge, (x, y, rw, rh), state);
                kept.update(&knowledge, &changed);
                assert_fresh(&kept, &knowledge, RADIUS, Cell::new(x % w, y % h));
            }
        }
    }

    #[test]
    fn diagrams_in_recycled_buffers_equal_fresh_ones() {
        // A diagram over the whole map leaves skeleton, clearance and parts
        // where the next one, over a map known only in its lower half, has
        // none.
        let whole = room(60, 50, &[(20, 10, 5, 30)]);
        let (_, old) = skeleton_of(&whole, Cell::new(5, 5));
        let mut half = whole.clone();
        half.fill_rect(0, 20, 60, 50, CellState::Unknown);
        let trav = Traversability::new(&half, RADIUS, Cell::new(5, 5));
        let g = half.geometry();
        let bounds = half.bounds_of(|c| c == CellState::Free).unwrap();
        let (x0, y0, x1, y1) = bounds;
        let mut field = Field::default();
        field.compute(&half, (x0, y0, x1 - x0 + 1, y1 - y0 + 1));
        let (rows, cols) = (0..field.bh, 0..field.bw);
        let written = field.written(g, &rows, &cols);
        let inside: std::collections::HashSet<usize> = written
            .ranges()
            .iter()
            .flat_map(|&(lo, hi)| lo..=hi)
            .collect();
        assert!((0..g.len()).any(|i| old.skeleton[i] && !inside.contains(&i)));
        let mut old = old;
        let reused = Gvd::reuse(old.recycle(), written.clone());
        let reused = field.draw(g, &trav.passable, rows.clone(), cols.clone(), reused);
        let fresh = Gvd::fresh(g.len(), written);
        let fresh = field.draw(g, &trav.passable, rows, cols, fresh);
        assert!(fresh.count() > 0);
        assert_eq!(reused.skeleton, fresh.skeleton);
        assert_eq!(reused.clearance, fresh.clearance);
        assert_eq!(reused.edge_component, fresh.edge_component);
    }

    #[test]
    fn separate_corridors_have_separate_edge_components() {
        // A full wall splits the room into two corridors.
        let map = room(60, 30, &[(30, 0, 2, 30)]);
        let (_, d) = skeleton_of(&map, Cell::new(10, 15));
        let g = map.geometry();
        let parts = |xs: std::ops::Range<usize>| -> std::collections::BTreeSet<u32> {
            (0..g.len())
                .filter(|&i| d.skeleton[i] && xs.contains(&g.cell(i).x))
                .map(|i| d.edge_component[i])
                .collect()
        };
        let (left, right) = (parts(0..30), parts(32..60));
        assert!(!left.is_empty() && !right.is_empty());
        assert!(left.is_disjoint(&right), "{left:?} {right:?}");
        assert!(!left.contains(&u32::MAX));
    }

    #[test]
    fn skeleton_passes_on_both_sides_of_a_pillar() {
        let map = room(60, 60, &[(25, 25, 10, 10)]);
        let (trav, d) = skeleton_of(&map, Cell::new(5, 5));
        let g = map.geometry();
        let col = skeleton_rows(&map, &d, 30);
        assert!(col.iter().any(|&y| y < 25), "{col:?}");
        assert!(col.iter().any(|&y| y > 35), "{col:?}");
        let row: Vec<usize> = (0..60)
            .filter(|&x| d.skeleton[g.index(Cell::new(x, 30))])
            .collect();
        assert!(row.iter().any(|&x| x < 25), "{row:?}");
        assert!(row.iter().any(|&x| x > 35), "{row:?}");
        // Midway between pillar and wall, one cell wide.
        assert!(col
            .iter()
            .all(|&y| (12..=13).contains(&y) || (46..=47).contains(&y)));
        // The ring around the pillar is connected, by the steps a path takes.
        let part = d.edge_component[g.index(Cell::new(30, col[0]))];
        for c in [
            Cell::new(30, *col.last().unwrap()),
            Cell::new(row[0], 30),
            Cell::new(*row.last().unwrap(), 30),
        ] {
            assert_eq!(d.edge_component[g.index(c)], part, "{c:?}");
            let open = |i: usize| trav.passable[i];
            let ci = g.index(c);
            let along = search(
                g,
                g.index(Cell::new(30, col[0])),
                |i| d.skeleton[i],
                open,
                |i| i == ci,
                |_| 0,
            );
            assert!(along.is_some(), "{c:?}");
        }
    }
}
