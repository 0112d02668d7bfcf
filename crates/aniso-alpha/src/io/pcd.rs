//! PCD reader (Point Cloud Library): ascii, binary, binary_compressed.

use std::path::Path;

use super::attributes::{Attribute, Values};
use super::error::show_token;
use super::lzf;
use super::ply::Scalar;
use super::text::{parse_f64, parse_label};
use super::{check_finite, is_finite, non_empty, IoError, PointCloud, ReadWarning};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

#[derive(Debug)]
struct Field {
    name: String,
    size: usize,
    kind: u8,
    count: usize,
}

impl Field {
    fn scalar(&self) -> Option<Scalar> {
        Some(match (self.kind, self.size) {
            (b'F', 4) => Scalar::F32,
            (b'F', 8) => Scalar::F64,
            (b'I', 1) => Scalar::I8,
            (b'I', 2) => Scalar::I16,
            (b'I', 4) => Scalar::I32,
            (b'U', 1) => Scalar::U8,
            (b'U', 2) => Scalar::U16,
            (b'U', 4) => Scalar::U32,
            _ => return None,
        })
    }

    fn bytes(&self) -> usize {
        self.size * self.count
    }
}

struct Header {
    fields: Vec<Field>,
    points: usize,
    data: Data,
    data_start: usize,
    lines: usize,
    /// HEIGHT > 1: an organized cloud (a depth image's pixels), whose
    /// pixels without a return are points of NaN coordinates.
    organized: bool,
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header, IoError> {
    let mut names: Option<Vec<String>> = None;
    let mut sizes: Option<Vec<usize>> = None;
    let mut types: Option<Vec<u8>> = None;
    let mut counts: Option<Vec<usize>> = None;
    let (mut width, mut height, mut points) = (None, None, None);
    let mut pos = 0usize;
    let mut line = 0usize;
    let data = loop {
        let Some(raw) = super::next_header_line(bytes, &mut pos) else {
            return Err(IoError::format(path, "PCD header has no DATA line"));
        };
        line += 1;
        let bad = |msg: String| IoError::parse(path, line, msg);
        let text = std::str::from_utf8(raw)
            .map_err(|_| bad("PCD header line is not valid text".into()))?;
        let mut toks = text.split_whitespace();
        let Some(key) = toks.next() else { continue };
        if key.starts_with('#') {
            continue;
        }
        let rest: Vec<&str> = toks.collect();
        let nums = |what: &str| -> Result<Vec<usize>, IoError> {
            rest.iter()
                .map(|t| {
                    t.parse::<usize>().map_err(|_| {
                        bad(format!(
                            "invalid {what} value '{}'",
                            show_token(t.as_bytes())
                        ))
                    })
                })
                .collect()
        };
        let one = |what: &str| -> Result<usize, IoError> {
            match nums(what)?.as_slice() {
                [v] => Ok(*v),
                _ => Err(bad(format!("{what} needs one value"))),
            }
        };
        match key.to_ascii_uppercase().as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" => names = Some(rest.iter().map(|s| s.to_string()).collect()),
            "SIZE" => sizes = Some(nums("SIZE")?),
            "COUNT" => counts = Some(nums("COUNT")?),
            "TYPE" => {
                let t = rest
                    .iter()
                    .map(|t| match t.as_bytes() {
                        [c @ (b'F' | b'I' | b'U')] => Ok(*c),
                        _ => Err(bad(format!("invalid TYPE '{}'", show_token(t.as_bytes())))),
                    })
                    .collect::<Result<Vec<u8>, _>>()?;
                types = Some(t);
            }
            "WIDTH" => width = Some(one("WIDTH")?),
            "HEIGHT" => height = Some(one("HEIGHT")?),
            "POINTS" => points = Some(one("POINTS")?),
            "DATA" => {
                break match rest.as_slice() {
                    ["ascii"] => Data::Ascii,
                    ["binary"] => Data::Binary,
                    ["binary_compressed"] => Data::Compressed,
                    _ => return Err(bad(format!("unknown PCD DATA '{}'", rest.join(" ")))),
                };
            }
            _ => {
                return Err(bad(format!(
                    "unexpected PCD header line '{}'",
                    show_token(raw)
                )))
            }
        }
    };
    let names = names.ok_or_else(|| IoError::format(path, "PCD header has no FIELDS line"))?;
    let n = names.len();
    let sizes = sizes.unwrap_or_else(|| vec![4; n]);
    let types = types.unwrap_or_else(|| vec![b'F'; n]);
    let counts = counts.unwrap_or_else(|| vec![1; n]);
    if sizes.len() != n || types.len() != n || counts.len() != n {
        return Err(IoError::format(
            path,
            "PCD header: FIELDS, SIZE, TYPE and COUNT have different lengths",
        ));
    }
    let fields: Vec<Field> = (0..n)
        .map(|i| Field {
            name: names[i].clone(),
            size: sizes[i],
            kind: types[i],
            count: counts[i],
        })
        .collect();
    if fields
        .iter()
        .any(|f| f.size.checked_mul(f.count).is_none_or(|b| b > 1 << 20))
    {
        return Err(IoError::format(path, "PCD header: field too large"));
    }
    // A zero-size field would make a zero stride: any POINTS would then
    // "fit" in no data (issue 19: 12 bytes read as 10M points).
    if let Some(f) = fields.iter().find(|f| f.size == 0 || f.count == 0) {
        return Err(IoError::format(
            path,
            format!(
                "PCD header: field '{}' has SIZE {} and COUNT {} (both must be at least 1)",
                show_token(f.name.as_bytes()),
                f.size,
                f.count
            ),
        ));
    }
    let area = match (width, height) {
        (Some(w), Some(h)) => Some(
            w.checked_mul(h)
                .ok_or_else(|| IoError::format(path, "PCD header: WIDTH × HEIGHT overflows"))?,
        ),
        _ => None,
    };
    let points = match (points, area) {
        (Some(p), Some(a)) if p != a => {
            return Err(IoError::format(
                path,
                format!(
                    "PCD header: POINTS {p} differs from WIDTH × HEIGHT = {} × {} = {a}",
                    width.unwrap_or(0),
                    height.unwrap_or(0)
                ),
            ))
        }
        (Some(p), _) => p,
        (None, Some(a)) => a,
        _ => return Err(IoError::format(path, "PCD header has no POINTS line")),
    };
    Ok(Header {
        fields,
        points,
        data,
        data_start: pos,
        lines: line,
        organized: height.is_some_and(|h| h > 1),
    })
}

