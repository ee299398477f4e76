//! One writer per output directory: `experiment`, `experiment merge` and
//! `report` hold an exclusive advisory lock on a file beside their `--out`
//! (`.NAME.cpsplan-lock` in its parent) while they write, and a second writer
//! is refused in one line that names the holder's process id. The lock is the
//! operating system's (`flock`), so it dies with its process: a killed run
//! leaves no lock behind, only (at worst) the file, which the next writer
//! takes over.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The exclusive lock on an output directory, held until dropped.
#[derive(Debug)]
pub struct OutLock {
    path: PathBuf,
    file: File,
}

impl OutLock {
    /// Takes the lock of `out` (which need not exist yet; its parent is
    /// created), or refuses when another process holds it.
    pub fn acquire(out: &Path) -> Result<Self> {
        let path = lock_path(out)?;
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create directory {}", parent.display()))?;
        }
        // A holder that ends removes the file after others may have opened
        // it: a lock taken on a file no longer at `path` is taken again.
        for _ in 0..16 {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .with_context(|| format!("cannot create the lock file {}", path.display()))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let mut holder = String::new();
                    let _ = file.read_to_string(&mut holder);
                    let who = match holder.trim().parse::<u32>() {
                        Ok(pid) => format!("another cpsplan (pid {pid})"),
                        Err(_) => "another cpsplan".to_string(),
                    };
                    bail!(
                        "--out {}: {who} is writing there; wait for it to end or choose another --out",
                        out.display()
                    );
                }
                Err(std::fs::TryLockError::Error(e)) => {
                    return Err(e).with_context(|| format!("cannot lock {}", path.display()));
                }
            }
            if !same_file(&file, &path) {
                continue;
            }
            file.set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| write!(file, "{}", std::process::id()))
                .with_context(|| format!("cannot write the lock file {}", path.display()))?;
            return Ok(Self { path, file });
        }
        bail!("--out {}: cannot take its lock", out.display())
    }
}

impl Drop for OutLock {
    fn drop(&mut self) {
        // Removed while still locked, then unlocked when the file closes.
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// `.NAME.cpsplan-lock` beside `out`.
fn lock_path(out: &Path) -> Result<PathBuf> {
    let named = match out.file_name() {
        Some(_) => out.to_path_buf(),
        // `.`, `..` or `/`: the directory by its real name.
        None => std::fs::canonicalize(out)
            .with_context(|| format!("--out {}: cannot resolve its name", out.display()))?,
    };
    let name = named
        .file_name()
        .with_context(|| format!("--out {}: needs a directory name", out.display()))?
        .to_string_lossy()
        .into_owned();
    let parent = match named.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok(parent.join(format!(".{name}.cpsplan-lock")))
}

/// Whether the open `file` is still the file at `path`.
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether the open `file` is still the file at `path` (assumed elsewhere).
#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_is_refused_until_the_first_ends() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("run");
        let first = OutLock::acquire(&out).unwrap();
        let lock = tmp.path().join(".run.cpsplan-lock");
        assert_eq!(
            std::fs::read_to_string(&lock).unwrap(),
            std::process::id().to_string()
        );
        let e = OutLock::acquire(&out).unwrap_err().to_string();
        assert!(
            e.contains(&format!("pid {}", std::process::id())) && !e.contains('\n'),
            "{e}"
        );
        drop(first);
        assert!(!lock.exists(), "the lock file goes with its holder");
        let again = OutLock::acquire(&out).unwrap();
        drop(again);
    }

    #[test]
    fn a_lock_file_left_by_a_killed_run_is_taken_over() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("run");
        std::fs::write(tmp.path().join(".run.cpsplan-lock"), "4194999").unwrap();
        let lock = OutLock::acquire(&out).unwrap();
        drop(lock);
    }

    #[test]
    fn the_lock_sits_beside_the_directory() {
        let p = lock_path(Path::new("a/b/run")).unwrap();
        assert_eq!(p, Path::new("a/b/.run.cpsplan-lock"));
        let p = lock_path(Path::new("run")).unwrap();
        assert_eq!(p, Path::new("./.run.cpsplan-lock"));
        let here = lock_path(Path::new(".")).unwrap();
        let name = std::env::current_dir().unwrap();
        let name = name.file_name().unwrap().to_string_lossy();
        assert!(here.ends_with(format!(".{name}.cpsplan-lock")), "{here:?}");
    }
}
