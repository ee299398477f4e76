//! `cpsplan experiment`: the episodes of an experiment file, in parallel, one
//! record each as it finishes; and `cpsplan experiment merge`, which joins the
//! directories of an experiment's shards.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use clap::{Args, Subcommand};
use cpsplan::bound::{known_map_bound, BoundParams};
use cpsplan::world::{default_start, resample_for};
use cpsplan::{run_episode_with, OccupancyGrid, Point};
use indicatif::{ProgressBar, ProgressStyle};

use super::{check_memory, load_planning_grid};
use crate::args::parse_count;
use crate::experiment::record::BoundRecord;
use crate::experiment::store::{
    page_name, record_name, refuse_filled, CSV_FILE, PAGES_DIR, PLAN_FILE, RECORDS_DIR, SPEC_FILE,
};
use crate::experiment::{
    parse_plan, EpisodeRecord, EpisodeSpec, ExperimentDir, Outcome, PlanFile, Shard,
};
use crate::formats::rosmap::{read_text, ReadLimits};
use crate::html::{episode_page, page_title, PageRecorder};
use crate::lock::OutLock;
use crate::memory::memory_budget;
use crate::report::{real_path, write_atomic, ReportDir};

/// Options of `cpsplan experiment`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct ExperimentArgs {
    /// `merge`: join the directories of an experiment's shards.
    #[command(subcommand)]
    pub command: Option<ExperimentCommand>,
    /// The experiment file: maps × starts × parameter sets × planners × child
    /// strategies × instruments × seeds (the user guide's "Experiments").
    #[arg(value_name = "FILE.toml", required = true)]
    pub file: Option<PathBuf>,
    /// Directory of the records: experiment.toml, plan.json, records/NNNNNN.json
    /// (one per episode, written as it finishes), episodes.csv.
    #[arg(long, value_name = "DIR", required = true)]
    pub out: Option<PathBuf>,
    /// Continue the experiment in --out: run only the episodes without a whole
    /// record (a damaged one is redone).
    #[arg(long)]
    pub resume: bool,
    /// Run only the K-th of N slices of the episodes (1 ≤ K ≤ N: those whose
    /// number leaves the remainder K − 1 when divided by N).
    #[arg(long, value_name = "K/N")]
    pub shard: Option<crate::experiment::Shard>,
    /// Episodes run at once [default: the number of cores].
    #[arg(long, value_name = "N", value_parser = parse_count)]
    pub jobs: Option<usize>,
    /// Also write each finished episode's page, pages/NNNNNN.html (the page of
    /// `explore --html`), before its record; `cpsplan report` shows them. With
    /// --resume, finished episodes without a page are run again.
    #[arg(long)]
    pub html: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The subcommands of `cpsplan experiment`.
#[derive(Debug, Subcommand)]
pub enum ExperimentCommand {
    /// Join the records of an experiment's shard directories into one directory;
    /// refuses duplicate or missing episodes.
    Merge(MergeArgs),
}

/// Options of `cpsplan experiment merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shards' directories (the --out of each `experiment --shard K/N`).
    #[arg(value_name = "DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// The merged directory (new or empty).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Print nothing but errors and warnings.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `cpsplan experiment` or its `merge`.
