//! The value parsers and help texts the commands' arguments share: each
//! command's argument type lives in its own module under [`crate::commands`].

use cpsplan::config::{ChildStrategy, InstrumentModel, Planner, Preset, Scoring};
use cpsplan::{Config, Point};

use crate::formats::cloud::LengthUnit;

/// The default configuration, for the defaults shown in `--help`.
pub(crate) fn defaults() -> Config {
    Config::default()
}

/// A flag's help line with its default value.
pub(crate) fn with_default(help: &str, default: impl std::fmt::Display) -> String {
    format!("{help} [default: {default}]")
}

pub(crate) fn scoring_name(s: Scoring) -> &'static str {
    match s {
        Scoring::Normalized => "normalized",
        Scoring::Literal => "literal",
    }
}

/// A finite number (ranges are checked with the whole configuration).
pub(crate) fn parse_real(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err("expected a finite number".to_string()),
        Err(_) => Err("expected a number".to_string()),
    }
}

/// A whole number, 0 or more.
pub(crate) fn parse_count(s: &str) -> Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| "expected a whole number, 0 or more".to_string())
}

/// A seed: a whole number from 0 to 2^64 - 1.
pub(crate) fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse::<u64>()
        .map_err(|_| "expected a whole number from 0 to 18446744073709551615".to_string())
}

/// `X,Y` in metres.
pub(crate) fn parse_point(s: &str) -> Result<Point, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y] = parts.as_slice() else {
        return Err(format!("expected X,Y in metres, got `{s}`"));
    };
    let num = |t: &str| {
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{t}` is not a number in `{s}`"))
    };
    Ok(Point::new(num(x)?, num(y)?))
}

/// Numbers separated by commas, each finite.
pub(crate) fn parse_list(s: &str, n: usize, what: &str) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != n {
        return Err(format!("expected {what}, got `{s}`"));
    }
    parts
        .iter()
        .map(|t| {
            t.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("`{t}` is not a number in `{s}`"))
        })
        .collect()
}

/// `LOW,HIGH` heights in metres, `LOW < HIGH`.
pub(crate) fn parse_wall_band(s: &str) -> Result<[f64; 2], String> {
    let v = parse_list(s, 2, "LOW,HIGH in metres")?;
    if v[0] >= v[1] {
        return Err(format!("`{s}`: LOW must be below HIGH"));
    }
    Ok([v[0], v[1]])
}

pub(crate) fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let v = parse_list(s, 2, "LO,HI in metres")?;
    Ok((v[0], v[1]))
}

pub(crate) fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let v = parse_list(s, 3, "X,Y,Z in metres")?;
    Ok([v[0], v[1], v[2]])
}

/// TX,TY,YAW: metres, metres, radians (or degrees with a `deg` suffix).
pub(crate) fn parse_transform(s: &str) -> Result<(f64, f64, f64), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [tx, ty, yaw] = parts.as_slice() else {
        return Err(format!(
            "expected TX,TY,YAW (metres, metres, radians), got `{s}`"
        ));
    };
    let num = |t: &str| {
        t.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("`{t}` is not a number in `{s}`"))
    };
    let yaw = match yaw
        .strip_suffix("deg")
        .or_else(|| yaw.strip_suffix('\u{b0}'))
    {
        Some(d) => num(d.trim())?.to_radians(),
        None => num(yaw)?,
    };
    Ok((num(tx)?, num(ty)?, yaw))
}

pub(crate) fn parse_unit(s: &str) -> Result<LengthUnit, String> {
    LengthUnit::parse(s.trim()).ok_or_else(|| format!("unknown unit `{s}` (one of: m, ft, us-ft)"))
}

pub(crate) fn parse_instrument(s: &str) -> Result<InstrumentModel, String> {
    InstrumentModel::ALL
        .into_iter()
        .find(|m| m.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = InstrumentModel::ALL.iter().map(|m| m.name()).collect();
            format!("unknown instrument `{s}` (one of: {})", names.join(", "))
        })
}

pub(crate) fn parse_strategy(s: &str) -> Result<ChildStrategy, String> {
    ChildStrategy::ALL
        .into_iter()
        .find(|m| m.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = ChildStrategy::ALL.iter().map(|m| m.name()).collect();
            format!(
                "unknown child strategy `{s}` (one of: {})",
                names.join(", ")
            )
        })
}

pub(crate) fn parse_preset(s: &str) -> Result<Preset, String> {
    Preset::ALL
        .into_iter()
        .find(|p| p.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = Preset::ALL.iter().map(|p| p.name()).collect();
            format!("unknown preset `{s}` (one of: {})", names.join(", "))
        })
}

pub(crate) fn parse_planner(s: &str) -> Result<Planner, String> {
    Planner::ALL
        .into_iter()
        .find(|p| p.name() == s.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = Planner::ALL.iter().map(|p| p.name()).collect();
            format!("unknown planner `{s}` (one of: {})", names.join(", "))
        })
}

pub(crate) fn parse_scan_number(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("expected a scan number (1, 2, ...), got `{s}`")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_with_signs_and_spaces() {
        assert_eq!(parse_point("1.5,-2").unwrap(), Point::new(1.5, -2.0));
        assert_eq!(parse_point(" 3 , 4 ").unwrap(), Point::new(3.0, 4.0));
        assert!(parse_point("1").is_err());
        assert!(parse_point("1,2,3").is_err());
        assert!(parse_point("a,2").is_err());
        assert!(parse_point("nan,2").is_err());
    }
}
