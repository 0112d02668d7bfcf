//! The interactive viewer: one self-contained HTML file (`aniso-alpha view`,
//! `detect --html`).
//!
//! The page needs no server and no network: the renderer (about 9 KB of
//! hand-written WebGL 1 JavaScript, [`VIEWER_JS`]) and the data are inlined.
//! A general 3D library would have cost far more bytes than the data of a
//! small scene (three.js's minified build alone is about 600 KB) for the
//! three things drawn here: point sprites, line segments and an orbit
//! camera.
//!
//! Data layout: the points are sorted background first, then structure by
//! structure, so that toggling a structure is skipping a range of one
//! vertex buffer. Positions are `float32` relative to the bounding box's
//! centre (subtracted in `f64`, so that georeferenced coordinates keep
//! their precision), colours `uint8` RGB; both are base64 in
//! `<script type="application/octet-stream">` elements. The structures,
//! parts, plane equations, segments and outlines are a JSON model; the
//! legend is plain HTML written here, so that it reads even where WebGL
//! does not run.
//!
//! At most [`DEFAULT_MAX_POINTS`] points are shown by default: beyond that
//! the background is thinned first (down to a tenth of the cap), then the
//! structures, each in proportion, by a fixed pseudo-random choice (the
//! same file gives the same page). The page states how many were kept.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use aniso_alpha::detect::fit::{fit_line_indices, fit_plane_indices};
use aniso_alpha::rng::mix;
use base64::Engine as _;
use serde_json::{json, Value};

use crate::common::CliError;
use crate::picture::{part_color, structure_color, BACKGROUND_DARK};

/// Default cap on the points drawn (`view --max-points`): 500,000 points
/// make a page of about 10 MB that a browser loads in a second or two and
/// orbits smoothly on integrated graphics.
pub const DEFAULT_MAX_POINTS: usize = 500_000;

/// The colour of the points when no labels are given.
const UNLABELLED: [u8; 3] = [176, 182, 190];

/// What the viewer shows.
#[derive(Debug, Clone, Copy)]
pub struct ViewInput<'a> {
    /// The page's title (usually the input file's name).
    pub title: &'a str,
    /// The points, in input order.
    pub points: &'a [[f64; 3]],
    /// Per point: its structure id, or −1 (background).
    pub labels: Option<&'a [i64]>,
    /// Per point: its part id, or −1 (ids shared by all structures, as
    /// `detect --part-labels` writes them).
    pub parts: Option<&'a [i64]>,
    /// A `detect --report` JSON: both the current schema (parts with
    /// `plane`/`polygon` or `segment`, `rms`, `log10_nfa` or `nfa`) and the older
    /// one (a `primitive` object per structure and part) are read.
    pub report: Option<&'a Value>,
    /// Cap on the points drawn.
    pub max_points: usize,
}

/// The kind of a structure or part, as the legend names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Plane,
    Surface,
    Line,
    Polyline,
    Unknown,
}

impl Kind {
    fn parse(s: &str) -> Kind {
        match s {
            "plane" => Kind::Plane,
            "surface" => Kind::Surface,
            "line" => Kind::Line,
            "polyline" => Kind::Polyline,
            _ => Kind::Unknown,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Kind::Plane => "plane",
            Kind::Surface => "surface",
            Kind::Line => "line",
            Kind::Polyline => "polyline",
            Kind::Unknown => "structure",
        }
    }
    fn linear(self) -> Option<bool> {
        match self {
            Kind::Plane | Kind::Surface => Some(false),
            Kind::Line | Kind::Polyline => Some(true),
            Kind::Unknown => None,
        }
    }
}

/// A part of a structure as the viewer knows it.
#[derive(Debug, Clone, Default)]
struct PartView {
    id: Option<i64>,
    points: Option<u64>,
    rms: Option<f64>,
    log10_nfa: Option<f64>,
    plane: Option<[f64; 4]>,
    segment: Option<[[f64; 3]; 2]>,
    /// Closed polygon (planes) or open polyline (a segment): vertices.
    outline: Vec<[f64; 3]>,
    closed: bool,
    /// Where the outline came from: `report`, `points`, or `fit`.
    outline_source: &'static str,
}

#[derive(Debug, Clone)]
struct StructureView {
    id: i64,
    kind: Kind,
    points: Option<u64>,
    rms: Option<f64>,
    /// log₁₀ of the number of false alarms.
    log10_nfa: Option<f64>,
    plane: Option<[f64; 4]>,
    segment: Option<[[f64; 3]; 2]>,
    parts: Vec<PartView>,
}

fn f64_of(v: &Value) -> Option<f64> {
    v.as_f64().filter(|x| x.is_finite())
}

fn vec3(v: &Value) -> Option<[f64; 3]> {
    let a = v.as_array()?;
    if a.len() != 3 {
        return None;
    }
    Some([f64_of(&a[0])?, f64_of(&a[1])?, f64_of(&a[2])?])
}

fn vec4(v: &Value) -> Option<[f64; 4]> {
    let a = v.as_array()?;
    if a.len() != 4 {
        return None;
    }
    Some([
        f64_of(&a[0])?,
        f64_of(&a[1])?,
        f64_of(&a[2])?,
        f64_of(&a[3])?,
    ])
}

