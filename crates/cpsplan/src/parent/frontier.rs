//! Steps 1 and 2 of section IV-A-1 kept across scans: the border, its significant
//! part and the band, updated where a scan changed the knowledge map instead of
//! recomputed over the whole map.
//!
//! In: the knowledge map and the cells a scan changed. Out: the same border,
//! significant border and band as [`border_cells`], [`significant_border`] and
//! [`band()`](super::band()) on the whole map (a property test compares them after every scan).
//!
//! Why a window suffices, with `W` the bounding box of the changed cells and `r`
//! the band's width in whole cells (a path of at most that travel takes at most
//! `r` steps, and no step moves more than one row or column):
//! - a cell's border state depends on its 4-neighbours, so it can change only in
//!   `W` grown by one cell;
//! - a group of 8-connected border cells changes only if it has a cell in `W`
//!   grown by two (a group split or joined there has one): only those groups are
//!   flooded again, and only their cells can become or stop being significant;
//! - a cell's band state depends on the Free cells and significant border cells
//!   within `r` of it, so it can change only within `r` of a changed cell or of a
//!   cell whose significance changed, and is found again from the significant
//!   border cells within `2r` of those.

use crate::config::ParentConfig;
use crate::grid::window::{merge_changes, Spans, Window};
use crate::grid::{DistanceField, GridGeometry, OccupancyGrid};

use super::band::band_within;
use super::border::{border_cells, border_in, flood_group, is_significant, significant_border};
use super::viewpoints::{viewpoints_kept, KeptLooks, Viewpoint};

/// Cell flag: a border cell.
const BORDER: u8 = 1;
/// Cell flag: a border cell of a significant group.
const SIGNIFICANT: u8 = 2;
/// Cell flag: flooded in this update.
const FLOODED: u8 = 4;

/// The border, the significant border and the band of one knowledge map, kept up
/// to date scan by scan ([`Frontier::update`]).
#[derive(Debug, Clone)]
pub struct Frontier {
    geometry: GridGeometry,
    min_cells: usize,
    band_cost: u32,
    band_steps: usize,
    flags: Vec<u8>,
    border: Vec<usize>,
    significant: Vec<usize>,
    band: Vec<usize>,
    /// The next list, swapped in after an update (kept to reuse its memory).
    spare: Vec<usize>,
    /// What the border groups' viewpoint searches found, for the groups no
    /// scan has changed since.
    looks: KeptLooks,
}

impl Frontier {
    /// The border and band of `knowledge` from scratch, with the border groups'
    /// minimum size and the band's width of `config`.
    pub fn new(knowledge: &OccupancyGrid, config: &ParentConfig) -> Self {
        let g = *knowledge.geometry();
        let border = border_cells(knowledge);
        let significant = significant_border(&g, &border, config.min_frontier_cells);
        let band_cost = DistanceField::cost_of(config.band_width, g.resolution);
        let band = band_within(knowledge, &significant, band_cost);
        let mut flags = vec![0u8; g.len()];
        for &i in &border {
            flags[i] |= BORDER;
        }
        for &i in &significant {
            flags[i] |= SIGNIFICANT;
        }
        Self {
            geometry: g,
            min_cells: config.min_frontier_cells,
            band_cost,
            band_steps: (band_cost / crate::grid::travel::STRAIGHT) as usize,
            flags,
            border,
            significant,
            band,
            spare: Vec::new(),
            looks: KeptLooks::default(),
        }
    }

    /// Every border cell, in index order ([`border_cells`]).
    pub fn border(&self) -> &[usize] {
        &self.border
    }

    /// The border cells of significant groups, in index order
    /// ([`significant_border`]).
    pub fn significant(&self) -> &[usize] {
        &self.significant
    }

    /// The band around the significant border, in index order ([`band()`](super::band())).
    pub fn band(&self) -> &[usize] {
        &self.band
    }

    /// The best viewpoint of every group of the significant border
    /// ([`super::viewpoints()`]), reusing the sight lines of the groups that no
    /// scan changed since the last call (the same answers).
    pub fn viewpoints(
        &self,
        knowledge: &OccupancyGrid,
        range_cells: f64,
        valid: impl Fn(usize) -> bool + Sync,
        cost: impl Fn(usize) -> f64 + Sync,
    ) -> Vec<Viewpoint> {
        let flags = &self.flags;
        viewpoints_kept(
            knowledge,
            &self.significant,
            |j| flags[j] & SIGNIFICANT != 0,
            range_cells,
            valid,
            cost,
            Some(&self.looks),
        )
    }

