//! Reading point clouds and writing results.
//!
//! Readers pick the format from the file extension (case-insensitive):
//!
//! | extension | format |
//! |---|---|
//! | `.xyz` `.txt` `.csv` `.pts` | text: x y z in the first three columns, whitespace or commas, `#` comments, one optional header line (or the point count line of `.pts`) |
//! | `.ply` | PLY ascii, binary little- or big-endian; x/y/z of any scalar type |
//! | `.las` `.laz` | LAS/LAZ with scale and offset applied (cargo feature `las`) |
//! | `.pcd` | PCD ascii, binary and binary_compressed |
//! | `.e57` | E57, every scan, each moved by its pose (cargo feature `e57`) |
//!
//! Point `i` of a [`PointCloud`] is the `i`-th point of the file. Every
//! error is an [`IoError`] that names the file (and, for text, the line);
//! no input makes a reader panic.
//!
//! Every output goes through [`atomic_write`], so it is written completely
//! or not at all.
//!
//! ```
//! use aniso_alpha::io::{read_points_bytes, ReadOptions};
//! use std::path::Path;
//! let scene = b"# x y z label\n0 0 0 -1\n1 0 0 2\n2 0 0 2\n";
//! let cloud = read_points_bytes(Path::new("scene.xyz"), scene, &ReadOptions::with_labels(3)).unwrap();
//! assert_eq!(cloud.points[1], [1.0, 0.0, 0.0]);
//! assert_eq!(cloud.labels, Some(vec![-1, 2, 2]));
//! ```

mod atomic;
mod attributes;
#[cfg(feature = "e57")]
mod e57;
mod error;
mod labelled;
mod labels;
#[cfg(feature = "las")]
mod las;
#[cfg(feature = "las")]
mod las_attrs;
#[cfg(feature = "las")]
mod las_bytes;
#[cfg(feature = "las")]
mod las_write;
mod lzf;
mod obj;
mod pcd;
mod ply;
mod scene;
mod text;

use std::fs::File;
use std::io::Read;
use std::path::Path;

pub use atomic::{
    atomic_write, check_output_path, output_key, remove_temp_files, resolve_output, same_file,
    AtomicWriter, ScratchFolder,
};
pub use attributes::{Attribute, AttributeType, LasSource, Values, Vlr};
pub use error::IoError;
pub use labelled::{write_labelled_cloud, Labelled, NO_RETURN_IN_LAS};
pub use labels::{read_labels, read_labels_bytes, write_labels};
#[cfg(feature = "las")]
pub use las_write::LasLabelWriter;
pub use obj::write_obj;
pub use ply::{write_ply, write_ply_to, Mesh, PlyEncoding};
pub use scene::{write_scene, write_xyz_labels, write_xyz_labels_parts};

/// A point cloud read from a file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointCloud {
    /// The points, in file order.
    pub points: Vec<[f64; 3]>,
    /// One label per point, when asked for and present (see
    /// [`ReadOptions`]); -1 conventionally means background.
    pub labels: Option<Vec<i64>>,
    /// Every other per-point property of the file, typed as in the file
    /// (colours, normals, intensity, classification, GPS time, any PLY
    /// vertex property, PCD field, LAS record field or extra bytes), when
    /// asked for with [`ReadOptions::attributes`]; empty otherwise.
    pub attributes: Vec<Attribute>,
    /// For a LAS/LAZ file read with [`ReadOptions::attributes`]: its
    /// header, VLRs and point records as in the file, so that a LAS output
    /// keeps every record byte for byte ([`write_labelled_cloud`]).
    pub las: Option<Box<LasSource>>,
    /// What the reader guessed and the user should hear about (e.g. a
    /// first line taken as a header); the CLI prints them.
    pub warnings: Vec<ReadWarning>,
}

/// Something a reader guessed: the file was read, but perhaps not as meant.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ReadWarning {
    /// A text file's first content line was skipped as a header.
    HeaderLine {
        /// 1-based line number.
        line: usize,
        /// The line (shortened).
        text: String,
    },
    /// Points of the file were not read (E57 points whose coordinates
    /// are flagged invalid).
    SkippedPoints {
        /// How many.
        count: u64,
        /// Why.
        reason: &'static str,
    },
    /// An organized PCD cloud (HEIGHT > 1, a depth image's pixels) holds
    /// pixels without a return, as PCL writes them: points of NaN
    /// coordinates. They are kept, so that row i is still the file's
    /// point i ([`PointCloud::finite_rows`] gives the others); `detect`
    /// labels them -1.
    NoReturn {
        /// Points without a return.
        count: u64,
        /// Points in the file.
        of: u64,
    },
}

