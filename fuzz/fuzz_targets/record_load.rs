//! Experiment record files as `report`, `merge` and `--resume` read them:
//! parsed, checked against the episode they claim and for sense, then
//! reported. Asserts: no panic; accepted records are plausible, name their
//! episode and render.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| cpsplan_fuzz::record_load::run(data));
