//! PLY reader (ascii, binary little/big endian) and writer.

use std::io::Write;
use std::path::Path;

use super::attributes::{Attribute, AttributeType, Values};
use super::error::show_token;
use super::text::parse_f64;
use super::{atomic_write, check_finite, non_empty, IoError, PointCloud};

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    pub(crate) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// The attribute type of this PLY type.
    pub(crate) fn attribute_type(self) -> AttributeType {
        match self {
            Scalar::I8 => AttributeType::I8,
            Scalar::U8 => AttributeType::U8,
            Scalar::I16 => AttributeType::I16,
            Scalar::U16 => AttributeType::U16,
            Scalar::I32 => AttributeType::I32,
            Scalar::U32 => AttributeType::U32,
            Scalar::F32 => AttributeType::F32,
            Scalar::F64 => AttributeType::F64,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The range of an integer type.
    fn int_range(self) -> Option<(i64, i64)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => return None,
        })
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Parses an ascii value of this type: integers must be plain
    /// integers within the type's range (`300`, `-5` and `1.5` are not
    /// `uchar`s, `1e20` is not an `int`).
    pub(crate) fn parse(self, tok: &[u8]) -> Result<f64, String> {
        match self.int_range() {
            None => parse_f64(tok).ok_or_else(|| "not a number".to_string()),
            Some((lo, hi)) => {
                let v = std::str::from_utf8(tok)
                    .ok()
                    .and_then(|s| s.strip_prefix('+').unwrap_or(s).parse::<i64>().ok())
                    .ok_or_else(|| format!("not an integer ({} property)", self.name()))?;
                if v < lo || v > hi {
                    return Err(format!(
                        "out of range for a {} property ({lo}..={hi})",
                        self.name()
                    ));
                }
                Ok(v as f64)
            }
        }
    }
}

/// A label value read from a number: it must be an integer (a float
/// label of NaN or 1.5 is an error, not 0 or 1).
pub(crate) fn label_of(v: f64) -> Option<i64> {
    (v.is_finite() && v.fract() == 0.0 && v.abs() < 9.0e18).then_some(v as i64)
}

