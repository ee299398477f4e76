//! How far apart two children must stand during a cycle: two body radii between
//! their centres, and neither's marker on the other's line of sight to the parent
//! (a marker hides the marker behind it; the lines of sight run at marker height,
//! above the robots' bodies).
//!
//! In: two children's cells, the parent's positions of the cycle, the children's
//! body and marker radii in cells. Out: whether the two may stand there together.

use crate::geom::Cell;

/// Whether children at `a` and `b` may stand together: at least two body radii
/// `radius` apart, and neither within `marker` of the other's line of sight to any
/// of `parents` (cell centres, distances in cells).
pub fn apart(a: Cell, b: Cell, parents: &[Cell], radius: f64, marker: f64) -> bool {
    let (ax, ay) = (a.x as f64, a.y as f64);
    let (bx, by) = (b.x as f64, b.y as f64);
    let sep = (2.0 * radius).ceil();
    if (ax - bx).powi(2) + (ay - by).powi(2) < sep * sep {
        return false;
    }
    parents.iter().all(|p| {
        let (px, py) = (p.x as f64, p.y as f64);
        !near_segment((ax, ay), (px, py), (bx, by), marker)
            && !near_segment((bx, by), (px, py), (ax, ay), marker)
    })
}

/// Whether point `q` lies closer than `r` to the segment from `s` to `e`.
fn near_segment(q: (f64, f64), s: (f64, f64), e: (f64, f64), r: f64) -> bool {
    let (dx, dy) = (e.0 - s.0, e.1 - s.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((q.0 - s.0) * dx + (q.1 - s.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (cx, cy) = (s.0 + t * dx - q.0, s.1 + t * dy - q.1);
    cx * cx + cy * cy < r * r
}

/// Where children of one cycle may stand together ([`apart`]).
#[derive(Debug, Clone)]
pub(super) struct Spacing {
    /// The parent's positions of the cycle.
    pub(super) parents: Vec<Cell>,
    /// A child's body radius, cells.
    pub(super) radius: f64,
    /// A marker's radius, cells.
    pub(super) marker: f64,
}

impl Spacing {
    /// Whether children at `a` and `b` may stand together.
    pub(super) fn ok(&self, a: Cell, b: Cell) -> bool {
        apart(a, b, &self.parents, self.radius, self.marker)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_child_on_the_other_ones_line_of_sight_hides_it() {
        let parent = Cell::new(0, 0);
        // In line with the parent, 3 m and 6 m away (0.25 m children, 0.1 m cells).
        assert!(!apart(
            Cell::new(30, 0),
            Cell::new(60, 0),
            &[parent],
            2.5,
            1.0
        ));
        // Off the line by more than the marker's radius.
        assert!(apart(
            Cell::new(30, 2),
            Cell::new(60, 0),
            &[parent],
            2.5,
            1.0
        ));
        assert!(!apart(
            Cell::new(30, 2),
            Cell::new(60, 0),
            &[parent],
            2.5,
            2.5
        ));
        // Too close, whatever the parent.
        assert!(!apart(Cell::new(30, 0), Cell::new(33, 0), &[], 2.5, 1.0));
        assert!(apart(Cell::new(30, 0), Cell::new(35, 0), &[], 2.5, 1.0));
    }
}
