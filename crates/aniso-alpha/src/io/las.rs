//! LAS/LAZ reader: the header through the `las` crate, the point records
//! read here (LAS) or through the `laz` crate (LAZ).
//!
//! Hostile files: everything the two crates trust for an allocation or an
//! index is checked here first, against the file's size ([`precheck`],
//! [`laz_precheck`]): the point data size, the extended VLRs, the laszip
//! VLR's items (they must describe exactly the header's point format), the
//! chunk table (its count bounded by the compressed bytes, its entries by
//! the data they describe), and for layered (LAS 1.4) chunks every layer
//! size. What is left, a panic inside the crates on corrupt compressed
//! data, is caught at this boundary ([`contain`]) and becomes an
//! [`IoError::Format`]. No allocation exceeds a bound set by the file's
//! size: the declared point count is capped by [`MAX_LAZ_RATIO`] times the
//! compressed bytes.

use std::io::{Seek, SeekFrom};
use std::path::Path;

use super::attributes::LasSource;
use super::las_attrs::{base_len, parse_vlrs, record_attributes};
use super::las_bytes::{u16_at, u32_at, u64_at, u8_at, ByteReader, LasBytes};
use super::{check_finite, non_empty, ClassSet, IoError, PointCloud};

/// The largest accepted ratio of decompressed point bytes to compressed
/// bytes in a LAZ file. LASzip reaches 5–20:1 on real scans and about
/// 100:1 on constant records; a header declaring more is refused as a
/// decompression bomb before anything is allocated.
pub(crate) const MAX_LAZ_RATIO: u64 = 1000;

/// The decoded fixed header fields this reader needs.
pub(crate) struct Layout {
    pub(crate) data_start: usize,
    pub(crate) record_len: usize,
    pub(crate) points: u64,
    pub(crate) compressed: bool,
    pub(crate) extended: bool,
    pub(crate) scale: [f64; 3],
    pub(crate) offset: [f64; 3],
}

/// Reads a LAS/LAZ file held in memory; with `labels`, the
/// classification gives the labels, the classes in the set read as
/// background (-1); with `attributes`, the records are kept
/// ([`PointCloud::las`]) and decoded into [`PointCloud::attributes`].
pub(crate) fn read_las(
    path: &Path,
    bytes: &[u8],
    labels_with: Option<ClassSet>,
    attributes: bool,
) -> Result<PointCloud, IoError> {
    let keep = Keep::from_attributes(attributes);
    read_las_from(path, bytes, None, labels_with, keep, &mut |_, _| {})
}

/// What a read keeps besides the points (and labels).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Keep {
    /// Nothing.
    Points,
    /// The records, with the header, VLRs and trailing data
    /// ([`PointCloud::las`]), for a copy of the file.
    Records,
    /// The records, decoded into [`PointCloud::attributes`] too.
    Attributes,
}

impl Keep {
    /// [`Keep::Attributes`] or [`Keep::Points`].
    pub(crate) fn from_attributes(attributes: bool) -> Keep {
        if attributes {
            Keep::Attributes
        } else {
            Keep::Points
        }
    }
}

/// The number of points a LAS/LAZ file declares, checked as a read
/// checks it (a LAZ file's chunk table must hold them).
pub(crate) fn las_points<B: LasBytes + ?Sized>(path: &Path, bytes: &B) -> Result<u64, IoError> {
    let bad = |m: String| invalid(path, m);
    precheck(bytes).map_err(bad)?;
    let (layout, _) = contain(path, || header_layout(bytes))?.map_err(bad)?;
    Ok(layout.points)
}

