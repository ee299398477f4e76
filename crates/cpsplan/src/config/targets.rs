//! Fixed targets and control points (beyond the paper; docs/ACCURACY.md
//! "Closed networks"): points that every parent station in sight measures, so
//! that the CPS chain closes into a network.
//!
//! In a TOML file the list is `[[targets]]` (one table per point). The team's own
//! targets are set by `[targets]` with `place = "auto"` and `max = N`; TOML cannot
//! hold `[[targets]]` and `[targets]` in one file, so a file that wants both gives
//! the points as `[[targets.points]]` under the `[targets]` table.

use std::fmt;

use serde::de::{self, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::bounds::{number, ConfigError, MAX_COORDINATE_M};

/// Most targets and control points of one run, given and placed together: every
/// target a station has measured stays in the filter's dense state, whose cost
/// grows with the cube of their number (docs/PERFORMANCE.md).
pub const MAX_TARGETS: usize = 200;

/// Whether a point's coordinates are known before the campaign.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TargetKind {
    /// A control point: known coordinates (GNSS, an existing site network) with
    /// a standard deviation per coordinate.
    Control,
    /// A free target: set up at a given place before the campaign, its
    /// coordinates unknown until a station measures it.
    #[default]
    Free,
}

impl TargetKind {
    /// The name in configuration files and records.
    pub fn name(self) -> &'static str {
        match self {
            TargetKind::Control => "control",
            TargetKind::Free => "free",
        }
    }
}

/// One target or control point given before the campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSpec {
    /// Its name in records and pictures (`T1`, `T2`, ... when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Easting, world frame, metres.
    pub x: f64,
    /// Northing, world frame, metres.
    pub y: f64,
    /// Height over the floor, metres (3D mode; the markers' height when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    /// Control point or free target.
    #[serde(default)]
    pub kind: TargetKind,
    /// A control point's standard deviation of each coordinate, mm (required for
    /// control points, ignored for free targets).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_mm: Option<f64>,
}

/// Where the team leaves targets of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TargetPlacement {
    /// Never (the default).
    #[default]
    None,
    /// A child leaves one of the `max` targets the team carries where the
    /// planner judges it worth it (`mission::targets` says when and why).
    Auto,
}

/// Targets and control points: those given before the campaign, and the team's
/// own (`--place-targets N`).
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct TargetsConfig {
    /// Whether the team leaves targets of its own.
    pub place: TargetPlacement,
    /// How many targets the team carries.
    pub max: usize,
    /// The targets and control points set up before the campaign.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<TargetSpec>,
}

impl TargetsConfig {
    /// Whether the run has no target at all (none given, none to place).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty() && self.team_targets() == 0
    }

    /// Whether the section is the default one (nothing given, nothing to place).
    pub fn is_unset(&self) -> bool {
        *self == TargetsConfig::default()
    }

    /// How many targets the team may leave.
    pub fn team_targets(&self) -> usize {
        match self.place {
            TargetPlacement::None => 0,
            TargetPlacement::Auto => self.max,
        }
    }

    /// Checks every given point (finite coordinates within
    /// [`MAX_COORDINATE_M`], a control point's σ, distinct names) and the number
    /// of targets against [`MAX_TARGETS`].
    pub fn check(&self) -> Result<(), ConfigError> {
        let err = |what: String| {
            Err(ConfigError::Target {
                key: "targets",
                what,
            })
        };
        if self.place == TargetPlacement::Auto && self.max == 0 {
            return err("`targets.place` = \"auto\" needs `targets.max` (how many targets the team carries) of at least 1".into());
        }
        let total = self.points.len().saturating_add(self.team_targets());
        if total > MAX_TARGETS {
            return err(format!(
                "{} targets given and {} to place: at most {MAX_TARGETS} in all",
                self.points.len(),
                self.team_targets()
            ));
        }
        let mut names = std::collections::BTreeSet::new();
        for (i, p) in self.points.iter().enumerate() {
            let name = self.name_of(i);
            let coords = [Some(p.x), Some(p.y), p.z];
            if coords
                .iter()
                .flatten()
                .any(|v| !(v.is_finite() && v.abs() <= MAX_COORDINATE_M))
            {
                return err(format!(
                    "target `{name}`: coordinates must be finite numbers within {} m of the origin",
                    number(MAX_COORDINATE_M)
                ));
            }
            match (p.kind, p.sigma_mm) {
                (TargetKind::Control, None) => {
                    return err(format!(
                        "control point `{name}` needs `sigma_mm`, the standard deviation of its coordinates"
                    ))
                }
                (TargetKind::Control, Some(s)) if !(s.is_finite() && (0.001..=1e7).contains(&s)) => {
                    return err(format!(
                        "control point `{name}`: `sigma_mm` must be a number from 0.001 to 10000000 mm (got {})",
                        number(s)
                    ))
                }
                _ => {}
            }
            if !names.insert(name.clone()) {
                return err(format!("two targets are named `{name}`"));
            }
        }
        Ok(())
    }

    /// The name of given point `i`: its own, or `T{i+1}`.
    pub fn name_of(&self, i: usize) -> String {
        self.points
            .get(i)
            .and_then(|p| p.name.clone())
            .unwrap_or_else(|| format!("T{}", i + 1))
    }
}

/// The `[targets]` table form.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Table {
    #[serde(default)]
    place: TargetPlacement,
    #[serde(default)]
    max: usize,
    #[serde(default)]
    points: Vec<TargetSpec>,
}

impl<'de> Deserialize<'de> for TargetsConfig {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Either;
        impl<'de> Visitor<'de> for Either {
            type Value = TargetsConfig;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a list of targets ([[targets]]) or a [targets] table")
            }

            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
                let points =
                    Vec::<TargetSpec>::deserialize(de::value::SeqAccessDeserializer::new(seq))?;
                Ok(TargetsConfig {
                    points,
                    ..TargetsConfig::default()
                })
            }

            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let t = Table::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(TargetsConfig {
                    place: t.place,
                    max: t.max,
                    points: t.points,
                })
            }
        }
        d.deserialize_any(Either)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_list_or_a_table() {
        let list: TargetsConfig =
            serde_json::from_str(r#"[{"x": 1, "y": 2, "kind": "control", "sigma_mm": 5}]"#)
                .unwrap();
        assert_eq!(list.points.len(), 1);
        assert_eq!(list.points[0].kind, TargetKind::Control);
        assert_eq!(list.place, TargetPlacement::None);
        let table: TargetsConfig = serde_json::from_str(
            r#"{"place": "auto", "max": 30, "points": [{"name": "A", "x": 0, "y": 0}]}"#,
        )
        .unwrap();
        assert_eq!((table.place, table.max), (TargetPlacement::Auto, 30));
        assert_eq!(table.name_of(0), "A");
        assert_eq!(table.name_of(1), "T2");
        assert_eq!(table.team_targets(), 30);
        let back: TargetsConfig =
            serde_json::from_str(&serde_json::to_string(&table).unwrap()).unwrap();
        assert_eq!(back, table);
        assert!(serde_json::from_str::<TargetsConfig>(r#"{"plac": "auto"}"#).is_err());
        assert!(serde_json::from_str::<TargetsConfig>(r#"[{"x": 1}]"#).is_err());
        assert!(serde_json::from_str::<TargetsConfig>("3").is_err());
    }
}
