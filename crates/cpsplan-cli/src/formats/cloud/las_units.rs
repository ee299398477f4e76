//! The length units of a LAS file's coordinate system, from its GeoTIFF keys
//! (the `LASF_Projection` GeoKeyDirectory VLR, record 34735) or its OGC WKT
//! (record 2112).
//!
//! GeoTIFF keys: `ProjLinearUnitsGeoKey` (3076) for x and y, falling back to
//! `GeogLinearUnitsGeoKey` (2052), and `VerticalUnitsGeoKey` (4099) for z;
//! EPSG unit codes 9001 (metre), 9002 (international foot) and 9003 (US survey
//! foot). WKT: the last linear `UNIT`/`LENGTHUNIT` before the vertical part
//! (`VERT_CS`, `VERTCRS`) for x and y, the last one after it for z, told by
//! its conversion factor.

use las::crs::GeoTiffData;
use las::Header;

use super::LengthUnit;

/// GeoTIFF key: linear units of a projected system.
const PROJ_LINEAR_UNITS: u16 = 3076;
/// GeoTIFF key: linear units of a geographic (geocentric) system.
const GEOG_LINEAR_UNITS: u16 = 2052;
/// GeoTIFF key: vertical units.
const VERTICAL_UNITS: u16 = 4099;

/// The units a LAS file states for its coordinates, where it states them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct FileUnits {
    /// Units of x and y.
    pub horizontal: Option<LengthUnit>,
    /// Units of z.
    pub vertical: Option<LengthUnit>,
}

impl FileUnits {
    /// The units `header`'s coordinate-system records state: GeoTIFF keys
    /// first, WKT for what they leave open.
    pub(crate) fn of(header: &Header) -> Self {
        let keys = header
            .get_geotiff_crs()
            .ok()
            .flatten()
            .map(|crs| {
                let key = |id| {
                    crs.entries.iter().find_map(|e| match e.data {
                        GeoTiffData::U16(code) if e.id == id => epsg_unit(code),
                        _ => None,
                    })
                };
                FileUnits {
                    horizontal: key(PROJ_LINEAR_UNITS).or_else(|| key(GEOG_LINEAR_UNITS)),
                    vertical: key(VERTICAL_UNITS),
                }
            })
            .unwrap_or_default();
        let wkt = header
            .get_wkt_crs_bytes()
            .map(|b| wkt_units(&String::from_utf8_lossy(b)))
            .unwrap_or_default();
        FileUnits {
            horizontal: keys.horizontal.or(wkt.horizontal),
            vertical: keys.vertical.or(wkt.vertical),
        }
    }
}

/// The unit an EPSG unit-of-measure code names, of the three known.
fn epsg_unit(code: u16) -> Option<LengthUnit> {
    match code {
        9001 => Some(LengthUnit::Metre),
        9002 => Some(LengthUnit::Foot),
        9003 => Some(LengthUnit::UsSurveyFoot),
        _ => None,
    }
}

/// The units of a WKT coordinate system.
pub(crate) fn wkt_units(wkt: &str) -> FileUnits {
    let upper = wkt.to_ascii_uppercase();
    let split = ["VERT_CS[", "VERTCRS[", "VERTICALCRS["]
        .iter()
        .filter_map(|k| upper.find(k))
        .min()
        .unwrap_or(upper.len());
    FileUnits {
        horizontal: last_linear_unit(&wkt[..split]),
        vertical: last_linear_unit(&wkt[split..]),
    }
}

/// The last `UNIT["name", factor ...]` of `wkt` whose factor is one of the
/// known length units.
fn last_linear_unit(wkt: &str) -> Option<LengthUnit> {
    let upper = wkt.to_ascii_uppercase();
    let mut found = None;
    let mut from = 0;
    while let Some(at) = upper[from..].find("UNIT[") {
        let start = from + at + "UNIT[".len();
        from = start;
        let rest = &wkt[start..];
        // Skip the quoted name, then read the factor.
        let Some(name_end) = rest.strip_prefix('"').and_then(|r| r.find('"')) else {
            continue;
        };
        let after = rest[name_end + 2..].trim_start();
        let Some(after) = after.strip_prefix(',') else {
            continue;
        };
        let number: String = after
            .trim_start()
            .chars()
            .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '-' | '+'))
            .collect();
        if let Ok(factor) = number.parse::<f64>() {
            if let Some(unit) = unit_of_factor(factor) {
                found = Some(unit);
            }
        }
    }
    found
}

/// The known unit whose metres-per-unit is `factor` (to 1 part in 10^9).
fn unit_of_factor(factor: f64) -> Option<LengthUnit> {
    [
        LengthUnit::Metre,
        LengthUnit::Foot,
        LengthUnit::UsSurveyFoot,
    ]
    .into_iter()
    .find(|u| ((factor - u.factor()) / u.factor()).abs() < 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wkt1_compound_systems_give_both_units() {
        let wkt = r#"COMPD_CS["NAD83 / Oregon GIC Lambert (ft) + NAVD88 height (ftUS)",PROJCS["NAD83 / Oregon GIC Lambert (ft)",GEOGCS["NAD83",DATUM["North_American_Datum_1983",SPHEROID["GRS 1980",6378137,298.257222101]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Lambert_Conformal_Conic_2SP"],UNIT["foot",0.3048,AUTHORITY["EPSG","9002"]]],VERT_CS["NAVD88 height (ftUS)",VERT_DATUM["North American Vertical Datum 1988",2005],UNIT["US survey foot",0.304800609601219,AUTHORITY["EPSG","9003"]]]]"#;
        assert_eq!(
            wkt_units(wkt),
            FileUnits {
                horizontal: Some(LengthUnit::Foot),
                vertical: Some(LengthUnit::UsSurveyFoot)
            }
        );
    }

    #[test]
    fn wkt2_and_metre_systems() {
        let wkt = r#"PROJCRS["WGS 84 / UTM zone 54N",BASEGEOGCRS["WGS 84",ANGLEUNIT["degree",0.0174532925199433]],CS[Cartesian,2],LENGTHUNIT["metre",1]]"#;
        assert_eq!(
            wkt_units(wkt),
            FileUnits {
                horizontal: Some(LengthUnit::Metre),
                vertical: None
            }
        );
        assert_eq!(wkt_units("garbage UNIT[ UNIT[\"x\""), FileUnits::default());
        assert_eq!(wkt_units(""), FileUnits::default());
    }

    #[test]
    fn epsg_codes() {
        assert_eq!(epsg_unit(9002), Some(LengthUnit::Foot));
        assert_eq!(epsg_unit(9003), Some(LengthUnit::UsSurveyFoot));
        assert_eq!(epsg_unit(9001), Some(LengthUnit::Metre));
        assert_eq!(epsg_unit(9004), None);
    }
}
