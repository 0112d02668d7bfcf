//! The run-wide modes of a detection, decided once per run from the
//! detector's parameters ([`super::Detector::regime`]): which structures
//! are sought, whether the significance test runs, whether the
//! orientations come from a sampler (over every point) or from the data's
//! modes (each over its own points), and whether normals given with the
//! points gate the claims of planes. The scan and the assembly ask the
//! regime what to do instead of testing these flags themselves, so that a
//! mode is decided in one place.

use super::detector::Normals;
use super::StructureKind;

/// The modes of one run (module doc).
#[derive(Debug, Clone)]
pub(crate) struct Regime {
    kind: StructureKind,
    log10_epsilon: Option<f64>,
    from_data: bool,
    gate: Option<Normals>,
}

impl Regime {
    /// The regime of a run looking for `kind`, with the significance
    /// test's ε (`None`: no test), orientations from the data or not, and
    /// the normals that gate the claims of planes (unit, zero where
    /// missing; ignored for lines).
    pub(crate) fn new(
        kind: StructureKind,
        epsilon: Option<f64>,
        from_data: bool,
        normals: Option<Normals>,
    ) -> Self {
        Regime {
            kind,
            log10_epsilon: epsilon.map(f64::log10),
            from_data,
            gate: normals.filter(|_| kind == StructureKind::Planes),
        }
    }

    /// Lines or planes.
    pub(crate) fn kind(&self) -> StructureKind {
        self.kind
    }

    /// log₁₀ ε of the significance test, or `None` without the test.
    pub(crate) fn significance(&self) -> Option<f64> {
        self.log10_epsilon
    }

    /// Whether line parts lying inside a surface are dropped
    /// (`assemble::embedded`): lines with the data's orientations, the
    /// automatic mode for real scans, whose scanners sample surfaces in
    /// rows. With the user's scale and a sampler (the paper's runs) a row
    /// of points is a line: three parallel lines in a plane, the paper's
    /// Fig. 12, are three lines.
    pub(crate) fn drops_lines_inside_surfaces(&self) -> bool {
        self.kind == StructureKind::Lines && self.from_data
    }

    /// Whether parts must have their shape's proportions at the scale of
    /// their ellipsoid (`assemble::proportions`): with the data's
    /// orientations, the automatic mode for real scans, whose dense
    /// surfaces hold wires and the sides of poles as strips a few points
    /// across. With a sampler (the user's scale, or the scale ladder of
    /// the paper's sparse scenes) a part of a few dozen points is judged
    /// by the significance test alone: the smallest faces of the paper's
    /// polyhedron are about four rows across, at the rule's threshold.
    pub(crate) fn checks_proportions(&self) -> bool {
        self.from_data
    }

    /// Whether every orientation looks at every point (a sampler's or
    /// explicit rotations), so that the pruning's candidate pairs can be
    /// found once for all of them; the data's modes each look at their
    /// own points.
    pub(crate) fn scans_every_point(&self) -> bool {
        !self.from_data
    }

    /// Whether short pieces of lines are kept for the significance test to
    /// judge: lines under the test. The scan's path filter then keeps
    /// paths shorter than nb_c (its threshold measured from the
    /// background, `scan::ScanFilter`) and the candidates start from them;
    /// their claims join the pieces along their fitted line (docs/method.md
    /// §4).
    pub(crate) fn keeps_short_lines(&self) -> bool {
        self.kind == StructureKind::Lines && self.log10_epsilon.is_some()
    }

    /// Whether the scan's path filter follows straight chains through
    /// ramifications (`scan::straight_filter`): short lines, whatever the
    /// orientations. A thin cable sampled densely (points closer than its
    /// width and noise) makes a web of edges at its α, which the paper's
    /// filter deletes whole (the simulated street's cables: 5% of their
    /// points found). The scanner rows that straight chains also follow
    /// across surfaces are the assembly's to drop (lines inside a surface,
    /// docs/method.md §4).
    pub(crate) fn follows_straight_chains(&self) -> bool {
        self.keeps_short_lines()
    }

    /// Whether a candidate's claim radius may widen with its noise (the
    /// radius among a few multiples of τ whose tube or slab makes it least
    /// explicable by chance): under the significance test, for lines, and
    /// for planes with the data's orientations, whose α is the median
    /// noise of the cloud (a plane noisier than that needs a wider slab).
    pub(crate) fn widens_claims(&self) -> bool {
        self.log10_epsilon.is_some() && (self.kind == StructureKind::Lines || self.from_data)
    }

    /// The normals that gate the claims of planes (a point claims a plane
    /// only if its normal agrees with the plane's), if any.
    pub(crate) fn claim_normals(&self) -> Option<&[[f32; 3]]> {
        self.gate.as_deref()
    }

    /// The same regime over the points `ids` of this one's cloud (their
    /// normals, in that order).
    pub(crate) fn on(&self, ids: &[u32]) -> Regime {
        Regime {
            gate: self
                .gate
                .as_ref()
                .map(|n| ids.iter().map(|&i| n[i as usize]).collect()),
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mode_answers_from_the_parameters() {
        let n: Normals = vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0; 3]].into();
        let lines = Regime::new(StructureKind::Lines, Some(1.0), false, Some(n.clone()));
        assert_eq!(lines.significance(), Some(0.0));
        assert!(lines.keeps_short_lines() && lines.follows_straight_chains());
        assert!(lines.widens_claims() && lines.scans_every_point());
        // Lines ignore normals.
        assert!(lines.claim_normals().is_none());
        let data_lines = Regime::new(StructureKind::Lines, Some(1.0), true, None);
        assert!(data_lines.keeps_short_lines() && data_lines.follows_straight_chains());
        assert!(data_lines.drops_lines_inside_surfaces() && !lines.drops_lines_inside_surfaces());
        assert!(!data_lines.scans_every_point());
        let paper = Regime::new(StructureKind::Lines, None, false, None);
        assert!(!paper.keeps_short_lines() && !paper.widens_claims());
        let planes = Regime::new(StructureKind::Planes, Some(1.0), false, Some(n));
        assert!(!planes.keeps_short_lines() && !planes.widens_claims());
        assert_eq!(planes.claim_normals().map(<[_]>::len), Some(3));
        let data_planes = Regime::new(StructureKind::Planes, Some(1.0), true, None);
        assert!(data_planes.widens_claims());
        // A subset carries its points' normals.
        let sub = planes.on(&[2, 0]);
        assert_eq!(sub.claim_normals(), Some(&[[0.0; 3], [0.0, 0.0, 1.0]][..]));
    }
}
