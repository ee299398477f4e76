//! The `map_load` fuzz target's body.
use std::path::Path;

use cpsplan::Config;
use cpsplan_cli::formats::rosmap::{MapMetadata, ReadLimits};

const RESOLUTIONS: [f64; 4] = [0.1, 0.05, 0.2, 0.5];

const LIMITS: ReadLimits = ReadLimits {
    max_pixels: 1 << 16,
    max_image_bytes: 1 << 20,
    max_text_bytes: 1 << 16,
};

/// ROS map loading: YAML metadata, then a PGM/PNM/PNG image, then resampling
/// to the planning resolution. Asserts: no panic, and nothing beyond the small
/// limits below is allocated (libFuzzer's -rss_limit_mb / -timeout catch that).
///
/// Input layout:
/// - byte 0: planning resolution choice (0.1, 0.05, 0.2, 0.5 m; `% 4`);
/// - bytes 1..3: YAML length, u16 little-endian (clamped to what remains);
/// - then the YAML text (lossy UTF-8), then the image bytes (the rest).
pub fn run(data: &[u8]) {
    if data.len() < 3 {
        return;
    }
    let resolution = RESOLUTIONS[usize::from(data[0]) % RESOLUTIONS.len()];
    let yaml_len = usize::from(u16::from_le_bytes([data[1], data[2]]));
    let rest = &data[3..];
    let (yaml, image) = rest.split_at(yaml_len.min(rest.len()));
    let yaml = String::from_utf8_lossy(yaml);

    let Ok(meta) = MapMetadata::parse(&yaml, Path::new("fuzz/map.yaml")) else {
        return;
    };
    let Ok(grid) = meta.grid_from_image(image, &LIMITS) else {
        return;
    };
    let g = grid.geometry();
    assert!(g.width > 0 && g.height > 0);
    assert!((g.width * g.height) as u64 <= LIMITS.max_pixels);

    let mut config = Config {
        resolution,
        ..Config::default()
    };
    config.limits.max_grid_cells = 1 << 18;
    if let Ok(planning) = cpsplan::world::resample_for(&grid, &config) {
        let p = planning.geometry();
        assert!((p.width * p.height) as u64 <= config.limits.max_grid_cells as u64);
        assert_eq!(p.resolution, resolution);
    }
}
