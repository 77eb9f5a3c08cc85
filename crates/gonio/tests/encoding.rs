//! Encodings and line ends: Latin-1 / Windows-1252 bytes in
//! header comments are read, CR-only line ends are read like LF and CRLF,
//! and line numbers in errors count every kind of line end.

use brtf_gonio::{ParseErrorKind, SourceFormat, detect_format, read_bytes, read_path, read_str};
use std::path::Path;

use crate::common::{assert_samples_identical, golden, layer, mpc_fixture_text, pgii_path};
use crate::read::expect_error;

/// `text` with every line end (LF or CRLF) replaced by a lone CR.
fn to_cr_only(bytes: &[u8]) -> Vec<u8> {
    let text = String::from_utf8(bytes.to_vec()).expect("the fixtures are UTF-8");
    text.replace("\r\n", "\n").replace('\n', "\r").into_bytes()
}

/// `bytes` with `line` (no line end) inserted as line 2.
fn insert_second_line(bytes: &[u8], line: &[u8]) -> Vec<u8> {
    let first_end = bytes.iter().position(|&b| b == b'\n').unwrap() + 1;
    let mut out = bytes[..first_end].to_vec();
    out.extend_from_slice(line);
    out.push(b'\n');
    out.extend_from_slice(&bytes[first_end..]);
    out
}

const MOUNTAIN_LATIN1: &[u8] = b"#sample_name \"Gr\xfcn gl\xe4nzend\"\n\
    #comment Fl\xe4che bei 20\xb0C, \x93matt\x94\n\
    #intheta 30\n#inphi 0\n#format: theta phi BSDF\n10 20 1\n10 40 2\n";

#[test]
fn latin1_mountain_header_comments_are_read() {
    let m = read_bytes(MOUNTAIN_LATIN1, "latin1.txt").unwrap();
    assert_eq!(m.sample_name.as_deref(), Some("Grün glänzend"));
    // Bytes 0x93/0x94 are Windows-1252 quotes, what Windows editors write.
    assert_eq!(m.header[1], "#comment Fläche bei 20°C, “matt”");
    assert_eq!(m.len(), 2);
    // Written back as UTF-8, it reads the same.
    let again = read_str(&brtf_gonio::to_mountain_string(&m), "again.txt").unwrap();
    assert_eq!(again.sample_name, m.sample_name);
    assert_samples_identical(&again.samples, &m.samples);
}

#[test]
fn latin1_mpc_header_comment_is_read() {
    let utf8 = mpc_fixture_text().into_bytes();
    let latin1 = insert_second_line(&utf8, b"#Messung: Fl\xe4che 20\xb0C");
    let plain = read_bytes(&utf8, "a:+30+0.mpc").unwrap();
    let m = read_bytes(&latin1, "a:+30+0.mpc").unwrap();
    assert!(m.header.iter().any(|l| l == "#Messung: Fläche 20°C"));
    assert_samples_identical(&m.samples, &plain.samples);
}

#[test]
fn latin1_in_the_real_scan_header_is_read() {
    let bytes = std::fs::read(pgii_path("golden_paper.txt")).unwrap();
    let bytes = insert_second_line(&bytes, b"#operator Fran\xe7ois M\xfcller\r");
    let m = read_bytes(&bytes, "golden_paper.txt").unwrap();
    assert!(m.header.iter().any(|l| l == "#operator François Müller"));
    assert_samples_identical(&m.samples, &golden().samples);
}

#[test]
fn utf8_lines_stay_utf8_beside_a_latin1_line() {
    let bytes = b"#note gr\xc3\xbcn\n#other gr\xfcn\n#intheta 1\n#inphi 0\n\
                  #format: theta phi BSDF\n10 20 1\n";
    let m = read_bytes(bytes, "mixed.txt").unwrap();
    assert_eq!(m.header[0], "#note grün");
    assert_eq!(m.header[1], "#other grün");
}

#[test]
fn latin1_in_a_data_row_names_line_and_column() {
    let bytes = b"#intheta 1\n#inphi 0\n#format: theta phi BSDF\n10 20 1\n10 2\xb0 1\n";
    let msg = expect_error(read_bytes(bytes, "deg.txt"), "deg.txt", 5, |k| {
        matches!(k, ParseErrorKind::NotANumber { column: 2, .. })
    });
    assert!(msg.contains("found `2°`"), "{msg}");
}

#[test]
fn cr_only_real_scans_read_like_the_originals() {
    for (name, original) in [
        ("golden_paper.txt", golden()),
        ("layer_020_030.txt", layer()),
    ] {
        let bytes = std::fs::read(pgii_path(name)).unwrap();
        let m = read_bytes(&to_cr_only(&bytes), name).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.header, original.header, "{name}");
        assert_eq!(m.incidence, original.incidence, "{name}");
        assert_samples_identical(&m.samples, &original.samples);
    }
}

#[test]
fn cr_only_mpc_reads_like_the_original() {
    let utf8 = mpc_fixture_text().into_bytes();
    let plain = read_bytes(&utf8, "a:+30+0.mpc").unwrap();
    let cr = to_cr_only(&utf8);
    // Detection must see the lines too, without the `.mpc` extension.
    assert_eq!(detect_format(&cr, Path::new("a")), SourceFormat::Mpc);
    let m = read_bytes(&cr, "a").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.header, plain.header);
    assert_eq!(m.incidence, plain.incidence);
    assert_eq!(m.beam, plain.beam);
    assert_samples_identical(&m.samples, &plain.samples);
}

#[test]
fn cr_only_errors_give_the_line_an_editor_shows() {
    let text = "#intheta 30\r#inphi 0\r#format: theta phi BSDF\r10 20 1\r10 x 1\r";
    expect_error(read_str(text, "cr.txt"), "cr.txt", 5, |k| {
        matches!(k, ParseErrorKind::NotANumber { column: 2, .. })
    });
    // Mixed line ends: LF, CRLF, CR each end one line.
    let text = "#intheta 30\n#inphi 0\r\n#format: theta phi BSDF\r10 20 1\n\r10 20\n";
    expect_error(read_str(text, "mixed.txt"), "mixed.txt", 6, |k| {
        matches!(k, ParseErrorKind::ColumnCount { found: 2, .. })
    });
    let bytes = b"#intheta 30\r#inphi 0\r#format: theta phi BSDF\r10 20 1\r\x00\r";
    expect_error(read_bytes(bytes, "nul.txt"), "nul.txt", 5, |k| {
        matches!(k, ParseErrorKind::Binary { .. })
    });
}

#[test]
fn header_lines_never_keep_a_carriage_return() {
    let m = read_str(
        "#a\rb\r\n#intheta 30\r\n#inphi 0\r#format: theta phi BSDF\n1 2 3\r",
        "r.txt",
    );
    // The lone CR ends `#a`, so `b` on line 2 is the first data row.
    let msg = m.unwrap_err().to_string();
    assert!(msg.starts_with("r.txt:2: no `#format:"), "{msg}");
    let m = read_str(
        "#a\r#b\r\n#intheta 30\r\n#inphi 0\r#format: theta phi BSDF\n1 2 3\r",
        "r.txt",
    )
    .unwrap();
    assert_eq!(m.header.len(), 5);
    assert!(m.header.iter().all(|l| !l.contains('\r')));
}

#[test]
fn shipped_file_with_cr_only_line_ends_reads_from_disk() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.mpc");
    std::fs::write(&path, to_cr_only(mpc_fixture_text().as_bytes())).unwrap();
    let m = read_path(&path).unwrap();
    assert_eq!(m.format, SourceFormat::Mpc);
    assert!(m.len() >= 6);
}