fn add(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A plane `[a, b, c, d]`, a segment, and an outline's vertices.
type Geometry = (Option<[f64; 4]>, Option<[[f64; 3]; 2]>, Vec<[f64; 3]>);

/// Plane, segment and outline of an older report's `primitive` object.
fn from_primitive(p: &Value) -> Geometry {
    let c = vec3(&p["centroid"]);
    match (p["type"].as_str(), c) {
        (Some("plane"), Some(c)) => {
            let Some(n) = vec3(&p["normal"]) else {
                return (None, None, Vec::new());
            };
            let plane = [n[0], n[1], n[2], -dot(n, c)];
            let axes = p["axes"].as_array();
            let ext = p["extent"].as_array();
            let rect = match (axes, ext) {
                (Some(ax), Some(ex)) if ax.len() == 2 && ex.len() == 2 => {
                    match (vec3(&ax[0]), vec3(&ax[1]), f64_of(&ex[0]), f64_of(&ex[1])) {
                        (Some(u), Some(v), Some(a), Some(b)) => {
                            let (a, b) = (a / 2.0, b / 2.0);
                            vec![
                                add(add(c, u, -a), v, -b),
                                add(add(c, u, a), v, -b),
                                add(add(c, u, a), v, b),
                                add(add(c, u, -a), v, b),
                            ]
                        }
                        _ => Vec::new(),
                    }
                }
                _ => Vec::new(),
            };
            (Some(plane), None, rect)
        }
        (Some("line"), Some(c)) => match (vec3(&p["direction"]), f64_of(&p["extent"])) {
            (Some(d), Some(len)) => {
                let seg = [add(c, d, -len / 2.0), add(c, d, len / 2.0)];
                (None, Some(seg), seg.to_vec())
            }
            _ => (None, None, Vec::new()),
        },
        _ => (None, None, Vec::new()),
    }
}

fn part_from_report(p: &Value, running_id: i64) -> PartView {
    let mut part = PartView {
        id: Some(p["id"].as_i64().unwrap_or(running_id)),
        points: p["points"].as_u64(),
        rms: f64_of(&p["rms"]),
        log10_nfa: log10_nfa(p),
        plane: vec4(&p["plane"]),
        segment: None,
        outline: Vec::new(),
        closed: false,
        outline_source: "",
    };
    if let Some(poly) = p["polygon"].as_array() {
        let pts: Vec<[f64; 3]> = poly.iter().filter_map(vec3).collect();
        if pts.len() >= 2 && pts.len() == poly.len() {
            part.outline = pts;
            part.closed = true;
            part.outline_source = "report";
        }
    }
    if let Some(seg) = p["segment"].as_array() {
        if seg.len() == 2 {
            if let (Some(a), Some(b)) = (vec3(&seg[0]), vec3(&seg[1])) {
                part.segment = Some([a, b]);
                if part.outline.is_empty() {
                    part.outline = vec![a, b];
                    part.outline_source = "report";
                }
            }
        }
    }
    let prim = &p["primitive"];
    if prim.is_object() {
        if part.rms.is_none() {
            part.rms = f64_of(&prim["rms_residual"]);
        }
        let (plane, seg, outline) = from_primitive(prim);
        part.plane = part.plane.or(plane);
        part.segment = part.segment.or(seg);
        if part.outline.is_empty() && !outline.is_empty() {
            part.closed = plane.is_some();
            part.outline = outline;
            part.outline_source = "fit";
        }
    }
    part
}

/// The structures named by the report, in its order.
fn structures_from_report(report: &Value) -> Vec<StructureView> {
    let mut out = Vec::new();
    let Some(list) = report["structures"].as_array() else {
        return out;
    };
    // Older reports have no part ids: parts are numbered structure by
    // structure, as `detect --part-labels` numbers them.
    let mut running = 0i64;
    for (i, s) in list.iter().enumerate() {
        let prim = &s["primitive"];
        let (plane, segment, _) = if prim.is_object() {
            from_primitive(prim)
        } else {
            (None, None, Vec::new())
        };
        let parts: Vec<PartView> = s["parts"]
            .as_array()
            .map(|ps| {
                ps.iter()
                    .map(|p| {
                        let part = part_from_report(p, running);
                        running += 1;
                        part
                    })
                    .collect()
            })
            .unwrap_or_default();
        out.push(StructureView {
            id: s["id"].as_i64().unwrap_or(i as i64),
            kind: Kind::parse(s["kind"].as_str().unwrap_or("")),
            points: s["points"].as_u64(),
            rms: f64_of(&s["rms"]).or_else(|| f64_of(&prim["rms_residual"])),
            log10_nfa: log10_nfa(s),
            plane,
            segment,
            parts,
        });
    }
    out
}

/// 2D convex hull (Andrew's monotone chain), counter-clockwise, indices.
fn hull_2d(pts: &[[f64; 2]]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    idx.sort_by(|&a, &b| {
        pts[a][0]
            .total_cmp(&pts[b][0])
            .then(pts[a][1].total_cmp(&pts[b][1]))
    });
    idx.dedup_by(|a, b| pts[*a] == pts[*b]);
    if idx.len() < 3 {
        return idx;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut h: Vec<usize> = Vec::with_capacity(2 * idx.len());
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &usize>> = if pass == 0 {
            Box::new(idx.iter())
        } else {
            Box::new(idx.iter().rev())
        };
        for &i in it {
            while h.len() >= start + 2
                && cross(pts[h[h.len() - 2]], pts[h[h.len() - 1]], pts[i]) <= 0.0
            {
                h.pop();
            }
            h.push(i);
        }
        h.pop();
    }
    h
}

/// The outline of a part computed from its points.
pub(crate) struct Outline {
    /// Polygon (closed) or segment (open) vertices.
    pub vertices: Vec<[f64; 3]>,
    closed: bool,
    plane: Option<[f64; 4]>,
    segment: Option<[[f64; 3]; 2]>,
    rms: f64,
}

/// Outline of a set of points from their own fit: the convex hull of
/// their projection on the least-squares plane, or the extreme
/// projections on the least-squares line.
pub(crate) fn outline_of_points(
    points: &[[f64; 3]],
    members: &[u32],
    linear: bool,
) -> Option<Outline> {
    if linear {
        let f = fit_line_indices(points, members).ok()?;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &i in members {
            let p = points[i as usize];
            let t = dot(
                [
                    p[0] - f.centroid[0],
                    p[1] - f.centroid[1],
                    p[2] - f.centroid[2],
                ],
                f.direction,
            );
            lo = lo.min(t);
            hi = hi.max(t);
        }
        let seg = [
            add(f.centroid, f.direction, lo),
            add(f.centroid, f.direction, hi),
        ];
        Some(Outline {
            vertices: seg.to_vec(),
            closed: false,
            plane: None,
            segment: Some(seg),
            rms: f.rms_residual,
        })
    } else {
        let f = fit_plane_indices(points, members).ok()?;
        let [u, v] = f.axes;
        let c = f.centroid;
        let flat: Vec<[f64; 2]> = members
            .iter()
            .map(|&i| {
                let p = points[i as usize];
                let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
                [dot(d, u), dot(d, v)]
            })
            .collect();
        let hull = hull_2d(&flat);
        let n = f.normal;
        Some(Outline {
            vertices: hull
                .iter()
                .map(|&k| add(add(c, u, flat[k][0]), v, flat[k][1]))
                .collect(),
            closed: true,
            plane: Some([n[0], n[1], n[2], -dot(n, c)]),
            segment: None,
            rms: f.rms_residual,
        })
    }
}

/// Keeps `keep` of `members` chosen by a fixed pseudo-random key, in their
/// original order.
fn thin(members: &mut Vec<u32>, keep: usize) {
    if members.len() <= keep {
        return;
    }
    if keep == 0 {
        members.clear();
        return;
    }
    members.select_nth_unstable_by_key(keep - 1, |&i| mix(i as u64));
    members.truncate(keep);
    members.sort_unstable();
}

fn fmt_num(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        format!("{x:.3e}")
    } else {
        let s = format!("{x:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.into()
        }
    }
}

