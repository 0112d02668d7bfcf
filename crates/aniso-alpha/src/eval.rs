//! Detection scores (docs/method.md §6): per-point precision / recall / F1 of
//! "structure vs background", and per-structure (and per-part) matches.
//!
//! Labels are `i64` per point: a structure id ≥ 0, or background (−1; any
//! negative value counts as background).
//!
//! * **Per point**: a point is *positive* when its label is ≥ 0. With TP =
//!   true and predicted positive, FP = predicted positive but background,
//!   FN = true positive but predicted background: precision = TP/(TP+FP),
//!   recall = TP/(TP+FN), F1 = 2PR/(P+R); a ratio 0/0 is reported as 0 (as
//!   scikit-learn does by default).
//! * **Per structure**: true structure t (all points with label t) is
//!   *found* when one detected structure d holds at least half of t's points
//!   (2·|t∩d| ≥ |t|) and more than half of d's points are t's
//!   (2·|t∩d| > |d|, background and other structures counting against it).
//!   d is the detected structure with the largest overlap (smallest id on
//!   ties). A polyhedron is one structure.
//! * **Per part** (polyhedra: `truth_parts` gives each point's facet, −1 if
//!   none): a true part (t, f) is matched the same way against detected
//!   parts (label, part) when `predicted_parts` is given, else against the
//!   detected structures (a detector that reports each facet as its own
//!   structure).
//!
//! ```
//! use aniso_alpha::eval::evaluate;
//! let truth = [0, 0, 0, 0, 1, 1, 1, -1, -1, -1];
//! let pred = [5, 5, 5, -1, 7, 7, 7, 7, -1, -1];
//! let e = evaluate(&truth, None, &pred, None).unwrap();
//! assert_eq!((e.true_positives, e.false_positives, e.false_negatives), (6, 1, 1));
//! assert!((e.precision - 6.0 / 7.0).abs() < 1e-12);
//! assert_eq!((e.structures_found, e.structures_total), (2, 2));
//! println!("{e}");
//! ```

use std::collections::BTreeMap;
use std::fmt;

/// Input error.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EvalError {
    /// A label vector does not have one entry per point.
    LengthMismatch {
        /// Which vector.
        what: &'static str,
        /// Expected length (number of truth labels).
        expected: usize,
        /// Its length.
        got: usize,
    },
}

impl fmt::Display for EvalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LengthMismatch {
                what,
                expected,
                got,
            } => write!(
                f,
                "{what} has {got} entries, expected {expected} (one per point)"
            ),
        }
    }
}

impl std::error::Error for EvalError {}

/// How one true structure (or part) was matched.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Match {
    /// True structure id.
    pub truth: i64,
    /// True part id (−1 for a whole structure).
    pub part: i64,
    /// Its number of points.
    pub size: usize,
    /// The detected structure (or, for parts with predicted parts, the
    /// detected `(structure, part)`) of largest overlap, if any.
    pub best: Option<(i64, i64)>,
    /// Points shared with `best`.
    pub overlap: usize,
    /// Number of points of `best`.
    pub best_size: usize,
    /// 2·overlap ≥ size and 2·overlap > best_size.
    pub found: bool,
}

/// All scores of one detection.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Number of points.
    pub points: usize,
    /// Structure points predicted as structure.
    pub true_positives: usize,
    /// Background points predicted as structure.
    pub false_positives: usize,
    /// Structure points predicted as background.
    pub false_negatives: usize,
    /// Background points predicted as background.
    pub true_negatives: usize,
    /// TP / (TP + FP) (0 if no point is predicted as structure).
    pub precision: f64,
    /// TP / (TP + FN) (0 if there is no true structure point).
    pub recall: f64,
    /// 2PR / (P + R) (0 if P + R = 0).
    pub f1: f64,
    /// Number of true structures.
    pub structures_total: usize,
    /// Number of true structures found.
    pub structures_found: usize,
    /// Number of detected structures (distinct predicted labels ≥ 0).
    pub detected_structures: usize,
    /// Number of true parts (0 without truth parts).
    pub parts_total: usize,
    /// Number of true parts found.
    pub parts_found: usize,
    /// One entry per true structure, by id.
    pub structures: Vec<Match>,
    /// One entry per true part, by (structure, part).
    pub parts: Vec<Match>,
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

