//! One region-part id per point of a region run's cloud (module doc of
//! `regions`, step 3), held in memory or in a scratch file: the one store
//! that grows with the cloud on the process that joins the regions, so
//! that a cloud larger than that process's memory can still be joined.
//!
//! The file holds each id as its bitwise complement (4 bytes, little
//! endian), so that its zero bytes, as the file is created, read as
//! [`UNSEEN`]. Ids are set and read by runs of consecutive points (a
//! region's core is a few long runs of input indices when the input is in
//! spatial order: tiles, or one file read in pieces).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// A point whose core region was not added yet.
pub(super) const UNSEEN: u32 = u32::MAX;

/// A gap between two points to read up to which one read covers both.
const READ_GAP: usize = 64;

/// The part ids of the points of a cloud.
#[derive(Debug)]
pub(super) enum PartIds {
    /// In memory.
    Memory(Vec<u32>),
    /// In a scratch file.
    File(Scratch),
}

/// A scratch file of ids, closed and removed when dropped.
#[derive(Debug)]
pub(super) struct Scratch {
    /// `None` only while dropped (closed before it is removed, which some
    /// systems require).
    file: Option<File>,
    path: PathBuf,
    len: usize,
}

impl Drop for Scratch {
    fn drop(&mut self) {
        drop(self.file.take());
        let _ = std::fs::remove_file(&self.path);
    }
}

impl Scratch {
    /// The open file.
    fn file(&self) -> std::io::Result<&File> {
        self.file
            .as_ref()
            .ok_or_else(|| std::io::Error::other("the scratch file is closed"))
    }
}

/// The runs of consecutive values of ascending `ids` as index ranges of
/// `ids`, two runs read as one when at most `gap` indices apart.
fn runs(ids: &[u32], gap: usize) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let mut start = 0;
    std::iter::from_fn(move || {
        if start >= ids.len() {
            return None;
        }
        let mut end = start + 1;
        while end < ids.len() && (ids[end] as usize) <= ids[end - 1] as usize + 1 + gap {
            end += 1;
        }
        let r = start..end;
        start = end;
        Some(r)
    })
}

impl PartIds {
    /// `n` points, none seen, in memory.
    pub(super) fn in_memory(n: usize) -> PartIds {
        PartIds::Memory(vec![UNSEEN; n])
    }

    /// `n` points, none seen, in a new scratch file in folder `dir`.
    pub(super) fn in_file(n: usize, dir: &Path) -> std::io::Result<PartIds> {
        static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let k = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let path = dir.join(format!(".aniso-alpha-part-ids-{}-{k}", std::process::id()));
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&path)?;
        let scratch = Scratch {
            file: Some(file),
            path,
            len: n,
        };
        scratch.file()?.set_len(n as u64 * 4)?;
        Ok(PartIds::File(scratch))
    }

    /// The number of points.
    pub(super) fn len(&self) -> usize {
        match self {
            PartIds::Memory(v) => v.len(),
            PartIds::File(s) => s.len,
        }
    }

    /// Sets point `ids[k]`'s id to `values[k]` (ids ascending, within the
    /// cloud).
    pub(super) fn set(&mut self, ids: &[u32], values: &[u32]) -> std::io::Result<()> {
        match self {
            PartIds::Memory(v) => {
                for (&i, &p) in ids.iter().zip(values) {
                    v[i as usize] = p;
                }
                Ok(())
            }
            PartIds::File(s) => {
                let mut buf = Vec::new();
                let mut file = s.file()?;
                for r in runs(ids, 0) {
                    buf.clear();
                    buf.extend(values[r.clone()].iter().flat_map(|&p| (!p).to_le_bytes()));
                    file.seek(SeekFrom::Start(u64::from(ids[r.start]) * 4))?;
                    file.write_all(&buf)?;
                }
                Ok(())
            }
        }
    }

    /// The ids of points `ids` (ascending, within the cloud), appended to
    /// `out` in that order.
    pub(super) fn get(&self, ids: &[u32], out: &mut Vec<u32>) -> std::io::Result<()> {
        match self {
            PartIds::Memory(v) => {
                out.extend(ids.iter().map(|&i| v[i as usize]));
                Ok(())
            }
            PartIds::File(s) => {
                let mut span = Vec::new();
                for r in runs(ids, READ_GAP) {
                    let first = ids[r.start] as usize;
                    s.read_range(first, ids[r.end - 1] as usize + 1 - first, &mut span)?;
                    out.extend(ids[r].iter().map(|&i| span[i as usize - first]));
                }
                Ok(())
            }
        }
    }

    /// The ids of points `first..first + n` (within the cloud) into `out`
    /// (replacing its content).
    pub(super) fn range(&self, first: usize, n: usize, out: &mut Vec<u32>) -> std::io::Result<()> {
        match self {
            PartIds::Memory(v) => {
                out.clear();
                out.extend_from_slice(&v[first..first + n]);
                Ok(())
            }
            PartIds::File(s) => s.read_range(first, n, out),
        }
    }
}

impl Scratch {
    /// The ids of points `first..first + n` into `out` (replacing it).
    fn read_range(&self, first: usize, n: usize, out: &mut Vec<u32>) -> std::io::Result<()> {
        let mut bytes = vec![0u8; n * 4];
        let mut file = self.file()?;
        file.seek(SeekFrom::Start(first as u64 * 4))?;
        file.read_exact(&mut bytes)?;
        out.clear();
        out.extend(
            bytes
                .chunks_exact(4)
                .map(|b| !u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn a_file_holds_what_memory_holds() {
        let dir = std::env::temp_dir();
        let n = 10_000;
        let mut mem = PartIds::in_memory(n);
        let mut file = PartIds::in_file(n, &dir).unwrap();
        let path = match &file {
            PartIds::File(s) => s.path.clone(),
            PartIds::Memory(_) => unreachable!(),
        };
        let mut rng = SplitMix64::new(3);
        for _ in 0..50 {
            let mut ids: Vec<u32> = (0..1 + rng.below(300))
                .map(|_| rng.below(n as u64) as u32)
                .collect();
            ids.sort_unstable();
            ids.dedup();
            let values: Vec<u32> = ids.iter().map(|_| rng.below(1 << 31) as u32).collect();
            mem.set(&ids, &values).unwrap();
            file.set(&ids, &values).unwrap();
            let mut probe: Vec<u32> = (0..200).map(|_| rng.below(n as u64) as u32).collect();
            probe.sort_unstable();
            let (mut a, mut b) = (Vec::new(), Vec::new());
            mem.get(&probe, &mut a).unwrap();
            file.get(&probe, &mut b).unwrap();
            assert_eq!(a, b);
        }
        let (mut a, mut b) = (Vec::new(), Vec::new());
        mem.range(0, n, &mut a).unwrap();
        file.range(0, n, &mut b).unwrap();
        assert_eq!(a, b);
        assert!(a.contains(&UNSEEN) && a.iter().any(|&p| p != UNSEEN));
        file.range(9_990, 10, &mut b).unwrap();
        assert_eq!(b, a[9_990..]);
        assert!(path.exists());
        drop(file);
        assert!(!path.exists(), "the scratch file is removed");
    }

    #[test]
    fn runs_split_at_gaps() {
        let ids = [1, 2, 3, 7, 8, 100, 101, 300];
        let exact: Vec<_> = runs(&ids, 0).collect();
        assert_eq!(exact, vec![0..3, 3..5, 5..7, 7..8]);
        let loose: Vec<_> = runs(&ids, 64).collect();
        assert_eq!(loose, vec![0..5, 5..7, 7..8]);
        assert_eq!(runs(&[], 0).count(), 0);
    }
}
