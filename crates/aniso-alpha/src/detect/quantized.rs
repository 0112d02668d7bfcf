//! Coordinates stored on levels coarser than a point's neighbourhood, and
//! the points moved within their level (docs/method.md §8, "Quantized
//! coordinates").
//!
//! A depth camera stores depth in steps (a Kinect's disparity: 12 mm apart
//! at 2.5 m, where its pixels are 4 mm apart), so every surface of its
//! frame is a staircase of flat terraces. The local shapes see the terrace,
//! not the surface: on PCL's `capture0001.pcd` the noise came out 4e-11,
//! every normal pointed along the depth axis, and the frame gave 476
//! parts, one per terrace. A point's true position lies anywhere within
//! its level (the quantization error is uniform over a step); moving each
//! point by a uniform draw across its step (dithering) restores the noise
//! the method assumes, σ = step/√12, and the terraces' surface.
//!
//! An axis counts as quantized when its levels are farther apart than the
//! finest local shape reaches: the median of the points' level steps
//! exceeds [`REACH_SPACINGS`] times their median nearest-neighbour
//! distance (both over a sample of at most 1,024 points drawn by a hash
//! of their coordinates), the radius of a point's [`NEIGHBOURS`] nearest
//! points on a regular sampling such as a depth image's pixels (on a
//! square grid the 16th nearest point is √5 ≈ 2.2 spacings away; the
//! terraces themselves make the sampling uneven, so the reach is not
//! measured on the cloud: on `capture0001` it came out 3 spacings).
//! Then a point's neighbourhood lies on one level (a terrace), which no
//! other sampling does: a regular grid's levels are one spacing apart, and
//! a LAS file's 1 cm levels under a 10 cm spacing a tenth of one. A level
//! holding a whole neighbourhood holds at least [`NEIGHBOURS`] points, so
//! an axis with more distinct values than n / [`NEIGHBOURS`] is given up
//! as soon as it has shown that many (a continuous axis costs n / 16 hash
//! insertions; only an axis of few levels is indexed).
//!
//! Structures that each lie exactly on one value (three parallel lines 50
//! apart, floors stacked at whole metres, flat roofs over a flat ground,
//! as synthetic clouds often are) have coarse levels too, and dithering
//! them would scatter them. Two tests tell a quantization from them, both
//! from the method's model of it: the values spread over at least a step
//! (Widrow's condition for a uniform quantization error; any two levels,
//! or three of equal weight, spread over less), and the levels are the
//! terraces of surfaces crossing them (`Terraces`): seen along the axis
//! (along the camera's rays for a depth), most points have mostly their
//! own level around them, and where they meet another level its nearest
//! point is on the next level up or down. Stacked structures fill each
//! other's columns; roofs meet the ground several levels apart. On PCL's
//! raw frames (`capture0001`–`0005`, `person`) a point's own level holds
//! most of its column for 57–60% of the sample, and the next level is the
//! nearest for 89–94% of those that meet one; on the stacked floors and
//! lines of the tests, 0.2–22%, and for the roofs the next level is the
//! nearest for 7%.
//!
//! Levels finer than the reach still hold a neighbourhood where a surface
//! is seen nearly face-on: a terrace is the step over the surface's slope
//! across the axis wide. A stereo camera's depth (uniform steps of
//! disparity, so of 1/z) makes the far wall of PCL's
//! `table_scene_mug_stereo_textured.pcd` a stack of exactly flat parts
//! (199 parts in 62 structures) while its median step is 0.6 of a
//! spacing. So an axis whose values spread over many steps
//! ([`MANY_STEPS`]: a surface crossing them, not a few structures each on
//! one value) is also quantized when its terraces are side by side in
//! part of the cloud: of the sampled points held by their own level that
//! meet another one, at least [`NEIGHBOURS`], and more than half of them
//! meet the next level nearest. PCL's stereo frame (16% of its sample
//! held), its structured-light `milk_cartoon_all_small_clorox.pcd` (13%),
//! its `region_growing_rgb_tutorial.pcd` (32%, terraces a pixel or two
//! wide at a grazing angle, which the majority missed) and the corpus'
//! mOSD frames (levels 0.9–1.3 spacings apart, 3–9% held) are dithered
//! this way; the stereo frame then gives 93 parts in 21 structures, none
//! exactly flat. The tests' roofs at 60 heights over a ground spread over
//! many steps but meet the ground many levels apart, and are left alone.
//!
//! The draw is a hash of the point's coordinates (rounded to a thousandth
//! of the reach), so copies of a point stay copies and the result does not
//! depend on the points' order, on how a cloud is cut into tiles or
//! regions, or on the file's number format. It does depend on the draw:
//! where the dithered noise (step/√12, about a spacing at steps of 3.5
//! spacings) brings the local normals near the mode search's
//! concentration threshold, another draw can tip the estimate
//! (docs/method.md §8).

