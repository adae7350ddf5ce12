//! Text files as people save them: UTF-8 (with or without a byte-order
//! mark), UTF-16 little- or big-endian (with a mark, or recognised by its
//! zero bytes), and Latin-1 (Windows exporters) where the bytes are not
//! valid UTF-8. Never fails: every byte sequence decodes to something.

/// Decodes `bytes` as the text encoding it most plausibly uses.
pub fn decode(bytes: &[u8]) -> String {
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]) {
        return String::from_utf8_lossy(rest).into_owned();
    }
    if let Some(rest) = bytes.strip_prefix(&[0xFF, 0xFE]) {
        return utf16(rest, u16::from_le_bytes);
    }
    if let Some(rest) = bytes.strip_prefix(&[0xFE, 0xFF]) {
        return utf16(rest, u16::from_be_bytes);
    }
    // UTF-16 without a mark: ASCII text has a zero in every other byte.
    let head = &bytes[..bytes.len().min(512)];
    if head.len() >= 4 {
        let zeros = |start: usize| {
            head.iter()
                .skip(start)
                .step_by(2)
                .filter(|b| **b == 0)
                .count()
        };
        let half = head.len() / 2;
        if zeros(1) * 10 >= half * 9 && zeros(0) == 0 {
            return utf16(bytes, u16::from_le_bytes);
        }
        if zeros(0) * 10 >= half * 9 && zeros(1) == 0 {
            return utf16(bytes, u16::from_be_bytes);
        }
    }
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_owned(),
        // Latin-1: each byte is the code point of the same value.
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}

fn utf16(bytes: &[u8], unit: fn([u8; 2]) -> u16) -> String {
    let units = bytes.chunks_exact(2).map(|c| unit([c[0], c[1]]));
    char::decode_utf16(units)
        .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::decode;

    fn utf16(s: &str, le: bool, bom: bool) -> Vec<u8> {
        let mut out = Vec::new();
        let units = std::iter::once(0xFEFF)
            .filter(|_| bom)
            .chain(s.encode_utf16());
        for u in units {
            out.extend(if le { u.to_le_bytes() } else { u.to_be_bytes() });
        }
        out
    }

    #[test]
    fn encodings_decode() {
        let s = "v 0 0 0\nf 1 2 3\n# café\n";
        assert_eq!(decode(s.as_bytes()), s);
        let mut bom = vec![0xEF, 0xBB, 0xBF];
        bom.extend(s.as_bytes());
        assert_eq!(decode(&bom), s);
        for le in [true, false] {
            for mark in [true, false] {
                assert_eq!(decode(&utf16(s, le, mark)), s, "le {le} bom {mark}");
            }
        }
        // Latin-1 é is 0xE9, invalid as UTF-8.
        assert_eq!(decode(b"newmtl caf\xe9\n"), "newmtl café\n");
        assert_eq!(decode(b""), "");
        assert_eq!(decode(&[0xFF]), "\u{ff}");
    }
}
