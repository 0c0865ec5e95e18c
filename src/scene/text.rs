//! The text of OBJ and MTL files as exporters write it: byte-order marks,
//! UTF-16 and MSVC's printed NaN, which would otherwise lose a statement
//! or read as a number.

use std::borrow::Cow;

/// The file as UTF-8 bytes: a UTF-8 byte-order mark skipped (Windows
/// tools write one; it would hide the first statement's keyword) and
/// UTF-16 with its mark decoded (invalid units become U+FFFD, which no
/// keyword or number contains).
pub(super) fn utf8_text(bytes: &[u8]) -> Cow<'_, [u8]> {
    let utf16 = |big_endian: bool| {
        let units = bytes[2..].chunks_exact(2).map(|p| {
            let pair = [p[0], p[1]];
            if big_endian {
                u16::from_be_bytes(pair)
            } else {
                u16::from_le_bytes(pair)
            }
        });
        Cow::Owned(
            char::decode_utf16(units)
                .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
                .collect::<String>()
                .into_bytes(),
        )
    };
    match bytes {
        [0xEF, 0xBB, 0xBF, rest @ ..] => Cow::Borrowed(rest),
        [0xFF, 0xFE, ..] => utf16(false),
        [0xFE, 0xFF, ..] => utf16(true),
        _ => Cow::Borrowed(bytes),
    }
}

/// Where the comment of `line` starts (its `#`), if it has one. A `#`
/// inside a number as MSVC prints NaN and infinity (`-1.#IND00`,
/// `1.#QNAN`, `1.#INF`) is refused: read as a comment, it would turn the
/// value into -1 or 1.
pub(super) fn comment_start(line: &[u8]) -> Result<Option<usize>, String> {
    let Some(hash) = line.iter().position(|&b| b == b'#') else {
        return Ok(None);
    };
    let after = &line[hash + 1..];
    let msvc = hash >= 2
        && line[hash - 1] == b'.'
        && line[hash - 2].is_ascii_digit()
        && ["IND", "QNAN", "SNAN", "INF"].iter().any(|word| {
            after.len() >= word.len() && after[..word.len()].eq_ignore_ascii_case(word.as_bytes())
        });
    if msvc {
        let start = line[..hash]
            .iter()
            .rposition(u8::is_ascii_whitespace)
            .map_or(0, |i| i + 1);
        let end = after
            .iter()
            .position(u8::is_ascii_whitespace)
            .map_or(line.len(), |i| hash + 1 + i);
        return Err(format!(
            "`{}` is not a number (MSVC's printing of NaN or infinity)",
            String::from_utf8_lossy(&line[start..end])
        ));
    }
    Ok(Some(hash))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_order_marks_and_utf16_give_the_same_text() {
        let plain = "v 0 0 0\nf 1 2 3\n";
        let mut bom = vec![0xEF, 0xBB, 0xBF];
        bom.extend_from_slice(plain.as_bytes());
        assert_eq!(&*utf8_text(&bom), plain.as_bytes());
        for big_endian in [false, true] {
            let mut bytes = if big_endian {
                vec![0xFE, 0xFF]
            } else {
                vec![0xFF, 0xFE]
            };
            for unit in plain.encode_utf16() {
                bytes.extend(if big_endian {
                    unit.to_be_bytes()
                } else {
                    unit.to_le_bytes()
                });
            }
            assert_eq!(&*utf8_text(&bytes), plain.as_bytes());
        }
        assert_eq!(&*utf8_text(plain.as_bytes()), plain.as_bytes());
    }

    #[test]
    fn msvc_nan_is_refused_and_comments_are_found() {
        for line in [
            "v -1.#IND00 0 0",
            "Kd 1.#QNAN 0 0",
            "v 0 1.#INF 2",
            "Ns 1.#ind",
        ] {
            let e = comment_start(line.as_bytes()).unwrap_err();
            assert!(e.contains("is not a number (MSVC"), "{line}: {e}");
        }
        assert_eq!(
            comment_start(b"v -1.#IND00 0").unwrap_err(),
            "`-1.#IND00` is not a number (MSVC's printing of NaN or infinity)"
        );
        assert_eq!(comment_start(b"v 1 2 3 # 1.#INF").unwrap(), Some(8));
        assert_eq!(comment_start(b"v 1. #comment").unwrap(), Some(5));
        assert_eq!(comment_start(b"v 1 2 3").unwrap(), None);
    }
}
