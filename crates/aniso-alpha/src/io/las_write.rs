//! LAS/LAZ files of a labelled cloud: see [`super::labelled`].

use std::fs::File;
use std::io::{BufWriter, Cursor, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::atomic::PendingFile;

use super::attributes::{AttributeType, LasSource, Values, Vlr};
use super::labelled::Labelled;
use super::las_attrs::{
    base_len, extra_bytes_vlr, extra_entry, parse_extra_fields, ExtraField, EXTRA_ENTRY_LEN,
};
use super::{IoError, PointCloud};

/// `user` as a NUL-padded 16-byte user id.
fn user_id(user: &[u8]) -> [u8; 16] {
    let mut u = [0u8; 16];
    u[..user.len()].copy_from_slice(user);
    u
}

/// `text` as a NUL-padded 32-byte field (cut at 32 bytes).
fn field32(text: &str) -> [u8; 32] {
    let mut d = [0u8; 32];
    let b = text.as_bytes();
    let k = b.len().min(32);
    d[..k].copy_from_slice(&b[..k]);
    d
}

/// The Extra Bytes VLR entries for a record of `extra` extra bytes, from
/// the existing VLR payload `old`: its entries kept as they are when they
/// describe at most `extra` bytes (a field named `structure` or `part`
/// renamed `input_…`), the undescribed rest as undocumented bytes (data
/// type 0), then `structure` and `part` (`i32`).
fn extra_entries(old: Option<&[u8]>, extra: usize) -> Vec<u8> {
    let mut out = Vec::new();
    let mut described = 0usize;
    if let Some(old) = old {
        let fields = parse_extra_fields(old);
        let total: Option<usize> = fields.iter().map(ExtraField::len).sum();
        if total.is_some_and(|t| t <= extra) {
            for (f, raw) in fields.iter().zip(old.chunks_exact(EXTRA_ENTRY_LEN)) {
                let start = out.len();
                out.extend_from_slice(raw);
                let name = f.name_str();
                if name == "structure" || name == "part" {
                    out[start + 4..start + 36].copy_from_slice(&field32(&format!("input_{name}")));
                }
            }
            described = total.unwrap_or(0);
        }
    }
    let mut left = extra - described;
    while left > 0 {
        let k = left.min(255);
        let f = ExtraField::undocumented(k as u8, "");
        extra_entry(&f, &[0; 32], &mut out);
        left -= k;
    }
    for (name, what) in [
        ("structure", "aniso-alpha structure id, -1 none"),
        ("part", "aniso-alpha part id, -1 none"),
    ] {
        let (f, d) = ExtraField::int32(name, what);
        extra_entry(&f, &d, &mut out);
    }
    out
}

fn put_u16(h: &mut [u8], at: usize, v: u16) {
    h[at..at + 2].copy_from_slice(&v.to_le_bytes());
}

fn put_u32(h: &mut [u8], at: usize, v: u32) {
    h[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn get_u64(h: &[u8], at: usize) -> u64 {
    h.get(at..at + 8)
        .and_then(|b| b.try_into().ok())
        .map(u64::from_le_bytes)
        .unwrap_or(0)
}

/// The whole file: `src` with the structure and part ids appended to
/// every record (see [`super::labelled`]).
pub(crate) fn labelled_file(
    src: &LasSource,
    labelled: &Labelled<'_>,
    laz: bool,
) -> Result<Vec<u8>, String> {
    let n = src.records.len() / src.record_len.max(1);
    let mut w = LasLabeller::new(
        Cursor::new(Vec::new()),
        src,
        n as u64,
        laz,
        labelled.classify,
    )?;
    w.append(&src.records, labelled.structure, labelled.part)?;
    Ok(w.finish()?.into_inner())
}

/// Where a labeller's records go: the file itself (LAS) or a LAZ
/// compressor writing into it.
enum Sink<W: Write + Seek + Send + Sync + 'static> {
    Las(W),
    Laz(Box<laz::LasZipCompressor<'static, W>>),
}

/// Writes a labelled copy of a LAS/LAZ file into `W` a range of records
/// at a time: the header and VLRs of the source with the Extra Bytes VLR
/// extended by `structure` and `part` (int32), each record copied byte for
/// byte with the two ids appended (and `classify` as the structures'
/// classification), then what followed the points in the source.
pub(crate) struct LasLabeller<W: Write + Seek + Send + Sync + 'static> {
    sink: Sink<W>,
    /// The header as written (its offsets into the trailing data are
    /// updated when that data is written).
    header: Vec<u8>,
    tail_start: u64,
    tail: Vec<u8>,
    old_len: usize,
    new_len: usize,
    class_at: usize,
    class_mask: u8,
    classify: Option<u8>,
    /// Records expected and records written.
    points: u64,
    written: u64,
    records: Vec<u8>,
}

impl<W: Write + Seek + Send + Sync + 'static> LasLabeller<W> {
    /// Writes the header and VLRs of `src`'s labelled copy into `out` (at
    /// its current position, which must be 0) for `points` records.
    pub(crate) fn new(
        mut out: W,
        src: &LasSource,
        points: u64,
        laz: bool,
        classify: Option<u8>,
    ) -> Result<Self, String> {
        let format = src.point_format;
        let base = base_len(format).ok_or_else(|| format!("unknown LAS point format {format}"))?;
        let old_len = src.record_len;
        let extra = old_len
            .checked_sub(base)
            .ok_or("record length shorter than the point format")?;
        let new_len = old_len + 8;
        let new_len16 =
            u16::try_from(new_len).map_err(|_| format!("record length {new_len} exceeds 65535"))?;
        if src.header.len() < 227 {
            return Err("LAS header shorter than 227 bytes".into());
        }
        // The classification byte and its mask.
        let (class_at, class_mask) = if format >= 6 { (16, 0xFF) } else { (15, 0x1F) };
        if let Some(c) = classify {
            if c & !class_mask != 0 {
                return Err(format!(
                    "classification {c} does not fit point format {format} (0-31)"
                ));
            }
        }
        let (vlrs, laz_vlr) = labelled_vlrs(src, format, extra, laz)?;
        let mut header = src.header.clone();
        let mut head_len = header.len();
        for v in &vlrs {
            head_len += 54 + v.data.len();
        }
        head_len += src.padding.len();
        let data_start = u32::try_from(head_len).map_err(|_| "header and VLRs exceed 4 GiB")?;
        put_u32(&mut header, 96, data_start);
        put_u32(&mut header, 100, vlrs.len() as u32);
        header[104] = format | if laz { 0x80 } else { 0 };
        put_u16(&mut header, 105, new_len16);

        let mut head = Vec::with_capacity(head_len);
        head.extend_from_slice(&header);
        for v in &vlrs {
            v.to_bytes(&mut head);
        }
        head.extend_from_slice(&src.padding);
        debug_assert_eq!(head.len(), head_len);
        out.write_all(&head).map_err(|e| e.to_string())?;
        let sink = match laz_vlr {
            None => Sink::Las(out),
            Some(vlr) => Sink::Laz(Box::new(
                laz::LasZipCompressor::new(out, vlr).map_err(|e| format!("LAZ: {e}"))?,
            )),
        };
        Ok(LasLabeller {
            sink,
            header,
            tail_start: src.tail_start,
            tail: src.tail.clone(),
            old_len,
            new_len,
            class_at,
            class_mask,
            classify,
            points,
            written: 0,
            records: Vec::new(),
        })
    }

    /// Appends `records` (the source's, in file order after those already
    /// written) with one structure and part id each.
    pub(crate) fn append(
        &mut self,
        records: &[u8],
        structure: &[i64],
        part: &[i64],
    ) -> Result<(), String> {
        let n = records.len() / self.old_len.max(1);
        if records.len() != n * self.old_len || structure.len() != n || part.len() != n {
            return Err(format!(
                "{} bytes of {}-byte records with {} structure and {} part ids",
                records.len(),
                self.old_len,
                structure.len(),
                part.len()
            ));
        }
        if self.written + n as u64 > self.points {
            return Err(format!(
                "{} records past the {} the header declares",
                self.written + n as u64,
                self.points
            ));
        }
        self.records.clear();
        self.records.reserve(n * self.new_len);
        for (i, rec) in records.chunks_exact(self.old_len).enumerate() {
            let start = self.records.len();
            self.records.extend_from_slice(rec);
            let s = structure[i];
            if let (Some(c), true) = (self.classify, s >= 0) {
                let b = &mut self.records[start + self.class_at];
                *b = (*b & !self.class_mask) | c;
            }
            self.records.extend_from_slice(&(s as i32).to_le_bytes());
            self.records
                .extend_from_slice(&(part[i] as i32).to_le_bytes());
        }
        match &mut self.sink {
            Sink::Las(w) => w.write_all(&self.records).map_err(|e| e.to_string())?,
            Sink::Laz(c) => c
                .compress_many(&self.records)
                .map_err(|e| format!("LAZ: {e}"))?,
        }
        self.written += n as u64;
        Ok(())
    }

    /// Ends the points (a LAZ file's chunk table), writes what followed
    /// them in the source and the header's offsets into it; gives back
    /// the writer. Every declared record must have been appended.
    pub(crate) fn finish(self) -> Result<W, String> {
        if self.written != self.points {
            return Err(format!(
                "{} records written, the header declares {}",
                self.written, self.points
            ));
        }
        let io = |e: std::io::Error| e.to_string();
        let mut out = match self.sink {
            Sink::Las(w) => w,
            Sink::Laz(mut c) => {
                c.done().map_err(|e| format!("LAZ: {e}"))?;
                let mut w = c.into_inner();
                w.seek(SeekFrom::End(0)).map_err(io)?;
                w
            }
        };
        if !self.tail.is_empty() {
            let new_start = out.stream_position().map_err(io)?;
            out.write_all(&self.tail).map_err(io)?;
            let moved = |old: u64| {
                if old >= self.tail_start && old < self.tail_start + self.tail.len() as u64 {
                    old - self.tail_start + new_start
                } else {
                    old
                }
            };
            for (at, min_len) in [(227, 235), (235, 247)] {
                if self.header.len() >= min_len {
                    out.seek(SeekFrom::Start(at as u64)).map_err(io)?;
                    out.write_all(&moved(get_u64(&self.header, at)).to_le_bytes())
                        .map_err(io)?;
                }
            }
            out.seek(SeekFrom::End(0)).map_err(io)?;
        }
        out.flush().map_err(io)?;
        Ok(out)
    }
}

/// A labelled copy of a LAS/LAZ file written a range of points at a time,
/// for a file larger than memory read with [`super::read_las_range`]:
/// the same file as [`super::write_labelled_cloud`] writes of the whole
/// cloud (LAZ for a `.laz` path), without ever holding its records.
/// Written atomically: the output appears complete at
/// [`LasLabelWriter::finish`], or not at all (dropping the writer before
/// removes the temporary file).
///
/// ```
/// use aniso_alpha::io::{read_las_range, read_points, LasLabelWriter, ReadOptions};
/// let dir = std::env::temp_dir().join(format!("las-label-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let input = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/las/simple.las");
/// let options = ReadOptions { attributes: true, ..ReadOptions::default() };
/// let first = read_las_range(&input, 0, 1000, &options)?;
/// let rest = read_las_range(&input, 1000, u64::MAX, &options)?;
/// let out = dir.join("labelled.laz");
/// let mut w = LasLabelWriter::create(&out, first.las.as_deref().unwrap(), 1065, Some(6))?;
/// for piece in [&first, &rest] {
///     let ids = vec![0i64; piece.points.len()];
///     w.append(&piece.las.as_ref().unwrap().records, &ids, &ids)?;
/// }
/// w.finish()?;
/// assert_eq!(read_points(&out, &ReadOptions::default())?.points.len(), 1065);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok::<(), aniso_alpha::io::IoError>(())
/// ```
pub struct LasLabelWriter {
    inner: LasLabeller<BufWriter<File>>,
    pending: PendingFile,
    path: PathBuf,
}

impl LasLabelWriter {
    /// Starts the labelled copy of `source` (the header, VLRs and trailing
    /// data of a LAS/LAZ file as read; its records are not used) at
    /// `path`, for `points` records (the source file's count); LAZ when
    /// `path` ends in `.laz`. `classify` is the LAS classification given
    /// to the structures' points.
    pub fn create(
        path: &Path,
        source: &LasSource,
        points: u64,
        classify: Option<u8>,
    ) -> Result<LasLabelWriter, IoError> {
        let laz = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("laz"));
        let (pending, file) = PendingFile::create(path)?;
        let out = BufWriter::with_capacity(1 << 20, file);
        let inner = LasLabeller::new(out, source, points, laz, classify)
            .map_err(|m| write_error(path, m))?;
        Ok(LasLabelWriter {
            inner,
            pending,
            path: path.to_path_buf(),
        })
    }

    /// Appends the next `records` of the source (in file order, the
    /// source's record length each) with one structure and part id each.
    pub fn append(
        &mut self,
        records: &[u8],
        structure: &[i64],
        part: &[i64],
    ) -> Result<(), IoError> {
        self.inner
            .append(records, structure, part)
            .map_err(|m| write_error(&self.path, m))
    }

    /// Completes the file (every declared record must have been appended)
    /// and moves it onto the output path.
    pub fn finish(self) -> Result<(), IoError> {
        let out = self
            .inner
            .finish()
            .map_err(|m| write_error(&self.path, m))?;
        let file = out.into_inner().map_err(|e| IoError::Write {
            path: self.path.clone(),
            source: e.into_error(),
        })?;
        self.pending.commit(file)
    }
}

