//! Total-station readings as CSV (docs/USER-GUIDE.md "Readings"): one reading
//! per row, under a header that names the columns and states their units in
//! the names. Lines starting with `#` are comments; other columns (time, code,
//! prism constant, as exports carry) are ignored.
//!
//! - `station`, `point`: the set-up and the point measured (letters, digits and
//!   `.`, `_`, `-`, `:`; at most 64 characters);
//! - the slope distance: `slope_distance_m` or `slope_distance_mm`;
//! - the horizontal direction, clockwise: `hz_direction_gon`, `_deg` or `_rad`;
//! - the zenith angle, face I (0 up, level at 100 gon): `zenith_angle_gon`,
//!   `_deg` or `_rad`.
//!
//! ```text
//! station,point,slope_distance_m,hz_direction_gon,zenith_angle_gon
//! S0002,C1.0003,12.3456,123.45678,100.01234
//! S0002,T1,31.0021,301.00012,99.98765
//! ```

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use cpsplan::accuracy::{Reading, MAX_NAME};

use super::config::one_line;
use super::rosmap::read_text;

/// The longest slope distance accepted, metres (ten times any instrument's range).
pub const MAX_DISTANCE_M: f64 = 20_000.0;

/// The header [`write_readings`] writes.
pub const HEADER: &str = "station,point,slope_distance_m,hz_direction_gon,zenith_angle_gon";

/// Why a readings file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadingsError {
    /// The file could not be read.
    #[error(transparent)]
    Read(#[from] super::rosmap::FormatError),
    /// A header or row is malformed.
    #[error("readings file {}{}: {message}", path.display(), line.map(|l| format!(", line {l}")).unwrap_or_default())]
    Bad {
        /// The file.
        path: PathBuf,
        /// The line, from 1.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
}

/// An angle's unit, named by a column's suffix.
#[derive(Debug, Clone, Copy, PartialEq)]
enum AngleUnit {
    Gon,
    Deg,
    Rad,
}

impl AngleUnit {
    fn to_rad(self, v: f64) -> f64 {
        match self {
            AngleUnit::Gon => v * PI / 200.0,
            AngleUnit::Deg => v.to_radians(),
            AngleUnit::Rad => v,
        }
    }
}

/// Which column holds a quantity, and its unit's factor (to metres or radians).
#[derive(Debug, Clone, Copy)]
struct Column<U> {
    index: usize,
    unit: U,
}

/// Reads a readings file of at most `max_bytes` bytes.
pub fn read_readings(path: &Path, max_bytes: u64) -> Result<Vec<Reading>, ReadingsError> {
    let text = read_text(path, max_bytes)?;
    parse_readings(&text, path)
}

/// Parses readings CSV text; `path` names it in messages.
pub fn parse_readings(text: &str, path: &Path) -> Result<Vec<Reading>, ReadingsError> {
    let bad = |line: Option<usize>, message: String| ReadingsError::Bad {
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
    let names: Vec<String> = header.iter().map(str::to_ascii_lowercase).collect();
    let find = |name: &str| names.iter().position(|h| h == name);
    // Exactly one column for each quantity, whatever its unit.
    let one = |quantity: &str, units: &[&str]| -> Result<(usize, usize), ReadingsError> {
        let found: Vec<(usize, usize)> = units
            .iter()
            .enumerate()
            .filter_map(|(u, suffix)| find(&format!("{quantity}_{suffix}")).map(|c| (c, u)))
            .collect();
        let spelled = units
            .iter()
            .map(|u| format!("{quantity}_{u}"))
            .collect::<Vec<_>>()
            .join(" or ");
        match found.as_slice() {
            [one] => Ok(*one),
            [] => Err(bad(Some(1), format!("the header needs a column {spelled}"))),
            _ => Err(bad(
                Some(1),
                format!("the header has more than one of {spelled}"),
            )),
        }
    };
    let (Some(cstation), Some(cpoint)) = (find("station"), find("point")) else {
        return Err(bad(
            Some(1),
            "the header must name the columns station and point".into(),
        ));
    };
    let distance = {
        let (index, u) = one("slope_distance", &["m", "mm"])?;
        Column {
            index,
            unit: [1.0, 1e-3][u],
        }
    };
    let angle = |quantity: &str| -> Result<Column<AngleUnit>, ReadingsError> {
        let (index, u) = one(quantity, &["gon", "deg", "rad"])?;
        Ok(Column {
            index,
            unit: [AngleUnit::Gon, AngleUnit::Deg, AngleUnit::Rad][u],
        })
    };
    let (hz, zenith) = (angle("hz_direction")?, angle("zenith_angle")?);
    let mut out = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map(|p| p.line() as usize);
            bad(line, one_line(&e.to_string()))
        })?;
        let line = record.position().map(|p| p.line() as usize);
        let field = |c: usize| record.get(c).unwrap_or("");
        let name = |c: usize, what: &str| -> Result<String, ReadingsError> {
            let s = field(c);
            if Reading::valid_name(s) {
                Ok(s.to_string())
            } else {
                Err(bad(
                    line,
                    format!(
                        "`{what}` = `{s}`: a name of 1 to {MAX_NAME} letters, digits, `.`, `_`, `-` or `:`"
                    ),
                ))
            }
        };
        let number = |c: usize| -> Result<f64, ReadingsError> {
            let s = field(c);
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(bad(
                    line,
                    format!("`{}` = `{s}` is not a finite number", &header[c]),
                )),
            }
        };
        let slope = number(distance.index)? * distance.unit;
        if !(slope > 0.0 && slope <= MAX_DISTANCE_M) {
            return Err(bad(
                line,
                format!(
                    "slope distance {slope} m: expected more than 0 and at most {MAX_DISTANCE_M} m"
                ),
            ));
        }
        let z = zenith.unit.to_rad(number(zenith.index)?);
        if !(z > 0.0 && z < PI) {
            return Err(bad(
                line,
                format!(
                    "zenith angle `{}`: expected between 0 and 200 gon (face I; reduce face II readings first)",
                    field(zenith.index)
                ),
            ));
        }
        out.push(Reading {
            station: name(cstation, "station")?,
            point: name(cpoint, "point")?,
            slope_distance_m: slope,
            hz_rad: hz.unit.to_rad(number(hz.index)?).rem_euclid(TAU),
            zenith_rad: z,
        });
    }
    Ok(out)
}