impl std::fmt::Display for ReadWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadWarning::HeaderLine { line, text } => {
                write!(f, "line {line} taken as a header: '{text}'")
            }
            ReadWarning::SkippedPoints { count, reason } => {
                write!(f, "{count} points skipped: {reason}")
            }
            ReadWarning::NoReturn { count, of } => write!(
                f,
                "{count} of {of} points of the organized cloud have no return (NaN coordinates)"
            ),
        }
    }
}

/// Names under which files store per-point normals, as (x, y, z)
/// attribute names: PLY's `nx ny nz` (CGAL, Open3D, PCL's PLY writer,
/// CloudCompare) and PCD's `normal_x normal_y normal_z` (PCL).
pub const NORMAL_NAMES: [[&str; 3]; 2] = [["nx", "ny", "nz"], ["normal_x", "normal_y", "normal_z"]];

impl PointCloud {
    /// The rows whose three coordinates are finite, when some are not
    /// (an organized PCD cloud's pixels without a return,
    /// [`ReadWarning::NoReturn`]); `None` when every point is finite, as
    /// every other reader guarantees.
    pub fn finite_rows(&self) -> Option<Vec<u32>> {
        if self.all_finite() {
            return None;
        }
        Some(
            (0u32..)
                .zip(&self.points)
                .filter(|(_, p)| is_finite(p))
                .map(|(i, _)| i)
                .collect(),
        )
    }

    /// Whether every point's three coordinates are finite (always, but
    /// for an organized PCD cloud's pixels without a return).
    pub fn all_finite(&self) -> bool {
        self.points.iter().all(is_finite)
    }

    /// The cloud of the points at `rows` (ascending), with their labels
    /// and attributes; no LAS source (its records are the whole file's)
    /// and no warnings.
    pub fn select(&self, rows: &[u32]) -> PointCloud {
        PointCloud {
            points: rows.iter().map(|&i| self.points[i as usize]).collect(),
            labels: self
                .labels
                .as_ref()
                .map(|l| rows.iter().map(|&i| l[i as usize]).collect()),
            attributes: self
                .attributes
                .iter()
                .map(|a| Attribute::new(a.name.clone(), a.values.select(rows)))
                .collect(),
            las: None,
            warnings: Vec::new(),
        }
    }

    /// The points' normals, when the file gives them and they were read
    /// with [`ReadOptions::attributes`]: the attributes named as in
    /// [`NORMAL_NAMES`] (case-insensitive), as read (not normalised; a
    /// file's 0 0 0 for "unknown" stays zero).
    pub fn normals(&self) -> Option<Vec<[f64; 3]>> {
        let column = |name: &str| {
            self.attributes
                .iter()
                .find(|a| a.name.eq_ignore_ascii_case(name))
                .filter(|a| a.values.len() == self.points.len())
        };
        NORMAL_NAMES.iter().find_map(|[x, y, z]| {
            let (x, y, z) = (column(x)?, column(y)?, column(z)?);
            Some(
                (0..self.points.len())
                    .map(|i| {
                        [
                            x.values.get_f64(i),
                            y.values.get_f64(i),
                            z.values.get_f64(i),
                        ]
                    })
                    .collect(),
            )
        })
    }
}

/// How to read a point file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadOptions {
    /// Text formats: 0-based column holding an integer label (`Some(3)` for
    /// `x y z label` ground-truth files). Every data line must have it.
    pub label_column: Option<usize>,
    /// Binary formats: read labels when the file carries them: the PLY
    /// vertex property `structure` or `label`, the PCD field `label`, the
    /// LAS classification. Absent properties give `labels: None`.
    pub read_labels: bool,
    /// The format, overriding the file's extension (`None`: by extension;
    /// standard input, `-`, is text unless given).
    pub format: Option<Format>,
    /// LAS classes read as background (-1) when the classification gives
    /// the labels; by default 0 and 1 (never classified, unclassified), 7
    /// (low noise) and 18 (high noise), see [`ClassSet::LAS_BACKGROUND`].
    pub background_classes: ClassSet,
    /// Keep every per-point attribute of the file in
    /// [`PointCloud::attributes`] (PLY, PCD, LAS/LAZ, E57), and a LAS
    /// file's records in [`PointCloud::las`]. Off, a reader decodes x, y,
    /// z (and the labels) only, as fast as before.
    pub attributes: bool,
}

