//! Readers: the real pgII scans, the seed's `.mpc` excerpt, every format
//! quirk of the spec, and broken files with `file:line` errors.

use std::path::Path;

use brtf_gonio::{
    Channels, IncidenceOrigin, ParseErrorKind, Quantity, ReadError, SourceFormat, detect_format,
    read_bytes, read_bytes_as, read_path, read_str,
};

use crate::common::{
    MPC_FIXTURE, angle_between_deg, fixture_path, golden, layer, mpc_fixture_text, pgii_path,
};

// ---------------------------------------------------------------- real data

#[test]
fn golden_paper_parses_completely() {
    let m = golden();
    assert_eq!(m.format, SourceFormat::Mountain);
    assert_eq!(m.len(), 127_039);
    assert_eq!(m.incidence.theta_deg, 26.8421);
    assert_eq!(m.incidence.phi_deg, 0.0);
    assert_eq!(m.incidence_origin, IncidenceOrigin::Header);
    assert_eq!(
        m.quantity,
        Quantity::Raw {
            unit: "uA".into(),
            beam_integral: None
        }
    );
    assert_eq!(m.channels, Channels::Y);
    assert_eq!(m.sample_name.as_deref(), Some("Golden_glossy_paper"));
    assert_eq!(
        m.count_negative(),
        368,
        "README: 368 slightly negative values"
    );
    assert_eq!(m.count_unavailable(), 0);
    assert_eq!(m.header.len(), 30);
    assert!(m.header.iter().all(|l| !l.ends_with('\r')), "CR stripped");
    assert!(m.samples.iter().all(|s| (0.0..360.0).contains(&s.phi_deg)));
    assert!(m.samples.iter().all(|s| s.theta_deg <= 90.0));
    // First row, verbatim: 89.98829 44.44809 2.138e-06.
    let first = m.samples[0];
    assert_eq!((first.theta_deg, first.phi_deg), (89.98829, 44.44809));
    assert_eq!(first.values, [2.138e-06, 0.0, 0.0]);
}

#[test]
fn golden_paper_peak_is_near_the_mirror_direction() {
    let peak = golden().front_peak().unwrap();
    let off = angle_between_deg((peak.theta_deg, peak.phi_deg), (26.99, 175.8));
    assert!(off < 0.5, "peak at {peak:?}, {off} deg from (26.99, 175.8)");
    let mirror = angle_between_deg((peak.theta_deg, peak.phi_deg), (26.8421, 180.0));
    assert!(mirror < 5.0, "peak {mirror} deg from the mirror direction");
}

#[test]
fn layer_parses_completely() {
    let m = layer();
    assert_eq!(m.len(), 126_567);
    assert_eq!(m.incidence.theta_deg, 31.3158);
    assert_eq!(m.incidence.phi_deg, 0.0);
    assert_eq!(m.sample_name.as_deref(), Some("Layered:_#20_on_top_of_#30"));
    assert!(matches!(&m.quantity, Quantity::Raw { unit, .. } if unit == "uA"));
    let peak = m.front_peak().unwrap();
    let off = angle_between_deg((peak.theta_deg, peak.phi_deg), (36.7, 179.9));
    assert!(off < 1.0, "peak at {peak:?}, {off} deg from (36.7, 179.9)");
}

#[test]
fn bytes_and_path_entry_points_agree() {
    let path = pgii_path("layer_020_030.txt");
    let bytes = std::fs::read(&path).unwrap();
    let from_bytes = read_bytes(&bytes, &path).unwrap();
    assert_eq!(&from_bytes, layer());
    let from_str = read_str(std::str::from_utf8(&bytes).unwrap(), "layer.txt").unwrap();
    assert_eq!(from_str.samples, layer().samples);
}

// ---------------------------------------------------------------- .mpc

