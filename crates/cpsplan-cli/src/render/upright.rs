//! Pictures drawn as RViz shows a map: world +x to the right and +y up. A grid
//! whose frame is turned against the world by about a quarter turn or a half
//! (ROS map_server `origin` yaw π, ±π/2: the MIT Stata basement's 3.14) is
//! re-indexed before it is drawn: the same cells at the same world places, its
//! frame turned by the quarter turns that bring it within [`SNAP_RAD`] of the
//! world's axes. What is left of the yaw (0.0016 rad for 3.14) keeps the
//! compass; every overlay is given in world coordinates and lands where it did.

use std::borrow::Cow;
use std::f64::consts::FRAC_PI_2;

use cpsplan::{Cell, GridGeometry, OccupancyGrid, Point};

/// How far from a quarter turn a yaw may be to be drawn upright.
pub(crate) const SNAP_RAD: f64 = 0.02;

/// The quarter turns (1, 2 or 3, counter-clockwise) within [`SNAP_RAD`] of `yaw`;
/// `None` when `yaw` is near 0 or far from every quarter turn.
pub(crate) fn quarter_turns(yaw: f64) -> Option<u8> {
    if !yaw.is_finite() {
        return None;
    }
    let k = (yaw / FRAC_PI_2).round();
    let left = yaw - k * FRAC_PI_2;
    let k = k.rem_euclid(4.0) as u8;
    (k != 0 && left.abs() <= SNAP_RAD).then_some(k)
}

/// The geometry of `g` turned by `k` quarter turns, and the old cell of each
/// new cell.
fn turned(g: &GridGeometry, k: u8) -> (GridGeometry, impl Fn(usize, usize) -> Cell + '_) {
    let (w, h, res) = (g.width, g.height, g.resolution);
    let left = g.yaw - f64::from(k) * FRAC_PI_2;
    let yaw = left.sin().atan2(left.cos());
    let (s, c) = yaw.sin_cos();
    // The new origin: a corner of the old grid, in world coordinates.
    let rot = |x: f64, y: f64| Point::new(g.origin.x + c * x - s * y, g.origin.y + s * x + c * y);
    let (wm, hm) = (w as f64 * res, h as f64 * res);
    let (new_w, new_h, origin) = match k {
        // World = O + R(yaw′)·(−y, x): the new x runs along the old −y.
        1 => (h, w, rot(-hm, 0.0)),
        // World = O + R(yaw′)·(−x, −y): the old far corner is the new origin.
        2 => (w, h, rot(-wm, -hm)),
        // World = O + R(yaw′)·(y, −x): the new y runs along the old −x.
        _ => (h, w, rot(0.0, -wm)),
    };
    let geometry = GridGeometry {
        width: new_w,
        height: new_h,
        resolution: res,
        origin,
        yaw,
    };
    let old = move |i: usize, j: usize| match k {
        1 => Cell::new(j, h - 1 - i),
        2 => Cell::new(w - 1 - i, h - 1 - j),
        _ => Cell::new(w - 1 - j, i),
    };
    (geometry, old)
}

/// The upright geometry of a grid of geometry `g` and, for each of its cells
/// in index order, the index of the same cell in `g`; `None` when `g` is drawn
/// as it is.
pub(crate) fn upright_order(g: &GridGeometry) -> Option<(GridGeometry, Vec<usize>)> {
    let k = quarter_turns(g.yaw)?;
    let (geometry, old) = turned(g, k);
    let mut order = Vec::with_capacity(g.len());
    for j in 0..geometry.height {
        for i in 0..geometry.width {
            order.push(g.index(old(i, j)));
        }
    }
    Some((geometry, order))
}

/// `grid` with its frame within [`SNAP_RAD`] of the world's axes (borrowed when
/// it is already).
pub(crate) fn upright(grid: &OccupancyGrid) -> Cow<'_, OccupancyGrid> {
    let Some((geometry, order)) = upright_order(grid.geometry()) else {
        return Cow::Borrowed(grid);
    };
    let cells = order.iter().map(|&i| grid.cells()[i]).collect();
    match OccupancyGrid::from_cells(geometry, cells) {
        Some(turned) => Cow::Owned(turned),
        None => Cow::Borrowed(grid),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cpsplan::CellState;

    /// The MIT Stata basement's map_server yaw, 3.14.
    const STATA_YAW: f64 = std::f64::consts::PI - 0.0016;

    #[test]
    fn only_yaws_near_a_quarter_turn_are_turned() {
        assert_eq!(quarter_turns(0.0), None);
        assert_eq!(quarter_turns(0.01), None);
        assert_eq!(quarter_turns(STATA_YAW), Some(2));
        assert_eq!(quarter_turns(-std::f64::consts::PI), Some(2));
        assert_eq!(quarter_turns(FRAC_PI_2), Some(1));
        assert_eq!(quarter_turns(-FRAC_PI_2 + 0.01), Some(3));
        assert_eq!(quarter_turns(0.7), None);
        assert_eq!(quarter_turns(f64::NAN), None);
    }

    /// Every cell keeps its world place, and the new frame lies along the
    /// world's axes within the snap.
    #[test]
    fn every_cell_keeps_its_world_place() {
        for yaw in [
            STATA_YAW,
            std::f64::consts::PI,
            FRAC_PI_2,
            -FRAC_PI_2 + 0.005,
            4.7,
        ] {
            let g = GridGeometry {
                width: 7,
                height: 4,
                resolution: 0.5,
                origin: Point::new(3.0, -2.0),
                yaw,
            };
            let cells: Vec<CellState> = (0..g.len())
                .map(|i| [CellState::Free, CellState::Occupied, CellState::Unknown][i % 3])
                .collect();
            let grid = OccupancyGrid::from_cells(g, cells).unwrap();
            let up = upright(&grid);
            let u = up.geometry();
            assert!(
                quarter_turns(u.yaw).is_none() && u.yaw.abs() <= SNAP_RAD,
                "{yaw}: {}",
                u.yaw
            );
            assert_eq!(u.len(), g.len());
            for j in 0..u.height {
                for i in 0..u.width {
                    let here = Cell::new(i, j);
                    let p = u.cell_center(here);
                    let was = g.world_to_cell(p).expect("inside the old grid");
                    assert_eq!(up.get(here), grid.get(was), "yaw {yaw} at {i},{j}");
                    assert!(g.cell_center(was).distance(p) < 1e-9);
                }
            }
        }
    }
}