/// A set of LAS classification codes (0–255).
///
/// ```
/// use aniso_alpha::io::ClassSet;
/// let s = ClassSet::from_classes(&[7, 18]);
/// assert!(s.contains(18) && !s.contains(1));
/// assert!(ClassSet::default().contains(1));
/// assert_eq!(ClassSet::default(), ClassSet::LAS_BACKGROUND);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClassSet([u64; 4]);

impl ClassSet {
    /// No class.
    pub const EMPTY: ClassSet = ClassSet([0; 4]);
    /// The classes that are not structures when a LAS classification is
    /// used as truth: 0 (created, never classified), 1 (unclassified), 7
    /// (low point, noise) and 18 (high noise).
    pub const LAS_BACKGROUND: ClassSet = ClassSet([1 | 1 << 1 | 1 << 7 | 1 << 18, 0, 0, 0]);

    /// The set of these classes.
    pub fn from_classes(classes: &[u8]) -> ClassSet {
        let mut s = ClassSet::EMPTY;
        for &c in classes {
            s.0[usize::from(c / 64)] |= 1 << (c % 64);
        }
        s
    }

    /// Whether `class` is in the set.
    pub fn contains(&self, class: u8) -> bool {
        self.0[usize::from(class / 64)] >> (class % 64) & 1 == 1
    }
}

impl Default for ClassSet {
    /// [`ClassSet::LAS_BACKGROUND`].
    fn default() -> Self {
        ClassSet::LAS_BACKGROUND
    }
}

impl ReadOptions {
    /// Options that read labels: from text column `label_column`, and from
    /// the label property of the binary formats.
    ///
    /// ```
    /// let o = aniso_alpha::io::ReadOptions::with_labels(3);
    /// assert_eq!(o.label_column, Some(3));
    /// assert!(o.read_labels);
    /// ```
    pub fn with_labels(label_column: usize) -> Self {
        ReadOptions {
            label_column: Some(label_column),
            read_labels: true,
            format: None,
            background_classes: ClassSet::LAS_BACKGROUND,
            attributes: false,
        }
    }
}

/// A point file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Text: `.xyz`, `.txt`, `.csv`, `.pts`.
    Text,
    /// `.ply`.
    Ply,
    /// `.las` or `.laz`.
    Las,
    /// `.pcd`.
    Pcd,
    /// `.e57`.
    E57,
}

const EXPECTED_POINTS: &str = ".xyz, .txt, .csv, .pts, .ply, .las, .laz, .pcd or .e57";

impl Format {
    /// The format of a point file, from its extension (case-insensitive).
    ///
    /// ```
    /// use aniso_alpha::io::Format;
    /// use std::path::Path;
    /// assert_eq!(Format::from_path(Path::new("a/B.PLY")).unwrap(), Format::Ply);
    /// assert!(Format::from_path(Path::new("scan.e58")).is_err());
    /// ```
    pub fn from_path(path: &Path) -> Result<Format, IoError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        Format::from_name(&ext).ok_or_else(|| IoError::UnknownFormat {
            path: path.to_path_buf(),
            expected: EXPECTED_POINTS,
        })
    }

    /// The format named by an extension or a `--format` value
    /// (case-insensitive, without the dot): `xyz` `txt` `csv` `pts` `ply`
    /// `las` `laz` `pcd` `e57`.
    ///
    /// ```
    /// use aniso_alpha::io::Format;
    /// assert_eq!(Format::from_name("LAZ"), Some(Format::Las));
    /// assert_eq!(Format::from_name("obj"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Format> {
        Some(match name.to_ascii_lowercase().as_str() {
            "xyz" | "txt" | "csv" | "pts" => Format::Text,
            "ply" => Format::Ply,
            "las" | "laz" => Format::Las,
            "pcd" => Format::Pcd,
            "e57" => Format::E57,
            _ => return None,
        })
    }

    /// The format of `path` under `options`: `options.format`, else text
    /// for standard input (`-`), else by extension.
    pub fn resolve(path: &Path, options: &ReadOptions) -> Result<Format, IoError> {
        match options.format {
            Some(f) => Ok(f),
            None if is_stdin(path) => Ok(Format::Text),
            None => Format::from_path(path),
        }
    }
}