impl Scalar {
    /// Decodes `b` (exactly `size()` bytes) as a number.
    #[inline]
    pub(crate) fn decode(self, b: &[u8], big: bool) -> f64 {
        macro_rules! get {
            ($t:ty, $n:literal) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                (if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }) as f64
            }};
        }
        match self {
            Scalar::I8 => get!(i8, 1),
            Scalar::U8 => get!(u8, 1),
            Scalar::I16 => get!(i16, 2),
            Scalar::U16 => get!(u16, 2),
            Scalar::I32 => get!(i32, 4),
            Scalar::U32 => get!(u32, 4),
            Scalar::F32 => get!(f32, 4),
            Scalar::F64 => get!(f64, 8),
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the data.
    data_start: usize,
    /// Number of header lines (ascii data starts on the next line).
    lines: usize,
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header, IoError> {
    let bad = |line: usize, msg: String| IoError::parse(path, line, msg);
    if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
        return Err(IoError::format(
            path,
            "not a PLY file (does not start with 'ply')",
        ));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut pos = 0usize;
    let mut line = 0usize;
    loop {
        let Some(raw) = super::next_header_line(bytes, &mut pos) else {
            return Err(IoError::format(path, "PLY header has no 'end_header' line"));
        };
        line += 1;
        if line == 1 {
            continue; // "ply"
        }
        let text = std::str::from_utf8(raw)
            .map_err(|_| bad(line, "PLY header line is not valid text".into()))?;
        let toks: Vec<&str> = text.split_whitespace().collect();
        match toks.as_slice() {
            [] => {}
            ["end_header"] => break,
            ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _version] => {
                encoding = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    _ => return Err(bad(line, format!("unknown PLY format '{f}'"))),
                })
            }
            ["element", name, count] => {
                let count = count.parse::<usize>().map_err(|_| {
                    bad(
                        line,
                        format!(
                            "invalid count '{}' for element '{name}'",
                            show_token(count.as_bytes())
                        ),
                    )
                })?;
                elements.push(Element {
                    name: (*name).to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            ["property", "list", ct, it, name] => {
                let count = Scalar::from_name(ct)
                    .filter(|s| s.is_int())
                    .ok_or_else(|| bad(line, format!("invalid list count type '{ct}'")))?;
                let item = Scalar::from_name(it)
                    .ok_or_else(|| bad(line, format!("unknown property type '{it}'")))?;
                let el = elements
                    .last_mut()
                    .ok_or_else(|| bad(line, "property before any element".into()))?;
                el.props.push(Property {
                    name: (*name).to_string(),
                    kind: Kind::List { count, item },
                });
            }
            ["property", ty, name] => {
                let s = Scalar::from_name(ty)
                    .ok_or_else(|| bad(line, format!("unknown property type '{ty}'")))?;
                let el = elements
                    .last_mut()
                    .ok_or_else(|| bad(line, "property before any element".into()))?;
                el.props.push(Property {
                    name: (*name).to_string(),
                    kind: Kind::Scalar(s),
                });
            }
            _ => {
                return Err(bad(
                    line,
                    format!("unexpected PLY header line '{}'", show_token(raw)),
                ))
            }
        }
    }
    let encoding =
        encoding.ok_or_else(|| IoError::format(path, "PLY header has no 'format' line"))?;
    Ok(Header {
        encoding,
        elements,
        data_start: pos,
        lines: line,
    })
}

/// Where x, y, z, the label and the kept attributes are among the vertex
/// properties.
struct VertexLayout {
    xyz: [usize; 3],
    label: Option<usize>,
    /// Scalar properties other than x, y, z kept as attributes (with
    /// `ReadOptions::attributes`): property index and type.
    attrs: Vec<(usize, Scalar)>,
}

fn vertex_layout(
    path: &Path,
    el: &Element,
    read_labels: bool,
    attributes: bool,
) -> Result<VertexLayout, IoError> {
    let find = |name: &str| el.props.iter().position(|p| p.name == name);
    let mut xyz = [0usize; 3];
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        let i = find(name).ok_or_else(|| {
            IoError::format(path, format!("PLY vertex element has no property '{name}'"))
        })?;
        if matches!(el.props[i].kind, Kind::List { .. }) {
            return Err(IoError::format(
                path,
                format!("PLY vertex property '{name}' is a list, not a number"),
            ));
        }
        xyz[k] = i;
    }
    let label = if read_labels {
        find("structure")
            .or_else(|| find("label"))
            .filter(|&i| matches!(el.props[i].kind, Kind::Scalar(_)))
    } else {
        None
    };
    // Vertex list properties are not kept (they are rare and have no
    // per-point column form).
    let attrs = if attributes {
        el.props
            .iter()
            .enumerate()
            .filter(|(i, _)| !xyz.contains(i))
            .filter_map(|(i, p)| match p.kind {
                Kind::Scalar(s) => Some((i, s)),
                Kind::List { .. } => None,
            })
            .collect()
    } else {
        Vec::new()
    };
    Ok(VertexLayout { xyz, label, attrs })
}

/// Empty attribute columns for the layout's attributes.
fn attribute_columns(el: &Element, layout: &VertexLayout) -> Vec<Attribute> {
    let n = super::attributes::reserve_per_column(el.count, layout.attrs.len());
    layout
        .attrs
        .iter()
        .map(|&(i, s)| {
            Attribute::new(
                el.props[i].name.clone(),
                Values::with_capacity(s.attribute_type(), n),
            )
        })
        .collect()
}

pub(crate) fn read_ply(
    path: &Path,
    bytes: &[u8],
    read_labels: bool,
    attributes: bool,
) -> Result<PointCloud, IoError> {
    let header = parse_header(path, bytes)?;
    let vertex = header
        .elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| IoError::format(path, "PLY file has no 'vertex' element"))?;
    let layout = vertex_layout(path, &header.elements[vertex], read_labels, attributes)?;
    let data = &bytes[header.data_start..];
    let cloud = match header.encoding {
        Encoding::Ascii => read_ascii(path, data, &header, vertex, &layout)?,
        Encoding::Little => read_binary(path, data, &header, vertex, &layout, false)?,
        Encoding::Big => read_binary(path, data, &header, vertex, &layout, true)?,
    };
    non_empty(path, cloud)
}