    /// Brings the state up to date with `knowledge` after the cells `changed` (any
    /// changes, in any order, repeats allowed) took new states.
    pub fn update(&mut self, knowledge: &OccupancyGrid, changed: &[usize]) {
        let g = self.geometry;
        debug_assert_eq!(&g, knowledge.geometry());
        let Some(changes) = Window::bounding(&g, changed) else {
            return;
        };
        self.looks.forget(&changes);
        // Step 1: the border, in the changed window grown by one.
        let near = changes.grow(1, &g);
        let near_spans = Spans::of(&[near], g.width);
        let old: Vec<usize> = near_spans.select(&self.border).collect();
        for &i in &old {
            self.flags[i] &= !BORDER;
        }
        let mut fresh = Vec::new();
        border_in(knowledge, near, &mut fresh);
        for &i in &fresh {
            self.flags[i] |= BORDER;
        }
        near_spans.replace(&self.border, &fresh, &mut self.spare);
        std::mem::swap(&mut self.border, &mut self.spare);

        // The significant border: cells that left the border, and the groups that
        // reach into the window grown by two, flooded again.
        let mut removed = Vec::new();
        let mut added = Vec::new();
        for &i in &old {
            if self.flags[i] & (BORDER | SIGNIFICANT) == SIGNIFICANT {
                self.flags[i] &= !SIGNIFICANT;
                removed.push(i);
            }
        }
        let touching = changes.grow(2, &g);
        let mut dirty = vec![touching];
        let starts: Vec<usize> = Spans::of(&[touching], g.width)
            .select(&self.border)
            .collect();
        let mut flooded = Vec::new();
        let mut group = Vec::new();
        let mut far = Vec::new();
        for s in starts {
            if self.flags[s] & FLOODED != 0 {
                continue;
            }
            self.flood(s, &mut group);
            flooded.extend_from_slice(&group);
            let keep = is_significant(group.len(), self.min_cells);
            // The cells whose significance flips outside the window grown by two.
            far.clear();
            for &i in &group {
                let was = self.flags[i] & SIGNIFICANT != 0;
                if was == keep {
                    continue;
                }
                self.flags[i] ^= SIGNIFICANT;
                if keep {
                    added.push(i);
                } else {
                    removed.push(i);
                }
                if !touching.holds(i % g.width, i / g.width) {
                    far.push(i);
                }
            }
            dirty.extend(Window::bounding(&g, &far));
        }
        for &i in &flooded {
            self.flags[i] &= !FLOODED;
        }
        removed.sort_unstable();
        added.sort_unstable();
        merge_changes(&self.significant, &removed, &added, &mut self.spare);
        std::mem::swap(&mut self.significant, &mut self.spare);

        // Step 2: the band within r of a changed cell or a changed significance,
        // searched again from the significant border within 2r of them.
        let r = self.band_steps;
        let affected: Vec<Window> = dirty.iter().map(|b| b.grow(r, &g)).collect();
        let sourced: Vec<Window> = dirty.iter().map(|b| b.grow(2 * r, &g)).collect();
        let affected = Spans::of(&affected, g.width);
        let sources: Vec<usize> = Spans::of(&sourced, g.width)
            .select(&self.significant)
            .collect();
        let reached = band_within(knowledge, &sources, self.band_cost);
        let fresh: Vec<usize> = affected.select(&reached).collect();
        affected.replace(&self.band, &fresh, &mut self.spare);
        std::mem::swap(&mut self.band, &mut self.spare);
    }

