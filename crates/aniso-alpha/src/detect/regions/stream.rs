//! The region run of a cloud read in pieces, which no process holds whole:
//! a LAS/LAZ file larger than memory, read a range of points at a time
//! (docs/method.md §8, "Regions").
//!
//! The same plan, regions, joining and fits as [`detect_by_regions`] on the
//! pieces' points stacked in order, so the same labels and parts:
//!
//! 1. [`survey`]: one pass over the pieces gives each one's count, first
//!    input index and bounding box, and the cloud's.
//! 2. [`detect_streamed`]: the region grid from the cloud's box; a second
//!    pass gives the cells that hold points (the regions, in the grid's
//!    (x, y) order); each region reads the pieces whose box meets its
//!    window and keeps the points in it (its core and margin), is detected
//!    as in memory, and is joined in the plan's order. Returns the joined
//!    parts ([`RegionJoined`]), whose point labels are read by input index
//!    range.
//! 3. [`refit_streamed`]: three passes over the pieces in input order fit
//!    the joined parts (bit for bit the in-memory fits); the first pass
//!    hands each piece and its labels to the caller, which writes them.
//!
//! What stays in memory: per piece its count and box; the regions' cells;
//! up to `jobs` regions' points and runs, and the steps of regions done
//! ahead of their turn; the joining's pair counts and margin labels still
//! waiting for their core region; the part ids, 4 bytes a point, in
//! memory or in a scratch file ([`RegionJoin::with_scratch`]). A piece is
//! read, cut and dropped. A file in spatial order (tiles, COPC, points
//! sorted along a curve) is read least: a file in acquisition order may be
//! read whole by each region whose window its pieces' boxes all meet.
//!
//! [`detect_by_regions`]: super::detect_by_regions

use std::borrow::Cow;
use std::collections::BTreeSet;

use crate::geometry::bounding_box;

use super::{
    run_region, run_regions, DetectError, Detector, RegionGrid, RegionJoin, RegionJoined,
    RegionRun, Selection,
};

/// A cloud read in pieces, in input order: piece `k` holds the points
/// that follow piece `k − 1`'s.
pub trait Pieces: Sync {
    /// The reader's error (a detection error passes through it).
    type Error: From<DetectError> + Send;

    /// The number of pieces.
    fn len(&self) -> usize;

    /// Whether there is no piece.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Piece `k`'s points, in input order.
    ///
    /// # Errors
    /// The reader's.
    fn points(&self, k: usize) -> Result<Vec<[f64; 3]>, Self::Error>;
}

/// What one pass over the pieces finds: each piece's count, first input
/// index and box, and the cloud's.
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// Per piece: its number of points.
    pub counts: Vec<usize>,
    /// Per piece: the input index of its first point.
    pub firsts: Vec<usize>,
    /// Per piece: its bounding box (min, max); inverted for an empty one.
    pub boxes: Vec<([f64; 3], [f64; 3])>,
    /// The cloud's points.
    pub n: usize,
    /// The cloud's bounding box (min, max).
    pub lo: [f64; 3],
    /// See `lo`.
    pub hi: [f64; 3],
}

/// Reads every piece once through `read` (piece `k`'s points), on the
/// current pool (one piece a thread at a time), and gives `f` its points;
/// the results in piece order.
fn each_piece<E: Send, T: Send>(
    pieces: usize,
    read: impl Fn(usize) -> Result<Vec<[f64; 3]>, E> + Sync,
    f: impl Fn(Vec<[f64; 3]>) -> T + Sync,
) -> Result<Vec<T>, E> {
    crate::par::map_ranges(pieces, || (), |_, k| read(k).map(&f))
        .into_iter()
        .collect()
}

/// The first pass (module doc, step 1).
///
/// # Errors
/// The reader's; [`DetectError::Empty`] when the pieces hold no point;
/// [`DetectError::BadParameter`] past 2³² points (a region run numbers
/// points with 32 bits).
pub fn survey<P: Pieces>(src: &P) -> Result<Survey, P::Error> {
    let found = each_piece(
        src.len(),
        |k| src.points(k),
        |p| (p.len(), bounding_box(&p)),
    )?;
    let counts: Vec<usize> = found.iter().map(|f| f.0).collect();
    let mut firsts = Vec::with_capacity(counts.len());
    let mut n = 0usize;
    for &c in &counts {
        firsts.push(n);
        n += c;
    }
    if n == 0 {
        return Err(DetectError::Empty.into());
    }
    if n > u32::MAX as usize {
        return Err(DetectError::BadParameter(format!(
            "{n} points: a region run numbers points with 32 bits (at most {})",
            u32::MAX
        ))
        .into());
    }
    let boxes: Vec<([f64; 3], [f64; 3])> = found.into_iter().map(|f| f.1).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for (blo, bhi) in &boxes {
        for k in 0..3 {
            lo[k] = lo[k].min(blo[k]);
            hi[k] = hi[k].max(bhi[k]);
        }
    }
    Ok(Survey {
        counts,
        firsts,
        boxes,
        n,
        lo,
        hi,
    })
}

