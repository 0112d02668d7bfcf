//! E57 reader through the `e57` crate (cargo feature `e57`).
//!
//! Every point cloud ("scan", `data3D` child) of the file is read, in file
//! order, through the crate's raw iterator; each point is taken from its
//! Cartesian coordinates, or from its spherical ones when the scan has no
//! Cartesian coordinates, and moved by the scan's pose into the file's
//! coordinate system (as libE57Format and the crate's simple reader do).
//! Points whose coordinates are flagged invalid (or a direction only) are
//! skipped, with a [`ReadWarning::SkippedPoints`].
//!
//! With attributes, every other field of the scans' prototype becomes a
//! column in its own type: an integer field in the smallest integer type
//! that holds its declared range (colours of 0–255 are `u8`), a scaled
//! integer as `f64` (scale and offset applied), a float as `f32` or `f64`.
//! The standard fields are named as the other readers name them
//! (`intensity`, `red`, `green`, `blue`), the rest by their E57 names
//! (`rowIndex`, `timeStamp`, `isColorInvalid`, an extension's field by its
//! own name). A file of several scans adds a `scan` column (its index) and
//! keeps the columns every scan has with one type.
//!
//! Hostile files: the crate checks each 1 KiB page's CRC and bounds its
//! XML; what it trusts for time and memory is the declared point count,
//! capped here at [`MAX_POINTS_PER_BYTE`] times the file size. A panic
//! inside the crate is caught at this boundary and becomes an
//! [`IoError::Format`].

use std::io::Cursor;
use std::path::Path;

use e57::{E57Reader, RecordDataType, RecordName, RecordValue};

use super::attributes::{Attribute, AttributeType, Values};
use super::{check_finite, non_empty, IoError, PointCloud, ReadWarning};

/// The largest accepted ratio of declared points to file bytes. A point
/// needs at least a few bits in any real file (x, y and z are never all
/// constant); a larger count is refused before anything is allocated.
pub(crate) const MAX_POINTS_PER_BYTE: u64 = 64;

/// Which coordinates a scan's points come from: the prototype indices.
enum Coordinates {
    /// x, y, z and the optional `cartesianInvalidState`.
    Cartesian([usize; 3], Option<usize>),
    /// range, azimuth, elevation and the optional `sphericalInvalidState`.
    Spherical([usize; 3], Option<usize>),
}

/// One kept field of a scan: its prototype index and column.
struct Column {
    index: usize,
    data_type: RecordDataType,
    attribute: Attribute,
}

