//! Stage 4b of the assembly (docs/method.md §4, "Lines inside a surface"):
//! a line part that lies inside a surface is that surface's sampling, not a
//! line, and goes.
//!
//! A scanner samples a surface along rings; far from the scanner, at a
//! grazing angle, the rings lie much farther apart than the points along a
//! ring, and each ring is a significant line under a uniform background.
//! The other side of the same fact: the points around such a "line"
//! (within its length across it) form a plane that contains it, where
//! a pole, a cable or a line in clutter has nothing around it, or clutter
//! without a plane, or a plane that it stands off.
//!
//! The test, for a line part of length L with claim radius τ, looks at
//! the points that are not its members, within L of its axis (the rings
//! of a surface seen at a grazing angle lie up to a line's length apart)
//! and projecting onto the middle 80% of its span (so that the ground at a
//! pole's foot or the structure at a line's ends does not count). A
//! surface that holds the line meets them in sheets: half-planes bounded
//! by the axis (one for the edge of a surface, two for a plane through the
//! line or for a crease where two surfaces meet). The line lies inside a
//! surface when at most two such sheets, each of points within τ of it
//! and spread along the line (a structure crossing the line, as a pole
//! through a crossbar, is not a sheet along it), hold at least as many
//! points as the line and at least half of the points around it.
//!
//! The same test runs a second time on the near surroundings, within
//! [`NEAR_TUBES`] claim radii of the axis. A line whose claim tube lies
//! along a crease (the foot of a façade, where ground meets wall) holds a
//! strip of both surfaces, and both go on beyond the tube; but a long
//! crease's surroundings of radius L hold the whole street around it
//! (the far façade, cars, trees), so its two sheets fall short of half.
//! Near the axis nothing but the two surfaces lies: the annulus from τ to
//! 3τ is twice the tube's width, so surfaces that go on at the tube's
//! density hold twice the line's points there, and at least as many
//! where their density falls off by half. A pole or a cable has nothing
//! within a few claim radii (the ground at a pole's foot is left out
//! with the span's ends).
//!
//! Rows are lines too: three coplanar parallel cables with nothing else
//! around them lie inside their "surface" as well. So the stage runs in
//! the automatic mode only (`Regime::drops_lines_inside_surfaces`), and
//! with the user's scale and a sampler every row stays a line.
//!
//! Planes have no such test (a plane inside a volume is what the
//! significance test already weighs).

use super::super::cloud::Cloud;
use super::super::local::any_orthogonal;
use super::shape::span;
use super::{Candidate, Draft};
use crate::geometry::{cross, dot, sub};
use crate::par::map_ranges;

/// Share of the span at each end left out of the surroundings.
const END_SHARE: f64 = 0.1;

/// Radius of the near surroundings, in claim radii.
const NEAR_TUBES: f64 = 3.0;

/// Drops the line parts that lie inside a surface (module doc); how many
/// went. Parts in parallel.
pub(super) fn reject_lines(
    parts: &mut Vec<Draft>,
    cands: &[Candidate],
    cloud: &Cloud<'_>,
) -> usize {
    let inside = map_ranges(parts.len(), Vec::new, |buf: &mut Vec<Placed>, pi| {
        let p = &parts[pi];
        in_surface(p, cands[p.cand].tau, cloud, buf)
    });
    let before = parts.len();
    let mut it = inside.into_iter();
    parts.retain(|_| !it.next().unwrap_or(false));
    before - parts.len()
}

/// A point around a line: its place along the axis, and where it lies
/// across it (angle and distance).
type Placed = (f64, f64, f64);

/// Whether the line part `p` of claim radius `tau` lies inside a surface
/// (module doc); `placed` is a buffer for the surrounding points.
fn in_surface(p: &Draft, tau: f64, cloud: &Cloud<'_>, placed: &mut Vec<Placed>) -> bool {
    let super::Primitive::Line(f) = &p.fit else {
        return false;
    };
    let (t0, t1) = span(f, &p.members, cloud.points());
    let length = t1 - t0;
    if length.is_nan() || length <= 0.0 {
        return false;
    }
    let near = NEAR_TUBES * tau;
    on_sheets_within(p, f, (t0, t1), length, tau, cloud, placed)
        || (near < length && on_sheets_within(p, f, (t0, t1), near, tau, cloud, placed))
}