fn fmt_plane(p: [f64; 4]) -> String {
    let mut s = String::new();
    for (k, (c, var)) in p[..3].iter().zip(["x", "y", "z"]).enumerate() {
        // A unit normal: six decimals (an error of 1e-6 rad moves a
        // 100 m plane by 0.1 mm).
        let v = format!("{:.6}", c.abs());
        let v = v.trim_end_matches('0').trim_end_matches('.');
        let c = &if v == "0" { 0.0 } else { *c };
        if k == 0 {
            if *c < 0.0 {
                s.push('−');
            }
        } else {
            s.push_str(if *c < 0.0 { " − " } else { " + " });
        }
        let _ = write!(s, "{v}{var}");
    }
    let _ = write!(
        s,
        " {} {} = 0",
        if p[3] < 0.0 { "−" } else { "+" },
        fmt_offset(p[3].abs())
    );
    s
}

/// A plane's offset d: as [`fmt_num`], but in full to the millimetre
/// (three decimals) from 1e6 to 1e15, where coordinates such as UTM's put
/// it and `1.121e6` would lose the plane.
fn fmt_offset(d: f64) -> String {
    if d.is_finite() && (1e6..1e15).contains(&d.abs()) {
        let s = format!("{d:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        fmt_num(d)
    }
}

/// A number of false alarms from its log₁₀.
fn fmt_nfa(log10: f64) -> String {
    let x = 10f64.powf(log10);
    if x > 0.0 && x.is_finite() {
        format!("{x:.2e}")
    } else {
        format!("10^{log10:.1}")
    }
}

/// `log10_nfa` of a report's structure or part (or `nfa`, older).
fn log10_nfa(v: &Value) -> Option<f64> {
    f64_of(&v["log10_nfa"]).or_else(|| f64_of(&v["nfa"]).filter(|x| *x > 0.0).map(f64::log10))
}

fn fmt_point(p: [f64; 3]) -> String {
    format!("({}, {}, {})", fmt_num(p[0]), fmt_num(p[1]), fmt_num(p[2]))
}

fn fmt_segment(s: [[f64; 3]; 2]) -> String {
    let len =
        ((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2) + (s[1][2] - s[0][2]).powi(2))
            .sqrt();
    format!(
        "{} → {}, length {}",
        fmt_point(s[0]),
        fmt_point(s[1]),
        fmt_num(len)
    )
}

fn html_escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            _ => o.push(c),
        }
    }
    o
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

fn b64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Writes the page of a detection to `path` (atomically, phase `write`):
/// what `detect --html` does.
pub fn write_html(
    path: &std::path::Path,
    title: &str,
    points: &[[f64; 3]],
    labels: &[i64],
    parts: &[i64],
    report: &Value,
    timings: &mut crate::common::Timings,
) -> Result<(), CliError> {
    let page = timings.phase("view", || {
        html(&ViewInput {
            title,
            points,
            labels: Some(labels),
            parts: Some(parts),
            report: Some(report),
            max_points: DEFAULT_MAX_POINTS,
        })
    })?;
    crate::common::write_output(path, timings, |w| w.write_all(page.as_bytes()))
}

/// The self-contained HTML page of `input`.
pub fn html(input: &ViewInput<'_>) -> Result<String, CliError> {
    check_input(input)?;
    let mut scene = structures_of(input);
    let counts = drawn_points(&mut scene, input.max_points);
    let frame = frame(input.points);
    let focus = first_view(input.points, &scene.members_of, &frame);
    let buffers = vertex_buffers(input, &scene, frame.center);
    let model = script_model(input, &frame, focus, &scene, &counts, &buffers);
    Ok(page(input, &scene, &counts, &model, &buffers))
}

/// The structures, and which points belong to each or to the background.
struct Scene {
    /// From the report first, then those only the labels name.
    structures: Vec<StructureView>,
    /// Per structure (as indexed in `structures`): its points.
    members_of: Vec<Vec<u32>>,
    /// The points of no structure.
    background: Vec<u32>,
}

/// How many points there are and how many are drawn.
struct Counts {
    /// Background points before thinning.
    background_total: usize,
    /// Points drawn, background and structures.
    shown: usize,
}

/// Where the scene lies: the bounding box's centre and half-diagonal.
struct Frame {
    center: [f64; 3],
    radius: f64,
}

/// The vertex buffers of the points and the outlines, and each structure's
/// range (first vertex, vertex count) in them.
struct Buffers {
    /// Points: positions (`float32` × 3, relative to the centre).
    pos: Vec<u8>,
    /// Points: colours (`uint8` RGB).
    col: Vec<u8>,
    /// Per structure: its points' range.
    ranges: Vec<(usize, usize)>,
    /// Outline segments: positions, two vertices a segment.
    lpos: Vec<u8>,
    /// Outline segments: colours.
    lcol: Vec<u8>,
    /// Per structure: its outline vertices' range.
    lranges: Vec<(usize, usize)>,
}

/// The errors of an input that cannot make a page: labels of the wrong
/// length, a cap of zero.
fn check_input(input: &ViewInput<'_>) -> Result<(), CliError> {
    let n = input.points.len();
    for (what, v) in [("labels", input.labels), ("part labels", input.parts)] {
        if let Some(v) = v {
            if v.len() != n {
                return Err(CliError::msg(format!("{} {what} for {n} points", v.len())));
            }
        }
    }
    if input.max_points == 0 {
        return Err(CliError::msg("--max-points must be at least 1"));
    }
    Ok(())
}

/// The structures (from the report, then those only the labels name, in id
/// order), their points and parts, completed from the points where the
/// report is silent.
fn structures_of(input: &ViewInput<'_>) -> Scene {
    let (mut structures, index_of_id) = structure_list(input);
    let mut members_of: Vec<Vec<u32>> = vec![Vec::new(); structures.len()];
    let mut background: Vec<u32> = Vec::new();
    match input.labels {
        Some(labels) => {
            for (i, &l) in labels.iter().enumerate() {
                if l < 0 {
                    background.push(i as u32);
                } else {
                    members_of[index_of_id[&l]].push(i as u32);
                }
            }
        }
        None => background.extend(0..input.points.len() as u32),
    }
    let part_members = part_members_of(input.parts);
    attach_label_parts(&mut structures, &part_members, input.labels, &index_of_id);
    complete_from_points(&mut structures, &members_of, &part_members, input.points);
    Scene {
        structures,
        members_of,
        background,
    }
}

/// The report's structures, then one per label id the report does not
/// know (in id order), and the index of each id in that list.
fn structure_list(input: &ViewInput<'_>) -> (Vec<StructureView>, BTreeMap<i64, usize>) {
    let mut structures = input.report.map(structures_from_report).unwrap_or_default();
    let mut index_of_id: BTreeMap<i64, usize> = BTreeMap::new();
    for (k, s) in structures.iter().enumerate() {
        index_of_id.entry(s.id).or_insert(k);
    }
    if let Some(labels) = input.labels {
        let ids: BTreeSet<i64> = labels.iter().copied().filter(|&l| l >= 0).collect();
        for id in ids {
            index_of_id.entry(id).or_insert_with(|| {
                structures.push(StructureView {
                    id,
                    kind: Kind::Unknown,
                    points: None,
                    rms: None,
                    log10_nfa: None,
                    plane: None,
                    segment: None,
                    parts: Vec::new(),
                });
                structures.len() - 1
            });
        }
    }
    (structures, index_of_id)
}

