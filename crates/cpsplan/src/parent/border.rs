//! The border of section IV-A-1, step 1: the lines between known-Free and Unknown
//! space (paper Fig. 4, cyan).
//!
//! In: the knowledge map. Out: the border cells, and the border without the
//! isolated notches that lead nowhere ([`significant_border`]).

use crate::grid::window::Window;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// Known-Free cells with an Unknown 4-neighbour: the border lines of Fig. 4, in
/// index order.
pub fn border_cells(knowledge: &OccupancyGrid) -> Vec<usize> {
    let mut out = Vec::new();
    if let Some(all) = Window::all(knowledge.geometry()) {
        border_in(knowledge, all, &mut out);
    }
    out
}

/// Appends to `out` the border cells ([`border_cells`]) inside `window`, in index
/// order.
pub(super) fn border_in(knowledge: &OccupancyGrid, window: Window, out: &mut Vec<usize>) {
    let g = knowledge.geometry();
    let (w, h) = (g.width, g.height);
    let k = knowledge.cells();
    let Window { x0, y0, x1, y1 } = window;
    let span = x1 - x0 + 1;
    // Row by row, in straight loops over the window's rows: `near[j]` is whether a
    // 4-neighbour of (x0 + j, y) is Unknown (outside the grid counts as known).
    let unknown = |c: &CellState| u8::from(*c == CellState::Unknown);
    let mut near = vec![0u8; span];
    for y in y0..=y1 {
        let row = &k[y * w..][..w];
        near.fill(0);
        // West neighbours: cells x0 - 1 .. x1 - 1.
        let (skip, from) = if x0 == 0 { (1, 0) } else { (0, x0 - 1) };
        for (n, c) in near[skip..].iter_mut().zip(&row[from..]) {
            *n |= unknown(c);
        }
        // East neighbours: cells x0 + 1 ..= x1 + 1, inside the grid.
        for (n, c) in near.iter_mut().zip(&row[x0 + 1..]) {
            *n |= unknown(c);
        }
        for other in [y.checked_sub(1), Some(y + 1).filter(|&a| a < h)]
            .into_iter()
            .flatten()
        {
            for (n, c) in near.iter_mut().zip(&k[other * w + x0..][..span]) {
                *n |= unknown(c);
            }
        }
        for (n, c) in near.iter_mut().zip(&row[x0..=x1]) {
            *n &= u8::from(*c == CellState::Free);
        }
        for (j, &n) in near.iter().enumerate() {
            if n != 0 {
                out.push(y * w + x0 + j);
            }
        }
    }
}

/// Keeps the border cells that belong to 8-connected groups of at least
/// `min_cells` cells. A lone border cell or two is a notch in a wall seen at a
/// grazing angle, not a way into unknown space: through it `S` counts the whole
/// unknown region behind the wall, while a scan reveals a cell or two.
pub fn significant_border(
    geometry: &GridGeometry,
    border: &[usize],
    min_cells: usize,
) -> Vec<usize> {
    if min_cells <= 1 || border.is_empty() {
        return border.to_vec();
    }
    // 0: not border, 1: border not yet grouped, 2: grouped.
    let mut mark = vec![0u8; geometry.len()];
    for &b in border {
        mark[b] = 1;
    }
    let mut keep = Vec::with_capacity(border.len());
    let mut group = Vec::new();
    for &b in border {
        if mark[b] != 1 {
            continue;
        }
        mark[b] = 2;
        flood_group(geometry, b, &mut group, |j| {
            let take = mark[j] == 1;
            if take {
                mark[j] = 2;
            }
            take
        });
        if is_significant(group.len(), min_cells) {
            keep.extend_from_slice(&group);
        }
    }
    keep.sort_unstable();
    keep
}

/// Whether a group of `cells` border cells is kept by [`significant_border`].
pub(super) fn is_significant(cells: usize, min_cells: usize) -> bool {
    min_cells <= 1 || cells >= min_cells
}

