//! The expected gain in square metres (beyond the paper), calibrated against what
//! scans actually add, and the rule that says whether a position is worth a scan.
//!
//! `S` of Eq. (1) counts every Unknown cell in view with Unknown treated as empty,
//! so it counts the unknown space behind walls that are not yet seen: measured
//! over the built-in and shared maps, a scan added a median 8 % of its `S`
//! (docs/RESULTS.md). The estimate here counts only the Unknown cells in view
//! that lie within `parent.unknown_depth` of known free space (by the 3-4
//! chamfer distance on 2 × 2 blocks; beyond that the beam has most likely met
//! a wall), scaled by `parent.gain_scale`, the measured
//! ratio of free area added to that count.

use crate::config::Config;
use crate::geom::Cell;
use crate::grid::{CellState, OccupancyGrid};

use std::sync::Arc;

use rayon::prelude::*;

use super::kept_views::{Kept, KeptView, KeptViews};
use super::view_runs::ViewClasses;

/// The gain estimate of one knowledge map.
#[derive(Debug, Clone)]
pub struct GainEstimate {
    /// Per cell its class for the views' sweep by runs: the Unknown cells
    /// within `unknown_depth` of a known-Free cell apart.
    classes: Arc<ViewClasses>,
    /// Area of one cell, m².
    cell_m2: f64,
    /// `parent.gain_scale`.
    scale: f64,
    /// Known free area, m².
    known_free_m2: f64,
    /// `parent.min_gain_cells`, `parent.min_gain_m2` and the share.
    min_cells: usize,
    min_m2: f64,
    min_share: f64,
    /// The views kept across scans by the field this estimate came from, and
    /// the cells of the knowledge map they belong to (they answer for no
    /// other map).
    kept: (Arc<KeptViews>, usize),
}

/// What a position is expected to add.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gain {
    /// `S` of Eq. (1): Unknown cells in view, Unknown treated as empty.
    pub s_cells: usize,
    /// Of those, the cells within `unknown_depth` of known free space.
    pub near_cells: usize,
    /// The calibrated estimate of the free area added, m².
    pub m2: f64,
}

impl GainEstimate {
    /// The estimate for `knowledge` with the parameters of `config.parent`.
    pub fn new(knowledge: &OccupancyGrid, config: &Config) -> Self {
        Self::from_field(&NearField::new(knowledge, config), knowledge, config)
    }

    /// The estimate from `field`, the [`NearField`] of `knowledge` kept across
    /// an episode's scans, with the parameters of `config.parent` (the same as
    /// [`Self::new`], without recomputing the field).
    pub fn from_field(field: &NearField, knowledge: &OccupancyGrid, config: &Config) -> Self {
        let g = knowledge.geometry();
        let cell_m2 = g.resolution * g.resolution;
        Self {
            classes: Arc::clone(&field.classes),
            cell_m2,
            scale: config.parent.gain_scale,
            known_free_m2: field.free_cells as f64 * cell_m2,
            min_cells: config.parent.min_gain_cells,
            min_m2: config.parent.min_gain_m2,
            min_share: config.parent.min_gain_share,
            kept: (
                Arc::clone(&field.kept.0),
                knowledge.cells().as_ptr() as usize,
            ),
        }
    }

    /// The kept views, when they belong to `knowledge`.
    fn kept_for(&self, knowledge: &OccupancyGrid) -> Option<&KeptViews> {
        let (kept, cells) = &self.kept;
        (*cells == knowledge.cells().as_ptr() as usize).then_some(kept.as_ref())
    }

    /// The gain of a scan from `at` within `range_cells` (one visibility sweep,
    /// the rule of [`super::expected_gain`]).
    pub fn at(&self, knowledge: &OccupancyGrid, at: Cell, range_cells: f64) -> Gain {
        self.kept_view(knowledge, at, range_cells, false).0
    }

    /// [`Self::at`] with the counted cells near known free space (the cells
    /// the estimate stands for), as indices in the order counted, shared with
    /// the kept view when there is one. On a grid of more than `u32::MAX`
    /// cells the list is empty.
    pub fn view(
        &self,
        knowledge: &OccupancyGrid,
        at: Cell,
        range_cells: f64,
    ) -> (Gain, Arc<[u32]>) {
        let listed = u32::try_from(knowledge.geometry().len()).is_ok();
        let (gain, cells) = self.kept_view(knowledge, at, range_cells, listed);
        (gain, cells.unwrap_or_default())
    }

