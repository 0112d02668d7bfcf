//! Quick pictures (`detect --png`, `alpha --png`) and the colours shared
//! with the viewer.
//!
//! A fixed view, the same for every picture: orthographic, z up, seen from
//! azimuth −60° (from the +x axis towards −y) and 25° above the horizontal
//! plane, i.e. looking along −(0.453, −0.785, 0.423) from the front right
//! and above, on a 1200 × 900 image on white, framed on the structures
//! (their extent fills about 70% of the image; the background around them is
//! clipped) or on all the points when there are none. The
//! triangles are drawn far to near (painter's order), so the output
//! depends only on the input: the same points and structures give the same
//! bytes. Rasterising and PNG encoding are `tiny-skia`'s; the points are
//! splatted straight into its pixel buffer (a million anti-aliased discs
//! as paths would be far slower).

use std::collections::{BTreeMap, BTreeSet};

use tiny_skia::{
    FillRule, LineCap, Paint, PathBuilder, Pixmap, PremultipliedColorU8, Stroke, Transform,
};

use crate::common::CliError;
use aniso_alpha::detect::Simplices;

/// Width of the pictures.
pub const WIDTH: u32 = 1200;
/// Height of the pictures.
pub const HEIGHT: u32 = 900;
/// Azimuth of the view direction, degrees from +x towards +y.
pub const AZIMUTH_DEG: f64 = -60.0;
/// Elevation of the view direction above the xy plane, degrees.
pub const ELEVATION_DEG: f64 = 25.0;

/// Background points in the viewer (on its dark canvas).
pub const BACKGROUND_DARK: [u8; 3] = [84, 90, 98];
/// Background points in the pictures (on white).
const BACKGROUND_LIGHT: [u8; 3] = [170, 172, 178];

fn hsl(h: f64, s: f64, l: f64) -> [u8; 3] {
    let h = h.rem_euclid(360.0) / 60.0;
    let c = (1.0 - (2.0 * l - 1.0).abs()) * s;
    let x = c * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = l - c / 2.0;
    [r, g, b].map(|v| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8)
}

fn base_hue(k: usize) -> f64 {
    // Golden-angle steps from blue: neighbours in the list differ most.
    210.0 + 137.507_764 * k as f64
}

/// The colour of the `k`-th structure.
pub fn structure_color(k: usize) -> [u8; 3] {
    hsl(base_hue(k), 0.70, 0.55)
}

/// The colour of the `j`-th part of the `k`-th structure: hues around the
/// structure's, alternating lightness.
pub fn part_color(k: usize, j: usize) -> [u8; 3] {
    const SHIFT: [f64; 7] = [0.0, 40.0, -40.0, 80.0, -80.0, 120.0, -120.0];
    let l = if (j / SHIFT.len()).is_multiple_of(2) {
        0.55
    } else {
        0.42
    };
    let l = if j % 2 == 1 { l - 0.06 } else { l };
    hsl(base_hue(k) + SHIFT[j % SHIFT.len()], 0.70, l)
}

/// The fixed view: screen right, screen up, and towards the viewer.
struct Camera {
    right: [f64; 3],
    up: [f64; 3],
    back: [f64; 3],
    scale: f64,
    offset: [f64; 2],
}

impl Camera {
    /// The fixed view, scaled so that `points` fill the image.
    fn fit(points: &[[f64; 3]]) -> Camera {
        Self::fit_iter(points.iter().copied(), 1.0)
    }

