//! A structural check of a LAZ file's compressed point data before the `laz`
//! decoder sees it, for what the decoder does not check itself:
//! - a LASzip record whose items do not add up to the point record length
//!   (with no items at all the decoder panics, with a wrong total it reads past
//!   its buffers; the total is summed without the 16-bit wrap-around of
//!   `LazVlr::items_size`), or that declares an item of a fixed-size type
//!   (Point10, GpsTime, ...) with another size (the decoder splits points by
//!   the types' sizes and overruns the record);
//! - variable-size chunks asked of the compressor that does not chunk (the
//!   decoder looks for a chunk table it never read and panics);
//! - a chunk table that claims more chunks than the file could hold (the
//!   decoder reserves memory for every claimed chunk first);
//! - variable-size chunks whose table covers fewer points than the header
//!   promises (the decoder indexes past the table's end and panics);
//! - layered chunks (point formats 6–10) whose layer sizes exceed the file (the
//!   decoder allocates every layer's size before reading it).
//!
//! The layout followed is LASzip's: the point data starts with the 8-byte
//! offset of the chunk table (or, when the writer could not update it, the
//! table's offset is the file's last 8 bytes); the table starts with a version
//! and the number of chunks. A layered chunk holds its first point raw, then
//! its point count, one 32-bit size per layer, then the layers.

use std::io::{Read, Seek, SeekFrom};

use laz::laszip::ChunkTable;
use laz::{LazItemType, LazVlr};

use super::{CloudFormat, CloudProblem};

/// What a check found wrong: the problem to report.
type Checked<T> = Result<T, CloudProblem>;

/// Whether the decoder will find a chunk table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Table {
    /// The table is where the decoder looks, or the decoder needs none.
    Found,
    /// The table is missing or cut off (a truncated file) while the chunks
    /// are of fixed size: decode through [`Patched`], which supplies an empty
    /// table (the decoder fails on a missing one; with fixed-size chunks it
    /// needs none to read on).
    Missing,
}

/// The LASzip compressor that does not chunk points (no chunk table).
const POINT_WISE: u16 = 1;
/// The LASzip compressor that chunks points and stores a chunk table.
const POINT_WISE_CHUNKED: u16 = 2;
/// The LASzip compressor that chunks points in layers (point formats 6–10).
const LAYERED_CHUNKED: u16 = 3;

/// Checks the compressed point data of a LAZ file of `len` bytes whose header
/// promises `points` records of `record_len` bytes from `data_start`;
/// `compressor` is the LASzip record's compressor code.
pub(crate) fn check<R: Read + Seek>(
    r: &mut R,
    vlr: &LazVlr,
    compressor: u16,
    points: u64,
    record_len: u16,
    data_start: u64,
    len: u64,
) -> Checked<Table> {
    for item in vlr.items() {
        let t = item.item_type();
        if let Some(size) = fixed_size(t).filter(|&s| s != item.size()) {
            return Err(bad(format!(
                "the LASzip item {t:?} is of {size} bytes, the record says {}",
                item.size()
            )));
        }
    }
    let items = items_size(vlr);
    if items != u64::from(record_len) {
        return Err(bad(format!(
            "the LASzip items describe {items}-byte points, the header {record_len}-byte ones"
        )));
    }
    if compressor == POINT_WISE && vlr.uses_variable_size_chunks() {
        // The decoder finds no chunk table to size the chunks by, and panics.
        return Err(bad(
            "the LASzip record asks for variable-size chunks from the compressor that does not chunk"
                .to_string(),
        ));
    }
    if !matches!(compressor, POINT_WISE_CHUNKED | LAYERED_CHUNKED) {
        // No chunk table (or a compressor the decoder refuses).
        return Ok(Table::Found);
    }
    let table = chunk_table(r, vlr, points, data_start, len)?;
    let layered = vlr.items().first().is_some_and(|i| i.version() >= 3);
    if layered {
        let decoded = match &table {
            TableState::Decoded(t) => Some(t),
            _ => None,
        };
        walk_layers(r, vlr, decoded, points, record_len, data_start, len)?;
    }
    Ok(match table {
        TableState::Missing => Table::Missing,
        _ => Table::Found,
    })
}

