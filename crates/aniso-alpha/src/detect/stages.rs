//! The named stages of a run (docs/method.md §4) and the wall time of
//! each, reported to an observer ([`crate::detect::Detector::on_stage`]):
//! what `--timings` prints under `stages`, and how the parallel fraction
//! of each stage is measured (one thread against several).

use std::sync::Arc;
use std::time::Instant;

/// A stage of a detection run, in the order a run meets them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// The orientation scan: per orientation, the triangulation of the
    /// transformed points, `F_{k,α,Q}` and the path filter (parallel over
    /// orientations).
    Scan,
    /// The union of the orientations' simplices and its component
    /// clean-up.
    Union,
    /// Candidate primitives from the union's components, and their
    /// footprints.
    Candidates,
    /// Claim radii from each candidate's noise (where the regime widens
    /// them).
    Widen,
    /// Claims, the merge of candidates that are one primitive, and the
    /// disjoint parts.
    Claims,
    /// The significance test (and, for lines, the rows inside a surface).
    Significance,
    /// The parts kept across the levels of a scale ladder.
    Select,
    /// One primitive, one part: coplanar parts found apart merged.
    Merge,
    /// Parts without their shape's proportions dropped.
    Proportions,
    /// The points left behind joined to the kept parts claiming them;
    /// structures, numbering, outlines or segments, labels.
    Structures,
}

impl Stage {
    /// Every stage, in run order.
    pub const ALL: [Stage; 10] = [
        Stage::Scan,
        Stage::Union,
        Stage::Candidates,
        Stage::Widen,
        Stage::Claims,
        Stage::Significance,
        Stage::Select,
        Stage::Merge,
        Stage::Proportions,
        Stage::Structures,
    ];

    /// Its name in reports (`--timings`): lower case, one word.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Scan => "scan",
            Stage::Union => "union",
            Stage::Candidates => "candidates",
            Stage::Widen => "widen",
            Stage::Claims => "claims",
            Stage::Significance => "significance",
            Stage::Select => "select",
            Stage::Merge => "merge",
            Stage::Proportions => "proportions",
            Stage::Structures => "structures",
        }
    }
}

/// The observer of a run's stages: called once per stage run (a scale
/// ladder runs the per-level stages once per level) with its wall
/// seconds.
pub(crate) type StageObserver = Arc<dyn Fn(Stage, f64) + Send + Sync>;

/// Times stages for an optional observer; without one it only runs them.
#[derive(Clone, Default)]
pub(crate) struct Clock(Option<StageObserver>);

impl Clock {
    /// A clock reporting to `observer`, if any.
    pub(crate) fn new(observer: Option<StageObserver>) -> Self {
        Clock(observer)
    }

    /// Runs `f` as `stage`, and reports its wall time.
    pub(crate) fn time<T>(&self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let Some(obs) = &self.0 else {
            return f();
        };
        let start = Instant::now();
        let out = f();
        obs(stage, start.elapsed().as_secs_f64());
        out
    }
}

impl std::fmt::Debug for Clock {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Clock(observed)"
        } else {
            "Clock"
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn names_are_distinct_and_in_run_order() {
        let names: Vec<&str> = Stage::ALL.iter().map(|s| s.name()).collect();
        let mut sorted = names.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), Stage::ALL.len());
        assert_eq!(names[0], "scan");
        assert_eq!(names[Stage::ALL.len() - 1], "structures");
    }

    #[test]
    fn a_clock_reports_each_stage_it_runs_and_returns_its_value() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let s = seen.clone();
        let clock = Clock::new(Some(Arc::new(move |st, secs| {
            s.lock().unwrap().push((st, secs))
        })));
        let v = clock.time(Stage::Claims, || {
            std::thread::sleep(std::time::Duration::from_millis(5));
            7
        });
        assert_eq!(v, 7);
        let seen = seen.lock().unwrap();
        assert_eq!(seen.len(), 1);
        assert_eq!(seen[0].0, Stage::Claims);
        assert!(seen[0].1 >= 0.004, "{}", seen[0].1);
        // Without an observer, the stage runs all the same.
        assert_eq!(Clock::default().time(Stage::Scan, || 3), 3);
    }
}
