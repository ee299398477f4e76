//! `plan.json`: every episode of an experiment and the shard a directory runs,
//! kept compact. An experiment's episodes differ mostly by seed, so the file
//! lists each distinct configuration once (`configs`, their seed left 0) and
//! each episode names its configuration by number: a million episodes take
//! about 0.3 GB instead of the 2.6 GB of a whole configuration each. Files of
//! the first format (a whole configuration in every episode) are still read.

use std::fmt;
use std::str::FromStr;

use cpsplan::config::{ChildStrategy, InstrumentModel, Planner};
use cpsplan::{Config, Point};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::spec::{EpisodeSpec, Plan, PLAN_FORMAT};

/// The first format: each episode with its whole configuration.
pub const PLAN_FORMAT_1: &str = "cpsplan-experiment-plan/1";
/// The formats read: the first and the current one.
pub const PLAN_FORMATS_READ: [&str; 2] = [PLAN_FORMAT_1, PLAN_FORMAT];

/// The `k`-th of `n` slices of an experiment (`1 ≤ k ≤ n`): the episodes whose
/// index leaves the remainder `k − 1` when divided by `n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which slice, from 1.
    pub k: usize,
    /// How many slices.
    pub n: usize,
}

impl Shard {
    /// The whole experiment.
    pub const WHOLE: Shard = Shard { k: 1, n: 1 };

    /// Whether the episode numbered `index` is in this slice.
    pub fn holds(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl FromStr for Shard {
    type Err = String;

    /// Parses `K/N` with `1 ≤ K ≤ N`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || format!("`{s}` is not K/N with 1 \u{2264} K \u{2264} N (e.g. 3/8)");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || k > n {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }
}

/// `plan.json`: the plan and the shard of the directory.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanFile {
    /// Every episode of the experiment.
    pub plan: Plan,
    /// The slice this directory runs; `None` after a merge (all of them).
    pub shard: Option<Shard>,
}

/// An episode as the file keeps it: its configuration by number.
#[derive(Serialize)]
struct EntryOut<'a> {
    index: usize,
    label: &'a str,
    map: &'a str,
    start: Option<Point>,
    parameters: &'a str,
    planner: Planner,
    child_strategy: ChildStrategy,
    instrument: InstrumentModel,
    seed: u64,
    config: usize,
}

/// The file as written.
#[derive(Serialize)]
struct FileOut<'a> {
    format: &'a str,
    name: &'a str,
    description: &'a str,
    bound: bool,
    configs: Vec<Config>,
    episodes: Vec<EntryOut<'a>>,
    shard: Option<Shard>,
}

/// `config` with seed 0: what episodes that differ only by seed share.
fn seedless(config: &Config) -> Config {
    Config {
        seed: 0,
        ..config.clone()
    }
}

impl Serialize for PlanFile {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let plan = &self.plan;
        let mut configs: Vec<Config> = Vec::new();
        let mut last = 0;
        let mut episodes = Vec::with_capacity(plan.episodes.len());
        for e in &plan.episodes {
            let own = seedless(&e.config);
            // Neighbours mostly share a configuration (seeds vary fastest).
            let config = match configs.get(last) {
                Some(c) if *c == own => last,
                _ => match configs.iter().position(|c| *c == own) {
                    Some(k) => k,
                    None => {
                        configs.push(own);
                        configs.len() - 1
                    }
                },
            };
            last = config;
            episodes.push(EntryOut {
                index: e.index,
                label: &e.label,
                map: &e.map,
                start: e.start,
                parameters: &e.parameters,
                planner: e.planner,
                child_strategy: e.child_strategy,
                instrument: e.instrument,
                seed: e.seed,
                config,
            });
        }
        FileOut {
            format: PLAN_FORMAT,
            name: &plan.name,
            description: &plan.description,
            bound: plan.bound,
            configs,
            episodes,
            shard: self.shard,
        }
        .serialize(serializer)
    }
}

/// An episode's configuration as read: by number, or whole (first format).
#[derive(Deserialize)]
#[serde(untagged)]
enum ConfigIn {
    Shared(usize),
    Own(Box<Config>),
}

/// An episode as read.
#[derive(Deserialize)]
struct EntryIn {
    index: usize,
    label: String,
    map: String,
    start: Option<Point>,
    parameters: String,
    planner: Planner,
    child_strategy: ChildStrategy,
    instrument: InstrumentModel,
    seed: u64,
    config: ConfigIn,
}

/// The file as read.
#[derive(Deserialize)]
struct FileIn {
    format: String,
    name: String,
    description: String,
    #[serde(default)]
    bound: bool,
    #[serde(default)]
    configs: Vec<Config>,
    episodes: Vec<EntryIn>,
    shard: Option<Shard>,
}

impl<'de> Deserialize<'de> for PlanFile {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let file = FileIn::deserialize(deserializer)?;
        if !PLAN_FORMATS_READ.contains(&file.format.as_str()) {
            return Err(D::Error::custom(format!(
                "format `{}`, expected `{PLAN_FORMAT}`",
                file.format
            )));
        }
        let configs = file.configs;
        let mut episodes = Vec::with_capacity(file.episodes.len());
        for e in file.episodes {
            let config = match e.config {
                ConfigIn::Own(c) => *c,
                ConfigIn::Shared(k) => match configs.get(k) {
                    Some(c) => Config {
                        seed: e.seed,
                        ..c.clone()
                    },
                    None => {
                        return Err(D::Error::custom(format!(
                            "episode {} names configuration {k}, but the file has {}",
                            e.index,
                            configs.len()
                        )))
                    }
                },
            };
            episodes.push(EpisodeSpec {
                index: e.index,
                label: e.label,
                map: e.map,
                start: e.start,
                parameters: e.parameters,
                planner: e.planner,
                child_strategy: e.child_strategy,
                instrument: e.instrument,
                seed: e.seed,
                config,
            });
        }
        Ok(PlanFile {
            plan: Plan {
                format: PLAN_FORMAT.into(),
                name: file.name,
                description: file.description,
                bound: file.bound,
                episodes,
            },
            shard: file.shard,
        })
    }
}
