//! 4-connected regions of grid cells: flood fill from a seed and labelling of
//! every region.

/// The cells 4-connected to `seed` through cells with `inside(index)`, as a mask
/// over a `width × height` grid. `seed` is included if it is inside.
pub fn flood4(
    width: usize,
    height: usize,
    seed: usize,
    inside: impl Fn(usize) -> bool,
) -> Vec<bool> {
    let mut mask = vec![false; width * height];
    if inside(seed) {
        fill4(width, height, seed, |j| {
            if inside(j) && !mask[j] {
                mask[j] = true;
                true
            } else {
                false
            }
        });
    }
    mask
}

/// Labels every 4-connected region of cells with `inside(index)`: per cell its
/// region number (`u32::MAX` outside), and per region its size in cells.
pub fn label4(
    width: usize,
    height: usize,
    inside: impl Fn(usize) -> bool,
) -> (Vec<u32>, Vec<usize>) {
    let mut label = vec![u32::MAX; width * height];
    let mut sizes = Vec::new();
    for s in 0..width * height {
        if label[s] != u32::MAX || !inside(s) {
            continue;
        }
        let id = sizes.len() as u32;
        let mut size = 0;
        fill4(width, height, s, |j| {
            if label[j] == u32::MAX && inside(j) {
                label[j] = id;
                size += 1;
                true
            } else {
                false
            }
        });
        sizes.push(size);
    }
    (label, sizes)
}

/// Scanline fill from `seed`: `claim(index)` marks a cell and says whether it
/// was newly claimed (and so belongs to the region); it is called for the seed
/// first. Runs of a row are claimed at once and the rows beside a run scanned
/// once over its length, so most cells are claimed from a run's scan rather
/// than pushed and popped one by one; every cell 4-connected to the seed
/// through claimed cells is claimed, the same set as a cell-by-cell fill.
fn fill4(width: usize, height: usize, seed: usize, mut claim: impl FnMut(usize) -> bool) {
    if !claim(seed) {
        return;
    }
    // Claimed runs whose ends are still to be extended and whose neighbouring
    // rows are still to be scanned: (row, first column, last column).
    let mut runs = vec![(seed / width, seed % width, seed % width)];
    while let Some((y, x0, x1)) = runs.pop() {
        let row = y * width;
        let mut left = x0;
        while left > 0 && claim(row + left - 1) {
            left -= 1;
        }
        let mut right = x1;
        while right + 1 < width && claim(row + right + 1) {
            right += 1;
        }
        let above = (y > 0).then(|| y - 1);
        let below = (y + 1 < height).then_some(y + 1);
        for ny in [above, below].into_iter().flatten() {
            let next = ny * width;
            let mut x = left;
            while x <= right {
                if claim(next + x) {
                    let start = x;
                    while x < right && claim(next + x + 1) {
                        x += 1;
                    }
                    runs.push((ny, start, x));
                }
                x += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_regions_split_by_a_wall() {
        // 5 × 3, column 2 is wall.
        let inside = |i: usize| i % 5 != 2;
        let (label, sizes) = label4(5, 3, inside);
        assert_eq!(sizes, vec![6, 6]);
        assert_eq!(label[0], 0);
        assert_eq!(label[4], 1);
        assert_eq!(label[2], u32::MAX);
        let m = flood4(5, 3, 0, inside);
        assert_eq!(m.iter().filter(|&&b| b).count(), 6);
        assert!(!m[3]);
        assert!(flood4(5, 3, 2, inside).iter().all(|&b| !b));
    }

    /// The 4-connected region of a seed, one cell at a time.
    fn region_by_cells(w: usize, h: usize, seed: usize, inside: &[bool]) -> Vec<bool> {
        let mut mask = vec![false; w * h];
        let mut stack = vec![seed];
        while let Some(i) = stack.pop() {
            if !inside[i] || mask[i] {
                continue;
            }
            mask[i] = true;
            let (x, y) = (i % w, i / w);
            if x > 0 {
                stack.push(i - 1);
            }
            if x + 1 < w {
                stack.push(i + 1);
            }
            if y > 0 {
                stack.push(i - w);
            }
            if y + 1 < h {
                stack.push(i + w);
            }
        }
        mask
    }

    proptest::proptest! {
        /// Random masks (dense and sparse, with winding runs): the scanline fill
        /// claims exactly the seed's 4-connected region, and the labels split
        /// the cells into those regions.
        #[test]
        fn the_fill_claims_the_seeds_region(
            w in 1usize..24,
            h in 1usize..24,
            density in 0.3f64..0.9,
            bits in proptest::collection::vec(0.0f64..1.0, 24 * 24),
            seed in 0usize..576,
        ) {
            let inside: Vec<bool> = bits[..w * h].iter().map(|&b| b < density).collect();
            let seed = seed % (w * h);
            let expected = if inside[seed] {
                region_by_cells(w, h, seed, &inside)
            } else {
                vec![false; w * h]
            };
            proptest::prop_assert_eq!(flood4(w, h, seed, |i| inside[i]), expected);
            let (label, sizes) = label4(w, h, |i| inside[i]);
            for (i, &l) in label.iter().enumerate() {
                if !inside[i] {
                    proptest::prop_assert_eq!(l, u32::MAX);
                    continue;
                }
                let region = region_by_cells(w, h, i, &inside);
                let same: Vec<bool> = label.iter().map(|&m| m == l).collect();
                proptest::prop_assert_eq!(&same, &region);
                proptest::prop_assert_eq!(sizes[l as usize], region.iter().filter(|&&b| b).count());
            }
        }
    }

    #[test]
    fn diagonal_contact_does_not_connect() {
        // 2 × 2 with only the diagonal cells inside.
        let inside = |i: usize| i == 0 || i == 3;
        let (_, sizes) = label4(2, 2, inside);
        assert_eq!(sizes, vec![1, 1]);
    }
}