/// Whether the points around the line part `p` (axis `f`, span
/// `(t0, t1)`) within `radius` of its axis lie on at most two sheets that
/// hold at least as many points as the line and half of those around it
/// (module doc).
fn on_sheets_within(
    p: &Draft,
    f: &super::super::fit::LineFit,
    (t0, t1): (f64, f64),
    radius: f64,
    tau: f64,
    cloud: &Cloud<'_>,
    placed: &mut Vec<Placed>,
) -> bool {
    let points = cloud.points();
    let length = t1 - t0;
    let (lo, hi) = (t0 + END_SHARE * length, t1 - END_SHARE * length);
    let mid = 0.5 * (t0 + t1);
    let centre = [0, 1, 2].map(|k| f.centroid[k] + mid * f.direction[k]);
    let reach = (radius * radius + 0.25 * (hi - lo) * (hi - lo)).sqrt();
    let u = any_orthogonal(f.direction);
    let w = cross(f.direction, u);
    placed.clear();
    let copies = cloud.copies();
    cloud.index().within(&centre, reach, |v| {
        if !copies.is_first(v as usize) || p.members.binary_search(&v).is_ok() {
            return;
        }
        let d = sub(points[v as usize], f.centroid);
        let t = dot(d, f.direction);
        let (x, y) = (dot(d, u), dot(d, w));
        let r = x.hypot(y);
        if (lo..=hi).contains(&t) && r <= radius {
            placed.push((t, y.atan2(x), r));
        }
    });
    if placed.len() < p.members.len() {
        return false;
    }
    let mut taken = vec![false; placed.len()];
    let mut on_sheets = 0;
    for _ in 0..2 {
        let Some(phi) = best_half_plane(placed, &taken, tau) else {
            break;
        };
        let sheet: Vec<usize> = (0..placed.len())
            .filter(|&i| !taken[i] && on_half_plane(placed[i], phi, tau))
            .collect();
        let along: Vec<f64> = sheet.iter().map(|&i| placed[i].0).collect();
        if spread(&along) * 2.0 < spread_uniform(lo, hi) {
            continue; // a crossing structure, not a sheet along the line
        }
        for &i in &sheet {
            taken[i] = true;
        }
        on_sheets += sheet.len();
    }
    on_sheets >= p.members.len() && 2 * on_sheets >= placed.len()
}

/// Whether the point (along, angle, distance) across the axis lies within
/// `tol` of the half-plane at angle `phi` bounded by the axis.
fn on_half_plane((_, theta, r): Placed, phi: f64, tol: f64) -> bool {
    let (s, c) = (theta - phi).sin_cos();
    r <= tol || (c > 0.0 && r * s.abs() <= tol)
}

/// Number of angle bins of the half-plane search (1°).
const ANGLE_BINS: usize = 360;

/// The angle of the half-plane bounded by the axis that holds the most of
/// the points not `taken` (each within `tol`), from a histogram of angles
/// in which a point counts for every bin within its angular tolerance;
/// `None` when no point is left.
fn best_half_plane(placed: &[Placed], taken: &[bool], tol: f64) -> Option<f64> {
    use std::f64::consts::PI;
    let bins = ANGLE_BINS as isize;
    let width = 2.0 * PI / ANGLE_BINS as f64;
    let mut diff = vec![0i64; ANGLE_BINS + 1];
    let mut any = false;
    for (&(_, theta, r), _) in placed.iter().zip(taken).filter(|(_, &t)| !t) {
        any = true;
        let reach = if r <= tol { PI } else { (tol / r).asin() };
        let centre = ((theta + PI) / width).floor() as isize;
        let half = (reach / width).ceil() as isize;
        if 2 * half + 1 >= bins {
            diff[0] += 1;
            diff[ANGLE_BINS] -= 1;
            continue;
        }
        let (a, b) = (
            (centre - half).rem_euclid(bins) as usize,
            (centre + half + 1).rem_euclid(bins) as usize,
        );
        diff[a] += 1;
        diff[b] -= 1;
        if a >= b {
            // The range wraps past the last bin.
            diff[ANGLE_BINS] -= 1;
            diff[0] += 1;
        }
    }
    if !any {
        return None;
    }
    let mut run = 0i64;
    let counts: Vec<i64> = diff[..ANGLE_BINS]
        .iter()
        .map(|d| {
            run += d;
            run
        })
        .collect();
    Some((middle_of_widest_peak(&counts) + 0.5) * width - PI)
}

