//! Mutations: how a seed becomes a broken file.
//!
//! Each mutation imitates a way real files go wrong (a bad disk byte, a
//! cut-off transfer, an editor that reorders or duplicates lines, another
//! platform's line ends or code page, a spreadsheet that writes `NaN` or
//! `1e308`), plus the edits that reach deep into a parser: header lines
//! with extreme values and format keys in the wrong place.

use brtf_model::Rng;

use crate::seeds::Target;

/// Inputs never grow beyond this (a whole 4 MB scan plus room), so memory
/// use measures the parsers, not the mutator.
const MAX_INPUT_BYTES: usize = 8 << 20;
/// At most this many bytes of copies when a line is duplicated many times.
const MAX_DUPLICATED_BYTES: usize = 1 << 20;

/// The kinds of mutation, for reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// One bit flipped.
    FlipBit,
    /// One byte replaced by a byte that matters to a parser.
    SetByte,
    /// A few bytes inserted.
    InsertBytes,
    /// A few bytes deleted.
    DeleteBytes,
    /// The file cut off.
    Truncate,
    /// A line deleted.
    DeleteLine,
    /// A line duplicated (sometimes many times).
    DuplicateLine,
    /// Two lines swapped, or a run of lines shuffled.
    ShuffleLines,
    /// A number replaced with NaN, infinity, 1e308, -0, a huge integer…
    ExtremeNumber,
    /// A header line added, changed or deleted.
    HeaderEdit,
    /// Line ends converted (LF, CRLF, CR-only) or mixed.
    LineEnds,
    /// A Latin-1 / Windows-1252 byte put into a line.
    Latin1,
    /// A piece of another seed spliced in.
    Splice,
    /// A very long token or a repeated chunk.
    Grow,
}

impl Kind {
    /// Every kind, in report order.
    pub const ALL: [Kind; 14] = [
        Kind::FlipBit,
        Kind::SetByte,
        Kind::InsertBytes,
        Kind::DeleteBytes,
        Kind::Truncate,
        Kind::DeleteLine,
        Kind::DuplicateLine,
        Kind::ShuffleLines,
        Kind::ExtremeNumber,
        Kind::HeaderEdit,
        Kind::LineEnds,
        Kind::Latin1,
        Kind::Splice,
        Kind::Grow,
    ];
}

/// Replacement numbers: the values that break naive parsers.
const EXTREME_NUMBERS: [&str; 32] = [
    "NaN",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "infinity",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e309",
    "-1e309",
    "4.9e-324",
    "1e-400",
    "-0",
    "-0.0",
    "0",
    "18446744073709551616",
    "18446744073709551615",
    "-9223372036854775809",
    "99999999999999999999999999999999999999",
    "9.9e+37",
    "-9.9e+37",
    "1e37",
    "180.0000001",
    "-90",
    "720",
    "1,5",
    "0x10",
    "1e",
    ".",
    "-",
    "",
];

/// Replacements for JSON values: wrong types as well as extreme numbers.
const JSON_VALUES: [&str; 8] = ["null", "true", "\"\"", "\"x\"", "[]", "{}", "[1e308]", "-1"];

/// Bytes inserted or set: separators, signs, comment and key characters,
/// quotes and brackets, line ends, NUL, and non-ASCII.
const INTERESTING_BYTES: &[u8] =
    b"\n\r\t #:-+.eE0123456789\"[]{},!\x00\x0b\x0c\x7f\xa0\xb0\xe4\xff";

