//! TOML configuration files: parse, validate, check a grid against the limits
//! and, for a valid configuration made small (at most 2 scans, 2 children, 10
//! Monte Carlo runs, 0.1 m cells), run a whole episode on a small fixed map.
//! Asserts: no panic; an episode under a validated configuration either runs or
//! returns an error; runs stay within the scan cap.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| cpsplan_fuzz::config_parse::run(data));
