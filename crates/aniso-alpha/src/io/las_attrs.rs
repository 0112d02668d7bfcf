//! The fields of LAS point records as typed attributes, the VLRs of a
//! file, and the Extra Bytes VLR (LAS 1.4 R15 §2.5.3: record id 4 of user
//! `LASF_Spec`, 192 bytes per described field).

use std::collections::{HashMap, HashSet};

use super::attributes::{Attribute, AttributeType, LasSource, Values, Vlr};

/// Size of the fixed part of a record of point format `format` (0–10).
pub(crate) fn base_len(format: u8) -> Option<usize> {
    Some(match format {
        0 => 20,
        1 => 28,
        2 => 26,
        3 => 34,
        4 => 57,
        5 => 63,
        6 => 30,
        7 => 36,
        8 => 38,
        9 => 59,
        10 => 67,
        _ => return None,
    })
}

/// How a record field is stored.
#[derive(Debug, Clone, Copy)]
enum Field {
    /// A whole value of this type.
    Whole(AttributeType),
    /// Bits `(byte >> shift) & mask` of one byte, as a `u8`.
    Bits(u8, u8),
}

use AttributeType as T;
use Field::{Bits, Whole};

/// The named fields of a record of point format `format` (offset, field),
/// under the names laspy gives them.
fn record_fields(format: u8) -> Vec<(&'static str, usize, Field)> {
    let mut f: Vec<(&'static str, usize, Field)> = vec![("intensity", 12, Whole(T::U16))];
    let (gps, rgb, nir, wave) = if format < 6 {
        f.extend([
            ("return_number", 14, Bits(0, 7)),
            ("number_of_returns", 14, Bits(3, 7)),
            ("scan_direction_flag", 14, Bits(6, 1)),
            ("edge_of_flight_line", 14, Bits(7, 1)),
            ("classification", 15, Bits(0, 31)),
            ("synthetic", 15, Bits(5, 1)),
            ("key_point", 15, Bits(6, 1)),
            ("withheld", 15, Bits(7, 1)),
            ("scan_angle_rank", 16, Whole(T::I8)),
            ("user_data", 17, Whole(T::U8)),
            ("point_source_id", 18, Whole(T::U16)),
        ]);
        match format {
            0 => (None, None, None, None),
            1 => (Some(20), None, None, None),
            2 => (None, Some(20), None, None),
            3 => (Some(20), Some(28), None, None),
            4 => (Some(20), None, None, Some(28)),
            _ => (Some(20), Some(28), None, Some(34)),
        }
    } else {
        f.extend([
            ("return_number", 14, Bits(0, 15)),
            ("number_of_returns", 14, Bits(4, 15)),
            ("synthetic", 15, Bits(0, 1)),
            ("key_point", 15, Bits(1, 1)),
            ("withheld", 15, Bits(2, 1)),
            ("overlap", 15, Bits(3, 1)),
            ("scanner_channel", 15, Bits(4, 3)),
            ("scan_direction_flag", 15, Bits(6, 1)),
            ("edge_of_flight_line", 15, Bits(7, 1)),
            ("classification", 16, Whole(T::U8)),
            ("user_data", 17, Whole(T::U8)),
            ("scan_angle", 18, Whole(T::I16)),
            ("point_source_id", 20, Whole(T::U16)),
        ]);
        match format {
            6 => (Some(22), None, None, None),
            7 => (Some(22), Some(30), None, None),
            8 => (Some(22), Some(30), Some(36), None),
            9 => (Some(22), None, None, Some(30)),
            _ => (Some(22), Some(30), Some(36), Some(38)),
        }
    };
    if let Some(o) = gps {
        f.push(("gps_time", o, Whole(T::F64)));
    }
    if let Some(o) = rgb {
        f.extend([
            ("red", o, Whole(T::U16)),
            ("green", o + 2, Whole(T::U16)),
            ("blue", o + 4, Whole(T::U16)),
        ]);
    }
    if let Some(o) = nir {
        f.push(("nir", o, Whole(T::U16)));
    }
    if let Some(o) = wave {
        f.extend([
            ("wavepacket_index", o, Whole(T::U8)),
            ("wavepacket_offset", o + 1, Whole(T::U64)),
            ("wavepacket_size", o + 9, Whole(T::U32)),
            ("return_point_wave_location", o + 13, Whole(T::F32)),
            ("x_t", o + 17, Whole(T::F32)),
            ("y_t", o + 21, Whole(T::F32)),
            ("z_t", o + 25, Whole(T::F32)),
        ]);
    }
    f
}

/// One field described by an Extra Bytes VLR.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ExtraField {
    /// LAS data type: 0 undocumented (`options` bytes), 1–10 u8, i8, u16,
    /// i16, u32, i32, u64, i64, f32, f64; 11–30 (deprecated) arrays of 2
    /// or 3 of those.
    pub(crate) data_type: u8,
    pub(crate) options: u8,
    /// The 32-byte name field.
    pub(crate) name: [u8; 32],
    pub(crate) scale: [f64; 3],
    pub(crate) offset: [f64; 3],
}