/// Header lines for the measurement formats, with values chosen to hit
/// every branch of the header parsers.
const GONIO_HEADER_LINES: &[&str] = &[
    "#intheta 1e308",
    "#intheta -0",
    "#intheta nan",
    "#intheta 95",
    "#intheta",
    "#inphi 1e308",
    "#inphi -720",
    "#incident_angle 30",
    "#incident_angle 200 0",
    "#upphi inf",
    "#format: theta phi",
    "#format: theta phi []",
    "#format: theta phi [",
    "#format: theta phi DSF BSDF",
    "#format: theta phi BTDF BTDF BTDF",
    "#format: phi theta DSF",
    "#colorimetry: CIE-XYZ",
    "#colorimetry: CIE-Y",
    "#colorimetry: RGB",
    "#datapoints_in_file 18446744073709551615",
    "#datapoints_in_file 18446744073709551616",
    "#datapoints_in_file -1",
    "#datapoints_in_file 0",
    "#sample_name \"",
    "#sample_name",
    "#beam_integral 0",
    "#beam_integral -1e308",
    "#incident angle theta [degree]:",
    "#incident angle phi [degree]:",
    "#incident angle theta [degree]: 1e309",
    "#incident angle theta [degree]: 400",
    "#using beam file:",
    "#using beam file: x nan",
    "#using beam file: x 1e308",
    "#theta phi beam-ref org-data minus-background/beam-ref cosine-out-corrected brtf voronoi-cell-size",
    "#",
    "#:",
    "30",
    "nan",
    "1e308",
    "-180",
];

/// Primitive texts for `.rad` files: every material type, odd argument
/// counts, extreme arguments, aliases, commands and comments.
const RAD_LINES: &[&str] = &[
    "void plastic p 0 0 5 0.5 0.5 0.5 0.05 0.1",
    "void metal m 0 0 5 0.9 0.9 0.9 0.9 0",
    "void trans t 0 0 7 0.5 0.5 0.5 0.05 0.1 0.5 0.1",
    "void plastic2 p2 4 0 1 0 . 0 6 0.5 0.5 0.5 0.05 0.1 0.2",
    "void metal2 m2 4 1e308 nan 0 . 0 6 0.5 0.5 0.5 0.9 0.1 0.2",
    "void trans2 t2 4 0 0 1 . 0 8 0.5 0.5 0.5 0.05 0.1 0.2 0.5 0.1",
    "void plastic p 0 0 5 -1 1e308 -0 1 -0.5",
    "void plastic p 0 0 18446744073709551616",
    "void plastic p 0 0 -1",
    "void plastic p 0 1 1 5 1 1 1 0 0",
    "void alias a p",
    "void alias a",
    "p alias b void",
    "inherit alias c p",
    "void light l 0 0 3 1e308 1e308 1e308",
    "void polygon g 0 0 9 0 0 0 1 0 0 0 1 0",
    "!xform -s 2 object.rad",
    "# a comment",
    "void",
    "void plastic",
    "void plastic p",
    "void plastic p 0",
    "void plastic p 0 0",
    "void plastic p 999999999999 0 0",
];

/// Uniform in `0..n` (`n > 0`).
pub(crate) fn below(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u64() % n as u64) as usize
}

/// Applies one random mutation to `bytes`. `other` is another seed of the
/// same target, for splicing. Returns what was done.
pub fn mutate(bytes: &mut Vec<u8>, target: Target, other: &[u8], rng: &mut Rng) -> Kind {
    let kind = Kind::ALL[below(rng, Kind::ALL.len())];
    apply(kind, bytes, target, other, rng);
    if bytes.len() > MAX_INPUT_BYTES {
        bytes.truncate(MAX_INPUT_BYTES);
    }
    kind
}