pub fn run(args: &ExperimentArgs) -> Result<()> {
    if let Some(ExperimentCommand::Merge(m)) = &args.command {
        return merge(m);
    }
    let (Some(file), Some(out)) = (&args.file, &args.out) else {
        bail!("an experiment needs FILE.toml and --out DIR");
    };
    let text = read_text(file, ReadLimits::default().max_text_bytes)?;
    let plan = parse_plan(&text, file)?;
    let name = plan.name.clone();
    let shard = args.shard.unwrap_or(Shard::WHOLE);
    let experiment_dir = file
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    // Every map of the shard loaded, and every run's memory checked, before
    // anything is written.
    let in_shard = |e: &&EpisodeSpec| shard.holds(e.index);
    let mine: Vec<&EpisodeSpec> = plan.episodes.iter().filter(in_shard).collect();
    let maps = MapFiles::load(&mine, experiment_dir)?;
    let _lock = OutLock::acquire(out)?;
    let dir = if args.resume {
        ExperimentDir::resume(out, &text, plan, shard)?
    } else {
        ExperimentDir::create(out, &text, plan, shard)?
    };
    let records = dir.records()?;
    for (path, why) in &records.damaged {
        if !args.quiet {
            eprintln!("redoing {}: {why}", path.display());
        }
        std::fs::remove_file(path).with_context(|| format!("cannot remove {}", path.display()))?;
    }
    for (path, why) in &records.foreign {
        eprintln!("warning: left alone: {} ({why})", path.display());
    }
    let episodes = &dir.file.plan.episodes;
    let total = episodes.len();
    let mine: Vec<&EpisodeSpec> = episodes.iter().filter(in_shard).collect();
    // With --html, a finished episode whose page is missing runs again.
    let done = |e: &EpisodeSpec| match records.valid.get(&e.index) {
        Some((_, r)) => {
            !args.html
                || matches!(r.outcome, Outcome::Failed { .. })
                || dir.page_path(e.index).is_file()
        }
        None => false,
    };
    let todo: Vec<&EpisodeSpec> = mine.iter().copied().filter(|e| !done(e)).collect();
    let before = mine.len() - todo.len();
    let jobs = args
        .jobs
        .unwrap_or_else(rayon::current_num_threads)
        .clamp(1, todo.len().max(1));
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::new(todo.len() as u64);
        if let Ok(style) = ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} episodes, eta {eta} {msg}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    };
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let failures: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());
    let written: Mutex<Vec<EpisodeRecord>> = Mutex::new(Vec::new());
    let write_error: Mutex<Option<anyhow::Error>> = Mutex::new(None);
    let bounds = dir.file.plan.bound.then(Bounds::default);
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= todo.len() || stop.load(Ordering::Relaxed) {
                    break;
                }
                let spec = todo[i];
                let (record, page) = run_one(
                    &name,
                    spec,
                    &maps,
                    experiment_dir,
                    bounds.as_ref(),
                    args.html,
                );
                if let Outcome::Failed { error } = &record.outcome {
                    if let Ok(mut f) = failures.lock() {
                        f.push((spec.label.clone(), error.clone()));
                    }
                }
                // The page first: a record on disk means its page is there too.
                let wrote = page
                    .map_or(Ok(()), |html| dir.write_page(spec.index, &html))
                    .and_then(|()| dir.write_record(&record));
                if let Err(e) = wrote {
                    if let Ok(mut w) = write_error.lock() {
                        w.get_or_insert(e);
                    }
                    stop.store(true, Ordering::Relaxed);
                    break;
                }
                if let Ok(mut w) = written.lock() {
                    w.push(record);
                }
                bar.set_message(spec.label.clone());
                bar.inc(1);
            });
        }
    });
    bar.finish_and_clear();
    if let Some(e) = write_error.into_inner().ok().flatten() {
        return Err(e);
    }
    // The records found whole before, and those written now, in episode order.
    let mut all: BTreeMap<usize, EpisodeRecord> = records
        .valid
        .into_iter()
        .map(|(index, (_, r))| (index, r))
        .collect();
    for r in written.into_inner().unwrap_or_default() {
        all.insert(r.episode.index, r);
    }
    dir.write_csv(all.values())?;
    let failures = failures.into_inner().unwrap_or_default();
    if !args.quiet {
        let of = if shard == Shard::WHOLE {
            format!("{total} episodes")
        } else {
            format!(
                "the {} episodes of shard {shard} ({total} in all)",
                mine.len()
            )
        };
        println!(
            "experiment `{}`: {} run, {before} done before, of {of}; records in {}",
            dir.file.plan.name,
            todo.len(),
            dir.root().join(RECORDS_DIR).display()
        );
    }
    if let Some((label, error)) = failures.first() {
        bail!(
            "{} of {} episodes could not run (their records say why); the first, {label}: {error}",
            failures.len(),
            todo.len()
        );
    }
    Ok(())
}

/// The map files of an experiment, each loaded once at every planning
/// resolution and cell limit its episodes use.
struct MapFiles {
    grids: HashMap<(PathBuf, u64, usize), Arc<OccupancyGrid>>,
}

impl MapFiles {
    /// Loads every map file `episodes` name, checking that each episode's run
    /// fits in memory, before any episode runs.
    fn load(episodes: &[&EpisodeSpec], experiment_dir: &Path) -> Result<Self> {
        let mut grids = HashMap::new();
        for e in episodes {
            if let Some(Err(message)) = e.builtin() {
                bail!("episode {}: {message}", e.label);
            }
            let Some(path) = e.map_path(experiment_dir) else {
                continue;
            };
            let key = Self::key(&path, e);
            if !grids.contains_key(&key) {
                let grid = load_planning_grid(&path, &e.config)?;
                grids.insert(key.clone(), Arc::new(grid));
            }
            check_memory(&grids[&key], &e.config)
                .with_context(|| format!("episode {}", e.label))?;
        }
        Ok(Self { grids })
    }

    fn key(path: &Path, e: &EpisodeSpec) -> (PathBuf, u64, usize) {
        (
            path.to_path_buf(),
            e.config.resolution.to_bits(),
            e.config.limits.max_grid_cells,
        )
    }