/// Size in bytes of one entry of an Extra Bytes VLR.
pub(crate) const EXTRA_ENTRY_LEN: usize = 192;

impl ExtraField {
    /// The scalar type and component count of a data type 1–30.
    fn scalar(&self) -> Option<(AttributeType, usize)> {
        let t = self.data_type;
        if t == 0 || t > 30 {
            return None;
        }
        let base = (t - 1) % 10;
        let ty = [
            T::U8,
            T::I8,
            T::U16,
            T::I16,
            T::U32,
            T::I32,
            T::U64,
            T::I64,
            T::F32,
            T::F64,
        ][usize::from(base)];
        Some((ty, 1 + usize::from((t - 1) / 10)))
    }

    /// Bytes this field takes in a record (`None`: an invalid data type).
    pub(crate) fn len(&self) -> Option<usize> {
        match self.data_type {
            0 => Some(usize::from(self.options)),
            _ => self.scalar().map(|(t, k)| t.size() * k),
        }
    }

    /// The name, up to the first NUL.
    pub(crate) fn name_str(&self) -> String {
        let end = self.name.iter().position(|&c| c == 0).unwrap_or(32);
        String::from_utf8_lossy(&self.name[..end]).into_owned()
    }

    /// A field of one `i32` named `name` (at most 32 bytes).
    pub(crate) fn int32(name: &str, description: &str) -> (ExtraField, [u8; 32]) {
        let mut n = [0u8; 32];
        n[..name.len().min(32)].copy_from_slice(&name.as_bytes()[..name.len().min(32)]);
        let mut d = [0u8; 32];
        d[..description.len().min(32)]
            .copy_from_slice(&description.as_bytes()[..description.len().min(32)]);
        (
            ExtraField {
                data_type: 6,
                options: 0,
                name: n,
                scale: [1.0; 3],
                offset: [0.0; 3],
            },
            d,
        )
    }

    /// `count` undocumented bytes (data type 0), named `name`.
    pub(crate) fn undocumented(count: u8, name: &str) -> ExtraField {
        let mut n = [0u8; 32];
        n[..name.len().min(32)].copy_from_slice(&name.as_bytes()[..name.len().min(32)]);
        ExtraField {
            data_type: 0,
            options: count,
            name: n,
            scale: [1.0; 3],
            offset: [0.0; 3],
        }
    }
}

/// The Extra Bytes VLR of `vlrs`, if any.
pub(crate) fn extra_bytes_vlr(vlrs: &[Vlr]) -> Option<&Vlr> {
    vlrs.iter().find(|v| v.is(b"LASF_Spec", 4))
}

/// The entries of an Extra Bytes VLR payload (a trailing partial entry is
/// ignored).
pub(crate) fn parse_extra_fields(data: &[u8]) -> Vec<ExtraField> {
    data.chunks_exact(EXTRA_ENTRY_LEN)
        .map(|e| {
            let f64s = |o: usize| {
                [0, 1, 2].map(|k| {
                    let b = &e[o + 8 * k..o + 8 * k + 8];
                    f64::from_le_bytes(b.try_into().unwrap_or([0; 8]))
                })
            };
            let mut name = [0u8; 32];
            name.copy_from_slice(&e[4..36]);
            ExtraField {
                data_type: e[2],
                options: e[3],
                name,
                scale: f64s(112),
                offset: f64s(136),
            }
        })
        .collect()
}

/// The 192-byte entry of `f` (with `description`), min/max/no-data zero.
pub(crate) fn extra_entry(f: &ExtraField, description: &[u8; 32], out: &mut Vec<u8>) {
    let start = out.len();
    out.extend_from_slice(&[0, 0, f.data_type, f.options]);
    out.extend_from_slice(&f.name);
    out.extend_from_slice(&[0; 4]); // unused
    out.extend_from_slice(&[0; 72]); // no_data, min, max
    for s in f.scale {
        out.extend_from_slice(&s.to_le_bytes());
    }
    for o in f.offset {
        out.extend_from_slice(&o.to_le_bytes());
    }
    out.extend_from_slice(description);
    debug_assert_eq!(out.len() - start, EXTRA_ENTRY_LEN);
}

/// Parses the VLRs that follow the public header: `n` of them from
/// `header_size`, ending at or before `data_start`. Returns them with the
/// bytes left before `data_start`.
pub(crate) fn parse_vlrs(
    b: &[u8],
    header_size: usize,
    n: u64,
    data_start: usize,
) -> Result<(Vec<Vlr>, Vec<u8>), String> {
    let mut vlrs = Vec::new();
    let mut pos = header_size;
    for k in 0..n {
        let head = b
            .get(pos..pos + 54)
            .filter(|_| pos + 54 <= data_start)
            .ok_or_else(|| format!("VLR {k} extends past the point data"))?;
        let len = usize::from(u16::from_le_bytes([head[20], head[21]]));
        let data = b
            .get(pos + 54..pos + 54 + len)
            .filter(|_| pos + 54 + len <= data_start)
            .ok_or_else(|| format!("VLR {k} extends past the point data"))?;
        let mut user_id = [0u8; 16];
        user_id.copy_from_slice(&head[2..18]);
        let mut description = [0u8; 32];
        description.copy_from_slice(&head[22..54]);
        vlrs.push(Vlr {
            reserved: u16::from_le_bytes([head[0], head[1]]),
            user_id,
            record_id: u16::from_le_bytes([head[18], head[19]]),
            description,
            data: data.to_vec(),
        });
        pos += 54 + len;
    }
    let padding = b.get(pos..data_start).unwrap_or_default().to_vec();
    Ok((vlrs, padding))
}

