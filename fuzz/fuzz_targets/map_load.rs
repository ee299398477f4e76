//! ROS map loading: YAML metadata, then a PGM/PNM/PNG image, then resampling
//! to the planning resolution. Asserts: no panic, and nothing beyond the small
//! limits below is allocated (libFuzzer's -rss_limit_mb / -timeout catch that).
//!
//! Input layout:
//! - byte 0: planning resolution choice (0.1, 0.05, 0.2, 0.5 m; `% 4`);
//! - bytes 1..3: YAML length, u16 little-endian (clamped to what remains);
//! - then the YAML text (lossy UTF-8), then the image bytes (the rest).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| cpsplan_fuzz::map_load::run(data));
