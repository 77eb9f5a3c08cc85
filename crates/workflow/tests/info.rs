//! `describe_files`: the text and JSON summaries `brtf info` prints.

use brtf_workflow::describe_files;
use std::path::PathBuf;

fn fixture() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../gonio/tests/fixtures/pab-aluA-st1:+30+0.mpc")
}

fn report(files: &[PathBuf], json: bool) -> Result<String, brtf_workflow::WorkflowError> {
    let mut out = Vec::new();
    describe_files(files, json, &mut out)?;
    Ok(String::from_utf8(out).unwrap())
}

#[test]
fn text_report_names_the_file_and_the_quantity() {
    let text = report(&[fixture(), fixture()], false).unwrap();
    assert_eq!(text.matches("pab-aluA-st1:+30+0.mpc\n").count(), 2);
    assert!(text.contains("theta_in = 30 deg, phi_in = 0 deg (from the header)"));
    assert!(text.contains("quantity      BSDF [1/sr] (CIE-Y)"));
    assert!(text.contains("6 (front 0, back 6); 5 negative, 0 not available"));
    // One blank line between the files' blocks.
    assert_eq!(text.matches("\n\n").count(), 1, "{text}");
}

#[test]
fn json_report_is_an_array_of_summaries() {
    let text = report(&[fixture()], true).unwrap();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    let entry = &value.as_array().unwrap()[0];
    assert!(entry["file"].as_str().unwrap().ends_with(":+30+0.mpc"));
    assert_eq!(entry["quantity"], "BSDF");
    assert_eq!(entry["back"]["count"], 6);
    assert_eq!(entry["beam"]["integral"], 0.063626);
}

#[test]
fn unreadable_files_are_named_in_the_error() {
    let err = report(&[PathBuf::from("/nonexistent/scan.txt")], false).unwrap_err();
    // The message and its causes, as the CLI prints them.
    let mut message = err.to_string();
    let mut cause = std::error::Error::source(&err);
    while let Some(c) = cause {
        message += &format!(": {c}");
        cause = c.source();
    }
    assert!(message.contains("/nonexistent/scan.txt"), "{message}");
    assert!(message.contains("No such file"), "{message}");
}
