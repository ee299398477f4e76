//! An experiment's directory: `experiment.toml` (the file as given), `plan.json`
//! (every episode and the shard this directory runs), `records/` (one JSON file
//! per finished episode, each written whole under a temporary name and renamed
//! into place, so that a killed run leaves only whole records) and
//! `episodes.csv` (one row per record).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::plan_file::{PlanFile, Shard};
use super::record::{episodes_csv, EpisodeRecord, RECORD_FORMAT};
use super::spec::Plan;
use crate::formats::rosmap::read_text;
use crate::memory::check_reading;
use crate::report::write_atomic;

/// The experiment file, copied.
pub const SPEC_FILE: &str = "experiment.toml";
/// The plan.
pub const PLAN_FILE: &str = "plan.json";
/// The records' directory.
pub const RECORDS_DIR: &str = "records";
/// The table of the records.
pub const CSV_FILE: &str = "episodes.csv";
/// The directory of the episode pages (`experiment --html`).
pub const PAGES_DIR: &str = "pages";

/// The largest record file read, bytes.
const MAX_RECORD_BYTES: u64 = 1 << 30;
/// The largest `plan.json` read, bytes (a million episodes take about 0.3 GB;
/// 2.6 GB in the first format).
const MAX_PLAN_BYTES: u64 = 4 << 30;
/// Bytes in memory per byte of `plan.json` while it is read: its text, the
/// episodes as read and the plan they become (measured: a million episodes,
/// 0.29 GB of file, peak 1.2 GB for `report`).
const PLAN_MEMORY_FACTOR: f64 = 5.0;
/// Bytes in memory per byte of the record files while they are read and
/// kept (a record's text is read and dropped; what is kept is smaller than it).
const RECORDS_MEMORY_FACTOR: f64 = 1.5;

/// An experiment directory.
#[derive(Debug)]
pub struct ExperimentDir {
    root: PathBuf,
    /// Its plan and shard.
    pub file: PlanFile,
}

/// Records of a directory, by episode index, and the files that held none.
#[derive(Debug, Default)]
pub struct Records {
    /// The whole, matching records.
    pub valid: BTreeMap<usize, (PathBuf, EpisodeRecord)>,
    /// The directory's own files that are not whole records of this plan
    /// (cut short, of another episode, temporary files of a killed run),
    /// with why: `--resume` redoes them.
    pub damaged: Vec<(PathBuf, String)>,
    /// Entries that are not the directory's own (other names, records beyond
    /// the plan, anything but a regular file), with why: read by nobody and
    /// left alone.
    pub foreign: Vec<(PathBuf, String)>,
}

impl ExperimentDir {
    /// Starts a new experiment in `out`, which must be absent or empty.
    pub fn create(out: &Path, spec_text: &str, plan: Plan, shard: Shard) -> Result<Self> {
        refuse_filled(
            out,
            "--resume continues the experiment there, or choose a new directory",
        )?;
        std::fs::create_dir_all(out)
            .with_context(|| format!("cannot create directory {}", out.display()))?;
        let dir = Self {
            root: out.to_path_buf(),
            file: PlanFile {
                plan,
                shard: Some(shard),
            },
        };
        // plan.json first, whole: a run that dies before it leaves an empty
        // directory, one that dies after it a directory `--resume` finishes
        // (it writes the experiment file again if it is missing).
        dir.write_plan()?;
        let records = out.join(RECORDS_DIR);
        std::fs::create_dir_all(&records)
            .with_context(|| format!("cannot create directory {}", records.display()))?;
        write_atomic(&out.join(SPEC_FILE), spec_text.as_bytes())?;
        Ok(dir)
    }

    /// Opens the experiment in `out` to continue it: its plan and shard must be
    /// `plan` and `shard`, planned from the experiment file `spec_text` (kept
    /// again if a run died before it wrote it).
    pub fn resume(out: &Path, spec_text: &str, plan: Plan, shard: Shard) -> Result<Self> {
        let dir = Self::open(out)?;
        let fresh = PlanFile {
            plan,
            shard: Some(shard),
        };
        if dir.file.shard != fresh.shard {
            bail!(
                "--resume: {} runs shard {}, not {shard}; give the same --shard as before",
                out.display(),
                dir.file.shard.map_or("(merged)".into(), |s| s.to_string())
            );
        }
        if dir.file.plan != fresh.plan {
            bail!(
                "--resume: the experiment in {} was planned from a different experiment file \
                 (its plan.json differs); resume with the file it was started with, or choose a new --out",
                out.display()
            );
        }
        let records = out.join(RECORDS_DIR);
        std::fs::create_dir_all(&records)
            .with_context(|| format!("cannot create directory {}", records.display()))?;
        if !out.join(SPEC_FILE).exists() {
            write_atomic(&out.join(SPEC_FILE), spec_text.as_bytes())?;
        }
        Ok(dir)
    }

