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

/// Depth-first fill from `seed`: `claim(index)` marks a cell and says whether it
/// was newly claimed (and so is to be expanded); it is called for the seed first.
fn fill4(width: usize, height: usize, seed: usize, mut claim: impl FnMut(usize) -> bool) {
    if !claim(seed) {
        return;
    }
    let mut stack = vec![seed];
    while let Some(i) = stack.pop() {
        let (x, y) = (i % width, i / width);
        let neighbours = [
            (x > 0).then(|| i - 1),
            (x + 1 < width).then(|| i + 1),
            (y > 0).then(|| i - width),
            (y + 1 < height).then(|| i + width),
        ];
        for j in neighbours.into_iter().flatten() {
            if claim(j) {
                stack.push(j);
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

    #[test]
    fn diagonal_contact_does_not_connect() {
        // 2 × 2 with only the diagonal cells inside.
        let inside = |i: usize| i == 0 || i == 3;
        let (_, sizes) = label4(2, 2, inside);
        assert_eq!(sizes, vec![1, 1]);
    }
}
