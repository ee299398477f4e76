//! The part of the map a step figure shows: the action with a margin, in a
//! landscape shape, or the whole map when that is small or mostly needed.

use cpsplan::{CellState, GridGeometry, OccupancyGrid};

/// The cells a figure shows: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::render) struct Window {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Window {
    /// Every cell of `g`.
    pub(in crate::render) fn whole_of(g: &GridGeometry) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: g.width,
            y1: g.height,
        }
    }

    /// Columns shown.
    pub(in crate::render) fn width(&self) -> usize {
        self.x1 - self.x0
    }

    /// Rows shown.
    pub(in crate::render) fn height(&self) -> usize {
        self.y1 - self.y0
    }

    /// The window around `points` (grid-frame cell coordinates) with a margin of
    /// `margin_m` metres or a tenth of the larger span, at least `min_side_m` on each
    /// side, widened towards a landscape shape but not further than the margin
    /// beyond the `known` part of the map; the whole grid when that would cover most
    /// of it or the grid is small.
    pub(in crate::render) fn around(
        g: &GridGeometry,
        points: impl Iterator<Item = (f64, f64)>,
        known: Option<Window>,
        margin_m: f64,
        min_side_m: f64,
    ) -> Self {
        let whole = Self::whole_of(g);
        if g.width.max(g.height) <= 200 {
            return whole;
        }
        let (mut lo, mut hi) = (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for (x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        if lo.0 > hi.0 {
            return whole;
        }
        let span = (hi.0 - lo.0).max(hi.1 - lo.1);
        let margin = (margin_m / g.resolution).max(0.1 * span);
        let min_side = min_side_m / g.resolution;
        // Sides with margins, at least `min_side`, between 1.25 and 1.8 times as
        // wide as tall (the picture's header adds height: so the whole picture
        // suits a landscape screen or page); grown about their centres, then
        // shifted back inside the limits.
        let mut w = (hi.0 - lo.0 + 2.0 * margin).max(min_side);
        let mut h = (hi.1 - lo.1 + 2.0 * margin).max(min_side);
        w = w.max(1.25 * h);
        h = h.max(w / 1.8);
        let known = known.unwrap_or(whole);
        let axis = |lo: f64, hi: f64, side: f64, known: (usize, usize), n: usize| {
            let n = n as f64;
            let limit_lo = (lo - margin).min(known.0 as f64 - margin).max(0.0);
            let limit_hi = (hi + margin).max(known.1 as f64 + margin).min(n);
            span_within((lo + hi) / 2.0, side, limit_lo, limit_hi, n)
        };
        let (x0, x1) = axis(lo.0, hi.0, w, (known.x0, known.x1), g.width);
        let (y0, y1) = axis(lo.1, hi.1, h, (known.y0, known.y1), g.height);
        let w = Self { x0, y0, x1, y1 };
        if w.width() == 0 || w.height() == 0 {
            return whole;
        }
        if (w.width() * w.height()) as f64 >= 0.6 * g.len() as f64 {
            whole
        } else {
            w
        }
    }

    /// The smallest window holding every cell of `grid` that is not Unknown.
    pub(in crate::render) fn known(grid: &OccupancyGrid) -> Option<Window> {
        let width = grid.width();
        let mut w: Option<Window> = None;
        for (i, _) in grid
            .cells()
            .iter()
            .enumerate()
            .filter(|(_, &c)| c != CellState::Unknown)
        {
            let (x, y) = (i % width, i / width);
            let k = w.get_or_insert(Window {
                x0: x,
                y0: y,
                x1: x + 1,
                y1: y + 1,
            });
            k.x0 = k.x0.min(x);
            k.y0 = k.y0.min(y);
            k.x1 = k.x1.max(x + 1);
            k.y1 = k.y1.max(y + 1);
        }
        w
    }

    /// The geometry of the window's cells (same world frame as `g`).
    pub(in crate::render) fn geometry(&self, g: &GridGeometry) -> GridGeometry {
        let origin = g.grid_to_world(self.x0 as f64 * g.resolution, self.y0 as f64 * g.resolution);
        let mut w = GridGeometry::new(self.width(), self.height(), g.resolution, origin);
        w.yaw = g.yaw;
        w
    }

    /// The window's part of a row-major per-cell array of a grid `width` cells wide.
    pub(in crate::render) fn crop<T: Copy>(&self, values: &[T], width: usize) -> Vec<T> {
        (self.y0..self.y1)
            .flat_map(|iy| {
                values[iy * width + self.x0..iy * width + self.x1]
                    .iter()
                    .copied()
            })
            .collect()
    }
}

/// The cells `a..b` of an axis of `n` cells covering `side` cells about `centre`,
/// shifted back inside `[limit_lo, limit_hi]` (and shortened to fit it). Robust to
/// rounding: where `limit_hi - side` falls an ulp below `limit_lo` the span starts
/// at `limit_lo` instead of panicking in `f64::clamp`.
fn span_within(centre: f64, side: f64, limit_lo: f64, limit_hi: f64, n: f64) -> (usize, usize) {
    let side = side.min(limit_hi - limit_lo).max(0.0);
    let start = (centre - side / 2.0).min(limit_hi - side).max(limit_lo);
    let (a, b) = (start.floor().max(0.0), (start + side).ceil().min(n));
    (a as usize, (b as usize).max(a as usize + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn span_survives_limits_an_ulp_apart() {
        // limit_hi - (limit_hi - limit_lo) rounds to just below limit_lo here:
        // `clamp(limit_lo, limit_hi - side)` would panic with min > max.
        let (lo, hi) = (67.18212205620061, 857.683462243974);
        assert!(hi - (hi - lo) < lo);
        let (a, b) = span_within(500.0, 1e9, lo, hi, 900.0);
        assert_eq!((a, b), (67, 858));
        // Inside the limits the span keeps its side about the centre.
        assert_eq!(span_within(100.0, 20.0, 0.0, 900.0, 900.0), (90, 110));
        // Pushed back inside at both ends.
        assert_eq!(span_within(2.0, 20.0, 0.0, 900.0, 900.0), (0, 20));
        assert_eq!(span_within(899.0, 20.0, 0.0, 900.0, 900.0), (880, 900));
    }
}