/// The column names given so far, and for each base name the next
/// suffix to try: a file of 65,000 fields of one name costs linear time
/// (a list and a scan from `_2` each time was cubic: the fuzzer's
/// timeout).
pub(crate) struct Names {
    taken: HashSet<String>,
    next: HashMap<String, usize>,
}

impl Names {
    pub(crate) fn new(taken: &[&str]) -> Names {
        Names {
            taken: taken.iter().map(|s| s.to_string()).collect(),
            next: HashMap::new(),
        }
    }

    /// A name fit for a PLY property: whitespace replaced by `_`, never
    /// empty, and unique among the names given (`_2`, `_3`… appended).
    pub(crate) fn unique(&mut self, name: &str, fallback: &str) -> String {
        let mut base: String = name
            .trim()
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        if base.is_empty() {
            base = fallback.to_string();
        }
        if self.taken.insert(base.clone()) {
            return base;
        }
        let k = self.next.entry(base.clone()).or_insert(2);
        loop {
            let out = format!("{base}_{k}");
            *k += 1;
            if self.taken.insert(out.clone()) {
                return out;
            }
        }
    }
}

/// The typed attributes of every record of `src`: the point format's
/// fields, then the extra bytes as the Extra Bytes VLR describes them
/// (scaled values as `f64`; arrays as `name_0`, `name_1`…; undocumented
/// bytes (data type 0) as `u8` columns `name_0`, `name_1`…, or, unnamed
/// or not described at all, `extra_byte_K`, K their offset in the extra
/// bytes).
pub(crate) fn record_attributes(src: &LasSource) -> Vec<Attribute> {
    let len = src.record_len;
    let n = src.records.len().checked_div(len).unwrap_or(0);
    let recs = || src.records.chunks_exact(len);
    let mut taken = Names::new(&["x", "y", "z"]);
    let mut out = Vec::new();
    for (name, o, field) in record_fields(src.point_format) {
        let name = taken.unique(name, name);
        let values = match field {
            Whole(ty) => {
                let mut v = Values::with_capacity(ty, n);
                for r in recs() {
                    v.push_bytes(&r[o..], false);
                }
                v
            }
            Bits(shift, mask) => Values::U8(recs().map(|r| (r[o] >> shift) & mask).collect()),
        };
        out.push(Attribute::new(name, values));
    }
    let Some(base) = base_len(src.point_format) else {
        return out;
    };
    let extra = len.saturating_sub(base);
    let fields = extra_bytes_vlr(&src.vlrs)
        .map(|v| parse_extra_fields(&v.data))
        .unwrap_or_default();
    let mut at = 0usize;
    let undocumented = |from: usize, to: usize, taken: &mut Names, out: &mut Vec<_>| {
        for k in from..to {
            let name = taken.unique(&format!("extra_byte_{k}"), "extra_byte");
            out.push(Attribute::new(
                name,
                Values::U8(recs().map(|r| r[base + k]).collect()),
            ));
        }
    };
    for f in &fields {
        let Some(size) = f.len() else { break };
        if at + size > extra {
            break;
        }
        match f.scalar() {
            None if f.name_str().trim().is_empty() => {
                undocumented(at, at + size, &mut taken, &mut out)
            }
            None => {
                // Named undocumented bytes: `name_0`, `name_1`…
                for k in 0..size {
                    let name = format!("{}_{k}", f.name_str());
                    let name = taken.unique(&name, "extra_byte");
                    out.push(Attribute::new(
                        name,
                        Values::U8(recs().map(|r| r[base + at + k]).collect()),
                    ));
                }
            }
            Some((ty, count)) => {
                let scaled = f.options & 0b11000 != 0;
                for c in 0..count {
                    let raw = f.name_str();
                    let name = if count == 1 {
                        raw
                    } else {
                        format!("{raw}_{c}")
                    };
                    let name = taken.unique(&name, &format!("extra_{at}"));
                    let o = base + at + c * ty.size();
                    let mut v = Values::with_capacity(ty, n);
                    for r in recs() {
                        v.push_bytes(&r[o..], false);
                    }
                    let values = if scaled {
                        let s = if f.options & 0b01000 != 0 {
                            f.scale[c]
                        } else {
                            1.0
                        };
                        let off = if f.options & 0b10000 != 0 {
                            f.offset[c]
                        } else {
                            0.0
                        };
                        Values::F64((0..n).map(|i| v.get_f64(i) * s + off).collect())
                    } else {
                        v
                    };
                    out.push(Attribute::new(name, values));
                }
            }
        }
        at += size;
    }
    undocumented(at, extra, &mut taken, &mut out);
    out
}