#[test]
fn seed_mpc_excerpt_parses() {
    let m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    assert_eq!(m.format, SourceFormat::Mpc);
    assert_eq!((m.incidence.theta_deg, m.incidence.phi_deg), (30.0, 0.0));
    assert_eq!(m.incidence_origin, IncidenceOrigin::Header);
    let beam = m.beam.as_ref().unwrap();
    assert_eq!(beam.integral, 0.063626);
    assert_eq!(beam.file, "pab-aluA-st1:beam.mpc.refint");
    assert_eq!(m.quantity, Quantity::Bsdf);
    assert_eq!(m.len(), 6);
    assert_eq!(m.header.len(), 14, "13 header lines + the bare value `30`");
    assert_eq!(m.header[8], "30");
    assert_eq!(m.header[10], "#0");
    // Back-hemisphere rows with negative BRTF and a sentinel beam-ref.
    let s = m.samples[0];
    assert_eq!((s.theta_deg, s.phi_deg), (95.5176, 119.535));
    assert_eq!(s.values[0], -0.00263091);
    assert_eq!(s.solid_angle_sr, Some(0.0351119));
    assert!(
        m.mpc_columns[0].beam_reference.is_nan(),
        "9.9e+37 is not available"
    );
    assert_eq!(m.mpc_columns[0].raw_signal, 5.14761e-06);
    assert_eq!(m.mpc_columns[5].cosine_corrected, 0.00150389);
    assert_eq!(m.count_in(brtf_gonio::Hemisphere::Back), 6);
    assert_eq!(m.count_negative(), 5);
    assert_eq!(m.count_unavailable(), 0, "the BRTF column has no sentinel");
}

#[test]
fn mpc_incidence_from_the_file_name_when_the_header_lacks_it() {
    let text: String = mpc_fixture_text()
        .lines()
        .filter(|l| !l.starts_with("#incident") && *l != "30" && *l != "#0")
        .map(|l| format!("{l}\n"))
        .collect();
    let m = read_str(&text, "pab-xenon-aluA-elox1-b:+15+0.mpc").unwrap();
    assert_eq!((m.incidence.theta_deg, m.incidence.phi_deg), (15.0, 0.0));
    assert_eq!(m.incidence_origin, IncidenceOrigin::FileName);
}

#[test]
fn mpc_header_fills_one_angle_and_name_the_other() {
    let text: String = mpc_fixture_text()
        .lines()
        .filter(|l| !l.starts_with("#incident angle phi") && *l != "#0")
        .map(|l| format!("{l}\n"))
        .collect();
    let m = read_str(&text, "x:+30+90.mpc").unwrap();
    assert_eq!((m.incidence.theta_deg, m.incidence.phi_deg), (30.0, 90.0));
}

#[test]
fn mpc_one_line_incidence_and_bare_phi() {
    let text = "#incident angle theta [degree]: 45\n#incident angle phi [degree]:\n90\n\
                10 20 1 2 3 4 0.5 0.01\n";
    let m = read_bytes_as(text.as_bytes(), "noname.mpc", SourceFormat::Mpc).unwrap();
    assert_eq!((m.incidence.theta_deg, m.incidence.phi_deg), (45.0, 90.0));
    assert!(m.beam.is_none());
}

#[test]
fn mpc_sentinel_in_brtf_and_cell_columns() {
    let text = "#incident angle theta [degree]:\n0\n#incident angle phi [degree]:\n#0\n\
                10 20 1 2 3 4 9.9e+37 9.9e+37\n";
    let m = read_bytes_as(text.as_bytes(), "s.mpc", SourceFormat::Mpc).unwrap();
    assert!(m.samples[0].values[0].is_nan());
    assert_eq!(m.samples[0].solid_angle_sr, None);
    assert_eq!(m.count_unavailable(), 1);
}

// ---------------------------------------------------------------- Mountain

const MOUNTAIN_MIN: &str = "#intheta 30\n#inphi 0\n#format: theta phi BSDF\n";

#[test]
fn mountain_accepts_tabs_spaces_and_crlf() {
    let text = "#sample_name \"two words\"\r\n#incident_angle\t30 \t 0\r\n\
                #format: theta\tphi\tDSF\r\n10\t20 0.5\r\n  30 \t 40\t0.25  \r\n\r\n";
    let m = read_str(text, "crlf.txt").unwrap();
    assert_eq!(m.len(), 2);
    assert_eq!(m.quantity, Quantity::Dsf);
    assert_eq!(m.sample_name.as_deref(), Some("two words"));
    assert_eq!(
        (m.samples[1].theta_deg, m.samples[1].values[0]),
        (30.0, 0.25)
    );
    assert_eq!(m.header[0], "#sample_name \"two words\"");
}

