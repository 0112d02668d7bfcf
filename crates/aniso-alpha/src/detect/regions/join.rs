//! The joining of region steps (module doc of `regions`, steps 3–5): each
//! region's step added in the plan's order ([`RegionJoin`]), the parts
//! joined across borders and numbered ([`RegionJoin::resolve`]), then each
//! point's labels and each joined part's fit, either over a cloud in
//! memory ([`RegionJoin::finish`]) or over points streamed in input order,
//! a tile at a time ([`RegionJoined::labels`], [`PartsRefit`]), with the
//! same result bit for bit.
//!
//! Memory: one part id a point (4 bytes, in memory or in a scratch file:
//! [`RegionJoin::with_scratch`]), the regions' parts, the pair counts, and
//! the margin labels whose core region was not added yet (those of regions
//! added before are counted at once, the others as soon as their region
//! is added: the waiting ones are swept whenever they have doubled);
//! structures are the parts' own.

use super::part_ids::{PartIds, UNSEEN};
use super::{RegionPart, RegionRun, RegionStep, SAME_SHARE};
use crate::detect::detection::Primitive;
use crate::detect::fit::{Fitted, PassFit};
use crate::detect::DetectError;
use crate::unionfind::UnionFind;
use std::collections::HashMap;

/// A point its core region left as background.
const NONE: u32 = u32::MAX - 1;

/// The part id of a `part_of` entry, if it is one.
fn part_id(p: u32) -> Option<u32> {
    (p < NONE).then_some(p)
}

/// The joining of region steps: add each region's step (in the plan's
/// order, or any fixed order), then [`Self::finish`] (a cloud in memory)
/// or [`Self::resolve`] (a cloud streamed).
#[derive(Debug)]
pub struct RegionJoin {
    /// Per point: the global region part its core region gave it,
    /// [`NONE`], or [`UNSEEN`].
    part_of: PartIds,
    /// Per global region part: its region.
    part_region: Vec<u32>,
    /// Per global region part: its core points.
    held: Vec<usize>,
    /// Margin labels waiting in `results`, and their number after the
    /// last sweep.
    waiting: usize,
    swept: usize,
    /// Doubly labelled points per (part in a margin, part of the core
    /// owner), and per (part in a margin, owner's region).
    pairs: HashMap<(u32, u32), u32>,
    over: HashMap<(u32, u32), u32>,
    results: Vec<RegionResult>,
    n_parts: u32,
    n_structures: u32,
    angle: f64,
    lines: bool,
    widened: usize,
    skipped: usize,
    normals_ignored: usize,
}

/// What one region's run leaves for the joining: per region part, its
/// structure and axis; the (point, part) labels of its margin whose core
/// region was not added yet.
#[derive(Debug, Clone)]
struct RegionResult {
    parts: Vec<(u32, Option<[f64; 3]>)>,
    margin: Vec<(u32, u32)>,
}

/// Waiting margin labels swept at the earliest when there are this many
/// (a handful in tests, so that their joinings sweep).
const FIRST_SWEEP: usize = if cfg!(test) { 16 } else { 1 << 16 };

/// The error of a scratch file's read or write.
fn scratch_error(e: std::io::Error) -> DetectError {
    DetectError::Scratch(e.to_string())
}

impl RegionJoin {
    /// A joining over a cloud of `n` points.
    pub fn new(n: usize) -> Self {
        Self::over(PartIds::in_memory(n))
    }

    /// A joining over a cloud of `n` points whose part ids (4 bytes a
    /// point) are kept in a scratch file in folder `dir` (removed when the
    /// joining and what it resolves to are dropped), for a cloud whose ids
    /// should not take the joining process's memory. The same joins.
    ///
    /// # Errors
    /// [`DetectError::Scratch`] when the file cannot be made.
    pub fn with_scratch(n: usize, dir: &std::path::Path) -> Result<Self, DetectError> {
        Ok(Self::over(PartIds::in_file(n, dir).map_err(scratch_error)?))
    }

    fn over(part_of: PartIds) -> Self {
        RegionJoin {
            part_of,
            part_region: Vec::new(),
            held: Vec::new(),
            waiting: 0,
            swept: 0,
            pairs: HashMap::new(),
            over: HashMap::new(),
            results: Vec::new(),
            n_parts: 0,
            n_structures: 0,
            angle: 0.0,
            lines: false,
            widened: 0,
            skipped: 0,
            normals_ignored: 0,
        }
    }

