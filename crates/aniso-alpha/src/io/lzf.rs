//! LZF decompression (the codec of PCD `binary_compressed`).

/// Decompresses LZF `input` into exactly `expected` bytes; `None` on any
/// malformed input.
pub(crate) fn decompress(input: &[u8], expected: usize) -> Option<Vec<u8>> {
    let mut out: Vec<u8> = Vec::with_capacity(expected);
    let mut i = 0usize;
    while i < input.len() {
        let ctrl = usize::from(input[i]);
        i += 1;
        if ctrl < 32 {
            // Literal run of ctrl + 1 bytes.
            let run = input.get(i..i + ctrl + 1)?;
            if out.len() + run.len() > expected {
                return None;
            }
            out.extend_from_slice(run);
            i += ctrl + 1;
        } else {
            // Back reference.
            let mut len = ctrl >> 5;
            if len == 7 {
                len += usize::from(*input.get(i)?);
                i += 1;
            }
            len += 2;
            let back = ((ctrl & 0x1f) << 8) + usize::from(*input.get(i)?) + 1;
            i += 1;
            if back > out.len() || out.len() + len > expected {
                return None;
            }
            let start = out.len() - back;
            for k in 0..len {
                let b = out[start + k];
                out.push(b);
            }
        }
    }
    (out.len() == expected).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literal_and_backref() {
        // "abc" literal, then copy 6 bytes from distance 3: "abcabcabc".
        let data = [2, b'a', b'b', b'c', (4 << 5), 2];
        assert_eq!(decompress(&data, 9).unwrap(), b"abcabcabc");
        // Long back reference (len field 7 + extra byte).
        let data = [0, b'z', (7 << 5), 1, 0];
        assert_eq!(decompress(&data, 1 + 10).unwrap(), vec![b'z'; 11]);
        assert!(decompress(&data, 12).is_none());
        assert!(decompress(&[5, 1], 6).is_none());
        assert!(decompress(&[(1 << 5), 9], 3).is_none());
    }
}