    /// The ground truth of episode `e` and its start.
    fn truth(&self, e: &EpisodeSpec, experiment_dir: &Path) -> Result<(Arc<OccupancyGrid>, Point)> {
        let (grid, own_start) = match e.builtin() {
            Some(map) => {
                let map = map.map_err(|m| anyhow!(m))?;
                let grid = resample_for(&map.generate(e.config.seed), &e.config)
                    .map_err(|err| anyhow!("built-in map `{}`: {err}", map.name()))?;
                (Arc::new(grid), Some(map.default_start()))
            }
            None => {
                let path = e.map_path(experiment_dir).unwrap_or_default();
                let grid = self
                    .grids
                    .get(&Self::key(&path, e))
                    .cloned()
                    .ok_or_else(|| anyhow!("map {} was not loaded", path.display()))?;
                (grid, None)
            }
        };
        let start = match e.start.or(own_start) {
            Some(p) => p,
            None => default_start(&grid)
                .ok_or_else(|| anyhow!("map {} has no free cell to start from", e.map))?,
        };
        Ok((grid, start))
    }
}

/// The known-map bounds of a run, each computed once however many episodes
/// share it (and however many workers ask for it at once).
#[derive(Default)]
struct Bounds {
    computed: Mutex<HashMap<String, Arc<OnceLock<BoundRecord>>>>,
}

impl Bounds {
    /// The bound of episode `spec` on `truth` from `start`.
    fn get(&self, spec: &EpisodeSpec, truth: &OccupancyGrid, start: Point) -> BoundRecord {
        // What the bound depends on: the map (and a built-in map's seed), the
        // start, and the scanner, robot, resolution and limits.
        let c = &spec.config;
        let key = serde_json::to_string(&(
            &spec.map,
            spec.builtin().map(|_| spec.seed),
            [start.x.to_bits(), start.y.to_bits()],
            &c.scanner,
            &c.robot,
            c.resolution.to_bits(),
            &c.limits,
        ))
        .unwrap_or_else(|_| spec.label.clone());
        let cell = match self.computed.lock() {
            Ok(mut m) => m.entry(key).or_default().clone(),
            Err(_) => Arc::default(),
        };
        cell.get_or_init(|| {
            let available = memory_budget().map(|b| (b.mb, b.source));
            match known_map_bound(truth, start, c, BoundParams::default(), available) {
                Ok(b) => BoundRecord::of(&b),
                Err(e) => BoundRecord::Failed {
                    error: e.to_string(),
                },
            }
        })
        .clone()
    }
}

/// Runs one episode into its record (with its map's bound when `bounds` is
/// given) and, with `html`, its page.
fn run_one(
    experiment: &str,
    spec: &EpisodeSpec,
    maps: &MapFiles,
    dir: &Path,
    bounds: Option<&Bounds>,
    html: bool,
) -> (EpisodeRecord, Option<String>) {
    let t0 = Instant::now();
    let mut wall_ms = 0.0;
    let result = maps.truth(spec, dir).and_then(|(truth, start)| {
        let mut recorder = html.then(|| PageRecorder::new(*truth.geometry()));
        let episode = run_episode_with(&truth, start, &spec.config, |step, knowledge| {
            if let Some(r) = recorder.as_mut() {
                r.record(step, knowledge, &spec.config);
            }
        })?;
        wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        // The bound's and the page's own time are not the episode's.
        let bound = bounds.map(|b| b.get(spec, &truth, start));
        let page = recorder
            .map(|r| {
                let title = page_title(experiment, &spec.label);
                episode_page(&episode, &r, &title, &spec.map)
            })
            .transpose()?;
        Ok((start, episode, bound, page))
    });
    if result.is_err() {
        wall_ms = t0.elapsed().as_secs_f64() * 1e3;
    }
    match result {
        Ok((start, episode, bound, page)) => (
            EpisodeRecord {
                bound,
                ..EpisodeRecord::finished(experiment, spec, start, &episode, wall_ms)
            },
            page,
        ),
        Err(e) => (
            EpisodeRecord::failed(experiment, spec, crate::errors::one_line(&e), wall_ms),
            None,
        ),
    }
}