    /// Counts a region whose margin was widened for its reach.
    pub fn widened(&mut self) {
        self.widened += 1;
    }

    /// Adds a region: its points `ids` (ascending), its `core` (ascending,
    /// a subset of `ids`) and its step, or `None` for a region of one
    /// position (its points stay background).
    ///
    /// # Errors
    /// A step whose labels do not match `ids`, a point id past the cloud,
    /// or a point whose structure is not its part's.
    pub fn add(
        &mut self,
        ids: &[u32],
        core: &[u32],
        step: Option<&RegionStep>,
    ) -> Result<(), DetectError> {
        let Some(step) = step else {
            self.skipped += 1;
            self.results.push(RegionResult {
                parts: Vec::new(),
                margin: Vec::new(),
            });
            return Ok(());
        };
        let bad = |what: String| Err(DetectError::BadParameter(format!("a region step {what}")));
        if step.part.len() != ids.len() || step.structure.len() != ids.len() {
            return bad(format!(
                "of {} labels for {} points",
                step.part.len(),
                ids.len()
            ));
        }
        if let Some(&i) = ids.iter().find(|&&i| i as usize >= self.part_of.len()) {
            return bad(format!(
                "names point {i}, past a cloud of {}",
                self.part_of.len()
            ));
        }
        let first_part = self.n_parts;
        let region = self.results.len() as u32;
        let mut held = vec![0usize; step.parts.len()];
        let (mut core_ids, mut core_parts) = (Vec::with_capacity(core.len()), Vec::new());
        let (mut margin_ids, mut margin_parts) = (Vec::new(), Vec::new());
        let mut c = 0usize;
        for (k, &i) in ids.iter().enumerate() {
            let is_core = c < core.len() && core[c] == i;
            if is_core {
                c += 1;
            }
            let (lp, ls) = (step.part[k], step.structure[k]);
            if lp >= 0 {
                match step.parts.get(lp as usize) {
                    Some(&(s, _)) if i64::from(s) == ls => {}
                    _ => return bad(format!("gives point {i} part {lp} and structure {ls}")),
                }
            }
            let part = (lp >= 0).then(|| first_part + lp as u32);
            match (is_core, part) {
                (true, p) => {
                    core_ids.push(i);
                    core_parts.push(p.unwrap_or(NONE));
                    if lp >= 0 {
                        held[lp as usize] += 1;
                    }
                }
                (false, Some(pm)) => {
                    margin_ids.push(i);
                    margin_parts.push(pm);
                }
                (false, None) => {}
            }
        }
        self.part_region
            .extend(std::iter::repeat_n(region, step.parts.len()));
        self.held.extend(held);
        self.part_of
            .set(&core_ids, &core_parts)
            .map_err(scratch_error)?;
        drop((core_ids, core_parts));
        let margin = self.pair_seen(margin_ids, margin_parts)?;
        self.waiting += margin.len();
        let first_structure = self.n_structures;
        let parts = step
            .parts
            .iter()
            .map(|&(s, a)| (first_structure + s, a))
            .collect::<Vec<_>>();
        self.n_parts += parts.len() as u32;
        self.n_structures += step.structures;
        self.angle = self.angle.max(step.part_angle);
        self.lines |= step.lines;
        self.normals_ignored += usize::from(step.normals_ignored);
        self.results.push(RegionResult { parts, margin });
        if self.waiting >= FIRST_SWEEP.max(2 * self.swept) {
            self.sweep()?;
        }
        Ok(())
    }

    /// Counts the margin labels (points `ids`, ascending, with parts
    /// `parts`) whose core region was added; returns the others.
    fn pair_seen(
        &mut self,
        ids: Vec<u32>,
        parts: Vec<u32>,
    ) -> Result<Vec<(u32, u32)>, DetectError> {
        let mut owners = Vec::with_capacity(ids.len());
        self.part_of.get(&ids, &mut owners).map_err(scratch_error)?;
        let mut left = Vec::new();
        for ((i, pm), owner) in ids.into_iter().zip(parts).zip(owners) {
            match owner {
                UNSEEN => left.push((i, pm)),
                owner => self.pair(pm, owner),
            }
        }
        left.shrink_to_fit();
        Ok(left)
    }

