//! LAS/LAZ files of a labelled cloud: see [`super::labelled`].

use std::io::Cursor;

use super::attributes::{AttributeType, LasSource, Values, Vlr};
use super::labelled::Labelled;
use super::las_attrs::{
    base_len, extra_bytes_vlr, extra_entry, parse_extra_fields, ExtraField, EXTRA_ENTRY_LEN,
};
use super::PointCloud;

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

fn put_u64(h: &mut [u8], at: usize, v: u64) {
    h[at..at + 8].copy_from_slice(&v.to_le_bytes());
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
    if let Some(c) = labelled.classify {
        if c & !class_mask != 0 {
            return Err(format!(
                "classification {c} does not fit point format {format} (0-31)"
            ));
        }
    }

    // VLRs: the old ones but the Extra Bytes (rebuilt in place) and the
    // laszip VLR (dropped; a new one for LAZ).
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
    let laz_vlr = if laz {
        let items =
            laz::LazItemRecordBuilder::default_for_point_format_id(format, extra as u16 + 8)
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
        Some(vlr)
    } else {
        None
    };

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

    let n = src.records.len() / old_len.max(1);
    let mut records = Vec::with_capacity(n * new_len);
    for (i, rec) in src.records.chunks_exact(old_len).enumerate() {
        let start = records.len();
        records.extend_from_slice(rec);
        let s = labelled.structure[i];
        if let (Some(c), true) = (labelled.classify, s >= 0) {
            let b = &mut records[start + class_at];
            *b = (*b & !class_mask) | c;
        }
        records.extend_from_slice(&(s as i32).to_le_bytes());
        records.extend_from_slice(&(labelled.part[i] as i32).to_le_bytes());
    }

    let mut out = Vec::with_capacity(head_len + records.len() + src.tail.len());
    out.extend_from_slice(&header);
    for v in &vlrs {
        v.to_bytes(&mut out);
    }
    out.extend_from_slice(&src.padding);
    debug_assert_eq!(out.len(), head_len);
    match laz_vlr {
        None => out.extend_from_slice(&records),
        Some(vlr) => {
            let mut cur = Cursor::new(out);
            cur.set_position(head_len as u64);
            let mut c = laz::LasZipCompressor::new(cur, vlr).map_err(|e| format!("LAZ: {e}"))?;
            c.compress_many(&records).map_err(|e| format!("LAZ: {e}"))?;
            c.done().map_err(|e| format!("LAZ: {e}"))?;
            out = c.into_inner().into_inner();
        }
    }
    // What followed the points, and the header offsets into it.
    if !src.tail.is_empty() {
        let new_start = out.len() as u64;
        let moved = |old: u64| {
            if old >= src.tail_start && old < src.tail_start + src.tail.len() as u64 {
                old - src.tail_start + new_start
            } else {
                old
            }
        };
        if header.len() >= 235 {
            let wf = get_u64(&header, 227);
            put_u64(&mut out, 227, moved(wf));
        }
        if header.len() >= 247 {
            let ev = get_u64(&header, 235);
            put_u64(&mut out, 235, moved(ev));
        }
        out.extend_from_slice(&src.tail);
    }
    Ok(out)
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
