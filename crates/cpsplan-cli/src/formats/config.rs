//! TOML configuration files (docs/USER-GUIDE.md "Configuration"): every key of
//! [`cpsplan::Config`], each optional. Syntax and type errors name the line,
//! the key and its section; values are checked later, once command-line flags
//! have been applied ([`Config::validate`]).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use cpsplan::Config;

use super::rosmap::{read_text, FormatError};

/// A parsed configuration file.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigFile {
    /// The defaults with every value the file gives.
    pub config: Config,
    /// The dotted keys the file sets (`scanner.range`, `children.count`, ...).
    pub keys: BTreeSet<String>,
}

impl ConfigFile {
    /// Whether the file sets the dotted key `key`.
    pub fn sets(&self, key: &str) -> bool {
        self.keys.contains(key)
    }
}

/// Why a configuration file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ConfigFileError {
    /// The file could not be read.
    #[error(transparent)]
    Read(#[from] FormatError),
    /// The TOML is malformed, or a key is unknown or of the wrong type.
    #[error("config file {}{}: {message}", path.display(), place(*line, key.as_deref()))]
    Toml {
        /// The file.
        path: PathBuf,
        /// The line of the problem, from 1 (when known).
        line: Option<usize>,
        /// The dotted key on that line (when there is one).
        key: Option<String>,
        /// The parser's message, on one line.
        message: String,
    },
}

fn place(line: Option<usize>, key: Option<&str>) -> String {
    match (line, key) {
        (Some(l), Some(k)) => format!(", line {l}, `{k}`"),
        (Some(l), None) => format!(", line {l}"),
        (None, Some(k)) => format!(", `{k}`"),
        (None, None) => String::new(),
    }
}

/// Reads a configuration file of at most `max_bytes` bytes.
pub fn read_config_file(path: &Path, max_bytes: u64) -> Result<ConfigFile, ConfigFileError> {
    let text = read_text(path, max_bytes)?;
    parse_config(&text, path)
}

/// Parses configuration text; `path` names it in messages.
pub fn parse_config(text: &str, path: &Path) -> Result<ConfigFile, ConfigFileError> {
    let config = toml::from_str::<Config>(text).map_err(|e| {
        let at = e.span().map(|s| s.start);
        ConfigFileError::Toml {
            path: path.to_path_buf(),
            line: at.map(|i| line_of(text, i)),
            key: at.and_then(|i| key_at(text, i)),
            message: one_line(e.message()),
        }
    })?;
    // The same text parsed as a table: it cannot fail where the typed parse did
    // not, but a failure only loses the list of keys.
    let keys = toml::from_str::<toml::Table>(text)
        .map(|t| {
            let mut keys = BTreeSet::new();
            collect_keys(&t, "", &mut keys);
            keys
        })
        .unwrap_or_default();
    let mut config = config;
    if let Some(p) = config.preset {
        p.apply(&mut config, |k| keys.contains(k));
    }
    Ok(ConfigFile { config, keys })
}

/// Line number (from 1) of byte offset `at`.
fn line_of(text: &str, at: usize) -> usize {
    let at = floor_boundary(text, at);
    text[..at].bytes().filter(|&b| b == b'\n').count() + 1
}

fn floor_boundary(text: &str, mut at: usize) -> usize {
    at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

/// The dotted key of the `key = value` line holding byte offset `at`, with the
/// `[section]` above it.
fn key_at(text: &str, at: usize) -> Option<String> {
    let at = floor_boundary(text, at);
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next().unwrap_or("");
    let (key, _) = line.split_once('=')?;
    let key = key.trim().trim_matches('"');
    if key.is_empty() || key.starts_with('[') || key.starts_with('#') {
        return None;
    }
    let section = text[..start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('[') && !l.starts_with("[["))
        .and_then(|l| l.split(']').next())
        .map(|l| l.trim_start_matches('[').trim().to_string());
    Some(match section {
        Some(s) if !s.is_empty() => format!("{s}.{key}"),
        _ => key.to_string(),
    })
}

/// The dotted paths of every leaf value of `table`.
pub(crate) fn collect_keys(table: &toml::Table, prefix: &str, out: &mut BTreeSet<String>) {
    for (k, v) in table {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(t) => collect_keys(t, &key, out),
            _ => {
                out.insert(key);
            }
        }
    }
}

/// A message on one line: line breaks become "; ".
pub(crate) fn one_line(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse_config(text, Path::new("c.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn type_errors_name_the_line_and_the_key() {
        let e = err("seed = 1\n[scanner]\nrange = \"far\"\n");
        assert!(
            e.starts_with("config file c.toml, line 3, `scanner.range`: "),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }

    #[test]
    fn unknown_keys_are_named() {
        let e = err("[children]\ncuont = 3\n");
        assert!(e.contains("line 2") && e.contains("cuont"), "{e}");
    }

    #[test]
    fn syntax_errors_give_a_line() {
        let e = err("[scanner\nrange = 3\n");
        assert!(e.contains("line 1"), "{e}");
    }

    #[test]
    fn keys_set_by_the_file_are_listed() {
        let f = parse_config("seed = 3\n[children]\ncount = 1\n", Path::new("c")).unwrap();
        assert!(f.sets("children.count") && f.sets("seed"));
        assert!(!f.sets("scanner.range"));
        assert_eq!(f.config.children.count, 1);
    }

    #[test]
    fn huge_whole_numbers_are_type_errors_not_panics() {
        let e = err("[children]\ncount = 1e11\n");
        assert!(e.contains("children.count"), "{e}");
        let f = parse_config(
            "[parent]\nmax_samples = 18446744073709551615\n",
            Path::new("c"),
        )
        .unwrap();
        let e = f.config.validate().unwrap_err();
        assert_eq!(e.key(), "parent.max_samples");
    }
}