/// Reads an E57 file held in memory; with `attributes`, every point field
/// besides the coordinates is kept in [`PointCloud::attributes`].
pub(crate) fn read_e57(path: &Path, bytes: &[u8], attributes: bool) -> Result<PointCloud, IoError> {
    let bad = |m: String| IoError::format(path, format!("invalid E57 file: {m}"));
    precheck(bytes).map_err(bad)?;
    let mut reader =
        contain(path, || E57Reader::new(Cursor::new(bytes)))?.map_err(|e| bad(e.to_string()))?;
    let scans = reader.pointclouds();
    if scans.is_empty() {
        return Err(bad("no point cloud (data3D) in the file".into()));
    }
    let declared = scans
        .iter()
        .fold(0u64, |s, pc| s.saturating_add(pc.records));
    let limit = (bytes.len() as u64).saturating_mul(MAX_POINTS_PER_BYTE);
    if declared > limit {
        return Err(bad(format!(
            "{declared} points declared in a file of {} bytes (more than {MAX_POINTS_PER_BYTE} per byte)",
            bytes.len()
        )));
    }
    let cap = usize::try_from(declared).unwrap_or(usize::MAX);
    let mut cloud = PointCloud::default();
    cloud.points.reserve(cap);
    let mut columns: Option<Vec<Attribute>> = None;
    let mut skipped = 0u64;
    for (s, pc) in scans.iter().enumerate() {
        let coords = coordinates(&pc.prototype).ok_or_else(|| {
            bad(format!(
                "scan {s} has neither Cartesian nor spherical coordinates"
            ))
        })?;
        let mut kept: Vec<Column> = if attributes {
            scan_columns(&pc.prototype, &coords, cap)
        } else {
            Vec::new()
        };
        let pose = pc.transform.as_ref().map(|t| {
            Pose::new(
                [t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z],
                [t.translation.x, t.translation.y, t.translation.z],
            )
        });
        let mut iter = contain(path, || reader.pointcloud_raw(pc))?
            .map_err(|e| bad(format!("scan {s}: {e}")))?;
        let start = cloud.points.len();
        let mut read = 0u64;
        loop {
            let Some(values) = contain(path, || iter.next())? else {
                break;
            };
            let values = values.map_err(|e| {
                bad(format!(
                    "scan {s}: data corrupt or truncated after {read} of {} points: {e}",
                    pc.records
                ))
            })?;
            read += 1;
            let at = |i: usize| {
                values
                    .get(i)
                    .and_then(|v| to_f64(v, &pc.prototype[i].data_type))
                    .ok_or_else(|| bad(format!("scan {s}: point {read} lacks field {i}")))
            };
            let p = match &coords {
                Coordinates::Cartesian(xyz, state) => {
                    if let Some(i) = *state {
                        if at(i)? != 0.0 {
                            skipped += 1;
                            continue;
                        }
                    }
                    [at(xyz[0])?, at(xyz[1])?, at(xyz[2])?]
                }
                Coordinates::Spherical(rae, state) => {
                    if let Some(i) = *state {
                        if at(i)? != 0.0 {
                            skipped += 1;
                            continue;
                        }
                    }
                    let (r, az, el) = (at(rae[0])?, at(rae[1])?, at(rae[2])?);
                    [
                        r * el.cos() * az.cos(),
                        r * el.cos() * az.sin(),
                        r * el.sin(),
                    ]
                }
            };
            let p = pose.as_ref().map_or(p, |q| q.apply(p));
            check_finite(path, &p, cloud.points.len(), None)?;
            cloud.points.push(p);
            for c in &mut kept {
                push_value(&mut c.attribute.values, &values[c.index], &c.data_type).map_err(
                    |m| {
                        bad(format!(
                            "scan {s}, point {read}, field '{}': {m}",
                            c.attribute.name
                        ))
                    },
                )?;
            }
        }
        if attributes {
            let mut these: Vec<Attribute> = kept.into_iter().map(|c| c.attribute).collect();
            if scans.len() > 1 {
                let n = cloud.points.len() - start;
                these.push(Attribute::new(
                    "scan",
                    Values::U32(vec![u32::try_from(s).unwrap_or(u32::MAX); n]),
                ));
            }
            columns = Some(match columns.take() {
                None => these,
                Some(mut all) => {
                    // Keep the columns every scan has, with one type.
                    all.retain_mut(|a| {
                        match these
                            .iter_mut()
                            .find(|b| b.name == a.name && b.values.ty() == a.values.ty())
                        {
                            Some(b) => append(&mut a.values, &mut b.values),
                            None => false,
                        }
                    });
                    all
                }
            });
        }
    }
    if skipped > 0 {
        cloud.warnings.push(ReadWarning::SkippedPoints {
            count: skipped,
            reason: "coordinates flagged invalid in the E57 file",
        });
    }
    cloud.attributes = columns.unwrap_or_default();
    non_empty(path, cloud)
}

/// Appends `b` to `a` when both have one type; `false` otherwise.
fn append(a: &mut Values, b: &mut Values) -> bool {
    macro_rules! cat {
        ($($v:ident),*) => {
            match (a, b) {
                $((Values::$v(x), Values::$v(y)) => { x.append(y); true })*
                _ => false,
            }
        };
    }
    cat!(I8, U8, I16, U16, I32, U32, I64, U64, F32, F64)
}

/// What the crate trusts before its own checks: the header's size fields.
fn precheck(bytes: &[u8]) -> Result<(), String> {
    if bytes.len() < 48 || &bytes[..8] != b"ASTM-E57" {
        return Err("no E57 signature ('ASTM-E57')".into());
    }
    let u64_at = |o: usize| u64::from_le_bytes(bytes[o..o + 8].try_into().unwrap_or([0; 8]));
    let (xml_offset, xml_len) = (u64_at(24), u64_at(32));
    if xml_offset.saturating_add(xml_len) > bytes.len() as u64 {
        return Err(format!(
            "XML section of {xml_len} bytes at {xml_offset} past the end of the file ({} bytes)",
            bytes.len()
        ));
    }
    Ok(())
}

/// Runs `f`, turning a panic inside it (from the `e57` crate on corrupt
/// data) into an error naming the file.
fn contain<T>(path: &Path, f: impl FnOnce() -> T) -> Result<T, IoError> {
    super::error::contain_decoder(path, "E57", f)
}

