//! The readers never panic: random bytes, and random mutations (line
//! deletions and duplications, byte flips, insertions, truncation) of real
//! excerpts. Whatever parses is also written, summarised and re-read.
//!
//! The pgII excerpts are cut from `../shared/data` at test time (the files
//! have no licence and are never copied into the repository).

use std::sync::OnceLock;

use brtf_gonio::{SourceFormat, read_bytes, read_bytes_as};
use proptest::prelude::*;

use crate::common::{mpc_fixture_text, pgii_path};

/// Header plus the first rows of each real scan, and the `.mpc` fixture.
fn excerpts() -> &'static [(String, Vec<u8>)] {
    static CELL: OnceLock<Vec<(String, Vec<u8>)>> = OnceLock::new();
    CELL.get_or_init(|| {
        let mut out = Vec::new();
        for name in ["golden_paper.txt", "layer_020_030.txt"] {
            let bytes = std::fs::read(pgii_path(name)).unwrap();
            // 30 header lines + 90 rows, CRLF kept where the file has it.
            let cut = bytes
                .iter()
                .enumerate()
                .filter(|(_, b)| **b == b'\n')
                .nth(119)
                .map_or(bytes.len(), |(i, _)| i + 1);
            let mut excerpt = bytes[..cut].to_vec();
            // Keep #datapoints_in_file consistent with the excerpt.
            let text = String::from_utf8(excerpt.clone()).unwrap();
            let fixed = text
                .lines()
                .map(|l| {
                    if l.starts_with("#datapoints_in_file") {
                        "#datapoints_in_file\t90".to_owned()
                    } else {
                        l.to_owned()
                    }
                })
                .collect::<Vec<_>>()
                .join("\n");
            excerpt = fixed.into_bytes();
            out.push((name.to_owned(), excerpt));
            // Without the row count, row deletions still parse, so the
            // writers and the summary get exercised on mutated data too.
            let uncounted: String = text
                .lines()
                .filter(|l| !l.starts_with("#datapoints_in_file"))
                .map(|l| format!("{l}\n"))
                .collect();
            out.push((format!("uncounted-{name}"), uncounted.into_bytes()));
        }
        out.push((
            "pab-aluA-st1:+30+0.mpc".to_owned(),
            mpc_fixture_text().into_bytes(),
        ));
        out
    })
}

#[test]
fn unmutated_excerpts_parse() {
    for (name, bytes) in excerpts() {
        let m = read_bytes(bytes, name).unwrap_or_else(|e| panic!("{e}"));
        assert!(m.len() >= 6);
    }
}

/// Reads `bytes` as both formats and, when that succeeds, writes, re-reads
/// and summarises the result. Any panic fails the property.
fn exercise(bytes: &[u8], name: &str) {
    let _ = read_bytes(bytes, name);
    for format in [SourceFormat::Mpc, SourceFormat::Mountain] {
        if let Ok(m) = read_bytes_as(bytes, name, format) {
            let text = brtf_gonio::to_mountain_string(&m);
            let again = read_bytes_as(text.as_bytes(), name, SourceFormat::Mountain)
                .expect("a written Mountain file reads back");
            assert_eq!(again.len(), m.len());
            if let Ok(mpc) = brtf_gonio::to_mpc_string(&m) {
                read_bytes_as(mpc.as_bytes(), name, SourceFormat::Mpc)
                    .expect("a written .mpc file reads back");
            }
            let _ = m.summary();
        }
    }
}

