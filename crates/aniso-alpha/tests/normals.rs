//! Normals given with the points (a scan's `nx ny nz`): a point joins a
//! plane only if its normal agrees with the plane's (`Detector::normals`,
//! `Detector::auto_oriented`).

use aniso_alpha::rng::SplitMix64;
use aniso_alpha::{DetectError, Detection, Detector, Given, StructureKind};

/// A wall z = 0 (8 m × 8 m, a 0.1 m grid, 5 mm of noise) and, on it, the
/// side faces of a window frame: 120 points at x = 4 ± 0.01, within 1.5 cm
/// of the wall's plane, whose surface faces along x. Returns the points,
/// their normals and whether each is a frame point.
fn wall_with_frame() -> (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<bool>) {
    let mut rng = SplitMix64::new(24);
    let (mut points, mut normals, mut frame) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..80 {
        for j in 0..80 {
            let jitter = |r: &mut SplitMix64| 0.02 * (r.uniform() - 0.5);
            points.push([
                i as f64 * 0.1 + jitter(&mut rng),
                j as f64 * 0.1 + jitter(&mut rng),
                0.01 * (rng.uniform() - 0.5),
            ]);
            normals.push([0.0, 0.0, 1.0]);
            frame.push(false);
        }
    }
    for k in 0..120 {
        let side = if k % 2 == 0 { -0.01 } else { 0.01 };
        points.push([
            4.0 + side,
            1.0 + 6.0 * rng.uniform(),
            0.015 * (rng.uniform() - 0.5),
        ]);
        normals.push([1.0, 0.0, 0.0]);
        frame.push(true);
    }
    (points, normals, frame)
}

/// The part holding most of the wall's points, and how many frame points
/// it holds.
fn frame_points_in_wall(det: &Detection, frame: &[bool]) -> (usize, usize) {
    let parts = det.part_labels();
    let mut count = std::collections::BTreeMap::new();
    for (p, &f) in parts.iter().zip(frame) {
        if !f && *p >= 0 {
            *count.entry(*p).or_insert(0usize) += 1;
        }
    }
    let (&wall, &size) = count.iter().max_by_key(|(_, &c)| c).expect("a wall part");
    let in_wall = parts
        .iter()
        .zip(frame)
        .filter(|(p, &f)| f && **p == wall)
        .count();
    (size, in_wall)
}

#[test]
fn points_whose_normals_cross_a_plane_stay_out_of_it() {
    let (points, normals, frame) = wall_with_frame();
    let given = Given::default();
    let with =
        Detector::auto_oriented(StructureKind::Planes, &points, &normals, &given, 12).unwrap();
    assert_eq!(with.normals_given(), Some(points.len()));
    let det = with.run(&points).unwrap();
    let (wall, frame_in) = frame_points_in_wall(&det, &frame);
    assert!(wall >= 6300, "wall part of {wall} of 6,400 points");
    assert_eq!(frame_in, 0, "frame points in the wall's part");
    // Without the normals the frame's points are within the wall's claim
    // radius and join it: the check above can fail.
    let det = Detector::auto(StructureKind::Planes, &points, &given)
        .unwrap()
        .run(&points)
        .unwrap();
    let (wall, frame_in) = frame_points_in_wall(&det, &frame);
    assert!(wall >= 6300, "wall part of {wall} of 6,400 points");
    assert!(
        frame_in >= 100,
        "only {frame_in} frame points joined the wall"
    );
}

#[test]
fn missing_normals_change_nothing() {
    // Zero or non-finite normals are missing: the run equals the run
    // without normals.
    let (points, _, _) = wall_with_frame();
    let given = Given::default();
    let plain = Detector::auto(StructureKind::Planes, &points, &given)
        .unwrap()
        .run(&points)
        .unwrap();
    let missing: Vec<[f64; 3]> = (0..points.len())
        .map(|i| match i % 3 {
            0 => [0.0; 3],
            1 => [f64::NAN, 0.0, 1.0],
            _ => [0.0, f64::INFINITY, 0.0],
        })
        .collect();
    let d = Detector::auto_oriented(StructureKind::Planes, &points, &missing, &given, 12).unwrap();
    // None usable: none used.
    assert_eq!(d.normals_given(), None);
    assert!(!d.given_normals().unwrap().used);
    assert_eq!(d.run(&points).unwrap(), plain);
}