fn check_len(what: &'static str, v: &[i64], n: usize) -> Result<(), EvalError> {
    if v.len() == n {
        Ok(())
    } else {
        Err(EvalError::LengthMismatch {
            what,
            expected: n,
            got: v.len(),
        })
    }
}

/// Matches every true group (key ≥ 0 entries of `truth_key`) against the
/// detected groups (`pred_key`).
fn match_groups<T: Ord + Copy>(
    truth_key: &[Option<T>],
    pred_key: &[Option<(i64, i64)>],
    describe: impl Fn(T) -> (i64, i64),
) -> Vec<Match> {
    let mut truth_size: BTreeMap<T, usize> = BTreeMap::new();
    let mut pred_size: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    let mut overlap: BTreeMap<(T, (i64, i64)), usize> = BTreeMap::new();
    for (t, p) in truth_key.iter().zip(pred_key) {
        if let Some(t) = t {
            *truth_size.entry(*t).or_default() += 1;
        }
        if let Some(p) = p {
            *pred_size.entry(*p).or_default() += 1;
        }
        if let (Some(t), Some(p)) = (t, p) {
            *overlap.entry((*t, *p)).or_default() += 1;
        }
    }
    truth_size
        .iter()
        .map(|(&t, &size)| {
            let best = overlap
                .range((t, (i64::MIN, i64::MIN))..=(t, (i64::MAX, i64::MAX)))
                .fold(
                    None,
                    |best: Option<((i64, i64), usize)>, (&(_, p), &n)| match best {
                        Some((_, m)) if m >= n => best,
                        _ => Some((p, n)),
                    },
                );
            let (truth, part) = describe(t);
            match best {
                Some((p, n)) => {
                    let best_size = pred_size[&p];
                    Match {
                        truth,
                        part,
                        size,
                        best: Some(p),
                        overlap: n,
                        best_size,
                        found: 2 * n >= size && 2 * n > best_size,
                    }
                }
                None => Match {
                    truth,
                    part,
                    size,
                    best: None,
                    overlap: 0,
                    best_size: 0,
                    found: false,
                },
            }
        })
        .collect()
}

/// Scores a detection (module docs). `truth_parts` and `predicted_parts`
/// are optional facet ids per point (−1 for none).
pub fn evaluate(
    truth: &[i64],
    truth_parts: Option<&[i64]>,
    predicted: &[i64],
    predicted_parts: Option<&[i64]>,
) -> Result<Evaluation, EvalError> {
    let n = truth.len();
    check_len("predicted labels", predicted, n)?;
    if let Some(tp) = truth_parts {
        check_len("truth parts", tp, n)?;
    }
    if let Some(pp) = predicted_parts {
        check_len("predicted parts", pp, n)?;
    }
    let (mut tp, mut fp, mut fneg, mut tn) = (0, 0, 0, 0);
    for (&t, &p) in truth.iter().zip(predicted) {
        match (t >= 0, p >= 0) {
            (true, true) => tp += 1,
            (false, true) => fp += 1,
            (true, false) => fneg += 1,
            (false, false) => tn += 1,
        }
    }
    let precision = ratio(tp, tp + fp);
    let recall = ratio(tp, tp + fneg);
    let f1 = if precision + recall > 0.0 {
        2.0 * precision * recall / (precision + recall)
    } else {
        0.0
    };

    let truth_key: Vec<Option<i64>> = truth.iter().map(|&t| (t >= 0).then_some(t)).collect();
    let pred_key: Vec<Option<(i64, i64)>> = predicted
        .iter()
        .map(|&p| (p >= 0).then_some((p, -1)))
        .collect();
    let structures = match_groups(&truth_key, &pred_key, |t| (t, -1));
    let detected_structures = {
        let mut d: Vec<i64> = predicted.iter().copied().filter(|&p| p >= 0).collect();
        d.sort_unstable();
        d.dedup();
        d.len()
    };

    let parts = match truth_parts {
        None => Vec::new(),
        Some(tparts) => {
            let tkey: Vec<Option<(i64, i64)>> = truth
                .iter()
                .zip(tparts)
                .map(|(&t, &f)| (t >= 0 && f >= 0).then_some((t, f)))
                .collect();
            let pkey: Vec<Option<(i64, i64)>> = match predicted_parts {
                Some(pparts) => predicted
                    .iter()
                    .zip(pparts)
                    .map(|(&p, &f)| (p >= 0 && f >= 0).then_some((p, f)))
                    .collect(),
                None => pred_key.clone(),
            };
            match_groups(&tkey, &pkey, |k| k)
        }
    };

    Ok(Evaluation {
        points: n,
        true_positives: tp,
        false_positives: fp,
        false_negatives: fneg,
        true_negatives: tn,
        precision,
        recall,
        f1,
        structures_total: structures.len(),
        structures_found: structures.iter().filter(|m| m.found).count(),
        detected_structures,
        parts_total: parts.len(),
        parts_found: parts.iter().filter(|m| m.found).count(),
        structures,
        parts,
    })
}