    /// A view, from the kept ones where there is one (with its near cells
    /// when `listed` asks for them), else counted and kept.
    fn kept_view(
        &self,
        knowledge: &OccupancyGrid,
        at: Cell,
        range_cells: f64,
        listed: bool,
    ) -> (Gain, Option<Arc<[u32]>>) {
        let gain = |s: usize, near: usize| Gain {
            s_cells: s,
            near_cells: near,
            m2: self.m2(near),
        };
        let index = knowledge.geometry().index(at);
        let kept = self.kept_for(knowledge);
        if let Some(v) = kept.and_then(|k| k.get(index, range_cells, listed)) {
            return (gain(v.unknown, v.near), v.cells.clone().filter(|_| listed));
        }
        let mut cells = Vec::new();
        let (s, near) = self.count(
            knowledge,
            at,
            range_cells,
            |i| {
                if listed {
                    cells.push(i as u32);
                }
            },
            |_, _| false,
        );
        let cells: Option<Arc<[u32]>> = listed.then(|| Arc::from(cells));
        if let Some(k) = kept {
            k.put(
                index,
                range_cells,
                KeptView {
                    unknown: s,
                    near,
                    cells: cells.clone(),
                },
            );
        }
        (gain(s, near), cells)
    }

    /// Whether a scan from `at` is worth planning ([`Self::worth_a_scan`] of
    /// [`Self::at`]), counting only until the answer is known.
    pub fn worth_at(&self, knowledge: &OccupancyGrid, at: Cell, range_cells: f64) -> bool {
        let per_cell = self.cell_m2 * self.scale;
        let need_near = if per_cell > 0.0 {
            (self.threshold_m2() / per_cell - 1e-9).ceil().max(0.0) as usize
        } else {
            0
        };
        let enough = |s: usize, near: usize| s >= self.min_cells && near >= need_near;
        let (s, near) = self.count(knowledge, at, range_cells, |_| {}, enough);
        enough(s, near) && self.m2(near) >= self.threshold_m2()
    }

    /// The Unknown cells in view from `at` and those of them near known free
    /// space (`on_near` sees each), until `stop(unknown, near)` says enough.
    fn count(
        &self,
        knowledge: &OccupancyGrid,
        at: Cell,
        range_cells: f64,
        mut on_near: impl FnMut(usize),
        stop: impl Fn(usize, usize) -> bool,
    ) -> (usize, usize) {
        self.classes
            .count(knowledge.geometry(), at, range_cells, &mut on_near, &stop)
    }

    /// The calibrated area, m², of `near_cells` cells.
    pub fn m2(&self, near_cells: usize) -> f64 {
        near_cells as f64 * self.cell_m2 * self.scale
    }

    /// The known free area, m².
    pub fn known_free_m2(&self) -> f64 {
        self.known_free_m2
    }

    /// The least estimated area, m², a scan must add to be planned: at least
    /// `parent.min_gain_m2` and `parent.min_gain_share` of the known free area.
    pub fn threshold_m2(&self) -> f64 {
        self.min_m2.max(self.min_share * self.known_free_m2)
    }

    /// Whether a scan with `gain` is worth planning: `S ≥ min_gain_cells` and
    /// the estimate at least [`Self::threshold_m2`].
    pub fn worth_a_scan(&self, gain: &Gain) -> bool {
        gain.s_cells >= self.min_cells && gain.m2 >= self.threshold_m2()
    }
}

/// Side of the blocks the near cells are found on, cells.
const BLOCK: usize = 2;