use std::borrow::Cow;

use crate::geometry::kdtree::KdTree;
use crate::rng;

use super::local::NEIGHBOURS;

/// At most this many points are asked for their nearest neighbour.
const SPACING_SAMPLE: usize = 1024;

/// The finest neighbourhood's radius ([`NEIGHBOURS`] points) in spacings,
/// on a regular sampling: on a square grid the 16th nearest point is √5 ≈
/// 2.2 spacings away.
pub const REACH_SPACINGS: f64 = 2.0;

/// Steps over which an axis' values must spread (standard deviation)
/// for levels finer than a neighbourhood to be asked whether some of
/// them are terraces: [`NEIGHBOURS`]. A surface crossing a depth camera's
/// levels crosses hundreds of them (the spread over the median step:
/// 21–52 on PCL's Kinect frames, 70–100 on the mOSD frames, 250 and
/// 1,000 on PCL's structured-light and stereo frames); a few structures
/// each on one value spread over a few (six stacked floors or lines: 1.7).
pub const MANY_STEPS: f64 = NEIGHBOURS as f64;

/// One axis whose coordinates lie on levels coarser than the points'
/// neighbourhoods.
#[derive(Debug, Clone, PartialEq)]
pub struct QuantizedAxis {
    /// 0, 1, 2: x, y, z.
    pub axis: usize,
    /// The median over the sampled points of their level's step (the mean
    /// of the gaps to the levels below and above).
    pub step: f64,
    /// [`REACH_SPACINGS`] times the median distance from a point to its
    /// nearest other point (a sample of at most 1,024 points): the finest
    /// neighbourhood's radius.
    pub reach: f64,
    /// The share of the sampled points whose own level holds most of
    /// their column (within [`Self::reach`] across the axis): the points
    /// on terraces wider than a neighbourhood.
    pub terraced: f64,
    /// Whether the levels are coarser than a neighbourhood for most
    /// points (the median step over [`REACH_SPACINGS`] exceeds the median
    /// spacing); else the terraces are wide only where surfaces are seen
    /// nearly face-on.
    pub coarse: bool,
    /// The axis' distinct values, ascending.
    levels: Vec<f64>,
}

impl QuantizedAxis {
    /// The axis' name.
    pub fn name(&self) -> &'static str {
        ["x", "y", "z"][self.axis]
    }

    /// The step of the level holding `v` (one of [`Self::levels`]): the
    /// mean of its gaps to the levels below and above (the one gap at an
    /// end).
    fn step_at(&self, v: f64) -> f64 {
        step_at(&self.levels, v)
    }
}

/// The quantized axes of a cloud, and the cloud moved within its levels.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Quantization {
    /// The quantized axes (none for almost every cloud).
    pub axes: Vec<QuantizedAxis>,
}