/// The bytes of a point the LASzip record's items describe. Summed here, not
/// by `LazVlr::items_size`, which adds the 16-bit sizes in 16 bits: items of
/// more than 65,535 bytes in all wrap around, and a total that wraps to the
/// point record length passes for it while the decoder then splits a record
/// buffer into more bytes than it has (a panic).
fn items_size(vlr: &LazVlr) -> u64 {
    vlr.items().iter().map(|i| u64::from(i.size())).sum()
}

/// The bytes of a LASzip item of type `t` (`None`: extra bytes, of the size
/// the record gives). The decoder splits each point by these sizes, whatever
/// sizes the record declares, so a record that declares others for them adds
/// up to the point record length while the decoder overruns it (a panic).
fn fixed_size(t: LazItemType) -> Option<u16> {
    match t {
        LazItemType::Byte(_) | LazItemType::Byte14(_) => None,
        LazItemType::Point10 => Some(20),
        LazItemType::GpsTime => Some(8),
        LazItemType::RGB12 | LazItemType::RGB14 => Some(6),
        LazItemType::RGBNIR14 => Some(8),
        LazItemType::WavePacket13 | LazItemType::WavePacket14 => Some(29),
        LazItemType::Point14 => Some(30),
    }
}

/// A problem with the compressed data, as a malformed-LAZ error.
fn bad(message: String) -> CloudProblem {
    CloudProblem::malformed(CloudFormat::Laz, message)
}

/// Reads a little-endian integer of `N` bytes at `pos`, `None` past the end.
fn read_at<R: Read + Seek, const N: usize>(r: &mut R, pos: u64, len: u64) -> Option<[u8; N]> {
    if pos.checked_add(N as u64)? > len {
        return None;
    }
    r.seek(SeekFrom::Start(pos)).ok()?;
    let mut b = [0; N];
    r.read_exact(&mut b).ok()?;
    Some(b)
}

/// What the decoder will find for a chunk table.
enum TableState {
    /// A table of a plausible size (fixed-size chunks: not decoded here).
    Sized,
    /// The decoded table of variable-size chunks.
    Decoded(ChunkTable),
    /// No readable table.
    Missing,
}

/// Checks the chunk table's size where the decoder will look for it; for
/// variable-size chunks, decodes it and checks that it covers `points`.
fn chunk_table<R: Read + Seek>(
    r: &mut R,
    vlr: &LazVlr,
    points: u64,
    data_start: u64,
    len: u64,
) -> Checked<TableState> {
    let offset_at = |r: &mut R, pos| read_at::<R, 8>(r, pos, len).map(i64::from_le_bytes);
    let Some(first) = offset_at(r, data_start) else {
        return Err(CloudProblem::Truncated {
            promised: points,
            found: 0,
        });
    };
    let start = data_start as i64;
    let offset = if first > start {
        Some(first)
    } else {
        len.checked_sub(8)
            .and_then(|end| offset_at(r, end))
            .filter(|&o| o > start)
    };
    let count = offset.and_then(|o| read_at::<R, 4>(r, (o as u64).saturating_add(4), len));
    let Some(count) = count.map(u32::from_le_bytes) else {
        if vlr.uses_variable_size_chunks() {
            return Err(bad(
                "the chunk table of its variable-size chunks is missing (a truncated file?)"
                    .to_string(),
            ));
        }
        return Ok(TableState::Missing);
    };
    let most = points.saturating_add(1).min(len);
    if u64::from(count) > most {
        return Err(bad(format!(
            "the chunk table claims {count} chunks, more than the file can hold"
        )));
    }
    if !vlr.uses_variable_size_chunks() {
        return Ok(TableState::Sized);
    }
    r.seek(SeekFrom::Start(data_start))
        .map_err(|e| CloudProblem::Io(e.to_string()))?;
    let table = ChunkTable::read_from(&mut *r, vlr)
        .map_err(|e| bad(format!("unreadable chunk table: {e}")))?;
    let covered = table
        .as_ref()
        .iter()
        .fold(0u64, |sum, e| sum.saturating_add(e.point_count));
    if covered < points {
        return Err(bad(format!(
            "the chunk table covers {covered} points, the header promises {points}"
        )));
    }
    Ok(TableState::Decoded(table))
}