/// The middle (a bin index, fractional, in `[0, n)`) of the longest run of
/// bins holding the highest count in the circular histogram `counts`: a
/// half-plane's points count over a range of angles (each within its
/// tolerance), and the middle of that range holds them with the most room.
fn middle_of_widest_peak(counts: &[i64]) -> f64 {
    let n = counts.len();
    let best = counts.iter().copied().max().unwrap_or(0);
    // Start after a bin below the peak, so that no run is cut in two by
    // the wrap; every bin at the peak: any angle will do.
    let Some(below) = counts.iter().position(|&c| c != best) else {
        return 0.0;
    };
    let (mut widest, mut from) = (0usize, 0usize);
    let mut len = 0;
    for k in 1..=n {
        let i = (below + k) % n;
        if counts[i] == best {
            len += 1;
            if len > widest {
                (widest, from) = (len, i + n + 1 - len);
            }
        } else {
            len = 0;
        }
    }
    (from as f64 + 0.5 * (widest as f64 - 1.0)) % n as f64
}

/// The standard deviation of `xs` (0 for fewer than two).
fn spread(xs: &[f64]) -> f64 {
    if xs.len() < 2 {
        return 0.0;
    }
    let n = xs.len() as f64;
    let m = xs.iter().sum::<f64>() / n;
    (xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n).sqrt()
}

/// The standard deviation of points spread evenly over `[lo, hi]`.
fn spread_uniform(lo: f64, hi: f64) -> f64 {
    (hi - lo) / 12f64.sqrt()
}

#[cfg(test)]
mod tests {
    use super::super::super::cloud::{Cloud, Copies};
    use super::*;

    /// A line of 40 points along x at height `z`, spacing 0.05.
    fn line_at(y: f64, z: f64) -> Vec<[f64; 3]> {
        (0..40).map(|i| [i as f64 * 0.05, y, z]).collect()
    }

    fn run(points: &[[f64; 3]], members: Vec<u32>, tau: f64) -> bool {
        let copies = Copies::none(points.len());
        let cloud = Cloud::new(points, &copies);
        let part = Draft::line(points, members, 0, (tau, 0.1)).0;
        in_surface(&part, tau, &cloud, &mut Vec::new())
    }

    #[test]
    fn a_ring_among_rings_lies_in_its_surface() {
        // Rings 0.4 apart on the ground, the middle one the part.
        let mut pts = Vec::new();
        for r in -3..=3 {
            pts.extend(line_at(r as f64 * 0.4, 0.0));
        }
        let members: Vec<u32> = (120..160).collect();
        assert!(run(&pts, members, 0.01));
    }

    #[test]
    fn a_crease_or_a_surface_edge_lies_in_its_surface() {
        // The foot of a wall: rings on the ground (y < 0) and on the wall
        // (z > 0), the corner ring the part.
        let mut pts = line_at(0.0, 0.0);
        for r in 1..=4 {
            pts.extend(line_at(-(r as f64) * 0.4, 0.0));
            pts.extend(line_at(0.0, r as f64 * 0.4));
        }
        assert!(run(&pts, (0..40).collect(), 0.01));
        // The edge of the ground alone.
        let mut pts = line_at(0.0, 0.0);
        for r in 1..=4 {
            pts.extend(line_at(-(r as f64) * 0.4, 0.0));
        }
        assert!(run(&pts, (0..40).collect(), 0.01));
    }