/// The readings as CSV under [`HEADER`] (metres and gon, every digit kept).
pub fn write_readings(readings: &[Reading]) -> String {
    let gon = |rad: f64| rad * 200.0 / PI;
    let mut out = String::with_capacity(64 * (readings.len() + 1));
    out.push_str(HEADER);
    out.push('\n');
    for r in readings {
        // Writing to a String cannot fail.
        let _ = writeln!(
            out,
            "{},{},{},{},{}",
            r.station,
            r.point,
            r.slope_distance_m,
            gon(r.hz_rad),
            gon(r.zenith_rad)
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse(text: &str) -> Result<Vec<Reading>, ReadingsError> {
        parse_readings(text, Path::new("r.csv"))
    }

    #[test]
    fn reads_the_units_the_header_states() {
        let text = "# S2 after the move\nstation,point,slope_distance_mm,hz_direction_deg,zenith_angle_gon,time\nS0002,C1.0003,12345.6,90,100,12:00:01\nS0002,T1, 31.5 ,-90,50,12:00:20\n";
        let r = parse(text).unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(
            (r[0].station.as_str(), r[0].point.as_str()),
            ("S0002", "C1.0003")
        );
        assert!((r[0].slope_distance_m - 12.3456).abs() < 1e-12);
        assert!((r[0].hz_rad - PI / 2.0).abs() < 1e-12);
        assert!((r[0].zenith_rad - PI / 2.0).abs() < 1e-12);
        // Hz is taken modulo a full turn.
        assert!((r[1].hz_rad - 1.5 * PI).abs() < 1e-12);
        assert!((r[1].zenith_rad - PI / 4.0).abs() < 1e-12);
    }

    #[test]
    fn problems_name_the_line() {
        let head = "station,point,slope_distance_m,hz_direction_gon,zenith_angle_gon\n";
        let err = |text: &str| parse(text).unwrap_err().to_string();
        let e = err(&format!("{head}S1,C1.1,10,0,100\nS1,C2.1,abc,0,100\n"));
        assert!(
            e.contains("line 3") && e.contains("`slope_distance_m` = `abc`"),
            "{e}"
        );
        let e = err(&format!("{head}S1,C1.1,-1,0,100\n"));
        assert!(e.contains("line 2") && e.contains("slope distance"), "{e}");
        let e = err(&format!("{head}S1,C1.1,10,0,250\n"));
        assert!(e.contains("face I"), "{e}");
        let e = err(&format!("{head}S1,C 1,10,0,100\n"));
        assert!(e.contains("`point` = `C 1`"), "{e}");
        let e = err(&format!("{head}S1,,10,0,100\n"));
        assert!(e.contains("`point` = ``"), "{e}");
        let e = err("station,point,slope_distance_m,hz_direction_gon\nS1,C1,1,2\n");
        assert!(
            e.contains("zenith_angle_gon or zenith_angle_deg or zenith_angle_rad"),
            "{e}"
        );
        let e = err(
            "station,point,slope_distance_m,slope_distance_mm,hz_direction_gon,zenith_angle_gon\n",
        );
        assert!(e.contains("more than one of slope_distance_m"), "{e}");
        let e = err("point,slope_distance_m,hz_direction_gon,zenith_angle_gon\n");
        assert!(e.contains("station and point"), "{e}");
        let e = err(&format!("{head}S1,C1.1,10,0\n"));
        assert!(e.contains("line 2"), "{e}");
        let e = err(&format!("{head}S1,C1.1,10,NaN,100\n"));
        assert!(e.contains("not a finite number"), "{e}");
    }

    #[test]
    fn an_empty_file_has_no_readings_but_needs_its_header() {
        assert!(
            parse("station,point,slope_distance_m,hz_direction_gon,zenith_angle_gon\n")
                .unwrap()
                .is_empty()
        );
        assert!(parse("").is_err());
    }

    proptest! {
        /// What is written reads back as it was.
        #[test]
        fn written_readings_read_back(
            rows in proptest::collection::vec(
                ("[A-Za-z0-9._:-]{1,12}", "[A-Za-z0-9._:-]{1,12}", 0.001f64..5_000.0, 0.0f64..TAU, 0.001f64..(PI - 0.001)),
                0..40,
            )
        ) {
            let readings: Vec<Reading> = rows
                .into_iter()
                .map(|(station, point, slope_distance_m, hz_rad, zenith_rad)| Reading {
                    station,
                    point,
                    slope_distance_m,
                    hz_rad,
                    zenith_rad,
                })
                .collect();
            let back = parse(&write_readings(&readings)).unwrap();
            prop_assert_eq!(back.len(), readings.len());
            for (a, b) in readings.iter().zip(&back) {
                prop_assert_eq!(&a.station, &b.station);
                prop_assert_eq!(&a.point, &b.point);
                prop_assert_eq!(a.slope_distance_m, b.slope_distance_m);
                let turn = (a.hz_rad - b.hz_rad).rem_euclid(TAU);
                prop_assert!(turn.min(TAU - turn) < 1e-12);
                prop_assert!((a.zenith_rad - b.zenith_rad).abs() < 1e-12);
            }
        }
    }
}
