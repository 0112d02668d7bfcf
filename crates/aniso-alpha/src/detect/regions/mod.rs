//! A detection region by region, for clouds whose whole run would not fit
//! in memory (docs/method.md §8, "Regions"): the cloud's x–y extent is cut
//! into square columns of side `side` (regions); each region is detected
//! on its own points and a margin around them, with its own parameters
//! from the data, and the parts that cross a region's border are joined
//! through the points both regions saw.
//!
//! 1. **Regions.** Point i belongs to the column ⌊(x − x₀)/side⌋,
//!    ⌊(y − y₀)/side⌋ (its *core* region). A region's run takes its core
//!    points and every point within `margin` of the column (in x and y).
//! 2. **Margin.** A region's result near its border depends on the points
//!    within the reach of its ellipsoids: 2α·λ_max, the halo of the tiled
//!    scan (`detect::split`). The margin starts at side / 16; a region whose
//!    detector (estimated on its points and margin) reaches farther is
//!    estimated again with the margin its reach asks for ([`wider_margin`];
//!    counted in [`RegionRun::widened`]), so a core point's result always
//!    had the whole reach around it. A region's margin depends on its own
//!    data only: the regions can run in any order, on any machine
//!    ([`RegionPlan`], [`region_step`], [`RegionJoin`]), with the same
//!    result.
//! 3. **Labels.** A point's part and structure are those its core region
//!    gave it. A region whose points are all at one position (a stray
//!    point far from the rest) has no spacing to estimate from: its points
//!    are background ([`RegionRun::skipped`]).
//! 4. **Joining.** A point in region B's margin that lies in region A's
//!    core was labelled by both: it pairs its part in A with its part in
//!    B. Two parts are one when most of the labelled points one of them
//!    has over the other's region lie in the other (the same majority as
//!    the assembly's same-primitive test, [`SAME_SHARE`]) and their
//!    planes (directions, for lines) agree within the part angle. Their
//!    structures join with them.
//! 5. **Numbering.** Joined parts and structures are numbered by their
//!    number of points, largest first (ties by first region).
//!
//! Regions run as tasks on the current thread pool, up to `jobs` at once
//! (by default as many as there are threads), each parallel inside: a
//! region's serial stages overlap another's.
//!
//! Memory: the cloud, one part id a point (a point's structure is its
//! part's), the margins' labels and up to `jobs` regions' runs at a time
//! (their triangulations and assembly, which dominate a whole run's
//! peak), with the steps of regions done ahead of their turn. A driver
//! that does not hold the cloud (tiles read region by region) takes the
//! same pieces: the grid and windows of `plan.rs`, and the joining's
//! labels and fits streamed over the points in input order
//! ([`RegionJoin::resolve`], [`RegionJoined::labels`], [`PartsRefit`]).
//! Deterministic: a region's result depends on its own points (in input
//! order) only, and the joining takes the regions in the plan's order.

mod join;
mod part_ids;
mod plan;
pub mod stream;

pub use join::{PartsRefit, RegionJoin, RegionJoined};
pub use plan::{side_for, side_for_extent, RegionGrid, RegionPlan, RegionWindow, FIRST_MARGIN};

use super::detection::{Detection, Primitive};
use super::scan::halo_width;
use super::{DetectError, Detector};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// The share of a part's doubly labelled points that must lie in another
/// part for the two to be joined: a majority, as in the assembly's
/// same-primitive test.
pub const SAME_SHARE: f64 = 0.5;

/// A margin widened for a detector's reach r becomes r times this (the
/// estimate on the wider margin may reach a little farther).
pub const MARGIN_SLACK: f64 = 1.25;

/// Points a region holds with [`side_for`]: 250,000. A region's run keeps
/// its per-point time near a single tile's and its peak at a few hundred
/// MiB (BENCHMARKS.md, growth over AHN tiles: 24.5 µs a point and 284 MiB
/// at 697k points against 21.0 µs at 43k), and a cloud of a few million
/// points gives enough regions to run at once on many threads (a region
/// is a task; its own stages are parallel only in part). Measured on the
/// AHN **train** tile copied 8 × 8 (2.79M points, 2 cores) against
/// 500,000: plane F1 0.900 against 0.903 (0.909 with the side rounded to
/// a millimetre: region borders move the score by about 0.01), one thread
/// 35.6 s against 38.4 s, peak RSS on two threads 352 MiB against 516 MiB;
/// the held-out tile copied so: F1 0.860 against 0.851 (BENCHMARKS.md,
/// "Region size").
pub const REGION_POINTS: usize = 250_000;

