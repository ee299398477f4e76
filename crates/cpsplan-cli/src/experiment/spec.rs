//! Experiment files: a set of episodes described as the cross product of maps ×
//! starts × parameter sets × planners × child strategies × instruments × seeds,
//! expanded into a [`Plan`] of numbered episodes with their whole configuration.
//!
//! ```toml
//! name = "alpha-beta"
//! maps = ["builtin:office", "builtin:site", "../maps/lab.yaml"]
//! seeds = { from = 0, count = 5 }
//! planners = ["paper"]
//!
//! [base]                  # any keys of a --config file, for every episode
//! children.count = 0
//!
//! [[parameters]]
//! name = "alpha0"
//! parent.alpha = 0.0
//!
//! [[parameters]]
//! name = "beta0"
//! parent.beta = 0.0
//! ```
//!
//! `bound = true` adds to every record the known-map bound of its map and start
//! (`cpsplan bound`), computed once per distinct map, seed of a built-in map,
//! start and scanner.

use std::path::{Path, PathBuf};

use cpsplan::config::{ChildStrategy, InstrumentModel, Planner};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{Config, Point};
use serde::{Deserialize, Serialize};

use crate::formats::config::one_line;
use crate::formats::rosmap::{read_text, FormatError};

/// The most episodes one experiment file may describe.
pub const MAX_EPISODES: usize = 1_000_000;

/// The format name of `plan.json`.
pub const PLAN_FORMAT: &str = "cpsplan-experiment-plan/2";

/// Why an experiment file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file could not be read.
    #[error(transparent)]
    Read(#[from] FormatError),
    /// The TOML is malformed, or a key is unknown or of the wrong type.
    #[error("experiment file {}: {message}", path.display())]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message, on one line.
        message: String,
    },
    /// A value is out of its range, or the episodes' configuration is invalid.
    #[error("experiment file {}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// The seeds of an experiment: a list, or `count` seeds from `from`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
enum Seeds {
    List(Vec<u64>),
    Range { from: u64, count: u64 },
}

impl Default for Seeds {
    fn default() -> Self {
        Seeds::List(vec![0])
    }
}

/// Where an episode starts: the map's default, or a world point `[x, y]`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged)]
enum StartEntry {
    Named(DefaultStart),
    At([f64; 2]),
}

/// The word `"default"`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(rename_all = "lowercase")]
enum DefaultStart {
    Default,
}

/// A map: `builtin:NAME` or a file path (relative to the experiment file), with
/// its own starts or the file's `starts`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
enum MapEntry {
    Plain(String),
    WithStarts {
        map: String,
        starts: Vec<StartEntry>,
    },
}

/// The experiment file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperimentFile {
    name: String,
    #[serde(default)]
    description: String,
    maps: Vec<MapEntry>,
    #[serde(default)]
    starts: Vec<StartEntry>,
    #[serde(default)]
    seeds: Seeds,
    #[serde(default)]
    planners: Vec<Planner>,
    #[serde(default)]
    child_strategies: Vec<ChildStrategy>,
    #[serde(default)]
    instruments: Vec<InstrumentModel>,
    #[serde(default)]
    base: toml::Table,
    #[serde(default)]
    parameters: Vec<toml::Table>,
    #[serde(default)]
    bound: bool,
}

/// One episode of an experiment: where it runs and its whole configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeSpec {
    /// Position in the experiment's cross product, from 0.
    pub index: usize,
    /// A short readable name: the map and the values of every axis with more
    /// than one value.
    pub label: String,
    /// `builtin:NAME` or the map file's path as the experiment file gives it.
    pub map: String,
    /// The start, world frame; `None`: the map's default start.
    pub start: Option<Point>,
    /// The name of the parameter set.
    pub parameters: String,
    /// The parent's planner (also in `config`).
    pub planner: Planner,
    /// The children's strategy (also in `config`).
    pub child_strategy: ChildStrategy,
    /// The instrument of the CPS links (also in `config`).
    pub instrument: InstrumentModel,
    /// The seed (also in `config`).
    pub seed: u64,
    /// Every parameter of the episode.
    pub config: Config,
}

impl EpisodeSpec {
    /// The built-in map, if `map` names one.
    pub fn builtin(&self) -> Option<Result<BuiltinMap, String>> {
        self.map
            .strip_prefix("builtin:")
            .map(|name| name.parse::<BuiltinMap>().map_err(|e| e.to_string()))
    }