/// The 8-connected group of `start` into `group` (`start` first): every cell
/// reached from it for which `take(cell)` is true. `take` marks what it takes,
/// so that no cell is taken twice; `start` is taken without asking, and the
/// caller marks it first.
pub(super) fn flood_group(
    geometry: &GridGeometry,
    start: usize,
    group: &mut Vec<usize>,
    mut take: impl FnMut(usize) -> bool,
) {
    let (w, h) = (geometry.width, geometry.height);
    group.clear();
    group.push(start);
    let mut next = 0;
    while next < group.len() {
        let i = group[next];
        next += 1;
        let (x, y) = (i % w, i / w);
        for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
            for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                let j = ny * w + nx;
                if take(j) {
                    group.push(j);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;

    #[test]
    fn border_of_a_half_known_strip() {
        let g = GridGeometry::new(40, 5, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        k.fill_rect(0, 0, 20, 5, CellState::Free);
        let b = border_cells(&k);
        assert_eq!(b.len(), 5);
        assert!(b.iter().all(|&i| g.cell(i).x == 19));
    }

    #[test]
    fn occupied_cells_are_never_border() {
        let g = GridGeometry::new(3, 1, 1.0, Point::default());
        let k = OccupancyGrid::from_cells(
            g,
            vec![CellState::Occupied, CellState::Unknown, CellState::Occupied],
        )
        .unwrap();
        assert!(border_cells(&k).is_empty());
    }

    /// The border rule cell by cell, for comparison.
    fn reference_border(knowledge: &OccupancyGrid) -> Vec<usize> {
        let g = knowledge.geometry();
        let (w, h) = (g.width, g.height);
        let k = knowledge.cells();
        let mut out = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if k[i] != CellState::Free {
                    continue;
                }
                let unknown = (x > 0 && k[i - 1] == CellState::Unknown)
                    || (x + 1 < w && k[i + 1] == CellState::Unknown)
                    || (y > 0 && k[i - w] == CellState::Unknown)
                    || (y + 1 < h && k[i + w] == CellState::Unknown);
                if unknown {
                    out.push(i);
                }
            }
        }
        out
    }

    /// The significant border by the rule: border cells whose 8-connected group
    /// (found cell by cell from a seen-set) has at least `min_cells` cells.
    fn reference_significant(g: &GridGeometry, border: &[usize], min_cells: usize) -> Vec<usize> {
        let (w, h) = (g.width as i64, g.height as i64);
        let is_border: std::collections::HashSet<usize> = border.iter().copied().collect();
        let mut seen = std::collections::HashSet::new();
        let mut keep = Vec::new();
        for &b in border {
            if !seen.insert(b) {
                continue;
            }
            let mut group = vec![b];
            let mut stack = vec![b];
            while let Some(i) = stack.pop() {
                let (x, y) = ((i as i64) % w, (i as i64) / w);
                for (dx, dy) in (-1..=1).flat_map(|dx| (-1..=1).map(move |dy| (dx, dy))) {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w || ny >= h {
                        continue;
                    }
                    let j = (ny * w + nx) as usize;
                    if is_border.contains(&j) && seen.insert(j) {
                        group.push(j);
                        stack.push(j);
                    }
                }
            }
            if group.len() >= min_cells {
                keep.extend(group);
            }
        }
        keep.sort_unstable();
        keep
    }

    proptest::proptest! {
        #[test]
        fn significant_border_keeps_the_groups_of_the_rule(
            w in 1usize..25,
            h in 1usize..25,
            bits in proptest::collection::vec(0u8..3, 625),
            min_cells in 0usize..6,
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let states = [CellState::Unknown, CellState::Free, CellState::Occupied];
            let cells = (0..g.len()).map(|i| states[bits[i] as usize]).collect();
            let k = OccupancyGrid::from_cells(g, cells).unwrap();
            let border = border_cells(&k);
            proptest::prop_assert_eq!(
                significant_border(&g, &border, min_cells),
                reference_significant(&g, &border, min_cells)
            );
        }

        #[test]
        fn border_matches_the_cell_by_cell_rule(
            w in 1usize..25,
            h in 1usize..25,
            bits in proptest::collection::vec(0u8..3, 625),
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let states = [CellState::Unknown, CellState::Free, CellState::Occupied];
            let cells = (0..g.len()).map(|i| states[bits[i] as usize]).collect();
            let k = OccupancyGrid::from_cells(g, cells).unwrap();
            proptest::prop_assert_eq!(border_cells(&k), reference_border(&k));
        }
    }
}