/// Where a scan's coordinates are: Cartesian if it has all three, else
/// spherical if it has all three.
fn coordinates(proto: &[e57::Record]) -> Option<Coordinates> {
    let find = |n: RecordName| proto.iter().position(|r| r.name == n);
    let cart = [
        find(RecordName::CartesianX),
        find(RecordName::CartesianY),
        find(RecordName::CartesianZ),
    ];
    if let [Some(x), Some(y), Some(z)] = cart {
        return Some(Coordinates::Cartesian(
            [x, y, z],
            find(RecordName::CartesianInvalidState),
        ));
    }
    let sph = [
        find(RecordName::SphericalRange),
        find(RecordName::SphericalAzimuth),
        find(RecordName::SphericalElevation),
    ];
    if let [Some(r), Some(a), Some(e)] = sph {
        return Some(Coordinates::Spherical(
            [r, a, e],
            find(RecordName::SphericalInvalidState),
        ));
    }
    None
}

/// The attribute columns of a scan: every field but the coordinates used
/// and their invalid state.
fn scan_columns(proto: &[e57::Record], coords: &Coordinates, cap: usize) -> Vec<Column> {
    let used: Vec<usize> = match coords {
        Coordinates::Cartesian(i, s) | Coordinates::Spherical(i, s) => {
            i.iter().copied().chain(*s).collect()
        }
    };
    let mut out: Vec<Column> = Vec::new();
    for (index, r) in proto.iter().enumerate() {
        if used.contains(&index) {
            continue;
        }
        let mut name = match &r.name {
            RecordName::Intensity => "intensity".to_string(),
            RecordName::ColorRed => "red".to_string(),
            RecordName::ColorGreen => "green".to_string(),
            RecordName::ColorBlue => "blue".to_string(),
            RecordName::Unknown { name, .. } => name.clone(),
            other => tag_name(other).to_string(),
        };
        if out.iter().any(|c| c.attribute.name == name) {
            name = format!("{name}_{index}");
        }
        let ty = column_type(&r.data_type);
        out.push(Column {
            index,
            data_type: r.data_type.clone(),
            attribute: Attribute::new(name, Values::with_capacity(ty, cap.min(1 << 20))),
        });
    }
    out
}

/// The E57 name of a standard field.
fn tag_name(n: &RecordName) -> &'static str {
    match n {
        RecordName::CartesianX => "cartesianX",
        RecordName::CartesianY => "cartesianY",
        RecordName::CartesianZ => "cartesianZ",
        RecordName::CartesianInvalidState => "cartesianInvalidState",
        RecordName::SphericalRange => "sphericalRange",
        RecordName::SphericalAzimuth => "sphericalAzimuth",
        RecordName::SphericalElevation => "sphericalElevation",
        RecordName::SphericalInvalidState => "sphericalInvalidState",
        RecordName::Intensity => "intensity",
        RecordName::IsIntensityInvalid => "isIntensityInvalid",
        RecordName::ColorRed => "colorRed",
        RecordName::ColorGreen => "colorGreen",
        RecordName::ColorBlue => "colorBlue",
        RecordName::IsColorInvalid => "isColorInvalid",
        RecordName::RowIndex => "rowIndex",
        RecordName::ColumnIndex => "columnIndex",
        RecordName::ReturnCount => "returnCount",
        RecordName::ReturnIndex => "returnIndex",
        RecordName::TimeStamp => "timeStamp",
        RecordName::IsTimeStampInvalid => "isTimeStampInvalid",
        RecordName::Unknown { .. } => "unknown",
    }
}

/// The column type of a field: an integer's smallest type holding its
/// declared range; scaled integers as `f64`.
fn column_type(t: &RecordDataType) -> AttributeType {
    match *t {
        RecordDataType::Single { .. } => AttributeType::F32,
        RecordDataType::Double { .. } | RecordDataType::ScaledInteger { .. } => AttributeType::F64,
        RecordDataType::Integer { min, max } => {
            let fits = |lo: i64, hi: i64| min >= lo && max <= hi;
            if fits(0, u8::MAX.into()) {
                AttributeType::U8
            } else if fits(i8::MIN.into(), i8::MAX.into()) {
                AttributeType::I8
            } else if fits(0, u16::MAX.into()) {
                AttributeType::U16
            } else if fits(i16::MIN.into(), i16::MAX.into()) {
                AttributeType::I16
            } else if fits(0, u32::MAX.into()) {
                AttributeType::U32
            } else if fits(i32::MIN.into(), i32::MAX.into()) {
                AttributeType::I32
            } else {
                AttributeType::I64
            }
        }
    }
}