/// The members of each part the part labels name, by part id.
fn part_members_of(parts: Option<&[i64]>) -> BTreeMap<i64, Vec<u32>> {
    let mut part_members: BTreeMap<i64, Vec<u32>> = Default::default();
    if let Some(parts) = parts {
        for (i, &p) in parts.iter().enumerate() {
            if p >= 0 {
                part_members.entry(p).or_default().push(i as u32);
            }
        }
    }
    part_members
}

/// Parts known from the part labels only: each goes to the structure
/// holding most of its points.
fn attach_label_parts(
    structures: &mut [StructureView],
    part_members: &BTreeMap<i64, Vec<u32>>,
    labels: Option<&[i64]>,
    index_of_id: &BTreeMap<i64, usize>,
) {
    let structure_of_point = |i: u32| -> Option<usize> {
        let l = labels?[i as usize];
        index_of_id.get(&l).copied()
    };
    let known_parts: BTreeSet<i64> = structures
        .iter()
        .flat_map(|s| s.parts.iter().filter_map(|p| p.id))
        .collect();
    let mut extra: Vec<(usize, i64)> = Vec::new();
    for (&pid, members) in part_members {
        if known_parts.contains(&pid) {
            continue;
        }
        let mut votes: BTreeMap<usize, usize> = Default::default();
        for &i in members {
            if let Some(k) = structure_of_point(i) {
                *votes.entry(k).or_default() += 1;
            }
        }
        if let Some((&k, _)) = votes
            .iter()
            .max_by_key(|(&k, &c)| (c, std::cmp::Reverse(k)))
        {
            extra.push((k, pid));
        }
    }
    for (k, pid) in extra {
        structures[k].parts.push(PartView {
            id: Some(pid),
            points: Some(part_members[&pid].len() as u64),
            ..Default::default()
        });
    }
}

/// Kinds, counts and outlines from the points where the report is silent.
fn complete_from_points(
    structures: &mut [StructureView],
    members_of: &[Vec<u32>],
    part_members: &BTreeMap<i64, Vec<u32>>,
    points: &[[f64; 3]],
) {
    for (k, s) in structures.iter_mut().enumerate() {
        let members = &members_of[k];
        if s.points.is_none() {
            s.points = Some(members.len() as u64);
        }
        if s.kind == Kind::Unknown && members.len() >= 3 {
            s.kind = guess_kind(points, members, s.parts.len());
        }
        let linear = s.kind.linear().unwrap_or(false);
        let n_parts = s.parts.len();
        for part in &mut s.parts {
            let own = part.id.and_then(|id| part_members.get(&id));
            // Points beat a fitted rectangle; the report's own outline
            // beats both.
            if part.outline_source == "report" {
                continue;
            }
            let pts: Option<&Vec<u32>> = own.or(if n_parts == 1 { Some(members) } else { None });
            if let Some(pts) = pts.filter(|p| p.len() >= 2) {
                if let Some(o) = outline_of_points(points, pts, linear) {
                    part.outline = o.vertices;
                    part.closed = o.closed;
                    part.outline_source = "points";
                    part.plane = part.plane.or(o.plane);
                    part.segment = part.segment.or(o.segment);
                    part.rms = part.rms.or(Some(o.rms));
                    if part.points.is_none() {
                        part.points = Some(pts.len() as u64);
                    }
                }
            }
        }
        if s.parts.is_empty() && members.len() >= 3 {
            if let Some(o) = outline_of_points(points, members, linear) {
                s.parts.push(PartView {
                    id: None,
                    points: Some(members.len() as u64),
                    rms: Some(o.rms),
                    log10_nfa: None,
                    plane: o.plane,
                    segment: o.segment,
                    outline: o.vertices,
                    closed: o.closed,
                    outline_source: "points",
                });
            }
        }
        if s.parts.len() == 1 {
            s.plane = s.plane.or(s.parts[0].plane);
            s.segment = s.segment.or(s.parts[0].segment);
            s.rms = s.rms.or(s.parts[0].rms);
        }
    }
}

/// Which points are drawn: thins the background first (down to a tenth of
/// `cap`), then the structures, each in proportion.
fn drawn_points(scene: &mut Scene, cap: usize) -> Counts {
    let members_of = &mut scene.members_of;
    let background = &mut scene.background;
    let n_struct: usize = members_of.iter().map(Vec::len).sum();
    let n_bg_all = background.len();
    let bg_keep = if n_bg_all + n_struct <= cap {
        n_bg_all
    } else {
        n_bg_all.min(cap.saturating_sub(n_struct).max(cap / 10))
    };
    thin(background, bg_keep);
    let struct_budget = cap - background.len();
    if n_struct > struct_budget {
        for m in members_of.iter_mut() {
            let keep = ((m.len() as u128 * struct_budget as u128) / n_struct as u128) as usize;
            thin(m, keep);
        }
    }
    let shown: usize = background.len() + members_of.iter().map(Vec::len).sum::<usize>();
    Counts {
        background_total: n_bg_all,
        shown,
    }
}