/// Points above which a cloud is detected region by region (the CLI's
/// `--regions auto`): 1,000,000. A whole run of that size peaks at about
/// 400 MiB (BENCHMARKS.md, "Growth over tiles": 285 MiB at 697k points);
/// above it the whole run's memory grows with the cloud (3.5 GiB at 11M).
pub const REGIONS_ABOVE: usize = 1_000_000;

/// One joined part of a region run.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionPart {
    /// Its id in [`RegionRun::part_labels`] (0 = most points).
    pub id: u32,
    /// The id of its structure in [`RegionRun::labels`].
    pub structure: u32,
    /// Its points (those whose core region gave them this part).
    pub points: usize,
    /// Its line or plane, fitted on those points.
    pub primitive: Primitive,
    /// How many regions' parts it joins.
    pub pieces: usize,
}

/// The result of [`detect_by_regions`].
#[derive(Debug, Clone, PartialEq)]
pub struct RegionRun {
    /// Per input point: its structure id, or −1.
    pub labels: Vec<i64>,
    /// Per input point: its part id, or −1.
    pub part_labels: Vec<i64>,
    /// The joined parts, by id.
    pub parts: Vec<RegionPart>,
    /// Number of regions with points.
    pub regions: usize,
    /// Regions run again with a wider margin (their reach exceeded the
    /// first margin).
    pub widened: usize,
    /// Region parts joined across borders (pairs that became one).
    pub joins: usize,
    /// Regions whose points are all at one position (no spacing to
    /// estimate from): their points are background.
    pub skipped: usize,
    /// Regions whose detector did not use the normals given with the
    /// points in full (they disagree with the region's geometry: normals
    /// estimated there instead; or their modes explain less of it: the
    /// orientations from estimated normals there).
    pub normals_ignored: usize,
}

/// How far a detector's ellipsoids reach: the largest 2α·λ_max of its
/// orientations (the halo of the tiled scan).
pub fn reach(detector: &Detector) -> Result<f64, DetectError> {
    let (jobs, _) = detector.scan_jobs(detector.modes())?;
    Ok(jobs.iter().map(halo_width).fold(0.0, f64::max))
}

/// The margin a region's detector asks for (module doc, step 2): `None`
/// when its reach is within `margin`, else the reach times
/// [`MARGIN_SLACK`]. A region's margin depends on its own data only, so
/// regions can run in any order, anywhere.
pub fn wider_margin(detector: &Detector, margin: f64) -> Result<Option<f64>, DetectError> {
    let r = reach(detector)?;
    Ok((r > margin).then_some(r * MARGIN_SLACK))
}

/// One region's detection, as the joining takes it: per point of the
/// region (in the order of its input indices), its part and structure
/// in the region (−1: none), and per part of the region its structure
/// and axis (plain numbers: a step can cross a process boundary).
#[derive(Debug, Clone, PartialEq)]
pub struct RegionStep {
    /// Per region point: its part in the region, or −1.
    pub part: Vec<i64>,
    /// Per region point: its structure in the region, or −1.
    pub structure: Vec<i64>,
    /// Per part of the region: its structure, and its plane's normal or
    /// its line's direction (`None`: not fitted).
    pub parts: Vec<(u32, Option<[f64; 3]>)>,
    /// The number of structures of the region.
    pub structures: u32,
    /// The detector's part angle (degrees), for the joining.
    pub part_angle: f64,
    /// Lines (k = 1) rather than planes.
    pub lines: bool,
    /// The normals given with the points were not used in full
    /// ([`crate::detect::GivenNormals`]: for neither or only one of the
    /// orientations and the claims' gate).
    pub normals_ignored: bool,
}

