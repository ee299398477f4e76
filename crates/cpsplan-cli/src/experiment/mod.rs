//! Experiments: many episodes from one TOML file, run in parallel, one record
//! per episode as it finishes, so that an interrupted run continues where it
//! stopped (`--resume`) and a large one splits over machines (`--shard K/N`,
//! joined again by `cpsplan experiment merge`).

pub mod medians;
pub mod oracle;
pub mod plan_file;
pub mod record;
pub mod spec;
pub mod store;
pub mod summary;
pub mod text;

pub use plan_file::{PlanFile, Shard};
pub use record::{EpisodeRecord, Outcome, ScanRecord};
pub use spec::{parse_plan, read_plan, EpisodeSpec, Plan, SpecError};
pub use store::ExperimentDir;