/// The Unknown cells near known free space that the gain estimate counts, and
/// the known free cells, of one knowledge map: computed once
/// ([`NearField::new`]) and then kept up to date scan by scan
/// ([`NearField::update`]) in the window the scan changed, instead of over the
/// whole map every planning round.
///
/// An Unknown cell is near when its block of 2 × 2 cells lies
/// within `parent.unknown_depth / 2` blocks of a free block (a block with a
/// Free cell) by the 3-4 chamfer distance. The block rounds the depth by at most
/// a block's diagonal; a quarter of the cells makes it fast enough for every
/// planning round.
#[derive(Debug, Clone)]
pub struct NearField {
    /// Per cell: Unknown and near.
    near: Arc<Vec<bool>>,
    /// Per cell its class for the views' sweep by runs (state and near flag),
    /// in rows and in columns.
    classes: Arc<ViewClasses>,
    /// Per block: within the depth of a free block.
    within: Vec<bool>,
    /// Blocks per row and column.
    bw: usize,
    bh: usize,
    /// The chamfer limit of the depth, and the blocks beyond the depth a
    /// window needs.
    limit: u16,
    pad: usize,
    /// Known-Free cells.
    free_cells: usize,
    /// The gain views of this map kept across scans.
    kept: Kept,
}

impl NearField {
    /// The field of `knowledge` with the depth `config.parent.unknown_depth`.
    /// Only the window of the free blocks, widened by the depth, is
    /// transformed.
    pub fn new(knowledge: &OccupancyGrid, config: &Config) -> Self {
        let g = knowledge.geometry();
        let k = knowledge.cells();
        let depth_b = (config.parent.unknown_depth / g.resolution).max(0.0) / BLOCK as f64;
        let (bw, bh) = (g.width.div_ceil(BLOCK), g.height.div_ceil(BLOCK));
        let mut field = Self {
            near: Arc::new(vec![false; k.len()]),
            classes: Arc::new(ViewClasses::new(g, k)),
            within: vec![false; bw * bh],
            bw,
            bh,
            limit: chamfer_limit(depth_b),
            pad: (depth_b.ceil() as usize).saturating_add(1),
            free_cells: k.iter().filter(|&&c| c == CellState::Free).count(),
            kept: Kept::default(),
        };
        if let Some(b) = knowledge.bounds_of(|c| c == CellState::Free) {
            field.transform(knowledge, b);
        }
        field
    }

    /// Brings the field up to date after a scan: `changed` are the cells that
    /// were Unknown before it (what [`crate::sensing::scan`] reports as new).
    /// Knowledge only grows, so the near blocks only grow too: the window of the
    /// cells that became Free, widened by the depth, holds every block that can
    /// join, and the transform there (of every free block in it) finds exactly
    /// those. The result equals [`Self::new`] of the updated map.
    pub fn update(&mut self, knowledge: &OccupancyGrid, changed: &[usize]) {
        let g = knowledge.geometry();
        let k = knowledge.cells();
        let near = Arc::make_mut(&mut self.near);
        let classes = Arc::make_mut(&mut self.classes);
        for &i in changed {
            near[i] = k[i] == CellState::Unknown && near[i];
            classes.set(i, k[i], near[i]);
        }
        // The near cells change only in the changed cells and the window the
        // transform redoes (the made-free cells' box widened by `pad` blocks):
        // the kept views that reach into that box widened once more go.
        if let Some((x0, y0, x1, y1)) = g.index_bounds(changed.iter().copied()) {
            let m = (self.pad + 1) * BLOCK;
            self.kept.0.forget_near(
                g.width,
                (
                    x0.saturating_sub(m),
                    y0.saturating_sub(m),
                    x1.saturating_add(m),
                    y1.saturating_add(m),
                ),
            );
        }
        let made_free = || changed.iter().copied().filter(|&i| k[i] == CellState::Free);
        self.free_cells += made_free().count();
        if let Some(b) = g.index_bounds(made_free()) {
            self.transform(knowledge, b);
        }
    }