fn apply(kind: Kind, bytes: &mut Vec<u8>, target: Target, other: &[u8], rng: &mut Rng) {
    let len = bytes.len();
    match kind {
        Kind::FlipBit => {
            if len > 0 {
                let at = below(rng, len);
                bytes[at] ^= 1 << below(rng, 8);
            }
        }
        Kind::SetByte => {
            if len > 0 {
                let at = below(rng, len);
                bytes[at] = interesting_byte(rng);
            }
        }
        Kind::InsertBytes => {
            let at = below(rng, len + 1);
            let run: Vec<u8> = (0..1 + below(rng, 12))
                .map(|_| interesting_byte(rng))
                .collect();
            bytes.splice(at..at, run);
        }
        Kind::DeleteBytes => {
            if len > 0 {
                let at = below(rng, len);
                let end = (at + 1 + below(rng, 16)).min(len);
                bytes.drain(at..end);
            }
        }
        Kind::Truncate => {
            if len > 0 {
                bytes.truncate(below(rng, len));
            }
        }
        Kind::DeleteLine => {
            if let Some(range) = random_line(bytes, rng) {
                bytes.drain(range);
            }
        }
        Kind::DuplicateLine => {
            if let Some(range) = random_line(bytes, rng) {
                let line = bytes[range.clone()].to_vec();
                // Mostly once; sometimes a block of thousands of copies.
                let copies = if below(rng, 8) == 0 {
                    (1 + below(rng, 5000)).min(MAX_DUPLICATED_BYTES / line.len().max(1))
                } else {
                    1
                };
                let block: Vec<u8> = line
                    .iter()
                    .copied()
                    .cycle()
                    .take(line.len() * copies)
                    .collect();
                bytes.splice(range.start..range.start, block);
            }
        }
        Kind::ShuffleLines => shuffle_lines(bytes, rng),
        Kind::ExtremeNumber => {
            if let Some(range) = random_number(bytes, rng) {
                let replacement = if target == Target::FitJson && below(rng, 3) == 0 {
                    JSON_VALUES[below(rng, JSON_VALUES.len())]
                } else {
                    EXTREME_NUMBERS[below(rng, EXTREME_NUMBERS.len())]
                };
                bytes.splice(range, replacement.bytes());
            }
        }
        Kind::HeaderEdit => header_edit(bytes, target, rng),
        Kind::LineEnds => {
            let text = std::mem::take(bytes);
            let lf: Vec<u8> = replace_all(&text, b"\r\n", b"\n");
            *bytes = match below(rng, 4) {
                0 => replace_all(&lf, b"\n", b"\r"),
                1 => replace_all(&lf, b"\n", b"\r\n"),
                2 => lf,
                // One line end changed: mixed line ends.
                _ => {
                    let mut mixed = text;
                    if let Some(range) = random_line(&mixed, rng)
                        && mixed[..range.end].ends_with(b"\n")
                    {
                        let end = [b"\r".as_slice(), b"\r\n", b"\n\r", b"\r\r\n"][below(rng, 4)];
                        mixed.splice(range.end - 1..range.end, end.iter().copied());
                    }
                    mixed
                }
            };
        }
        Kind::Latin1 => {
            if let Some(range) = random_line(bytes, rng) {
                let at = range.start + below(rng, range.len().max(1)).min(range.len());
                let byte = 0x80 + below(rng, 0x80) as u8;
                bytes.insert(at.min(bytes.len()), byte);
            }
        }
        Kind::Splice => {
            if !other.is_empty() {
                let start = below(rng, other.len());
                let end = (start + 1 + below(rng, 512)).min(other.len());
                let at = below(rng, len + 1);
                bytes.splice(at..at, other[start..end].iter().copied());
            }
        }
        Kind::Grow => {
            let at = below(rng, len + 1);
            let filler: Vec<u8> = match below(rng, 4) {
                0 => std::iter::repeat_n(b'9', 1 + below(rng, 100_000)).collect(),
                1 => std::iter::repeat_n(b' ', 1 + below(rng, 100_000)).collect(),
                2 => std::iter::repeat_n(b'\n', 1 + below(rng, 100_000)).collect(),
                _ => {
                    let start = below(rng, len.max(1));
                    let end = (start + 1 + below(rng, 64)).min(len);
                    let chunk = &bytes[start.min(end)..end];
                    chunk
                        .iter()
                        .copied()
                        .cycle()
                        .take(chunk.len() * below(rng, 4096))
                        .collect()
                }
            };
            bytes.splice(at..at, filler);
        }
    }
}

fn interesting_byte(rng: &mut Rng) -> u8 {
    if below(rng, 4) == 0 {
        rng.next_u64() as u8
    } else {
        INTERESTING_BYTES[below(rng, INTERESTING_BYTES.len())]
    }
}