/// Layer-size fields a layered item's chunk header holds.
fn layers_of(item: LazItemType) -> u64 {
    match item {
        LazItemType::Point14 => 9,
        LazItemType::RGBNIR14 => 2,
        LazItemType::Byte14(n) => u64::from(n),
        _ => 1,
    }
}

/// Walks the chunks of layered data as the decoder will, checking that each
/// chunk's layers lie within the file.
fn walk_layers<R: Read + Seek>(
    r: &mut R,
    vlr: &LazVlr,
    table: Option<&ChunkTable>,
    points: u64,
    record_len: u16,
    data_start: u64,
    len: u64,
) -> Checked<()> {
    let layers: u64 = vlr.items().iter().map(|i| layers_of(i.item_type())).sum();
    let fixed = (!vlr.uses_variable_size_chunks()).then(|| u64::from(vlr.chunk_size()));
    let mut pos = data_start + 8;
    let mut covered = 0u64;
    let mut chunk = 0usize;
    while covered < points {
        let in_chunk = match (fixed, table) {
            (Some(n), _) if n > 0 => n,
            (None, Some(t)) => t.as_ref().get(chunk).map_or(0, |e| e.point_count),
            _ => 0,
        };
        // A chunk of unknown size runs to the end of the points.
        let in_chunk = if in_chunk == 0 {
            points - covered
        } else {
            in_chunk
        };
        let truncated = CloudProblem::Truncated {
            promised: points,
            found: covered,
        };
        let sizes_at = pos + u64::from(record_len) + 4;
        let mut end = sizes_at + 4 * layers;
        if end > len {
            return Err(truncated);
        }
        for k in 0..layers {
            let size = read_at::<R, 4>(r, sizes_at + 4 * k, len)
                .ok_or_else(|| bad("unreadable layer sizes".to_string()))?;
            end += u64::from(u32::from_le_bytes(size));
        }
        if end > len {
            return Err(truncated);
        }
        pos = end;
        covered = covered.saturating_add(in_chunk);
        chunk += 1;
    }
    Ok(())
}

/// A LAZ file seen with an empty chunk table appended: the offset at the
/// start of the point data points past the file's end, where 8 zero bytes
/// (table version 0, no chunks) follow. For files whose table is missing.
pub(crate) struct Patched<R> {
    inner: R,
    /// Where the point data, and the table offset, start.
    data_start: u64,
    /// The real file's length.
    len: u64,
    pos: u64,
}

impl<R: Read + Seek> Patched<R> {
    /// `inner`, a LAZ file of `len` bytes whose point data starts at
    /// `data_start`, with an empty chunk table.
    pub(crate) fn new(inner: R, data_start: u64, len: u64) -> Self {
        Self {
            inner,
            data_start,
            len,
            pos: 0,
        }
    }

    /// The virtual byte at `pos` if it differs from the file's.
    fn patched(&self, pos: u64) -> Option<u8> {
        if (self.data_start..self.data_start + 8).contains(&pos) {
            Some(self.len.to_le_bytes()[(pos - self.data_start) as usize])
        } else if pos >= self.len {
            Some(0)
        } else {
            None
        }
    }
}

impl<R: Read + Seek> Read for Patched<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let end = self.len + 8;
        if buf.is_empty() || self.pos >= end {
            return Ok(0);
        }
        if let Some(b) = self.patched(self.pos) {
            buf[0] = b;
            self.pos += 1;
            return Ok(1);
        }
        // A run of real bytes, up to the patch or the file's end.
        let stop = if self.pos < self.data_start {
            self.data_start
        } else {
            self.len
        };
        let n = buf.len().min((stop - self.pos) as usize);
        self.inner.seek(SeekFrom::Start(self.pos))?;
        let got = self.inner.read(&mut buf[..n])?;
        self.pos += got as u64;
        Ok(got)
    }
}