/// Index and scalar type of field `name` (its first component).
fn locate(path: &Path, h: &Header, name: &str) -> Result<Option<(usize, Scalar)>, IoError> {
    let Some(i) = h.fields.iter().position(|f| f.name == name) else {
        return Ok(None);
    };
    let s = h.fields[i].scalar().ok_or_else(|| {
        IoError::format(path, format!("PCD field '{name}' has an unsupported type"))
    })?;
    Ok(Some((i, s)))
}

/// One kept attribute column of a PCD file.
#[derive(Debug, Clone, Copy)]
enum Col {
    /// Component `comp` of field `field`, of type `scalar`.
    Plain {
        field: usize,
        comp: usize,
        scalar: Scalar,
    },
    /// A packed colour (`rgb` or `rgba`, 4 bytes: PCL's 0xAARRGGBB),
    /// kept as `u8` columns red, green, blue (and alpha).
    Rgb { field: usize, alpha: bool },
}

/// The attribute columns of every field but x, y, z and padding (`_`):
/// a field of COUNT k > 1 gives `name_0` … `name_{k-1}`.
fn columns(path: &Path, h: &Header) -> Result<(Vec<Col>, Vec<Attribute>), IoError> {
    let columns: usize = h
        .fields
        .iter()
        .filter(|f| !matches!(f.name.as_str(), "x" | "y" | "z" | "_"))
        .map(|f| {
            if (f.name == "rgb" || f.name == "rgba") && f.size == 4 && f.count == 1 {
                3 + usize::from(f.name == "rgba")
            } else {
                f.count
            }
        })
        .fold(0usize, usize::saturating_add);
    let n = super::attributes::reserve_per_column(h.points, columns);
    let mut cols = Vec::new();
    let mut attrs = Vec::new();
    for (fi, f) in h.fields.iter().enumerate() {
        if matches!(f.name.as_str(), "x" | "y" | "z" | "_") {
            continue;
        }
        if (f.name == "rgb" || f.name == "rgba") && f.size == 4 && f.count == 1 {
            let alpha = f.name == "rgba";
            cols.push(Col::Rgb { field: fi, alpha });
            let names: &[&str] = if alpha {
                &["red", "green", "blue", "alpha"]
            } else {
                &["red", "green", "blue"]
            };
            for name in names {
                attrs.push(Attribute::new(*name, Values::U8(Vec::with_capacity(n))));
            }
            continue;
        }
        let scalar = f.scalar().ok_or_else(|| {
            IoError::format(
                path,
                format!(
                    "PCD field '{}' has an unsupported type {} of size {}",
                    show_token(f.name.as_bytes()),
                    f.kind as char,
                    f.size
                ),
            )
        })?;
        for comp in 0..f.count {
            cols.push(Col::Plain {
                field: fi,
                comp,
                scalar,
            });
            let name = if f.count == 1 {
                f.name.clone()
            } else {
                format!("{}_{comp}", f.name)
            };
            attrs.push(Attribute::new(
                name,
                Values::with_capacity(scalar.attribute_type(), n),
            ));
        }
    }
    Ok((cols, attrs))
}