#[derive(Clone, Debug)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    FlipByte(usize, u8),
    InsertBytes(usize, Vec<u8>),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::FlipByte(i, b)),
        (
            any::<usize>(),
            prop::collection::vec(
                prop_oneof![
                    Just(b'\n'),
                    Just(b'\t'),
                    Just(b' '),
                    Just(b'#'),
                    Just(b'-'),
                    Just(b'e'),
                    Just(b'.'),
                    Just(b':'),
                    b'0'..=b'9',
                    any::<u8>()
                ],
                1..12
            )
        )
            .prop_map(|(i, v)| Mutation::InsertBytes(i, v)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn apply(bytes: &mut Vec<u8>, mutation: &Mutation) {
    if bytes.is_empty() {
        return;
    }
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(
            bytes
                .iter()
                .enumerate()
                .filter(|(_, b)| **b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .filter(|&i| i < bytes.len())
        .collect();
    let line_range = |k: usize| {
        let start = line_starts[k % line_starts.len()];
        let end = bytes[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| start + p + 1);
        start..end
    };
    match mutation {
        Mutation::DeleteLine(k) => {
            let r = line_range(*k);
            bytes.drain(r);
        }
        Mutation::DuplicateLine(k) => {
            let r = line_range(*k);
            let line = bytes[r.clone()].to_vec();
            bytes.splice(r.start..r.start, line);
        }
        Mutation::FlipByte(i, b) => {
            let n = bytes.len();
            bytes[i % n] ^= b | 1;
        }
        Mutation::InsertBytes(i, v) => {
            let at = i % (bytes.len() + 1);
            bytes.splice(at..at, v.iter().copied());
        }
        Mutation::Truncate(i) => {
            let n = bytes.len();
            bytes.truncate(i % n);
        }
    }
}

// 256 cases each by default; set PROPTEST_CASES for a longer run.
proptest! {
    #[test]
    fn random_bytes_never_panic(
        bytes in prop::collection::vec(any::<u8>(), 0..400),
        name in prop_oneof![Just("r.txt"), Just("r:+15+0.mpc"), Just("")],
    ) {
        exercise(&bytes, name);
    }

    #[test]
    fn random_text_lines_never_panic(
        lines in prop::collection::vec("[#0-9eE+\\-. \t:a-z\\[\\]\"]{0,30}", 0..30),
    ) {
        let text = lines.join("\n");
        exercise(text.as_bytes(), "lines:+10+0.mpc");
        exercise(text.as_bytes(), "lines.txt");
    }

    #[test]
    fn mutated_real_excerpts_never_panic(
        which in 0usize..5,
        mutations in prop::collection::vec(mutation(), 1..6),
    ) {
        let (name, original) = &excerpts()[which];
        let mut bytes = original.clone();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        exercise(&bytes, name);
    }

    #[test]
    fn programmatic_round_trip_is_exact(
        rows in prop::collection::vec(
            (0.0f64..=180.0, -180.0f64..360.0, prop::array::uniform3(prop_oneof![
                Just(f64::NAN), -1e3f64..1e3, -1e-300f64..1e-300, any::<f64>().prop_filter("finite", |v| v.is_finite() && v.abs() < 1e37)
            ])),
            1..50,
        ),
        xyz in any::<bool>(),
    ) {
        use brtf_gonio::{Channels, Incidence, Measurement, Quantity, Sample, normalize_phi_deg};
        let channels = if xyz { Channels::Xyz } else { Channels::Y };
        let samples: Vec<Sample> = rows
            .iter()
            .map(|&(t, p, v)| {
                let values = if xyz { v } else { [v[0], 0.0, 0.0] };
                Sample::new(t, normalize_phi_deg(p), values)
            })
            .collect();
        let m = Measurement::new(
            SourceFormat::Mountain, Incidence::new(10.0, 0.0), Quantity::Dsf, channels, samples,
        );
        let back = brtf_gonio::read_str(&brtf_gonio::to_mountain_string(&m), "p.txt").unwrap();
        crate::common::assert_samples_identical(&back.samples, &m.samples);
        if !xyz {
            let mut bsdf = m.clone();
            bsdf.quantity = Quantity::Bsdf;
            let mpc = brtf_gonio::to_mpc_string(&bsdf).unwrap();
            let back = brtf_gonio::read_str(&mpc, "p.mpc").unwrap();
            crate::common::assert_samples_identical(&back.samples, &bsdf.samples);
        }
    }
}
