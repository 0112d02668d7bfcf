//! The options of a detection as a front end takes them (the CLI's flags,
//! the Python package's keyword arguments), checked, and turned into a
//! [`Detector`]: one builder, so that the CLI and the Python package run
//! the same detector for the same options.
//!
//! [`DetectOptions`] holds every option with its default; [`DetectOptions::build`]
//! checks them (each error names the option as the front end spells it,
//! [`Style`]) and builds the detector:
//!
//! - with `alpha`, `lambda3` and `min_size` all given, the paper's explicit
//!   run ([`Detector::lines`], [`Detector::planes`]; `lambda2` defaults to
//!   `lambda3`) on the paper's box sampler, unless `sampler` says otherwise;
//! - otherwise the missing parameters and the orientations come from the
//!   data ([`Detector::auto_with`], [`Detector::auto_oriented`] with
//!   normals), the given values kept; `sampler` may replace the data's
//!   orientations by the box or Fibonacci sampler.
//!
//! ```
//! use aniso_alpha::options::{DetectOptions, Style};
//! use aniso_alpha::StructureKind;
//! let scene = aniso_alpha::synth::lines(1);
//! let opts = DetectOptions {
//!     alpha: Some(1.0),
//!     lambda3: Some(10.0),
//!     min_size: Some(4),
//!     ..DetectOptions::new(StructureKind::Lines)
//! };
//! let det = opts.build(&scene.points, None, Style::Python)?.run(&scene.points)?;
//! assert!(det.structures.len() >= 4);
//! let bad = DetectOptions { min_size: Some(0), ..opts };
//! let err = bad.build(&scene.points, None, Style::Python).unwrap_err();
//! assert_eq!(err.to_string(), "bad parameter: min_size must be between 1 and 4294967295, got 0");
//! # Ok::<(), aniso_alpha::DetectError>(())
//! ```

use crate::detect::orientations::Sampler;
use crate::detect::{DetectError, Detector, Given, StructureKind, LAMBDA_RANGE};

/// How a front end spells its options, for the error messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Command-line flags: `--min-size`.
    Cli,
    /// Python keyword arguments: `min_size`.
    Python,
}

impl Style {
    /// `name` (an option's snake_case name) as this front end spells it.
    pub fn name(self, name: &str) -> String {
        match self {
            Style::Cli => format!("--{}", name.replace('_', "-")),
            Style::Python => name.to_string(),
        }
    }
}

/// Where the orientations scanned come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SamplerChoice {
    /// The modes of the data's local normals (planes) or directions
    /// (lines), each with its own scale.
    Data,
    /// The paper's box sampler (`m1`, `m2`).
    Box,
    /// Near-uniform Fibonacci directions (`step`).
    Fibonacci,
}

impl SamplerChoice {
    /// `"data"`, `"box"` or `"fibonacci"`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "data" => Some(SamplerChoice::Data),
            "box" => Some(SamplerChoice::Box),
            "fibonacci" => Some(SamplerChoice::Fibonacci),
            _ => None,
        }
    }
}

/// Every option of a detection, as the CLI's `detect` and the Python
/// package's `detect` take them. Integers are `u64` so that a front end
/// passes what the user wrote and the check here names what is wrong.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectOptions {
    /// Lines or planes.
    pub structure: StructureKind,
    /// α, the ellipsoid's short semi-axis (a radius); `None`: estimated.
    pub alpha: Option<f64>,
    /// λ₂ of planes; `None`: λ₃ when the run is explicit, else estimated.
    pub lambda2: Option<f64>,
    /// λ₃, the long axis; `None`: estimated.
    pub lambda3: Option<f64>,
    /// nb_c, the simplices a piece needs; `None`: estimated.
    pub min_size: Option<u64>,
    /// The orientations; `None`: the box sampler for an explicit run, the
    /// data's otherwise.
    pub sampler: Option<SamplerChoice>,
    /// Box sampler: grid spacing on the box faces (default 0.3).
    pub m1: f64,
    /// Turns about a plane's normal when λ₂ ≠ λ₃ (box and data
    /// orientations; default 12).
    pub m2: u64,
    /// Fibonacci sampler: angular step in degrees (default 10).
    pub step: f64,
    /// The significance test's ε (default 1: at most one false alarm
    /// expected); `None`: no test, nb_c alone (the paper).
    pub epsilon: Option<f64>,
    /// Triangulate in tiles of this side with halos (same result, bounded
    /// memory); `None`: whole.
    pub tile: Option<f64>,
}

