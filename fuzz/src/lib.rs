//! The bodies of the fuzz targets, one module each, shared by the libFuzzer
//! targets in `fuzz_targets/` and by the main workspace's regression test
//! (`crates/cpsplan-cli/tests/fuzz_regressions.rs`), which replays every input
//! in `regressions/` and `seeds/` through them. Each `run` panics on a defect.

pub mod cloud_grid;
pub mod config_parse;
pub mod map_load;
pub mod plan_inputs;
pub mod record_load;