#[test]
fn mountain_quantities() {
    for (word, expected) in [
        ("DSF", Quantity::Dsf),
        ("BSDF", Quantity::Bsdf),
        ("BRDF", Quantity::Bsdf),
        ("BTDF", Quantity::Bsdf),
        (
            "[uA]",
            Quantity::Raw {
                unit: "uA".into(),
                beam_integral: None,
            },
        ),
    ] {
        let text = format!("#intheta 0\n#inphi 0\n#format: theta phi {word}\n10 20 1\n");
        assert_eq!(
            read_str(&text, "q.txt").unwrap().quantity,
            expected,
            "{word}"
        );
    }
}

#[test]
fn mountain_xyz_upphi_and_negative_phi() {
    let text = "#intheta 20\n#inphi -90\n#upphi 90\n#colorimetry: CIE-XYZ\n\
                #datapoints_in_file 2\n#format: theta phi BSDF\n\
                10 -179.5 0.1 0.2 0.3\n120 180 -0.01 9.9e+37 0.5\n";
    let m = read_str(text, "xyz.txt").unwrap();
    assert_eq!(m.channels, Channels::Xyz);
    assert_eq!(m.incidence.phi_deg, 270.0, "phi normalised to [0, 360)");
    assert_eq!(m.up_phi_deg, 90.0);
    assert_eq!(m.samples[0].phi_deg, 180.5);
    assert_eq!(m.samples[1].phi_deg, 180.0);
    assert_eq!(m.samples[0].values, [0.1, 0.2, 0.3]);
    assert_eq!(m.luminance_of(&m.samples[0]), 0.2);
    assert!(m.samples[1].values[1].is_nan());
    assert_eq!(m.count_unavailable(), 1);
    assert_eq!(m.count_negative(), 1);
    assert_eq!(m.count_in(brtf_gonio::Hemisphere::Back), 1);
}

#[test]
fn mountain_back_lit_incidence() {
    let text = "#intheta 150\n#inphi 0\n#format: theta phi BSDF\n170 0 1\n";
    let m = read_str(text, "back.txt").unwrap();
    assert_eq!(m.incidence.theta_deg, 150.0);
    assert!(m.incident_direction().z < 0.0);
}

#[test]
fn format_detection() {
    let mpc = mpc_fixture_text();
    assert_eq!(
        detect_format(mpc.as_bytes(), Path::new("a.mpc")),
        SourceFormat::Mpc
    );
    assert_eq!(
        detect_format(mpc.as_bytes(), Path::new("a.txt")),
        SourceFormat::Mpc
    );
    assert_eq!(
        detect_format(MOUNTAIN_MIN.as_bytes(), Path::new("a.txt")),
        SourceFormat::Mountain
    );
    assert_eq!(
        detect_format(b"1 2 3 4 5 6 7 8\n", Path::new("a")),
        SourceFormat::Mpc
    );
    assert_eq!(
        detect_format(b"1 2 3\n", Path::new("a")),
        SourceFormat::Mountain
    );
}

// ---------------------------------------------------------------- errors

/// Asserts a parse error of the expected kind whose message names the file
/// and the line, and returns the message.
pub(crate) fn expect_error(
    result: Result<brtf_gonio::Measurement, ReadError>,
    name: &str,
    line: usize,
    is_kind: impl Fn(&ParseErrorKind) -> bool,
) -> String {
    let err = result.expect_err("the input is broken");
    let message = err.to_string();
    assert!(is_kind(err.kind().unwrap()), "unexpected kind: {message}");
    assert_eq!(err.line(), Some(line), "{message}");
    assert!(
        message.starts_with(&format!("{name}:{line}: ")),
        "message must start with `{name}:{line}: `, got `{message}`"
    );
    message
}