#[test]
fn lines_ignore_normals() {
    let scene = aniso_alpha::synth::lines(1);
    let normals = vec![[1.0, 0.0, 0.0]; scene.points.len()];
    let d = Detector::lines(1.0, 10.0, 4);
    let plain = d.clone().run(&scene.points).unwrap();
    assert_eq!(d.normals(&normals).run(&scene.points).unwrap(), plain);
}

#[test]
fn a_normal_per_point_or_an_error() {
    let (points, normals, _) = wall_with_frame();
    let given = Given::default();
    let short = &normals[..10];
    assert!(matches!(
        Detector::auto_oriented(StructureKind::Planes, &points, short, &given, 12),
        Err(DetectError::BadParameter(m)) if m.contains("10 normals")
    ));
    let explicit = Detector::planes(0.05, 4.0, 4.0, 20).normals(short);
    assert!(matches!(
        explicit.run(&points),
        Err(DetectError::BadParameter(m)) if m.contains("10 normals")
    ));
}

#[test]
fn copies_keep_their_normals() {
    // The run takes the distinct points (copies get their first
    // occurrence's labels): the normals must follow them. A copy of every
    // fifth point, its normal with it, appended: the frame still stays
    // out of the wall, and every copy is labelled as its original.
    let (mut points, mut normals, mut frame) = wall_with_frame();
    let n = points.len();
    for i in (0..n).step_by(5) {
        points.push(points[i]);
        normals.push(normals[i]);
        frame.push(frame[i]);
    }
    let det = Detector::auto_oriented(
        StructureKind::Planes,
        &points,
        &normals,
        &Given::default(),
        12,
    )
    .unwrap()
    .run(&points)
    .unwrap();
    let (_, frame_in) = frame_points_in_wall(&det, &frame);
    assert_eq!(frame_in, 0);
    let parts = det.part_labels();
    for (k, i) in (0..n).step_by(5).enumerate() {
        assert_eq!(parts[n + k], parts[i]);
    }
}

/// Three perpendicular 6 m walls (a 0.1 m grid, 5 mm of noise) meeting
/// at a corner.
fn corner() -> Vec<[f64; 3]> {
    let mut rng = SplitMix64::new(31);
    let mut points = Vec::new();
    for i in 1..60 {
        for j in 1..60 {
            let (u, v) = (i as f64 * 0.1, j as f64 * 0.1);
            let mut e = || 0.01 * (rng.uniform() - 0.5);
            points.push([u, v, e()]);
            points.push([e(), u, v]);
            points.push([u, e(), v]);
        }
    }
    points
}

#[test]
fn normals_that_disagree_with_the_points_are_ignored() {
    // A placeholder 0 0 1 for every point (a tool's default), and normals
    // shuffled from one point to another: a third or fewer of the planar
    // points agree with their neighbourhood, so the normals are not used
    // and the run is the run without them. The true normals are used.
    let points = corner();
    let given = Given::default();
    let plain = Detector::auto(StructureKind::Planes, &points, &given)
        .unwrap()
        .run(&points)
        .unwrap();
    assert!(plain.num_parts() >= 2);
    let placeholder = vec![[0.0, 0.0, 1.0]; points.len()];
    let truth: Vec<[f64; 3]> = (0..points.len())
        .map(|i| match i % 3 {
            0 => [0.0, 0.0, 1.0],
            1 => [1.0, 0.0, 0.0],
            _ => [0.0, 1.0, 0.0],
        })
        .collect();
    let shuffled: Vec<[f64; 3]> = (0..points.len())
        .map(|i| truth[(i + 1) % points.len()])
        .collect();
    for bad in [&placeholder, &shuffled] {
        let d = Detector::auto_oriented(StructureKind::Planes, &points, bad, &given, 12).unwrap();
        let g = d.given_normals().unwrap();
        assert!(!g.used && g.agreement < 0.5, "{g:?}");
        assert_eq!(d.normals_given(), None);
        assert_eq!(d.run(&points).unwrap(), plain);
    }
    let d = Detector::auto_oriented(StructureKind::Planes, &points, &truth, &given, 12).unwrap();
    let g = d.given_normals().unwrap();
    assert!(g.used && g.agreement > 0.9, "{g:?}");
    assert_eq!(d.normals_given(), Some(points.len()));
    // Normals given to a detector made otherwise ([`Detector::normals`])
    // pass the same check when it runs: the placeholder gates nothing.
    let explicit = Detector::auto(StructureKind::Planes, &points, &given)
        .unwrap()
        .normals(&placeholder);
    assert_eq!(explicit.run(&points).unwrap(), plain);
}