    /// Counts every waiting margin label whose core region was added since.
    fn sweep(&mut self) -> Result<(), DetectError> {
        self.waiting = 0;
        for r in 0..self.results.len() {
            let margin = std::mem::take(&mut self.results[r].margin);
            if margin.is_empty() {
                continue;
            }
            let (ids, parts) = margin.into_iter().unzip();
            let left = self.pair_seen(ids, parts)?;
            self.waiting += left.len();
            self.results[r].margin = left;
        }
        self.swept = self.waiting;
        Ok(())
    }

    /// The joined run over `points` (module doc, steps 4–5).
    ///
    /// # Errors
    /// [`DetectError::NoSpacing`] when every region was of one position
    /// (the whole cloud's answer).
    pub fn finish(self, points: &[[f64; 3]]) -> Result<RegionRun, DetectError> {
        self.finish_with(points, true)
    }

    /// Every global region part, in order: its structure and axis.
    fn parts(&self) -> impl Iterator<Item = (u32, Option<[f64; 3]>)> + '_ {
        self.results.iter().flat_map(|r| r.parts.iter().copied())
    }

    /// Counts a doubly labelled point: part `pm` in a margin, `owner` (a
    /// `part_of` entry) of its core region.
    fn pair(&mut self, pm: u32, owner: u32) {
        if let Some(owner) = part_id(owner) {
            let owner_region = self.part_region[owner as usize];
            *self.pairs.entry((pm, owner)).or_insert(0) += 1;
            *self.over.entry((pm, owner_region)).or_insert(0) += 1;
        }
    }

    /// [`Self::finish`], with or without the joining of step 4.
    pub(super) fn finish_with(
        self,
        points: &[[f64; 3]],
        joining: bool,
    ) -> Result<RegionRun, DetectError> {
        let joined = self.resolve_with(joining)?;
        let (part_labels, labels) = joined.labels(0, points.len())?;
        let mut refit = joined.refit();
        for _ in 0..3 {
            refit.add_points(&joined, 0, points)?;
            refit.end_pass();
        }
        Ok(RegionRun {
            labels,
            part_labels,
            ..joined.run(&refit)
        })
    }

    /// The parts joined across borders and numbered (module doc, steps
    /// 4–5), before any point's labels or any fit.
    ///
    /// # Errors
    /// As [`Self::finish`].
    pub fn resolve(self) -> Result<RegionJoined, DetectError> {
        self.resolve_with(true)
    }

    fn resolve_with(mut self, joining: bool) -> Result<RegionJoined, DetectError> {
        if self.skipped == self.results.len() {
            return Err(DetectError::NoSpacing);
        }
        // The margin labels whose core region came later (every region is
        // added now).
        self.sweep()?;
        let (n_parts, n_structures) = (self.n_parts as usize, self.n_structures as usize);
        let (mut parts_uf, mut structures_uf, joins) = if joining {
            join(&self, n_parts, n_structures)
        } else {
            (UnionFind::new(n_parts), UnionFind::new(n_structures), 0)
        };
        Ok(RegionJoined::number(
            self,
            &mut parts_uf,
            &mut structures_uf,
            joins,
        ))
    }
}

/// Whether two axes (planes: normals; lines: directions) agree within
/// `angle_deg`, either way.
fn agree(a: Option<[f64; 3]>, b: Option<[f64; 3]>, angle_deg: f64) -> bool {
    match (a, b) {
        (Some(u), Some(v)) => {
            let c = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]).abs();
            c >= angle_deg.to_radians().cos()
        }
        _ => false,
    }
}

/// The joining (module doc, step 4): union-finds over the global part and
/// structure ids, and the number of joins, from the pair counts of `j`.
fn join(j: &RegionJoin, n_parts: usize, n_structures: usize) -> (UnionFind, UnionFind, usize) {
    let (pairs, over, angle_deg, region) = (&j.pairs, &j.over, j.angle, &j.part_region);
    // Per global part: its structure and primitive.
    let info: Vec<(u32, Option<[f64; 3]>)> = j.parts().collect();
    // Counts the other way: for a core part `owner` seen from region r,
    // how many of its points r's margin labelled.
    let mut seen: HashMap<(u32, u32), u32> = HashMap::new();
    for (&(pm, owner), &c) in pairs {
        *seen.entry((owner, region[pm as usize])).or_insert(0) += c;
    }
    let mut keys: Vec<(u32, u32)> = pairs.keys().copied().collect();
    keys.sort_unstable();
    let mut parts_uf = UnionFind::new(n_parts);
    let mut structures_uf = UnionFind::new(n_structures);
    let mut joins = 0usize;
    for (pm, owner) in keys {
        let c = f64::from(pairs[&(pm, owner)]);
        let ((sm, prim_m), rm) = (info[pm as usize], region[pm as usize]);
        let ((so, prim_o), ro) = (info[owner as usize], region[owner as usize]);
        let of_margin = f64::from(over[&(pm, ro)]);
        let of_owner = f64::from(seen[&(owner, rm)]);
        let majority = c >= SAME_SHARE * of_margin || c >= SAME_SHARE * of_owner;
        if majority && agree(prim_m, prim_o, angle_deg) && parts_uf.union_min_root(pm, owner) {
            joins += 1;
            structures_uf.union_min_root(sm, so);
        }
    }
    (parts_uf, structures_uf, joins)
}