    /// The fixed view, scaled so that `points` fill `1/zoom` of the
    /// image (the rest is clipped).
    fn fit_iter(points: impl Iterator<Item = [f64; 3]>, zoom: f64) -> Camera {
        let (a, e) = (AZIMUTH_DEG.to_radians(), ELEVATION_DEG.to_radians());
        let back = [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()];
        let right = [-a.sin(), a.cos(), 0.0];
        let up = [-e.sin() * a.cos(), -e.sin() * a.sin(), e.cos()];
        let mut cam = Camera {
            right,
            up,
            back,
            scale: 1.0,
            offset: [0.0, 0.0],
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut any = false;
        for p in points {
            any = true;
            let q = [dot(p, right), dot(p, up)];
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        if !any {
            lo = [0.0; 2];
            hi = [1.0; 2];
        }
        let margin = 0.05;
        let (w, h) = (WIDTH as f64, HEIGHT as f64);
        let span = [(hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300)];
        let scale =
            ((1.0 - 2.0 * margin) * w / span[0]).min((1.0 - 2.0 * margin) * h / span[1]) / zoom;
        cam.scale = if scale.is_finite() { scale } else { 1.0 };
        let mid = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        cam.offset = [w / 2.0 - mid[0] * cam.scale, h / 2.0 + mid[1] * cam.scale];
        cam
    }

    /// Pixel coordinates (y down).
    fn project(&self, p: [f64; 3]) -> (f32, f32) {
        (
            (self.offset[0] + dot(p, self.right) * self.scale) as f32,
            (self.offset[1] - dot(p, self.up) * self.scale) as f32,
        )
    }

    /// Larger is nearer to the viewer.
    fn depth(&self, p: [f64; 3]) -> f64 {
        dot(p, self.back)
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Draws an anti-aliased disc of radius `r` pixels, colour `c` at opacity
/// `alpha`, straight into the pixel buffer (source-over).
fn splat(pixmap: &mut Pixmap, (x, y): (f32, f32), r: f32, c: [u8; 3], alpha: f32) {
    let (w, h) = (pixmap.width() as i32, pixmap.height() as i32);
    if !(x.is_finite() && y.is_finite()) {
        return;
    }
    let (x0, x1) = ((x - r - 1.0).floor() as i32, (x + r + 1.0).ceil() as i32);
    let (y0, y1) = ((y - r - 1.0).floor() as i32, (y + r + 1.0).ceil() as i32);
    let pixels = pixmap.pixels_mut();
    for py in y0.max(0)..=y1.min(h - 1) {
        for px in x0.max(0)..=x1.min(w - 1) {
            let d = ((px as f32 + 0.5 - x).powi(2) + (py as f32 + 0.5 - y).powi(2)).sqrt();
            let cover = (r + 0.5 - d).clamp(0.0, 1.0) * alpha;
            if cover <= 0.0 {
                continue;
            }
            let i = (py * w + px) as usize;
            let dst = pixels[i];
            let blend = |s: u8, d: u8| -> u8 {
                (s as f32 * cover + d as f32 * (1.0 - cover))
                    .round()
                    .clamp(0.0, 255.0) as u8
            };
            let a = blend(255, dst.alpha());
            let out = PremultipliedColorU8::from_rgba(
                blend(c[0], dst.red()).min(a),
                blend(c[1], dst.green()).min(a),
                blend(c[2], dst.blue()).min(a),
                a,
            );
            if let Some(out) = out {
                pixels[i] = out;
            }
        }
    }
}

fn paint(c: [u8; 3], alpha: u8, anti_alias: bool) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(c[0], c[1], c[2], alpha);
    p.anti_alias = anti_alias;
    p
}

fn fill_triangle(pixmap: &mut Pixmap, t: [(f32, f32); 3], paint: &Paint<'_>) {
    let mut pb = PathBuilder::new();
    pb.move_to(t[0].0, t[0].1);
    pb.line_to(t[1].0, t[1].1);
    pb.line_to(t[2].0, t[2].1);
    pb.close();
    if let Some(path) = pb.finish() {
        pixmap.fill_path(&path, paint, FillRule::Winding, Transform::identity(), None);
    }
}

/// A point of the image, in pixels (y down).
type Px = (f32, f32);

fn stroke_segments(pixmap: &mut Pixmap, segs: &[(Px, Px)], paint: &Paint<'_>, width: f32) {
    if segs.is_empty() {
        return;
    }
    let mut pb = PathBuilder::new();
    for (a, b) in segs {
        pb.move_to(a.0, a.1);
        pb.line_to(b.0, b.1);
    }
    if let Some(path) = pb.finish() {
        let stroke = Stroke {
            width,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        pixmap.stroke_path(&path, paint, &stroke, Transform::identity(), None);
    }
}

fn new_pixmap() -> Result<Pixmap, CliError> {
    let mut pm =
        Pixmap::new(WIDTH, HEIGHT).ok_or_else(|| CliError::msg("cannot allocate the picture"))?;
    pm.fill(tiny_skia::Color::WHITE);
    Ok(pm)
}

fn encode(pm: &Pixmap) -> Result<Vec<u8>, CliError> {
    pm.encode_png()
        .map_err(|e| CliError::msg(format!("cannot encode the picture: {e}")))
}

/// For each point: its colour (structure and part) or `None`
/// (background), and the members of each (structure, part rank), as the
/// viewer numbers them: structure k is label k, part j is the rank of its
/// id among the part ids of its structure.
#[allow(clippy::type_complexity)]
fn point_colors(
    labels: &[i64],
    parts: Option<&[i64]>,
) -> (Vec<Option<[u8; 3]>>, BTreeMap<(usize, usize), Vec<u32>>) {
    let mut part_ids: BTreeMap<i64, BTreeSet<i64>> = BTreeMap::new();
    if let Some(parts) = parts {
        for (&l, &p) in labels.iter().zip(parts) {
            if l >= 0 && p >= 0 {
                part_ids.entry(l).or_default().insert(p);
            }
        }
    }
    let rank: BTreeMap<(i64, i64), usize> = part_ids
        .iter()
        .flat_map(|(&l, ps)| ps.iter().enumerate().map(move |(j, &p)| ((l, p), j)))
        .collect();
    let mut members: BTreeMap<(usize, usize), Vec<u32>> = BTreeMap::new();
    let colors = labels
        .iter()
        .enumerate()
        .map(|(i, &l)| {
            if l < 0 {
                return None;
            }
            let k = l as usize;
            let p = parts.map_or(-1, |p| p[i]);
            Some(match rank.get(&(l, p)) {
                Some(&j) => {
                    members.entry((k, j)).or_default().push(i as u32);
                    part_color(k, j)
                }
                None => structure_color(k),
            })
        })
        .collect();
    (colors, members)
}

fn darken(c: [u8; 3], f: f32) -> [u8; 3] {
    c.map(|x| (x as f32 * f).round() as u8)
}

/// The picture of a detection: background points dimmed; for planes each
/// part's outline (the hull of its points on its fitted plane, filled
/// translucent, far to near), for lines the structures' edges; then the
/// structure points, coloured by structure and part as in the viewer.
/// `simplices` are vertex pairs (lines) or triples (planes); an edge takes
/// the colour of its first vertex.
pub fn detection_png(
    points: &[[f64; 3]],
    labels: &[i64],
    parts: Option<&[i64]>,
    simplices: &Simplices,
    outlines: &BTreeMap<(usize, usize), Vec<[f64; 3]>>,
) -> Result<Vec<u8>, CliError> {
    let (colors, members) = point_colors(labels, parts);
    // Framed on the structures (with room around them), or on everything.
    let cam = if colors.iter().any(Option::is_some) {
        Camera::fit_iter(
            points
                .iter()
                .zip(&colors)
                .filter(|(_, c)| c.is_some())
                .map(|(p, _)| *p),
            1.25,
        )
    } else {
        Camera::fit(points)
    };
    let mut pm = new_pixmap()?;
    let xy: Vec<(f32, f32)> = points.iter().map(|&p| cam.project(p)).collect();
    for (i, c) in colors.iter().enumerate() {
        if c.is_none() {
            splat(&mut pm, xy[i], 1.4, BACKGROUND_LIGHT, 1.0);
        }
    }
    // Planar parts: their outlines, far to near.
    let planar = simplices.size() == 3;
    if planar {
        let mut polys: Vec<(f64, [u8; 3], Vec<[f64; 3]>)> = Vec::new();
        for (&(k, j), m) in &members {
            if m.len() < 3 {
                continue;
            }
            // The detection's own outline, else the hull of the points.
            let given = outlines.get(&(k, j)).filter(|o| o.len() >= 3).cloned();
            let outline = given
                .or_else(|| crate::view::outline_of_points(points, m, false).map(|o| o.vertices));
            if let Some(vertices) = outline {
                let n = vertices.len().max(1) as f64;
                let depth = vertices.iter().map(|&p| cam.depth(p)).sum::<f64>() / n;
                polys.push((depth, part_color(k, j), vertices));
            }
        }
        polys.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, c, poly) in &polys {
            let mut pb = PathBuilder::new();
            for (q, &p) in poly.iter().enumerate() {
                let (x, y) = cam.project(p);
                if q == 0 {
                    pb.move_to(x, y);
                } else {
                    pb.line_to(x, y);
                }
            }
            pb.close();
            if let Some(path) = pb.finish() {
                pm.fill_path(
                    &path,
                    &paint(*c, 70, true),
                    FillRule::Winding,
                    Transform::identity(),
                    None,
                );
                let stroke = Stroke {
                    width: 2.0,
                    ..Stroke::default()
                };
                pm.stroke_path(
                    &path,
                    &paint(darken(*c, 0.8), 255, true),
                    &stroke,
                    Transform::identity(),
                    None,
                );
            }
        }
    }
    let mut by_color: BTreeMap<[u8; 3], Vec<(Px, Px)>> = BTreeMap::new();
    for s in simplices.iter().filter(|s| s.len() == 2) {
        let c = colors[s[0] as usize].unwrap_or(BACKGROUND_LIGHT);
        by_color
            .entry(c)
            .or_default()
            .push((xy[s[0] as usize], xy[s[1] as usize]));
    }
    for (c, segs) in &by_color {
        stroke_segments(&mut pm, segs, &paint(*c, 255, true), 2.2);
    }
    for (i, c) in colors.iter().enumerate() {
        if let Some(c) = c {
            splat(&mut pm, xy[i], 3.4, darken(*c, 0.6), 1.0);
            splat(&mut pm, xy[i], 2.4, *c, 1.0);
        }
    }
    encode(&pm)
}

/// [`detection_png`] of a detection written to `path` (atomically, phase
/// `write`): planar parts outlined by the detection's own outlines (the
/// boundary of each part's 2D α-shape), where it has them.
pub fn write_detection_png(
    path: &std::path::Path,
    points: &[[f64; 3]],
    det: &aniso_alpha::detect::Detection,
    parts: &[i64],
    timings: &mut crate::common::Timings,
) -> Result<(), CliError> {
    let mut outlines = BTreeMap::new();
    for s in &det.structures {
        for (j, p) in s.parts.iter().enumerate() {
            if p.plane().is_some() && p.outline.len() >= 3 {
                outlines.insert((s.id as usize, j), p.outline.clone());
            }
        }
    }
    let png = timings.phase("picture", || {
        detection_png(points, &det.labels, Some(parts), &det.simplices, &outlines)
    })?;
    crate::common::write_output(path, timings, |w| w.write_all(&png))
}

/// The picture of an α-shape: its triangles shaded by their slope to a
/// fixed light (far to near), its dangling edges, over all the points.
pub fn shape_png(
    points: &[[f64; 3]],
    faces: &[[u32; 3]],
    edges: &[[u32; 2]],
) -> Result<Vec<u8>, CliError> {
    let cam = Camera::fit(points);
    let mut pm = new_pixmap()?;
    let xy: Vec<(f32, f32)> = points.iter().map(|&p| cam.project(p)).collect();
    for &q in &xy {
        splat(&mut pm, q, 1.2, BACKGROUND_LIGHT, 0.9);
    }
    let light = {
        let l = [
            0.6 * cam.back[0] + 0.6 * cam.up[0] + 0.3 * cam.right[0],
            0.6 * cam.back[1] + 0.6 * cam.up[1] + 0.3 * cam.right[1],
            0.6 * cam.back[2] + 0.6 * cam.up[2] + 0.3 * cam.right[2],
        ];
        let n = dot(l, l).sqrt();
        l.map(|x| x / n)
    };
    let mut order: Vec<(f64, usize)> = faces
        .iter()
        .enumerate()
        .map(|(k, f)| (f.iter().map(|&v| cam.depth(points[v as usize])).sum(), k))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let base = [70.0, 130.0, 200.0];
    let mut seams = Vec::with_capacity(order.len() * 3);
    for &(_, k) in &order {
        let [a, b, c] = faces[k].map(|v| points[v as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = dot(n, n).sqrt();
        let shade = if len > 0.0 {
            0.35 + 0.65 * (dot(n, light) / len).abs()
        } else {
            0.35
        };
        let col = base.map(|x: f64| (x * shade).round().clamp(0.0, 255.0) as u8);
        let t = faces[k].map(|v| xy[v as usize]);
        fill_triangle(&mut pm, t, &paint(col, 255, false));
        seams.clear();
        seams.extend([(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]);
        stroke_segments(&mut pm, &seams, &paint([20, 30, 45], 40, true), 0.6);
    }
    let segs: Vec<_> = edges
        .iter()
        .map(|e| (xy[e[0] as usize], xy[e[1] as usize]))
        .collect();
    stroke_segments(&mut pm, &segs, &paint([40, 44, 52], 255, true), 1.2);
    encode(&pm)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_is_distinct() {
        let cs: Vec<[u8; 3]> = (0..12).map(structure_color).collect();
        for i in 0..cs.len() {
            for j in 0..i {
                let d: i32 = (0..3)
                    .map(|k| (cs[i][k] as i32 - cs[j][k] as i32).abs())
                    .sum();
                assert!(d > 30, "{i} {j} {:?} {:?}", cs[i], cs[j]);
            }
        }
        assert_eq!(part_color(3, 0), structure_color(3));
        assert_ne!(part_color(3, 1), part_color(3, 2));
        assert_eq!(hsl(0.0, 1.0, 0.5), [255, 0, 0]);
        assert_eq!(hsl(120.0, 1.0, 0.5), [0, 255, 0]);
    }

    #[test]
    fn the_view_is_the_stated_one() {
        let cam = Camera::fit(&[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]);
        assert!((cam.back[0] - 0.453).abs() < 1e-3);
        assert!((cam.back[1] + 0.785).abs() < 1e-3);
        assert!((cam.back[2] - 0.423).abs() < 1e-3);
        // Orthonormal, right-handed: right × up = back.
        let r = cam.right;
        let u = cam.up;
        let x = [
            r[1] * u[2] - r[2] * u[1],
            r[2] * u[0] - r[0] * u[2],
            r[0] * u[1] - r[1] * u[0],
        ];
        for (a, b) in x.iter().zip(cam.back) {
            assert!((a - b).abs() < 1e-12);
        }
        // z up on screen: a higher point is higher in the image (smaller y).
        assert!(cam.project([0.0, 0.0, 1.0]).1 < cam.project([0.0, 0.0, 0.0]).1);
    }

    #[test]
    fn pictures_are_deterministic_and_coloured() {
        let mut pts = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                pts.push([i as f64, j as f64, 0.0]);
            }
        }
        pts.push([5.0, 5.0, 8.0]);
        let labels: Vec<i64> = (0..pts.len())
            .map(|i| if i < 100 { 0 } else { -1 })
            .collect();
        let simplices = Simplices::from_flat(3, vec![0, 1, 10, 1, 11, 10]);
        let a = detection_png(&pts, &labels, None, &simplices, &BTreeMap::new()).unwrap();
        let b = detection_png(&pts, &labels, None, &simplices, &BTreeMap::new()).unwrap();
        assert_eq!(a, b);
        let edges = Simplices::from_flat(2, vec![2, 3]);
        let c = detection_png(&pts, &labels, None, &edges, &BTreeMap::new()).unwrap();
        assert_ne!(a, c);
        let pm = Pixmap::decode_png(&a).unwrap();
        assert_eq!((pm.width(), pm.height()), (WIDTH, HEIGHT));
        let want = structure_color(0);
        let hits = pm
            .pixels()
            .iter()
            .filter(|p| p.red() == want[0] && p.green() == want[1] && p.blue() == want[2])
            .count();
        assert!(hits > 100, "{hits}");
        let s = shape_png(&pts, &[[0, 1, 100], [1, 2, 100]], &[[50, 60]]).unwrap();
        let pm = Pixmap::decode_png(&s).unwrap();
        let shaded = pm
            .pixels()
            .iter()
            .filter(|p| p.blue() as i32 > p.red() as i32 + 40)
            .count();
        assert!(shaded > 1000, "{shaded}");
    }
}
