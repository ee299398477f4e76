//! Free space along the beams: a cell is seen empty when a beam from its scan's
//! origin to a point passes through it within the obstacle height band (its
//! band there is observed and holds nothing), and the cell where a beam ends on
//! the ground is seen too. The 2D traversal ([`Traversal`]), with the beam's
//! height where it enters and leaves each cell.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::ground::Ground;
use super::BeamOrigin;
use crate::grid::traversal::Traversal;
use crate::grid::GridGeometry;

/// Beams per progress report.
const CHUNK: usize = 1 << 16;

/// The cells seen empty by the beams of `origins` to the kept `points`,
/// heights measured from `ground`, the obstacle band `(low, high)`.
/// `progress(beams)` after every chunk.
pub fn cleared(
    points: &[[f64; 3]],
    keep: &[bool],
    origins: &[BeamOrigin],
    geometry: &GridGeometry,
    ground: &Ground,
    band: (f64, f64),
    mut progress: impl FnMut(u64),
) -> Vec<bool> {
    let seen: Vec<AtomicBool> = (0..geometry.len())
        .map(|_| AtomicBool::new(false))
        .collect();
    for o in origins {
        let range = o.points.clone();
        for chunk in range.clone().step_by(CHUNK) {
            let end = (chunk + CHUNK).min(range.end);
            (chunk..end)
                .into_par_iter()
                .filter(|&i| keep[i])
                .for_each(|i| {
                    trace(o.origin, points[i], geometry, ground, band, |c| {
                        seen[c].store(true, Ordering::Relaxed)
                    });
                });
            progress((end - chunk) as u64);
        }
    }
    seen.into_iter().map(AtomicBool::into_inner).collect()
}

/// Calls `mark(cell)` for every cell the beam from `from` to `to` crosses
/// within the band, and for its last cell when the beam ends below the band.
fn trace(
    from: [f64; 3],
    to: [f64; 3],
    g: &GridGeometry,
    ground: &Ground,
    (low, high): (f64, f64),
    mut mark: impl FnMut(usize),
) {
    let r = g.resolution;
    let (sx, sy) = g.to_local(crate::geom::Point::new(from[0], from[1]));
    let (ex, ey) = g.to_local(crate::geom::Point::new(to[0], to[1]));
    let dz = to[2] - from[2];
    let (tx, ty) = ((ex / r).floor() as i64, (ey / r).floor() as i64);
    let traversal = Traversal::new(r, (sx, sy), (ex, ey));
    let (mut cell, mut t_in) = (traversal.start(), 0.0);
    // Every cell before the last, with the beam's parameter where it leaves it.
    for (x, y, entry) in traversal {
        let t_out = entry.min(1.0);
        if let Some(c) = g.checked_cell(cell.0, cell.1) {
            let i = g.index(c);
            let base = ground.height(i);
            let (z0, z1) = (from[2] + dz * t_in - base, from[2] + dz * t_out - base);
            if z0.max(z1) >= low && z0.min(z1) <= high {
                mark(i);
            }
        }
        (cell, t_in) = ((x, y), t_out);
    }
    // The last cell: seen when the beam ends on the ground there.
    if let Some(c) = g.checked_cell(tx, ty) {
        let i = g.index(c);
        if to[2] - ground.height(i) < low {
            mark(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;

    fn marks(from: [f64; 3], to: [f64; 3]) -> Vec<usize> {
        let g = GridGeometry::new(20, 3, 0.1, Point::new(0.0, 0.0));
        let mut out = Vec::new();
        trace(from, to, &g, &Ground::Flat, (0.2, 2.0), |c| out.push(c));
        out.iter().map(|&c| c % 20).collect()
    }

    #[test]
    fn a_level_beam_in_the_band_clears_every_cell_but_the_hit() {
        assert_eq!(
            marks([0.05, 0.15, 1.0], [1.55, 0.15, 1.0]),
            (0..15).collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_beam_to_the_floor_clears_until_it_leaves_the_band_and_sees_its_end() {
        // From 1.0 m down to the floor 1.9 m away: below 0.2 m after 80 % of it.
        let m = marks([0.05, 0.15, 1.0], [1.95, 0.15, 0.0]);
        assert_eq!(m.last(), Some(&19));
        assert!(m.contains(&0) && m.contains(&15));
        assert!(!m.contains(&17) && !m.contains(&18), "{m:?}");
    }

    #[test]
    fn a_beam_over_the_band_clears_nothing() {
        assert!(marks([0.05, 0.15, 3.0], [1.55, 0.15, 3.5]).is_empty());
    }
}
