//! Radius outlier removal: a point with fewer than `k` other points within a
//! radius is dropped (stray returns, dust, the mixed pixels at depth edges). The
//! points are bucketed in cubes of the radius; a point's neighbours lie in the
//! 27 cubes around its own.

use rayon::prelude::*;

/// Which points have at least `k` others within `radius` (true: keep).
pub fn inliers(points: &[[f64; 3]], radius: f64, k: usize) -> Vec<bool> {
    let key = |p: &[f64; 3]| -> [i64; 3] {
        // Casts saturate; neighbouring cubes are found with saturating steps.
        [
            (p[0] / radius).floor() as i64,
            (p[1] / radius).floor() as i64,
            (p[2] / radius).floor() as i64,
        ]
    };
    let mut order: Vec<([i64; 3], usize)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (key(p), i))
        .collect();
    order.par_sort_unstable();
    let keys: Vec<[i64; 3]> = order.iter().map(|o| o.0).collect();
    let r2 = radius * radius;
    let mut keep = vec![false; points.len()];
    let found: Vec<(usize, bool)> = order
        .par_iter()
        .map(|&(c, i)| {
            let p = &points[i];
            let mut n = 0usize;
            'cubes: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let q = [
                            c[0].saturating_add(dx),
                            c[1].saturating_add(dy),
                            c[2].saturating_add(dz),
                        ];
                        let lo = keys.partition_point(|k| *k < q);
                        let hi = keys.partition_point(|k| *k <= q);
                        for &(_, j) in &order[lo..hi] {
                            if j == i {
                                continue;
                            }
                            let o = &points[j];
                            let d2 = (o[0] - p[0]).powi(2)
                                + (o[1] - p[1]).powi(2)
                                + (o[2] - p[2]).powi(2);
                            if d2 <= r2 {
                                n += 1;
                                if n >= k {
                                    break 'cubes;
                                }
                            }
                        }
                    }
                }
            }
            (i, n >= k)
        })
        .collect();
    for (i, k) in found {
        keep[i] = k;
    }
    keep
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isolated_points_go_and_clusters_stay() {
        let mut pts = vec![[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [0.0, 0.05, 0.0]];
        pts.push([5.0, 5.0, 5.0]); // alone
        pts.push([9.0, 9.0, 9.0]);
        pts.push([9.0, 9.0, 9.08]); // a pair: one neighbour each
        let keep = inliers(&pts, 0.1, 2);
        assert_eq!(keep, vec![true, true, true, false, false, false]);
        let keep = inliers(&pts, 0.1, 1);
        assert_eq!(keep, vec![true, true, true, false, true, true]);
    }

    #[test]
    fn neighbours_across_cube_faces_count() {
        // Straddling the cube boundary at x = 0 with negative coordinates.
        let pts = [[-0.01, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, -0.01, -0.01]];
        assert_eq!(inliers(&pts, 0.1, 2), vec![true; 3]);
    }
}
