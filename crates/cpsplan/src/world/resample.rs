//! Conservative resampling of an occupancy grid to the planner's resolution
//! (DESIGN.md "Conventions": a planning cell is occupied if any source cell in it is).
//!
//! Coarsening (the usual case, e.g. a 0.05 m SLAM map planned at 0.1 m): every
//! source cell is assigned to the target cell that contains its centre, and the
//! target takes the *worst* state among its source cells, in the order
//! Occupied > Unknown > Free. Target cells along the ragged top/right edge that
//! contain no source centre take the worst state of the source cells that overlap
//! them (or Unknown if none does).
//!
//! Refining (target resolution finer than the source) is nearest-neighbour: every
//! target cell takes the state of the source cell under its centre.

use crate::config::{Config, ConfigError};
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// Resolutions closer than this (metres) are treated as equal.
const SAME_RESOLUTION_TOLERANCE: f64 = 1e-9;

/// Slack, in target cells, absorbed by `ceil`/`floor` against floating-point noise
/// (so that e.g. 30 cells of 0.03 m at 0.1 m give 9, not 10, planning cells).
const CELL_EPSILON: f64 = 1e-9;

/// Resample `grid` to cells `resolution` metres wide, conservatively.
///
/// The result keeps the source's origin and yaw; its width and height are
/// `ceil(extent / resolution)`, so it covers the whole source. When coarsening, a
/// planning cell is Occupied if any source cell mapped into it (by its centre) is
/// Occupied, else Unknown if any is Unknown, else Free; cells at the ragged
/// top/right edge with no source centre take the worst state of the source cells
/// overlapping them, or Unknown if none. When refining, the result is
/// nearest-neighbour. A resolution within 1e-9 m of the source's returns a clone.
///
/// # Panics
///
/// If `resolution` is not finite and positive (validate configuration first).
pub fn resample_conservative(grid: &OccupancyGrid, resolution: f64) -> OccupancyGrid {
    assert!(
        resolution.is_finite() && resolution > 0.0,
        "resample_conservative: resolution must be finite and positive, got {resolution}"
    );
    let src = *grid.geometry();
    if (resolution - src.resolution).abs() <= SAME_RESOLUTION_TOLERANCE {
        return grid.clone();
    }
    let scale = src.resolution / resolution; // target cells per source cell
    let width = target_len(src.width, scale);
    let height = target_len(src.height, scale);
    let geometry = GridGeometry {
        width,
        height,
        resolution,
        origin: src.origin,
        yaw: src.yaw,
    };
    let cells = if resolution > src.resolution {
        coarsen(grid, &geometry, scale)
    } else {
        refine(grid, &geometry, scale)
    };
    OccupancyGrid::from_cells(geometry, cells).expect("cell count matches geometry")
}

/// [`resample_conservative`] to `config.resolution`, after checking the planning
/// grid it would make against the configuration's limits
/// ([`Config::check_grid`]): nothing is allocated for a grid beyond them.
pub fn resample_for(grid: &OccupancyGrid, config: &Config) -> Result<OccupancyGrid, ConfigError> {
    let (width, height) = resampled_size(grid.geometry(), config.resolution);
    let o = grid.geometry().origin;
    config.check_grid(width, height, config.resolution, (o.x, o.y))?;
    Ok(resample_conservative(grid, config.resolution))
}

/// Columns and rows of `geometry` resampled to `resolution` (saturating: a
/// size beyond `u64` is `u64::MAX`; non-finite or non-positive resolutions give
/// `u64::MAX` too).
pub fn resampled_size(geometry: &GridGeometry, resolution: f64) -> (u64, u64) {
    if !(resolution.is_finite() && resolution > 0.0) {
        return (u64::MAX, u64::MAX);
    }
    if (resolution - geometry.resolution).abs() <= SAME_RESOLUTION_TOLERANCE {
        return (geometry.width as u64, geometry.height as u64);
    }
    let scale = geometry.resolution / resolution;
    let len = |n: usize| {
        if n == 0 {
            0
        } else {
            // `as` saturates: infinities and huge values become u64::MAX.
            (n as f64 * scale - CELL_EPSILON).ceil().max(1.0) as u64
        }
    };
    (len(geometry.width), len(geometry.height))
}

/// Number of target cells covering `n` source cells, `scale` target cells each.
fn target_len(n: usize, scale: f64) -> usize {
    if n == 0 {
        return 0;
    }
    let len = (n as f64 * scale - CELL_EPSILON).ceil();
    (len.max(1.0)) as usize
}