impl<R: Read + Seek> Seek for Patched<R> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let end = self.len + 8;
        let target = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => end.checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        let Some(target) = target else {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "seek before the start",
            ));
        };
        self.pos = target;
        Ok(target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn items_of_more_than_64k_bytes_do_not_wrap_to_the_record_length() {
        use laz::LazItemRecordBuilder;
        // 20 + 8 + 6 + 2 × 32,768 bytes: 34 in 16 bits, the record length of
        // point format 3.
        let items = LazItemRecordBuilder::new()
            .add_item(LazItemType::Point10)
            .add_item(LazItemType::GpsTime)
            .add_item(LazItemType::RGB12)
            .add_item(LazItemType::Byte(32_768))
            .add_item(LazItemType::Byte(32_768))
            .build();
        let vlr = LazVlr::from_laz_items(items);
        assert_eq!(items_size(&vlr), 65_570);
        let file = vec![0; 400];
        let err = check(&mut Cursor::new(file), &vlr, 2, 1, 34, 0, 400).unwrap_err();
        assert_eq!(
            err.to_string(),
            "not a valid LAZ file: the LASzip items describe 65570-byte points, \
             the header 34-byte ones"
        );
    }

    #[test]
    fn items_must_have_their_types_sizes() {
        // Point10, Point10, RGB12 declared as 20 + 8 + 6 bytes: 34, the record
        // length of point format 3, while the decoder splits 20 + 20 + 6.
        let mut data = vec![2, 0, 0, 0, 2, 2, 0, 0, 0, 0, 0, 0, 0x50, 0xc3, 0, 0];
        data.extend_from_slice(&[0xff; 16]);
        data.extend_from_slice(&3u16.to_le_bytes());
        for (t, size) in [(6u16, 20u16), (6, 8), (8, 6)] {
            for v in [t, size, 2] {
                data.extend_from_slice(&v.to_le_bytes());
            }
        }
        let vlr = LazVlr::from_buffer(&data).unwrap();
        assert_eq!(items_size(&vlr), 34);
        let file = vec![0; 400];
        let err = check(&mut Cursor::new(file), &vlr, 2, 1, 34, 0, 400).unwrap_err();
        assert_eq!(
            err.to_string(),
            "not a valid LAZ file: the LASzip item Point10 is of 20 bytes, the record says 8"
        );
    }

    #[test]
    fn variable_chunks_need_the_chunking_compressor() {
        // Compressor 1 (point-wise, unchunked), chunk size 0 (variable), one
        // Point10 item.
        let mut data = vec![1, 0, 0, 0, 2, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        data.extend_from_slice(&[0xff; 16]);
        data.extend_from_slice(&1u16.to_le_bytes());
        for v in [6u16, 20, 2] {
            data.extend_from_slice(&v.to_le_bytes());
        }
        let vlr = LazVlr::from_buffer(&data).unwrap();
        assert!(vlr.uses_variable_size_chunks());
        let err = check(&mut Cursor::new(vec![0; 100]), &vlr, 1, 1, 20, 0, 100).unwrap_err();
        assert!(err.to_string().contains("variable-size chunks"), "{err}");
        assert!(check(&mut Cursor::new(vec![0; 100]), &vlr, 2, 1, 20, 0, 100).is_err());
    }

    #[test]
    fn the_patched_view_appends_an_empty_table() {
        let file: Vec<u8> = (0..20).collect();
        let mut view = Patched::new(Cursor::new(file.clone()), 4, 20);
        let mut all = Vec::new();
        view.read_to_end(&mut all).unwrap();
        let mut want = file[..4].to_vec();
        want.extend_from_slice(&20u64.to_le_bytes());
        want.extend_from_slice(&file[12..]);
        want.extend_from_slice(&[0; 8]);
        assert_eq!(all, want);
        view.seek(SeekFrom::End(-8)).unwrap();
        let mut tail = [1; 8];
        view.read_exact(&mut tail).unwrap();
        assert_eq!(tail, [0; 8]);
        view.seek(SeekFrom::Start(2)).unwrap();
        let mut two = [0; 4];
        view.read_exact(&mut two).unwrap();
        assert_eq!(two, [2, 3, 20, 0]);
        assert!(view.seek(SeekFrom::Current(-100)).is_err());
    }
}