    /// Opens an experiment directory for reading.
    pub fn open(root: &Path) -> Result<Self> {
        let path = root.join(PLAN_FILE);
        if !path.exists() {
            bail!(
                "{} holds no experiment (it has no {PLAN_FILE})",
                root.display()
            );
        }
        // A regular file only (a FIFO would block, a device never end), and
        // one that fits: the text and the plan parsed from it.
        let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
        check_reading(&path.display().to_string(), bytes, PLAN_MEMORY_FACTOR)?;
        let text = read_text(&path, MAX_PLAN_BYTES)?;
        let file: PlanFile = serde_json::from_str(&text)
            .with_context(|| format!("{} is not an experiment plan", path.display()))?;
        if let Some((i, e)) = file
            .plan
            .episodes
            .iter()
            .enumerate()
            .find(|(i, e)| e.index != *i)
        {
            bail!("{}: episode {i} is numbered {}", path.display(), e.index);
        }
        Ok(Self {
            root: root.to_path_buf(),
            file,
        })
    }

    /// The directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Where the record of episode `index` goes.
    pub fn record_path(&self, index: usize) -> PathBuf {
        self.root.join(RECORDS_DIR).join(record_name(index))
    }

    /// Where the page of episode `index` goes (`experiment --html`).
    pub fn page_path(&self, index: usize) -> PathBuf {
        self.root.join(PAGES_DIR).join(page_name(index))
    }

    /// Writes the page of episode `index` whole (temporary file, then rename).
    pub fn write_page(&self, index: usize, html: &str) -> Result<()> {
        let dir = self.root.join(PAGES_DIR);
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create directory {}", dir.display()))?;
        write_atomic(&self.page_path(index), html.as_bytes())
    }

    fn write_plan(&self) -> Result<()> {
        let json = serde_json::to_vec_pretty(&self.file)?;
        write_atomic(&self.root.join(PLAN_FILE), &json)
    }

    /// Writes a record whole (temporary file, then rename).
    pub fn write_record(&self, record: &EpisodeRecord) -> Result<()> {
        let json = serde_json::to_vec_pretty(record)?;
        write_atomic(&self.record_path(record.episode.index), &json)
    }

    /// Reads every record file, sorting the whole ones that match the plan from
    /// the damaged ones; leftover temporary files of killed runs are listed as
    /// damaged.
    pub fn records(&self) -> Result<Records> {
        let dir = self.root.join(RECORDS_DIR);
        let mut out = Records::default();
        let entries = match std::fs::read_dir(&dir) {
            Ok(e) => e,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(out),
            Err(e) => return Err(e).with_context(|| format!("cannot read {}", dir.display())),
        };
        let mut paths: Vec<PathBuf> = Vec::new();
        for entry in entries {
            let entry = entry.with_context(|| format!("cannot read {}", dir.display()))?;
            paths.push(entry.path());
        }
        paths.sort();
        // The records are kept: refuse before reading if they cannot be.
        let bytes: u64 = paths
            .iter()
            .filter_map(|p| std::fs::metadata(p).ok())
            .filter(|m| m.is_file() && m.len() <= MAX_RECORD_BYTES)
            .map(|m| m.len())
            .sum();
        check_reading(
            &format!("the records of {}", dir.display()),
            bytes,
            RECORDS_MEMORY_FACTOR,
        )?;
        for path in paths {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            // Only regular files are read (a FIFO would block, a device
            // never end); a symbolic link counts as what it names.
            if !std::fs::metadata(&path).is_ok_and(|m| m.is_file()) {
                out.foreign.push((path, "not a regular file".into()));
                continue;
            }
            let index = match parse_record_name(&name) {
                Some(index) => index,
                None if is_temp_name(&name) => {
                    out.damaged
                        .push((path, "a temporary file of a killed run".into()));
                    continue;
                }
                None => {
                    let why = "not a record file name (NNNNNN.json)";
                    out.foreign.push((path, why.into()));
                    continue;
                }
            };
            let episodes = self.file.plan.episodes.len();
            if index >= episodes {
                let why = format!("episode {index}, but the plan has {episodes}");
                out.foreign.push((path, why));
                continue;
            }
            match self.check_record(&path, index) {
                Ok(record) => {
                    out.valid.insert(index, (path, record));
                }
                Err(why) => out.damaged.push((path, why)),
            }
        }
        Ok(out)
    }