/// Runs `detector` on a region's points `sub` (its core and margin, in
/// input order), without outlines: a region's step keeps its labels and
/// its parts' axes, and the joined parts are outlined by no one
/// ([`Detector::outlines`]).
///
/// # Errors
/// As [`Detector::run`].
pub fn region_step(detector: Detector, sub: &[[f64; 3]]) -> Result<RegionStep, DetectError> {
    let ignored = detector.given_normals().is_some_and(|g| !g.in_full());
    let part_angle = detector.part_angle_degrees();
    let det = detector.outlines(false).run(sub)?;
    let mut step = step_of(&det, part_angle);
    step.normals_ignored = ignored;
    Ok(step)
}

/// A plane's normal or a line's direction.
fn axis(p: &Primitive) -> Option<[f64; 3]> {
    match p {
        Primitive::Plane(f) => Some(f.normal),
        Primitive::Line(f) => Some(f.direction),
        Primitive::None => None,
    }
}

/// The [`RegionStep`] of a region's detection.
fn step_of(det: &Detection, part_angle: f64) -> RegionStep {
    let mut parts = Vec::with_capacity(det.num_parts());
    for st in &det.structures {
        for p in &st.parts {
            parts.push((st.id, axis(&p.primitive)));
        }
    }
    RegionStep {
        part: det.part_labels(),
        structure: det.labels.clone(),
        parts,
        structures: det.structures.len() as u32,
        part_angle,
        lines: det.kind == super::StructureKind::Lines,
        normals_ignored: false,
    }
}

/// Detects region by region (module doc). `build(ids, sub)` builds the
/// detector of the points `ids` (input indices, ascending; `sub` their
/// coordinates, which the region then runs on) from their data
/// (with [`Detector::auto`] or the options' builder, and the normals of
/// those points if the cloud has them); `side` is the region side in input
/// units. Two parts' primitives agree within the detectors' part angle
/// ([`Detector::part_angle`]).
///
/// # Errors
/// A region's error; a side that is not positive and finite.
pub fn detect_by_regions(
    points: &[[f64; 3]],
    side: f64,
    build: impl Fn(&[u32], &[[f64; 3]]) -> Result<Detector, DetectError> + Sync,
) -> Result<RegionRun, DetectError> {
    regions_run(points, side, true, 0, build, &mut |_, _| true)
}

/// [`detect_by_regions`] with up to `jobs` regions running at once (0:
/// as many as the current pool has threads), calling `progress(done,
/// total)` after each region joined (in the plan's order); `false`
/// returned cancels the run.
///
/// # Errors
/// As [`detect_by_regions`]; [`DetectError::Cancelled`] when `progress`
/// returned `false`.
pub fn detect_by_regions_with_progress(
    points: &[[f64; 3]],
    side: f64,
    jobs: usize,
    build: impl Fn(&[u32], &[[f64; 3]]) -> Result<Detector, DetectError> + Sync,
    progress: &mut (dyn FnMut(usize, usize) -> bool + Send),
) -> Result<RegionRun, DetectError> {
    regions_run(points, side, true, jobs, build, progress)
}

/// One region's run as the joining takes it: its points (core and margin,
/// ascending), its core (ascending, a subset of them), its step (`None`: a
/// region of one position), and how many times its margin was widened.
struct RegionDone<'a> {
    ids: Vec<u32>,
    core: Cow<'a, [u32]>,
    step: Option<RegionStep>,
    widened: usize,
}