/// An [`IoError::Write`] of `path` with `message`.
fn write_error(path: &Path, message: String) -> IoError {
    IoError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
    }
}

/// The VLRs of a labelled copy: the source's but the Extra Bytes (rebuilt
/// in place) and the laszip VLR (dropped; a new one for LAZ, returned).
fn labelled_vlrs(
    src: &LasSource,
    format: u8,
    extra: usize,
    laz: bool,
) -> Result<(Vec<Vlr>, Option<laz::LazVlr>), String> {
    let old_eb = extra_bytes_vlr(&src.vlrs).map(|v| v.data.as_slice());
    let eb = extra_entries(old_eb, extra);
    if eb.len() > usize::from(u16::MAX) {
        return Err("too many extra-bytes fields for one VLR".into());
    }
    let eb_vlr = Vlr {
        reserved: 0,
        user_id: user_id(b"LASF_Spec"),
        record_id: 4,
        description: field32("Extra Bytes"),
        data: eb,
    };
    let mut vlrs: Vec<Vlr> = Vec::with_capacity(src.vlrs.len() + 2);
    let mut placed = false;
    for v in &src.vlrs {
        if v.is(b"laszip encoded", 22204) {
            continue;
        }
        if v.is(b"LASF_Spec", 4) {
            if !placed {
                vlrs.push(eb_vlr.clone());
                placed = true;
            }
            continue;
        }
        vlrs.push(v.clone());
    }
    if !placed {
        vlrs.push(eb_vlr);
    }
    if !laz {
        return Ok((vlrs, None));
    }
    let items = laz::LazItemRecordBuilder::default_for_point_format_id(format, extra as u16 + 8)
        .map_err(|e| format!("LAZ: {e}"))?;
    let vlr = laz::LazVlr::from_laz_items(items);
    let mut data = Vec::new();
    vlr.write_to(&mut data).map_err(|e| e.to_string())?;
    vlrs.push(Vlr {
        reserved: 0,
        user_id: user_id(b"laszip encoded"),
        record_id: 22204,
        description: field32("laz-rs"),
        data,
    });
    Ok((vlrs, Some(vlr)))
}