/// Binary data: walks every element, so that a header lying about any
/// count is caught.
fn read_binary(
    path: &Path,
    data: &[u8],
    header: &Header,
    vertex: usize,
    layout: &VertexLayout,
    big: bool,
) -> Result<PointCloud, IoError> {
    let truncated = |el: &Element, i: usize| {
        IoError::format(
            path,
            format!(
                "PLY file truncated: element '{}' declares {} entries, data ends in entry {}",
                el.name, el.count, i
            ),
        )
    };
    let mut off = 0usize;
    let mut cloud = PointCloud::default();
    for (ei, el) in header.elements.iter().enumerate() {
        let fixed: Option<usize> = el
            .props
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => Some(s.size()),
                Kind::List { .. } => None,
            })
            .sum();
        let is_vertex = ei == vertex;
        if let Some(stride) = fixed {
            let need = el.count.checked_mul(stride);
            let left = data.len() - off;
            if need.is_none_or(|n| n > left) {
                let i = left.checked_div(stride).unwrap_or(0);
                return Err(truncated(el, i));
            }
            let need = need.unwrap_or(0);
            if is_vertex {
                read_fixed_vertices(path, &data[off..off + need], el, layout, big, &mut cloud)?;
            }
            off += need;
            continue;
        }
        // Lists: walk entry by entry.
        let mut values = vec![0.0f64; el.props.len()];
        if is_vertex {
            let cap = el.count.min(data.len() - off);
            cloud.points.reserve(cap);
            cloud.attributes = attribute_columns(el, layout);
        }
        for i in 0..el.count {
            for (pi, p) in el.props.iter().enumerate() {
                match p.kind {
                    Kind::Scalar(s) => {
                        let b = data
                            .get(off..off + s.size())
                            .ok_or_else(|| truncated(el, i))?;
                        values[pi] = s.decode(b, big);
                        off += s.size();
                    }
                    Kind::List { count, item } => {
                        let b = data
                            .get(off..off + count.size())
                            .ok_or_else(|| truncated(el, i))?;
                        let n = count.decode(b, big);
                        off += count.size();
                        if n < 0.0 {
                            return Err(IoError::format(
                                path,
                                format!(
                                    "PLY element '{}' entry {i}: negative list length",
                                    el.name
                                ),
                            ));
                        }
                        let len = (n as usize).checked_mul(item.size());
                        match len {
                            Some(len) if len <= data.len() - off => off += len,
                            _ => return Err(truncated(el, i)),
                        }
                    }
                }
            }
            if is_vertex {
                push_vertex(path, &values, layout, &mut cloud, None)?;
                for (c, &(i, _)) in cloud.attributes.iter_mut().zip(&layout.attrs) {
                    c.values.push_f64(values[i]);
                }
            }
        }
    }
    Ok(cloud)
}

/// Vertices with only scalar properties: one fixed-size record each.
fn read_fixed_vertices(
    path: &Path,
    data: &[u8],
    el: &Element,
    layout: &VertexLayout,
    big: bool,
    cloud: &mut PointCloud,
) -> Result<(), IoError> {
    let mut offsets = Vec::with_capacity(el.props.len());
    let mut stride = 0usize;
    for p in &el.props {
        offsets.push(stride);
        if let Kind::Scalar(s) = p.kind {
            stride += s.size();
        }
    }
    let field = |i: usize| match el.props[i].kind {
        Kind::Scalar(s) => (offsets[i], s),
        Kind::List { .. } => (0, Scalar::U8), // excluded by vertex_layout
    };
    let [fx, fy, fz] = layout.xyz.map(field);
    let fl = layout.label.map(field);
    if stride == 0 {
        return Ok(());
    }
    let bad_label = |i: usize, v: f64| {
        IoError::format(path, format!("PLY vertex {i}: label {v} is not an integer"))
    };
    cloud.points.reserve(el.count);
    let mut labels = Vec::new();
    if !layout.attrs.is_empty() {
        let mut columns = attribute_columns(el, layout);
        let at: Vec<usize> = layout.attrs.iter().map(|&(i, _)| offsets[i]).collect();
        for rec in data.chunks_exact(stride) {
            for (c, &o) in columns.iter_mut().zip(&at) {
                c.values.push_bytes(&rec[o..], big);
            }
        }
        cloud.attributes = columns;
    }
    for rec in data.chunks_exact(stride) {
        let p = [
            fx.1.decode(&rec[fx.0..], big),
            fy.1.decode(&rec[fy.0..], big),
            fz.1.decode(&rec[fz.0..], big),
        ];
        check_finite(path, &p, cloud.points.len(), None)?;
        cloud.points.push(p);
        if let Some((o, s)) = fl {
            let v = s.decode(&rec[o..], big);
            labels.push(label_of(v).ok_or_else(|| bad_label(cloud.points.len() - 1, v))?);
        }
    }
    if fl.is_some() {
        cloud.labels = Some(labels);
    }
    Ok(())
}