    /// The record in `path`, a regular file named for episode `index` of
    /// the plan, if it is a whole record of that episode.
    fn check_record(&self, path: &Path, index: usize) -> Result<EpisodeRecord, String> {
        let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
        if meta.len() > MAX_RECORD_BYTES {
            return Err("larger than any record".into());
        }
        let text = read_text(path, MAX_RECORD_BYTES).map_err(|e| e.to_string())?;
        parse_record(&text, &self.file.plan, index)
    }

    /// Writes `episodes.csv` of `records`.
    pub fn write_csv<'a>(
        &self,
        records: impl IntoIterator<Item = &'a EpisodeRecord>,
    ) -> Result<()> {
        write_atomic(&self.root.join(CSV_FILE), &episodes_csv(records)?)
    }
}

/// The record that `text` holds, if it is a whole, plausible record of
/// episode `index` of `plan` (the check `report`, `merge` and `--resume`
/// make of every record file).
pub fn parse_record(text: &str, plan: &Plan, index: usize) -> Result<EpisodeRecord, String> {
    let record: EpisodeRecord =
        serde_json::from_str(text).map_err(|e| format!("not a whole record ({e})"))?;
    if record.format != RECORD_FORMAT {
        return Err(format!(
            "format `{}`, expected `{RECORD_FORMAT}`",
            record.format
        ));
    }
    let Some(spec) = plan.episodes.get(index) else {
        return Err(format!(
            "episode {index}, but the plan has {}",
            plan.episodes.len()
        ));
    };
    if record.experiment != plan.name || record.episode != *spec {
        return Err(format!(
            "the record is of another episode than plan.json's {index} ({})",
            spec.label
        ));
    }
    record
        .plausible()
        .map_err(|why| format!("not a plausible record: {why}"))?;
    Ok(record)
}

/// Refuses an `--out` that exists and is not an empty directory; `hint` says
/// what to do instead.
pub fn refuse_filled(out: &Path, hint: &str) -> Result<()> {
    match std::fs::read_dir(out).map(|mut entries| entries.next().is_some()) {
        Ok(true) => bail!("--out {} already holds files: {hint}", out.display()),
        Err(_) if out.exists() => bail!("--out {} exists and is not a directory", out.display()),
        _ => Ok(()),
    }
}

/// `000042.json`.
pub fn record_name(index: usize) -> String {
    format!("{index:06}.json")
}

/// `000042.html`.
pub fn page_name(index: usize) -> String {
    format!("{index:06}.html")
}

/// Whether `name` is a temporary record file ([`write_atomic`]'s
/// `.NNNNNN.json.PID.tmp`).
fn is_temp_name(name: &str) -> bool {
    name.strip_prefix('.')
        .and_then(|n| n.strip_suffix(".tmp"))
        .and_then(|n| n.rsplit_once('.'))
        .is_some_and(|(record, pid)| {
            parse_record_name(record).is_some() && pid.bytes().all(|b| b.is_ascii_digit())
        })
}

fn parse_record_name(name: &str) -> Option<usize> {
    let digits = name.strip_suffix(".json")?;
    (digits.len() >= 6 && digits.bytes().all(|b| b.is_ascii_digit()))
        .then(|| digits.parse().ok())
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shards_split_the_episodes_exactly() {
        for n in 1..=9 {
            for index in 0..50 {
                let holders = (1..=n).filter(|&k| Shard { k, n }.holds(index)).count();
                assert_eq!(holders, 1, "episode {index}, {n} shards");
            }
        }
    }

    #[test]
    fn shards_parse_as_k_of_n() {
        assert_eq!("3/8".parse::<Shard>(), Ok(Shard { k: 3, n: 8 }));
        assert_eq!(" 1 / 1 ".parse::<Shard>(), Ok(Shard::WHOLE));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "-1/2", "1/2/3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        assert_eq!(Shard { k: 2, n: 5 }.to_string(), "2/5");
    }

    #[test]
    fn record_names_round_trip() {
        for i in [0, 7, 999_999, 1_000_000] {
            assert_eq!(parse_record_name(&record_name(i)), Some(i));
        }
        for bad in [
            "12.json",
            "00001a.json",
            ".000001.json.1.tmp",
            "000001.json.tmp",
        ] {
            assert_eq!(parse_record_name(bad), None, "{bad}");
        }
    }
}