impl DetectOptions {
    /// The defaults for `structure`: every parameter estimated, the data's
    /// orientations, the significance test at ε = 1.
    pub fn new(structure: StructureKind) -> Self {
        DetectOptions {
            structure,
            alpha: None,
            lambda2: None,
            lambda3: None,
            min_size: None,
            sampler: None,
            m1: 0.3,
            m2: 12,
            step: 10.0,
            epsilon: Some(1.0),
            tile: None,
        }
    }

    /// Whether alpha, lambda3 and min_size are all given: the paper's run
    /// with explicit parameters.
    pub fn explicit(&self) -> bool {
        self.alpha.is_some() && self.lambda3.is_some() && self.min_size.is_some()
    }

    /// The orientations the run scans (the default resolved).
    pub fn sampler_used(&self) -> SamplerChoice {
        self.sampler.unwrap_or(if self.explicit() {
            SamplerChoice::Box
        } else {
            SamplerChoice::Data
        })
    }

    /// The options that set the orientation count, as the front end spells
    /// them (for an error about too many orientations).
    pub fn orientation_flags(&self, style: Style) -> String {
        match self.sampler_used() {
            SamplerChoice::Fibonacci => format!("{} {}", style.name("step"), self.step),
            _ => format!(
                "{} {} {} {}",
                style.name("m1"),
                self.m1,
                style.name("m2"),
                self.m2
            ),
        }
    }

    /// Checks every option; the error names the first bad one as `style`
    /// spells it.
    ///
    /// # Errors
    /// [`DetectError::BadParameter`].
    pub fn check(&self, style: Style) -> Result<(), DetectError> {
        let bad = |name: &str, what: String| {
            Err(DetectError::BadParameter(format!(
                "{} {what}",
                style.name(name)
            )))
        };
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                bad(name, format!("must be positive and finite, got {v}"))
            }
        };
        if let Some(a) = self.alpha {
            positive("alpha", a)?;
        }
        if self.structure == StructureKind::Lines && self.lambda2.is_some() {
            return bad(
                "lambda2",
                "is a parameter of planes (lines use lambda3 only)".into(),
            );
        }
        for (name, l) in [("lambda2", self.lambda2), ("lambda3", self.lambda3)] {
            if let Some(l) = l {
                if !(l.is_finite() && (LAMBDA_RANGE.0..=LAMBDA_RANGE.1).contains(&l)) {
                    return bad(
                        name,
                        format!(
                            "must be between {} and {}, got {l}",
                            LAMBDA_RANGE.0, LAMBDA_RANGE.1
                        ),
                    );
                }
            }
        }
        if let Some(m) = self.min_size {
            if m == 0 || m > u64::from(u32::MAX) {
                return bad(
                    "min_size",
                    format!("must be between 1 and {}, got {m}", u32::MAX),
                );
            }
        }
        positive("m1", self.m1)?;
        if self.m2 == 0 || self.m2 > u64::from(u32::MAX) {
            return bad(
                "m2",
                format!("must be between 1 and {}, got {}", u32::MAX, self.m2),
            );
        }
        positive("step", self.step)?;
        if let Some(e) = self.epsilon {
            positive("epsilon", e)?;
        }
        if let Some(t) = self.tile {
            positive("tile", t)?;
        }
        Ok(())
    }

    /// The checked options as a detector for `points` (and their
    /// `normals`, one per point, when given; lines ignore them).
    ///
    /// # Errors
    /// A bad option ([`Self::check`]); for an estimated run, empty input,
    /// non-finite or out-of-range coordinates, a number of normals other
    /// than of points.
    pub fn build(
        &self,
        points: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
        style: Style,
    ) -> Result<Detector, DetectError> {
        self.check(style)?;
        // In range after `check`.
        let m2 = self.m2 as u32;
        let min_size = self.min_size.map(|m| m as u32);
        let box_sampler = Sampler::Box { m1: self.m1, m2 };
        let fibonacci = Sampler::Fibonacci {
            step_degrees: self.step,
        };
        let normals = normals.filter(|_| self.structure == StructureKind::Planes);
        let d = match (self.alpha, self.lambda3, min_size) {
            (Some(alpha), Some(lambda3), Some(nb_c)) => {
                let d = match self.structure {
                    StructureKind::Lines => Detector::lines(alpha, lambda3, nb_c),
                    StructureKind::Planes => {
                        Detector::planes(alpha, self.lambda2.unwrap_or(lambda3), lambda3, nb_c)
                    }
                };
                let d = match self.sampler_used() {
                    SamplerChoice::Box => d.sampler(box_sampler),
                    SamplerChoice::Fibonacci => d.sampler(fibonacci),
                    SamplerChoice::Data => d.data_orientations(points, m2),
                };
                match normals {
                    Some(n) => d.normals(n),
                    None => d,
                }
            }
            _ => {
                let given = Given {
                    alpha: self.alpha,
                    lambda2: self.lambda2,
                    lambda3: self.lambda3,
                    min_size,
                };
                let d = match normals {
                    Some(n) => Detector::auto_oriented(self.structure, points, n, &given, m2)?,
                    None => Detector::auto_with(self.structure, points, &given, m2)?,
                };
                match self.sampler_used() {
                    SamplerChoice::Data => d,
                    SamplerChoice::Box => d.sampler(box_sampler),
                    SamplerChoice::Fibonacci => d.sampler(fibonacci),
                }
            }
        };
        Ok(d.significance(self.epsilon).tile(self.tile))
    }

    /// [`Self::build`] for one region of a region run
    /// (`detect::regions`): the detector of a cloud's points `ids`
    /// (`sub`: their coordinates), with those points' normals when the
    /// cloud has `normals`.
    ///
    /// # Errors
    /// As [`Self::build`].
    pub fn build_region(
        &self,
        ids: &[u32],
        sub: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
        style: Style,
    ) -> Result<Detector, DetectError> {
        let nsub: Option<Vec<[f64; 3]>> =
            normals.map(|n| ids.iter().map(|&i| n[i as usize]).collect());
        self.build(sub, nsub.as_deref(), style)
    }
}