fn push_vertex(
    path: &Path,
    values: &[f64],
    layout: &VertexLayout,
    cloud: &mut PointCloud,
    line: Option<usize>,
) -> Result<(), IoError> {
    let p = layout.xyz.map(|i| values[i]);
    check_finite(path, &p, cloud.points.len(), line)?;
    cloud.points.push(p);
    if let Some(i) = layout.label {
        let v = values[i];
        let label = label_of(v).ok_or_else(|| {
            let at = cloud.points.len() - 1;
            match line {
                Some(line) => IoError::parse(path, line, format!("label {v} is not an integer")),
                None => IoError::format(
                    path,
                    format!("PLY vertex {at}: label {v} is not an integer"),
                ),
            }
        })?;
        cloud.labels.get_or_insert_with(Vec::new).push(label);
    }
    Ok(())
}

/// Ascii data: one entry per line (blank lines are skipped).
fn read_ascii(
    path: &Path,
    data: &[u8],
    header: &Header,
    vertex: usize,
    layout: &VertexLayout,
) -> Result<PointCloud, IoError> {
    let mut lines = data.split(|&b| b == b'\n').enumerate();
    let mut cloud = PointCloud::default();
    let mut last_line = header.lines;
    for (ei, el) in header.elements.iter().enumerate() {
        let is_vertex = ei == vertex;
        let mut values = vec![0.0f64; el.props.len()];
        // Per property: whether it is read (x, y, z, the label, attributes).
        let mut wanted = vec![false; el.props.len()];
        if is_vertex {
            cloud.points.reserve(el.count.min(data.len() / 6));
            cloud.attributes = attribute_columns(el, layout);
            for i in layout.xyz.iter().chain(&layout.label) {
                wanted[*i] = true;
            }
            for &(i, _) in &layout.attrs {
                wanted[i] = true;
            }
        }
        for i in 0..el.count {
            let (ln, raw) = loop {
                match lines.next() {
                    Some((_, l)) if l.iter().all(|b| b.is_ascii_whitespace()) => {}
                    Some((k, l)) => break (header.lines + k + 1, l),
                    None => {
                        return Err(IoError::parse(
                            path,
                            last_line + 1,
                            format!(
                                "PLY file ends early: element '{}' declares {} entries, found {}",
                                el.name, el.count, i
                            ),
                        ))
                    }
                }
            };
            last_line = ln;
            let mut toks = raw
                .split(|b| b.is_ascii_whitespace())
                .filter(|t| !t.is_empty());
            let missing = || {
                IoError::parse(
                    path,
                    ln,
                    format!("too few values for an entry of element '{}'", el.name),
                )
            };
            for (pi, p) in el.props.iter().enumerate() {
                match p.kind {
                    Kind::Scalar(s) => {
                        let t = toks.next().ok_or_else(missing)?;
                        if wanted[pi] {
                            values[pi] = s.parse(t).map_err(|why| {
                                IoError::parse(
                                    path,
                                    ln,
                                    format!(
                                        "invalid value '{}' for property '{}': {why}",
                                        show_token(t),
                                        p.name
                                    ),
                                )
                            })?;
                        }
                    }
                    Kind::List { .. } => {
                        let t = toks.next().ok_or_else(missing)?;
                        let n = std::str::from_utf8(t)
                            .ok()
                            .and_then(|s| s.parse::<usize>().ok())
                            .ok_or_else(|| {
                                IoError::parse(
                                    path,
                                    ln,
                                    format!("invalid list length '{}'", show_token(t)),
                                )
                            })?;
                        for _ in 0..n {
                            toks.next().ok_or_else(missing)?;
                        }
                    }
                }
            }
            if is_vertex {
                push_vertex(path, &values, layout, &mut cloud, Some(ln))?;
                for (c, &(i, _)) in cloud.attributes.iter_mut().zip(&layout.attrs) {
                    c.values.push_f64(values[i]);
                }
            }
        }
    }
    Ok(cloud)
}