/// Piece `k` read again, checked against the survey.
fn piece_again<P: Pieces>(src: &P, survey: &Survey, k: usize) -> Result<Vec<[f64; 3]>, P::Error> {
    let pts = src.points(k)?;
    if pts.len() != survey.counts[k] {
        return Err(DetectError::InputChanged(format!(
            "piece {k} holds {} points, {} when the run began",
            pts.len(),
            survey.counts[k]
        ))
        .into());
    }
    Ok(pts)
}

/// The region run of the pieces (module doc, step 2) with regions of side
/// `side`, up to `jobs` at once (0: as many as the pool has threads),
/// joined in `join` (a [`RegionJoin`] over [`Survey::n`] points, in memory
/// or with a scratch file); `build` and `progress` as for
/// [`detect_by_regions_with_progress`](super::detect_by_regions_with_progress).
///
/// # Errors
/// The reader's; a region's; [`DetectError::InputChanged`] when a piece
/// no longer holds the points the survey counted;
/// [`DetectError::NoSpacing`] when every region was of one position.
pub fn detect_streamed<P: Pieces>(
    src: &P,
    survey: &Survey,
    side: f64,
    jobs: usize,
    join: RegionJoin,
    build: impl Fn(&[u32], &[[f64; 3]]) -> Result<Detector, DetectError> + Sync,
    progress: &mut (dyn FnMut(usize, usize) -> bool + Send),
) -> Result<RegionJoined, P::Error> {
    let grid = RegionGrid::of_extent(survey.lo, side)?;
    let mut cells = BTreeSet::new();
    let again = |k| piece_again(src, survey, k);
    for piece in each_piece(src.len(), again, |p| grid.cells(&p))? {
        cells.extend(piece);
    }
    let cells: Vec<(i64, i64)> = cells.into_iter().collect();
    let run = |r: usize| {
        let select = |margin: f64| -> Result<Selection<'static>, P::Error> {
            let window = grid.window(cells[r], margin);
            let (wlo, whi) = window.bounds();
            let mut sel = Selection {
                ids: Vec::new(),
                core: Cow::Owned(Vec::new()),
                points: Vec::new(),
            };
            let mut core = Vec::new();
            for (k, (blo, bhi)) in survey.boxes.iter().enumerate() {
                let meets =
                    blo[0] <= whi[0] && bhi[0] >= wlo[0] && blo[1] <= whi[1] && bhi[1] >= wlo[1];
                if !meets {
                    continue;
                }
                let pts = piece_again(src, survey, k)?;
                for (i, p) in pts.iter().enumerate() {
                    if window.contains(p) {
                        let id = (survey.firsts[k] + i) as u32;
                        sel.ids.push(id);
                        sel.points.push(*p);
                        if window.is_core(p) {
                            core.push(id);
                        }
                    }
                }
            }
            sel.core = Cow::Owned(core);
            Ok(sel)
        };
        run_region(super::FIRST_MARGIN * grid.side(), select, &build)
    };
    Ok(run_regions(cells.len(), jobs, join, run, progress)?.resolve()?)
}

