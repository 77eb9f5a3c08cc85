//! The text of a tensor tree's `ScatteringData`: nested `{ … }`.
//!
//! A node is either 2^rank children, each in its own braces, or a grid of
//! 2^(rank·k) values (k ≥ 0) separated by blanks and/or commas. Child n
//! covers the upper half of dimension i when bit i of n is set; a grid is
//! row-major with dimension 0 slowest. A `}` may be followed by a comma.
//! The parser keeps an explicit stack (no recursion), reads each byte
//! once, and refuses trees deeper than [`MAX_DEPTH`] halvings.

use super::TreeCell;
use crate::klems::NEGATIVE_LIMIT;
use crate::read::number::{parse_f64, parse_prefix};

/// Halvings of the unit square beyond which a tree is refused: cells of
/// 2⁻²⁰ are far finer than any real file (bsdf2ttree's finest is 2⁻⁹)
/// and still exact in f64.
pub const MAX_DEPTH: u32 = 20;

/// What is wrong, at a byte offset of the text.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum TreeFault {
    /// A brace or the end is missing, or text follows the tree.
    Syntax(&'static str),
    /// A grid whose value count is not a power of 2^rank.
    Count(usize),
    /// A value that is not a finite number (the text, shortened).
    NotANumber(String),
    /// A value below −1e-3.
    Negative(f64),
    /// More than [`MAX_DEPTH`] halvings.
    TooDeep,
}

/// The cells of a tree, the small negative values read as 0, and the
/// deepest halving.
pub(super) struct ParsedTree {
    pub cells: Vec<TreeCell>,
    pub clipped: usize,
    pub depth: u32,
}

/// A branch node being read: its region and the next child to read.
struct Frame {
    min: [f64; 4],
    size: f64,
    depth: u32,
    next: usize,
}

fn skip_blanks(bytes: &[u8], mut pos: usize) -> usize {
    while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
        pos += 1;
    }
    pos
}

/// Skips blanks, one optional comma and blanks again.
fn skip_separator(bytes: &[u8], pos: usize) -> usize {
    let pos = skip_blanks(bytes, pos);
    if bytes.get(pos) == Some(&b',') {
        skip_blanks(bytes, pos + 1)
    } else {
        pos
    }
}

/// Parses a tree of `rank` (3 or 4) dimensions. Errors give the byte
/// offset in `text` of the fault.
pub(super) fn parse_tree(text: &str, rank: usize) -> Result<ParsedTree, (usize, TreeFault)> {
    let bytes = text.as_bytes();
    let mut out = ParsedTree {
        cells: Vec::new(),
        clipped: 0,
        depth: 0,
    };
    let mut stack: Vec<Frame> = Vec::new();
    // The node whose `{` comes next: its region.
    let mut pending = Some(([0.0; 4], 1.0, 0u32));
    let mut pos = 0;
    loop {
        if let Some((min, size, depth)) = pending.take() {
            pos = skip_blanks(bytes, pos);
            if bytes.get(pos) != Some(&b'{') {
                return Err((pos, TreeFault::Syntax("expected `{`")));
            }
            pos = skip_blanks(bytes, pos + 1);
            if bytes.get(pos) == Some(&b'{') {
                if depth >= MAX_DEPTH {
                    return Err((pos, TreeFault::TooDeep));
                }
                stack.push(Frame {
                    min,
                    size,
                    depth,
                    next: 0,
                });
            } else {
                pos = read_grid(bytes, pos, rank, (min, size, depth), &mut out)?;
                if stack.is_empty() {
                    break;
                }
            }
        }
        let Some(top) = stack.last_mut() else { break };
        if top.next < 1 << rank {
            let half = 0.5 * top.size;
            let mut min = top.min;
            for (i, m) in min.iter_mut().enumerate().take(rank) {
                if top.next >> i & 1 == 1 {
                    *m += half;
                }
            }
            pending = Some((min, half, top.depth + 1));
            top.next += 1;
            continue;
        }
        pos = skip_blanks(bytes, pos);
        if bytes.get(pos) != Some(&b'}') {
            return Err((pos, TreeFault::Syntax("expected `}` after the children")));
        }
        pos = skip_separator(bytes, pos + 1);
        stack.pop();
        if stack.is_empty() {
            break;
        }
    }
    pos = skip_blanks(bytes, pos);
    if pos < bytes.len() {
        return Err((pos, TreeFault::Syntax("text after the end of the tree")));
    }
    Ok(out)
}

/// Reads a grid's values from `pos` up to and past its `}`, appending its
/// cells; returns the position after it.
fn read_grid(
    bytes: &[u8],
    mut pos: usize,
    rank: usize,
    (min, size, depth): ([f64; 4], f64, u32),
    out: &mut ParsedTree,
) -> Result<usize, (usize, TreeFault)> {
    let start = pos;
    let first = out.cells.len();
    loop {
        while pos < bytes.len() && (bytes[pos].is_ascii_whitespace() || bytes[pos] == b',') {
            pos += 1;
        }
        match bytes.get(pos) {
            None => return Err((pos, TreeFault::Syntax("missing `}`"))),
            Some(b'}') => break,
            Some(b'{') => return Err((pos, TreeFault::Syntax("`{` among a grid's values"))),
            _ => {}
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b.is_ascii_whitespace() || b == b',' || b == b'}' || b == b'{')
            .map_or(bytes.len(), |n| pos + n);
        let token = std::str::from_utf8(&bytes[pos..end]).unwrap_or("");
        let value = match parse_prefix(&bytes[pos..end]) {
            Some((v, used)) if used == end - pos => Ok(v),
            _ => parse_f64(token),
        };
        let value = match value {
            Ok(v) if v.is_finite() => v,
            _ => {
                let shown: String = token.chars().take(40).collect();
                return Err((pos, TreeFault::NotANumber(shown)));
            }
        };
        let value = if value >= 0.0 {
            value
        } else if value >= NEGATIVE_LIMIT {
            out.clipped += 1;
            0.0
        } else {
            return Err((pos, TreeFault::Negative(value)));
        };
        out.cells.push(TreeCell { min, size, value });
        pos = end;
    }
    let n = out.cells.len() - first;
    // n = 2^(rank·k): k halvings of each dimension.
    let k =
        (0..=MAX_DEPTH).find(|&k| (rank as u32) * k < 64 && n as u64 == 1u64 << (rank as u32 * k));
    let Some(k) = k else {
        return Err((start, TreeFault::Count(n)));
    };
    if depth + k > MAX_DEPTH {
        return Err((start, TreeFault::TooDeep));
    }
    out.depth = out.depth.max(depth + k);
    let side = 1usize << k;
    let cell = size / side as f64;
    for (j, c) in out.cells[first..].iter_mut().enumerate() {
        for (i, (m, start)) in c.min.iter_mut().zip(min).enumerate().take(rank) {
            let index = (j >> ((rank - 1 - i) * k as usize)) & (side - 1);
            *m = start + index as f64 * cell;
        }
        c.size = cell;
    }
    Ok(skip_separator(bytes, pos + 1))
}