/// The warnings a front end gives before running `detector` on `points`
/// points with `threads` threads: normals given but not used, and a run
/// of more than [`HUGE_RUN`] point insertions (its options named as
/// `style` spells them).
pub fn run_warnings(
    options: &DetectOptions,
    detector: &Detector,
    points: usize,
    threads: usize,
    style: Style,
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(g) = detector.given_normals().filter(|g| !g.in_full()) {
        let lead = match g.explained {
            Some(_) => "the input's normals do worse than normals estimated from the points",
            None => "the input's normals disagree with its points",
        };
        out.push(format!("{lead}: {}", g.ignored_reason()));
    }
    if let Some((e, m)) = detector
        .estimate()
        .filter(|e| !e.normals_spread())
        .and_then(|e| e.ladder_declined.map(|m| (e, m)))
    {
        let cover = e.modes.iter().filter(|m| m.cover).count();
        let instead = match e.kind {
            crate::detect::StructureKind::Planes => format!(
                "the modes were scanned instead, with {cover} direction(s) {}° apart covering the \
                 normals of the points no mode scans",
                crate::detect::estimate::COVER_STEP_DEG
            ),
            crate::detect::StructureKind::Lines => "the modes were scanned instead".to_string(),
        };
        out.push(format!(
            "the modes of the cloud explain {:.0}% of {} (under half; {:.0}% look locally {}), \
             which calls for the scale ladder of sparse structures, but the scale ladder scans at \
             most {} points (it triangulates them once per rotation of its sampler) and {m} would \
             take it: {instead}; {}, {} and {} give the paper's sampled scan",
            100.0 * e.explained,
            e.kind.counted_points(),
            100.0 * e.structured,
            e.kind.locally(),
            crate::detect::estimate::LADDER_MAX_POINTS,
            style.name("alpha"),
            style.name("lambda3"),
            style.name("min_size"),
        ));
    }
    if let Some(e) = detector
        .estimate()
        .filter(|e| e.ladder_declined.is_none() || e.normals_spread())
    {
        let cover = e.modes.iter().filter(|m| m.cover).count();
        if cover > 0 {
            out.push(format!(
                "the modes of the local normals explain {:.0}% of the points though {:.0}% look \
                 locally planar: the normals spread without peaks (many facets, or a curved \
                 surface), so {cover} direction(s) {}° apart cover the normals no mode scans; on a \
                 curved surface their parts are planar patches",
                100.0 * e.explained,
                100.0 * e.structured,
                crate::detect::estimate::COVER_STEP_DEG,
            ));
        }
    }
    let orientations = detector.orientation_count().unwrap_or(0);
    let work = points as f64 * orientations as f64;
    if work > HUGE_RUN {
        let threads = threads.max(1) as f64;
        let hours = work * 1e-6 / threads / 3600.0;
        out.push(format!(
            "a large run: {points} points × {orientations} orientations = {work:.2e} point \
             insertions, very roughly {hours:.1} hour(s) on {threads} thread(s); fewer orientations \
             ({}) or fewer points make it shorter",
            match options.sampler_used() {
                SamplerChoice::Fibonacci => style.name("step"),
                _ => format!("{}, {}", style.name("m1"), style.name("m2")),
            }
        ));
    }
    out
}