/// The joined parts' fits (module doc, step 3): three passes over the
/// pieces in input order; in the first, `first_pass(k, first, points,
/// structures, parts)` gets piece `k` (its first input index and points)
/// and its points' structure and part ids (−1: none). Returns the run
/// without the points' labels (they went to `first_pass`).
///
/// # Errors
/// The reader's; `first_pass`'s; [`DetectError::InputChanged`] when a
/// piece no longer holds the points the survey counted.
pub fn refit_streamed<P: Pieces>(
    src: &P,
    survey: &Survey,
    joined: &RegionJoined,
    mut first_pass: impl FnMut(usize, usize, &[[f64; 3]], &[i64], &[i64]) -> Result<(), P::Error>,
) -> Result<RegionRun, P::Error> {
    let mut refit = joined.refit();
    for pass in 0..3 {
        for (k, &first) in survey.firsts.iter().enumerate() {
            let pts = piece_again(src, survey, k)?;
            refit.add_points(joined, first, &pts)?;
            if pass == 0 {
                let (parts, structures) = joined.labels(first, pts.len())?;
                first_pass(k, first, &pts, &structures, &parts)?;
            }
        }
        refit.end_pass();
    }
    Ok(joined.run(&refit))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::regions::detect_by_regions;
    use crate::detect::{Given, StructureKind};
    use crate::rng::SplitMix64;

    /// A cloud in pieces of `size` points, counting its reads.
    struct InPieces<'a> {
        points: &'a [[f64; 3]],
        size: usize,
        reads: std::sync::atomic::AtomicUsize,
    }

    impl Pieces for InPieces<'_> {
        type Error = DetectError;
        fn len(&self) -> usize {
            self.points.len().div_ceil(self.size)
        }
        fn points(&self, k: usize) -> Result<Vec<[f64; 3]>, DetectError> {
            self.reads
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let end = ((k + 1) * self.size).min(self.points.len());
            Ok(self.points[k * self.size..end].to_vec())
        }
    }

    /// Ground over 0..90 × 0..60 with a pitched roof and a flat roof on
    /// it, the rows shuffled into acquisition-like order (strips along y).
    fn scene() -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(11);
        let mut pts = Vec::new();
        for strip in 0..3 {
            for iy in 0..60 {
                for ix in strip * 30..(strip + 1) * 30 {
                    let (x, y) = (
                        ix as f64 + 0.2 * (rng.uniform() - 0.5),
                        iy as f64 + 0.2 * (rng.uniform() - 0.5),
                    );
                    let z = if (20.0..50.0).contains(&x) && (10.0..25.0).contains(&y) {
                        5.0 + 0.4 * (y - 10.0)
                    } else if (60.0..80.0).contains(&x) && (35.0..50.0).contains(&y) {
                        7.0
                    } else {
                        0.0
                    };
                    pts.push([x, y, z + 0.02 * (rng.uniform() - 0.5)]);
                }
            }
        }
        pts
    }

    fn build(_: &[u32], sub: &[[f64; 3]]) -> Result<Detector, DetectError> {
        Ok(Detector::auto(StructureKind::Planes, sub, &Given::default())?.threads(1))
    }

    #[test]
    fn pieces_give_the_in_memory_region_run() {
        let pts = scene();
        let side = 25.0;
        let want = detect_by_regions(&pts, side, build).unwrap();
        assert!(want.regions >= 6 && want.joins > 0, "{want:?}");
        for size in [pts.len(), 1000, 777] {
            let src = InPieces {
                points: &pts,
                size,
                reads: Default::default(),
            };
            let survey = survey(&src).unwrap();
            assert_eq!(survey.n, pts.len());
            let joined = detect_streamed(
                &src,
                &survey,
                side,
                2,
                RegionJoin::new(survey.n),
                build,
                &mut |_, _| true,
            )
            .unwrap();
            let (mut labels, mut part_labels) = (Vec::new(), Vec::new());
            let run = refit_streamed(&src, &survey, &joined, |_, first, p, s, q| {
                assert_eq!(first, labels.len());
                assert!(s.len() == p.len() && q.len() == p.len());
                labels.extend_from_slice(s);
                part_labels.extend_from_slice(q);
                Ok(())
            })
            .unwrap();
            assert_eq!(labels, want.labels, "pieces of {size}");
            assert_eq!(part_labels, want.part_labels, "pieces of {size}");
            assert_eq!(run.parts, want.parts, "pieces of {size}");
            assert_eq!(
                (run.regions, run.widened, run.joins, run.skipped),
                (want.regions, want.widened, want.joins, want.skipped)
            );
            // A region reads only the pieces whose box meets its window:
            // past the five passes over all of them (survey, cells, three
            // refits), fewer reads than every selection (one per margin
            // tried) reading every piece.
            let pieces = src.len();
            let reads = src.reads.load(std::sync::atomic::Ordering::Relaxed) - 5 * pieces;
            if pieces > 1 {
                let selections = want.regions + want.widened;
                assert!(
                    reads < selections * pieces,
                    "{reads} reads, {pieces} pieces, {selections} selections"
                );
            }
        }
    }

    #[test]
    fn a_piece_that_changed_is_an_error_and_an_empty_cloud_too() {
        struct Shrinking(std::sync::atomic::AtomicUsize);
        impl Pieces for Shrinking {
            type Error = DetectError;
            fn len(&self) -> usize {
                1
            }
            fn points(&self, _: usize) -> Result<Vec<[f64; 3]>, DetectError> {
                let t = self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                Ok(scene()[..2000 - t].to_vec())
            }
        }
        let src = Shrinking(Default::default());
        let s = survey(&src).unwrap();
        let err = detect_streamed(
            &src,
            &s,
            10.0,
            1,
            RegionJoin::new(s.n),
            build,
            &mut |_, _| true,
        )
        .unwrap_err();
        assert!(matches!(err, DetectError::InputChanged(_)), "{err:?}");
        let empty = InPieces {
            points: &[],
            size: 10,
            reads: Default::default(),
        };
        assert_eq!(survey(&empty).unwrap_err(), DetectError::Empty);
    }
}
