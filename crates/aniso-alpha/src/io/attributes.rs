//! The per-point attribute table of a [`super::PointCloud`]: every property a
//! file gives its points besides x, y, z (colours, normals, intensity,
//! classification, GPS time, a PLY property, a PCD field, a LAS record
//! field or extra bytes), each a typed column in the file's own type.

/// The type of an attribute's values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AttributeType {
    /// `i8`.
    I8,
    /// `u8`.
    U8,
    /// `i16`.
    I16,
    /// `u16`.
    U16,
    /// `i32`.
    I32,
    /// `u32`.
    U32,
    /// `i64`.
    I64,
    /// `u64`.
    U64,
    /// `f32`.
    F32,
    /// `f64`.
    F64,
}

impl AttributeType {
    /// Size of one value in bytes.
    pub fn size(self) -> usize {
        match self {
            AttributeType::I8 | AttributeType::U8 => 1,
            AttributeType::I16 | AttributeType::U16 => 2,
            AttributeType::I32 | AttributeType::U32 | AttributeType::F32 => 4,
            AttributeType::I64 | AttributeType::U64 | AttributeType::F64 => 8,
        }
    }
}

/// One attribute's values, one per point, in the file's type.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub enum Values {
    I8(Vec<i8>),
    U8(Vec<u8>),
    I16(Vec<i16>),
    U16(Vec<u16>),
    I32(Vec<i32>),
    U32(Vec<u32>),
    I64(Vec<i64>),
    U64(Vec<u64>),
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// Applies `$body` to the vector inside any [`Values`] variant.
macro_rules! each {
    ($v:expr, $x:ident => $body:expr) => {
        match $v {
            Values::I8($x) => $body,
            Values::U8($x) => $body,
            Values::I16($x) => $body,
            Values::U16($x) => $body,
            Values::I32($x) => $body,
            Values::U32($x) => $body,
            Values::I64($x) => $body,
            Values::U64($x) => $body,
            Values::F32($x) => $body,
            Values::F64($x) => $body,
        }
    };
}

/// Like `each!`, rebuilding the same variant from `$body`.
macro_rules! map_same {
    ($v:expr, $x:ident => $body:expr) => {
        match $v {
            Values::I8($x) => Values::I8($body),
            Values::U8($x) => Values::U8($body),
            Values::I16($x) => Values::I16($body),
            Values::U16($x) => Values::U16($body),
            Values::I32($x) => Values::I32($body),
            Values::U32($x) => Values::U32($body),
            Values::I64($x) => Values::I64($body),
            Values::U64($x) => Values::U64($body),
            Values::F32($x) => Values::F32($body),
            Values::F64($x) => Values::F64($body),
        }
    };
}

impl Values {
    /// An empty column of type `ty` with room for `n` values.
    pub fn with_capacity(ty: AttributeType, n: usize) -> Values {
        match ty {
            AttributeType::I8 => Values::I8(Vec::with_capacity(n)),
            AttributeType::U8 => Values::U8(Vec::with_capacity(n)),
            AttributeType::I16 => Values::I16(Vec::with_capacity(n)),
            AttributeType::U16 => Values::U16(Vec::with_capacity(n)),
            AttributeType::I32 => Values::I32(Vec::with_capacity(n)),
            AttributeType::U32 => Values::U32(Vec::with_capacity(n)),
            AttributeType::I64 => Values::I64(Vec::with_capacity(n)),
            AttributeType::U64 => Values::U64(Vec::with_capacity(n)),
            AttributeType::F32 => Values::F32(Vec::with_capacity(n)),
            AttributeType::F64 => Values::F64(Vec::with_capacity(n)),
        }
    }

    /// The type of the values.
    pub fn ty(&self) -> AttributeType {
        match self {
            Values::I8(_) => AttributeType::I8,
            Values::U8(_) => AttributeType::U8,
            Values::I16(_) => AttributeType::I16,
            Values::U16(_) => AttributeType::U16,
            Values::I32(_) => AttributeType::I32,
            Values::U32(_) => AttributeType::U32,
            Values::I64(_) => AttributeType::I64,
            Values::U64(_) => AttributeType::U64,
            Values::F32(_) => AttributeType::F32,
            Values::F64(_) => AttributeType::F64,
        }
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        each!(self, v => v.len())
    }

    /// Whether there is no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i` as an `f64` (exact for every type but 64-bit integers
    /// beyond 2^53).
    #[allow(clippy::unnecessary_cast)] // `as f64` is a no-op for the F64 arm
    pub fn get_f64(&self, i: usize) -> f64 {
        each!(self, v => v[i] as f64)
    }

