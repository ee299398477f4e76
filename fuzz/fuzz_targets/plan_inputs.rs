//! One planning step for a real team (`cpsplan::mission::plan_step`) on a small
//! occupancy grid built from the input, with robots anywhere (cell centres,
//! cell corners, outside the map, non-finite) and a few configuration knobs.
//! Asserts: no panic; errors are fine.
//!
//! Input layout (missing bytes read as 0):
//! - 0: width − 1 (`% 64`), 1: height − 1 (`% 64`), 2: resolution (`% 3` of
//!   0.05 / 0.1 / 0.2 m), 3: child strategy (`% 5`, `ChildStrategy::ALL`);
//! - 4: scanner.range, 5: children.min_range, 6: children.max_range (0: none),
//!   7: robot.radius (see `knob`);
//! - 8: children (`% 4`) in bits 0–1; bit 2: make every robot's cell Free;
//! - 9..: four positions of 3 bytes (parent, then children): a mode byte and
//!   two coordinate bytes (see `position`);
//! - then the cells, 2 bits each from the low bits up, row-major from the
//!   bottom row: 0 or 1 Free, 2 Occupied, 3 Unknown; cells past the input's
//!   end are Free.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| cpsplan_fuzz::plan_inputs::run(data));