/// LAS type code (1–10) of an attribute type.
fn las_type(t: AttributeType) -> u8 {
    match t {
        AttributeType::U8 => 1,
        AttributeType::I8 => 2,
        AttributeType::U16 => 3,
        AttributeType::I16 => 4,
        AttributeType::U32 => 5,
        AttributeType::I32 => 6,
        AttributeType::U64 => 7,
        AttributeType::I64 => 8,
        AttributeType::F32 => 9,
        AttributeType::F64 => 10,
    }
}

/// The LAS names of point format 0's fields (laspy's), which an extra-bytes
/// field may not take.
const FORMAT0_NAMES: [&str; 18] = [
    "X",
    "Y",
    "Z",
    "x",
    "y",
    "z",
    "intensity",
    "return_number",
    "number_of_returns",
    "scan_direction_flag",
    "edge_of_flight_line",
    "classification",
    "synthetic",
    "key_point",
    "withheld",
    "scan_angle_rank",
    "user_data",
    "point_source_id",
];

/// A LAS 1.2 file of point format 0 holding a cloud read from another
/// format: coordinates quantised to one power-of-ten scale (the finest,
/// down to 1e-9, at which the extent fits 32-bit integers, offsets at the
/// bounding box's corner), every point return 1 of 1; attributes
/// `intensity`, `classification` (values 0–31), `user_data` and
/// `point_source_id` of the LAS type go to the record's field, every other
/// attribute to a typed extra-bytes field (a name of a format 0 field
/// prefixed `input_`).
pub(crate) fn source_from_points(cloud: &PointCloud) -> Result<LasSource, String> {
    let n = cloud.points.len();
    let legacy = u32::try_from(n).map_err(|_| format!("{n} points exceed LAS 1.2's 2^32 - 1"))?;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &cloud.points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if n == 0 {
        lo = [0.0; 3];
        hi = [0.0; 3];
    }
    let offset = lo.map(f64::floor);
    let extent = (0..3).map(|k| hi[k] - offset[k]).fold(0.0f64, f64::max);
    let mut scale = 1e-9f64;
    let mut e = -9i32;
    while extent / scale > 2.0e9 {
        e += 1;
        scale = 10f64.powi(e);
        if e > 300 {
            return Err("coordinates too large for LAS".into());
        }
    }

    // Which attributes go to the record, which to extra bytes.
    let mut record_field: [Option<usize>; 4] = [None; 4]; // intensity, class, user data, source id
    let mut extras: Vec<(usize, String)> = Vec::new();
    for (ai, a) in cloud.attributes.iter().enumerate() {
        let t = a.values.ty();
        let slot = match (a.name.as_str(), t) {
            ("intensity", AttributeType::U16) => Some(0),
            ("classification", AttributeType::U8) if matches!(&a.values, Values::U8(v) if v.iter().all(|&c| c < 32)) => {
                Some(1)
            }
            ("user_data", AttributeType::U8) => Some(2),
            ("point_source_id", AttributeType::U16) => Some(3),
            _ => None,
        };
        match slot {
            Some(s) if record_field[s].is_none() => record_field[s] = Some(ai),
            _ => {
                let name = if FORMAT0_NAMES.contains(&a.name.as_str())
                    || a.name == "structure"
                    || a.name == "part"
                {
                    format!("input_{}", a.name)
                } else {
                    a.name.clone()
                };
                extras.push((ai, name));
            }
        }
    }
    let extra: usize = extras
        .iter()
        .map(|(ai, _)| cloud.attributes[*ai].values.ty().size())
        .sum();
    let record_len = 20 + extra;
    let mut eb = Vec::new();
    for (ai, name) in &extras {
        let f = ExtraField {
            data_type: las_type(cloud.attributes[*ai].values.ty()),
            options: 0,
            name: field32(name),
            scale: [1.0; 3],
            offset: [0.0; 3],
        };
        extra_entry(&f, &[0; 32], &mut eb);
    }
    let mut vlrs = Vec::new();
    if !eb.is_empty() {
        vlrs.push(Vlr {
            reserved: 0,
            user_id: user_id(b"LASF_Spec"),
            record_id: 4,
            description: field32("Extra Bytes"),
            data: eb,
        });
    }

    let mut records = Vec::with_capacity(n * record_len);
    let mut qlo = [i32::MAX; 3];
    let mut qhi = [i32::MIN; 3];
    for (i, p) in cloud.points.iter().enumerate() {
        for k in 0..3 {
            let q = ((p[k] - offset[k]) / scale).round();
            let q = q.clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
            qlo[k] = qlo[k].min(q);
            qhi[k] = qhi[k].max(q);
            records.extend_from_slice(&q.to_le_bytes());
        }
        let get = |s: usize| record_field[s].map(|ai| cloud.attributes[ai].values.get_f64(i));
        records.extend_from_slice(&(get(0).unwrap_or(0.0) as u16).to_le_bytes());
        records.push(0b0000_1001); // return 1 of 1
        records.push(get(1).unwrap_or(0.0) as u8);
        records.push(0); // scan angle rank
        records.push(get(2).unwrap_or(0.0) as u8);
        records.extend_from_slice(&(get(3).unwrap_or(0.0) as u16).to_le_bytes());
        for (ai, _) in &extras {
            cloud.attributes[*ai].values.write_le(i, &mut records);
        }
    }

    let mut h = vec![0u8; 227];
    h[0..4].copy_from_slice(b"LASF");
    h[24] = 1;
    h[25] = 2;
    h[26..58].copy_from_slice(&field32("OTHER"));
    h[58..90].copy_from_slice(&field32("aniso-alpha"));
    put_u16(&mut h, 94, 227);
    h[104] = 0;
    put_u16(&mut h, 105, record_len as u16);
    put_u32(&mut h, 107, legacy);
    put_u32(&mut h, 111, legacy); // points by return: all first returns
    for k in 0..3 {
        h[131 + 8 * k..139 + 8 * k].copy_from_slice(&scale.to_le_bytes());
        h[155 + 8 * k..163 + 8 * k].copy_from_slice(&offset[k].to_le_bytes());
        let (a, b) = if n == 0 {
            (0.0, 0.0)
        } else {
            (
                f64::from(qhi[k]) * scale + offset[k],
                f64::from(qlo[k]) * scale + offset[k],
            )
        };
        h[179 + 16 * k..187 + 16 * k].copy_from_slice(&a.to_le_bytes());
        h[187 + 16 * k..195 + 16 * k].copy_from_slice(&b.to_le_bytes());
    }
    Ok(LasSource {
        header: h,
        vlrs,
        padding: Vec::new(),
        point_format: 0,
        record_len,
        records,
        tail_start: 0,
        tail: Vec::new(),
    })
}
