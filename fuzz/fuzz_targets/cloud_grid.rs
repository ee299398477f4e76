//! Point cloud bytes to an occupancy grid: a LAS, LAZ, E57, PLY or PCD file
//! parsed from memory, then projected. Asserts: no panic, nothing beyond the
//! small point and cell limits, counts that add up.
//!
//! Input layout: byte 0 the format, byte 1 the resolution and options, then the
//! file (see `cpsplan_fuzz::cloud_grid::run`).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| cpsplan_fuzz::cloud_grid::run(data));