    /// Floods the 8-connected group of border cells of `start` into `group`,
    /// marking its cells [`FLOODED`].
    fn flood(&mut self, start: usize, group: &mut Vec<usize>) {
        let flags = &mut self.flags;
        flags[start] |= FLOODED;
        flood_group(&self.geometry, start, group, |j| {
            let take = flags[j] & (BORDER | FLOODED) == BORDER;
            if take {
                flags[j] |= FLOODED;
            }
            take
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Cell, Point};
    use crate::grid::fixtures::{paint, STATES};
    use crate::grid::CellState;
    use crate::sensing::scan;
    use proptest::prelude::*;

    fn assert_fresh(state: &Frontier, knowledge: &OccupancyGrid, config: &ParentConfig) {
        let fresh = Frontier::new(knowledge, config);
        assert_eq!(state.border(), fresh.border(), "border");
        assert_eq!(
            state.significant(),
            fresh.significant(),
            "significant border"
        );
        assert_eq!(state.band(), fresh.band(), "band");
        assert_eq!(state.flags, fresh.flags, "flags");
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// Scans of a random map from random cells: after every scan the kept
        /// state equals the state computed from scratch.
        #[test]
        fn scans_keep_the_state_of_a_fresh_computation(
            w in 8usize..60,
            h in 8usize..60,
            walls in proptest::collection::vec((0usize..60, 0usize..60, 1usize..12, 1usize..12), 0..10),
            stops in proptest::collection::vec((0usize..60, 0usize..60), 1..8),
            range in 3.0f64..25.0,
            min_cells in 0usize..6,
            band_width in 0.0f64..2.0,
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let mut truth = OccupancyGrid::filled(g, CellState::Free);
            for &(x, y, rw, rh) in &walls {
                let (x, y) = (x % w, y % h);
                truth.fill_rect(x, y, (x + rw).min(w), (y + rh).min(h), CellState::Occupied);
            }
            let config = ParentConfig { min_frontier_cells: min_cells, band_width, ..ParentConfig::default() };
            let mut knowledge = OccupancyGrid::filled(g, CellState::Unknown);
            let mut state = Frontier::new(&knowledge, &config);
            for &(x, y) in &stops {
                let mut changed = Vec::new();
                scan(&truth, &mut knowledge, Cell::new(x % w, y % h), range, |i| changed.push(i));
                state.update(&knowledge, &changed);
                assert_fresh(&state, &knowledge, &config);
            }
        }

        /// Scans of a random map at 1 m a cell (so that groups lie outside the
        /// windows a scan changes), each followed by an arbitrary change: after
        /// every scan the viewpoints from the
        /// kept looks equal those of a fresh search, for positions and
        /// travel costs that change from call to call.
        #[test]
        fn kept_looks_give_the_viewpoints_of_a_fresh_search(
            walls in proptest::collection::vec((0usize..90, 0usize..90, 1usize..20, 1usize..4), 0..16),
            stops in proptest::collection::vec((0usize..90, 0usize..90, 0usize..1000), 1..10),
            edits in proptest::collection::vec((0usize..90, 0usize..90, 1usize..6, 1usize..6, 0usize..3), 10),
            range in 4.0f64..30.0,
        ) {
            let g = GridGeometry::new(90, 90, 1.0, Point::default());
            let mut truth = OccupancyGrid::filled(g, CellState::Free);
            for (n, &(x, y, a, b)) in walls.iter().enumerate() {
                let (rw, rh) = if n % 2 == 0 { (a, b) } else { (b, a) };
                truth.fill_rect(x, y, (x + rw).min(90), (y + rh).min(90), CellState::Occupied);
            }
            let config = ParentConfig { min_frontier_cells: 0, ..ParentConfig::default() };
            let mut knowledge = OccupancyGrid::filled(g, CellState::Unknown);
            let mut state = Frontier::new(&knowledge, &config);
            for (&(x, y, salt), &(ex, ey, ew, eh, es)) in stops.iter().zip(&edits) {
                let mut changed = Vec::new();
                scan(&truth, &mut knowledge, Cell::new(x, y), range, |i| changed.push(i));
                state.update(&knowledge, &changed);
                // Any change, also one that does not touch a group's cells.
                let changed = paint(&mut knowledge, (ex, ey, ew, eh), STATES[es]);
                state.update(&knowledge, &changed);
                let k = knowledge.cells();
                let valid = |i: usize| k[i] == CellState::Free && !(i + salt).is_multiple_of(5);
                let cost = |i: usize| ((i * 7919 + salt) % 13) as f64;
                let fresh = super::super::viewpoints(&knowledge, state.significant(), range, valid, cost);
                prop_assert_eq!(state.viewpoints(&knowledge, range, valid, cost), fresh.clone());
                // Asked again in the same state: the same.
                prop_assert_eq!(state.viewpoints(&knowledge, range, valid, cost), fresh);
            }
        }

        /// Arbitrary changes, including known cells turning Unknown again.
        #[test]
        fn any_changes_keep_the_state_of_a_fresh_computation(
            w in 4usize..40,
            h in 4usize..40,
            start in proptest::collection::vec(0usize..3, 1600),
            edits in proptest::collection::vec((0usize..40, 0usize..40, 1usize..15, 1usize..15, 0usize..3), 1..8),
            min_cells in 0usize..8,
            band_width in 0.0f64..1.5,
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let cells = (0..g.len()).map(|i| STATES[start[i]]).collect();
            let mut knowledge = OccupancyGrid::from_cells(g, cells).unwrap();
            let config = ParentConfig { min_frontier_cells: min_cells, band_width, ..ParentConfig::default() };
            let mut state = Frontier::new(&knowledge, &config);
            for &(x, y, rw, rh, s) in &edits {
                let changed = paint(&mut knowledge, (x, y, rw, rh), STATES[s]);
                state.update(&knowledge, &changed);
                assert_fresh(&state, &knowledge, &config);
            }
        }
    }
}
