//! The input cloud written back with two added per-point fields, the
//! structure id and the part id of a detection ([`write_labelled_cloud`]).
//!
//! - LAS/LAZ from a LAS/LAZ input: every point record copied byte for byte
//!   with 8 bytes appended (two `i32` extra bytes, `structure` and `part`,
//!   described in the Extra Bytes VLR, record id 4 of `LASF_Spec`); the
//!   header's record length, VLR count, point data offset and the offsets
//!   of what follows the points adjusted; every other VLR and extended
//!   VLR kept (a LAZ input's laszip VLR replaced). Only the classification
//!   changes, and only with [`Labelled::classify`].
//! - LAS/LAZ from any other input: a LAS 1.2 file of point format 0, the
//!   coordinates quantised to one power-of-ten scale fine enough for the
//!   extent to fit 32-bit integers, every attribute as a typed extra-bytes
//!   field, then `structure` and `part`.
//! - PLY: every point with its attributes (a LAS input's fields under
//!   laspy's names; its 16-bit colours as `uchar`, divided by 257 when any
//!   exceeds 255), `int structure`, `int part`, and the meshes.

use std::path::Path;

#[cfg(feature = "las")]
use super::atomic_write;
use super::attributes::{Attribute, Values};
use super::{IoError, Mesh, PlyEncoding, PointCloud};

/// What [`write_labelled_cloud`] adds to a cloud.
#[derive(Debug, Clone, Copy)]
pub struct Labelled<'a> {
    /// One structure id per point, −1 for background.
    pub structure: &'a [i64],
    /// One part id per point, −1 for background.
    pub part: &'a [i64],
    /// PLY only: edges between points (element `edge`).
    pub edges: &'a [[u32; 2]],
    /// PLY only: triangles (element `face`).
    pub faces: &'a [[u32; 3]],
    /// PLY only: (structure, part) of each edge, then each face; empty or
    /// one per edge and face.
    pub element_labels: &'a [[i64; 2]],
    /// The LAS classification given to every point of a structure
    /// (structure ≥ 0); LAS/LAZ, and a PLY's `classification` property
    /// (added when missing).
    pub classify: Option<u8>,
}

impl<'a> Labelled<'a> {
    /// Structure and part ids alone: no mesh, no classification.
    pub fn new(structure: &'a [i64], part: &'a [i64]) -> Self {
        Labelled {
            structure,
            part,
            edges: &[],
            faces: &[],
            element_labels: &[],
            classify: None,
        }
    }
}

/// The names the added fields take; an input attribute of the same name
/// is kept as `input_structure` / `input_part`.
const ADDED: [&str; 2] = ["structure", "part"];

/// Why a cloud with points of NaN coordinates (an organized cloud's
/// pixels without a return) is not written as LAS.
pub const NO_RETURN_IN_LAS: &str = "LAS/LAZ cannot hold points without a return (NaN coordinates \
     of an organized cloud): write the labelled cloud as .ply, which keeps every row";

/// Writes `cloud` with its structure and part ids, atomically, in the
/// format of `path`'s extension: `.las`, `.laz` (cargo feature `las`) or
/// `.ply` (binary). See the module docs for what is kept.
///
/// ```
/// use aniso_alpha::io::{read_points, write_labelled_cloud, Labelled, ReadOptions};
/// let dir = std::env::temp_dir().join(format!("doc-labelled-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let input = dir.join("in.ply");
/// std::fs::write(&input, "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n\
///     property float y\nproperty float z\nproperty uchar red\nend_header\n0 0 0 255\n1 0 0 7\n").unwrap();
/// let opts = ReadOptions { attributes: true, ..ReadOptions::default() };
/// let cloud = read_points(&input, &opts).unwrap();
/// let out = dir.join("out.ply");
/// write_labelled_cloud(&out, &cloud, &Labelled::new(&[0, -1], &[3, -1])).unwrap();
/// let back = read_points(&out, &opts).unwrap();
/// assert_eq!(back.points, cloud.points);
/// let names: Vec<&str> = back.attributes.iter().map(|a| a.name.as_str()).collect();
/// assert_eq!(names, ["structure", "part", "red"]);
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write_labelled_cloud(
    path: &Path,
    cloud: &PointCloud,
    labelled: &Labelled<'_>,
) -> Result<(), IoError> {
    let n = cloud.points.len();
    let invalid = |m: String| IoError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, m),
    };
    if labelled.structure.len() != n || labelled.part.len() != n {
        return Err(invalid(format!(
            "{} structure ids and {} part ids for {n} points",
            labelled.structure.len(),
            labelled.part.len()
        )));
    }
    if let Some(v) = labelled
        .structure
        .iter()
        .chain(labelled.part)
        .find(|v| i32::try_from(**v).is_err())
    {
        return Err(invalid(format!("id {v} does not fit a 32-bit integer")));
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "ply" => write_ply_labelled(path, cloud, labelled),
        "las" | "laz" if !cloud.all_finite() => Err(invalid(NO_RETURN_IN_LAS.into())),
        "las" | "laz" => write_las_labelled(path, cloud, labelled, ext == "laz"),
        _ => Err(IoError::UnknownFormat {
            path: path.to_path_buf(),
            expected: ".ply, .las or .laz",
        }),
    }
}