// ---------------------------------------------------------------- writer

/// PLY encodings the writer produces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlyEncoding {
    /// Text; coordinates printed in shortest round-trip form, so reading
    /// back gives the same bits.
    Ascii,
    /// Binary little endian (the compact default).
    #[default]
    BinaryLittleEndian,
}

/// Points with optional labels, edges and triangles, for [`write_ply`] and
/// [`super::write_obj`]. Indices refer to `points`.
///
/// ```
/// use aniso_alpha::io::Mesh;
/// let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// let mesh = Mesh { faces: &[[0, 1, 2]], ..Mesh::new(&pts) };
/// assert_eq!(mesh.edges.len(), 0);
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Mesh<'a> {
    /// Vertex coordinates.
    pub points: &'a [[f64; 3]],
    /// One label per point (written as the int vertex property
    /// `structure`), if any.
    pub labels: Option<&'a [i64]>,
    /// One part id per point (the int vertex property `part`), if any
    /// (PLY only).
    pub parts: Option<&'a [i64]>,
    /// More vertex properties, one value per point each, written after
    /// `structure` and `part` in their own type (64-bit integers as
    /// `double`; PLY only). Names must be unique, without whitespace, and
    /// none of x, y, z, structure, part.
    pub attributes: &'a [Attribute],
    /// Edges (PLY element `edge`, OBJ `l` lines).
    pub edges: &'a [[u32; 2]],
    /// Triangles (PLY element `face`, OBJ `f` lines).
    pub faces: &'a [[u32; 3]],
    /// Per edge, then per face: (structure, part), written as the int
    /// properties `structure` and `part` of the `edge` and `face` elements
    /// (PLY only). Either empty or one per edge and face.
    pub element_labels: &'a [[i64; 2]],
}

impl<'a> Mesh<'a> {
    /// Just points: no labels, edges or faces.
    pub fn new(points: &'a [[f64; 3]]) -> Self {
        Mesh {
            points,
            labels: None,
            parts: None,
            attributes: &[],
            edges: &[],
            faces: &[],
            element_labels: &[],
        }
    }

    /// Checks labels and indices; an `InvalidInput` error otherwise.
    pub(crate) fn validate(&self) -> std::io::Result<()> {
        let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, m);
        let n = self.points.len();
        for l in [self.labels, self.parts].into_iter().flatten() {
            if l.len() != n {
                return Err(invalid(format!("{} labels for {} points", l.len(), n)));
            }
            if let Some(v) = l.iter().find(|v| i32::try_from(**v).is_err()) {
                return Err(invalid(format!("label {v} does not fit a PLY int")));
            }
        }
        let mut names: Vec<&str> = vec!["x", "y", "z"];
        if self.labels.is_some() {
            names.push("structure");
        }
        if self.parts.is_some() {
            names.push("part");
        }
        for a in self.attributes {
            if a.values.len() != n {
                return Err(invalid(format!(
                    "attribute '{}' has {} values for {} points",
                    a.name,
                    a.values.len(),
                    n
                )));
            }
            if a.name.is_empty() || a.name.chars().any(|c| c.is_whitespace()) {
                return Err(invalid(format!(
                    "attribute name '{}' is not a PLY property name",
                    a.name
                )));
            }
            if names.contains(&a.name.as_str()) {
                return Err(invalid(format!("two vertex properties named '{}'", a.name)));
            }
            names.push(&a.name);
        }
        let ne = self.edges.len() + self.faces.len();
        if !self.element_labels.is_empty() && self.element_labels.len() != ne {
            return Err(invalid(format!(
                "{} element labels for {ne} edges and faces",
                self.element_labels.len()
            )));
        }
        if let Some(v) = self
            .element_labels
            .iter()
            .flatten()
            .find(|v| i32::try_from(**v).is_err())
        {
            return Err(invalid(format!("label {v} does not fit a PLY int")));
        }
        let limit = n.min(i32::MAX as usize);
        let bad = self
            .edges
            .iter()
            .flatten()
            .chain(self.faces.iter().flatten())
            .find(|&&i| i as usize >= limit);
        if let Some(i) = bad {
            return Err(invalid(format!(
                "vertex index {i} out of range ({n} points)"
            )));
        }
        Ok(())
    }
}