impl Quantization {
    /// The axes of `points` whose levels are coarser than a
    /// neighbourhood's reach, spread over more than a step, and terraces
    /// side by side rather than structures stacked (none when the cloud
    /// has fewer than 2·[`NEIGHBOURS`] points or a non-finite one).
    pub fn of(points: &[[f64; 3]]) -> Quantization {
        let n = points.len();
        let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
        if n < 2 * NEIGHBOURS || !points.iter().all(finite) {
            // Too few to tell; a non-finite point is the run's error to
            // give.
            return Quantization::default();
        }
        let every = n.div_ceil(SPACING_SAMPLE) as u64;
        let sample: Vec<u32> = (0u32..)
            .zip(points)
            .filter(|(_, p)| hash(p, 3) % every == 0)
            .map(|(i, _)| i)
            .collect();
        if sample.is_empty() {
            // Copies of a few points, none drawn: nothing to measure.
            return Quantization::default();
        }
        let mut axes = Vec::new();
        // The finest neighbourhood's radius, measured once, for the axes
        // that get that far.
        let mut reach = None;
        for axis in 0..3 {
            let Some(levels) = levels_of(points, axis, n / NEIGHBOURS) else {
                continue;
            };
            if levels.len() < 2 {
                continue;
            }
            let mut steps: Vec<f64> = sample
                .iter()
                .map(|&i| step_at(&levels, points[i as usize][axis]))
                .collect();
            let step = median(&mut steps);
            // Levels coarser than a neighbourhood are a quantization only
            // where they are the steps of surfaces crossing them: values
            // spread over more than a step (Widrow's condition), and
            // terraces side by side.
            let spread = spread(points, &sample, axis);
            if spread < step {
                continue;
            }
            // The median spacing is below step / REACH_SPACINGS exactly
            // when more than half of the sample has a point that near:
            // then most neighbourhoods lie on one level.
            let coarse = near_for_most(points, &sample, step / REACH_SPACINGS);
            // Values spread over many steps are a surface crossing them,
            // not a few structures each on one value: then the terraces
            // need only be wider than a neighbourhood in part of the
            // cloud (on the surfaces seen nearly face-on).
            let many = spread >= MANY_STEPS * step;
            if !coarse && !many {
                continue;
            }
            let reach = *reach.get_or_insert_with(|| REACH_SPACINGS * spacing(points, &sample));
            let t = Terraces::of(points, &sample, axis, &levels, reach);
            if !((coarse && t.side_by_side()) || (many && t.in_part())) {
                continue;
            }
            axes.push(QuantizedAxis {
                axis,
                step,
                reach,
                terraced: t.held_share(),
                coarse,
                levels,
            });
        }
        Quantization { axes }
    }

    /// Whether no axis is quantized.
    pub fn is_empty(&self) -> bool {
        self.axes.is_empty()
    }

    /// `points` moved, on each quantized axis, by a uniform draw across
    /// the step of their level (centred on the level); the draw is a hash
    /// of the point's coordinates, each rounded to a thousandth of the
    /// reach (so that the same cloud written as float32 or as text is
    /// drawn alike), and the axis. A value that is not one of the levels
    /// (another cloud's) takes the step of the nearest one.
    pub fn dither(&self, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let Some(grain) = self.axes.first().map(|a| a.reach / 1000.0) else {
            return points.to_vec();
        };
        points
            .iter()
            .map(|p| {
                let key = p.map(|v| (v / grain).round());
                let mut q = *p;
                for a in &self.axes {
                    let u = unit(&key, a.axis);
                    q[a.axis] = p[a.axis] + (u - 0.5) * a.step_at(p[a.axis]);
                }
                q
            })
            .collect()
    }

    /// The points a run sees: `points` dithered ([`Self::dither`]) where
    /// an axis is quantized, else `points` themselves.
    pub fn seen<'a>(&self, points: &'a [[f64; 3]]) -> Cow<'a, [[f64; 3]]> {
        if self.is_empty() {
            Cow::Borrowed(points)
        } else {
            Cow::Owned(self.dither(points))
        }
    }

    /// One line per quantized axis, for the CLI's warning and Python's.
    pub fn describe(&self) -> Vec<String> {
        self.axes
            .iter()
            .map(|a| {
                let how = if a.coarse {
                    format!(
                        "farther than a point's {} nearest neighbours reach ({:.4}, {} spacings)",
                        NEIGHBOURS, a.reach, REACH_SPACINGS
                    )
                } else {
                    format!(
                        "finer than a point's {} nearest neighbours reach ({:.4}, {} spacings), \
                         but {:.0}% of the points lie on terraces wider than that (surfaces seen \
                         nearly face-on)",
                        NEIGHBOURS,
                        a.reach,
                        REACH_SPACINGS,
                        100.0 * a.terraced
                    )
                };
                format!(
                    "the {} coordinates lie on levels {:.4} apart (median), {how}: steps of a \
                     quantization (a depth camera's, or coordinates stored at a coarse scale); \
                     each point is moved within its level (dithered) so that its surface, not \
                     the step, is seen",
                    a.name(),
                    a.step,
                )
            })
            .collect()
    }
}

