//! `brtf info`: a summary of each measurement or BSDF XML file (Klems
//! matrices or a tensor tree), as text or as one JSON array.

use crate::WorkflowError;
use brtf_gonio::klems::BsdfXml;
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;

/// One entry of the JSON array: the file and its summary.
#[derive(Serialize)]
struct FileSummary<S> {
    file: String,
    #[serde(flatten)]
    summary: S,
}

#[derive(Serialize)]
#[serde(untagged)]
enum Entry {
    Measurement(FileSummary<brtf_gonio::Summary>),
    Klems(FileSummary<brtf_gonio::klems::KlemsInfo>),
    Tree(FileSummary<brtf_gonio::klems::TreeInfo>),
}

/// Writes the summary of every file to `out`: a block of text per file,
/// or (`json`) one JSON array of summaries, each with its `file`. Stops at
/// the first file that cannot be read; the error names it.
pub fn describe_files(
    files: &[PathBuf],
    json: bool,
    out: &mut impl Write,
) -> Result<(), WorkflowError> {
    let mut entries = Vec::with_capacity(files.len());
    for (i, path) in files.iter().enumerate() {
        let file = path.display().to_string();
        let (entry, text) = if brtf_gonio::klems::is_klems_file(path) {
            match brtf_gonio::klems::read_any_path(path)? {
                BsdfXml::Klems(bsdf) => {
                    let summary = bsdf.info();
                    let text = summary.to_string();
                    (Entry::Klems(FileSummary { file, summary }), text)
                }
                BsdfXml::TensorTree(tree) => {
                    let summary = tree.info();
                    let text = summary.to_string();
                    (Entry::Tree(FileSummary { file, summary }), text)
                }
            }
        } else {
            let summary = brtf_gonio::read_path(path)?.summary();
            let text = summary.to_string();
            (Entry::Measurement(FileSummary { file, summary }), text)
        };
        if json {
            entries.push(entry);
            continue;
        }
        let gap = if i > 0 { "\n" } else { "" };
        write!(out, "{gap}{}\n{text}", path.display())?;
    }
    if json {
        let text = serde_json::to_string_pretty(&entries).expect("summaries serialise");
        writeln!(out, "{text}")?;
    }
    Ok(())
}
