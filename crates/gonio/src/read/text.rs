//! Bytes to text, and text to numbered lines.
//!
//! This module owns what both readers accept before any format rule
//! applies: a UTF-8 byte-order mark is dropped, a NUL byte means the file
//! is not text, and a line that is not valid UTF-8 is read as Latin-1
//! (Windows-1252 for bytes 0x80-0x9F). Instruments and lab PCs write header
//! comments such as `#Fläche 20°C` in the Windows code page; refusing
//! those files over a comment helped no one. Lines end at `\n`, `\r\n` or a
//! lone `\r` (classic Mac OS), and every line end counts for line numbers,
//! in error messages too.

use std::borrow::Cow;

/// The characters of Windows-1252 bytes 0x80-0x9F. Latin-1 has invisible
/// C1 control codes there, which no text editor writes; the five bytes
/// Windows-1252 leaves undefined keep their Latin-1 meaning.
const WINDOWS_1252_80_9F: [char; 32] = [
    '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8D}', 'Ž', '\u{8F}',
    '\u{90}', '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9D}', 'ž', 'Ÿ',
];

/// The character a single-byte (Latin-1 / Windows-1252) `byte` stands for.
fn latin1_char(byte: u8) -> char {
    match byte {
        0x80..=0x9F => WINDOWS_1252_80_9F[usize::from(byte - 0x80)],
        _ => char::from(byte),
    }
}

/// Decodes `bytes` as UTF-8, reading each line that is not valid UTF-8 as
/// Latin-1. Borrows when the whole input is UTF-8 (the usual case).
pub(crate) fn decode(bytes: &[u8]) -> Cow<'_, str> {
    if let Ok(text) = std::str::from_utf8(bytes) {
        return Cow::Borrowed(text);
    }
    // Line by line, so that a UTF-8 file with one Latin-1 line keeps its
    // UTF-8 characters. Splitting at `\n` alone is enough here: `\r` is
    // ASCII and decodes the same either way.
    let mut text = String::with_capacity(bytes.len() + bytes.len() / 8);
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            text.push('\n');
        }
        match std::str::from_utf8(line) {
            Ok(valid) => text.push_str(valid),
            Err(_) => text.extend(line.iter().map(|&b| latin1_char(b))),
        }
    }
    Cow::Owned(text)
}

/// The 1-based line number of byte `offset`, counting `\n`, `\r\n` and a
/// lone `\r` as one line end each (as [`Lines`] does).
pub(crate) fn line_number_at(bytes: &[u8], offset: usize) -> usize {
    let head = &bytes[..offset.min(bytes.len())];
    let line_feeds = head.iter().filter(|&&b| b == b'\n').count();
    // A `\r` directly before the offset may still be followed by `\n`.
    let lone_returns = head
        .iter()
        .enumerate()
        .filter(|&(i, &b)| b == b'\r' && bytes.get(i + 1) != Some(&b'\n'))
        .count();
    1 + line_feeds + lone_returns
}

/// The lines of a text with their 1-based numbers, line ends removed.
///
/// A line ends at `\n`, `\r\n` or a lone `\r`. Each step costs one scan of
/// the line: the next `\n` is found once and remembered, so a file with
/// only `\r` line ends is not rescanned line after line.
pub(crate) struct Lines<'a> {
    text: &'a str,
    pos: usize,
    number: usize,
    /// Offset of the next `\n` at or after `pos` (the text length when
    /// there is none); `None` until searched.
    next_line_feed: Option<usize>,
}

impl<'a> Lines<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        Self::resume(text, 0, 0)
    }

    /// The lines of `text` from byte `pos` (the start of a line), the
    /// first numbered `lines_before + 1`.
    pub(crate) fn resume(text: &'a str, pos: usize, lines_before: usize) -> Self {
        Self {
            text,
            pos,
            number: lines_before,
            next_line_feed: None,
        }
    }

    /// The byte offset where the next line starts.
    pub(crate) fn position(&self) -> usize {
        self.pos
    }

    /// Where the next `\n` was found (at or after some earlier position;
    /// the text's length when there is none), to hand to the next
    /// iterator over the same text ([`Lines::with_line_feed`]).
    pub(crate) fn line_feed(&self) -> Option<usize> {
        self.next_line_feed
    }

    /// Takes a [`Lines::line_feed`] of an earlier iterator over the same
    /// text; used only while it lies at or after the position.
    pub(crate) fn with_line_feed(mut self, line_feed: Option<usize>) -> Self {
        self.next_line_feed = line_feed;
        self
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a str);

    fn next(&mut self) -> Option<Self::Item> {
        let len = self.text.len();
        if self.pos >= len {
            return None;
        }
        let line_feed = match self.next_line_feed {
            Some(at) if at >= self.pos => at,
            _ => {
                let at = self.text[self.pos..]
                    .find('\n')
                    .map_or(len, |i| self.pos + i);
                self.next_line_feed = Some(at);
                at
            }
        };
        let segment = &self.text[self.pos..line_feed];
        let (end, next) = match segment.find('\r') {
            // `\r\n`: one line end.
            Some(i) if self.pos + i + 1 == line_feed && line_feed < len => {
                (self.pos + i, line_feed + 1)
            }
            // A lone `\r`.
            Some(i) => (self.pos + i, self.pos + i + 1),
            None => (line_feed, line_feed + 1),
        };
        let line = &self.text[self.pos..end];
        self.pos = next;
        self.number += 1;
        Some((self.number, line))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(text: &str) -> Vec<(usize, &str)> {
        Lines::new(text).collect()
    }

    #[test]
    fn every_line_end_counts_once() {
        assert_eq!(lines("a\nb\n"), [(1, "a"), (2, "b")]);
        assert_eq!(lines("a\r\nb\r\n"), [(1, "a"), (2, "b")]);
        assert_eq!(lines("a\rb\r"), [(1, "a"), (2, "b")]);
        assert_eq!(lines("a\rb"), [(1, "a"), (2, "b")]);
        assert_eq!(
            lines("a\r\rb\n\nc"),
            [(1, "a"), (2, ""), (3, "b"), (4, ""), (5, "c")]
        );
        assert_eq!(lines("a\r"), [(1, "a")]);
        assert_eq!(lines(""), []);
        let text = "a\r\nb\rc\n\rd";
        for (number, line) in lines(text) {
            let offset = line.as_ptr() as usize - text.as_ptr() as usize;
            assert_eq!(line_number_at(text.as_bytes(), offset), number, "{line}");
        }
    }

    #[test]
    fn latin1_lines_are_decoded() {
        assert!(matches!(
            decode(b"plain \xC3\xA4"),
            Cow::Borrowed("plain ä")
        ));
        assert_eq!(decode(b"#Fl\xE4che 20\xB0C\n1 2"), "#Fläche 20°C\n1 2");
        assert_eq!(decode(b"#\x80 \x93q\x94\n#\xC3\xA4"), "#€ “q”\n#ä");
    }
}