/// The attributes as PLY vertex properties: names clear of x, y, z and
/// the added fields, a LAS input's colours as `uchar`, the classification
/// set by `classify`.
fn ply_attributes(cloud: &PointCloud, labelled: &Labelled<'_>) -> Vec<Attribute> {
    let mut out: Vec<Attribute> = cloud.attributes.clone();
    let taken: Vec<String> = out.iter().map(|a| a.name.clone()).collect();
    for a in &mut out {
        if ADDED.contains(&a.name.as_str()) || ["x", "y", "z"].contains(&a.name.as_str()) {
            let mut name = format!("input_{}", a.name);
            while taken.contains(&name) {
                name.insert_str(0, "input_");
            }
            a.name = name;
        }
    }
    if cloud.las.is_some() {
        let colour = |a: &Attribute| matches!(a.name.as_str(), "red" | "green" | "blue");
        let wide = out.iter().filter(|a| colour(a)).any(|a| match &a.values {
            Values::U16(v) => v.iter().any(|&c| c > 255),
            _ => false,
        });
        for a in out.iter_mut().filter(|a| colour(a)) {
            if let Values::U16(v) = &a.values {
                let d = if wide { 257 } else { 1 };
                a.values = Values::U8(
                    v.iter()
                        .map(|&c| ((u32::from(c) + d / 2) / d).min(255) as u8)
                        .collect(),
                );
            }
        }
    }
    if let Some(class) = labelled.classify {
        let set = |old: &dyn Fn(usize) -> f64| -> Vec<f64> {
            (0..cloud.points.len())
                .map(|i| {
                    if labelled.structure[i] >= 0 {
                        f64::from(class)
                    } else {
                        old(i)
                    }
                })
                .collect()
        };
        match out.iter_mut().find(|a| a.name == "classification") {
            Some(a) => {
                let old = a.values.clone();
                let mut v = Values::with_capacity(old.ty(), old.len());
                for x in set(&|i| old.get_f64(i)) {
                    v.push_f64(x);
                }
                a.values = v;
            }
            None => out.push(Attribute::new(
                "classification",
                Values::U8(set(&|_| 0.0).into_iter().map(|x| x as u8).collect()),
            )),
        }
    }
    out
}

fn write_ply_labelled(
    path: &Path,
    cloud: &PointCloud,
    labelled: &Labelled<'_>,
) -> Result<(), IoError> {
    let attributes = ply_attributes(cloud, labelled);
    let mesh = Mesh {
        labels: Some(labelled.structure),
        parts: Some(labelled.part),
        attributes: &attributes,
        edges: labelled.edges,
        faces: labelled.faces,
        element_labels: labelled.element_labels,
        ..Mesh::new(&cloud.points)
    };
    super::write_ply(path, &mesh, PlyEncoding::BinaryLittleEndian)
}

#[cfg(not(feature = "las"))]
fn write_las_labelled(
    path: &Path,
    _cloud: &PointCloud,
    _labelled: &Labelled<'_>,
    _laz: bool,
) -> Result<(), IoError> {
    Err(IoError::Unsupported {
        path: path.to_path_buf(),
        message: "LAS/LAZ support is not compiled in (cargo feature `las`)",
    })
}

#[cfg(feature = "las")]
fn write_las_labelled(
    path: &Path,
    cloud: &PointCloud,
    labelled: &Labelled<'_>,
    laz: bool,
) -> Result<(), IoError> {
    let err = |m: String| IoError::Write {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, m),
    };
    let src;
    let src = match &cloud.las {
        Some(s) if s.records.len() == s.record_len * cloud.points.len() => s.as_ref(),
        _ => {
            src = super::las_write::source_from_points(cloud).map_err(err)?;
            &src
        }
    };
    let file = super::las_write::labelled_file(src, labelled, laz).map_err(err)?;
    atomic_write(path, |w| std::io::Write::write_all(w, &file))
}
