//! Rectangles of cells and sorted cell lists updated inside them: what state kept
//! across scans needs, since a scan changes the knowledge map only inside the
//! bounding box of the cells it revealed.
//!
//! A union of rectangles is handled as [`Spans`]: sorted, disjoint, inclusive
//! ranges of cell indices, one or more per grid row.

use crate::grid::GridGeometry;

/// An inclusive rectangle of cells `(x0, y0)..=(x1, y1)` on a grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// Last column (inclusive).
    pub x1: usize,
    /// Last row (inclusive).
    pub y1: usize,
}

impl Window {
    /// The bounding box of the cells `indices` of `geometry`; `None` if there are
    /// none.
    pub fn bounding(geometry: &GridGeometry, indices: &[usize]) -> Option<Self> {
        let w = geometry.width;
        let mut it = indices.iter().map(|&i| (i % w, i / w));
        let (x, y) = it.next()?;
        let mut b = Self {
            x0: x,
            y0: y,
            x1: x,
            y1: y,
        };
        for (x, y) in it {
            b.x0 = b.x0.min(x);
            b.x1 = b.x1.max(x);
            b.y0 = b.y0.min(y);
            b.y1 = b.y1.max(y);
        }
        Some(b)
    }

    /// The whole grid; `None` for an empty one.
    pub fn all(geometry: &GridGeometry) -> Option<Self> {
        (geometry.width > 0 && geometry.height > 0).then(|| Self {
            x0: 0,
            y0: 0,
            x1: geometry.width - 1,
            y1: geometry.height - 1,
        })
    }

    /// The window grown by `r` cells on every side, clipped to the grid.
    pub fn grow(self, r: usize, geometry: &GridGeometry) -> Self {
        Self {
            x0: self.x0.saturating_sub(r),
            y0: self.y0.saturating_sub(r),
            x1: self.x1.saturating_add(r).min(geometry.width - 1),
            y1: self.y1.saturating_add(r).min(geometry.height - 1),
        }
    }

    /// Whether the window holds the whole of `other`.
    pub fn contains(&self, other: &Window) -> bool {
        self.x0 <= other.x0 && self.y0 <= other.y0 && self.x1 >= other.x1 && self.y1 >= other.y1
    }

    /// Whether the two windows share a cell.
    pub fn meets(&self, other: &Window) -> bool {
        self.x0 <= other.x1 && other.x0 <= self.x1 && self.y0 <= other.y1 && other.y0 <= self.y1
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.x1 - self.x0 + 1
    }

    /// Whether cell `(x, y)` lies in the window.
    pub fn holds(&self, x: usize, y: usize) -> bool {
        (self.x0..=self.x1).contains(&x) && (self.y0..=self.y1).contains(&y)
    }
}

/// A union of windows as sorted, disjoint, inclusive index ranges.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Spans(Vec<(usize, usize)>);

impl Spans {
    /// The cells of the union of `windows` on a grid `width` cells wide.
    pub fn of(windows: &[Window], width: usize) -> Self {
        let (Some(top), Some(bottom)) = (
            windows.iter().map(|w| w.y0).min(),
            windows.iter().map(|w| w.y1).max(),
        ) else {
            return Self::default();
        };
        let mut out = Vec::new();
        let mut row: Vec<(usize, usize)> = Vec::new();
        for y in top..=bottom {
            row.clear();
            row.extend(
                windows
                    .iter()
                    .filter(|w| (w.y0..=w.y1).contains(&y))
                    .map(|w| (w.x0, w.x1)),
            );
            row.sort_unstable();
            let mut merged: Option<(usize, usize)> = None;
            for &(a, b) in &row {
                merged = match merged {
                    Some((m0, m1)) if a <= m1 + 1 => Some((m0, m1.max(b))),
                    Some((m0, m1)) => {
                        out.push((y * width + m0, y * width + m1));
                        Some((a, b))
                    }
                    None => Some((a, b)),
                };
            }
            if let Some((m0, m1)) = merged {
                out.push((y * width + m0, y * width + m1));
            }
        }
        Self(out)
    }

    /// The ranges, sorted and disjoint.
    pub fn ranges(&self) -> &[(usize, usize)] {
        &self.0
    }

    /// The entries of the sorted `list` inside the spans, in order.
    pub fn select<'a>(&'a self, list: &'a [usize]) -> impl Iterator<Item = usize> + 'a {
        let mut from = 0;
        self.0.iter().flat_map(move |&(lo, hi)| {
            let start = from + list[from..].partition_point(|&i| i < lo);
            let end = start + list[start..].partition_point(|&i| i <= hi);
            from = end;
            list[start..end].iter().copied()
        })
    }