/// The joined and numbered parts of a region run (module doc, step 5):
/// what gives each point its labels and each part its fit, over the cloud
/// in memory or streamed in input order.
#[derive(Debug)]
pub struct RegionJoined {
    /// Per point: its global region part, [`NONE`], or [`UNSEEN`] (as in
    /// [`RegionJoin`]).
    part_of: PartIds,
    /// Per global region part: its final part and structure ids (MAX:
    /// a part no core point holds).
    final_of: Vec<(u32, u32)>,
    /// Per final part: its structure, points and pieces.
    summary: Vec<(u32, usize, usize)>,
    lines: bool,
    /// Number of regions with points.
    pub regions: usize,
    /// Regions run again with a wider margin.
    pub widened: usize,
    /// Region parts joined across borders.
    pub joins: usize,
    /// Regions of one position.
    pub skipped: usize,
    /// Regions whose detector did not use the given normals.
    pub normals_ignored: usize,
}

/// Final ids of the roots with points, largest first (ties by root id);
/// MAX for the others.
fn rank(count: &[usize]) -> Vec<u32> {
    let mut roots: Vec<u32> = (0..count.len() as u32)
        .filter(|&r| count[r as usize] > 0)
        .collect();
    roots.sort_by(|&a, &b| count[b as usize].cmp(&count[a as usize]).then(a.cmp(&b)));
    let mut id = vec![u32::MAX; count.len()];
    for (k, &r) in roots.iter().enumerate() {
        id[r as usize] = k as u32;
    }
    id
}

impl RegionJoined {
    /// Final ids (module doc, step 5): joined parts and structures
    /// numbered by their number of points, largest first.
    fn number(
        join: RegionJoin,
        parts_uf: &mut UnionFind,
        structures_uf: &mut UnionFind,
        joins: usize,
    ) -> Self {
        let structure_of: Vec<u32> = join.parts().map(|(s, _)| s).collect();
        let n_parts = structure_of.len();
        let held = &join.held;
        let mut part_count = vec![0usize; n_parts];
        let mut structure_count = vec![0usize; join.n_structures as usize];
        for (p, &c) in held.iter().enumerate() {
            part_count[parts_uf.find(p as u32) as usize] += c;
            structure_count[structures_uf.find(structure_of[p]) as usize] += c;
        }
        let part_id = rank(&part_count);
        let structure_id = rank(&structure_count);
        let n_final = part_id.iter().filter(|&&i| i != u32::MAX).count();
        let mut summary = vec![(0u32, 0usize, 0usize); n_final];
        let mut final_of = vec![(u32::MAX, u32::MAX); n_parts];
        for p in 0..n_parts {
            let root = parts_uf.find(p as u32) as usize;
            let id = part_id[root];
            if id == u32::MAX {
                continue;
            }
            let sid = structure_id[structures_uf.find(structure_of[p]) as usize];
            final_of[p] = (id, sid);
            let s = &mut summary[id as usize];
            *s = (sid, part_count[root], s.2 + 1);
        }
        RegionJoined {
            part_of: join.part_of,
            final_of,
            summary,
            lines: join.lines,
            regions: join.results.len(),
            widened: join.widened,
            joins,
            skipped: join.skipped,
            normals_ignored: join.normals_ignored,
        }
    }

    /// The number of points of the cloud.
    pub fn len(&self) -> usize {
        self.part_of.len()
    }

    /// Whether the cloud has no points (never, for a joining of regions).
    pub fn is_empty(&self) -> bool {
        self.part_of.len() == 0
    }

    /// The number of joined parts.
    pub fn num_parts(&self) -> usize {
        self.summary.len()
    }

