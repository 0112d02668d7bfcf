//! Wavefront OBJ writer.

use std::path::Path;

use super::{atomic_write, IoError, Mesh};

/// Writes `mesh` as Wavefront OBJ, atomically: `v x y z` lines, then `f`
/// lines for the triangles and `l` lines for the edges (1-based indices, as
/// OBJ wants). Labels are not written.
///
/// ```
/// use aniso_alpha::io::{write_obj, Mesh};
/// let path = std::env::temp_dir().join(format!("doc-{}.obj", std::process::id()));
/// let pts = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
/// write_obj(&path, &Mesh { faces: &[[0, 1, 2]], edges: &[[0, 1]], ..Mesh::new(&pts) }).unwrap();
/// let text = std::fs::read_to_string(&path).unwrap();
/// assert!(text.ends_with("v 0 1 0\nf 1 2 3\nl 1 2\n"));
/// # std::fs::remove_file(&path).unwrap();
/// ```
pub fn write_obj(path: &Path, mesh: &Mesh<'_>) -> Result<(), IoError> {
    atomic_write(path, |w| {
        let mesh = Mesh {
            labels: None,
            parts: None,
            element_labels: &[],
            ..*mesh
        };
        mesh.validate()?;
        w.write_all(b"# written by aniso-alpha\n")?;
        for p in mesh.points {
            writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
        }
        for f in mesh.faces {
            writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
        }
        for e in mesh.edges {
            writeln!(w, "l {} {}", e[0] + 1, e[1] + 1)?;
        }
        Ok(())
    })
}