/// `cpsplan experiment merge DIR... --out DIR`.
fn merge(args: &MergeArgs) -> Result<()> {
    let dirs: Vec<ExperimentDir> = args
        .dirs
        .iter()
        .map(|d| ExperimentDir::open(d))
        .collect::<Result<_>>()?;
    let Some(first) = dirs.first() else {
        bail!("merge needs at least one experiment directory");
    };
    let mut seen: Vec<PathBuf> = Vec::new();
    for d in &dirs {
        let real = std::fs::canonicalize(d.root()).unwrap_or_else(|_| d.root().to_path_buf());
        if seen.contains(&real) {
            bail!(
                "{} is given twice: merge each shard once",
                d.root().display()
            );
        }
        seen.push(real);
    }
    for d in &dirs[1..] {
        if d.file.plan != first.file.plan {
            bail!(
                "{} and {} hold different experiments (their {PLAN_FILE} differ): \
                 merge only the shards of one experiment file",
                first.root().display(),
                d.root().display()
            );
        }
    }
    let episodes = &first.file.plan.episodes;
    let mut found: Vec<Option<(PathBuf, EpisodeRecord)>> = vec![None; episodes.len()];
    for d in &dirs {
        let records = d.records()?;
        for (path, why) in &records.foreign {
            eprintln!("warning: left out: {} ({why})", path.display());
        }
        if let Some((path, why)) = records.damaged.first() {
            bail!(
                "{}: {why}; `experiment {SPEC_FILE} --out {} --resume` with its --shard redoes it",
                path.display(),
                d.root().display()
            );
        }
        for (index, (path, record)) in records.valid {
            if let Some((other, _)) = &found[index] {
                bail!(
                    "episode {index} ({}) is in both {} and {}: merge each shard once",
                    episodes[index].label,
                    other.display(),
                    path.display()
                );
            }
            found[index] = Some((path, record));
        }
    }
    let missing: Vec<&EpisodeSpec> = episodes
        .iter()
        .filter(|e| found[e.index].is_none())
        .collect();
    if let Some(e) = missing.first() {
        let shards: Vec<String> = dirs
            .iter()
            .filter_map(|d| d.file.shard)
            .map(|s| s.to_string())
            .collect();
        bail!(
            "{} of {} episodes have no record, the first {} ({}); the directories hold shards {}: \
             run the missing shards, or --resume the unfinished ones",
            missing.len(),
            episodes.len(),
            e.index,
            e.label,
            if shards.is_empty() {
                "(merged)".into()
            } else {
                shards.join(", ")
            }
        );
    }
    let target = real_path(&args.out);
    if let Some(inside) = seen.iter().find(|d| target.starts_with(d)) {
        bail!(
            "--out {} lies inside {}, a directory being merged: choose a directory outside them",
            args.out.display(),
            inside.display()
        );
    }
    let _lock = OutLock::acquire(&args.out)?;
    refuse_filled(&args.out, "choose a new directory")?;
    let spec = read_text(
        &first.root().join(SPEC_FILE),
        ReadLimits::default().max_text_bytes,
    )?;
    let out = ReportDir::create(&args.out)?;
    let tmp = out.path();
    write_atomic(&tmp.join(SPEC_FILE), spec.as_bytes())?;
    let merged = PlanFile {
        plan: first.file.plan.clone(),
        shard: None,
    };
    write_atomic(&tmp.join(PLAN_FILE), &serde_json::to_vec_pretty(&merged)?)?;
    let records_dir = tmp.join(RECORDS_DIR);
    std::fs::create_dir(&records_dir)
        .with_context(|| format!("cannot create directory {}", records_dir.display()))?;
    let records: Vec<EpisodeRecord> = found
        .into_iter()
        .flatten()
        .map(|(path, r)| {
            let to = records_dir.join(record_name(r.episode.index));
            std::fs::copy(&path, &to)
                .map(|_| r)
                .with_context(|| format!("cannot copy {}", path.display()))
        })
        .collect::<Result<_>>()?;
    // The shards' pages, of the episodes merged.
    let mut pages = 0usize;
    for d in &dirs {
        for r in &records {
            let from = d.page_path(r.episode.index);
            if from.is_file() {
                let to_dir = tmp.join(PAGES_DIR);
                std::fs::create_dir_all(&to_dir)
                    .with_context(|| format!("cannot create directory {}", to_dir.display()))?;
                std::fs::copy(&from, to_dir.join(page_name(r.episode.index)))
                    .with_context(|| format!("cannot copy {}", from.display()))?;
                pages += 1;
            }
        }
    }
    write_atomic(
        &tmp.join(CSV_FILE),
        &crate::experiment::record::episodes_csv(&records)?,
    )?;
    out.commit()?;
    if args.quiet {
        return Ok(());
    }
    println!(
        "experiment `{}`: {} records{} from {} director{} merged into {}",
        first.file.plan.name,
        records.len(),
        if pages > 0 {
            format!(" and {pages} pages")
        } else {
            String::new()
        },
        dirs.len(),
        if dirs.len() == 1 { "y" } else { "ies" },
        args.out.display()
    );
    Ok(())
}
