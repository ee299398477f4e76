//! Seeded k-means clustering of 2-D samples (section IV-A-1, step 3): k-means++
//! initialisation (Arthur & Vassilvitskii 2007) followed by Lloyd iterations.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Samples per parallel piece of the assignment step (below it a piece is not
/// worth a thread).
const ASSIGN_CHUNK: usize = 512;

/// The result of clustering.
#[derive(Debug, Clone, PartialEq)]
pub struct Clustering {
    /// Cluster centroids.
    pub centroids: Vec<[f64; 2]>,
    /// For each sample, the index of its cluster.
    pub assignment: Vec<usize>,
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

/// Clusters `points` into at most `k` clusters (fewer if there are fewer distinct
/// points), running at most `iterations` Lloyd steps. Empty input gives no clusters.
pub fn kmeans(
    points: &[[f64; 2]],
    k: usize,
    iterations: usize,
    rng: &mut ChaCha8Rng,
) -> Clustering {
    if points.is_empty() || k == 0 {
        return Clustering {
            centroids: Vec::new(),
            assignment: vec![0; points.len()],
        };
    }
    // k-means++ seeding.
    let mut centroids = vec![points[rng.random_range(0..points.len())]];
    let mut d2: Vec<f64> = points.iter().map(|&p| dist2(p, centroids[0])).collect();
    while centroids.len() < k {
        let total: f64 = d2.iter().sum();
        if total <= 0.0 {
            break; // every point coincides with a centroid
        }
        let mut pick = rng.random::<f64>() * total;
        let mut chosen = points.len() - 1;
        for (i, &d) in d2.iter().enumerate() {
            if pick < d {
                chosen = i;
                break;
            }
            pick -= d;
        }
        let c = points[chosen];
        centroids.push(c);
        for (d, &p) in d2.iter_mut().zip(points) {
            *d = d.min(dist2(p, c));
        }
    }
    let k = centroids.len();
    let mut assignment = vec![usize::MAX; points.len()];
    let mut sums = vec![[0.0f64; 3]; k];
    for _ in 0..iterations {
        // Each sample's nearest centroid on its own, so in parallel: the same
        // assignment in any order.
        let changed = assignment
            .par_iter_mut()
            .zip(points.par_iter())
            .with_min_len(ASSIGN_CHUNK)
            .map(|(a, &p)| {
                let best = nearest(&centroids, p);
                std::mem::replace(a, best) != best
            })
            .reduce(|| false, |x, y| x | y);
        if !changed {
            break;
        }
        sums.iter_mut().for_each(|s| *s = [0.0; 3]);
        for (&a, &p) in assignment.iter().zip(points) {
            sums[a][0] += p[0];
            sums[a][1] += p[1];
            sums[a][2] += 1.0;
        }
        for (c, s) in centroids.iter_mut().zip(&sums) {
            if s[2] > 0.0 {
                *c = [s[0] / s[2], s[1] / s[2]];
            }
        }
    }
    // Drop clusters that ended empty and renumber.
    let mut count = vec![0usize; k];
    for &a in &assignment {
        count[a] += 1;
    }
    let mut remap = vec![usize::MAX; k];
    let mut kept = Vec::new();
    for (i, &n) in count.iter().enumerate() {
        if n > 0 {
            remap[i] = kept.len();
            kept.push(centroids[i]);
        }
    }
    for a in &mut assignment {
        *a = remap[*a];
    }
    Clustering {
        centroids: kept,
        assignment,
    }
}

fn nearest(centroids: &[[f64; 2]], p: [f64; 2]) -> usize {
    let mut best = 0;
    let mut bd = f64::INFINITY;
    for (i, &c) in centroids.iter().enumerate() {
        let d = dist2(p, c);
        if d < bd {
            bd = d;
            best = i;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn separates_two_blobs_and_is_deterministic() {
        let mut pts = Vec::new();
        for i in 0..50 {
            let t = i as f64 * 0.1;
            pts.push([t.sin(), t.cos()]);
            pts.push([100.0 + t.cos(), 50.0 + t.sin()]);
        }
        let a = kmeans(&pts, 2, 50, &mut ChaCha8Rng::seed_from_u64(3));
        let b = kmeans(&pts, 2, 50, &mut ChaCha8Rng::seed_from_u64(3));
        assert_eq!(a, b);
        assert_eq!(a.centroids.len(), 2);
        for (n, &c) in a.assignment.iter().enumerate() {
            assert_eq!(c, a.assignment[n % 2], "blob members must share a cluster");
        }
        assert_ne!(a.assignment[0], a.assignment[1]);
    }

    #[test]
    fn never_more_clusters_than_distinct_points() {
        let pts = vec![[1.0, 1.0]; 10];
        let c = kmeans(&pts, 5, 10, &mut ChaCha8Rng::seed_from_u64(0));
        assert_eq!(c.centroids.len(), 1);
        assert!(kmeans(&[], 3, 10, &mut ChaCha8Rng::seed_from_u64(0))
            .centroids
            .is_empty());
    }
}