/// Rank of a state in the conservative order Free < Unknown < Occupied.
fn severity(state: CellState) -> u8 {
    match state {
        CellState::Free => 0,
        CellState::Unknown => 1,
        CellState::Occupied => 2,
    }
}

/// The worse of two states (Occupied > Unknown > Free).
fn worse(a: CellState, b: CellState) -> CellState {
    if severity(b) > severity(a) {
        b
    } else {
        a
    }
}

/// For each source index along one axis, the target index containing its centre.
fn centre_map(n_src: usize, n_dst: usize, scale: f64) -> Vec<usize> {
    (0..n_src)
        .map(|s| {
            let t = ((s as f64 + 0.5) * scale).floor();
            (t.max(0.0) as usize).min(n_dst.saturating_sub(1))
        })
        .collect()
}

/// Source indices along one axis that overlap target index `t` (half-open range).
fn overlap_range(t: usize, n_src: usize, scale: f64) -> (usize, usize) {
    // Target t spans [t, t + 1) target cells = [t / scale, (t + 1) / scale) source cells.
    let lo = (t as f64 / scale + CELL_EPSILON).floor().max(0.0) as usize;
    let hi = ((t as f64 + 1.0) / scale - CELL_EPSILON).ceil().max(0.0) as usize;
    (lo.min(n_src), hi.min(n_src))
}

/// Coarsening: worst state of the source cells whose centres fall in each target.
fn coarsen(grid: &OccupancyGrid, dst: &GridGeometry, scale: f64) -> Vec<CellState> {
    let (sw, sh) = (grid.width(), grid.height());
    let map_x = centre_map(sw, dst.width, scale);
    let map_y = centre_map(sh, dst.height, scale);
    let mut acc: Vec<Option<CellState>> = vec![None; dst.len()];
    let src_cells = grid.cells();
    for (sy, &ty) in map_y.iter().enumerate() {
        let src_row = &src_cells[sy * sw..(sy + 1) * sw];
        let dst_row = &mut acc[ty * dst.width..(ty + 1) * dst.width];
        for (&state, &tx) in src_row.iter().zip(&map_x) {
            let slot = &mut dst_row[tx];
            *slot = Some(match *slot {
                Some(prev) => worse(prev, state),
                None => state,
            });
        }
    }
    acc.iter()
        .enumerate()
        .map(|(i, slot)| match slot {
            Some(state) => *state,
            None => {
                // Ragged edge: no source centre here; use the overlapping sources.
                let (tx, ty) = (i % dst.width, i / dst.width);
                let (x0, x1) = overlap_range(tx, sw, scale);
                let (y0, y1) = overlap_range(ty, sh, scale);
                let mut state: Option<CellState> = None;
                for sy in y0..y1 {
                    for &s in &src_cells[sy * sw + x0..sy * sw + x1] {
                        state = Some(state.map_or(s, |prev| worse(prev, s)));
                    }
                }
                state.unwrap_or(CellState::Unknown)
            }
        })
        .collect()
}

