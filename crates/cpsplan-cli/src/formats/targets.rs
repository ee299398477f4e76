//! Targets and control points as CSV (`--targets FILE.csv`; docs/USER-GUIDE.md
//! "Targets and control points"): one point per row under a header naming the
//! columns `name`, `x`, `y` (metres, world frame), and optionally `z`, `kind`
//! (`control` or `free`, the default) and `sigma_mm` (a control point's
//! standard deviation of each coordinate). Lines starting with `#` are
//! comments.
//!
//! ```text
//! name,x,y,kind,sigma_mm
//! GNSS-1,12.40,-3.75,control,15
//! GNSS-2,88.10,41.20,control,15
//! T1,40.0,10.5,free,
//! ```

use std::path::{Path, PathBuf};

use cpsplan::config::{TargetKind, TargetSpec};

use super::rosmap::read_text;

/// Why a targets file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TargetsError {
    /// The file could not be read.
    #[error(transparent)]
    Read(#[from] super::rosmap::FormatError),
    /// A header or row is malformed.
    #[error("targets file {}{}: {message}", path.display(), line.map(|l| format!(", line {l}")).unwrap_or_default())]
    Bad {
        /// The file.
        path: PathBuf,
        /// The line, from 1.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
}

/// Reads a targets file of at most `max_bytes` bytes.
pub fn read_targets(path: &Path, max_bytes: u64) -> Result<Vec<TargetSpec>, TargetsError> {
    let text = read_text(path, max_bytes)?;
    parse_targets(&text, path)
}

/// Parses targets CSV text; `path` names it in messages.
pub fn parse_targets(text: &str, path: &Path) -> Result<Vec<TargetSpec>, TargetsError> {
    let bad = |line: Option<usize>, message: String| TargetsError::Bad {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(false)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| bad(Some(1), one_line(&e.to_string())))?
        .clone();
    let column = |name: &str| header.iter().position(|h| h.eq_ignore_ascii_case(name));
    for h in header.iter() {
        if !["name", "x", "y", "z", "kind", "sigma_mm"]
            .iter()
            .any(|k| h.eq_ignore_ascii_case(k))
        {
            return Err(bad(
                Some(1),
                format!("unknown column `{h}` (the columns are name, x, y, z, kind, sigma_mm)"),
            ));
        }
    }
    let (Some(cx), Some(cy)) = (column("x"), column("y")) else {
        return Err(bad(
            Some(1),
            "the header must name the columns x and y".into(),
        ));
    };
    let (cname, cz, ckind, csigma) = (
        column("name"),
        column("z"),
        column("kind"),
        column("sigma_mm"),
    );
    let mut out = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map(|p| p.line() as usize);
            bad(line, one_line(&e.to_string()))
        })?;
        let line = record.position().map(|p| p.line() as usize);
        let field = |c: Option<usize>| c.and_then(|c| record.get(c)).filter(|s| !s.is_empty());
        let number = |c: Option<usize>, name: &str| -> Result<Option<f64>, TargetsError> {
            match field(c) {
                None => Ok(None),
                Some(s) => match s.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(Some(v)),
                    _ => Err(bad(
                        line,
                        format!("`{name}` = `{s}` is not a finite number"),
                    )),
                },
            }
        };
        let x = number(Some(cx), "x")?.ok_or_else(|| bad(line, "`x` is missing".into()))?;
        let y = number(Some(cy), "y")?.ok_or_else(|| bad(line, "`y` is missing".into()))?;
        let kind = match field(ckind) {
            None => TargetKind::Free,
            Some(k) if k.eq_ignore_ascii_case("control") => TargetKind::Control,
            Some(k) if k.eq_ignore_ascii_case("free") => TargetKind::Free,
            Some(k) => {
                return Err(bad(
                    line,
                    format!("`kind` = `{k}`: expected `control` or `free`"),
                ))
            }
        };
        out.push(TargetSpec {
            name: field(cname).map(str::to_string),
            x,
            y,
            z: number(cz, "z")?,
            kind,
            sigma_mm: number(csigma, "sigma_mm")?,
        });
    }
    Ok(out)
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_control_points_and_free_targets() {
        let text = "# site control\nname,x,y,kind,sigma_mm\nG1,12.4,-3.75,control,15\nT1, 40 ,10.5,free,\n,1,2,,\n";
        let t = parse_targets(text, Path::new("t.csv")).unwrap();
        assert_eq!(t.len(), 3);
        assert_eq!(t[0].name.as_deref(), Some("G1"));
        assert_eq!(
            (t[0].kind, t[0].sigma_mm),
            (TargetKind::Control, Some(15.0))
        );
        assert_eq!(
            (t[1].x, t[1].kind, t[1].sigma_mm),
            (40.0, TargetKind::Free, None)
        );
        assert_eq!(t[2].name, None);
    }

    #[test]
    fn problems_name_the_line() {
        let e = parse_targets("x,y\n1,2\n3,abc\n", Path::new("t.csv")).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("line 3") && m.contains("`y` = `abc`"), "{m}");
        let e = parse_targets("x,y,colour\n1,2,red\n", Path::new("t.csv")).unwrap_err();
        assert!(e.to_string().contains("unknown column `colour`"));
        let e = parse_targets("name,x\nA,1\n", Path::new("t.csv")).unwrap_err();
        assert!(e.to_string().contains("x and y"));
        let e = parse_targets("x,y,kind\n1,2,prism\n", Path::new("t.csv")).unwrap_err();
        assert!(e.to_string().contains("`control` or `free`"));
        let e = parse_targets("x,y\n1,2,3\n", Path::new("t.csv")).unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
    }
}
