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
use std::sync::{Arc, Mutex};

use crate::grid::distance::{feature_transform_into, FeatureBuffers};
use crate::grid::{CellState, GridGeometry, OccupancyGrid, Traversability};

mod components;
#[cfg(test)]
pub(super) mod tests;
mod update;

use components::{edge_components, Components};
pub use update::VoronoiField;

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
    /// Per cell: the connected part of the skeleton it belongs to (`u32::MAX` off
    /// the skeleton).
    pub edge_component: Vec<u32>,
    /// The skeleton's cells, ascending: what a recycled diagram has to reset.
    cells: Vec<usize>,
    clearance: Clearances,
}

impl Gvd {
    /// Number of skeleton cells.
    pub fn count(&self) -> usize {
        self.cells.len()
    }

    /// The skeleton's cells, ascending.
    pub fn cells(&self) -> &[usize] {
        &self.cells
    }

    /// Distance in cells from the centre of cell `index` to the centre of the
    /// nearest non-Free cell or of the ring of cells just outside the grid (0
    /// on non-Free cells).
    #[inline]
    pub fn clearance(&self, index: usize) -> f32 {
        self.clearance.at(index)
    }

    /// [`Self::clearance`] of every cell.
    pub fn clearances(&self) -> Vec<f32> {
        (0..self.skeleton.len())
            .map(|i| self.clearance(i))
            .collect()
    }

    /// A diagram of `n` cells with no skeleton: the buffers of a dropped
    /// diagram of the same size when one is kept, else fresh ones.
    fn blank(n: usize) -> Self {
        let kept = RECYCLED.lock().ok().and_then(|mut kept| {
            let at = kept.iter().position(|d| d.skeleton.len() == n)?;
            Some(kept.swap_remove(at))
        });
        match kept {
            Some(d) => Self::reuse(d),
            None => Self::fresh(n),
        }
    }

    /// [`Self::blank`] in fresh buffers.
    fn fresh(n: usize) -> Self {
        Self {
            skeleton: vec![false; n],
            edge_component: vec![NONE; n],
            cells: Vec::new(),
            clearance: Clearances::default(),
        }
    }

    /// [`Self::blank`] in the buffers of a dropped diagram, reset on its
    /// skeleton.
    fn reuse(mut d: Recycled) -> Self {
        for &i in &d.cells {
            d.skeleton[i] = false;
            d.edge_component[i] = NONE;
        }
        d.cells.clear();
        Self {
            skeleton: d.skeleton,
            edge_component: d.edge_component,
            cells: d.cells,
            clearance: Clearances::default(),
        }
    }

    /// Moves the buffers out, for [`RECYCLED`].
    fn recycle(&mut self) -> Recycled {
        Recycled {
            skeleton: std::mem::take(&mut self.skeleton),
            edge_component: std::mem::take(&mut self.edge_component),
            cells: std::mem::take(&mut self.cells),
        }
    }
}

/// The clearances of a diagram: those of the field it was drawn from, over the
/// field's padded frame (0 outside it).
#[derive(Debug, Clone, Default)]
struct Clearances {
    values: Arc<Vec<f32>>,
    /// The grid's width.
    width: usize,
    /// First column and row of the frame on the grid, and its size.
    x0: usize,
    y0: usize,
    bw: usize,
    bh: usize,
}

impl Clearances {
    /// The clearance of grid cell `index`.
    #[inline]
    fn at(&self, index: usize) -> f32 {
        if self.width == 0 {
            return 0.0;
        }
        let (x, y) = (index % self.width, index / self.width);
        let (bx, by) = (x.wrapping_sub(self.x0), y.wrapping_sub(self.y0));
        if bx >= self.bw || by >= self.bh {
            return 0.0;
        }
        self.values[(by + 1) * (self.bw + 2) + bx + 1]
    }
}

/// The buffers of a dropped [`Gvd`].
struct Recycled {
    skeleton: Vec<bool>,
    edge_component: Vec<u32>,
    cells: Vec<usize>,
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
    /// Per padded cell: the square root of its squared distance to its
    /// feature (shared with the diagrams drawn from the field).
    clearance: Arc<Vec<f32>>,
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
        if Arc::get_mut(&mut self.clearance).is_none() {
            // A diagram still holds the old clearances.
            self.clearance = Arc::default();
        }
        let clearance = Arc::make_mut(&mut self.clearance);
        clearance.clear();
        clearance.resize(pw * ph, 0.0);
        clearance
            .par_iter_mut()
            .zip(self.features.d2.par_iter())
            .for_each(|(c, &d)| *c = clearance_of(d));
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
        self.draw(g, passable, rows, cols, Gvd::blank(g.len()))
    }

    /// [`Self::diagram`] drawn into `out`, a [`Gvd::blank`].
    fn draw(
        &self,
        g: &GridGeometry,
        passable: &[bool],
        rows: Range<usize>,
        cols: Range<usize>,
        mut out: Gvd,
    ) -> Gvd {
        out.clearance = Clearances {
            values: Arc::clone(&self.clearance),
            width: g.width,
            x0: self.x0,
            y0: self.y0,
            bw: self.bw,
            bh: self.bh,
        };
        if rows.is_empty() || cols.is_empty() {
            return out;
        }
        let w = g.width;
        let pw = self.pw();
        let (x0, x1) = (self.x0 + cols.start, self.x0 + cols.end);
        let y0 = self.y0 + rows.start;
        let y1 = self.y0 + rows.end;
        let (right, up) = (&self.right, &self.up);
        let n = cols.len();
        // Each row's skeleton cells, in order: the labelling below visits
        // them alone rather than every cell of the frame.
        let skeleton_rows: Vec<Vec<usize>> = out.skeleton[y0 * w..y1 * w]
            .par_chunks_mut(w)
            .enumerate()
            .map(|(ry, row)| {
                let (by, y) = (rows.start + ry, y0 + ry);
                let i0 = (by + 1) * pw + cols.start + 1;
                let (r, r_left) = (&right[i0..i0 + n], &right[i0 - 1..i0 - 1 + n]);
                let (u, u_below) = (&up[i0..i0 + n], &up[i0 - pw..i0 - pw + n]);
                let open = &passable[y * w + x0..y * w + x1];
                let row = &mut row[x0..x1];
                for k in 0..n {
                    row[k] = open[k]
                        & ((r[k] == PAIR_FIRST)
                            | (r_left[k] == PAIR_SECOND)
                            | (u[k] == PAIR_FIRST)
                            | (u_below[k] == PAIR_SECOND));
                }
                let mut on = Vec::new();
                for (c, chunk) in row.chunks(32).enumerate() {
                    if chunk.iter().fold(false, |a, &b| a | b) {
                        let first = y * w + x0 + c * 32;
                        on.extend((0..chunk.len()).filter(|&k| chunk[k]).map(|k| first + k));
                    }
                }
                on
            })
            .collect();
        out.cells = skeleton_rows.concat();
        edge_components(
            g,
            passable,
            &out.skeleton,
            &mut out.edge_component,
            &out.cells,
        );
        out
    }
}

/// The clearance, in cells, of a cell at the squared distance `d2` from its
/// feature.
#[inline]
fn clearance_of(d2: u32) -> f32 {
    (d2 as f64).sqrt() as f32
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
        return Gvd::blank(g.len());
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