/// Writes `mesh` as PLY to `path`, atomically: vertices with `double x, y,
/// z` (plus `int structure` when labels are given), then an `edge` element
/// (`int vertex1, int vertex2`) and a `face` element (`list uchar int
/// vertex_indices`) when present.
///
/// ```
/// use aniso_alpha::io::{read_points, write_ply, Mesh, PlyEncoding, ReadOptions};
/// let path = std::env::temp_dir().join(format!("doc-{}.ply", std::process::id()));
/// let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// let labels = [0, 0, -1];
/// let mesh = Mesh { labels: Some(&labels), faces: &[[0, 1, 2]], ..Mesh::new(&pts) };
/// write_ply(&path, &mesh, PlyEncoding::BinaryLittleEndian).unwrap();
/// let back = read_points(&path, &ReadOptions::with_labels(3)).unwrap();
/// assert_eq!(back.points, pts);
/// assert_eq!(back.labels, Some(labels.to_vec()));
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_ply(path: &Path, mesh: &Mesh<'_>, encoding: PlyEncoding) -> Result<(), IoError> {
    atomic_write(path, |w| write_ply_to(w, mesh, encoding))
}

/// Writes `mesh` as PLY to any writer (see [`write_ply`]).
pub fn write_ply_to(
    w: &mut dyn Write,
    mesh: &Mesh<'_>,
    encoding: PlyEncoding,
) -> std::io::Result<()> {
    mesh.validate()?;
    let fmt = match encoding {
        PlyEncoding::Ascii => "ascii",
        PlyEncoding::BinaryLittleEndian => "binary_little_endian",
    };
    write!(
        w,
        "ply\nformat {fmt} 1.0\ncomment written by aniso-alpha\nelement vertex {}\n\
         property double x\nproperty double y\nproperty double z\n",
        mesh.points.len()
    )?;
    if mesh.labels.is_some() {
        w.write_all(b"property int structure\n")?;
    }
    if mesh.parts.is_some() {
        w.write_all(b"property int part\n")?;
    }
    for a in mesh.attributes {
        writeln!(w, "property {} {}", ply_type_name(a.values.ty()), a.name)?;
    }
    let el = !mesh.element_labels.is_empty();
    let el_props: &[u8] = if el {
        b"property int structure\nproperty int part\n"
    } else {
        b""
    };
    if !mesh.edges.is_empty() {
        write!(
            w,
            "element edge {}\nproperty int vertex1\nproperty int vertex2\n",
            mesh.edges.len()
        )?;
        w.write_all(el_props)?;
    }
    if !mesh.faces.is_empty() {
        write!(
            w,
            "element face {}\nproperty list uchar int vertex_indices\n",
            mesh.faces.len()
        )?;
        w.write_all(el_props)?;
    }
    let (edge_labels, face_labels) = if el {
        mesh.element_labels.split_at(mesh.edges.len())
    } else {
        (&[][..], &[][..])
    };
    w.write_all(b"end_header\n")?;
    match encoding {
        PlyEncoding::Ascii => {
            for (i, p) in mesh.points.iter().enumerate() {
                write!(w, "{} {} {}", p[0], p[1], p[2])?;
                for l in [mesh.labels, mesh.parts].into_iter().flatten() {
                    write!(w, " {}", l[i])?;
                }
                for a in mesh.attributes {
                    write_ascii_value(w, &a.values, i)?;
                }
                w.write_all(b"\n")?;
            }
            for (k, e) in mesh.edges.iter().enumerate() {
                write!(w, "{} {}", e[0], e[1])?;
                if let Some([s, p]) = edge_labels.get(k) {
                    write!(w, " {s} {p}")?;
                }
                w.write_all(b"\n")?;
            }
            for (k, f) in mesh.faces.iter().enumerate() {
                write!(w, "3 {} {} {}", f[0], f[1], f[2])?;
                if let Some([s, p]) = face_labels.get(k) {
                    write!(w, " {s} {p}")?;
                }
                w.write_all(b"\n")?;
            }
        }
        PlyEncoding::BinaryLittleEndian => {
            let mut buf = Vec::with_capacity(1 << 16);
            let mut flush = |buf: &mut Vec<u8>, force: bool| -> std::io::Result<()> {
                if force || buf.len() >= (1 << 16) - 64 {
                    w.write_all(buf)?;
                    buf.clear();
                }
                Ok(())
            };
            for (i, p) in mesh.points.iter().enumerate() {
                for c in p {
                    buf.extend_from_slice(&c.to_le_bytes());
                }
                for l in [mesh.labels, mesh.parts].into_iter().flatten() {
                    buf.extend_from_slice(&(l[i] as i32).to_le_bytes());
                }
                for a in mesh.attributes {
                    match &a.values {
                        Values::I64(_) | Values::U64(_) => {
                            buf.extend_from_slice(&a.values.get_f64(i).to_le_bytes())
                        }
                        v => v.write_le(i, &mut buf),
                    }
                }
                flush(&mut buf, false)?;
            }
            for (k, e) in mesh.edges.iter().enumerate() {
                for v in e {
                    buf.extend_from_slice(&(*v as i32).to_le_bytes());
                }
                if let Some(sp) = edge_labels.get(k) {
                    for x in sp {
                        buf.extend_from_slice(&(*x as i32).to_le_bytes());
                    }
                }
                flush(&mut buf, false)?;
            }
            for (k, f) in mesh.faces.iter().enumerate() {
                buf.push(3);
                for v in f {
                    buf.extend_from_slice(&(*v as i32).to_le_bytes());
                }
                if let Some(sp) = face_labels.get(k) {
                    for x in sp {
                        buf.extend_from_slice(&(*x as i32).to_le_bytes());
                    }
                }
                flush(&mut buf, false)?;
            }
            flush(&mut buf, true)?;
        }
    }
    Ok(())
}