/// Region `r`'s run (module doc, steps 1–2): its detector built on its
/// core and first margin, estimated again on a wider margin while its
/// reach asks for one, then run. `select(margin)` gives the region's
/// points within `margin` of its column: their input indices, their
/// core's, and their coordinates.
fn run_region<'a, E: From<DetectError>>(
    first_margin: f64,
    mut select: impl FnMut(f64) -> Result<Selection<'a>, E>,
    build: &(impl Fn(&[u32], &[[f64; 3]]) -> Result<Detector, DetectError> + Sync),
) -> Result<RegionDone<'a>, E> {
    let mut margin = first_margin;
    let mut widened = 0;
    loop {
        let Selection { ids, core, points } = select(margin)?;
        let detector = match build(&ids, &points) {
            Ok(d) => d,
            // A region of one position (a stray point, a stack of copies)
            // has no spacing to estimate: its points are background, as a
            // whole run leaves an isolated point.
            Err(DetectError::NoSpacing) => {
                return Ok(RegionDone {
                    ids: Vec::new(),
                    core: Cow::Borrowed(&[]),
                    step: None,
                    widened,
                })
            }
            Err(e) => return Err(e.into()),
        };
        match wider_margin(&detector, margin)? {
            None => {
                let step = region_step(detector, &points)?;
                return Ok(RegionDone {
                    ids,
                    core,
                    step: Some(step),
                    widened,
                });
            }
            Some(m) => {
                widened += 1;
                margin = m;
            }
        }
    }
}

/// A region's points within a margin of its column: their input indices
/// (ascending), those of its core, and their coordinates.
struct Selection<'a> {
    ids: Vec<u32>,
    core: Cow<'a, [u32]>,
    points: Vec<[f64; 3]>,
}

/// The joining side of a run whose regions finish in any order: the
/// regions done ahead of their turn wait in `pending`, and each is added
/// to the join in the plan's order.
struct InOrder<'a, 'p, E> {
    joined: RegionJoin,
    pending: BTreeMap<usize, RegionDone<'a>>,
    next: usize,
    total: usize,
    progress: &'p mut (dyn FnMut(usize, usize) -> bool + Send),
    /// The first failure met (region, error).
    failed: Option<(usize, E)>,
}

impl<'a, E: From<DetectError>> InOrder<'a, '_, E> {
    /// Takes region `r`'s run and adds every region whose turn has come.
    fn take(&mut self, r: usize, done: RegionDone<'a>) -> Result<(), E> {
        self.pending.insert(r, done);
        while let Some(d) = self.pending.remove(&self.next) {
            for _ in 0..d.widened {
                self.joined.widened();
            }
            match &d.step {
                None => self.joined.add(&[], &[], None)?,
                Some(step) => self.joined.add(&d.ids, &d.core, Some(step))?,
            }
            self.next += 1;
            if !(self.progress)(self.next, self.total) {
                return Err(DetectError::Cancelled.into());
            }
        }
        Ok(())
    }
}

/// Runs regions `0..total` (`run(r)`) as tasks on the current pool, up to
/// `jobs` at once (0: as many as the pool has threads), and adds each to
/// `join` in the plan's order; the first region's error (by region) stops
/// the run. A region's result does not depend on which ran first, so the
/// joining is the same for any `jobs` and any number of threads.
fn run_regions<'a, E: From<DetectError> + Send>(
    total: usize,
    jobs: usize,
    join: RegionJoin,
    run: impl Fn(usize) -> Result<RegionDone<'a>, E> + Sync,
    progress: &mut (dyn FnMut(usize, usize) -> bool + Send),
) -> Result<RegionJoin, E> {
    let jobs = if jobs == 0 {
        crate::par::threads()
    } else {
        jobs
    }
    .clamp(1, total.max(1));
    let state = Mutex::new(InOrder {
        joined: join,
        pending: BTreeMap::new(),
        next: 0,
        total,
        progress,
        failed: None,
    });
    let next_region = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let worker = || {
        while !stop.load(Ordering::Relaxed) {
            let r = next_region.fetch_add(1, Ordering::Relaxed);
            if r >= total {
                return;
            }
            let done = run(r);
            let mut st = state.lock().unwrap_or_else(|p| p.into_inner());
            if let Err(e) = done.and_then(|d| st.take(r, d)) {
                stop.store(true, Ordering::Relaxed);
                if st.failed.as_ref().is_none_or(|(f, _)| r < *f) {
                    st.failed = Some((r, e));
                }
            }
        }
    };
    crate::par::spawn_workers(jobs, worker);
    let st = state.into_inner().unwrap_or_else(|p| p.into_inner());
    match st.failed {
        Some((_, e)) => Err(e),
        None => Ok(st.joined),
    }
}