/// Refining: nearest-neighbour, the source cell under each target centre.
fn refine(grid: &OccupancyGrid, dst: &GridGeometry, scale: f64) -> Vec<CellState> {
    let (sw, sh) = (grid.width(), grid.height());
    let nearest = |t: usize, n_src: usize| -> usize {
        let s = ((t as f64 + 0.5) / scale).floor().max(0.0) as usize;
        s.min(n_src.saturating_sub(1))
    };
    let src_x: Vec<usize> = (0..dst.width).map(|t| nearest(t, sw)).collect();
    let src_cells = grid.cells();
    let mut cells = Vec::with_capacity(dst.len());
    for ty in 0..dst.height {
        let sy = nearest(ty, sh);
        let src_row = &src_cells[sy * sw..(sy + 1) * sw];
        cells.extend(src_x.iter().map(|&sx| src_row[sx]));
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Cell, Point};

    fn grid(w: usize, h: usize, res: f64, state: CellState) -> OccupancyGrid {
        let mut g = GridGeometry::new(w, h, res, Point::new(-1.5, 2.25));
        g.yaw = 0.3;
        OccupancyGrid::filled(g, state)
    }

    #[test]
    fn single_occupied_cell_marks_exactly_its_coarse_cell() {
        for (sx, sy) in [(0, 0), (3, 7), (19, 19), (10, 4)] {
            let mut g = grid(20, 20, 0.05, CellState::Free);
            g.set(Cell::new(sx, sy), CellState::Occupied);
            let r = resample_conservative(&g, 0.1);
            assert_eq!((r.width(), r.height()), (10, 10));
            assert_eq!(r.count(CellState::Occupied), 1);
            assert_eq!(r.get(Cell::new(sx / 2, sy / 2)), CellState::Occupied);
            assert_eq!(r.count(CellState::Free), 99);
            // The occupied source centre lies in the occupied coarse cell.
            let c = r
                .geometry()
                .world_to_cell(g.geometry().cell_center(Cell::new(sx, sy)));
            assert_eq!(c, Some(Cell::new(sx / 2, sy / 2)));
        }
    }

    #[test]
    fn occupied_beats_unknown_beats_free() {
        let mut g = grid(4, 2, 0.05, CellState::Free);
        g.set(Cell::new(0, 0), CellState::Unknown);
        g.set(Cell::new(1, 1), CellState::Occupied);
        g.set(Cell::new(2, 0), CellState::Unknown);
        let r = resample_conservative(&g, 0.1);
        assert_eq!(r.cells(), &[CellState::Occupied, CellState::Unknown]);
    }

    #[test]
    fn free_only_stays_free() {
        for res in [0.1, 0.07, 0.15, 0.3] {
            let g = grid(37, 23, 0.05, CellState::Free);
            let r = resample_conservative(&g, res);
            assert_eq!(r.count(CellState::Free), r.cells().len(), "res {res}");
        }
    }

    #[test]
    fn equal_resolution_is_identity() {
        let mut g = grid(7, 5, 0.05, CellState::Free);
        g.set(Cell::new(3, 2), CellState::Occupied);
        g.set(Cell::new(6, 4), CellState::Unknown);
        assert_eq!(resample_conservative(&g, 0.05), g);
        assert_eq!(resample_conservative(&g, 0.05 + 1e-12), g);
    }

    #[test]
    fn sizes_cover_the_source_and_keep_placement() {
        // (source cells, source res, target res, expected target cells)
        let cases = [
            (566, 0.1, 0.1, 566),
            (1536, 0.02, 0.1, 308),
            (1006, 0.03, 0.1, 302),
            (30, 0.03, 0.1, 9),
            (1, 0.05, 0.1, 1),
            (7, 0.05, 0.1, 4),
            (10, 0.1, 0.05, 20),
            (3, 0.1, 0.04, 8),
        ];
        for (n, src, dst, want) in cases {
            let g = grid(n, n, src, CellState::Free);
            let r = resample_conservative(&g, dst);
            assert_eq!((r.width(), r.height()), (want, want), "{n} × {src} → {dst}");
            assert_eq!(r.geometry().origin, g.geometry().origin);
            assert_eq!(r.geometry().yaw, g.geometry().yaw);
            assert_eq!(r.resolution(), dst);
        }
        let empty = grid(0, 0, 0.05, CellState::Free);
        assert!(resample_conservative(&empty, 0.1).cells().is_empty());
    }

    #[test]
    fn ragged_edge_takes_overlapping_sources() {
        // 7 cells of 0.05 m → 4 cells of 0.1 m; the last one holds only the centre
        // of source cell 6 (0.325 m).
        let mut g = grid(7, 1, 0.05, CellState::Free);
        g.set(Cell::new(6, 0), CellState::Occupied);
        let r = resample_conservative(&g, 0.1);
        assert_eq!(r.width(), 4);
        assert_eq!(r.get(Cell::new(3, 0)), CellState::Occupied);
        assert_eq!(r.count(CellState::Occupied), 1);

        // 2 cells of 0.1 m → 2 cells of 0.16 m. Both source centres (0.05, 0.15 m)
        // fall in target 0; target 1 (0.16–0.32 m) holds no centre and takes the
        // state of source 1 (0.1–0.2 m), which overlaps it.
        let mut g = grid(2, 1, 0.1, CellState::Free);
        g.set(Cell::new(1, 0), CellState::Occupied);
        let r = resample_conservative(&g, 0.16);
        assert_eq!(r.cells(), &[CellState::Occupied, CellState::Occupied]);
        let g = grid(2, 1, 0.1, CellState::Free);
        let r = resample_conservative(&g, 0.16);
        assert_eq!(r.cells(), &[CellState::Free, CellState::Free]);
    }

    #[test]
    fn refining_is_nearest_neighbour() {
        let mut g = grid(2, 2, 0.1, CellState::Free);
        g.set(Cell::new(1, 0), CellState::Occupied);
        g.set(Cell::new(0, 1), CellState::Unknown);
        let r = resample_conservative(&g, 0.05);
        assert_eq!((r.width(), r.height()), (4, 4));
        for y in 0..4 {
            for x in 0..4 {
                assert_eq!(r.get(Cell::new(x, y)), g.get(Cell::new(x / 2, y / 2)));
            }
        }
    }
}
