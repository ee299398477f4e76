//! Steps 2 and 3 of section IV-A-1: sample points scattered uniformly over the
//! band, and the number of k-means clusters adapted to the band's size ("the
//! number of clusters are determined adaptively according to the size of border
//! area").
//!
//! In: the band's cells and the parent planner's parameters. Out: the samples (in
//! continuous cell units: cell `(x, y)` spans `[x, x + 1) × [y, y + 1)`) and `k`.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::config::ParentConfig;
use crate::grid::GridGeometry;

/// Area of the band in square metres.
pub fn band_area(geometry: &GridGeometry, band_cells: usize) -> f64 {
    band_cells as f64 * geometry.resolution * geometry.resolution
}

/// Samples uniformly scattered over the band: `samples_per_m2` per square metre of
/// band, between 1 and `max_samples`. Each sample takes a band cell uniformly at
/// random and a uniform point inside it. `band_cells` must not be empty.
pub fn scatter(
    geometry: &GridGeometry,
    band_cells: &[usize],
    config: &ParentConfig,
    rng: &mut ChaCha8Rng,
) -> Vec<[f64; 2]> {
    let area = band_area(geometry, band_cells.len());
    let n = ((area * config.samples_per_m2).round() as usize).clamp(1, config.max_samples);
    (0..n)
        .map(|_| {
            let c = geometry.cell(band_cells[rng.random_range(0..band_cells.len())]);
            [
                c.x as f64 + rng.random::<f64>(),
                c.y as f64 + rng.random::<f64>(),
            ]
        })
        .collect()
}

/// `k` of k-means for a band of `band_area` m²: one cluster per `cluster_area`,
/// between 1 and `max_clusters`.
pub fn cluster_count(band_area: f64, config: &ParentConfig) -> usize {
    ((band_area / config.cluster_area).ceil() as usize).clamp(1, config.max_clusters)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use rand::SeedableRng;

    #[test]
    fn samples_lie_in_band_cells_and_scale_with_area() {
        let g = GridGeometry::new(50, 50, 0.1, Point::default());
        let band: Vec<usize> = (0..g.len()).filter(|&i| i % 50 < 10).collect();
        let config = ParentConfig::default();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let samples = scatter(&g, &band, &config, &mut rng);
        // 500 cells of 0.01 m² at 8 per m².
        assert_eq!(samples.len(), 40);
        for s in &samples {
            assert!(
                s[0] >= 0.0 && s[0] < 10.0 && s[1] >= 0.0 && s[1] < 50.0,
                "{s:?}"
            );
        }
        assert_eq!(cluster_count(band_area(&g, band.len()), &config), 1);
        assert_eq!(cluster_count(48.5, &config), 3);
        assert_eq!(cluster_count(1e9, &config), config.max_clusters);
    }
}