    /// The final part and structure of each of the `n` points from input
    /// index `first` on (`None`: none).
    fn final_parts(
        &self,
        first: usize,
        n: usize,
    ) -> Result<impl Iterator<Item = Option<(u32, u32)>> + '_, DetectError> {
        if first.checked_add(n).is_none_or(|end| end > self.len()) {
            return Err(DetectError::BadParameter(format!(
                "points {first}..{} past a cloud of {}",
                first.saturating_add(n),
                self.len()
            )));
        }
        let mut ids = Vec::new();
        self.part_of
            .range(first, n, &mut ids)
            .map_err(scratch_error)?;
        Ok(ids
            .into_iter()
            .map(|p| part_id(p).map(|p| self.final_of[p as usize])))
    }

    /// The part and structure labels (−1: none) of the `n` points from
    /// input index `first` on.
    ///
    /// # Errors
    /// Points past the cloud; [`DetectError::Scratch`] when the scratch
    /// file cannot be read.
    pub fn labels(&self, first: usize, n: usize) -> Result<(Vec<i64>, Vec<i64>), DetectError> {
        Ok(self
            .final_parts(first, n)?
            .map(|f| match f {
                Some((p, s)) => (i64::from(p), i64::from(s)),
                None => (-1, -1),
            })
            .unzip())
    }

    /// A refit of every joined part (its line or plane), to be fed the
    /// points in input order.
    pub fn refit(&self) -> PartsRefit {
        PartsRefit {
            fits: vec![PassFit::new(self.lines); self.summary.len()],
            pass: 0,
        }
    }

    /// The run, its parts fitted by `refit` (fed every point three times),
    /// without the points' labels (empty: [`Self::labels`] gives them).
    pub fn run(&self, refit: &PartsRefit) -> RegionRun {
        RegionRun {
            labels: Vec::new(),
            part_labels: Vec::new(),
            parts: self.parts(refit),
            regions: self.regions,
            widened: self.widened,
            joins: self.joins,
            skipped: self.skipped,
            normals_ignored: self.normals_ignored,
        }
    }

    /// The joined parts, with the fits of a refit fed every point three
    /// times.
    fn parts(&self, refit: &PartsRefit) -> Vec<RegionPart> {
        self.summary
            .iter()
            .zip(&refit.fits)
            .enumerate()
            .map(|(k, (&(structure, points, pieces), fit))| RegionPart {
                id: k as u32,
                structure,
                points,
                primitive: match fit.finish() {
                    Ok(Fitted::Plane(f)) => Primitive::Plane(f),
                    Ok(Fitted::Line(f)) => Primitive::Line(f),
                    Err(_) => Primitive::None,
                },
                pieces,
            })
            .collect()
    }
}

/// The fits of a region run's joined parts over points streamed in input
/// order ([`PassFit`] per part): three passes, each over every point in
/// input order (in chunks: [`Self::add_points`] with each chunk's first input
/// index), each ended by [`Self::end_pass`]. The fits are those of the
/// points gathered, bit for bit.
#[derive(Debug, Clone)]
pub struct PartsRefit {
    fits: Vec<PassFit>,
    pass: u8,
}

impl PartsRefit {
    /// The pass under way (0, 1, 2; 3 when done).
    pub fn pass(&self) -> u8 {
        self.pass
    }

    /// Adds the points `points`, input indices `first..`, to the pass under
    /// way, for the joining `joined`.
    ///
    /// # Errors
    /// As [`RegionJoined::labels`].
    pub fn add_points(
        &mut self,
        joined: &RegionJoined,
        first: usize,
        points: &[[f64; 3]],
    ) -> Result<(), DetectError> {
        for (f, &p) in joined.final_parts(first, points.len())?.zip(points) {
            let Some((id, _)) = f else {
                continue;
            };
            let fit = &mut self.fits[id as usize];
            match self.pass {
                0 => fit.add_sum(p),
                1 => fit.add_moment(p),
                2 => fit.add_residual(p),
                _ => {}
            }
        }
        Ok(())
    }

    /// Ends the pass under way.
    pub fn end_pass(&mut self) {
        match self.pass {
            0 => self.fits.iter_mut().for_each(PassFit::end_sums),
            1 => self.fits.iter_mut().for_each(PassFit::end_moments),
            _ => {}
        }
        self.pass = (self.pass + 1).min(3);
    }
}