    /// The map file, resolved against the directory of the experiment file.
    pub fn map_path(&self, experiment_dir: &Path) -> Option<PathBuf> {
        self.builtin()
            .is_none()
            .then(|| experiment_dir.join(&self.map))
    }
}

/// Every episode of an experiment, in a fixed order: `plan.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// [`PLAN_FORMAT`].
    pub format: String,
    /// The experiment's name.
    pub name: String,
    /// What it is for.
    pub description: String,
    /// Whether each record carries the known-map bound of its map and start
    /// (`cpsplan bound`), to measure the planners against.
    #[serde(default)]
    pub bound: bool,
    /// The episodes, `episodes[i].index == i`.
    pub episodes: Vec<EpisodeSpec>,
}

/// Reads an experiment file of at most `max_bytes` bytes and expands it.
pub fn read_plan(path: &Path, max_bytes: u64) -> Result<Plan, SpecError> {
    let text = read_text(path, max_bytes)?;
    parse_plan(&text, path)
}

/// Parses experiment text and expands it; `path` names it in messages.
pub fn parse_plan(text: &str, path: &Path) -> Result<Plan, SpecError> {
    let file: ExperimentFile = toml::from_str(text).map_err(|e| SpecError::Toml {
        path: path.to_path_buf(),
        message: one_line(&e.to_string()),
    })?;
    expand(file, path)
}

/// A value that `values` holds twice, if any (sorted, so that a million
/// seeds take no longer than their sorting).
fn twice<K: Ord>(mut values: Vec<K>) -> Option<K> {
    values.sort_unstable();
    let at = values.windows(2).position(|w| w[0] == w[1])?;
    values.into_iter().nth(at)
}

/// The values of one axis: the given ones, or the configuration's own (`None`).
fn axis<T: Copy>(values: &[T]) -> Vec<Option<T>> {
    if values.is_empty() {
        vec![None]
    } else {
        values.iter().copied().map(Some).collect()
    }
}

/// `base` with `over` laid on top, key by key (tables merged, other values replaced).
fn merged(base: &toml::Table, over: &toml::Table) -> toml::Table {
    let mut out = base.clone();
    for (k, v) in over {
        match (out.get_mut(k), v) {
            (Some(toml::Value::Table(a)), toml::Value::Table(b)) => {
                *a = merged(a, b);
            }
            _ => {
                out.insert(k.clone(), v.clone());
            }
        }
    }
    out
}