/// The distinct values of `axis`, ascending, or `None` as soon as there
/// are more than `most` of them: a continuous axis is given up after
/// `most` + 1 distinct values are seen, without sorting the cloud.
fn levels_of(points: &[[f64; 3]], axis: usize, most: usize) -> Option<Vec<f64>> {
    let mut seen = std::collections::HashSet::with_capacity(most.min(1 << 16) + 1);
    for p in points {
        // +0.0 for -0.0: one level.
        seen.insert((p[axis] + 0.0).to_bits());
        if seen.len() > most {
            return None;
        }
    }
    let mut v: Vec<f64> = seen.into_iter().map(f64::from_bits).collect();
    v.sort_unstable_by(f64::total_cmp);
    Some(v)
}

/// The step of the level nearest to `v` among `levels` (ascending, at
/// least two): the mean of its gaps to the levels below and above, or the
/// one gap at an end.
fn step_at(levels: &[f64], v: f64) -> f64 {
    let i = levels.partition_point(|&l| l < v).min(levels.len() - 1);
    let i = if i > 0 && (v - levels[i - 1]).abs() < (levels[i] - v).abs() {
        i - 1
    } else {
        i
    };
    let below = (i > 0).then(|| levels[i] - levels[i - 1]);
    let above = (i + 1 < levels.len()).then(|| levels[i + 1] - levels[i]);
    match (below, above) {
        (Some(b), Some(a)) => 0.5 * (a + b),
        (Some(g), None) | (None, Some(g)) => g,
        (None, None) => 0.0,
    }
}

/// Whether more than half of the points at `sample` have another point
/// (not a copy) nearer than `r`: whether their median distance to the
/// nearest other point is below `r`. A grid of cells of side `r` over the
/// points, sorted by cell, and the 27 cells around each sampled point.
fn near_for_most(points: &[[f64; 3]], sample: &[u32], r: f64) -> bool {
    if r.is_nan() || r <= 0.0 {
        return false;
    }
    let cell = |p: &[f64; 3], off: [i64; 3]| -> u64 {
        let c = |a: usize| ((p[a] / r).floor() as i64 + off[a]) as f64;
        hash(&[c(0), c(1), c(2)], 5)
    };
    let around: Vec<[i64; 3]> = (0..27)
        .map(|o: i64| [o % 3 - 1, o / 3 % 3 - 1, o / 9 - 1])
        .collect();
    let grid = CellIndex::around(points, sample, &around, cell);
    let r2 = r * r;
    let has_near = |&i: &u32| {
        let p = &points[i as usize];
        around.iter().any(|&o| {
            grid.points_in(cell(p, o)).any(|j| {
                let q = &points[j as usize];
                let d2 = (0..3).map(|a| (p[a] - q[a]).powi(2)).sum::<f64>();
                d2 > 0.0 && d2 < r2
            })
        })
    };
    2 * sample.iter().filter(|i| has_near(i)).count() > sample.len()
}

/// The standard deviation of the `axis` coordinates of the points at
/// `sample`. Widrow's quantization theorem: a quantization error is
/// uniform over the step (the model the dither restores) when the values
/// spread over at least a step; a few structures each lying on one value
/// (two floors, three parallel lines) spread over less.
fn spread(points: &[[f64; 3]], sample: &[u32], axis: usize) -> f64 {
    let n = sample.len() as f64;
    let mean = sample
        .iter()
        .map(|&i| points[i as usize][axis])
        .sum::<f64>()
        / n;
    let var = sample
        .iter()
        .map(|&i| (points[i as usize][axis] - mean).powi(2))
        .sum::<f64>()
        / n;
    var.sqrt()
}

/// How the levels of `axis` lie across it, seen along its columns (the
/// points within `reach` of a sampled point across the axis): the
/// terraces of surfaces crossing them, side by side, or structures
/// stacked along it. A point of a terrace wider than its column has
/// mostly its own level around it, and where it meets another level, the
/// nearest is the next one up or down: the staircase of one surface.
/// Stacked structures (parallel lines, floors) fill each other's columns;
/// flat roofs at a few heights over the ground meet it several levels
/// apart. Where every level is positive, the axis is a depth seen from a
/// camera at the origin (a depth frame in its own coordinates, the only
/// way one axis of a scan is quantized), and the columns are the camera's
/// rays: the points' directions, scaled to the sample's median depth.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Terraces {
    /// The sampled points.
    sample: usize,
    /// Those whose own level holds most of their column (held).
    held: usize,
    /// Those that meet another level in their column.
    meeting: usize,
    /// Of those, the ones whose nearest other level is the next.
    next: usize,
    /// The held points that meet another level.
    held_meeting: usize,
    /// Of those, the ones whose nearest other level is the next.
    held_next: usize,
}