#[test]
fn normals_whose_modes_explain_less_give_the_modes_to_the_estimated_ones() {
    // The corner's true normals, each tilted 10–22° in a random direction
    // (normals over too few neighbours): every one lies within 25° of its
    // wall's, so they pass the agreement check, but they scatter the
    // walls' peaks. Their modes explain less of the cloud than those of
    // the estimated normals, so the orientations come from the latter,
    // and the three walls are found as without normals; the given normals
    // (all within the 36.9° gate) still gate the claims.
    let points = corner();
    let given = Given::default();
    let plain = Detector::auto(StructureKind::Planes, &points, &given).unwrap();
    let plain_run = plain.run(&points).unwrap();
    let mut rng = SplitMix64::new(5);
    let tilted: Vec<[f64; 3]> = (0..points.len())
        .map(|i| {
            let tilt = (10.0 + 12.0 * rng.uniform()).to_radians();
            let turn = std::f64::consts::TAU * rng.uniform();
            let (a, b) = (tilt.sin() * turn.cos(), tilt.sin() * turn.sin());
            match i % 3 {
                0 => [a, b, tilt.cos()],
                1 => [tilt.cos(), a, b],
                _ => [a, tilt.cos(), b],
            }
        })
        .collect();
    let d = Detector::auto_oriented(StructureKind::Planes, &points, &tilted, &given, 12).unwrap();
    let g = d.given_normals().unwrap();
    let (from_given, from_own) = g.explained.expect("the modes were compared");
    assert!(g.agreement > 0.5 && from_given < from_own, "{g:?}");
    assert!(!g.used && g.gate && !g.ignored(), "{g:?}");
    assert!(g
        .ignored_reason()
        .contains("orientations come from the estimated normals"));
    assert_eq!(d.normals_given(), Some(points.len()));
    let axes = |d: &Detector| match d.orientations() {
        aniso_alpha::detect::OrientationSet::Data(m) => {
            m.iter().map(|m| m.axis).collect::<Vec<_>>()
        }
        other => panic!("{other:?}"),
    };
    assert_eq!(axes(&d), axes(&plain));
    let run = d.run(&points).unwrap();
    let wall_share = |det: &Detection| {
        let labels = det.part_labels();
        (0..3)
            .map(|w| {
                let mut count = std::collections::BTreeMap::new();
                for i in (w..points.len()).step_by(3) {
                    *count.entry(labels[i]).or_insert(0usize) += 1;
                }
                let best = count
                    .iter()
                    .filter(|(p, _)| **p >= 0)
                    .map(|(_, c)| *c)
                    .max();
                best.unwrap_or(0) as f64 / (points.len() / 3) as f64
            })
            .fold(1.0, f64::min)
    };
    assert!(wall_share(&plain_run) > 0.9, "{}", wall_share(&plain_run));
    assert!(wall_share(&run) > 0.9, "{}", wall_share(&run));
    // The warning both front ends print says so.
    let warnings = aniso_alpha::options::run_warnings(
        &aniso_alpha::options::DetectOptions::new(StructureKind::Planes),
        &d,
        points.len(),
        1,
        aniso_alpha::options::Style::Cli,
    );
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("do worse than normals estimated")),
        "{warnings:?}"
    );
}