/// Pushes a packed colour onto the next 3 (or 4) columns.
fn push_rgb(attrs: &mut [Attribute], v: u32, alpha: bool) {
    let parts = [v >> 16, v >> 8, v, v >> 24];
    let k = if alpha { 4 } else { 3 };
    for (a, c) in attrs.iter_mut().zip(&parts[..k]) {
        a.values.push_f64(f64::from(*c & 0xFF));
    }
}

/// Number of attribute columns a `Col` fills.
fn width(c: &Col) -> usize {
    match c {
        Col::Plain { .. } => 1,
        Col::Rgb { alpha, .. } => 3 + usize::from(*alpha),
    }
}

pub(crate) fn read_pcd(
    path: &Path,
    bytes: &[u8],
    read_labels: bool,
    attributes: bool,
) -> Result<PointCloud, IoError> {
    let h = parse_header(path, bytes)?;
    let mut xyz = Vec::with_capacity(3);
    for name in ["x", "y", "z"] {
        let f = locate(path, &h, name)?
            .ok_or_else(|| IoError::format(path, format!("PCD file has no field '{name}'")))?;
        xyz.push(f);
    }
    let xyz = [xyz[0], xyz[1], xyz[2]];
    let label = if read_labels {
        locate(path, &h, "label")?
    } else {
        None
    };
    let data = &bytes[h.data_start..];
    let (cols, attrs) = if attributes {
        columns(path, &h)?
    } else {
        (Vec::new(), Vec::new())
    };
    let keep = Keep {
        cols: &cols,
        attrs,
        sizes: h.fields.iter().map(|f| f.size).collect(),
    };
    let cloud = match h.data {
        Data::Ascii => read_ascii(path, data, &h, xyz, label, keep)?,
        Data::Binary => {
            let stride: usize = h.fields.iter().map(Field::bytes).sum();
            let offsets = offsets(&h);
            let need = h.points.checked_mul(stride);
            if need.is_none_or(|n| n > data.len()) {
                return Err(IoError::format(
                    path,
                    format!(
                        "PCD file truncated: header declares {} points of {} bytes, {} bytes of data",
                        h.points,
                        stride,
                        data.len()
                    ),
                ));
            }
            // Field f of point i starts at i * stride + offsets[f].
            decode(
                path,
                data,
                (h.points, h.organized),
                xyz,
                label,
                keep,
                |f, i| i * stride + offsets[f],
            )?
        }
        Data::Compressed => {
            let word = |k: usize| -> Option<usize> {
                let b = data.get(k..k + 4)?;
                Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            };
            let (Some(csize), Some(usize_)) = (word(0), word(4)) else {
                return Err(IoError::format(
                    path,
                    "PCD file truncated: no compressed sizes",
                ));
            };
            let stride: usize = h.fields.iter().map(Field::bytes).sum();
            let comp = data.get(8..8 + csize).ok_or_else(|| {
                IoError::format(
                    path,
                    "PCD file truncated: compressed data shorter than declared",
                )
            })?;
            if h.points.checked_mul(stride) != Some(usize_) || usize_ > csize * 90 + 64 {
                return Err(IoError::format(
                    path,
                    "PCD compressed sizes do not match the header",
                ));
            }
            let raw = lzf::decompress(comp, usize_)
                .ok_or_else(|| IoError::format(path, "PCD compressed data is corrupt"))?;
            // Column-major: all values of field 0, then of field 1, ...
            let mut base = Vec::with_capacity(h.fields.len());
            let mut acc = 0usize;
            for f in &h.fields {
                base.push(acc);
                acc += f.bytes() * h.points;
            }
            let fb: Vec<usize> = h.fields.iter().map(Field::bytes).collect();
            decode(
                path,
                &raw,
                (h.points, h.organized),
                xyz,
                label,
                keep,
                |f, i| base[f] + i * fb[f],
            )?
        }
    };
    let mut cloud = non_empty(path, cloud)?;
    let absent = cloud.points.iter().filter(|p| !is_finite(p)).count();
    if absent == cloud.points.len() {
        return Err(IoError::format(
            path,
            "every point of the organized cloud is NaN (no return)",
        ));
    }
    if absent > 0 {
        cloud.warnings.push(ReadWarning::NoReturn {
            count: absent as u64,
            of: cloud.points.len() as u64,
        });
    }
    Ok(cloud)
}