/// The byte range of a random line, its `\n` included.
fn random_line(bytes: &[u8], rng: &mut Rng) -> Option<std::ops::Range<usize>> {
    if bytes.is_empty() {
        return None;
    }
    // A random byte's line: long lines are picked more often, which is
    // fine, and no index of all lines is needed for a 4 MB file.
    let at = below(rng, bytes.len());
    let start = bytes[..at]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let end = bytes[at..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| at + i + 1);
    Some(start..end)
}

/// Swaps two nearby lines, or shuffles a run of up to 8 lines.
fn shuffle_lines(bytes: &mut Vec<u8>, rng: &mut Rng) {
    let Some(first) = random_line(bytes, rng) else {
        return;
    };
    let mut lines: Vec<Vec<u8>> = Vec::new();
    let mut end = first.start;
    for _ in 0..2 + below(rng, 7) {
        if end >= bytes.len() {
            break;
        }
        let next = bytes[end..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| end + i + 1);
        lines.push(bytes[end..next].to_vec());
        end = next;
    }
    // A line without its `\n` (the last one) keeps the file's last place.
    if lines.last().is_some_and(|l| !l.ends_with(b"\n")) {
        let last = lines.len() - 1;
        lines[last].push(b'\n');
    }
    for i in (1..lines.len()).rev() {
        lines.swap(i, below(rng, i + 1));
    }
    bytes.splice(first.start..end, lines.concat());
}

/// The byte range of a random number-like token.
fn random_number(bytes: &[u8], rng: &mut Rng) -> Option<std::ops::Range<usize>> {
    if bytes.is_empty() {
        return None;
    }
    let is_number_byte =
        |b: u8| b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e' | b'E');
    // The first digit at or after a random place (wrapping around once).
    let at = below(rng, bytes.len());
    let digit = bytes[at..]
        .iter()
        .position(u8::is_ascii_digit)
        .map(|i| at + i)
        .or_else(|| bytes[..at].iter().position(u8::is_ascii_digit))?;
    let start = bytes[..digit]
        .iter()
        .rposition(|&b| !is_number_byte(b))
        .map_or(0, |i| i + 1);
    let end = bytes[digit..]
        .iter()
        .position(|&b| !is_number_byte(b))
        .map_or(bytes.len(), |i| digit + i);
    Some(start..end)
}

/// Adds, changes or removes a header line (for `.rad`: a primitive).
fn header_edit(bytes: &mut Vec<u8>, target: Target, rng: &mut Rng) {
    let pool: &[&str] = match target {
        Target::Rad => RAD_LINES,
        Target::FitJson => &[
            "\"schema\": 1,",
            "\"schema\": 18446744073709551616,",
            "\"schema\": -0,",
            "\"incidences\": [],",
            "\"table\": null,",
            "\"global\": null,",
            "\"kind\": \"metal2\",",
            "\"theta_in\": 1e308,",
        ],
        _ => GONIO_HEADER_LINES,
    };
    let line = pool[below(rng, pool.len())];
    // Mostly among the first lines, where headers live.
    let header_end = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(40)
        .map_or(bytes.len(), |(i, _)| i + 1);
    let at = below(rng, header_end + 1);
    let at = bytes[..at]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    match below(rng, 3) {
        // Replace the line there.
        0 => {
            let end = bytes[at..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |i| at + i);
            bytes.splice(at..end, line.bytes());
        }
        // Insert before it.
        _ => {
            let mut text = line.as_bytes().to_vec();
            text.push(b'\n');
            bytes.splice(at..at, text);
        }
    }
}

fn replace_all(text: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(text.len() + text.len() / 16);
    let mut i = 0;
    while i < text.len() {
        if text[i..].starts_with(from) {
            out.extend_from_slice(to);
            i += from.len();
        } else {
            out.push(text[i]);
            i += 1;
        }
    }
    out
}