impl fmt::Display for Evaluation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "points {}  TP {}  FP {}  FN {}  TN {}",
            self.points,
            self.true_positives,
            self.false_positives,
            self.false_negatives,
            self.true_negatives
        )?;
        writeln!(
            f,
            "precision {:.3}  recall {:.3}  F1 {:.3}",
            self.precision, self.recall, self.f1
        )?;
        write!(
            f,
            "structures found {}/{} ({} detected)",
            self.structures_found, self.structures_total, self.detected_structures
        )?;
        if self.parts_total > 0 {
            write!(f, "  parts found {}/{}", self.parts_found, self.parts_total)?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "{:>8} {:>6} {:>6} {:>12} {:>8} {:>10} {:>6}",
            "truth", "part", "size", "best", "overlap", "best_size", "found"
        )?;
        for m in self.structures.iter().chain(&self.parts) {
            let best = match m.best {
                None => "-".to_string(),
                Some((d, -1)) => d.to_string(),
                Some((d, p)) => format!("{d}.{p}"),
            };
            let part = if m.part >= 0 {
                m.part.to_string()
            } else {
                "-".to_string()
            };
            writeln!(
                f,
                "{:>8} {:>6} {:>6} {:>12} {:>8} {:>10} {:>6}",
                m.truth,
                part,
                m.size,
                best,
                m.overlap,
                m.best_size,
                if m.found { "yes" } else { "no" }
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perfect_and_empty() {
        let truth = [0, 0, 1, 1, -1];
        let e = evaluate(&truth, None, &truth, None).unwrap();
        assert_eq!((e.precision, e.recall, e.f1), (1.0, 1.0, 1.0));
        assert_eq!((e.structures_found, e.structures_total), (2, 2));
        // Relabelled ids are fine.
        let e = evaluate(&truth, None, &[9, 9, 3, 3, -1], None).unwrap();
        assert_eq!(e.structures_found, 2);
        assert_eq!(e.structures[0].best, Some((9, -1)));
        // Nothing predicted: 0/0 precision is 0.
        let e = evaluate(&truth, None, &[-1; 5], None).unwrap();
        assert_eq!((e.precision, e.recall, e.f1), (0.0, 0.0, 0.0));
        assert_eq!((e.structures_found, e.detected_structures), (0, 0));
        assert_eq!(e.structures[0].best, None);
        let e = evaluate(&[], None, &[], None).unwrap();
        assert_eq!((e.points, e.structures_total), (0, 0));
    }

    #[test]
    fn hand_counted() {
        // t0: 4 points, 3 in d5; d5 also holds one background point →
        // 3/4 ≥ 1/2 and 3/4 of d5 is t0: found.
        // t1: 4 points, 2 in d7 and 2 in d8; d7 holds 2 background points:
        // 2/4 ≥ 1/2 but d7 is only half t1 (not most): not found.
        // t2: 2 points merged with t3 (4 points) into d9: t3 found, t2 not.
        let truth = [0, 0, 0, 0, 1, 1, 1, 1, -1, -1, -1, -1, 2, 2, 3, 3, 3, 3];
        let pred = [5, 5, 5, -1, 7, 7, 8, 8, 5, 7, 7, -1, 9, 9, 9, 9, 9, 9];
        let e = evaluate(&truth, None, &pred, None).unwrap();
        assert_eq!(e.true_positives, 13);
        assert_eq!(e.false_positives, 3);
        assert_eq!(e.false_negatives, 1);
        assert_eq!(e.true_negatives, 1);
        let (p, r) = (13.0 / 16.0, 13.0 / 14.0);
        assert!((e.precision - p).abs() < 1e-15);
        assert!((e.recall - r).abs() < 1e-15);
        assert!((e.f1 - 2.0 * p * r / (p + r)).abs() < 1e-15);
        assert_eq!(e.detected_structures, 4);
        let found: Vec<bool> = e.structures.iter().map(|m| m.found).collect();
        assert_eq!(found, vec![true, false, false, true]);
        assert_eq!(e.structures[1].best, Some((7, -1))); // tie 2-2: smaller id
        assert_eq!((e.structures[1].overlap, e.structures[1].best_size), (2, 4));
        assert_eq!((e.structures[3].overlap, e.structures[3].best_size), (4, 6));
        assert_eq!(e.structures_found, 2);
        let text = e.to_string();
        assert!(text.contains("structures found 2/4"), "{text}");
    }

    #[test]
    fn exactly_half_rules() {
        // Half of t is enough; half of d is not.
        let e = evaluate(&[0, 0, 0, 0, -1], None, &[1, 1, -1, -1, -1], None).unwrap();
        assert!(e.structures[0].found);
        let e = evaluate(&[0, 0, -1, -1], None, &[1, 1, 1, 1], None).unwrap();
        assert!(!e.structures[0].found);
        let e = evaluate(&[0, 0, 0, -1, -1], None, &[1, 1, 1, 1, 1], None).unwrap();
        assert!(e.structures[0].found);
    }

    #[test]
    fn parts() {
        // One polyhedron with 3 facets of 4 points.
        let truth = [0; 12];
        let tparts = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2];
        // Detected as one structure with parts 10, 11 (facets 1 and 2 merged).
        let pred = [3; 12];
        let pparts = [10, 10, 10, 10, 11, 11, 11, 11, 11, 11, 11, 11];
        let e = evaluate(&truth, Some(&tparts), &pred, Some(&pparts)).unwrap();
        assert_eq!((e.structures_found, e.structures_total), (1, 1));
        assert_eq!((e.parts_found, e.parts_total), (1, 3));
        assert_eq!(e.parts[0].best, Some((3, 10)));
        assert!(!e.parts[1].found && !e.parts[2].found);
        // Without predicted parts, facets are matched against structures:
        // a detector reporting each facet as a structure finds all parts but
        // not the polyhedron.
        let pred = [4, 4, 4, 4, 5, 5, 5, 5, 6, 6, 6, 6];
        let e = evaluate(&truth, Some(&tparts), &pred, None).unwrap();
        assert_eq!((e.parts_found, e.parts_total), (3, 3));
        assert_eq!(e.structures_found, 0);
        assert!(e.to_string().contains("parts found 3/3"));
    }

    #[test]
    fn errors() {
        assert_eq!(
            evaluate(&[0, 1], None, &[0], None),
            Err(EvalError::LengthMismatch {
                what: "predicted labels",
                expected: 2,
                got: 1
            })
        );
        assert!(evaluate(&[0, 1], Some(&[0]), &[0, 1], None).is_err());
        assert!(evaluate(&[0, 1], None, &[0, 1], Some(&[1, 2, 3])).is_err());
    }
}