#[test]
fn truncated_row() {
    let text = format!("{MOUNTAIN_MIN}10 20 1\n10 2");
    let msg = expect_error(read_str(&text, "cut.txt"), "cut.txt", 5, |k| {
        matches!(
            k,
            ParseErrorKind::ColumnCount {
                expected: 3,
                found: 2,
                ..
            }
        )
    });
    assert!(
        msg.contains("expected 3 columns (theta phi value), found 2"),
        "{msg}"
    );
}

#[test]
fn wrong_column_count_mountain_and_mpc() {
    let text = format!("{MOUNTAIN_MIN}10 20 1 4\n");
    expect_error(read_str(&text, "wide.txt"), "wide.txt", 4, |k| {
        matches!(k, ParseErrorKind::ColumnCount { found: 4, .. })
    });
    let mut mpc = mpc_fixture_text();
    mpc.push_str("98.0 130.0 1 2 3 4 5\n");
    let msg = expect_error(read_str(&mpc, "seven.mpc"), "seven.mpc", 21, |k| {
        matches!(
            k,
            ParseErrorKind::ColumnCount {
                expected: 8,
                found: 7,
                ..
            }
        )
    });
    assert!(msg.contains("voronoi-cell-size"), "{msg}");
}

#[test]
fn text_in_numbers() {
    let text = format!("{MOUNTAIN_MIN}10 20 1\n10 2O 1\n");
    let msg = expect_error(read_str(&text, "typo.txt"), "typo.txt", 5, |k| {
        matches!(k, ParseErrorKind::NotANumber { column: 2, .. })
    });
    assert!(msg.contains("`2O`"), "{msg}");
    let mut mpc = mpc_fixture_text();
    mpc = mpc.replace("0.0351942", "0.035l942");
    expect_error(read_str(&mpc, "typo.mpc"), "typo.mpc", 16, |k| {
        matches!(k, ParseErrorKind::NotANumber { column: 8, .. })
    });
}

#[test]
fn nan_and_inf_are_reported_by_line() {
    for bad in ["nan", "NaN", "inf", "-infinity", "1e999"] {
        let text = format!("{MOUNTAIN_MIN}10 20 1\n10 20 {bad}\n");
        expect_error(read_str(&text, "nan.txt"), "nan.txt", 5, |k| {
            matches!(k, ParseErrorKind::NonFinite { column: 3, .. })
        });
    }
}

#[test]
fn theta_out_of_range() {
    let text = format!("{MOUNTAIN_MIN}190 20 1\n");
    expect_error(read_str(&text, "t.txt"), "t.txt", 4, |k| {
        matches!(k, ParseErrorKind::AngleOutOfRange { .. })
    });
}

#[test]
fn incidence_out_of_range() {
    let text = "#intheta 200\n#inphi 0\n#format: theta phi BSDF\n10 20 1\n";
    expect_error(read_str(text, "big.txt"), "big.txt", 1, |k| {
        matches!(
            k,
            ParseErrorKind::AngleOutOfRange {
                what: "theta_in",
                ..
            }
        )
    });
    // A signed in-plane angle flips the azimuth.
    let text = "#intheta -20\n#inphi 0\n#format: theta phi BSDF\n10 20 1\n";
    let m = read_str(text, "neg.txt").unwrap();
    assert_eq!((m.incidence.theta_deg, m.incidence.phi_deg), (20.0, 180.0));
}

#[test]
fn missing_incidence() {
    let text = "#format: theta phi BSDF\n10 20 1\n";
    let msg = expect_error(read_str(text, "noinc.txt"), "noinc.txt", 2, |k| {
        matches!(
            k,
            ParseErrorKind::MissingIncidence {
                missing: "theta",
                ..
            }
        )
    });
    assert!(msg.contains("#intheta"), "{msg}");
    let text = "#intheta 10\n#format: theta phi BSDF\n10 20 1\n";
    expect_error(read_str(text, "nophi.txt"), "nophi.txt", 3, |k| {
        matches!(k, ParseErrorKind::MissingIncidence { missing: "phi", .. })
    });
    let mpc: String = mpc_fixture_text()
        .lines()
        .filter(|l| !l.starts_with("#incident") && *l != "30" && *l != "#0")
        .map(|l| format!("{l}\n"))
        .collect();
    expect_error(read_str(&mpc, "plain.mpc"), "plain.mpc", 11, |k| {
        matches!(k, ParseErrorKind::MissingIncidence { .. })
    });
}