/// The warnings of a region run: regions whose detector did not use the
/// normals given with the points.
pub fn region_warnings(run: &crate::detect::regions::RegionRun) -> Vec<String> {
    let mut out = Vec::new();
    if run.normals_ignored > 0 {
        out.push(format!(
            "the input's normals disagree with its points in {} of {} region(s): fewer than half of \
             a region's locally planar points have their given normal within 25 degrees of their \
             neighbourhood's (normals estimated there instead), or the orientation modes of the \
             given normals explain less of the region than those of normals estimated from its \
             points (the orientations come from the estimated normals there)",
            run.normals_ignored, run.regions
        ));
    }
    out
}

/// Point insertions (points × orientations) above which a run is
/// announced as long: at roughly a microsecond each, about half an hour
/// of one core.
pub const HUGE_RUN: f64 = 2e9;

#[cfg(test)]
mod tests {
    use super::*;

    fn msg(o: DetectOptions, style: Style) -> String {
        o.check(style).unwrap_err().to_string()
    }

    #[test]
    fn errors_name_the_option_as_the_front_end_spells_it() {
        let o = DetectOptions {
            min_size: Some(0),
            ..DetectOptions::new(StructureKind::Planes)
        };
        assert!(msg(o, Style::Python).contains("min_size must be"));
        assert!(msg(o, Style::Cli).contains("--min-size must be"));
        let o = DetectOptions {
            lambda2: Some(4.0),
            ..DetectOptions::new(StructureKind::Lines)
        };
        assert!(
            msg(o, Style::Python).starts_with("bad parameter: lambda2 is a parameter of planes")
        );
        let o = DetectOptions {
            epsilon: Some(-1.0),
            ..DetectOptions::new(StructureKind::Lines)
        };
        assert_eq!(
            msg(o, Style::Cli),
            "bad parameter: --epsilon must be positive and finite, got -1"
        );
        for (o, name) in [
            (
                DetectOptions {
                    m2: 0,
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "m2",
            ),
            (
                DetectOptions {
                    m1: f64::NAN,
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "m1",
            ),
            (
                DetectOptions {
                    step: 0.0,
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "step",
            ),
            (
                DetectOptions {
                    tile: Some(0.0),
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "tile",
            ),
            (
                DetectOptions {
                    alpha: Some(-1.0),
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "alpha",
            ),
            (
                DetectOptions {
                    lambda3: Some(1e9),
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "lambda3",
            ),
            (
                DetectOptions {
                    min_size: Some(1 << 33),
                    ..DetectOptions::new(StructureKind::Planes)
                },
                "min_size",
            ),
        ] {
            assert!(
                msg(o, Style::Python).starts_with(&format!("bad parameter: {name} ")),
                "{name}: {}",
                msg(o, Style::Python)
            );
        }
    }

    #[test]
    fn explicit_run_is_the_papers_and_defaults_resolve() {
        let scene = crate::synth::lines(1);
        let o = DetectOptions {
            alpha: Some(1.0),
            lambda3: Some(10.0),
            min_size: Some(4),
            ..DetectOptions::new(StructureKind::Lines)
        };
        assert_eq!(o.sampler_used(), SamplerChoice::Box);
        let d = o.build(&scene.points, None, Style::Cli).unwrap();
        let paper = Detector::lines(1.0, 10.0, 4);
        assert_eq!(d.orientations(), paper.orientations());
        assert_eq!(
            d.run(&scene.points).unwrap().labels,
            paper.run(&scene.points).unwrap().labels
        );
        let auto = DetectOptions::new(StructureKind::Lines);
        assert_eq!(auto.sampler_used(), SamplerChoice::Data);
        assert_eq!(auto.orientation_flags(Style::Cli), "--m1 0.3 --m2 12");
        let fib = DetectOptions {
            sampler: Some(SamplerChoice::Fibonacci),
            ..auto
        };
        assert_eq!(fib.orientation_flags(Style::Python), "step 10");
        let d = fib.build(&scene.points, None, Style::Python).unwrap();
        assert!(matches!(
            d.orientations(),
            crate::detect::OrientationSet::Sampler(Sampler::Fibonacci { .. })
        ));
        let d = DetectOptions {
            epsilon: None,
            ..auto
        }
        .build(&scene.points, None, Style::Python)
        .unwrap();
        assert_eq!(d.epsilon(), None);
    }
}
