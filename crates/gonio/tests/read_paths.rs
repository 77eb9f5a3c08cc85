//! The Mountain reader's two row paths give the same samples: plain rows
//! (the byte loop) and rows that go through the general per-line rules.
//! A form feed between fields is whitespace to the general rules but not
//! plain, so it sends every row down the general path.

use brtf_gonio::read_bytes;

use crate::common::{assert_samples_identical, pgii_path};

#[test]
fn plain_and_general_rows_read_the_real_scans_identically() {
    for name in ["golden_paper.txt", "layer_020_030.txt"] {
        let path = pgii_path(name);
        let bytes = std::fs::read(&path).unwrap();
        let plain = read_bytes(&bytes, &path).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let data_start: usize = text
            .split_inclusive('\n')
            .take_while(|line| line.starts_with('#'))
            .map(str::len)
            .sum();
        // Every data row's first tab becomes a form feed plus a tab.
        let (head, rows) = text.split_at(data_start);
        let general_text = format!("{head}{}", rows.replacen('\t', "\x0C\t", usize::MAX));
        let general = read_bytes(general_text.as_bytes(), &path).unwrap();
        assert_eq!(plain.samples.len(), general.samples.len(), "{name}");
        assert_samples_identical(&plain.samples, &general.samples);
        // Mixed: every other row plain.
        let mixed: String = text
            .split_inclusive('\n')
            .enumerate()
            .map(|(i, line)| {
                if i % 2 == 0 && !line.starts_with('#') {
                    line.replacen('\t', " \x0C", 1)
                } else {
                    line.to_owned()
                }
            })
            .collect();
        let mixed = read_bytes(mixed.as_bytes(), &path).unwrap();
        assert_samples_identical(&plain.samples, &mixed.samples);
    }
}

#[test]
fn errors_name_the_same_line_on_either_path() {
    let head = "#intheta 30\n#inphi 0\n#format: theta phi BRDF\n";
    for (rows, line) in [
        ("1 2 3\n4 5 6\n7 8\n", 6),
        ("1 2 3\r\n\r\n4 5 x\r\n", 6),
        ("1 2 3\r4 5 6\r200 5 6\r", 6),
        ("1 2 3\n#late\n", 5),
        ("1 2 3\n4 5 6 7\n", 5),
    ] {
        let text = format!("{head}{rows}");
        let err = read_bytes(text.as_bytes(), "t.txt")
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(&format!("t.txt:{line}:")),
            "{rows:?}: {err}"
        );
    }
    // Blank lines, trailing blanks, a file without a final line end.
    let text = format!("{head}1 2 3 \n\n  4\t5\t6\t\r\n7 8 9");
    let m = read_bytes(text.as_bytes(), "t.txt").unwrap();
    assert_eq!(m.samples.len(), 3);
    assert_eq!(m.samples[2].values[0], 9.0);
}