#[test]
fn conflicting_name_and_header() {
    let msg = expect_error(
        read_str(&mpc_fixture_text(), "pab-aluA-st1:+45+0.mpc"),
        "pab-aluA-st1:+45+0.mpc",
        9,
        |k| matches!(k, ParseErrorKind::IncidenceConflict { .. }),
    );
    assert!(
        msg.contains("theta = 30") && msg.contains("theta = 45"),
        "{msg}"
    );
}

#[test]
fn conflicting_header_lines() {
    let text = "#incident_angle 30 0\n#intheta 31\n#format: theta phi BSDF\n10 20 1\n";
    expect_error(read_str(text, "two.txt"), "two.txt", 2, |k| {
        matches!(k, ParseErrorKind::HeaderConflict { .. })
    });
}

#[test]
fn empty_files() {
    for text in ["", "  \n\r\n\t"] {
        let msg = expect_error(read_str(text, "empty.txt"), "empty.txt", 1, |k| {
            matches!(k, ParseErrorKind::Empty)
        });
        assert!(msg.contains("empty"));
    }
    expect_error(
        read_str(MOUNTAIN_MIN, "header-only.txt"),
        "header-only.txt",
        3,
        |k| matches!(k, ParseErrorKind::NoData),
    );
}

#[test]
fn binary_junk() {
    let mut bytes = format!("{MOUNTAIN_MIN}10 20 1\n").into_bytes();
    bytes.extend_from_slice(b"\x00\x01\x02junk\n");
    let msg = expect_error(read_bytes(&bytes, "nul.txt"), "nul.txt", 5, |k| {
        matches!(
            k,
            ParseErrorKind::Binary {
                what: "NUL byte",
                ..
            }
        )
    });
    assert!(msg.contains("not a text file"), "{msg}");
    // Bytes that are not UTF-8 are read as Latin-1 (see `encoding.rs`), so
    // junk in a data row is reported as the bad field it is.
    let mut bytes = format!("{MOUNTAIN_MIN}10 20 1\n").into_bytes();
    bytes.extend_from_slice(b"\xff\xfe\x80 1 2\n");
    let msg = expect_error(read_bytes(&bytes, "junk.txt"), "junk.txt", 5, |k| {
        matches!(k, ParseErrorKind::NotANumber { column: 1, .. })
    });
    assert!(msg.contains("found `ÿþ€`"), "{msg}");
}

#[test]
fn datapoints_mismatch() {
    let text = "#intheta 1\n#inphi 0\n#datapoints_in_file 3\n#format: theta phi BSDF\n\
                10 20 1\n10 21 1\n";
    let msg = expect_error(read_str(text, "count.txt"), "count.txt", 3, |k| {
        matches!(
            k,
            ParseErrorKind::DatapointsMismatch {
                declared: 3,
                found: 2
            }
        )
    });
    assert!(msg.contains("declares 3 rows but the file has 2"), "{msg}");
}

#[test]
fn missing_or_bad_format_line() {
    let text = "#intheta 1\n#inphi 0\n10 20 1\n";
    expect_error(read_str(text, "nofmt.txt"), "nofmt.txt", 3, |k| {
        matches!(k, ParseErrorKind::MissingFormat)
    });
    let text = "#intheta 1\n#inphi 0\n#format: theta phi lux\n10 20 1\n";
    expect_error(read_str(text, "lux.txt"), "lux.txt", 3, |k| {
        matches!(k, ParseErrorKind::BadHeaderValue { .. })
    });
}

#[test]
fn header_after_data() {
    let text = format!("{MOUNTAIN_MIN}10 20 1\n#intheta 40\n10 21 1\n");
    expect_error(read_str(&text, "late.txt"), "late.txt", 5, |k| {
        matches!(k, ParseErrorKind::HeaderAfterData { first_data_line: 4 })
    });
}

#[test]
fn missing_file_names_the_path() {
    let err = read_path(Path::new("/nonexistent/dir/scan.mpc")).unwrap_err();
    assert!(matches!(err, ReadError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/dir/scan.mpc"));
}