/// A value as `f64` (scale and offset applied); `None` when the value does
/// not match its field's type.
fn to_f64(v: &RecordValue, t: &RecordDataType) -> Option<f64> {
    match (v, t) {
        (RecordValue::Single(x), RecordDataType::Single { .. }) => Some(f64::from(*x)),
        (RecordValue::Double(x), RecordDataType::Double { .. }) => Some(*x),
        (RecordValue::Integer(i), RecordDataType::Integer { .. }) => Some(*i as f64),
        (RecordValue::ScaledInteger(i), RecordDataType::ScaledInteger { scale, offset, .. }) => {
            Some(*i as f64 * scale + offset)
        }
        _ => None,
    }
}

/// Appends `v` to its column, checking an integer against its declared
/// range (a corrupt file can code values past it).
fn push_value(col: &mut Values, v: &RecordValue, t: &RecordDataType) -> Result<(), String> {
    match (col, v, t) {
        (Values::F32(c), RecordValue::Single(x), _) => c.push(*x),
        (Values::F64(c), RecordValue::Double(_) | RecordValue::ScaledInteger(_), _) => {
            c.push(to_f64(v, t).ok_or("value of another type than its field")?)
        }
        (c, RecordValue::Integer(i), RecordDataType::Integer { min, max }) => {
            if i < min || i > max {
                return Err(format!(
                    "value {i} outside its declared range {min}..={max}"
                ));
            }
            // In range, so it fits the column's type (column_type);
            // push_f64 would round an i64 beyond 2^53.
            match c {
                Values::I64(c) => c.push(*i),
                c => c.push_f64(*i as f64),
            }
        }
        _ => return Err("value of another type than its field".into()),
    }
    Ok(())
}

/// A scan's pose: a rotation (unit quaternion) then a translation.
struct Pose {
    rotation: [[f64; 3]; 3],
    translation: [f64; 3],
}

impl Pose {
    /// From a quaternion `[w, x, y, z]` (normalised here; a zero one is the
    /// identity) and a translation.
    fn new(q: [f64; 4], translation: [f64; 3]) -> Pose {
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        let [w, x, y, z] = if n > 0.0 && n.is_finite() {
            q.map(|c| c / n)
        } else {
            [1.0, 0.0, 0.0, 0.0]
        };
        Pose {
            rotation: [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - w * z),
                    2.0 * (x * z + w * y),
                ],
                [
                    2.0 * (x * y + w * z),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - w * x),
                ],
                [
                    2.0 * (x * z - w * y),
                    2.0 * (y * z + w * x),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ],
            translation,
        }
    }

    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        [0, 1, 2].map(|k| r[k][0] * p[0] + r[k][1] * p[1] + r[k][2] * p[2] + self.translation[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turn_about_z() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let pose = Pose::new([h, 0.0, 0.0, h], [10.0, 0.0, 0.0]);
        let p = pose.apply([1.0, 0.0, 0.0]);
        assert!(
            (p[0] - 10.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12,
            "{p:?}"
        );
        // Not normalised: the same rotation.
        let p2 = Pose::new([2.0, 0.0, 0.0, 2.0], [10.0, 0.0, 0.0]).apply([1.0, 0.0, 0.0]);
        assert!((p2[0] - p[0]).abs() < 1e-12 && (p2[1] - p[1]).abs() < 1e-12);
    }

    #[test]
    fn integer_columns_take_the_smallest_type() {
        let t = |min, max| column_type(&RecordDataType::Integer { min, max });
        assert_eq!(t(0, 255), AttributeType::U8);
        assert_eq!(t(-66, 66), AttributeType::I8);
        assert_eq!(t(0, 256), AttributeType::U16);
        assert_eq!(t(-1, 40000), AttributeType::I32);
        assert_eq!(t(0, 1 << 40), AttributeType::I64);
    }

    #[test]
    fn out_of_range_integers_are_errors() {
        let t = RecordDataType::Integer { min: 0, max: 255 };
        let mut c = Values::U8(Vec::new());
        assert!(push_value(&mut c, &RecordValue::Integer(256), &t).is_err());
        push_value(&mut c, &RecordValue::Integer(255), &t).unwrap();
        assert_eq!(c, Values::U8(vec![255]));
        let big = RecordDataType::Integer {
            min: 0,
            max: i64::MAX,
        };
        let mut c = Values::I64(Vec::new());
        push_value(&mut c, &RecordValue::Integer((1 << 60) + 1), &big).unwrap();
        assert_eq!(c, Values::I64(vec![(1 << 60) + 1]));
    }

    #[test]
    fn header_sizes_are_checked() {
        assert!(precheck(b"not an e57").is_err());
        let mut h = b"ASTM-E57".to_vec();
        h.resize(48, 0);
        h[32..40].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(precheck(&h).unwrap_err().contains("past the end"));
    }
}
