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
    precheck(bytes).map_err(|m| IoError::format(path, format!("invalid LAS/LAZ file: {m}")))?;
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
    // The reader sizes its buffer as n × record length, both from the
    // header: keep a batch within 16 MiB and within the file.
    let n = batch_size(batch.record_len(), bytes.len());
    loop {
        let got = reader.fill_points(n, &mut batch).map_err(err)?;
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

fn u16_at(b: &[u8], o: usize) -> Option<u64> {
    Some(u64::from(u16::from_le_bytes(
        b.get(o..o + 2)?.try_into().ok()?,
    )))
}

fn u32_at(b: &[u8], o: usize) -> Option<u64> {
    Some(u64::from(u32::from_le_bytes(
        b.get(o..o + 4)?.try_into().ok()?,
    )))
}

fn u64_at(b: &[u8], o: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(o..o + 8)?.try_into().ok()?))
}

/// Checks the header fields that the `las` crate trusts for allocations
/// and arithmetic (it panics or aborts on some lies): the point data size
/// must not overflow, and an extended VLR must fit in the file. Fields that
/// are missing (a short file) are left to the crate, which reports them.
fn precheck(b: &[u8]) -> Result<(), String> {
    let len = b.len() as u64;
    let (Some(major), Some(minor)) = (b.get(24).copied(), b.get(25).copied()) else {
        return Ok(());
    };
    let v14 = major > 1 || (major == 1 && minor >= 4);
    let offset = u32_at(b, 96).unwrap_or(0);
    let record_len = u16_at(b, 105).unwrap_or(0);
    let mut count = u32_at(b, 107).unwrap_or(0);
    if v14 {
        count = count.max(u64_at(b, 247).unwrap_or(0));
    }
    let end = count
        .checked_mul(record_len)
        .and_then(|n| n.checked_add(offset))
        .ok_or("point count × record length overflows")?;
    let compressed = b.get(104).is_some_and(|f| f & 0xC0 != 0);
    if !compressed && end > len && record_len > 0 {
        return Err(format!(
            "truncated: header declares {count} points of {record_len} bytes, file has {len} bytes"
        ));
    }
    if v14 {
        let start = u64_at(b, 235).unwrap_or(0);
        let n = u32_at(b, 243).unwrap_or(0);
        if start > 0 && n > 0 {
            let rec = usize::try_from(start)
                .ok()
                .and_then(|s| u64_at(b, s.checked_add(20)?))
                .ok_or("extended VLR starts past the end of the file")?;
            if rec.checked_add(start + 60).is_none_or(|e| e > len) {
                return Err("extended VLR extends past the end of the file".into());
            }
        }
    }
    Ok(())
}

/// Points per batch: at most 65536, at most 16 MiB of records, and no more
/// records than the file could hold uncompressed (LAZ aside), at least 1.
fn batch_size(record_len: usize, file_len: usize) -> u64 {
    let record_len = record_len.max(1);
    let n = (16usize << 20) / record_len;
    let n = n.min(1 << 16).min(file_len / record_len + 1).max(1);
    n as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batches_stay_small() {
        assert_eq!(batch_size(20, 1 << 30), 1 << 16);
        assert_eq!(batch_size(0, 0), 1);
        assert!(batch_size(65535, 1 << 30) * 65535 <= 16 << 20);
        assert_eq!(batch_size(20, 300), 16);
    }

    #[test]
    fn fuzz_regression_huge_evlr() {
        // libFuzzer: an extended VLR of length ~2^64 made the `las` crate
        // panic ("capacity overflow").
        let bytes = include_bytes!("../../tests/fuzz_regressions/las-evlr-capacity-overflow.las");
        let e = read_las(Path::new("evlr.las"), bytes, true).unwrap_err();
        assert!(
            e.to_string().starts_with("evlr.las: invalid LAS/LAZ file"),
            "{e}"
        );
    }

    #[test]
    fn fuzz_regression_huge_record_length() {
        // libFuzzer found a header with a huge record length and point
        // count: the reader allocated 2.7 GB at once.
        let bytes = include_bytes!("../../tests/fuzz_regressions/las-oom-record-length.las");
        let _ = read_las(Path::new("oom.las"), bytes, true);
    }
}