/// The bounding box (min, max) of `points`; min above max for none.
fn bounds(points: impl IntoIterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Half the diagonal of the box (`lo`, `hi`).
fn half_diagonal(lo: [f64; 3], hi: [f64; 3]) -> f64 {
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt() / 2.0
}

/// The geometry: the centre of the points' bounding box and its
/// half-diagonal (1 for no points or a single one).
fn frame(points: &[[f64; 3]]) -> Frame {
    if points.is_empty() {
        return Frame {
            center: [0.0; 3],
            radius: 1.0,
        };
    }
    let (lo, hi) = bounds(points.iter().copied());
    let d = half_diagonal(lo, hi);
    Frame {
        center: [0, 1, 2].map(|k| (lo[k] + hi[k]) / 2.0),
        radius: if d > 0.0 { d } else { 1.0 },
    }
}

/// The first view (`{"center", "radius"}`, relative to the frame's centre):
/// framed on the structures' drawn points, else on everything.
fn first_view(points: &[[f64; 3]], members_of: &[Vec<u32>], frame: &Frame) -> Value {
    let (center, radius) = (frame.center, frame.radius);
    let (lo, hi) = bounds(members_of.iter().flatten().map(|&i| points[i as usize]));
    if lo[0] <= hi[0] {
        let c: Vec<f64> = (0..3).map(|k| (lo[k] + hi[k]) / 2.0 - center[k]).collect();
        let r = half_diagonal(lo, hi);
        json!({"center": c, "radius": if r > 0.0 { r * 1.2 } else { radius }})
    } else {
        json!({"center": [0.0, 0.0, 0.0], "radius": radius})
    }
}

/// Appends `p`, relative to `center`, as three little-endian `float32`.
fn push_pos(pos: &mut Vec<u8>, p: [f64; 3], center: [f64; 3]) {
    for k in 0..3 {
        pos.extend_from_slice(&((p[k] - center[k]) as f32).to_le_bytes());
    }
}

/// The vertex buffers: the drawn points (background first, then structure
/// by structure) and the parts' outlines as line segments.
fn vertex_buffers(input: &ViewInput<'_>, scene: &Scene, center: [f64; 3]) -> Buffers {
    let structures = &scene.structures;
    let shown = scene.background.len() + scene.members_of.iter().map(Vec::len).sum::<usize>();
    let part_index: BTreeMap<i64, usize> = structures
        .iter()
        .flat_map(|s| {
            s.parts
                .iter()
                .enumerate()
                .filter_map(|(j, p)| p.id.map(|id| (id, j)))
        })
        .collect();
    let mut pos: Vec<u8> = Vec::with_capacity(shown * 12);
    let mut col: Vec<u8> = Vec::with_capacity(shown * 3);
    // Unlabelled points are not background: drawn light, not dimmed.
    let bg_color = if input.labels.is_some() {
        BACKGROUND_DARK
    } else {
        UNLABELLED
    };
    for &i in &scene.background {
        push_pos(&mut pos, input.points[i as usize], center);
        col.extend_from_slice(&bg_color);
    }
    let mut ranges = Vec::with_capacity(structures.len());
    let mut start = scene.background.len();
    for (k, m) in scene.members_of.iter().enumerate() {
        for &i in m {
            push_pos(&mut pos, input.points[i as usize], center);
            let part = input
                .parts
                .map(|p| p[i as usize])
                .filter(|&p| p >= 0)
                .and_then(|p| part_index.get(&p).copied());
            col.extend_from_slice(&match part {
                Some(j) => part_color(k, j),
                None => structure_color(k),
            });
        }
        ranges.push((start, m.len()));
        start += m.len();
    }
    let mut lpos: Vec<u8> = Vec::new();
    let mut lcol: Vec<u8> = Vec::new();
    let mut lranges = Vec::with_capacity(structures.len());
    let mut lstart = 0usize;
    for (k, s) in structures.iter().enumerate() {
        let mut count = 0;
        for (j, p) in s.parts.iter().enumerate() {
            let c = lighten(part_color(k, j));
            let m = p.outline.len();
            let segs = if p.closed && m >= 3 {
                m
            } else {
                m.saturating_sub(1)
            };
            for e in 0..segs {
                push_pos(&mut lpos, p.outline[e], center);
                push_pos(&mut lpos, p.outline[(e + 1) % m], center);
                lcol.extend_from_slice(&c);
                lcol.extend_from_slice(&c);
                count += 2;
            }
        }
        lranges.push((lstart, count));
        lstart += count;
    }
    Buffers {
        pos,
        col,
        ranges,
        lpos,
        lcol,
        lranges,
    }
}

/// The JSON model for the script, escaped for a `<script>` element.
fn script_model(
    input: &ViewInput<'_>,
    frame: &Frame,
    focus: Value,
    scene: &Scene,
    counts: &Counts,
    buffers: &Buffers,
) -> String {
    let (ranges, lranges) = (&buffers.ranges, &buffers.lranges);
    let model = json!({
        "title": input.title,
        "input_points": input.points.len(),
        "shown_points": counts.shown,
        "radius": frame.radius,
        "center": frame.center,
        "focus": focus,
        "background": {
            "start": 0,
            "count": scene.background.len(),
            "total": counts.background_total,
        },
        "structures": scene.structures.iter().enumerate().map(|(k, s)| json!({
            "id": s.id,
            "kind": s.kind.name(),
            "points": s.points,
            "start": ranges[k].0,
            "count": ranges[k].1,
            "lstart": lranges[k].0,
            "lcount": lranges[k].1,
        })).collect::<Vec<_>>(),
    });
    model.to_string().replace("</", "<\\/")
}

/// The legend's items: one per structure, with its equation and, for more
/// than one part, the list of its parts.
fn legend(structures: &[StructureView]) -> String {
    let mut legend = String::new();
    for (k, s) in structures.iter().enumerate() {
        let mut line = format!(
            "{} · {} pts",
            s.kind.name(),
            s.points.map_or("?".into(), |p| p.to_string())
        );
        if let Some(r) = s.rms {
            let _ = write!(line, " · rms {}", fmt_num(r));
        }
        if let Some(x) = s.log10_nfa {
            let _ = write!(line, " · NFA {}", fmt_nfa(x));
        }
        let _ = write!(
            legend,
            "<li class=\"st\" data-s=\"{k}\"><label><input type=\"checkbox\" class=\"stog\" data-s=\"{k}\" checked>\
<span class=\"sw\" style=\"background:{}\"></span><b>#{}</b> {}</label>",
            hex(structure_color(k)),
            s.id,
            html_escape(&line)
        );
        // The whole structure's plane or line only where it is one.
        let single = matches!(s.kind, Kind::Plane | Kind::Line | Kind::Unknown);
        if let (Some(p), true) = (s.plane, single) {
            let _ = write!(
                legend,
                "<div class=\"eq\">{}</div>",
                html_escape(&fmt_plane(p))
            );
        } else if let (Some(g), true) = (s.segment, single) {
            let _ = write!(
                legend,
                "<div class=\"eq\">{}</div>",
                html_escape(&fmt_segment(g))
            );
        }
        if s.parts.len() > 1 {
            // Open when the legend stays short.
            let open = structures.len() <= 8 && s.parts.len() <= 12;
            let _ = write!(
                legend,
                "<details{}><summary>{} parts</summary><ol>",
                if open { " open" } else { "" },
                s.parts.len()
            );
            for (j, p) in s.parts.iter().enumerate() {
                legend_part(&mut legend, k, j, p);
            }
            legend.push_str("</ol></details>");
        }
        legend.push_str("</li>");
    }
    legend
}

/// Appends the legend item of part `j` of structure `k`.
fn legend_part(legend: &mut String, k: usize, j: usize, p: &PartView) {
    let mut t = String::new();
    if let Some(id) = p.id {
        let _ = write!(t, "part {id}");
    }
    if let Some(c) = p.points {
        let _ = write!(t, " · {c} pts");
    }
    if let Some(r) = p.rms {
        let _ = write!(t, " · rms {}", fmt_num(r));
    }
    if let Some(x) = p.log10_nfa {
        let _ = write!(t, " · NFA {}", fmt_nfa(x));
    }
    let eq = match (p.plane, p.segment) {
        (Some(pl), _) => fmt_plane(pl),
        (None, Some(g)) => fmt_segment(g),
        _ => String::new(),
    };
    let _ = write!(
        legend,
        "<li><span class=\"sw\" style=\"background:{}\"></span>{}<div class=\"eq\">{}</div></li>",
        hex(part_color(k, j)),
        html_escape(t.trim_start_matches(" · ")),
        html_escape(&eq)
    );
}

/// The line saying how many points, structures and background points
/// there are, and how many are drawn.
fn info_line(input: &ViewInput<'_>, scene: &Scene, counts: &Counts) -> String {
    let n = input.points.len();
    let (shown, cap, n_bg_all) = (counts.shown, input.max_points, counts.background_total);
    format!(
        "{} points{}; {} structure(s), {} background point(s){}",
        n,
        if shown < n {
            format!(" (showing {shown}: the cap is {cap})")
        } else {
            String::new()
        },
        scene.structures.len(),
        n_bg_all,
        if scene.background.len() < n_bg_all {
            format!(", {} drawn", scene.background.len())
        } else {
            String::new()
        }
    )
}

/// The report's parameters as one paragraph, or nothing without them.
fn params_paragraph(report: Option<&Value>) -> String {
    report
        .and_then(|r| r.get("parameters"))
        .filter(|p| p.is_object())
        .map(|p| {
            let mut s = String::new();
            if let Some(o) = p.as_object() {
                for (key, v) in o {
                    // `{"value", "estimated", "reason"}` objects, or plain values.
                    let (v, estimated) = match v.get("value") {
                        Some(x) => (x, v["estimated"].as_bool() == Some(true)),
                        None => (v, false),
                    };
                    if v.is_object() || v.is_array() || v.is_null() {
                        continue;
                    }
                    let v = match (v.as_str(), v.as_f64()) {
                        (Some(t), _) => t.to_string(),
                        (None, Some(x)) => fmt_num(x),
                        _ => v.to_string(),
                    };
                    let est = if estimated { " (estimated)" } else { "" };
                    let _ = write!(s, "{key} {v}{est}, ");
                }
            }
            format!(
                "<p class=\"params\">{}</p>",
                html_escape(s.trim_end_matches(", "))
            )
        })
        .unwrap_or_default()
}

/// The page: the panel (title, counts, parameters, controls, legend), the
/// model, the base64 vertex buffers and the script.
fn page(
    input: &ViewInput<'_>,
    scene: &Scene,
    counts: &Counts,
    model: &str,
    buffers: &Buffers,
) -> String {
    let legend = legend(&scene.structures);
    let info = info_line(input, scene, counts);
    let params = params_paragraph(input.report);
    let title = html_escape(input.title);
    let Buffers {
        pos,
        col,
        lpos,
        lcol,
        ..
    } = buffers;
    let mut page = String::with_capacity(pos.len() * 4 / 3 + col.len() * 4 / 3 + 64 * 1024);
    let _ = write!(
        page,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>aniso-alpha: {title}</title>
<style>{CSS}</style></head>
<body>
<canvas id="gl"></canvas>
<aside id="panel">
<h1>{title}</h1>
<p id="info">{info}</p>
{params}
<p class="help">drag: orbit · right-drag or shift-drag: pan · wheel: zoom · double-click: reset</p>
<div class="ctl"><label><input type="checkbox" id="bg" checked> background</label>
<label><input type="checkbox" id="outl" checked> outlines</label>
<label>size <input type="range" id="psize" min="1" max="12" step="0.5" value="4"></label></div>
<div class="ctl"><button id="all">all</button> <button id="none">none</button></div>
<ol id="legend">{legend}</ol>
<p id="status"></p>
</aside>
<script type="application/json" id="model">{model}</script>
<script type="application/octet-stream" id="pos">{}</script>
<script type="application/octet-stream" id="col">{}</script>
<script type="application/octet-stream" id="lpos">{}</script>
<script type="application/octet-stream" id="lcol">{}</script>
<script>{VIEWER_JS}</script>
</body></html>
"#,
        b64(pos),
        b64(col),
        b64(lpos),
        b64(lcol),
    );
    page
}
/// Line (or polyline) when the points' spread across their main direction
/// is small against their length; plane (or surface) otherwise.
fn guess_kind(points: &[[f64; 3]], members: &[u32], n_parts: usize) -> Kind {
    let linear = match (
        fit_line_indices(points, members),
        fit_plane_indices(points, members),
    ) {
        (Ok(l), Ok(p)) => {
            // The second extent of the plane fit against the line's length.
            p.extent[1] < 0.05 * l.extent.max(f64::MIN_POSITIVE)
        }
        (Ok(_), Err(_)) => true,
        _ => false,
    };
    match (linear, n_parts > 1) {
        (true, false) => Kind::Line,
        (true, true) => Kind::Polyline,
        (false, false) => Kind::Plane,
        (false, true) => Kind::Surface,
    }
}

fn lighten(c: [u8; 3]) -> [u8; 3] {
    c.map(|x| (x as u16 + (255 - x as u16) / 2) as u8)
}

const CSS: &str = "html,body{margin:0;height:100%;background:#15181d;color:#d8dde3;\
font:13px/1.4 system-ui,sans-serif;overflow:hidden}\
#gl{position:absolute;left:0;top:0;width:calc(100% - 340px);height:100%;cursor:grab;display:block}\
#panel{position:absolute;right:0;top:0;width:340px;height:100%;box-sizing:border-box;padding:10px 12px;\
overflow-y:auto;background:#1e2228;border-left:1px solid #333}\
h1{font-size:15px;margin:0 0 6px;overflow-wrap:anywhere}\
p{margin:4px 0}.help,.params{color:#8a939e;font-size:12px}\
.ctl{margin:6px 0}.ctl label{margin-right:10px}\
#legend{list-style:none;padding:0;margin:8px 0}\
#legend>li{padding:4px 0;border-top:1px solid #2c3138}\
#legend ol{padding-left:22px;margin:2px 0}\
.sw{display:inline-block;width:10px;height:10px;border-radius:2px;margin:0 6px 0 4px}\
.eq{color:#9aa4ae;font-size:11px;margin-left:24px;font-family:ui-monospace,monospace}\
details{margin-left:22px}summary{cursor:pointer;color:#9aa4ae}\
li.hl{background:#2a3038}#status{color:#e0a060}\
button{background:#2a3038;color:#d8dde3;border:1px solid #444;border-radius:3px}";

/// The renderer (hand-written WebGL 1, no dependencies).
pub const VIEWER_JS: &str = r##""use strict";
(function () {
  var status = document.getElementById("status");
  function fail(msg) { status.textContent = msg; document.body.setAttribute("data-error", msg); }
  window.addEventListener("error", function (e) { fail("error: " + e.message); });
  var M = JSON.parse(document.getElementById("model").textContent);
  function bytes(id) {
    var s = atob(document.getElementById(id).textContent.trim());
    var u = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) u[i] = s.charCodeAt(i);
    return u;
  }
  var canvas = document.getElementById("gl");
  var gl = canvas.getContext("webgl", { antialias: true, preserveDrawingBuffer: true });
  if (!gl) { fail("WebGL is not available in this browser: only the legend is shown."); return; }
  function shader(type, src) {
    var s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  var prog = gl.createProgram();
  gl.attachShader(prog, shader(gl.VERTEX_SHADER,
    "attribute vec3 p; attribute vec3 c; uniform mat4 m; uniform float s; uniform float k;" +
    "varying vec3 v; void main() { gl_Position = m * vec4(p, 1.0); gl_PointSize = s; v = c * k; }"));
  gl.attachShader(prog, shader(gl.FRAGMENT_SHADER,
    "precision mediump float; varying vec3 v; uniform float r;" +
    "void main() { if (r > 0.5) { vec2 d = gl_PointCoord - 0.5; if (dot(d, d) > 0.25) discard; }" +
    " gl_FragColor = vec4(v, 1.0); }"));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  gl.useProgram(prog);
  var aP = gl.getAttribLocation(prog, "p"), aC = gl.getAttribLocation(prog, "c");
  var uM = gl.getUniformLocation(prog, "m"), uS = gl.getUniformLocation(prog, "s");
  var uK = gl.getUniformLocation(prog, "k"), uR = gl.getUniformLocation(prog, "r");
  function buffer(id) {
    var b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, bytes(id), gl.STATIC_DRAW); return b;
  }
  var pos = buffer("pos"), col = buffer("col"), lpos = buffer("lpos"), lcol = buffer("lcol");
  gl.enableVertexAttribArray(aP); gl.enableVertexAttribArray(aC);
  function bind(p, c) {
    gl.bindBuffer(gl.ARRAY_BUFFER, p); gl.vertexAttribPointer(aP, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, c); gl.vertexAttribPointer(aC, 3, gl.UNSIGNED_BYTE, true, 0, 0);
  }
  gl.enable(gl.DEPTH_TEST);
  var S = M.structures, R = M.radius;
  var shown = S.map(function () { return true; });
  var state = { bg: true, outl: true, size: 4, hl: -1 };
  var cam = {};
  function reset() {
    cam.yaw = -Math.PI / 3; cam.pitch = 0.45; cam.dist = 2.2 * M.focus.radius; cam.t = M.focus.center.slice();
  }
  reset();
  function mul(a, b) {
    var o = new Float32Array(16);
    for (var i = 0; i < 4; i++) for (var j = 0; j < 4; j++) {
      var s = 0; for (var k = 0; k < 4; k++) s += a[k * 4 + j] * b[i * 4 + k]; o[i * 4 + j] = s;
    }
    return o;
  }
  function basis() {
    var cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch), cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
    var back = [cp * cy, cp * sy, sp];
    var right = [-sy, cy, 0];
    var up = [-sp * cy, -sp * sy, cp];
    return { back: back, right: right, up: up };
  }
  function matrix() {
    var b = basis(), e = [0, 1, 2].map(function (i) { return cam.t[i] + cam.dist * b.back[i]; });
    var v = new Float32Array([
      b.right[0], b.up[0], b.back[0], 0, b.right[1], b.up[1], b.back[1], 0,
      b.right[2], b.up[2], b.back[2], 0,
      -(b.right[0] * e[0] + b.right[1] * e[1] + b.right[2] * e[2]),
      -(b.up[0] * e[0] + b.up[1] * e[1] + b.up[2] * e[2]),
      -(b.back[0] * e[0] + b.back[1] * e[1] + b.back[2] * e[2]), 1]);
    var reach = 1.5 * (R + Math.hypot(cam.t[0], cam.t[1], cam.t[2]));
    var near = Math.max(cam.dist - reach, cam.dist * 0.002), far = cam.dist + reach;
    var f = 1 / Math.tan(0.35), asp = canvas.width / Math.max(canvas.height, 1);
    var p = new Float32Array([f / asp, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1,
      0, 0, 2 * far * near / (near - far), 0]);
    return mul(p, v);
  }
  var pending = false;
  function redraw() { if (!pending) { pending = true; requestAnimationFrame(draw); } }
  function draw() {
    pending = false;
    var dpr = window.devicePixelRatio || 1;
    var w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.082, 0.094, 0.114, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.uniformMatrix4fv(uM, false, matrix());
    bind(pos, col);
    gl.uniform1f(uR, 1);
    if (state.bg && M.background.count > 0) {
      // The background never hides a structure: drawn first, without
      // writing depth.
      gl.depthMask(false);
      gl.uniform1f(uS, Math.max(1, state.size * 0.6) * dpr); gl.uniform1f(uK, state.hl >= 0 ? 0.5 : 1);
      gl.drawArrays(gl.POINTS, M.background.start, M.background.count);
      gl.depthMask(true);
    }
    gl.uniform1f(uS, state.size * dpr);
    for (var i = 0; i < S.length; i++) {
      if (!shown[i] || S[i].count === 0) continue;
      gl.uniform1f(uK, state.hl < 0 || state.hl === i ? 1 : 0.3);
      gl.drawArrays(gl.POINTS, S[i].start, S[i].count);
    }
    if (state.outl) {
      bind(lpos, lcol); gl.uniform1f(uR, 0);
      for (var j = 0; j < S.length; j++) {
        if (!shown[j] || S[j].lcount === 0) continue;
        gl.uniform1f(uK, state.hl < 0 || state.hl === j ? 1 : 0.3);
        gl.drawArrays(gl.LINES, S[j].lstart, S[j].lcount);
      }
    }
    var err = gl.getError();
    if (err !== gl.NO_ERROR) fail("WebGL error " + err);
    document.body.setAttribute("data-drawn", String(+(document.body.getAttribute("data-drawn") || 0) + 1));
  }
  var drag = null;
  canvas.addEventListener("contextmenu", function (e) { e.preventDefault(); });
  canvas.addEventListener("pointerdown", function (e) {
    drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey || e.button === 1 };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointerup", function () { drag = null; });
  canvas.addEventListener("pointermove", function (e) {
    if (!drag) return;
    var dx = e.clientX - drag.x, dy = e.clientY - drag.y; drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      var b = basis(), s = 2 * cam.dist * Math.tan(0.35) / Math.max(canvas.clientHeight, 1);
      for (var i = 0; i < 3; i++) cam.t[i] += (-dx * b.right[i] + dy * b.up[i]) * s;
    } else {
      cam.yaw -= dx * 0.008;
      cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + dy * 0.008));
    }
    redraw();
  });
  canvas.addEventListener("wheel", function (e) {
    e.preventDefault();
    cam.dist = Math.max(R * 1e-4, cam.dist * Math.exp(e.deltaY * 0.0015)); redraw();
  }, { passive: false });
  canvas.addEventListener("dblclick", function () { reset(); redraw(); });
  window.addEventListener("resize", redraw);
  document.getElementById("bg").addEventListener("change", function (e) { state.bg = e.target.checked; redraw(); });
  document.getElementById("outl").addEventListener("change", function (e) { state.outl = e.target.checked; redraw(); });
  document.getElementById("psize").addEventListener("input", function (e) { state.size = +e.target.value; redraw(); });
  var toggles = document.querySelectorAll("input.stog");
  function setAll(v) { for (var i = 0; i < toggles.length; i++) { toggles[i].checked = v; shown[+toggles[i].dataset.s] = v; } redraw(); }
  document.getElementById("all").addEventListener("click", function () { setAll(true); });
  document.getElementById("none").addEventListener("click", function () { setAll(false); });
  for (var t = 0; t < toggles.length; t++) {
    toggles[t].addEventListener("change", function (e) { shown[+e.target.dataset.s] = e.target.checked; redraw(); });
  }
  var rows = document.querySelectorAll("#legend > li");
  for (var r = 0; r < rows.length; r++) {
    rows[r].addEventListener("mouseenter", function (e) { state.hl = +e.currentTarget.dataset.s; e.currentTarget.classList.add("hl"); redraw(); });
    rows[r].addEventListener("mouseleave", function (e) { state.hl = -1; e.currentTarget.classList.remove("hl"); redraw(); });
  }
  draw();
})();
"##;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let pts = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.5, 0.5],
            [0.5, 0.0],
            [0.0, 0.0],
        ];
        let mut h = hull_2d(&pts);
        h.sort_unstable();
        assert_eq!(h, vec![0, 1, 2, 3]);
        assert_eq!(hull_2d(&[[0.0, 0.0], [1.0, 1.0]]).len(), 2);
    }

    #[test]
    fn thinning_is_exact_and_repeatable() {
        let mut a: Vec<u32> = (0..1000).collect();
        thin(&mut a, 100);
        assert_eq!(a.len(), 100);
        assert!(a.windows(2).all(|w| w[0] < w[1]));
        let mut b: Vec<u32> = (0..1000).collect();
        thin(&mut b, 100);
        assert_eq!(a, b);
        // Spread over the range, not a prefix.
        assert!(a[0] < 100 && *a.last().unwrap() > 900);
    }

    #[test]
    fn plane_equations_read_well() {
        assert_eq!(
            fmt_plane([0.0, 0.6, -0.8, 12.5]),
            "0x + 0.6y − 0.8z + 12.5 = 0"
        );
        assert_eq!(fmt_plane([-1.0, 0.0, 0.0, -3.0]), "−1x + 0y + 0z − 3 = 0");
        // UTM: d in full, the normal to six decimals.
        assert_eq!(
            fmt_plane([0.316228, 0.948683, 0.0, -1121431.5974]),
            "0.316228x + 0.948683y + 0z − 1121431.597 = 0"
        );
        assert_eq!(fmt_num(1.0e-7), "1.000e-7");
    }

    fn square(n: usize) -> Vec<[f64; 3]> {
        let mut pts = Vec::new();
        for i in 0..n {
            for j in 0..n {
                pts.push([i as f64, j as f64, 5.0]);
            }
        }
        pts
    }

    #[test]
    fn labels_alone_give_structures_and_outlines() {
        let mut pts = square(6);
        // A line of 10 points and 5 background points.
        for i in 0..10 {
            pts.push([20.0 + i as f64, 0.0, 0.0]);
        }
        for i in 0..5 {
            pts.push([i as f64 * 3.0, 17.0, -4.0 + i as f64]);
        }
        let labels: Vec<i64> = (0..pts.len())
            .map(|i| match i {
                0..36 => 3,
                36..46 => 0,
                _ => -1,
            })
            .collect();
        let page = html(&ViewInput {
            title: "t<est>",
            points: &pts,
            labels: Some(&labels),
            parts: None,
            report: None,
            max_points: DEFAULT_MAX_POINTS,
        })
        .unwrap();
        assert!(page.contains("<h1>t&lt;est&gt;</h1>"));
        // Structures in id order: the line (id 0) then the plane (id 3).
        let l0 = page.find("<b>#0</b> line · 10 pts").unwrap();
        let l3 = page.find("<b>#3</b> plane · 36 pts").unwrap();
        assert!(l0 < l3);
        // The plane z = 5, written with its unit normal.
        assert!(page.contains("0x + 0y + 1z − 5 = 0"), "{page}");
        assert!(page.contains("(20, 0, 0) → (29, 0, 0), length 9"), "{page}");
        let model: Value = serde_json::from_str(
            page.split("<script type=\"application/json\" id=\"model\">")
                .nth(1)
                .unwrap()
                .split("</script>")
                .next()
                .unwrap(),
        )
        .unwrap();
        assert_eq!(model["background"]["count"], 5);
        assert_eq!(model["structures"][0]["start"], 5);
        assert_eq!(model["structures"][0]["count"], 10);
        assert_eq!(model["structures"][1]["start"], 15);
        // The square's hull: 4 edges, 8 line vertices; the line: 1 edge.
        assert_eq!(model["structures"][0]["lcount"], 2);
        assert_eq!(model["structures"][1]["lcount"], 8);
    }

    #[test]
    fn report_outlines_are_drawn_and_cap_is_kept() {
        let pts = square(40);
        let labels = vec![0i64; pts.len()];
        let report = json!({"structures": [{"id": 0, "kind": "plane", "points": 1600, "rms": 0.0,
            "nfa": 1e-30, "parts": [{"id": 0, "points": 1600, "rms": 0.0,
            "plane": [0.0, 0.0, 1.0, -5.0],
            "polygon": [[0.0,0.0,5.0],[39.0,0.0,5.0],[39.0,39.0,5.0],[20.0,45.0,5.0],[0.0,39.0,5.0]]}]}]});
        let page = html(&ViewInput {
            title: "r",
            points: &pts,
            labels: Some(&labels),
            parts: None,
            report: Some(&report),
            max_points: 1000,
        })
        .unwrap();
        assert!(page.contains("NFA 1.00e-30"));
        assert!(page.contains("showing 1000"));
        // The report's pentagon, not the points' hull (a square).
        assert!(page.contains("\"lcount\":10"), "{page}");
        assert!(html(&ViewInput {
            labels: Some(&labels[1..]),
            ..ViewInput {
                title: "r",
                points: &pts,
                labels: None,
                parts: None,
                report: None,
                max_points: 10,
            }
        })
        .is_err());
    }
}