impl Terraces {
    fn of(points: &[[f64; 3]], sample: &[u32], axis: usize, levels: &[f64], reach: f64) -> Self {
        let mut t = Terraces {
            sample: sample.len(),
            ..Terraces::default()
        };
        if reach.is_nan() || reach <= 0.0 {
            return t;
        }
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let depth = levels[0] > 0.0;
        let mut values: Vec<f64> = sample.iter().map(|&i| points[i as usize][axis]).collect();
        let scale = median(&mut values);
        // A point's place across the axis: on its ray for a depth.
        let across = |p: &[f64; 3]| -> [f64; 2] {
            if depth {
                [p[u] / p[axis] * scale, p[v] / p[axis] * scale]
            } else {
                [p[u], p[v]]
            }
        };
        let cell = |p: &[f64; 3], du: i64, dv: i64| -> u64 {
            let a = across(p);
            let c = |x: f64, d: i64| ((x / reach).floor() as i64 + d) as f64;
            hash(&[c(a[0], du), c(a[1], dv), 0.0], 7)
        };
        const AROUND: [(i64, i64); 9] = [
            (-1, -1),
            (-1, 0),
            (-1, 1),
            (0, -1),
            (0, 0),
            (0, 1),
            (1, -1),
            (1, 0),
            (1, 1),
        ];
        let grid = CellIndex::around(points, sample, &AROUND, |p, (du, dv)| cell(p, du, dv));
        let level = |x: f64| levels.partition_point(|&l| l < x);
        let r2 = reach * reach;
        for &i in sample {
            let p = &points[i as usize];
            let (k, pa) = (level(p[axis]), across(p));
            let (mut same, mut other) = (0usize, 0usize);
            // The other level nearest across: (distance², levels apart).
            let mut nearest = (f64::INFINITY, 0usize);
            for (du, dv) in AROUND {
                // A point's own column leaves it out.
                for j in grid.points_in(cell(p, du, dv)) {
                    let q = &points[j as usize];
                    let qa = across(q);
                    let d2 = (pa[0] - qa[0]).powi(2) + (pa[1] - qa[1]).powi(2);
                    if d2 >= r2 || j == i {
                        continue;
                    }
                    if q[axis] == p[axis] {
                        same += 1;
                    } else {
                        other += 1;
                        // Of levels equally near (stacked exactly), the
                        // farthest apart.
                        let apart = level(q[axis]).abs_diff(k);
                        if d2 < nearest.0 || (d2 == nearest.0 && apart > nearest.1) {
                            nearest = (d2, apart);
                        }
                    }
                }
            }
            let held = other < same;
            let next = usize::from(nearest.1 == 1);
            t.held += usize::from(held);
            if other > 0 {
                t.meeting += 1;
                t.next += next;
                if held {
                    t.held_meeting += 1;
                    t.held_next += next;
                }
            }
        }
        t
    }

    /// Terraces side by side over most of the cloud: more than half of the
    /// sample held by its own level, and of the points that meet another
    /// level, more than half meeting the next one nearest.
    fn side_by_side(&self) -> bool {
        2 * self.held > self.sample && 2 * self.next > self.meeting
    }

    /// Terraces side by side where a surface is seen nearly face-on: at
    /// least [`NEIGHBOURS`] held points meet another level (a
    /// neighbourhood's worth of terrace edges), and more than half of them
    /// meet the next one nearest.
    fn in_part(&self) -> bool {
        self.held_meeting >= NEIGHBOURS && 2 * self.held_next > self.held_meeting
    }

    /// The share of the sample held by its own level.
    fn held_share(&self) -> f64 {
        self.held as f64 / self.sample.max(1) as f64
    }
}