    #[test]
    fn the_half_plane_is_the_middle_of_the_widest_peak() {
        assert_eq!(middle_of_widest_peak(&[0, 2, 2, 2, 0, 2, 1]), 2.0);
        // A peak across the wrap: bins 6, 0, 1.
        assert_eq!(middle_of_widest_peak(&[3, 3, 0, 1, 0, 0, 3]), 0.0);
        assert_eq!(middle_of_widest_peak(&[3, 0, 0, 1, 0, 3, 3]), 6.0);
        assert_eq!(middle_of_widest_peak(&[1, 1, 1]), 0.0);
    }

    #[test]
    fn a_crease_in_clutter_lies_in_its_surfaces() {
        // The foot of a wall sampled on a 0.05 grid: the part is the strip
        // of both surfaces within its claim radius 0.1 of the crease (3 rows
        // of ground, 2 of wall), and both surfaces go on to 0.5.
        let tau = 0.1;
        let mut pts = Vec::new();
        for r in 0..3 {
            pts.extend(line_at(-(r as f64) * 0.05, 0.0));
        }
        for r in 1..=2 {
            pts.extend(line_at(0.0, r as f64 * 0.05));
        }
        let members: Vec<u32> = (0..pts.len() as u32).collect();
        for r in 3..=10 {
            pts.extend(line_at(-(r as f64) * 0.05, 0.0));
            pts.extend(line_at(0.0, r as f64 * 0.05));
        }
        // Clutter in the street, out of both surfaces' reach from the axis:
        // more than the sheets hold within the line's length.
        let mut s = 777u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            pts.push([rnd() * 1.95, -0.4 - rnd() * 1.3, 0.4 + rnd() * 1.3]);
        }
        let copies = Copies::none(pts.len());
        let cloud = Cloud::new(&pts, &copies);
        let part = Draft::line(&pts, members.clone(), 0, (tau, 0.1)).0;
        let super::super::Primitive::Line(f) = &part.fit else {
            panic!("a line part");
        };
        let ends = span(f, &part.members, &pts);
        let length = ends.1 - ends.0;
        // Within the line's length the clutter outweighs the sheets...
        let far = on_sheets_within(&part, f, ends, length, tau, &cloud, &mut Vec::new());
        assert!(!far, "the far surroundings alone hold the crease");
        // ...near the axis the two surfaces hold it.
        assert!(run(&pts, members, tau));
    }

    #[test]
    fn a_line_above_a_plane_or_alone_stands_free() {
        // The same rings, and the part 0.5 above the middle one: off the plane.
        let mut pts = Vec::new();
        for r in -3..=3 {
            pts.extend(line_at(r as f64 * 0.4, 0.0));
        }
        let first = pts.len() as u32;
        pts.extend(line_at(0.0, 0.5));
        let members: Vec<u32> = (first..first + 40).collect();
        assert!(!run(&pts, members, 0.01));
        // Alone: nothing around it.
        let alone = line_at(0.0, 0.0);
        assert!(!run(&alone, (0..40).collect(), 0.01));
        // A cable 1.2 above densely sampled ground (rows 0.05 apart, within
        // the window of radius 1.95): one row lies right below it, most of
        // the ground does not lie in a half-plane bounded by the cable.
        let mut pts = Vec::new();
        for r in -40..=40 {
            pts.extend(line_at(r as f64 * 0.05, 0.0));
        }
        let first = pts.len() as u32;
        pts.extend(line_at(0.0, 1.2));
        assert!(!run(&pts, (first..first + 40).collect(), 0.01));
    }

    #[test]
    fn a_line_crossing_another_or_in_scattered_points_stands_free() {
        // A perpendicular line through its middle (a crossbar on a pole):
        // the surroundings are linear.
        let mut pts = line_at(0.0, 0.0);
        pts.extend((0..80).map(|i| [1.0, 0.0, -2.0 + i as f64 * 0.05]));
        assert!(!run(&pts, (0..40).collect(), 0.01));
        // Scattered points around it (a uniform background).
        let mut pts = line_at(0.0, 0.0);
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            pts.push([rnd() * 2.0, rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0]);
        }
        assert!(!run(&pts, (0..40).collect(), 0.01));
    }
}