/// [`detect_by_regions`], with or without the joining of step 4 (without:
/// each region's parts stay apart), on a cloud in memory.
fn regions_run(
    points: &[[f64; 3]],
    side: f64,
    joining: bool,
    jobs: usize,
    build: impl Fn(&[u32], &[[f64; 3]]) -> Result<Detector, DetectError> + Sync,
    progress: &mut (dyn FnMut(usize, usize) -> bool + Send),
) -> Result<RegionRun, DetectError> {
    let plan = RegionPlan::new(points, side)?;
    let run = |r: usize| {
        let select = |margin: f64| -> Result<Selection<'_>, DetectError> {
            let ids = plan.points_within(points, r, margin);
            let sub = ids.iter().map(|&i| points[i as usize]).collect();
            Ok(Selection {
                ids,
                core: Cow::Borrowed(plan.core(r)),
                points: sub,
            })
        };
        run_region(plan.first_margin(), select, &build)
    };
    let join = RegionJoin::new(points.len());
    run_regions(plan.len(), jobs, join, run, progress)?.finish_with(points, joining)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::{Given, StructureKind};
    use crate::rng::SplitMix64;
    use std::collections::HashMap;

    /// A jittered grid of spacing 1 over `[x0, x1) × [y0, y1)` at height
    /// `z(x, y)`.
    fn sheet(
        rng: &mut SplitMix64,
        (x0, x1): (f64, f64),
        (y0, y1): (f64, f64),
        z: impl Fn(f64, f64) -> f64,
        out: &mut Vec<[f64; 3]>,
    ) {
        let mut y = y0;
        while y < y1 {
            let mut x = x0;
            while x < x1 {
                let (jx, jy) = (0.2 * (rng.uniform() - 0.5), 0.2 * (rng.uniform() - 0.5));
                let jz = 0.02 * (rng.uniform() - 0.5);
                out.push([x + jx, y + jy, z(x + jx, y + jy) + jz]);
                x += 1.0;
            }
            y += 1.0;
        }
    }

    /// Ground 0..120 × 0..120 at z = 0; one pitched roof face crossing the
    /// region border near x = 40 (z = 6 + 0.4·(y − 20) over 25..55 ×
    /// 20..35); two flat roofs at z = 8, 60 apart (10..25 × 80..95 and
    /// 85..100 × 80..95).
    fn scene() -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(7);
        let mut pts = Vec::new();
        let on_a_roof = |x: f64, y: f64| {
            (25.0..55.0).contains(&x) && (20.0..35.0).contains(&y)
                || (10.0..25.0).contains(&x) && (80.0..95.0).contains(&y)
                || (85.0..100.0).contains(&x) && (80.0..95.0).contains(&y)
        };
        let mut ground = Vec::new();
        sheet(
            &mut rng,
            (0.0, 120.0),
            (0.0, 120.0),
            |_, _| 0.0,
            &mut ground,
        );
        pts.extend(ground.into_iter().filter(|p| !on_a_roof(p[0], p[1])));
        sheet(
            &mut rng,
            (25.0, 55.0),
            (20.0, 35.0),
            |_, y| 6.0 + 0.4 * (y - 20.0),
            &mut pts,
        );
        sheet(&mut rng, (10.0, 25.0), (80.0, 95.0), |_, _| 8.0, &mut pts);
        sheet(&mut rng, (85.0, 100.0), (80.0, 95.0), |_, _| 8.0, &mut pts);
        pts
    }

    /// The automatic detector of the points `ids` of `pts`, on one thread.
    fn build(sub: &[[f64; 3]]) -> Result<Detector, DetectError> {
        Ok(Detector::auto(StructureKind::Planes, sub, &Given::default())?.threads(1))
    }

    fn by_regions(pts: &[[f64; 3]], side: f64) -> RegionRun {
        detect_by_regions(pts, side, |_, sub| build(sub)).unwrap()
    }

    /// The part most of `ids`' points carry, and its share of them.
    fn main_part(labels: &[i64], ids: impl Iterator<Item = usize>) -> (i64, f64) {
        let mut count: HashMap<i64, usize> = HashMap::new();
        let mut n = 0usize;
        for i in ids {
            *count.entry(labels[i]).or_insert(0) += 1;
            n += 1;
        }
        let (&p, &c) = count.iter().max_by_key(|(p, c)| (**c, -**p)).unwrap();
        (p, c as f64 / n as f64)
    }

    #[test]
    fn a_plane_across_regions_is_one_part_and_planes_apart_stay_apart() {
        let pts = scene();
        let run = by_regions(&pts, 40.0);
        assert_eq!(run.regions, 9);
        assert!(run.joins > 0);
        let where_ = |f: &dyn Fn(&[f64; 3]) -> bool| -> Vec<usize> {
            (0..pts.len()).filter(|&i| f(&pts[i])).collect()
        };
        let ground = where_(&|p| p[2].abs() < 0.1);
        let roof = where_(&|p| p[2] > 5.0 && p[1] < 40.0);
        let west = where_(&|p| p[2] > 7.5 && p[0] < 50.0 && p[1] > 70.0);
        let east = where_(&|p| p[2] > 7.5 && p[0] > 50.0 && p[1] > 70.0);
        // The ground spans the nine regions: one part holds nearly all.
        let (g, share) = main_part(&run.part_labels, ground.iter().copied());
        assert!(g >= 0 && share > 0.95, "ground: part {g}, share {share}");
        assert!(
            run.parts[g as usize].pieces >= 9,
            "{:?}",
            run.parts[g as usize]
        );
        // The roof face crosses x = 40 and is one part.
        let (r, share) = main_part(&run.part_labels, roof.iter().copied());
        assert!(
            r >= 0 && r != g && share > 0.9,
            "roof: part {r}, share {share}"
        );
        assert!(run.parts[r as usize].pieces >= 2);
        // Two coplanar roofs 60 apart: two parts.
        let (w, sw) = main_part(&run.part_labels, west.iter().copied());
        let (e, se) = main_part(&run.part_labels, east.iter().copied());
        assert!(
            w >= 0 && e >= 0 && w != e,
            "west {w} ({sw}), east {e} ({se})"
        );
        // Ids are numbered by size; the labels and parts agree.
        for (k, p) in run.parts.iter().enumerate() {
            assert_eq!(p.id as usize, k);
            let n = run.part_labels.iter().filter(|&&l| l == k as i64).count();
            assert_eq!(n, p.points);
            if k > 0 {
                assert!(run.parts[k - 1].points >= p.points);
            }
        }
        // Each region's first margin (side/16 = 2.5) is under its reach:
        // each was estimated again, once, with the margin it asked for.
        assert_eq!(run.widened, 9);
    }

    #[test]
    fn regions_joined_in_any_order_give_the_same_run() {
        // What a driver does with regions run elsewhere: the plan, each
        // region's margin and step from its own points, the joining, in
        // reverse order here.
        let pts = scene();
        let want = by_regions(&pts, 40.0);
        let plan = RegionPlan::new(&pts, 40.0).unwrap();
        let mut steps = Vec::new();
        for r in (0..plan.len()).rev() {
            let mut margin = plan.first_margin();
            let mut widened = false;
            let (ids, sub, d) = loop {
                let ids = plan.points_within(&pts, r, margin);
                // A driver of tiles finds the same points and core by the
                // window's own test over every point.
                let window = plan.grid().window(plan.cell(r), margin);
                let tested: Vec<u32> = (0..pts.len() as u32)
                    .filter(|&i| window.contains(&pts[i as usize]))
                    .collect();
                assert_eq!(tested, ids, "region {r}, margin {margin}");
                let core: Vec<u32> = ids
                    .iter()
                    .copied()
                    .filter(|&i| window.is_core(&pts[i as usize]))
                    .collect();
                assert_eq!(core, plan.core(r));
                let sub: Vec<[f64; 3]> = ids.iter().map(|&i| pts[i as usize]).collect();
                let d = build(&sub).unwrap();
                match wider_margin(&d, margin).unwrap() {
                    None => break (ids, sub, d),
                    Some(m) => {
                        margin = m;
                        widened = true;
                    }
                }
            };
            steps.push((r, ids, region_step(d, &sub).unwrap(), widened));
        }
        // The joining takes the regions in the plan's order (the numbering
        // of region parts follows it), wherever they ran.
        steps.sort_by_key(|s| s.0);
        let mut join = RegionJoin::new(pts.len());
        // The same joining with its part ids in a scratch file (its
        // waiting margin labels swept every few regions in tests).
        let dir = std::env::temp_dir();
        let mut streamed = RegionJoin::with_scratch(pts.len(), &dir).unwrap();
        for (r, ids, step, widened) in &steps {
            if *widened {
                join.widened();
                streamed.widened();
            }
            join.add(ids, plan.core(*r), Some(step)).unwrap();
            streamed.add(ids, plan.core(*r), Some(step)).unwrap();
        }
        assert_eq!(join.finish(&pts).unwrap(), want);
        // Streamed in uneven chunks (tiles in input order): labels chunk by
        // chunk and three refit passes give the same run, fits bit for bit.
        let joined = streamed.resolve().unwrap();
        let chunks = [0, 1000, 1001, 5000, pts.len()];
        let (mut part_labels, mut labels) = (Vec::new(), Vec::new());
        let mut refit = joined.refit();
        for pass in 0..3 {
            for w in chunks.windows(2) {
                if pass == 0 {
                    let (p, l) = joined.labels(w[0], w[1] - w[0]).unwrap();
                    part_labels.extend(p);
                    labels.extend(l);
                }
                refit.add_points(&joined, w[0], &pts[w[0]..w[1]]).unwrap();
            }
            refit.end_pass();
        }
        let run = RegionRun {
            labels,
            part_labels,
            ..joined.run(&refit)
        };
        assert_eq!(run, want);
        assert!(joined.labels(pts.len() - 1, 2).is_err());
        // A step of the wrong length, one naming points past the cloud, and
        // one that gives a point another structure than its part's are
        // refused.
        let mut join = RegionJoin::new(pts.len());
        let (r, ids, step, _) = &steps[0];
        assert!(join.add(&ids[1..], plan.core(*r), Some(step)).is_err());
        let mut small = RegionJoin::new(ids[ids.len() - 1] as usize);
        let err = small.add(ids, plan.core(*r), Some(step)).unwrap_err();
        assert!(err.to_string().contains("past"), "{err}");
        let mut bad = step.clone();
        let k = bad.part.iter().position(|&p| p >= 0).unwrap();
        bad.structure[k] = i64::from(bad.structures);
        let err = join.add(ids, plan.core(*r), Some(&bad)).unwrap_err();
        assert!(err.to_string().contains("structure"), "{err}");
    }

    #[test]
    fn one_region_gives_the_whole_runs_labels() {
        let pts = scene();
        let run = by_regions(&pts, 1000.0);
        assert_eq!((run.regions, run.joins), (1, 0));
        let d = Detector::auto(StructureKind::Planes, &pts, &Given::default())
            .unwrap()
            .threads(1);
        let det = d.run(&pts).unwrap();
        assert_eq!(run.part_labels, det.part_labels());
        assert_eq!(run.labels, det.labels);
    }

    #[test]
    fn without_the_joining_a_plane_across_regions_is_in_pieces() {
        // The oracle can fail: without the joining, the ground is one
        // part per region.
        let pts = scene();
        let run = regions_run(&pts, 40.0, false, 0, |_, sub| build(sub), &mut |_, _| true).unwrap();
        assert_eq!(run.joins, 0);
        let ground: Vec<usize> = (0..pts.len()).filter(|&i| pts[i][2].abs() < 0.1).collect();
        let (_, share) = main_part(&run.part_labels, ground.into_iter());
        assert!(share < 0.3, "{share}");
    }

    #[test]
    fn a_progress_callback_sees_every_region_and_can_cancel() {
        let pts = scene();
        for jobs in [1, 3] {
            let mut seen = Vec::new();
            let run = detect_by_regions_with_progress(
                &pts,
                60.0,
                jobs,
                |_, sub| build(sub),
                &mut |done, total| {
                    seen.push((done, total));
                    true
                },
            )
            .unwrap();
            assert_eq!(run.regions, 4);
            // In the plan's order, whichever region finished first.
            assert_eq!(seen, [(1, 4), (2, 4), (3, 4), (4, 4)]);
            let r = detect_by_regions_with_progress(
                &pts,
                60.0,
                jobs,
                |_, sub| build(sub),
                &mut |done, _| done < 2,
            );
            assert!(matches!(r, Err(DetectError::Cancelled)));
        }
    }

    #[test]
    fn regions_run_at_once_give_the_run_of_one_at_a_time() {
        // Every region finishing in any order, on pools of 1 and 2
        // threads (one thread: the region tasks take turns): the same run.
        let pts = scene();
        let one =
            detect_by_regions_with_progress(&pts, 40.0, 1, |_, sub| build(sub), &mut |_, _| true)
                .unwrap();
        assert_eq!(one.regions, 9);
        for (threads, jobs) in [(1, 9), (2, 2), (2, 9)] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let run = pool
                .install(|| {
                    detect_by_regions_with_progress(
                        &pts,
                        40.0,
                        jobs,
                        |_, sub| build(sub),
                        &mut |_, _| true,
                    )
                })
                .unwrap();
            assert_eq!(run.labels, one.labels, "{threads} threads, {jobs} jobs");
            assert_eq!(run.part_labels, one.part_labels);
            assert_eq!(run.parts, one.parts);
            assert_eq!((run.widened, run.joins), (one.widened, one.joins));
        }
    }

    #[test]
    fn the_first_failing_region_is_the_error() {
        // A build refuses any region holding a core point of region 3 or
        // 5 (theirs and their neighbours', through the margins): with 4
        // regions at once, the run stops with that error, whichever region
        // met it first, and no labels come back.
        let pts = scene();
        let plan = RegionPlan::new(&pts, 40.0).unwrap();
        let bad: Vec<u32> = [3usize, 5].iter().map(|&r| plan.core(r)[0]).collect();
        let r = detect_by_regions_with_progress(
            &pts,
            40.0,
            4,
            |ids, sub| {
                if bad.iter().any(|b| ids.binary_search(b).is_ok()) {
                    Err(DetectError::BadParameter("region refused".into()))
                } else {
                    build(sub)
                }
            },
            &mut |_, _| true,
        );
        assert!(matches!(r, Err(DetectError::BadParameter(m)) if m == "region refused"));
    }

    #[test]
    fn a_region_of_one_position_is_background_not_an_error() {
        let mut pts = scene();
        let n = pts.len();
        pts.extend([[500.0, 500.0, 1.0]; 3]);
        let run = by_regions(&pts, 40.0);
        assert_eq!((run.regions, run.skipped), (10, 1));
        assert!(run.part_labels[n..].iter().all(|&l| l == -1));
        assert!(run.part_labels[..n].iter().filter(|&&l| l >= 0).count() > n / 2);
    }

    #[test]
    fn a_cloud_of_one_position_per_region_is_the_whole_runs_error() {
        let pts = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [100.0, 0.0, 0.0]];
        let r = detect_by_regions(&pts, 10.0, |_, sub| build(sub));
        assert!(matches!(r, Err(DetectError::NoSpacing)), "{r:?}");
    }

    #[test]
    fn a_bad_side_is_an_error() {
        let pts = scene();
        for side in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let r = detect_by_regions(&pts, side, |_, _| unreachable!());
            assert!(matches!(r, Err(DetectError::BadParameter(_))), "{side}");
        }
    }

    #[test]
    fn the_side_for_a_cloud_holds_about_the_region_points() {
        let pts: Vec<[f64; 3]> = (0..3_000_000u32)
            .map(|i| [f64::from(i % 2000), f64::from(i / 2000), 0.0])
            .collect();
        let side = side_for(&pts).unwrap();
        // 2000 x 1500 at one point per unit: 250k points in a square of
        // side 500.
        assert!((side - 500.0).abs() < 1.0, "{side}");
        // Regions only above REGIONS_ABOVE points.
        assert!(side_for(&pts[..1_000_000]).is_none());
        assert!(side_for(&pts[..1_000_001]).is_some());
    }
}