    /// Marks the blocks within the depth of the free blocks of the window
    /// around the cells `x0..=x1`, `y0..=y1` (widened by the depth), and the
    /// Unknown cells of the blocks that join. The window is transformed in
    /// strips of rows in parallel: a distance up to the limit comes from at most
    /// `pad` rows away, so each strip is exact with that margin.
    fn transform(
        &mut self,
        knowledge: &OccupancyGrid,
        (x0, y0, x1, y1): (usize, usize, usize, usize),
    ) {
        let g = knowledge.geometry();
        let k = knowledge.cells();
        let (pad, limit, bw) = (self.pad, self.limit, self.bw);
        let (bx0, by0) = (
            (x0 / BLOCK).saturating_sub(pad),
            (y0 / BLOCK).saturating_sub(pad),
        );
        let (bx1, by1) = (
            (x1 / BLOCK).saturating_add(pad).min(bw - 1),
            (y1 / BLOCK).saturating_add(pad).min(self.bh - 1),
        );
        let (ww, wh) = (bx1 - bx0 + 1, by1 - by0 + 1);
        // Free blocks of the window.
        let mut free = vec![false; ww * wh];
        for y in by0 * BLOCK..((by1 + 1) * BLOCK).min(g.height) {
            let row = &k[y * g.width..(y + 1) * g.width];
            let by = y / BLOCK - by0;
            for x in bx0 * BLOCK..((bx1 + 1) * BLOCK).min(g.width) {
                if row[x] == CellState::Free {
                    free[by * ww + x / BLOCK - bx0] = true;
                }
            }
        }
        let strip = wh
            .div_ceil(rayon::current_num_threads().max(1))
            .max(4 * pad);
        let strips: Vec<(usize, Vec<bool>)> = (0..wh.div_ceil(strip))
            .into_par_iter()
            .map(|s| {
                let (r0, r1) = (s * strip, ((s + 1) * strip).min(wh));
                let (m0, m1) = (r0.saturating_sub(pad), (r1 + pad).min(wh));
                let d = chamfer(ww, m1 - m0, |x, y| free[(y + m0) * ww + x]);
                let within = d[(r0 - m0) * ww..(r1 - m0) * ww]
                    .iter()
                    .map(|&v| v <= limit)
                    .collect();
                (r0, within)
            })
            .collect();
        let near = Arc::make_mut(&mut self.near);
        let classes = Arc::make_mut(&mut self.classes);
        for (r0, within) in strips {
            for (j, &w) in within.iter().enumerate() {
                let (bx, by) = (bx0 + j % ww, by0 + r0 + j / ww);
                if !w || self.within[by * bw + bx] {
                    continue;
                }
                self.within[by * bw + bx] = true;
                for y in by * BLOCK..((by + 1) * BLOCK).min(g.height) {
                    for x in bx * BLOCK..((bx + 1) * BLOCK).min(g.width) {
                        let i = y * g.width + x;
                        near[i] = k[i] == CellState::Unknown;
                        classes.set(i, k[i], near[i]);
                    }
                }
            }
        }
    }

    /// Per cell: Unknown and near known free space.
    pub fn near(&self) -> &[bool] {
        &self.near
    }

    /// The known-Free cells.
    pub fn free_cells(&self) -> usize {
        self.free_cells
    }
}

/// The chamfer distance of `depth` cells, in the units of [`chamfer`].
fn chamfer_limit(depth: f64) -> u16 {
    (3.0 * depth.max(0.0) + 1e-9)
        .floor()
        .min(f64::from(u16::MAX - 1)) as u16
}