/// The PLY type an attribute is written as (64-bit integers as `double`,
/// PLY having none).
fn ply_type_name(ty: AttributeType) -> &'static str {
    match ty {
        AttributeType::I8 => "char",
        AttributeType::U8 => "uchar",
        AttributeType::I16 => "short",
        AttributeType::U16 => "ushort",
        AttributeType::I32 => "int",
        AttributeType::U32 => "uint",
        AttributeType::F32 => "float",
        AttributeType::F64 | AttributeType::I64 | AttributeType::U64 => "double",
    }
}

/// ` value` of attribute values `v` at `i`, in shortest round-trip form.
fn write_ascii_value(w: &mut dyn Write, v: &Values, i: usize) -> std::io::Result<()> {
    match v {
        Values::I8(x) => write!(w, " {}", x[i]),
        Values::U8(x) => write!(w, " {}", x[i]),
        Values::I16(x) => write!(w, " {}", x[i]),
        Values::U16(x) => write!(w, " {}", x[i]),
        Values::I32(x) => write!(w, " {}", x[i]),
        Values::U32(x) => write!(w, " {}", x[i]),
        Values::I64(_) | Values::U64(_) => write!(w, " {}", v.get_f64(i)),
        Values::F32(x) => write!(w, " {}", x[i]),
        Values::F64(x) => write!(w, " {}", x[i]),
    }
}