fn expand(file: ExperimentFile, path: &Path) -> Result<Plan, SpecError> {
    let invalid = |message: String| SpecError::Invalid {
        path: path.to_path_buf(),
        message,
    };
    if file.name.trim().is_empty() {
        return Err(invalid("`name` is empty".into()));
    }
    if file.maps.is_empty() {
        return Err(invalid("`maps` lists no map".into()));
    }
    let seeds: Vec<u64> = match file.seeds {
        Seeds::List(list) => list,
        Seeds::Range { from, count } => {
            if count == 0 || count > MAX_EPISODES as u64 || from.checked_add(count).is_none() {
                return Err(invalid(format!(
                    "`seeds`: count must be 1 to {MAX_EPISODES}, and from + count at most {}",
                    u64::MAX
                )));
            }
            (from..from + count).collect()
        }
    };
    if seeds.is_empty() {
        return Err(invalid("`seeds` lists no seed".into()));
    }
    if let Some(seed) = twice(seeds.clone()) {
        return Err(invalid(format!(
            "`seeds` lists seed {seed} twice (it would count twice)"
        )));
    }
    // Parameter sets: named tables of configuration keys.
    let mut sets: Vec<(String, Config)> = Vec::new();
    let tables = if file.parameters.is_empty() {
        vec![toml::Table::new()]
    } else {
        file.parameters
    };
    for (i, table) in tables.iter().enumerate() {
        let mut keys = table.clone();
        let name = match keys.remove("name") {
            Some(toml::Value::String(s)) if !s.trim().is_empty() => s,
            Some(_) => {
                return Err(invalid(format!(
                    "parameter set {}: `name` must be a non-empty string",
                    i + 1
                )))
            }
            None if tables.len() == 1 => "default".to_string(),
            None => {
                return Err(invalid(format!(
                    "parameter set {} has no `name` (needed when there are several)",
                    i + 1
                )))
            }
        };
        if sets.iter().any(|(n, _)| *n == name) {
            return Err(invalid(format!("two parameter sets are named `{name}`")));
        }
        let table = merged(&file.base, &keys);
        let mut config: Config = table.clone().try_into().map_err(|e: toml::de::Error| {
            invalid(format!(
                "parameter set `{name}` (with [base]): {}",
                one_line(e.message())
            ))
        })?;
        if let Some(p) = config.preset {
            let mut set = std::collections::BTreeSet::new();
            crate::formats::config::collect_keys(&table, "", &mut set);
            p.apply(&mut config, |k| set.contains(k));
        }
        sets.push((name, config));
    }
    // Maps with their starts.
    let default_starts = if file.starts.is_empty() {
        vec![StartEntry::Named(DefaultStart::Default)]
    } else {
        file.starts
    };
    let mut places: Vec<(String, Option<Point>)> = Vec::new();
    for entry in &file.maps {
        let (map, starts) = match entry {
            MapEntry::Plain(m) => (m, &default_starts),
            MapEntry::WithStarts { map, starts } => (map, starts),
        };
        if let Some(name) = map.strip_prefix("builtin:") {
            name.parse::<BuiltinMap>()
                .map_err(|e| invalid(format!("map `{map}`: {e}")))?;
        } else if map.trim().is_empty() {
            return Err(invalid("a map is an empty string".into()));
        }
        if starts.is_empty() {
            return Err(invalid(format!("map `{map}` lists no start")));
        }
        for s in starts {
            let start = match *s {
                StartEntry::Named(DefaultStart::Default) => None,
                StartEntry::At([x, y]) => {
                    if !(x.is_finite() && y.is_finite()) {
                        return Err(invalid(format!("map `{map}`: a start is not finite")));
                    }
                    Some(Point::new(x, y))
                }
            };
            places.push((map.clone(), start));
        }
    }
    let keys = places
        .iter()
        .map(|(m, s)| (m, s.map(|p| (p.x.to_bits(), p.y.to_bits()))));
    if let Some((map, _)) = twice(keys.collect()) {
        return Err(invalid(format!(
            "map `{map}` is listed twice with the same start (it would count twice)"
        )));
    }
    let planners = axis(&file.planners);
    let strategies = axis(&file.child_strategies);
    let instruments = axis(&file.instruments);
    let count = [
        places.len(),
        sets.len(),
        planners.len(),
        strategies.len(),
        instruments.len(),
        seeds.len(),
    ]
    .iter()
    .try_fold(1usize, |n, &k| n.checked_mul(k))
    .filter(|&n| n <= MAX_EPISODES)
    .ok_or_else(|| invalid(format!("more than {MAX_EPISODES} episodes")))?;
    for (what, twice) in [
        (
            "planners",
            twice(file.planners.iter().map(|p| p.name()).collect()),
        ),
        (
            "child_strategies",
            twice(file.child_strategies.iter().map(|c| c.name()).collect()),
        ),
        (
            "instruments",
            twice(file.instruments.iter().map(|m| m.name()).collect()),
        ),
    ] {
        if let Some(value) = twice {
            return Err(invalid(format!("`{what}` lists `{value}` twice")));
        }
    }
    let mut varies = Varies {
        places: places.len() > 1,
        maps: {
            let mut m: Vec<&String> = places.iter().map(|(m, _)| m).collect();
            m.dedup();
            m.len() > 1
        },
        sets: sets.len() > 1,
        planners: planners.len() > 1,
        strategies: strategies.len() > 1,
        instruments: instruments.len() > 1,
        long: false,
    };
    let mut episodes = Vec::with_capacity(count);
    for (map, start) in &places {
        for (set, base) in &sets {
            for &planner in &planners {
                for &strategy in &strategies {
                    for &instrument in &instruments {
                        for &seed in &seeds {
                            let mut config = base.clone();
                            if let Some(p) = planner {
                                config.parent.planner = p;
                            }
                            if let Some(s) = strategy {
                                config.children.strategy = s;
                            }
                            if let Some(m) = instrument {
                                config.instrument.model = m;
                            }
                            config.seed = seed;
                            config
                                .validate()
                                .map_err(|e| invalid(format!("parameter set `{set}`: {e}")))?;
                            let index = episodes.len();
                            episodes.push(EpisodeSpec {
                                index,
                                label: varies.label(map, *start, set, &config),
                                map: map.clone(),
                                start: *start,
                                parameters: set.clone(),
                                planner: config.parent.planner,
                                child_strategy: config.children.strategy,
                                instrument: config.instrument.model,
                                seed,
                                config,
                            });
                        }
                    }
                }
            }
        }
    }
    // Labels name the conditions of a report: where the short ones collide
    // (`a/lab.yaml` and `b/lab.yaml`, starts 2.01 and 2.04), every label
    // gives the map's whole name and the starts in full.
    let mut labels: Vec<&String> = episodes.iter().map(|e| &e.label).collect();
    labels.sort_unstable();
    if labels.windows(2).any(|w| w[0] == w[1]) {
        varies.long = true;
        for e in &mut episodes {
            e.label = varies.label(&e.map, e.start, &e.parameters, &e.config);
        }
    }
    Ok(Plan {
        format: PLAN_FORMAT.into(),
        name: file.name,
        description: file.description,
        bound: file.bound,
        episodes,
    })
}