/// The points `start..start + count` of a LAS/LAZ file (a range past the
/// end is cut at it), read from `bytes` without the rest of the point
/// records: the records of an uncompressed file are read at their offset,
/// a LAZ file's from the chunk that holds `start`. The checks of a hostile
/// file are those of a whole read. `keep` says what is kept besides the
/// points and labels.
/// `progress(bytes, file_size)` is called after each batch of records
/// (the bytes as the share of the range's points read).
pub(crate) fn read_las_from<B: LasBytes + ?Sized>(
    path: &Path,
    bytes: &B,
    range: Option<(u64, u64)>,
    labels_with: Option<ClassSet>,
    keep: Keep,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PointCloud, IoError> {
    let read_labels = labels_with.is_some();
    let background = labels_with.unwrap_or(ClassSet::EMPTY);
    let bad = |m: String| invalid(path, m);
    precheck(bytes).map_err(bad)?;
    let (layout, laz) = contain(path, || header_layout(bytes))?.map_err(bad)?;
    let (start, count) = match range {
        None => (0, layout.points),
        Some((s, _)) if s >= layout.points && layout.points > 0 => {
            return Err(IoError::format(
                path,
                format!(
                    "point range starts at {s}, the file has {} points",
                    layout.points
                ),
            ))
        }
        Some((s, n)) => (s, n.min(layout.points.saturating_sub(s))),
    };
    let mut cloud = PointCloud::default();
    let cap = usize::try_from(count)
        .unwrap_or(usize::MAX)
        .min(usize::try_from(bytes.size() / 4).unwrap_or(usize::MAX));
    cloud.points.reserve(cap);
    let mut labels = Vec::new();
    if read_labels {
        labels.reserve(cap);
    }
    let class_at = if layout.extended { 16 } else { 15 };
    let class_mask = if layout.extended { 0xFF } else { 0x1F };
    let records = keep != Keep::Points;
    let mut kept: Vec<u8> = Vec::new();
    if records {
        kept.reserve(
            cap.saturating_mul(layout.record_len).min(
                usize::try_from(bytes.size())
                    .unwrap_or(usize::MAX)
                    .saturating_mul(4),
            ),
        );
    }
    let mut sink = |batch: &[u8]| -> Result<(), IoError> {
        if records {
            kept.extend_from_slice(batch);
        }
        for rec in batch.chunks_exact(layout.record_len) {
            let p = [0usize, 1, 2].map(|k| {
                let raw = i32::from_le_bytes([
                    rec[4 * k],
                    rec[4 * k + 1],
                    rec[4 * k + 2],
                    rec[4 * k + 3],
                ]);
                layout.scale[k] * f64::from(raw) + layout.offset[k]
            });
            check_finite(path, &p, cloud.points.len(), None)?;
            cloud.points.push(p);
            if read_labels {
                let class = rec[class_at] & class_mask;
                labels.push(if background.contains(class) {
                    -1
                } else {
                    i64::from(class)
                });
            }
        }
        Ok(())
    };
    for_each_batch(
        path,
        bytes,
        &layout,
        laz,
        (start, count),
        &mut sink,
        progress,
    )?;
    if read_labels {
        cloud.labels = Some(labels);
    }
    if records {
        let src = source(bytes, &layout, kept).map_err(bad)?;
        if keep == Keep::Attributes {
            cloud.attributes = record_attributes(&src);
        }
        cloud.las = Some(Box::new(src));
    }
    non_empty(path, cloud)
}

/// Feeds `sink` the records `range` (start, count) of a checked file, a
/// batch at a time ([`batch_size`]), calling `progress` after each.
fn for_each_batch<B: LasBytes + ?Sized>(
    path: &Path,
    bytes: &B,
    layout: &Layout,
    laz: Option<laz::LazVlr>,
    range: (u64, u64),
    sink: &mut dyn FnMut(&[u8]) -> Result<(), IoError>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<(), IoError> {
    let (start, count) = range;
    let bad = |m: String| invalid(path, m);
    let len = layout.record_len as u64;
    let batch = batch_size(layout.record_len, bytes.size());
    match laz {
        None => {
            let truncated = || {
                IoError::format(
                    path,
                    format!(
                        "LAS file truncated: header declares {} points of {} bytes, file has {} bytes",
                        layout.points,
                        layout.record_len,
                        bytes.size()
                    ),
                )
            };
            let mut at = start;
            while at < start + count {
                let n = (start + count - at).min(batch);
                let offset = at
                    .checked_mul(len)
                    .and_then(|o| o.checked_add(layout.data_start as u64))
                    .ok_or_else(truncated)?;
                let records = bytes.piece(offset, n * len).ok_or_else(truncated)?;
                sink(&records)?;
                at += n;
                progress(share(at - start, count, bytes.size()), bytes.size());
            }
        }
        Some(vlr) => {
            let mut source = std::io::BufReader::with_capacity(1 << 20, ByteReader::new(bytes));
            source
                .seek(SeekFrom::Start(layout.data_start as u64))
                .map_err(|e| bad(format!("LAZ: {e}")))?;
            let mut dec = contain(path, move || laz::LasZipDecompressor::new(source, vlr))?
                .map_err(|e| bad(format!("LAZ: {e}")))?;
            let corrupt = |done: u64, e: &dyn std::fmt::Display| {
                IoError::format(
                    path,
                    format!(
                        "LAZ data corrupt or truncated after {done} of {} points: {e}",
                        layout.points
                    ),
                )
            };
            if start > 0 {
                contain(path, || dec.seek(start))?.map_err(|e| corrupt(start, &e))?;
            }
            let mut buf = Vec::new();
            let mut at = start;
            while at < start + count {
                let n = (start + count - at).min(batch) as usize;
                buf.resize(n * layout.record_len, 0);
                contain(path, || dec.decompress_many(&mut buf))?.map_err(|e| corrupt(at, &e))?;
                sink(&buf)?;
                at += n as u64;
                progress(share(at - start, count, bytes.size()), bytes.size());
            }
        }
    }
    Ok(())
}

/// The header, VLRs and data after the points of a LAS file, with its
/// `records`.
fn source<B: LasBytes + ?Sized>(
    bytes: &B,
    layout: &Layout,
    records: Vec<u8>,
) -> Result<LasSource, String> {
    let header_size = u16_at(bytes, 94).ok_or("short header")?;
    let n_vlrs = u32_at(bytes, 100).ok_or("short header")?;
    if header_size > layout.data_start as u64 {
        return Err("header size past the point data".into());
    }
    let head = bytes
        .piece(0, layout.data_start as u64)
        .ok_or("header size past the point data")?;
    let header = head[..header_size as usize].to_vec();
    let (vlrs, padding) = parse_vlrs(&head, header_size as usize, n_vlrs, layout.data_start)?;
    // What follows the points: LAS 1.4 extended VLRs, or a LAS 1.3+
    // waveform record stored in the file (global encoding bit 1).
    let points_end = if layout.compressed {
        layout.data_start as u64
    } else {
        layout.data_start as u64 + layout.points * layout.record_len as u64
    };
    let len = bytes.size();
    let mut tail_start = u64::MAX;
    let minor = u8_at(bytes, 25).unwrap_or(0);
    let global = u16_at(bytes, 6).unwrap_or(0);
    if minor >= 3 && header_size >= 235 && global & 2 != 0 {
        let wf = u64_at(bytes, 227).unwrap_or(0);
        if wf >= points_end && wf < len {
            tail_start = tail_start.min(wf);
        }
    }
    if minor >= 4 && header_size >= 247 && u32_at(bytes, 243).unwrap_or(0) > 0 {
        let ev = u64_at(bytes, 235).unwrap_or(0);
        if ev >= points_end && ev < len {
            tail_start = tail_start.min(ev);
        }
    }
    let (tail_start, tail) = if tail_start == u64::MAX {
        (0, Vec::new())
    } else {
        let tail = bytes
            .piece(tail_start, len - tail_start)
            .ok_or("trailing data past the end of the file")?;
        (tail_start, tail.into_owned())
    };
    Ok(LasSource {
        header,
        vlrs,
        padding,
        point_format: u8_at(bytes, 104).unwrap_or(0) & 0x3F,
        record_len: layout.record_len,
        records,
        tail_start,
        tail,
    })
}

/// A LAS/LAZ file that fails a check.
fn invalid(path: &Path, message: String) -> IoError {
    IoError::format(path, format!("invalid LAS/LAZ file: {message}"))
}

/// Runs `f`, turning a panic inside it (from the `las` or `laz` crates on
/// corrupt data) into an error naming the file.
pub(crate) fn contain<T>(path: &Path, f: impl FnOnce() -> T) -> Result<T, IoError> {
    super::error::contain_decoder(path, "LAS/LAZ", f)
}

/// Parses the header with the `las` crate and, for LAZ, checks the laszip
/// VLR and chunk table ([`laz_precheck`]).
fn header_layout<B: LasBytes + ?Sized>(bytes: &B) -> Result<(Layout, Option<laz::LazVlr>), String> {
    let header = las::Header::new(std::io::BufReader::new(ByteReader::new(bytes)))
        .map_err(|e| e.to_string())?;
    let format = header.point_format();
    let t = header.transforms();
    let layout = Layout {
        data_start: u32_at(bytes, 96).ok_or("short header")? as usize,
        record_len: usize::from(format.len()),
        points: header.number_of_points(),
        compressed: format.is_compressed,
        extended: format.is_extended,
        scale: [t.x.scale, t.y.scale, t.z.scale],
        offset: [t.x.offset, t.y.offset, t.z.offset],
    };
    if layout.record_len < 20 {
        return Err(format!("point record length {} < 20", layout.record_len));
    }
    let laz = if layout.compressed {
        Some(laz_precheck(bytes, &layout)?)
    } else {
        None
    };
    Ok((layout, laz))
}

/// Checks the header fields that the `las` crate trusts for allocations
/// and arithmetic (it panics or aborts on some lies): the point data size
/// must not overflow, and an extended VLR must fit in the file. Fields that
/// are missing (a short file) are left to the crate, which reports them.
fn precheck<B: LasBytes + ?Sized>(b: &B) -> Result<(), String> {
    let len = b.size();
    let (Some(major), Some(minor)) = (u8_at(b, 24), u8_at(b, 25)) else {
        return Ok(());
    };
    let v14 = major > 1 || (major == 1 && minor >= 4);
    let offset = u32_at(b, 96).unwrap_or(0);
    let record_len = u16_at(b, 105).unwrap_or(0);
    let mut count = u32_at(b, 107).unwrap_or(0);
    if v14 {
        count = count.max(u64_at(b, 247).unwrap_or(0));
    }
    let end = count
        .checked_mul(record_len)
        .and_then(|n| n.checked_add(offset))
        .ok_or("point count × record length overflows")?;
    let compressed = u8_at(b, 104).is_some_and(|f| f & 0xC0 != 0);
    if !compressed && end > len && record_len > 0 {
        return Err(format!(
            "truncated: header declares {count} points of {record_len} bytes, file has {len} bytes"
        ));
    }
    if compressed && count.saturating_mul(record_len) > len.saturating_mul(MAX_LAZ_RATIO) {
        return Err(format!(
            "header declares {count} points of {record_len} bytes, over {MAX_LAZ_RATIO} times the \
             {len} bytes of the file (a LAZ decompression bomb, or a corrupt count)"
        ));
    }
    if v14 {
        let start = u64_at(b, 235).unwrap_or(0);
        let n = u32_at(b, 243).unwrap_or(0);
        if start > 0 && n > 0 {
            let rec = start
                .checked_add(20)
                .and_then(|at| u64_at(b, at))
                .ok_or("extended VLR starts past the end of the file")?;
            if rec.checked_add(start + 60).is_none_or(|e| e > len) {
                return Err("extended VLR extends past the end of the file".into());
            }
        }
    }
    Ok(())
}

/// The laszip VLR's payload: the VLRs are walked here (bounded by the
/// header's count and the file), `None` if there is no laszip VLR.
fn find_laszip_vlr<B: LasBytes + ?Sized>(b: &B) -> Option<Vec<u8>> {
    let header_size = u16_at(b, 94)?;
    let n = u32_at(b, 100)?;
    let mut pos = header_size;
    for _ in 0..n {
        let head = b.piece(pos, 54)?;
        let len = u64::from(u16::from_le_bytes([head[20], head[21]]));
        let user = &head[2..18];
        let user = &user[..user.iter().position(|&c| c == 0).unwrap_or(16)];
        let record = u16::from_le_bytes([head[18], head[19]]);
        if user == b"laszip encoded" && record == 22204 {
            return b.piece(pos + 54, len).map(|d| d.into_owned());
        }
        b.piece(pos + 54, len)?;
        pos += 54 + len;
    }
    None
}

/// One LAZ item as the laszip VLR lists it: (type, size, version).
type Item = (u16, u16, u16);

/// The item types LASzip uses for a point format (with `extra` bytes).
fn expected_items(format: u8, extra: u16) -> Option<Vec<u16>> {
    // Types: 0 Byte, 6 Point10, 7 GpsTime, 8 RGB12, 9 WavePacket13,
    // 10 Point14, 11 RGB14, 12 RGBNIR14, 13 WavePacket14, 14 Byte14.
    let mut v: Vec<u16> = match format {
        0 => vec![6],
        1 => vec![6, 7],
        2 => vec![6, 8],
        3 => vec![6, 7, 8],
        4 => vec![6, 7, 9],
        5 => vec![6, 7, 8, 9],
        6 => vec![10],
        7 => vec![10, 11],
        8 => vec![10, 12],
        9 => vec![10, 13],
        10 => vec![10, 12, 13],
        _ => return None,
    };
    if extra > 0 {
        v.push(if format >= 6 { 14 } else { 0 });
    }
    Some(v)
}

/// Size in bytes of a LAZ item of a fixed-size type.
fn item_size(kind: u16) -> Option<u16> {
    Some(match kind {
        6 => 20,
        7 => 8,
        8 | 11 => 6,
        9 | 13 => 29,
        10 => 30,
        12 => 8,
        _ => return None,
    })
}

/// Number of layers (sizes stored at the start of a layered chunk) of a
/// LAS 1.4 item.
fn item_layers(item: Item) -> u64 {
    match item.0 {
        10 => 9,
        11 | 13 => 1,
        12 => 2,
        14 => u64::from(item.1),
        _ => 0,
    }
}

/// Validates a LAZ file before the `laz` crate reads it; returns the
/// parsed laszip VLR. See the module docs. The checks, in order: the
/// laszip VLR's own fields ([`LaszipHeader::parse`]), its items against
/// the point format ([`check_items`]), the chunk table ([`chunk_table`]),
/// the points its chunks hold ([`check_chunk_points`]) and, for the
/// layered formats 6–10, each chunk's layer sizes ([`check_layers`]).
pub(crate) fn laz_precheck<B: LasBytes + ?Sized>(
    b: &B,
    layout: &Layout,
) -> Result<laz::LazVlr, String> {
    let data = find_laszip_vlr(b).ok_or("compressed point format but no laszip VLR")?;
    let header = LaszipHeader::parse(&data)?;
    let layered = check_items(b, layout, &header)?;
    let vlr = laz::LazVlr::from_buffer(&data).map_err(|e| format!("laszip VLR: {e}"))?;
    let Some(table) = chunk_table(b, layout, header.variable())? else {
        return Ok(vlr);
    };
    check_chunk_points(&table, layout, &header)?;
    if layered {
        check_layers(b, layout, &header.items, &table.entries)?;
    }
    Ok(vlr)
}

/// The fields of a laszip VLR that the checks read.
struct LaszipHeader {
    /// 2 (chunked) or 3 (chunked, layered).
    compressor: u16,
    /// Points per chunk; 0 or `u32::MAX`: chunks of variable size.
    chunk_size: u32,
    /// (kind, size, version) of each item.
    items: Vec<Item>,
}

impl LaszipHeader {
    /// The VLR's compressor, coder, chunk size and items, checked on their
    /// own.
    fn parse(data: &[u8]) -> Result<Self, String> {
        let field = |o: usize, n: usize| data.get(o..o + n).ok_or("laszip VLR is too short");
        let compressor = u16::from_le_bytes(field(0, 2)?.try_into().unwrap_or_default());
        let coder = u16::from_le_bytes(field(2, 2)?.try_into().unwrap_or_default());
        let chunk_size = u32::from_le_bytes(field(12, 4)?.try_into().unwrap_or_default());
        let num_items = usize::from(u16::from_le_bytes(
            field(32, 2)?.try_into().unwrap_or_default(),
        ));
        if !(compressor == 2 || compressor == 3) {
            return Err(format!(
                "unsupported LAZ compressor {compressor} (expected chunked: 2 or 3)"
            ));
        }
        if coder != 0 {
            return Err(format!("unknown LAZ coder {coder}"));
        }
        if num_items == 0 {
            return Err("the laszip VLR lists no items".into());
        }
        let items = field(34, 6 * num_items)?
            .chunks_exact(6)
            .map(|c| {
                (
                    u16::from_le_bytes([c[0], c[1]]),
                    u16::from_le_bytes([c[2], c[3]]),
                    u16::from_le_bytes([c[4], c[5]]),
                )
            })
            .collect();
        Ok(LaszipHeader {
            compressor,
            chunk_size,
            items,
        })
    }

    /// Whether the chunks hold a variable number of points each.
    fn variable(&self) -> bool {
        self.chunk_size == 0 || self.chunk_size == u32::MAX
    }
}

/// The VLR's items against the header's point format and record length:
/// the kinds the format needs, each of its size and of a version the
/// format allows, and the compressor that goes with it. Returns whether
/// the format is layered (6–10).
fn check_items<B: LasBytes + ?Sized>(
    b: &B,
    layout: &Layout,
    header: &LaszipHeader,
) -> Result<bool, String> {
    let format = u8_at(b, 104).unwrap_or(0) & 0x3F;
    let base = base_len(format).ok_or_else(|| format!("unknown point format {format}"))?;
    let extra = layout
        .record_len
        .checked_sub(base)
        .and_then(|e| u16::try_from(e).ok())
        .ok_or("record length shorter than the point format")?;
    let want = expected_items(format, extra).ok_or("unknown point format")?;
    let layered = format >= 6;
    let kinds: Vec<u16> = header.items.iter().map(|i| i.0).collect();
    if kinds != want {
        return Err(format!(
            "the laszip VLR's items {kinds:?} do not describe point format {format} with {extra} extra bytes"
        ));
    }
    for &(kind, size, version) in &header.items {
        let ok_size = match kind {
            0 | 14 => size == extra,
            _ => item_size(kind) == Some(size),
        };
        if !ok_size {
            return Err(format!("LAZ item {kind} has a wrong size {size}"));
        }
        let ok_version = if layered {
            version == 3 || version == 4
        } else {
            version == 1 || version == 2
        };
        if !ok_version {
            return Err(format!(
                "LAZ item {kind} has an unsupported version {version}"
            ));
        }
    }
    let compressor = header.compressor;
    if (compressor == 3) != layered {
        return Err(format!(
            "LAZ compressor {compressor} does not fit point format {format}"
        ));
    }
    Ok(layered)
}

/// A LAZ file's chunk table.
struct ChunkTable {
    /// (points, bytes) of each chunk; the points are 0 in a table of
    /// fixed-size chunks.
    entries: Vec<(u64, u64)>,
    /// The chunks the table declares.
    count: u64,
    /// The bytes of compressed data before the table.
    compressed_bytes: u64,
}

/// The chunk table, found where the first 8 bytes of the point data say
/// (or, when the writer could not seek back, the last 8 bytes of the
/// file), its count bounded by the compressed data's size before it is
/// read; `None` for an empty table of a file without points.
fn chunk_table<B: LasBytes + ?Sized>(
    b: &B,
    layout: &Layout,
    variable: bool,
) -> Result<Option<ChunkTable>, String> {
    let len = b.size();
    let start = layout.data_start as u64;
    let mut table = u64_at(b, start).ok_or("no LAZ point data")? as i64;
    if table <= start as i64 {
        table = u64_at(b, len.saturating_sub(8)).unwrap_or(0) as i64;
    }
    if table <= start as i64 {
        return Err("LAZ file has no chunk table".into());
    }
    let table = table as u64;
    if table < start + 8 || table.checked_add(8).is_none_or(|e| e > len) {
        return Err(format!(
            "LAZ chunk table offset {table} is outside the file ({len} bytes)"
        ));
    }
    let count = u32_at(b, table + 4).unwrap_or(0);
    let compressed_bytes = table - start - 8;
    // Every chunk starts with one raw record: this bounds the count (and the
    // table's allocation) by the compressed data's size.
    let record_len = layout.record_len as u64;
    if count > compressed_bytes / record_len {
        return Err(format!(
            "LAZ chunk table declares {count} chunks, more than {compressed_bytes} bytes of data can hold"
        ));
    }
    if count == 0 {
        if layout.points > 0 {
            return Err("LAZ chunk table is empty but the header declares points".into());
        }
        return Ok(None);
    }
    let mut cur = ByteReader::new(b);
    cur.seek(SeekFrom::Start(table))
        .map_err(|e| format!("LAZ chunk table: {e}"))?;
    let entries = laz::laszip::ChunkTable::read(&mut cur, variable)
        .map_err(|e| format!("LAZ chunk table: {e}"))?;
    let entries = entries
        .as_ref()
        .iter()
        .map(|e| (e.point_count, e.byte_count))
        .collect();
    Ok(Some(ChunkTable {
        entries,
        count,
        compressed_bytes,
    }))
}

/// The chunks against the data and the header: each holds its first
/// record (and, when their sizes vary, a point), their bytes fit in the
/// compressed data, and their points are at least the header's.
fn check_chunk_points(
    table: &ChunkTable,
    layout: &Layout,
    header: &LaszipHeader,
) -> Result<(), String> {
    let record_len = layout.record_len as u64;
    let variable = header.variable();
    let mut total_bytes = 0u64;
    let mut total_points = 0u64;
    for &(points, bytes) in &table.entries {
        if bytes < record_len {
            return Err(format!(
                "LAZ chunk table: a chunk of {bytes} bytes cannot hold its first record"
            ));
        }
        total_bytes = total_bytes.saturating_add(bytes);
        if variable {
            if points == 0 {
                return Err("LAZ chunk table: a chunk of 0 points".into());
            }
            total_points = total_points.saturating_add(points);
        }
    }
    let compressed_bytes = table.compressed_bytes;
    if total_bytes > compressed_bytes {
        return Err(format!(
            "LAZ chunk table: chunks of {total_bytes} bytes in {compressed_bytes} bytes of data"
        ));
    }
    if !variable {
        total_points = table.count.saturating_mul(u64::from(header.chunk_size));
    }
    if total_points < layout.points {
        return Err(format!(
            "LAZ chunk table holds {total_points} points, the header declares {}",
            layout.points
        ));
    }
    Ok(())
}

/// For the layered formats: each chunk's layer sizes, read after its first
/// record and point count, fit in the chunk.
fn check_layers<B: LasBytes + ?Sized>(
    b: &B,
    layout: &Layout,
    items: &[Item],
    entries: &[(u64, u64)],
) -> Result<(), String> {
    let record_len = layout.record_len as u64;
    let layers: u64 = items.iter().map(|&i| item_layers(i)).sum();
    // A chunk's head: its first record, its point count, its layer sizes.
    let head = record_len + 4 + 4 * layers;
    let mut at = layout.data_start as u64 + 8;
    for &(_, bytes) in entries {
        if bytes < head {
            return Err("LAZ chunk too short for its layer sizes".into());
        }
        let sizes_at = at + record_len + 4;
        let sizes = b
            .piece(sizes_at, 4 * layers)
            .ok_or("LAZ chunk past the end of the file")?;
        let sum: u64 = sizes
            .chunks_exact(4)
            .map(|c| u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .sum();
        if sum > bytes - head {
            return Err(format!(
                "LAZ chunk declares {sum} bytes of layers in {} bytes",
                bytes - head
            ));
        }
        at += bytes;
    }
    Ok(())
}

/// `size` times `done / count`.
fn share(done: u64, count: u64, size: u64) -> u64 {
    (size as f64 * done as f64 / count.max(1) as f64) as u64
}

/// Points per batch: at most 65536, at most 16 MiB of records, and no more
/// records than the file could hold uncompressed (LAZ aside), at least 1.
fn batch_size(record_len: usize, file_len: u64) -> u64 {
    let record_len = record_len.max(1) as u64;
    let n = (16u64 << 20) / record_len;
    n.min(1 << 16).min(file_len / record_len + 1).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_stay_small() {
        assert_eq!(batch_size(20, 1 << 30), 1 << 16);
        assert_eq!(batch_size(0, 0), 1);
        assert!(batch_size(65535, 1 << 30) * 65535 <= 16 << 20);
        assert_eq!(batch_size(20, 300), 16);
    }

    #[test]
    fn fuzz_regression_huge_evlr() {
        // libFuzzer: an extended VLR of length ~2^64 made the `las` crate
        // panic ("capacity overflow").
        let bytes = include_bytes!("../../tests/fuzz_regressions/las-evlr-capacity-overflow.las");
        let e = read_las(Path::new("evlr.las"), bytes, Some(ClassSet::EMPTY), true).unwrap_err();
        assert!(
            e.to_string().starts_with("evlr.las: invalid LAS/LAZ file"),
            "{e}"
        );
    }

    #[test]
    fn fuzz_regression_gps_time_switch_recursion() {
        // libFuzzer: corrupt GPS times coded as endless "switch to another
        // time sequence"; laz 0.13 recursed once per switch and overflowed
        // the stack (SIGSEGV with a 2 MiB thread stack, this file; 8 MiB
        // for others). The vendored laz loops and gives an error. Read on
        // a thread with a 1 MiB stack so that a recursion would show.
        let bytes = include_bytes!("../../tests/fuzz_regressions/laz-gps-switch-recursion.laz");
        for attributes in [false, true] {
            let e = std::thread::Builder::new()
                .stack_size(1 << 20)
                .spawn(move || {
                    read_las(
                        Path::new("gps.laz"),
                        bytes,
                        Some(ClassSet::EMPTY),
                        attributes,
                    )
                })
                .unwrap()
                .join()
                .unwrap()
                .unwrap_err();
            assert!(
                e.to_string().contains("endless GPS time sequence switches"),
                "{e}"
            );
        }
    }

    #[test]
    fn fuzz_regression_many_extra_byte_names() {
        // libFuzzer (timeout, 39 s): a record of 16,474 bytes, 16,454 of
        // them extra bytes, each a column; their names were made unique
        // by scanning a list (quadratic, cubic for repeated names), before
        // the reader found the file has no point. Now a set (see
        // unique_names_stay_unique_and_linear): milliseconds.
        let bytes =
            include_bytes!("../../tests/fuzz_regressions/las-extra-bytes-names-timeout.las");
        let e = read_las(Path::new("names.las"), bytes, None, true).unwrap_err();
        assert!(matches!(e, IoError::NoPoints { .. }), "{e}");
    }

    #[test]
    fn unique_names_stay_unique_and_linear() {
        let mut n = super::super::las_attrs::Names::new(&["x", "y", "z"]);
        assert_eq!(n.unique("x", "f"), "x_2");
        assert_eq!(n.unique("a b", "f"), "a_b");
        assert_eq!(n.unique("  ", "f"), "f");
        assert_eq!(n.unique("a_b_2", "f"), "a_b_2");
        assert_eq!(n.unique("a b", "f"), "a_b_3");
        let all: std::collections::HashSet<String> =
            (0..65_536).map(|_| n.unique("same", "f")).collect();
        assert_eq!(all.len(), 65_536);
    }

    /// A laszip VLR's payload: compressor, coder 0, the chunk size, and
    /// the items (kind, size, version).
    fn laszip(compressor: u16, coder: u16, chunk_size: u32, items: &[Item]) -> Vec<u8> {
        let mut v = vec![0u8; 34];
        v[0..2].copy_from_slice(&compressor.to_le_bytes());
        v[2..4].copy_from_slice(&coder.to_le_bytes());
        v[12..16].copy_from_slice(&chunk_size.to_le_bytes());
        v[32..34].copy_from_slice(&(items.len() as u16).to_le_bytes());
        for &(kind, size, version) in items {
            for x in [kind, size, version] {
                v.extend_from_slice(&x.to_le_bytes());
            }
        }
        v
    }

    fn layout(record_len: usize, points: u64) -> Layout {
        Layout {
            data_start: 0,
            record_len,
            points,
            compressed: true,
            extended: false,
            scale: [1.0; 3],
            offset: [0.0; 3],
        }
    }

    #[test]
    fn laszip_header_fields_are_checked_on_their_own() {
        let h = LaszipHeader::parse(&laszip(2, 0, 50_000, &[(6, 20, 2)])).unwrap();
        assert_eq!((h.compressor, h.chunk_size), (2, 50_000));
        assert_eq!(h.items, vec![(6, 20, 2)]);
        assert!(!h.variable());
        assert!(LaszipHeader::parse(&laszip(3, 0, u32::MAX, &[(10, 30, 3)]))
            .unwrap()
            .variable());
        let err = |v: Vec<u8>| LaszipHeader::parse(&v).err().unwrap();
        assert!(err(laszip(1, 0, 0, &[(6, 20, 2)])).contains("unsupported LAZ compressor 1"));
        assert!(err(laszip(2, 1, 0, &[(6, 20, 2)])).contains("unknown LAZ coder 1"));
        assert!(err(laszip(2, 0, 0, &[])).contains("lists no items"));
        let mut short = laszip(2, 0, 0, &[(6, 20, 2), (7, 8, 2)]);
        short.truncate(36);
        assert!(err(short).contains("too short"));
    }

    #[test]
    fn chunks_must_hold_the_header_s_points_in_the_data() {
        let fixed = LaszipHeader::parse(&laszip(2, 0, 100, &[(6, 20, 2)])).unwrap();
        let variable = LaszipHeader::parse(&laszip(2, 0, 0, &[(6, 20, 2)])).unwrap();
        let table = |entries: Vec<(u64, u64)>, compressed_bytes| ChunkTable {
            count: entries.len() as u64,
            entries,
            compressed_bytes,
        };
        // Two fixed chunks of 100 points: 200 points at most.
        let two = table(vec![(0, 40), (0, 40)], 80);
        assert!(check_chunk_points(&two, &layout(20, 200), &fixed).is_ok());
        let e = check_chunk_points(&two, &layout(20, 201), &fixed).unwrap_err();
        assert!(
            e.contains("holds 200 points, the header declares 201"),
            "{e}"
        );
        let e = check_chunk_points(&table(vec![(0, 40), (0, 40)], 79), &layout(20, 1), &fixed)
            .unwrap_err();
        assert!(e.contains("chunks of 80 bytes in 79 bytes"), "{e}");
        let e = check_chunk_points(&table(vec![(0, 19)], 80), &layout(20, 1), &fixed).unwrap_err();
        assert!(e.contains("cannot hold its first record"), "{e}");
        // Variable chunks count their own points.
        let var = table(vec![(3, 40), (4, 40)], 80);
        assert!(check_chunk_points(&var, &layout(20, 7), &variable).is_ok());
        assert!(check_chunk_points(&var, &layout(20, 8), &variable).is_err());
        let e =
            check_chunk_points(&table(vec![(0, 40)], 80), &layout(20, 0), &variable).unwrap_err();
        assert!(e.contains("a chunk of 0 points"), "{e}");
    }

    #[test]
    fn layered_chunks_must_hold_their_layers() {
        // Point format 6 (one layer item of 9 layers) in records of 30
        // bytes: a chunk is its first record, a point count, 9 layer sizes
        // and the layers.
        let items = [(10, 30, 3)];
        let layers = item_layers(items[0]);
        let head = 30 + 4 + 4 * layers;
        let chunk = |sizes: u32| {
            let mut c = vec![0u8; 8 + 30 + 4];
            for _ in 0..layers {
                c.extend_from_slice(&sizes.to_le_bytes());
            }
            c
        };
        let ok = chunk(1);
        let bytes = head + layers;
        assert!(check_layers(ok.as_slice(), &layout(30, 1), &items, &[(1, bytes)]).is_ok());
        let e = check_layers(ok.as_slice(), &layout(30, 1), &items, &[(1, bytes - 1)]).unwrap_err();
        assert!(e.contains("bytes of layers in"), "{e}");
        let e = check_layers(ok.as_slice(), &layout(30, 1), &items, &[(1, head - 1)]).unwrap_err();
        assert!(e.contains("too short for its layer sizes"), "{e}");
        let cut = &ok[..ok.len() - 1];
        let e = check_layers(cut, &layout(30, 1), &items, &[(1, bytes)]).unwrap_err();
        assert!(e.contains("past the end of the file"), "{e}");
    }

    #[test]
    fn fuzz_regression_huge_record_length() {
        // libFuzzer found a header with a huge record length and point
        // count: the reader allocated 2.7 GB at once.
        let bytes = include_bytes!("../../tests/fuzz_regressions/las-oom-record-length.las");
        let _ = read_las(Path::new("oom.las"), bytes, Some(ClassSet::EMPTY), true);
    }
}