/// The 3-4 chamfer distance transform of a `width × height` window to the cells
/// with `is_source(x, y)`: three per straight step, four per diagonal one
/// (`3·max(|dx|, |dy|) + min(|dx|, |dy|)`, within 6 % of three times the
/// Euclidean distance), in two raster passes, saturating at `u16::MAX`. A
/// fraction of the cost of the exact transform, and the estimate needs no more.
fn chamfer(width: usize, height: usize, is_source: impl Fn(usize, usize) -> bool) -> Vec<u16> {
    let (w, h) = (width, height);
    let mut d = vec![u16::MAX; w * h];
    if w == 0 {
        return d;
    }
    for y in 0..h {
        for (x, v) in d[y * w..(y + 1) * w].iter_mut().enumerate() {
            if is_source(x, y) {
                *v = 0;
            }
        }
    }
    // The three neighbours of the row before (or after) first, over whole rows
    // (no dependency within the row), then the one beside, left to right (or
    // right to left).
    let from_row = |row: &mut [u16], other: &[u16]| {
        row[0] = row[0].min(other[0].saturating_add(3));
        if w > 1 {
            row[0] = row[0].min(other[1].saturating_add(4));
            row[w - 1] = row[w - 1]
                .min(other[w - 1].saturating_add(3))
                .min(other[w - 2].saturating_add(4));
        }
        for x in 1..w.saturating_sub(1) {
            row[x] = row[x]
                .min(other[x].saturating_add(3))
                .min(other[x - 1].saturating_add(4))
                .min(other[x + 1].saturating_add(4));
        }
    };
    for y in 0..h {
        let (done, rest) = d.split_at_mut(y * w);
        let row = &mut rest[..w];
        if y > 0 {
            from_row(row, &done[(y - 1) * w..]);
        }
        for x in 1..w {
            row[x] = row[x].min(row[x - 1].saturating_add(3));
        }
    }
    for y in (0..h).rev() {
        let (head, below) = d.split_at_mut((y + 1) * w);
        let row = &mut head[y * w..];
        if y + 1 < h {
            from_row(row, &below[..w]);
        }
        for x in (0..w - 1).rev() {
            row[x] = row[x].min(row[x + 1].saturating_add(3));
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;

    /// A 50 × 36 ground truth from `cells` (seven in ten Free, two Occupied,
    /// one Unknown, never seen), nothing known of it yet, and a configuration
    /// of `unknown_depth` = `depth`.
    fn random_start(cells: &[u8], depth: f64) -> (OccupancyGrid, OccupancyGrid, Config) {
        let g = GridGeometry::new(50, 36, 0.1, Point::default());
        let states = cells
            .iter()
            .map(|&c| match c {
                0..=6 => CellState::Free,
                7 | 8 => CellState::Occupied,
                _ => CellState::Unknown,
            })
            .collect();
        let truth = OccupancyGrid::from_cells(g, states).expect("sizes match");
        let mut config = Config::default();
        config.parent.unknown_depth = depth;
        (truth, OccupancyGrid::filled(g, CellState::Unknown), config)
    }

    proptest::proptest! {
        /// The windowed transform marks exactly the Unknown cells within the
        /// depth of a Free cell by the chamfer metric (brute force over every
        /// pair), and `worth_at` agrees with `worth_a_scan` of `at`.
        #[test]
        fn near_cells_match_brute_force(
            cells in proptest::collection::vec(0u8..3, 24 * 18),
            depth in 0.0f64..1.0,
        ) {
            let g = GridGeometry::new(24, 18, 0.1, Point::default());
            let states = cells
                .iter()
                .map(|&c| [CellState::Unknown, CellState::Free, CellState::Occupied][c as usize])
                .collect();
            let k = OccupancyGrid::from_cells(g, states).expect("sizes match");
            let mut config = Config::default();
            config.parent.unknown_depth = depth;
            let e = GainEstimate::new(&k, &config);
            let field = NearField::new(&k, &config);
            let limit = i64::from(chamfer_limit(depth / 0.1 / BLOCK as f64));
            let b = BLOCK as i64;
            for i in 0..g.len() {
                let (bx, by) = ((i % 24) as i64 / b, (i / 24) as i64 / b);
                let want = k.cells()[i] == CellState::Unknown
                    && (0..g.len()).any(|j| {
                        let (jx, jy) = ((j % 24) as i64 / b, (j / 24) as i64 / b);
                        let (dx, dy) = ((jx - bx).abs(), (jy - by).abs());
                        k.cells()[j] == CellState::Free && 3 * dx.max(dy) + dx.min(dy) <= limit
                    });
                proptest::prop_assert_eq!(field.near()[i], want, "cell {}", i);
            }
            for at in [Cell::new(3, 3), Cell::new(12, 9), Cell::new(20, 15)] {
                let full = e.worth_a_scan(&e.at(&k, at, 8.0));
                proptest::prop_assert_eq!(e.worth_at(&k, at, 8.0), full);
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
        /// Kept up to date scan by scan, the field equals the field computed
        /// from scratch after every scan, and so does the estimate from it.
        #[test]
        fn updated_field_equals_a_fresh_one(
            cells in proptest::collection::vec(0u8..10, 50 * 36),
            stops in proptest::collection::vec((0usize..50, 0usize..36), 1..8),
            depth in 0.0f64..1.5,
            range in 3.0f64..30.0,
        ) {
            let (truth, mut knowledge, config) = random_start(&cells, depth);
            let mut field = NearField::new(&knowledge, &config);
            for (x, y) in stops {
                let mut changed = Vec::new();
                crate::sensing::scan(&truth, &mut knowledge, Cell::new(x, y), range, |i| {
                    changed.push(i)
                });
                field.update(&knowledge, &changed);
                let fresh = NearField::new(&knowledge, &config);
                proptest::prop_assert_eq!(field.near(), fresh.near());
                proptest::prop_assert!(*field.classes == *fresh.classes, "classes kept");
                proptest::prop_assert_eq!(field.free_cells(), fresh.free_cells());
                proptest::prop_assert_eq!(&field.within, &fresh.within);
                let (a, b) = (
                    GainEstimate::from_field(&field, &knowledge, &config),
                    GainEstimate::new(&knowledge, &config),
                );
                let at = Cell::new(x, y);
                proptest::prop_assert_eq!(a.at(&knowledge, at, range), b.at(&knowledge, at, range));
                proptest::prop_assert_eq!(a.known_free_m2(), b.known_free_m2());
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
        /// The views kept across scans answer as fresh ones do after every
        /// scan: counts, and the near cells in their order.
        #[test]
        fn kept_views_equal_fresh_ones_after_every_scan(
            cells in proptest::collection::vec(0u8..10, 50 * 36),
            stops in proptest::collection::vec((0usize..50, 0usize..36), 1..6),
            depth in 0.0f64..1.5,
            range in 3.0f64..20.0,
        ) {
            let (truth, mut knowledge, config) = random_start(&cells, depth);
            let mut field = NearField::new(&knowledge, &config);
            let probes: Vec<Cell> = (0..36)
                .step_by(3)
                .flat_map(|y| (0..50).step_by(4).map(move |x| Cell::new(x, y)))
                .collect();
            let ranges = [range, range / 2.0];
            for (x, y) in stops {
                // Every probe's views kept before the scan.
                let kept = GainEstimate::from_field(&field, &knowledge, &config);
                for &p in &probes {
                    for r in ranges {
                        kept.at(&knowledge, p, r);
                        kept.view(&knowledge, p, r);
                    }
                }
                let mut changed = Vec::new();
                crate::sensing::scan(&truth, &mut knowledge, Cell::new(x, y), range, |i| {
                    changed.push(i)
                });
                field.update(&knowledge, &changed);
                let (a, b) = (
                    GainEstimate::from_field(&field, &knowledge, &config),
                    GainEstimate::new(&knowledge, &config),
                );
                for &p in &probes {
                    for r in ranges {
                        let (va, ca) = a.view(&knowledge, p, r);
                        let (vb, cb) = b.view(&knowledge, p, r);
                        proptest::prop_assert_eq!(va, vb, "{:?} at {}", p, r);
                        proptest::prop_assert_eq!(&ca, &cb);
                        proptest::prop_assert_eq!(a.at(&knowledge, p, r), vb);
                    }
                }
            }
            proptest::prop_assert!(field.kept.0.len() > 0, "views were kept");
        }
    }

    #[test]
    fn counts_only_unknown_near_known_free_space() {
        // A corridor known up to x = 20, unknown beyond; depth 1 m = 10 cells.
        let g = GridGeometry::new(100, 10, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        k.fill_rect(0, 0, 100, 1, CellState::Occupied);
        k.fill_rect(0, 9, 100, 10, CellState::Occupied);
        k.fill_rect(0, 1, 20, 9, CellState::Free);
        let mut config = Config::default();
        config.parent.unknown_depth = 1.0;
        config.parent.gain_scale = 1.0;
        let e = GainEstimate::new(&k, &config);
        let gain = e.at(&k, Cell::new(10, 5), 200.0);
        assert_eq!(gain.s_cells, 80 * 8);
        assert_eq!(gain.near_cells, 10 * 8);
        assert!((gain.m2 - 0.8).abs() < 1e-9);
        assert!((e.known_free_m2() - 1.6).abs() < 1e-9);
        // The share rule: 50 % of 1.6 m² is 0.8 m², just met.
        config.parent.min_gain_m2 = 0.0;
        config.parent.min_gain_share = 0.5;
        assert!(GainEstimate::new(&k, &config).worth_a_scan(&gain));
        config.parent.min_gain_share = 0.51;
        assert!(!GainEstimate::new(&k, &config).worth_a_scan(&gain));
    }
}