    /// Appends a value decoded from `b` (at least `ty().size()` bytes,
    /// little-endian unless `big`).
    #[inline]
    pub(crate) fn push_bytes(&mut self, b: &[u8], big: bool) {
        macro_rules! push {
            ($v:expr, $t:ty, $n:literal) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                $v.push(if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                })
            }};
        }
        match self {
            Values::I8(v) => push!(v, i8, 1),
            Values::U8(v) => push!(v, u8, 1),
            Values::I16(v) => push!(v, i16, 2),
            Values::U16(v) => push!(v, u16, 2),
            Values::I32(v) => push!(v, i32, 4),
            Values::U32(v) => push!(v, u32, 4),
            Values::I64(v) => push!(v, i64, 8),
            Values::U64(v) => push!(v, u64, 8),
            Values::F32(v) => push!(v, f32, 4),
            Values::F64(v) => push!(v, f64, 8),
        }
    }

    /// Appends `x` converted to the column's type (the caller checked that
    /// it fits: an integer type's range, see `ply::Scalar::parse`).
    pub(crate) fn push_f64(&mut self, x: f64) {
        match self {
            Values::I8(v) => v.push(x as i8),
            Values::U8(v) => v.push(x as u8),
            Values::I16(v) => v.push(x as i16),
            Values::U16(v) => v.push(x as u16),
            Values::I32(v) => v.push(x as i32),
            Values::U32(v) => v.push(x as u32),
            Values::I64(v) => v.push(x as i64),
            Values::U64(v) => v.push(x as u64),
            Values::F32(v) => v.push(x as f32),
            Values::F64(v) => v.push(x),
        }
    }

    /// Appends value `i` in little-endian bytes to `out`.
    #[inline]
    pub(crate) fn write_le(&self, i: usize, out: &mut Vec<u8>) {
        each!(self, v => out.extend_from_slice(&v[i].to_le_bytes()))
    }

    /// The values at `indices`, in that order.
    pub fn select(&self, indices: &[u32]) -> Values {
        map_same!(self, v => indices.iter().map(|&i| v[i as usize]).collect())
    }
}

/// A named per-point attribute.
///
/// ```
/// use aniso_alpha::io::{Attribute, AttributeType, Values};
/// let a = Attribute::new("intensity", Values::U16(vec![7, 300]));
/// assert_eq!(a.values.ty(), AttributeType::U16);
/// assert_eq!(a.values.get_f64(1), 300.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// The name in the file (PLY property, PCD field, LAS field or extra
    /// bytes name; see the README's Formats section for LAS names).
    pub name: String,
    /// One value per point.
    pub values: Values,
}

impl Attribute {
    /// An attribute.
    pub fn new(name: impl Into<String>, values: Values) -> Attribute {
        Attribute {
            name: name.into(),
            values,
        }
    }
}

/// A variable-length record of a LAS file, as in the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Vlr {
    /// The reserved field.
    pub reserved: u16,
    /// The user id (NUL-padded).
    pub user_id: [u8; 16],
    /// The record id.
    pub record_id: u16,
    /// The description (NUL-padded).
    pub description: [u8; 32],
    /// The payload.
    pub data: Vec<u8>,
}

impl Vlr {
    /// Whether the user id is `user` (up to the first NUL).
    pub fn is(&self, user: &[u8], record_id: u16) -> bool {
        let end = self.user_id.iter().position(|&c| c == 0).unwrap_or(16);
        &self.user_id[..end] == user && self.record_id == record_id
    }

    /// The 54-byte VLR header followed by the payload (the LAS writer's).
    #[cfg_attr(not(feature = "las"), allow(dead_code))]
    pub(crate) fn to_bytes(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.reserved.to_le_bytes());
        out.extend_from_slice(&self.user_id);
        out.extend_from_slice(&self.record_id.to_le_bytes());
        out.extend_from_slice(&(self.data.len() as u16).to_le_bytes());
        out.extend_from_slice(&self.description);
        out.extend_from_slice(&self.data);
    }
}

/// The parts of a LAS/LAZ file a cloud was read from, as in the file
/// (records decompressed), kept with [`super::ReadOptions::attributes`] so
/// that a LAS output copies every point record byte for byte.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LasSource {
    /// The public header block.
    pub header: Vec<u8>,
    /// The VLRs in file order (a LAZ file's laszip VLR included).
    pub vlrs: Vec<Vlr>,
    /// Bytes between the last VLR and the point data (user-defined).
    pub padding: Vec<u8>,
    /// Point data format, 0–10 (compression bits cleared).
    pub point_format: u8,
    /// Point record length in bytes.
    pub record_len: usize,
    /// The point records, `record_len` bytes each, in file order.
    pub records: Vec<u8>,
    /// Where the file's data after the points (extended VLRs, or the
    /// LAS 1.3 waveform record) started, if any.
    pub tail_start: u64,
    /// That data, as in the file.
    pub tail: Vec<u8>,
}

/// Values reserved over all attribute columns before a reader has seen
/// the data: 2^24 (128 MiB of `f64` at most).
const RESERVE_TOTAL: usize = 1 << 24;

/// Values to reserve in each of `columns` attribute columns for `count`
/// declared records: at most 2^20 per column and [`RESERVE_TOTAL`] over
/// all of them, so that a header's claims (a large count, thousands of
/// fields) cannot reserve more than that; past it the columns grow with
/// the data actually read (issue 19).
pub(crate) fn reserve_per_column(count: usize, columns: usize) -> usize {
    count.min(1 << 20).min(RESERVE_TOTAL / columns.max(1))
}

#[cfg(test)]
mod reserve_tests {
    use super::reserve_per_column;

    #[test]
    fn reservations_are_bounded_whatever_the_header_claims() {
        assert_eq!(reserve_per_column(1000, 5), 1000);
        assert_eq!(reserve_per_column(usize::MAX, 1), 1 << 20);
        assert_eq!(reserve_per_column(10_000_000, 4000), (1 << 24) / 4000);
        assert_eq!(reserve_per_column(10, 0), 10);
        for columns in [1, 3, 16, 1000, 100_000] {
            assert!(reserve_per_column(usize::MAX, columns) * columns <= 1 << 24);
        }
    }
}
