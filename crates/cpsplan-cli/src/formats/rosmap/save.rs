//! Saving a grid as a ROS `map_server` map: the PGM image and the YAML beside
//! it, written whole.

use std::fmt::Write as _;
use std::fs;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};

use cpsplan::{CellState, OccupancyGrid};

use super::{
    check_resolution, FormatError, DEFAULT_FREE_THRESH, DEFAULT_OCCUPIED_THRESH, PIXEL_FREE,
    PIXEL_OCCUPIED, PIXEL_UNKNOWN,
};

/// Save a grid as a ROS `map_server` map: `<stem>.pgm` (binary P5; free 254,
/// occupied 0, unknown 205) next to `yaml_path`, and the YAML itself (trinary,
/// thresholds 0.65 / 0.196, `negate: 0`). Loading the result with [`load_map`](super::load_map)
/// gives back an identical grid.
///
/// Both files are written under temporary names in the target directory and then
/// renamed, so a failure leaves no half-written file behind.
pub fn save_map(grid: &OccupancyGrid, yaml_path: &Path) -> Result<(), FormatError> {
    save_map_with_notes(grid, yaml_path, &[])
}

/// A map encoded for [`save_map`]: the YAML, and the image with its path.
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedMap {
    /// The YAML text.
    pub yaml: String,
    /// Where the image goes: beside the YAML, its stem with `.pgm`.
    pub image_path: PathBuf,
    /// The PGM image.
    pub pgm: Vec<u8>,
}

/// The YAML and image [`save_map_with_notes`] writes for `grid` at `yaml_path`.
pub fn encode_map(
    grid: &OccupancyGrid,
    yaml_path: &Path,
    notes: &[String],
) -> Result<EncodedMap, FormatError> {
    let g = grid.geometry();
    if g.is_empty() {
        return Err(FormatError::bad(yaml_path, "grid", "the grid has no cells"));
    }
    check_resolution(g.resolution, yaml_path, "resolution")?;
    if ![g.origin.x, g.origin.y, g.yaw]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(FormatError::bad(yaml_path, "origin", "not finite"));
    }
    let stem = yaml_path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| {
            FormatError::bad(yaml_path, "path", "needs a UTF-8 file name, e.g. map.yaml")
        })?;
    let image_name = format!("{stem}.pgm");
    let image_path = yaml_path.with_file_name(&image_name);
    if image_path == yaml_path {
        return Err(FormatError::bad(
            yaml_path,
            "path",
            "the YAML file must not end in .pgm (the image takes that name)",
        ));
    }

    // The image: P5 header, then rows from the top of the map.
    let (w, h) = (g.width, g.height);
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.reserve(w * h);
    for row in grid.cells().chunks_exact(w).rev() {
        pgm.extend(row.iter().map(|c| match c {
            CellState::Free => PIXEL_FREE,
            CellState::Occupied => PIXEL_OCCUPIED,
            CellState::Unknown => PIXEL_UNKNOWN,
        }));
    }

    // The YAML, by hand. `{:?}` of an f64 is the shortest text that parses back to
    // the same value, and always reads as a float.
    let mut yaml = String::new();
    for note in notes {
        for line in note.lines() {
            let _ = writeln!(yaml, "# {line}");
        }
    }
    let _ = writeln!(yaml, "image: {}", yaml_string(&image_name));
    let _ = writeln!(yaml, "resolution: {:?}", g.resolution);
    let _ = writeln!(
        yaml,
        "origin: [{:?}, {:?}, {:?}]",
        g.origin.x, g.origin.y, g.yaw
    );
    let _ = writeln!(yaml, "negate: 0");
    let _ = writeln!(yaml, "occupied_thresh: {DEFAULT_OCCUPIED_THRESH:?}");
    let _ = writeln!(yaml, "free_thresh: {DEFAULT_FREE_THRESH:?}");
    let _ = writeln!(yaml, "mode: trinary");

    Ok(EncodedMap {
        yaml,
        image_path,
        pgm,
    })
}

/// [`save_map`] with `notes` as comment lines at the top of the YAML (where the
/// map came from, units converted).
pub fn save_map_with_notes(
    grid: &OccupancyGrid,
    yaml_path: &Path,
    notes: &[String],
) -> Result<(), FormatError> {
    let EncodedMap {
        yaml,
        image_path,
        pgm,
    } = encode_map(grid, yaml_path, notes)?;
    let image_tmp = write_temp(&image_path, &pgm)?;
    let yaml_tmp = match write_temp(yaml_path, yaml.as_bytes()) {
        Ok(t) => t,
        Err(e) => {
            let _ = fs::remove_file(&image_tmp);
            return Err(e);
        }
    };
    let commit = fs::rename(&image_tmp, &image_path)
        .map_err(|e| FormatError::io(&image_path, e))
        .and_then(|()| fs::rename(&yaml_tmp, yaml_path).map_err(|e| FormatError::io(yaml_path, e)));
    if commit.is_err() {
        let _ = fs::remove_file(&image_tmp);
        let _ = fs::remove_file(&yaml_tmp);
    }
    commit
}

/// A file name as a YAML scalar: plain when safe, otherwise double-quoted.
fn yaml_string(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | '/'))
        && s.starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_');
    if plain {
        return s.to_string();
    }
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Write `bytes` to a fresh temporary file next to `target`; return its path.
fn write_temp(target: &Path, bytes: &[u8]) -> Result<PathBuf, FormatError> {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = target.parent().unwrap_or(Path::new(""));
    let pid = std::process::id();
    for attempt in 0..100u32 {
        let tmp = dir.join(format!(".{name}.{pid}.{attempt}.tmp"));
        let mut file = match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => f,
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(FormatError::io(target, e)),
        };
        let written = file.write_all(bytes).and_then(|()| file.sync_all());
        drop(file);
        return match written {
            Ok(()) => Ok(tmp),
            Err(e) => {
                let _ = fs::remove_file(&tmp);
                Err(FormatError::io(target, e))
            }
        };
    }
    Err(FormatError::io(
        target,
        io::Error::new(io::ErrorKind::AlreadyExists, "no free temporary file name"),
    ))
}