fn offsets(h: &Header) -> Vec<usize> {
    let mut acc = 0;
    h.fields
        .iter()
        .map(|f| {
            let o = acc;
            acc += f.bytes();
            o
        })
        .collect()
}

/// The attribute columns being filled.
struct Keep<'a> {
    cols: &'a [Col],
    attrs: Vec<Attribute>,
    /// SIZE of each field.
    sizes: Vec<usize>,
}

/// Decodes binary points, `at(field, point)` giving the byte offset (in
/// bounds: the callers checked the data size).
fn decode(
    path: &Path,
    data: &[u8],
    (n, organized): (usize, bool),
    xyz: [(usize, Scalar); 3],
    label: Option<(usize, Scalar)>,
    mut keep: Keep<'_>,
    at: impl Fn(usize, usize) -> usize,
) -> Result<PointCloud, IoError> {
    let get = |(f, s): (usize, Scalar), i: usize| -> Result<f64, IoError> {
        let o = at(f, i);
        data.get(o..o + s.size())
            .map(|b| s.decode(b, false))
            .ok_or_else(|| IoError::format(path, "PCD file truncated"))
    };
    let mut cloud = PointCloud {
        points: Vec::with_capacity(n),
        labels: label.map(|_| Vec::with_capacity(n)),
        ..Default::default()
    };
    for i in 0..n {
        let p = [get(xyz[0], i)?, get(xyz[1], i)?, get(xyz[2], i)?];
        if !organized {
            check_finite(path, &p, i, None)?;
        }
        cloud.points.push(p);
        if let (Some(l), Some(out)) = (label, cloud.labels.as_mut()) {
            out.push(get(l, i)? as i64);
        }
        let mut k = 0;
        for c in keep.cols {
            match *c {
                Col::Plain {
                    field,
                    comp,
                    scalar,
                } => {
                    let o = at(field, i) + comp * keep.sizes[field];
                    let b = data
                        .get(o..o + scalar.size())
                        .ok_or_else(|| IoError::format(path, "PCD file truncated"))?;
                    keep.attrs[k].values.push_bytes(b, false);
                }
                Col::Rgb { field, alpha } => {
                    let o = at(field, i);
                    let b = data
                        .get(o..o + 4)
                        .ok_or_else(|| IoError::format(path, "PCD file truncated"))?;
                    let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                    push_rgb(&mut keep.attrs[k..], v, alpha);
                }
            }
            k += width(c);
        }
    }
    cloud.attributes = keep.attrs;
    Ok(cloud)
}

