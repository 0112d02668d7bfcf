//! LAS/LAZ through the `las` crate.

use std::io::Cursor;
use std::path::Path;

use super::{check_finite, non_empty, IoError, PointCloud};

pub(crate) fn read_las(
    path: &Path,
    bytes: &[u8],
    read_labels: bool,
) -> Result<PointCloud, IoError> {
    let err = |e: las::Error| IoError::format(path, format!("invalid LAS/LAZ file: {e}"));
    // The reader wants an owned, 'static source.
    let mut reader = las::Reader::new(Cursor::new(bytes.to_vec())).map_err(err)?;
    let declared = reader.header().number_of_points();
    // Never trust the header for an allocation: a point takes ≥ 20 bytes.
    let cap = usize::try_from(declared).unwrap_or(0).min(bytes.len() / 20);
    let mut cloud = PointCloud {
        points: Vec::with_capacity(cap),
        labels: read_labels.then(|| Vec::with_capacity(cap)),
    };
    let mut batch = las::PointDataBuilder::new()
        .for_header(reader.header())
        .build();
    loop {
        let got = reader.fill_points(1 << 16, &mut batch).map_err(err)?;
        if got == 0 {
            break;
        }
        for ((x, y), z) in batch.x().zip(batch.y()).zip(batch.z()) {
            let p = [x, y, z];
            check_finite(path, &p, cloud.points.len(), None)?;
            cloud.points.push(p);
        }
        if let Some(labels) = cloud.labels.as_mut() {
            labels.extend(batch.classification().map(i64::from));
        }
    }
    if (cloud.points.len() as u64) < declared {
        return Err(IoError::format(
            path,
            format!(
                "LAS file truncated: header declares {declared} points, found {}",
                cloud.points.len()
            ),
        ));
    }
    non_empty(path, cloud)
}
