//! Ground-truth scene files (the writers of [`crate::synth`]'s scenes).

use std::io::{self, Write};
use std::path::Path;

use super::{atomic_write, IoError};
use crate::synth::Scene;

/// Writes one line `x y z label` per point (shortest round-trip decimal
/// form of each coordinate), after a `#` comment line naming the columns.
///
/// ```
/// use aniso_alpha::io::write_xyz_labels;
/// use aniso_alpha::synth::SceneOptions;
/// let scene = SceneOptions::lines().seed(3).generate().unwrap();
/// let mut out = Vec::new();
/// write_xyz_labels(&scene, &mut out).unwrap();
/// assert!(out.starts_with(b"# x y z label\n"));
/// ```
pub fn write_xyz_labels(scene: &Scene, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "# x y z label")?;
    for (p, l) in scene.points.iter().zip(&scene.labels) {
        writeln!(out, "{} {} {} {}", p[0], p[1], p[2], l)?;
    }
    Ok(())
}

/// Writes one line `x y z label part` per point (see [`write_xyz_labels`]).
pub fn write_xyz_labels_parts(scene: &Scene, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "# x y z label part")?;
    for ((p, l), q) in scene.points.iter().zip(&scene.labels).zip(&scene.parts) {
        writeln!(out, "{} {} {} {} {}", p[0], p[1], p[2], l, q)?;
    }
    Ok(())
}

/// Writes `scene` to `path` atomically: `x y z label`, plus the `part`
/// column when `parts` is set.
pub fn write_scene(path: &Path, scene: &Scene, parts: bool) -> Result<(), IoError> {
    atomic_write(path, |w| {
        let mut w = io::BufWriter::new(w);
        if parts {
            write_xyz_labels_parts(scene, &mut w)?;
        } else {
            write_xyz_labels(scene, &mut w)?;
        }
        w.flush()
    })
}
