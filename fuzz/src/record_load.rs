//! The `record_load` fuzz target's body.
use std::path::Path;
use std::sync::OnceLock;

use cpsplan_cli::commands::report::render;
use cpsplan_cli::experiment::record::episodes_csv;
use cpsplan_cli::experiment::store::parse_record;
use cpsplan_cli::experiment::{parse_plan, Plan, Shard};

/// The experiment the records claim to belong to: two built-in maps, two
/// parameter sets (the parent alone, a team), two seeds, with the known-map
/// bound; `fuzz/seeds/record_load/` holds its real records.
pub const EXPERIMENT: &str = r#"
name = "fuzz"
description = "records for the record_load fuzz target"
maps = ["builtin:site", "builtin:tunnel"]
seeds = { from = 0, count = 2 }
bound = true

[base]
mission.max_scans = 3

[[parameters]]
name = "alone"
children.count = 0

[[parameters]]
name = "team"
children.count = 2
"#;

fn plan() -> &'static Plan {
    static PLAN: OnceLock<Plan> = OnceLock::new();
    PLAN.get_or_init(|| parse_plan(EXPERIMENT, Path::new("fuzz.toml")).expect("a valid plan"))
}

/// A record file as `report`, `merge` and `--resume` read it. Byte 0 picks
/// the episode whose record it claims to be (one past the plan's last
/// included), byte 1 how many times the report counts it (1–3); the rest is
/// the file. Asserts: no panic; an accepted record is plausible and names that
/// episode exactly; the report of accepted records renders whole.
pub fn run(data: &[u8]) {
    let [pick, copies, rest @ ..] = data else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let plan = plan();
    let index = *pick as usize % (plan.episodes.len() + 1);
    let Ok(record) = parse_record(text, plan, index) else {
        return;
    };
    assert!(index < plan.episodes.len(), "a record beyond the plan");
    assert_eq!(record.episode, plan.episodes[index]);
    assert!(record.plausible().is_ok());
    let records = vec![record; 1 + *copies as usize % 3];
    episodes_csv(&records).expect("the CSV of accepted records");
    let rendered =
        render(plan, Some(Shard::WHOLE), &records).expect("the report of accepted records");
    assert!(!rendered.md.is_empty() && !rendered.csv.is_empty());
}