/// Whether `path` is `-`, standard input.
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Reads a point file, its format chosen by extension.
///
/// ```no_run
/// use aniso_alpha::io::{read_points, ReadOptions};
/// let cloud = read_points("scan.ply".as_ref(), &ReadOptions::default())?;
/// println!("{} points", cloud.points.len());
/// # Ok::<(), aniso_alpha::io::IoError>(())
/// ```
pub fn read_points(path: &Path, options: &ReadOptions) -> Result<PointCloud, IoError> {
    read_points_with_progress(path, options, &mut |_, _| {})
}

/// [`read_points`], calling `progress(bytes_read, file_size)` while the
/// file is read (for a progress bar). `-` reads standard input. Text is
/// streamed through one buffer and LAS/LAZ read at offsets (neither file
/// is held in memory); the other formats are loaded whole.
pub fn read_points_with_progress(
    path: &Path,
    options: &ReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PointCloud, IoError> {
    let format = Format::resolve(path, options)?;
    if format == Format::Text {
        if is_stdin(path) {
            let stdin = std::io::stdin().lock();
            return text::read_text_stream(path, stdin, options.label_column, 0, &mut |done| {
                progress(done, done)
            });
        }
        let (file, total) = open_file(path)?;
        return text::read_text_stream(
            path,
            file,
            options.label_column,
            usize::try_from(total).unwrap_or(0),
            &mut |done| progress(done, total.max(done)),
        );
    }
    #[cfg(feature = "las")]
    if format == Format::Las && !is_stdin(path) {
        // Read at offsets: the file's bytes are never all in memory.
        let keep = las::Keep::from_attributes(options.attributes);
        return read_las_file(path, None, options, keep, progress);
    }
    let bytes = if is_stdin(path) {
        let mut bytes = Vec::new();
        std::io::stdin()
            .lock()
            .read_to_end(&mut bytes)
            .map_err(|source| IoError::Open {
                path: path.to_path_buf(),
                source,
            })?;
        bytes
    } else {
        read_file(path, progress)?
    };
    parse_format(format, path, &bytes, options)
}

/// Opens a file for reading, with clear errors for a missing file or a
/// directory; returns it with its size.
fn open_file(path: &Path) -> Result<(File, u64), IoError> {
    let open_err = |source| IoError::Open {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(open_err)?;
    if meta.is_dir() {
        return Err(IoError::IsDirectory {
            path: path.to_path_buf(),
        });
    }
    Ok((File::open(path).map_err(open_err)?, meta.len()))
}

/// Loads a whole file, with clear errors for a missing file or a directory.
pub(crate) fn read_file(
    path: &Path,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Vec<u8>, IoError> {
    let (mut file, total) = open_file(path)?;
    let mut bytes = Vec::with_capacity(usize::try_from(total).unwrap_or(0).saturating_add(1));
    let mut chunk = vec![0u8; 8 << 20];
    loop {
        let k = match file.read(&mut chunk) {
            Ok(0) => break,
            Ok(k) => k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(source) => {
                return Err(IoError::Open {
                    path: path.to_path_buf(),
                    source,
                })
            }
        };
        bytes.extend_from_slice(&chunk[..k]);
        progress(bytes.len() as u64, total.max(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The points `start..start + count` of a LAS/LAZ file, in file order
/// (a range that passes the end is cut at it; one that starts past it is
/// an error), as [`read_points`] reads them, without holding the file's
/// other points or bytes: an uncompressed file's records are read at their
/// offset, a LAZ file's from the start of the chunk that holds `start`. So
/// a file larger than memory is read a range at a time; with
/// `options.attributes`, [`PointCloud::las`] holds the range's records
/// with the file's header and VLRs. Needs the cargo feature `las`.
///
/// ```no_run
/// use aniso_alpha::io::{las_point_count, read_las_range, ReadOptions};
/// let path = "big.laz".as_ref();
/// let n = las_point_count(path)?;
/// let mut start = 0;
/// while start < n {
///     let piece = read_las_range(path, start, 1 << 22, &ReadOptions::default())?;
///     start += piece.points.len() as u64;
/// }
/// # Ok::<(), aniso_alpha::io::IoError>(())
/// ```
pub fn read_las_range(
    path: &Path,
    start: u64,
    count: u64,
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    #[cfg(feature = "las")]
    {
        let keep = las::Keep::from_attributes(options.attributes);
        read_las_file(path, Some((start, count)), options, keep, &mut |_, _| {})
    }
    #[cfg(not(feature = "las"))]
    {
        let _ = (start, count, options);
        Err(las_unsupported(path))
    }
}

/// [`read_las_range`] keeping the range's records in [`PointCloud::las`]
/// without decoding them into attributes: what a labelled copy of the
/// file needs (`LasLabelWriter::append`), at the records' size.
pub fn read_las_range_records(path: &Path, start: u64, count: u64) -> Result<PointCloud, IoError> {
    #[cfg(feature = "las")]
    {
        let options = ReadOptions::default();
        read_las_file(
            path,
            Some((start, count)),
            &options,
            las::Keep::Records,
            &mut |_, _| {},
        )
    }
    #[cfg(not(feature = "las"))]
    {
        let _ = (start, count);
        Err(las_unsupported(path))
    }
}

/// A LAS/LAZ file on disk, read at offsets.
#[cfg(feature = "las")]
fn las_file(path: &Path) -> Result<las_bytes::FileBytes, IoError> {
    let (file, total) = open_file(path)?;
    Ok(las_bytes::FileBytes::new(file, total))
}

/// The points `range` (start, count; `None`: all) of a LAS/LAZ file on
/// disk, keeping `keep`.
#[cfg(feature = "las")]
fn read_las_file(
    path: &Path,
    range: Option<(u64, u64)>,
    options: &ReadOptions,
    keep: las::Keep,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<PointCloud, IoError> {
    las::read_las_from(
        path,
        &las_file(path)?,
        range,
        options.read_labels.then_some(options.background_classes),
        keep,
        progress,
    )
}

/// The number of points a LAS/LAZ file's header declares, after the
/// checks a read makes of the header (and of a LAZ file's chunk table),
/// without reading the points. Needs the cargo feature `las`.
pub fn las_point_count(path: &Path) -> Result<u64, IoError> {
    #[cfg(feature = "las")]
    {
        las::las_points(path, &las_file(path)?)
    }
    #[cfg(not(feature = "las"))]
    {
        Err(las_unsupported(path))
    }
}

/// The error of a LAS/LAZ function built without the `las` feature.
#[cfg(not(feature = "las"))]
fn las_unsupported(path: &Path) -> IoError {
    IoError::Unsupported {
        path: path.to_path_buf(),
        message: "LAS/LAZ support is not compiled in (cargo feature `las`)",
    }
}

/// Parses a point file held in memory; `path` picks the format by
/// extension (unless `options.format` is set) and names the file in errors.
pub fn read_points_bytes(
    path: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    parse_format(Format::resolve(path, options)?, path, bytes, options)
}

fn parse_format(
    format: Format,
    path: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    match format {
        Format::Text => read_xyz_bytes(path, bytes, options),
        Format::Ply => read_ply_bytes(path, bytes, options),
        Format::Las => read_las_bytes(path, bytes, options),
        Format::Pcd => read_pcd_bytes(path, bytes, options),
        Format::E57 => read_e57_bytes(path, bytes, options),
    }
}

/// Parses a text point file (xyz/txt/csv/pts) held in memory; `name` only
/// names it in errors. Uses `options.label_column`.
///
/// ```
/// use aniso_alpha::io::{read_xyz_bytes, ReadOptions};
/// let c = read_xyz_bytes("a.csv".as_ref(), b"x,y,z\n1,2,3\n", &ReadOptions::default()).unwrap();
/// assert_eq!(c.points, vec![[1.0, 2.0, 3.0]]);
/// assert_eq!(c.warnings[0].to_string(), "line 1 taken as a header: 'x,y,z'");
/// ```
pub fn read_xyz_bytes(
    name: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    text::read_text(name, bytes, options.label_column)
}

/// Parses a PLY file (ascii or binary) held in memory; `name` only names
/// it in errors. Reads the `vertex` element's x, y, z (and, with
/// `options.read_labels`, its `structure` or `label` property).
///
/// ```
/// use aniso_alpha::io::{read_ply_bytes, ReadOptions};
/// let ply = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n";
/// let c = read_ply_bytes("m.ply".as_ref(), ply, &ReadOptions::default()).unwrap();
/// assert_eq!(c.points, vec![[1.0, 2.0, 3.0]]);
/// ```
pub fn read_ply_bytes(
    name: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    ply::read_ply(name, bytes, options.read_labels, options.attributes)
}

/// Parses a PCD file (ascii, binary or binary_compressed) held in memory;
/// `name` only names it in errors. With `options.read_labels`, a `label`
/// field gives the labels.
///
/// ```
/// use aniso_alpha::io::{read_pcd_bytes, ReadOptions};
/// let pcd = b"VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n";
/// let c = read_pcd_bytes("c.pcd".as_ref(), pcd, &ReadOptions::default()).unwrap();
/// assert_eq!(c.points, vec![[1.0, 2.0, 3.0]]);
/// ```
pub fn read_pcd_bytes(
    name: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    pcd::read_pcd(name, bytes, options.read_labels, options.attributes)
}

/// Parses a LAS or LAZ file held in memory (scale and offset applied);
/// `name` only names it in errors. With `options.read_labels`, the
/// classification gives the labels. Needs the cargo feature `las`;
/// without it this returns [`IoError::Unsupported`].
pub fn read_las_bytes(
    name: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    #[cfg(feature = "las")]
    {
        las::read_las(
            name,
            bytes,
            options.read_labels.then_some(options.background_classes),
            options.attributes,
        )
    }
    #[cfg(not(feature = "las"))]
    {
        let _ = (bytes, options);
        Err(las_unsupported(name))
    }
}

/// Parses an E57 file held in memory: the points of every scan, each
/// moved by its pose into the file's coordinate system (points flagged
/// invalid are skipped, with a [`ReadWarning::SkippedPoints`]); with
/// `options.attributes`, every other field (intensity, colours, row and
/// column, time stamps, extension fields) in its own type. E57 has no
/// classification: `labels` stay `None`. Needs the cargo feature `e57`;
/// without it this returns [`IoError::Unsupported`].
pub fn read_e57_bytes(
    name: &Path,
    bytes: &[u8],
    options: &ReadOptions,
) -> Result<PointCloud, IoError> {
    #[cfg(feature = "e57")]
    {
        e57::read_e57(name, bytes, options.attributes)
    }
    #[cfg(not(feature = "e57"))]
    {
        let _ = (bytes, options);
        Err(IoError::Unsupported {
            path: name.to_path_buf(),
            message: "E57 support is not compiled in (cargo feature `e57`)",
        })
    }
}

/// The next `\n`-terminated line of a binary file's text header, starting
/// at `*pos` (without its `\n`; the last line may lack one), advancing
/// `*pos` past it; `None` at the end of `bytes`.
pub(crate) fn next_header_line<'a>(bytes: &'a [u8], pos: &mut usize) -> Option<&'a [u8]> {
    if *pos >= bytes.len() {
        return None;
    }
    let end = bytes[*pos..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |k| *pos + k);
    let raw = &bytes[*pos..end];
    *pos = (end + 1).min(bytes.len());
    Some(raw)
}

/// Fails with [`IoError::NoPoints`] on an empty cloud.
pub(crate) fn non_empty(path: &Path, cloud: PointCloud) -> Result<PointCloud, IoError> {
    if cloud.points.is_empty() {
        Err(IoError::NoPoints {
            path: path.to_path_buf(),
        })
    } else {
        Ok(cloud)
    }
}

/// Whether all three coordinates of `p` are finite.
#[inline]
pub(crate) fn is_finite(p: &[f64; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}

/// Fails with [`IoError::NonFinite`] unless all three coordinates are finite.
#[inline]
pub(crate) fn check_finite(
    path: &Path,
    p: &[f64; 3],
    index: usize,
    line: Option<usize>,
) -> Result<(), IoError> {
    if is_finite(p) {
        Ok(())
    } else {
        Err(IoError::NonFinite {
            path: path.to_path_buf(),
            line,
            index,
        })
    }
}