/// Which axes take more than one value (those name the episodes).
struct Varies {
    places: bool,
    maps: bool,
    sets: bool,
    planners: bool,
    strategies: bool,
    instruments: bool,
    /// Maps by their whole names and starts in full (short labels collide).
    long: bool,
}

impl Varies {
    fn label(&self, map: &str, start: Option<Point>, set: &str, config: &Config) -> String {
        let mut parts = vec![if self.long {
            map.to_string()
        } else {
            short_map(map)
        }];
        // The start when one is given, or when it is all that tells places apart.
        if self.places && (start.is_some() || !self.maps) {
            parts.push(match start {
                Some(p) if self.long => format!("at{},{}", p.x, p.y),
                Some(p) => format!("at{:.1},{:.1}", p.x, p.y),
                None => "default-start".into(),
            });
        }
        if self.sets {
            parts.push(set.to_string());
        }
        if self.planners {
            parts.push(config.parent.planner.name().to_string());
        }
        if self.strategies {
            parts.push(config.children.strategy.name().to_string());
        }
        if self.instruments {
            parts.push(config.instrument.model.name().to_string());
        }
        parts.push(format!("seed{}", config.seed));
        parts.join("/")
    }
}

/// `builtin:site` → `site`; `maps/lab.yaml` → `lab`.
fn short_map(map: &str) -> String {
    match map.strip_prefix("builtin:") {
        Some(name) => name.to_string(),
        None => Path::new(map)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| map.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(text: &str) -> Result<Plan, SpecError> {
        parse_plan(text, Path::new("test.toml"))
    }

    #[test]
    fn a_preset_in_base_applies_to_every_set_under_its_own_keys() {
        let p = plan(
            "name = \"p\"\nmaps = [\"builtin:site\"]\n[base]\npreset = \"paper\"\n\
             [[parameters]]\nname = \"as-is\"\n[[parameters]]\nname = \"share\"\nparent.min_gain_share = 0.01\n",
        )
        .unwrap();
        let (a, b) = (&p.episodes[0].config, &p.episodes[1].config);
        assert_eq!(a.preset, Some(cpsplan::config::Preset::Paper));
        assert_eq!(
            (a.parent.min_gain_share, a.parent.calibration_window),
            (0.0, 0)
        );
        assert_eq!(
            (b.parent.min_gain_share, b.parent.calibration_window),
            (0.01, 0)
        );
    }

    #[test]
    fn the_cross_product_is_numbered_with_seeds_innermost() {
        let p = plan(
            r#"
            name = "x"
            maps = ["builtin:site", { map = "builtin:office", starts = ["default", [3.0, 4.0]] }]
            seeds = { from = 5, count = 2 }
            planners = ["paper", "tour"]
            [base]
            children.count = 0
            parent.alpha = 0.5
            [[parameters]]
            name = "a"
            [[parameters]]
            name = "b"
            parent.alpha = 0.0
            "#,
        )
        .unwrap();
        // 3 places × 2 sets × 2 planners × 2 seeds.
        assert_eq!(p.episodes.len(), 24);
        for (i, e) in p.episodes.iter().enumerate() {
            assert_eq!(e.index, i);
            assert_eq!(e.seed, e.config.seed);
            assert_eq!(e.planner, e.config.parent.planner);
            assert_eq!(e.config.children.count, 0, "[base] applies to every set");
            let alpha = if e.parameters == "a" { 0.5 } else { 0.0 };
            assert_eq!(e.config.parent.alpha, alpha, "a set's keys override [base]");
        }
        let seeds: Vec<u64> = p.episodes.iter().take(4).map(|e| e.seed).collect();
        assert_eq!(seeds, [5, 6, 5, 6]);
        assert_eq!(p.episodes[0].label, "site/a/paper/seed5");
        assert_eq!(p.episodes[2].label, "site/a/tour/seed5");
        assert_eq!(p.episodes[16].start, Some(Point::new(3.0, 4.0)));
        assert_eq!(p.episodes[16].label, "office/at3.0,4.0/a/paper/seed5");
        let labels: std::collections::HashSet<&str> =
            p.episodes.iter().map(|e| e.label.as_str()).collect();
        assert_eq!(labels.len(), p.episodes.len(), "labels are unique");
    }

    #[test]
    fn absent_axes_keep_the_configuration_s_values() {
        let p = plan(
            r#"
            name = "x"
            maps = ["builtin:tunnel"]
            [base]
            parent.planner = "tour"
            children.strategy = "angle"
            instrument.model = "ts16"
            "#,
        )
        .unwrap();
        assert_eq!(p.episodes.len(), 1);
        let e = &p.episodes[0];
        assert_eq!(e.planner, Planner::Tour);
        assert_eq!(e.child_strategy, ChildStrategy::Angle);
        assert_eq!(e.instrument, InstrumentModel::Ts16);
        assert_eq!(e.parameters, "default");
        assert_eq!(e.seed, 0);
        assert_eq!(e.label, "tunnel/seed0");
    }

    #[test]
    fn labels_tell_apart_what_their_short_form_would_merge() {
        let p = plan("name = \"x\"\nmaps = [\"a/lab.yaml\", \"b/lab.yaml\"]\nseeds = [0]").unwrap();
        let labels: Vec<&str> = p.episodes.iter().map(|e| e.label.as_str()).collect();
        assert_eq!(labels, ["a/lab.yaml/seed0", "b/lab.yaml/seed0"]);
        let p = plan(
            "name = \"x\"\nmaps = [{ map = \"builtin:site\", starts = [[2.01, 3.0], [2.04, 3.0]] }]\nseeds = [0]",
        )
        .unwrap();
        let labels: Vec<&str> = p.episodes.iter().map(|e| e.label.as_str()).collect();
        assert_eq!(
            labels,
            ["builtin:site/at2.01,3/seed0", "builtin:site/at2.04,3/seed0"]
        );
        // Short labels where they are distinct.
        let p = plan("name = \"x\"\nmaps = [\"a/lab.yaml\", \"b/hall.yaml\"]").unwrap();
        assert_eq!(p.episodes[0].label, "lab/seed0");
    }

    #[test]
    fn mistakes_are_named() {
        let cases = [
            ("name = \"x\"\nmaps = []", "lists no map"),
            ("name = \"x\"\nmaps = [\"builtin:moon\"]", "moon"),
            ("name = \"x\"\nmaps = [\"builtin:site\"]\ncolour = 1", "colour"),
            ("name = \"x\"\nmaps = [\"builtin:site\"]\nseeds = []", "no seed"),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\nseeds = { from = 0, count = 0 }",
                "count",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\n[[parameters]]\nparent.alfa = 1.0",
                "alfa",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\n[[parameters]]\nname = \"a\"\n[[parameters]]\nparent.alpha = 1.0",
                "no `name`",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\n[[parameters]]\nname = \"a\"\n[[parameters]]\nname = \"a\"",
                "two parameter sets",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\n[base]\nscanner.range = -1.0",
                "scanner.range",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\nseeds = { from = 0, count = 600000 }\nplanners = [\"paper\", \"tour\"]",
                "more than",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\nseeds = [3, 1, 3]",
                "seed 3 twice",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\", \"builtin:tunnel\", \"builtin:site\"]",
                "`builtin:site` is listed twice",
            ),
            (
                "name = \"x\"\nmaps = [\"builtin:site\"]\nplanners = [\"tour\", \"paper\", \"tour\"]",
                "`tour` twice",
            ),
        ];
        for (text, needle) in cases {
            let e = plan(text).expect_err(text).to_string();
            assert!(e.contains(needle), "{text:?}: {e}");
            assert!(e.starts_with("experiment file test.toml"), "{e}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
    }
}
