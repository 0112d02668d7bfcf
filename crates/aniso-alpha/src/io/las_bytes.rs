//! Random access to the bytes of a LAS/LAZ file, held in memory or read
//! from disk a piece at a time, so that one reader (and its checks of
//! hostile files) serves both: a file in memory, and a range of points of
//! a file larger than memory.

use std::borrow::Cow;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::sync::Mutex;

/// A LAS/LAZ file's bytes by offset.
pub(crate) trait LasBytes: Sync {
    /// The file's size in bytes.
    fn size(&self) -> u64;
    /// The `n` bytes at `at`; `None` where they pass the end of the file
    /// (nothing is allocated for a range the file does not hold).
    fn piece(&self, at: u64, n: u64) -> Option<Cow<'_, [u8]>>;
}

impl LasBytes for [u8] {
    fn size(&self) -> u64 {
        self.len() as u64
    }

    fn piece(&self, at: u64, n: u64) -> Option<Cow<'_, [u8]>> {
        let at = usize::try_from(at).ok()?;
        let end = at.checked_add(usize::try_from(n).ok()?)?;
        self.get(at..end).map(Cow::Borrowed)
    }
}

/// An open file read at offsets (one reader at a time).
pub(crate) struct FileBytes {
    file: Mutex<File>,
    size: u64,
}

impl FileBytes {
    /// The file, with its size.
    pub(crate) fn new(file: File, size: u64) -> FileBytes {
        FileBytes {
            file: Mutex::new(file),
            size,
        }
    }
}

impl LasBytes for FileBytes {
    fn size(&self) -> u64 {
        self.size
    }

    fn piece(&self, at: u64, n: u64) -> Option<Cow<'_, [u8]>> {
        if at.checked_add(n)? > self.size {
            return None;
        }
        let mut buf = vec![0u8; usize::try_from(n).ok()?];
        let mut file = self.file.lock().unwrap_or_else(|e| e.into_inner());
        file.seek(SeekFrom::Start(at)).ok()?;
        file.read_exact(&mut buf).ok()?;
        Some(Cow::Owned(buf))
    }
}

/// [`Read`] and [`Seek`] over a [`LasBytes`] (for the `las` and `laz`
/// crates); reads stop at the end of the file.
pub(crate) struct ByteReader<'a, B: ?Sized> {
    bytes: &'a B,
    pos: u64,
}

impl<'a, B: LasBytes + ?Sized> ByteReader<'a, B> {
    /// A reader at offset 0.
    pub(crate) fn new(bytes: &'a B) -> Self {
        ByteReader { bytes, pos: 0 }
    }
}

impl<B: LasBytes + ?Sized> Read for ByteReader<'_, B> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = self.bytes.size().saturating_sub(self.pos);
        let n = (buf.len() as u64).min(left);
        if n == 0 {
            return Ok(0);
        }
        let got = self
            .bytes
            .piece(self.pos, n)
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::UnexpectedEof))?;
        buf[..n as usize].copy_from_slice(&got);
        self.pos += n;
        Ok(n as usize)
    }
}

impl<B: LasBytes + ?Sized> Seek for ByteReader<'_, B> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let base = match to {
            SeekFrom::Start(p) => Some(p),
            SeekFrom::End(d) => self.bytes.size().checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        let p = base.ok_or_else(|| {
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "seek before the start")
        })?;
        self.pos = p;
        Ok(p)
    }
}

/// One byte at `o`.
pub(crate) fn u8_at<B: LasBytes + ?Sized>(b: &B, o: u64) -> Option<u8> {
    b.piece(o, 1).map(|s| s[0])
}

/// A little-endian `u16` at `o`.
pub(crate) fn u16_at<B: LasBytes + ?Sized>(b: &B, o: u64) -> Option<u64> {
    let s = b.piece(o, 2)?;
    Some(u64::from(u16::from_le_bytes([s[0], s[1]])))
}

/// A little-endian `u32` at `o`.
pub(crate) fn u32_at<B: LasBytes + ?Sized>(b: &B, o: u64) -> Option<u64> {
    let s = b.piece(o, 4)?;
    Some(u64::from(u32::from_le_bytes(s[..4].try_into().ok()?)))
}

/// A little-endian `u64` at `o`.
pub(crate) fn u64_at<B: LasBytes + ?Sized>(b: &B, o: u64) -> Option<u64> {
    let s = b.piece(o, 8)?;
    Some(u64::from_le_bytes(s[..8].try_into().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_and_file_give_the_same_bytes() {
        let data: Vec<u8> = (0..=255u8).cycle().take(1000).collect();
        let path = std::env::temp_dir().join(format!("las-bytes-{}.bin", std::process::id()));
        std::fs::write(&path, &data).unwrap();
        let file = FileBytes::new(File::open(&path).unwrap(), data.len() as u64);
        for (at, n) in [(0, 0), (0, 10), (990, 10), (500, 1), (999, 1)] {
            assert_eq!(
                file.piece(at, n).as_deref(),
                data.as_slice().piece(at, n).as_deref()
            );
            assert!(file.piece(at, n).is_some());
        }
        for (at, n) in [(991, 10), (1000, 1), (u64::MAX, 2), (2, u64::MAX)] {
            assert!(file.piece(at, n).is_none(), "{at} {n}");
            assert!(data.as_slice().piece(at, n).is_none(), "{at} {n}");
        }
        assert_eq!(u32_at(&file, 4), u32_at(data.as_slice(), 4));
        assert_eq!(u64_at(&file, 993), None);
        let mut r = ByteReader::new(&file);
        r.seek(SeekFrom::End(-3)).unwrap();
        let mut rest = Vec::new();
        r.read_to_end(&mut rest).unwrap();
        assert_eq!(rest, &data[997..]);
        assert!(r.seek(SeekFrom::Current(-2000)).is_err());
        std::fs::remove_file(&path).unwrap();
    }
}
