//! LAS and LAZ files, through the `las` crate (LAZ by its `laz` feature).
//!
//! Before the crate reads a file, its header is checked for what the crate
//! takes on trust (gadomski/las-rs#149): the point count against
//! `limits.max_cloud_points` and, for uncompressed points, against the file's
//! length (a short file is reported as truncated with the points it does
//! hold); the extended VLR's length against the file (the crate allocates it
//! whole); sizes that overflow. Compressed data is checked by `laz_check`.
//! Coordinates are converted to metres from the units the file states
//! (`las_units`), or those of `--units`.

use std::io::{Read, Seek, SeekFrom};

use las::{PointData, PointDataBuilder, Reader};

use super::collect::{check_claim, Collector};
use super::frame::SourceCrs;
use super::las_units::FileUnits;
use super::laz_check::{Patched, Table};
use super::{
    laz_check, one_line, Cloud, CloudFormat, CloudProblem, CloudReadOptions, LengthUnit, Source,
};

/// Points decoded per batch.
const BATCH: u64 = 1 << 16;

/// Bytes of an extended VLR's header.
const EVLR_HEADER: u64 = 60;

/// Bytes of a VLR's header.
const VLR_HEADER: u64 = 54;

/// Reads a LAS or LAZ file (which one is told by its header, whatever the
/// extension said).
pub(crate) fn read<S: Source>(
    source: &S,
    expected: CloudFormat,
    options: &CloudReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Cloud, CloudProblem> {
    let len = source.len();
    let mut r = source.open().map_err(io)?;
    let raw = las::raw::Header::read_from(&mut r).map_err(|e| header_problem(expected, e))?;
    // Where the VLRs start: the crate reads them after the header's fields,
    // whatever size the header claims.
    let vlrs_start = r.stream_position().map_err(io)?;
    let format = if raw.point_data_record_format & 0x80 != 0 {
        CloudFormat::Laz
    } else {
        CloudFormat::Las
    };
    let points = check_raw(&mut r, &raw, format, len, options)?;
    r.seek(SeekFrom::Start(0)).map_err(io)?;
    let header = las::Header::new(&mut r).map_err(|e| header_problem(format, e))?;
    if header.number_of_points() != points {
        return Err(malformed(format, "inconsistent point counts"));
    }
    check_transforms(&header, format)?;
    let data_start = u64::from(raw.offset_to_point_data);
    check_vlrs_end(&header, format, vlrs_start, data_start)?;
    let mut patch = None;
    if format == CloudFormat::Laz {
        let vlr = header.laz_vlr().map_err(|e| malformed(format, e))?;
        let compressor = header
            .vlrs()
            .iter()
            .find(|v| las::laz::is_laszip_vlr(v))
            .and_then(|v| v.data.get(..2))
            .map_or(0, |b| u16::from_le_bytes([b[0], b[1]]));
        let table = laz_check::check(
            &mut r,
            &vlr,
            compressor,
            points,
            raw.point_data_record_length,
            data_start,
            len,
        )?;
        if table == Table::Missing {
            patch = Some(data_start);
        }
    }
    let (factors, notes) = conversion(FileUnits::of(&header), options.units);
    let crs = SourceCrs::of(
        header.vlrs().iter().chain(header.evlrs()),
        header.has_wkt_crs(),
    );
    drop(r);
    let open = || open_reader(source, patch);

    let mut collector = Collector::new(options, progress, points)?;
    for note in notes {
        collector.note(note);
    }
    let mut reader = open().map_err(|e| {
        if eof(&e) {
            truncated(points, 0)
        } else {
            malformed(format, e)
        }
    })?;
    let mut batch = PointDataBuilder::new().for_header(reader.header()).build();
    while collector.seen() < points {
        let before = collector.seen();
        let n = match reader.fill_points(BATCH.min(points - before), &mut batch) {
            Ok(0) => return Err(truncated(points, before)),
            Ok(n) => n,
            Err(e) if eof(&e) => {
                let found = decodable(&open, before).unwrap_or(before);
                return Err(truncated(points, found));
            }
            Err(e) => return Err(malformed(format, e)),
        };
        let xs = batch.x();
        let ys = batch.y();
        let zs = batch.z();
        for ((x, y), z) in xs.zip(ys).zip(zs).take(n as usize) {
            collector.push([x * factors[0], y * factors[0], z * factors[1]])?;
        }
    }
    collector.end_scan(None);
    let mut cloud = collector.finish(format)?;
    cloud.metres_per_unit = factors;
    cloud.crs = crs;
    Ok(cloud)
}

/// Checks the raw header's sizes against the file and the limits; the point
/// count.
fn check_raw<R: Read + Seek>(
    r: &mut R,
    raw: &las::raw::Header,
    format: CloudFormat,
    len: u64,
    options: &CloudReadOptions,
) -> Result<u64, CloudProblem> {
    let legacy = u64::from(raw.number_of_point_records);
    let points = match raw.large_file {
        Some(large) if legacy == 0 => large.number_of_point_records,
        _ => legacy,
    };
    if points == 0 {
        return Err(CloudProblem::Empty);
    }
    check_claim(points, options)?;
    let record = u64::from(raw.point_data_record_length);
    let start = u64::from(raw.offset_to_point_data);
    let end = points
        .checked_mul(record)
        .and_then(|bytes| bytes.checked_add(start))
        .ok_or_else(|| malformed(format, "the point data's size overflows"))?;
    if format == CloudFormat::Las && end > len {
        let found = len.saturating_sub(start).checked_div(record).unwrap_or(0);
        return Err(truncated(points, found));
    }
    if let Some(evlr) = raw.evlr {
        let at = evlr.start_of_first_evlr;
        let length_at = at.saturating_add(20);
        let mut length = [0; 8];
        let within = at.saturating_add(EVLR_HEADER) <= len
            && r.seek(SeekFrom::Start(length_at)).is_ok()
            && r.read_exact(&mut length).is_ok();
        if !within || u64::from_le_bytes(length) > len - at - EVLR_HEADER {
            return Err(CloudProblem::TruncatedBytes {
                what: "the first extended VLR",
                needed: if within {
                    EVLR_HEADER.saturating_add(u64::from_le_bytes(length))
                } else {
                    EVLR_HEADER
                },
                available: len.saturating_sub(at),
            });
        }
    }
    Ok(points)
}

/// Refuses VLRs that run into the point data. The crate checks their end
/// against the point data's start from the size the header claims, not from
/// where it read them, so a header that claims fewer bytes than its fields take
/// lets them overlap; the point data is then read (and for a LAZ file without
/// its chunk table, patched: [`Patched`]) over bytes already taken as VLRs, and
/// the second reading of the header finds a LASzip record other than the one
/// checked (one without items panics the decoder).
fn check_vlrs_end(
    header: &las::Header,
    format: CloudFormat,
    vlrs_start: u64,
    data_start: u64,
) -> Result<(), CloudProblem> {
    let end = header.vlrs().iter().fold(vlrs_start, |end, v| {
        end.saturating_add(VLR_HEADER + v.data.len() as u64)
    });
    if end > data_start {
        return Err(malformed(
            format,
            format!("its VLRs end at byte {end}, after the point data's start at {data_start}"),
        ));
    }
    Ok(())
}

/// Refuses scales and offsets that make every coordinate meaningless.
fn check_transforms(header: &las::Header, format: CloudFormat) -> Result<(), CloudProblem> {
    let t = header.transforms();
    for (axis, t) in [("x", t.x), ("y", t.y), ("z", t.z)] {
        if !(t.scale.is_finite() && t.offset.is_finite()) || t.scale == 0.0 {
            return Err(malformed(
                format,
                format!(
                    "{axis} scale {} and offset {} make no coordinates",
                    t.scale, t.offset
                ),
            ));
        }
    }
    Ok(())
}

/// Metres per unit for x/y and for z, and the notes that say so.
fn conversion(file: FileUnits, given: Option<LengthUnit>) -> ([f64; 2], Vec<String>) {
    let mut notes = Vec::new();
    if let Some(unit) = given {
        if unit != LengthUnit::Metre {
            notes.push(format!(
                "LAS coordinates taken as {} (--units): converted to metres (× {})",
                unit.plural(),
                unit.factor()
            ));
        } else if file.horizontal.is_some_and(|u| u != unit) {
            notes.push("LAS coordinates taken as metres (--units), not the file's units".into());
        }
        return ([unit.factor(); 2], notes);
    }
    let horizontal = file.horizontal.unwrap_or(LengthUnit::Metre);
    let vertical = file.vertical.unwrap_or(horizontal);
    if horizontal == vertical {
        if horizontal != LengthUnit::Metre {
            notes.push(format!(
                "LAS coordinates in {}: converted to metres (× {})",
                horizontal.plural(),
                horizontal.factor()
            ));
        }
    } else {
        for (what, unit) in [("x and y", horizontal), ("heights", vertical)] {
            if unit != LengthUnit::Metre {
                notes.push(format!(
                    "LAS {what} in {}: converted to metres (× {})",
                    unit.plural(),
                    unit.factor()
                ));
            }
        }
    }
    ([horizontal.factor(), vertical.factor()], notes)
}

/// A reader of `source`'s points; for a LAZ file whose chunk table is
/// missing (`patch` holds where its point data starts), through a view that
/// supplies an empty one.
fn open_reader<S: Source>(source: &S, patch: Option<u64>) -> Result<Reader, las::Error> {
    let inner = source.open()?;
    match patch {
        Some(data_start) => Reader::new(Patched::new(inner, data_start, source.len())),
        None => Reader::new(inner),
    }
}

/// A header that could not be read: cut short, or damaged.
fn header_problem(format: CloudFormat, e: las::Error) -> CloudProblem {
    if eof(&e) {
        malformed(format, "the file ends inside its header")
    } else {
        malformed(format, e)
    }
}

/// Whether `e` is the data running out.
fn eof(e: &las::Error) -> bool {
    let io = match e {
        las::Error::Io(io) => io,
        las::Error::LasZipError(laz::LasZipError::IoError(io)) => io,
        _ => return false,
    };
    io.kind() == std::io::ErrorKind::UnexpectedEof
}

/// How many points decode from a reader `open` gives, knowing that at least
/// `known` do: the whole points of a truncated file.
fn decodable(open: &dyn Fn() -> Result<Reader, las::Error>, known: u64) -> Option<u64> {
    let mut reader = open().ok()?;
    let mut batch: PointData = PointDataBuilder::new().for_header(reader.header()).build();
    let mut done = 0;
    while done < known {
        done += reader
            .fill_points(BATCH.min(known - done), &mut batch)
            .ok()?;
    }
    while let Ok(1) = reader.fill_points(1, &mut batch) {
        done += 1;
    }
    Some(done)
}

/// The file ends after `found` of the `promised` points.
fn truncated(promised: u64, found: u64) -> CloudProblem {
    CloudProblem::Truncated { promised, found }
}

/// A decoder's complaint.
fn malformed(format: CloudFormat, e: impl std::fmt::Display) -> CloudProblem {
    CloudProblem::malformed(format, e)
}

/// A read failure.
fn io(e: std::io::Error) -> CloudProblem {
    CloudProblem::Io(one_line(e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vlrs_running_into_the_point_data_are_refused() {
        use crate::formats::cloud::{encode_las, parse_cloud};
        use cpsplan::model::ModelPoint;
        let points: Vec<ModelPoint> = (0..10)
            .map(|k| ModelPoint {
                position: [k as f64 * 0.1, 0.5, 0.0],
                scan: 0,
            })
            .collect();
        for compressed in [false, true] {
            let mut file = encode_las(&points, compressed).unwrap();
            let start = u32::from_le_bytes(file[96..100].try_into().unwrap());
            // A header that claims no bytes, and point data 22 bytes into the
            // VLRs: the crate's own check counts the VLRs from byte 0.
            file[94..96].copy_from_slice(&0u16.to_le_bytes());
            file[96..100].copy_from_slice(&(start - 22).to_le_bytes());
            let err = parse_cloud(&file, CloudFormat::Las, &CloudReadOptions::default())
                .unwrap_err()
                .to_string();
            let want = format!(
                "its VLRs end at byte {start}, after the point data's start at {}",
                start - 22
            );
            assert!(err.ends_with(&want), "{err}");
        }
    }

    #[test]
    fn units_become_factors_and_notes() {
        let feet = FileUnits {
            horizontal: Some(LengthUnit::Foot),
            vertical: None,
        };
        let (f, notes) = conversion(feet, None);
        assert_eq!(f, [0.3048, 0.3048]);
        assert_eq!(
            notes,
            vec!["LAS coordinates in international feet: converted to metres (× 0.3048)"]
        );

        let mixed = FileUnits {
            horizontal: Some(LengthUnit::Metre),
            vertical: Some(LengthUnit::UsSurveyFoot),
        };
        let (f, notes) = conversion(mixed, None);
        assert_eq!(f, [1.0, 1200.0 / 3937.0]);
        assert_eq!(notes.len(), 1);
        assert!(
            notes[0].starts_with("LAS heights in US survey feet"),
            "{notes:?}"
        );

        let (f, notes) = conversion(FileUnits::default(), None);
        assert_eq!((f, notes.len()), ([1.0, 1.0], 0));

        let (f, notes) = conversion(feet, Some(LengthUnit::Metre));
        assert_eq!(f, [1.0, 1.0]);
        assert_eq!(notes.len(), 1);
        let (f, _) = conversion(FileUnits::default(), Some(LengthUnit::UsSurveyFoot));
        assert_eq!(f, [1200.0 / 3937.0; 2]);
    }
}
