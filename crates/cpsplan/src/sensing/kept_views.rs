//! The gain estimate's views kept across scans (beyond the paper): what a scan
//! from a cell would count ([`super::GainEstimate::view`]) depends only on the
//! knowledge map and the near cells within its range, so it stays valid until
//! a scan changes either there. A planning round asks for the same views again
//! and again (every candidate every round, the tour's hill climbs), and on a
//! large map almost all of them lie far from what the last scan changed.
//!
//! [`super::NearField`] keeps the views of its knowledge map and drops, on every
//! update, those whose reach meets the window the update may have changed (the
//! changed cells' bounding box widened by the near cells' window). The answers
//! are exactly those of a fresh view.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// At most this many views are kept; past it the store starts afresh (the
/// answers stay the same, only the time changes).
pub const MAX_KEPT_VIEWS: usize = 16_384;

/// At most this many near cells (4 bytes each: 32 MiB) are kept over all
/// views; past it the store starts afresh.
pub const MAX_KEPT_CELLS: usize = 8 << 20;

/// One view's counts and, when asked for, the near cells it saw in order.
#[derive(Debug)]
pub(super) struct KeptView {
    pub(super) unknown: usize,
    pub(super) near: usize,
    pub(super) cells: Option<Arc<[u32]>>,
}

/// A view's key: the cell's index and the range's bits.
type Key = (u32, u64);

/// The kept views of one knowledge map.
#[derive(Debug, Default)]
pub(super) struct KeptViews {
    views: Mutex<Store>,
}

/// The views and how many near cells they hold.
#[derive(Debug, Default)]
struct Store {
    views: HashMap<Key, Arc<KeptView>>,
    cells: usize,
}

/// The near cells a view holds.
fn cells_of(v: &KeptView) -> usize {
    v.cells.as_ref().map_or(0, |c| c.len())
}

impl KeptViews {
    /// The view from cell `index` at `range`, if kept (with its cells when
    /// `cells` is asked for).
    pub(super) fn get(&self, index: usize, range: f64, cells: bool) -> Option<Arc<KeptView>> {
        let key = (u32::try_from(index).ok()?, range.to_bits());
        let store = self.views.lock().ok()?;
        store
            .views
            .get(&key)
            .filter(|v| !cells || v.cells.is_some())
            .cloned()
    }

    /// Keeps the view from cell `index` at `range`.
    pub(super) fn put(&self, index: usize, range: f64, view: KeptView) {
        let Ok(index) = u32::try_from(index) else {
            return;
        };
        if let Ok(mut store) = self.views.lock() {
            let cells = cells_of(&view);
            if store.views.len() >= MAX_KEPT_VIEWS
                || store.cells.saturating_add(cells) > MAX_KEPT_CELLS
            {
                *store = Store::default();
            }
            store.cells += cells;
            if let Some(old) = store.views.insert((index, range.to_bits()), Arc::new(view)) {
                store.cells -= cells_of(&old);
            }
        }
    }

    /// Drops every view whose reach (its range plus two cells, Chebyshev)
    /// meets the cells `x0..=x1`, `y0..=y1` of a grid `width` cells wide.
    pub(super) fn forget_near(&self, width: usize, (x0, y0, x1, y1): (usize, usize, usize, usize)) {
        let Ok(mut store) = self.views.lock() else {
            return;
        };
        let Store { views, cells } = &mut *store;
        views.retain(|&(index, bits), v| {
            let reach = f64::from_bits(bits).max(0.0).ceil() + 2.0;
            let reach = if reach.is_finite() {
                reach as usize
            } else {
                usize::MAX
            };
            let (x, y) = (index as usize % width, index as usize / width);
            let keep = x.saturating_add(reach) < x0
                || y.saturating_add(reach) < y0
                || x > x1.saturating_add(reach)
                || y > y1.saturating_add(reach);
            if !keep {
                *cells -= cells_of(v);
            }
            keep
        });
    }

    /// How many views are kept.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.views.lock().map_or(0, |s| s.views.len())
    }

    /// How many near cells the kept views hold, as counted and as summed.
    #[cfg(test)]
    fn cells(&self) -> (usize, usize) {
        self.views.lock().map_or((0, 0), |s| {
            (s.cells, s.views.values().map(|v| cells_of(v)).sum())
        })
    }
}

/// The kept views as a field of [`super::NearField`]: a copy of the field
/// starts with none (its map may go its own way).
#[derive(Debug, Default)]
pub(super) struct Kept(pub(super) Arc<KeptViews>);

impl Clone for Kept {
    fn clone(&self) -> Self {
        Self::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(cells: usize) -> KeptView {
        KeptView {
            unknown: cells,
            near: cells,
            cells: Some(vec![0u32; cells].into()),
        }
    }

    #[test]
    fn views_are_found_replaced_forgotten_near_a_change_and_counted() {
        let kept = KeptViews::default();
        // A 100-cell-wide grid: views at (10, 10) and (90, 10), range 5.
        kept.put(10 * 100 + 10, 5.0, view(3));
        kept.put(10 * 100 + 90, 5.0, view(4));
        kept.put(10 * 100 + 90, 5.0, view(6));
        assert_eq!(kept.cells(), (9, 9));
        assert!(kept.get(10 * 100 + 10, 5.0, true).is_some());
        assert!(
            kept.get(10 * 100 + 10, 4.0, false).is_none(),
            "another range"
        );
        // A change at x 20..=25: (10, 10) reaches x 17 (5 + 2 cells), kept;
        // a change at x 16 meets it.
        kept.forget_near(100, (20, 0, 25, 99));
        assert_eq!(kept.len(), 2);
        kept.forget_near(100, (16, 0, 16, 99));
        assert_eq!(kept.len(), 1);
        assert_eq!(kept.cells(), (6, 6));
        // Counts only: not an answer when the cells are wanted.
        kept.put(
            5,
            5.0,
            KeptView {
                unknown: 1,
                near: 1,
                cells: None,
            },
        );
        assert!(kept.get(5, 5.0, false).is_some());
        assert!(kept.get(5, 5.0, true).is_none());
    }

    #[test]
    fn the_store_starts_afresh_past_its_cell_limit() {
        let kept = KeptViews::default();
        kept.put(1, 5.0, view(MAX_KEPT_CELLS - 10));
        kept.put(2, 5.0, view(5));
        assert_eq!(kept.len(), 2);
        kept.put(3, 5.0, view(20));
        assert_eq!(kept.len(), 1, "past the limit: only the newest");
        assert_eq!(kept.cells(), (20, 20));
    }
}