    /// Writes into `out` the sorted `list` with its entries inside the spans
    /// replaced by `fresh` (sorted; entries outside the spans are dropped).
    pub fn replace(&self, list: &[usize], fresh: &[usize], out: &mut Vec<usize>) {
        out.clear();
        out.reserve(list.len() + fresh.len());
        let (mut a, mut f) = (0, 0);
        for &(lo, hi) in &self.0 {
            let start = a + list[a..].partition_point(|&i| i < lo);
            out.extend_from_slice(&list[a..start]);
            a = start + list[start..].partition_point(|&i| i <= hi);
            f += fresh[f..].partition_point(|&i| i < lo);
            let fend = f + fresh[f..].partition_point(|&i| i <= hi);
            out.extend_from_slice(&fresh[f..fend]);
            f = fend;
        }
        out.extend_from_slice(&list[a..]);
    }
}

/// Writes into `out` the sorted `list` without the sorted `removed` and with the
/// sorted `added` (none of which is in `list`).
pub fn merge_changes(list: &[usize], removed: &[usize], added: &[usize], out: &mut Vec<usize>) {
    out.clear();
    out.reserve(list.len() + added.len());
    let (mut r, mut a) = (0, 0);
    for &i in list {
        while a < added.len() && added[a] < i {
            out.push(added[a]);
            a += 1;
        }
        while r < removed.len() && removed[r] < i {
            r += 1;
        }
        if r < removed.len() && removed[r] == i {
            r += 1;
        } else {
            out.push(i);
        }
    }
    out.extend_from_slice(&added[a..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use proptest::prelude::*;

    fn window(g: &GridGeometry, (ax, ay, bx, by): (usize, usize, usize, usize)) -> Window {
        let (ax, bx) = (ax % g.width, bx % g.width);
        let (ay, by) = (ay % g.height, by % g.height);
        Window {
            x0: ax.min(bx),
            y0: ay.min(by),
            x1: ax.max(bx),
            y1: ay.max(by),
        }
    }

    #[test]
    fn bounding_and_grow() {
        let g = GridGeometry::new(10, 8, 0.1, Point::default());
        let b = Window::bounding(&g, &[g.width * 3 + 4, g.width * 5 + 2]).unwrap();
        assert_eq!((b.x0, b.y0, b.x1, b.y1), (2, 3, 4, 5));
        let grown = b.grow(3, &g);
        assert_eq!((grown.x0, grown.y0, grown.x1, grown.y1), (0, 0, 7, 7));
        assert!(grown.contains(&b) && !b.contains(&grown));
        assert_eq!(Window::bounding(&g, &[]), None);
    }

    proptest! {
        #[test]
        fn spans_select_and_replace_follow_the_cell_rule(
            w in 1usize..20,
            h in 1usize..20,
            rects in proptest::collection::vec((0usize..20, 0usize..20, 0usize..20, 0usize..20), 1..4),
            list_bits in proptest::collection::vec(any::<bool>(), 400),
            fresh_bits in proptest::collection::vec(any::<bool>(), 400),
            removed_bits in proptest::collection::vec(any::<bool>(), 400),
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let windows: Vec<Window> = rects.iter().map(|&r| window(&g, r)).collect();
            let inside = |i: usize| windows.iter().any(|b| b.holds(i % w, i / w));
            let spans = Spans::of(&windows, w);
            let list: Vec<usize> = (0..g.len()).filter(|&i| list_bits[i]).collect();
            let fresh: Vec<usize> = (0..g.len()).filter(|&i| fresh_bits[i] && inside(i)).collect();
            let selected: Vec<usize> = spans.select(&list).collect();
            let expected: Vec<usize> = list.iter().copied().filter(|&i| inside(i)).collect();
            prop_assert_eq!(selected, expected);
            let mut out = Vec::new();
            spans.replace(&list, &fresh, &mut out);
            let expected: Vec<usize> = (0..g.len())
                .filter(|&i| if inside(i) { fresh_bits[i] } else { list_bits[i] })
                .collect();
            prop_assert_eq!(&out, &expected);
            // Every span lies in one row, and they are sorted and disjoint.
            for pair in spans.ranges().windows(2) {
                prop_assert!(pair[0].1 < pair[1].0);
            }
            for &(lo, hi) in spans.ranges() {
                prop_assert_eq!(lo / w, hi / w);
            }
            let removed: Vec<usize> = list.iter().copied().filter(|&i| removed_bits[i]).collect();
            let added: Vec<usize> = (0..g.len()).filter(|&i| !list_bits[i] && fresh_bits[i]).collect();
            merge_changes(&list, &removed, &added, &mut out);
            let expected: Vec<usize> = (0..g.len())
                .filter(|&i| (list_bits[i] && !removed_bits[i]) || (!list_bits[i] && fresh_bits[i]))
                .collect();
            prop_assert_eq!(out, expected);
        }
    }
}
