//! The part of a big map the episode picture shows: what the episode knows (and
//! what it missed), where the robots went, and a margin; not the mostly unknown
//! rest of the grid.

use cpsplan::GridGeometry;

use super::step::Window;

/// The cells the episode picture shows: the bounding box of the cells `shown`
/// (grid-frame indices, row-major) and of `points` (grid-frame cell coordinates),
/// widened by `margin_m` metres or 3 % of its longer side, whichever is more, and
/// clipped to the grid; the whole grid when there is nothing to show.
pub(crate) fn crop_window(
    g: &GridGeometry,
    shown: impl Iterator<Item = usize>,
    points: impl Iterator<Item = (f64, f64)>,
    margin_m: f64,
) -> Window {
    let (mut lo, mut hi) = (
        (f64::INFINITY, f64::INFINITY),
        (f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    let mut add = |x: f64, y: f64| {
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    };
    for i in shown.filter(|&i| i < g.len()) {
        let (x, y) = ((i % g.width) as f64, (i / g.width) as f64);
        add(x, y);
        add(x + 1.0, y + 1.0);
    }
    for (x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
        add(x, y);
    }
    if lo.0 > hi.0 {
        return Window::whole_of(g);
    }
    let span = (hi.0 - lo.0).max(hi.1 - lo.1);
    let margin = (margin_m / g.resolution).max(0.03 * span);
    let clip = |v: f64, n: usize| v.max(0.0).min(n as f64);
    let x0 = clip((lo.0 - margin).floor(), g.width) as usize;
    let y0 = clip((lo.1 - margin).floor(), g.height) as usize;
    let x1 = clip((hi.0 + margin).ceil(), g.width) as usize;
    let y1 = clip((hi.1 + margin).ceil(), g.height) as usize;
    if x1 <= x0 || y1 <= y0 {
        return Window::whole_of(g);
    }
    Window { x0, y0, x1, y1 }
}

#[cfg(test)]
mod tests {
    use cpsplan::Point;

    use super::*;

    #[test]
    fn crop_holds_known_cells_and_points_with_a_margin() {
        let g = GridGeometry::new(1000, 800, 0.1, Point::new(0.0, 0.0));
        // Known cells (200..=300, 100..=150) and a point at (350.5, 90.5).
        let shown = [100 * 1000 + 200, 150 * 1000 + 300];
        let w = crop_window(&g, shown.into_iter(), [(350.5, 90.5)].into_iter(), 2.0);
        // Margin 20 cells (2 m > 3 % of 151).
        assert_eq!((w.x0, w.y0, w.x1, w.y1), (180, 70, 371, 171));
        // Clipped at the grid's edges.
        let w = crop_window(&g, [0].into_iter(), [(999.0, 799.0)].into_iter(), 2.0);
        assert_eq!((w.x0, w.y0, w.x1, w.y1), (0, 0, 1000, 800));
        // Nothing to show: everything.
        let none = crop_window(&g, std::iter::empty(), [(f64::NAN, 1.0)].into_iter(), 2.0);
        assert_eq!(none, Window::whole_of(&g));
    }
}