/// The median distance from a point at `sample` to its nearest other
/// point (copies skipped): the cloud's spacing, for the report.
fn spacing(points: &[[f64; 3]], sample: &[u32]) -> f64 {
    let tree = KdTree::new(points, None);
    let mut out = Vec::with_capacity(NEIGHBOURS);
    let mut near: Vec<f64> = sample
        .iter()
        .filter_map(|&i| {
            let p = &points[i as usize];
            // The point itself and its nearest; more only past copies.
            for k in [2, NEIGHBOURS] {
                tree.nearest(p, k, &mut out);
                if let Some(d2) = out.iter().map(|&(d2, _)| d2).find(|&d2| d2 > 0.0) {
                    return Some(d2.sqrt());
                }
            }
            None
        })
        .collect();
    if near.is_empty() {
        return 0.0;
    }
    median(&mut near)
}

/// The median of `v` (not empty), the upper one of an even count.
fn median(v: &mut [f64]) -> f64 {
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// A well-mixed hash of a point's coordinates and a salt (splitmix64's
/// output function chained over the bits).
fn hash(p: &[f64; 3], salt: u64) -> u64 {
    let mut h = salt.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    for v in p {
        h = rng::mix(h ^ v.to_bits());
    }
    h
}

/// A uniform draw in [0, 1) from a point's coordinates and an axis.
fn unit(p: &[f64; 3], axis: usize) -> f64 {
    rng::unit(hash(p, axis as u64))
}

/// The points in the cells around some sampled points, sorted by cell: a
/// grid that indexes only where it will be asked.
struct CellIndex(Vec<(u64, u32)>);

impl CellIndex {
    /// The points whose cell is one of those at `offsets` from a point at
    /// `sample`; `cell(p, o)` is the key of the cell `o` away from `p`'s
    /// (`O::default()`: its own).
    fn around<O: Copy + Default>(
        points: &[[f64; 3]],
        sample: &[u32],
        offsets: &[O],
        cell: impl Fn(&[f64; 3], O) -> u64,
    ) -> CellIndex {
        let wanted: std::collections::HashSet<u64> = sample
            .iter()
            .flat_map(|&i| offsets.iter().map(move |&o| (i, o)))
            .map(|(i, o)| cell(&points[i as usize], o))
            .collect();
        let mut grid: Vec<(u64, u32)> = (0u32..)
            .zip(points)
            .map(|(i, p)| (cell(p, O::default()), i))
            .filter(|(key, _)| wanted.contains(key))
            .collect();
        grid.sort_unstable_by_key(|e| e.0);
        CellIndex(grid)
    }

    /// The points of the cell `key`.
    fn points_in(&self, key: u64) -> impl Iterator<Item = u32> + '_ {
        let from = self.0.partition_point(|e| e.0 < key);
        self.0[from..]
            .iter()
            .take_while(move |e| e.0 == key)
            .map(|e| e.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// A slanted plane z = 0.5·x + 0.2·y sampled on a grid of spacing d,
    /// its z rounded to levels `step` apart.
    fn staircase(d: f64, step: f64) -> Vec<[f64; 3]> {
        let mut pts = Vec::new();
        for i in 0..80 {
            for j in 0..80 {
                let (x, y) = (i as f64 * d, j as f64 * d);
                let z = 0.5 * x + 0.2 * y;
                pts.push([x, y, (z / step).round() * step]);
            }
        }
        pts
    }

    #[test]
    fn a_staircase_is_quantized_and_its_dither_restores_the_plane() {
        let pts = staircase(0.01, 0.05);
        let q = Quantization::of(&pts);
        assert_eq!(q.axes.len(), 1, "{q:?}");
        let a = &q.axes[0];
        assert_eq!(a.axis, 2);
        assert!((a.step - 0.05).abs() < 1e-9, "{}", a.step);
        assert!(a.reach < a.step, "{a:?}");
        let moved = q.dither(&pts);
        // Each point stays within half a step of its level, and x, y stay.
        for (p, m) in pts.iter().zip(&moved) {
            assert_eq!((p[0], p[1]), (m[0], m[1]));
            assert!((p[2] - m[2]).abs() <= 0.025 + 1e-12);
        }
        // The dither is uniform across the step: its spread is step/√12.
        let r: Vec<f64> = pts.iter().zip(&moved).map(|(p, m)| m[2] - p[2]).collect();
        let mean = r.iter().sum::<f64>() / r.len() as f64;
        let sd = (r.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / r.len() as f64).sqrt();
        assert!(
            mean.abs() < 1e-3 && (sd - 0.05 / 12f64.sqrt()).abs() < 1e-3,
            "{mean} {sd}"
        );
        // The same draw for the same point, in any order, and in a part of
        // the cloud (a tile) as in the whole.
        let rev: Vec<[f64; 3]> = pts.iter().rev().copied().collect();
        let back: Vec<[f64; 3]> = q.dither(&rev).into_iter().rev().collect();
        assert_eq!(back, moved);
        assert_eq!(q.dither(&pts[100..200]), moved[100..200]);
    }

    #[test]
    fn grids_fine_levels_and_noise_are_not_quantized() {
        // A regular grid: its x and y levels are one spacing apart.
        let grid: Vec<[f64; 3]> = (0..2500)
            .map(|k| [(k % 50) as f64, (k / 50) as f64, 0.0])
            .collect();
        assert!(Quantization::of(&grid).is_empty());
        // Levels a tenth of the spacing apart (a LAS file's 1 cm under a
        // 10 cm spacing): the neighbourhoods span many levels.
        assert!(Quantization::of(&staircase(0.1, 0.01)).is_empty());
        // Continuous noise: every value distinct.
        let mut rng = SplitMix64::new(3);
        let noisy: Vec<[f64; 3]> = (0..3000)
            .map(|_| [rng.uniform(), rng.uniform(), 0.01 * rng.uniform()])
            .collect();
        assert!(Quantization::of(&noisy).is_empty());
        // Too few points to tell.
        assert!(Quantization::of(&staircase(0.01, 0.05)[..20]).is_empty());
        // Thousands of copies of two points: no panic, nothing found.
        let copies: Vec<[f64; 3]> = (0..5000).map(|k| [0.0, 0.0, (k % 2) as f64]).collect();
        assert!(Quantization::of(&copies).is_empty());
    }

    #[test]
    fn structures_each_on_one_value_are_not_quantized() {
        // Three parallel lines 50 apart (the Python `detect` example):
        // y on three levels, far coarser than the points' spacing.
        let lines: Vec<[f64; 3]> = (0..90)
            .map(|k| [(k % 30) as f64 * 100.0 / 29.0, 50.0 * (k / 30) as f64, 0.0])
            .collect();
        assert!(Quantization::of(&lines).is_empty());
        // Six such lines, random along, from y = 50 (every level positive:
        // the columns are rays from the origin).
        let mut rng = SplitMix64::new(5);
        let lines: Vec<[f64; 3]> = (0..6000)
            .map(|k| [100.0 * rng.uniform(), 50.0 * (1 + k % 6) as f64, 0.0])
            .collect();
        assert!(Quantization::of(&lines).is_empty());
        // Floors stacked 3 apart, random across: 2, 3 (each spreads over
        // less than a step) and 6 (they fill each other's columns), from
        // the ground and from 3 up (rays).
        for (floors, from) in [(2, 0.0), (3, 0.0), (6, 0.0), (6, 3.0)] {
            let pts: Vec<[f64; 3]> = (0..floors * 2000)
                .map(|k| {
                    let z = from + 3.0 * (k % floors) as f64;
                    [10.0 * rng.uniform(), 10.0 * rng.uniform(), z]
                })
                .collect();
            assert!(
                Quantization::of(&pts).is_empty(),
                "{floors} floors from {from}"
            );
        }
        // Flat roofs 3, 6, ..., 18 high on 6 blocks of a flat ground, each
        // exactly level: the roofs meet the ground several levels apart.
        let city: Vec<[f64; 3]> = (0..12000)
            .map(|_| {
                let (x, y) = (60.0 * rng.uniform(), 10.0 * rng.uniform());
                let block = (x / 10.0).floor();
                let on_roof = (x - 10.0 * block - 5.0).abs() < 3.0 && (y - 5.0).abs() < 3.0;
                [x, y, if on_roof { 3.0 * (block + 1.0) } else { 0.0 }]
            })
            .collect();
        assert!(Quantization::of(&city).is_empty());
        // The oracle can fail: the same ground as one slanted staircase.
        let slope: Vec<[f64; 3]> = (0..12000)
            .map(|_| {
                let (x, y) = (60.0 * rng.uniform(), 10.0 * rng.uniform());
                [x, y, (0.3 * x / 3.0).round() * 3.0]
            })
            .collect();
        assert_eq!(Quantization::of(&slope).axes.len(), 1);
        // And a depth frame: a wall and a floor seen from a camera at the
        // origin (pixels 1/500 rad apart), depth in steps of 25 mm (a
        // Kinect's at 3 m, where its pixels are 6 mm apart).
        let mut frame = Vec::new();
        for i in 0..160 {
            for j in 0..120 {
                let (a, b) = ((i as f64 - 80.0) / 500.0, (j as f64 - 60.0) / 500.0);
                // The floor y = 0.2 where the ray meets it first; else the
                // wall z = 3.
                let t = if b > 0.0 { (0.2 / b).min(3.0) } else { 3.0 };
                let z = (t / 0.025).round() * 0.025;
                frame.push([a * z, b * z, z]);
            }
        }
        let q = Quantization::of(&frame);
        assert_eq!(q.axes.len(), 1, "{q:?}");
        assert_eq!(q.axes[0].axis, 2);
    }

    /// A wall z = 3 + 0.1·x (about 6° from face-on) over a floor y = 0.2,
    /// seen from a camera at the origin with pixels 1/500 rad apart, its
    /// depth stored as `depth(z)` (the point moved along its ray).
    fn tilted_wall_frame(depth: impl Fn(f64) -> f64) -> Vec<[f64; 3]> {
        let mut frame = Vec::new();
        for i in 0..160 {
            for j in 0..120 {
                let (a, b) = ((i as f64 - 80.0) / 500.0, (j as f64 - 60.0) / 500.0);
                let wall = 3.0 / (1.0 - 0.1 * a);
                let t = if b > 0.0 { (0.2 / b).min(wall) } else { wall };
                let z = depth(t);
                frame.push([a * z, b * z, z]);
            }
        }
        frame
    }

    #[test]
    fn levels_finer_than_a_neighbourhood_are_quantized_where_they_make_terraces() {
        // A stereo camera's depth: uniform steps of 1/z (disparity), 4 mm
        // apart at 3 m where the pixels are 6 mm apart. The steps are
        // finer than a neighbourhood, but the wall, nearly face-on, is a
        // staircase of terraces 40 mm wide.
        let q = 4.4e-4;
        let frame = tilted_wall_frame(|t| 1.0 / ((1.0 / t / q).round() * q));
        let found = Quantization::of(&frame);
        assert_eq!(found.axes.len(), 1, "{found:?}");
        let a = &found.axes[0];
        assert_eq!(a.axis, 2);
        assert!(!a.coarse && a.step < a.reach, "{a:?}");
        assert!(a.terraced > 0.5, "{a:?}");
        assert!(
            found.describe()[0].contains("finer than"),
            "{:?}",
            found.describe()
        );
        // The oracle can fail: the same frame with its depth as measured
        // (every value distinct) is not quantized.
        assert!(Quantization::of(&tilted_wall_frame(|t| t)).is_empty());
        // Flat roofs at 60 heights (values spread over many levels), each
        // exactly level, on 8 × 8 blocks of a flat ground: held by their
        // own level, they meet the ground many levels apart.
        let mut rng = SplitMix64::new(11);
        let heights: Vec<f64> = (0..64).map(|k| (1 + (k * 37) % 60) as f64).collect();
        let city: Vec<[f64; 3]> = (0..40000)
            .map(|_| {
                let (x, y) = (80.0 * rng.uniform(), 80.0 * rng.uniform());
                let (bx, by) = ((x / 10.0).floor(), (y / 10.0).floor());
                let on_roof =
                    (x - 10.0 * bx - 5.0).abs() < 3.5 && (y - 10.0 * by - 5.0).abs() < 3.5;
                let h = heights[(8.0 * by + bx) as usize];
                [x, y, if on_roof { h } else { 0.0 }]
            })
            .collect();
        assert!(Quantization::of(&city).is_empty());
    }

    #[test]
    fn a_levels_step_is_its_gaps_mean() {
        let levels = [0.0, 1.0, 3.0, 7.0];
        assert_eq!(step_at(&levels, 0.0), 1.0);
        assert_eq!(step_at(&levels, 1.0), 1.5);
        assert_eq!(step_at(&levels, 3.0), 3.0);
        assert_eq!(step_at(&levels, 7.0), 4.0);
        // A value between levels takes the nearest one's step.
        assert_eq!(step_at(&levels, 2.4), 3.0);
        assert_eq!(step_at(&levels, -5.0), 1.0);
    }
}