fn read_ascii(
    path: &Path,
    data: &[u8],
    h: &Header,
    xyz: [(usize, Scalar); 3],
    label: Option<(usize, Scalar)>,
    mut keep: Keep<'_>,
) -> Result<PointCloud, IoError> {
    // Token index of each field's first component.
    let mut tok_of = Vec::with_capacity(h.fields.len());
    let mut acc = 0usize;
    for f in &h.fields {
        tok_of.push(acc);
        acc += f.count;
    }
    let want = [tok_of[xyz[0].0], tok_of[xyz[1].0], tok_of[xyz[2].0]];
    let want_label = label.map(|(f, _)| tok_of[f]);
    let mut cloud = PointCloud {
        points: Vec::with_capacity(h.points.min(data.len() / 6)),
        labels: label.map(|_| Vec::new()),
        ..Default::default()
    };
    let mut last = h.lines;
    let mut toks: Vec<&[u8]> = Vec::with_capacity(acc);
    for (k, raw) in data.split(|&b| b == b'\n').enumerate() {
        if cloud.points.len() == h.points {
            break;
        }
        let ln = h.lines + k + 1;
        toks.clear();
        toks.extend(
            raw.split(|b| b.is_ascii_whitespace())
                .filter(|t| !t.is_empty()),
        );
        if toks.is_empty() {
            continue;
        }
        last = ln;
        if toks.len() < acc {
            return Err(IoError::parse(
                path,
                ln,
                format!("expected {acc} values, found {}", toks.len()),
            ));
        }
        let num = |t: usize| {
            parse_f64(toks[t]).ok_or_else(|| {
                IoError::parse(
                    path,
                    ln,
                    format!("invalid number '{}'", show_token(toks[t])),
                )
            })
        };
        let p = [num(want[0])?, num(want[1])?, num(want[2])?];
        if !h.organized {
            check_finite(path, &p, cloud.points.len(), Some(ln))?;
        }
        cloud.points.push(p);
        if let (Some(t), Some(out)) = (want_label, cloud.labels.as_mut()) {
            let v = parse_label(toks[t]).ok_or_else(|| {
                IoError::parse(path, ln, format!("invalid label '{}'", show_token(toks[t])))
            })?;
            out.push(v);
        }
        let mut k = 0;
        for c in keep.cols {
            let field = match *c {
                Col::Plain { field, .. } | Col::Rgb { field, .. } => field,
            };
            let comp = match *c {
                Col::Plain { comp, .. } => comp,
                Col::Rgb { .. } => 0,
            };
            let t = toks[tok_of[field] + comp];
            let bad = |why: String| {
                IoError::parse(
                    path,
                    ln,
                    format!(
                        "invalid value '{}' for field '{}': {why}",
                        show_token(t),
                        show_token(h.fields[field].name.as_bytes())
                    ),
                )
            };
            match *c {
                Col::Plain { scalar, .. } => {
                    let v = scalar.parse(t).map_err(bad)?;
                    keep.attrs[k].values.push_f64(v);
                }
                Col::Rgb { alpha, .. } => {
                    // PCL prints a float-typed rgb as the float whose bits
                    // are the colour; an integer-typed one as the integer.
                    let v = if h.fields[field].kind == b'F' {
                        (Scalar::F32.parse(t).map_err(bad)? as f32).to_bits()
                    } else {
                        Scalar::U32.parse(t).map_err(bad)? as u32
                    };
                    push_rgb(&mut keep.attrs[k..], v, alpha);
                }
            }
            k += width(c);
        }
    }
    cloud.attributes = keep.attrs;
    if cloud.points.len() < h.points {
        return Err(IoError::parse(
            path,
            last + 1,
            format!(
                "PCD file ends early: header declares {} points, found {}",
                h.points,
                cloud.points.len()
            ),
        ));
    }
    Ok(cloud)
}
