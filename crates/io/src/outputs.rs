//! The listing of an output folder's files (`fit.json`'s `outputs`): each
//! file with its SHA-256 and the step that wrote it, so that a later
//! `brtf export` or `brtf plot` replaces its own files and only those.

use crate::IoError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The step that wrote an output file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Producer {
    /// `brtf fit`'s own tables (`params.csv`).
    Fit,
    /// The Radiance exports (`brtf export`, or `brtf fit` unless `--no-export`).
    Export,
    /// The plots and `report.html` (`brtf plot`, or `brtf fit` unless `--no-plots`).
    Plot,
}

/// One file of an output folder.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct OutputFile {
    /// Path inside the folder, `/`-separated.
    pub path: String,
    /// SHA-256 of the file's bytes, lower-case hex.
    pub sha256: String,
    /// The step that wrote it.
    pub by: Producer,
}

/// Describes the `written` files (inside `dir`), reading each for its digest.
pub fn describe_outputs(
    dir: &Path,
    written: &[PathBuf],
    by: Producer,
) -> Result<Vec<OutputFile>, IoError> {
    written
        .iter()
        .map(|file| {
            let path = file.strip_prefix(dir).unwrap_or(file);
            let full = dir.join(path);
            let bytes = std::fs::read(&full).map_err(|source| IoError {
                path: full,
                what: "cannot read",
                source,
            })?;
            Ok(OutputFile {
                path: slash_path(path),
                sha256: crate::sha256_hex(&bytes),
                by,
            })
        })
        .collect()
}

/// The listing after `by` wrote `fresh` into `dir`: the other steps'
/// entries of `listing` are kept, and the files `by` listed before but
/// did not write again are removed from `dir` (a refit with other options
/// must not leave an old `-theta.rad` behind). Sorted by path.
pub fn replace_outputs(
    dir: &Path,
    listing: &[OutputFile],
    fresh: Vec<OutputFile>,
    by: Producer,
) -> Result<Vec<OutputFile>, IoError> {
    for old in listing.iter().filter(|o| o.by == by) {
        if fresh.iter().all(|f| f.path != old.path) && is_inside(&old.path) {
            let path = dir.join(&old.path);
            match std::fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(IoError {
                        path,
                        what: "cannot remove a stale output",
                        source: e,
                    });
                }
                _ => {}
            }
        }
    }
    let mut merged: Vec<OutputFile> = listing
        .iter()
        .filter(|o| o.by != by && fresh.iter().all(|f| f.path != o.path))
        .cloned()
        .collect();
    merged.extend(fresh);
    merged.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(merged)
}

/// Every file under `dir`, as `/`-separated paths relative to it, sorted.
pub fn folder_files(dir: &Path) -> Result<Vec<String>, IoError> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) -> Result<(), IoError> {
        let fail = |source| IoError {
            path: dir.to_path_buf(),
            what: "cannot read",
            source,
        };
        for entry in std::fs::read_dir(dir).map_err(fail)? {
            let entry = entry.map_err(fail)?;
            let path = entry.path();
            if entry.file_type().map_err(fail)?.is_dir() {
                walk(root, &path, out)?;
            } else {
                out.push(slash_path(path.strip_prefix(root).unwrap_or(&path)));
            }
        }
        Ok(())
    }
    let mut files = Vec::new();
    walk(dir, dir, &mut files)?;
    files.sort();
    Ok(files)
}

fn slash_path(path: &Path) -> String {
    let parts: Vec<_> = path.iter().map(|p| p.to_string_lossy()).collect();
    parts.join("/")
}

/// A listed path stays inside its folder (a hand-edited listing must not
/// make brtf remove files elsewhere).
fn is_inside(path: &str) -> bool {
    !path.is_empty()
        && !path.starts_with('/')
        && path
            .split('/')
            .all(|c| !c.is_empty() && c != ".." && c != ".")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_replaces_only_its_own_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for name in ["params.csv", "a-theta.rad", "a.rad", "report.html"] {
            std::fs::write(d.join(name), name).unwrap();
        }
        let listing = [
            describe_outputs(d, &[d.join("params.csv")], Producer::Fit).unwrap(),
            describe_outputs(d, &["a-theta.rad".into(), "a.rad".into()], Producer::Export).unwrap(),
            describe_outputs(d, &["report.html".into()], Producer::Plot).unwrap(),
        ]
        .concat();
        assert_eq!(listing[0].path, "params.csv");
        assert_eq!(listing[0].sha256, crate::sha256_hex(b"params.csv"));
        std::fs::write(d.join("a.rad"), "new").unwrap();
        let fresh = describe_outputs(d, &["a.rad".into()], Producer::Export).unwrap();
        let merged = replace_outputs(d, &listing, fresh, Producer::Export).unwrap();
        let paths: Vec<&str> = merged.iter().map(|o| o.path.as_str()).collect();
        assert_eq!(paths, ["a.rad", "params.csv", "report.html"]);
        assert_eq!(merged[0].sha256, crate::sha256_hex(b"new"));
        assert_eq!(folder_files(d).unwrap(), paths, "a-theta.rad removed");
    }

    #[test]
    fn listed_paths_outside_the_folder_are_never_removed() {
        assert!(is_inside("plots/map-t0.svg"));
        for bad in ["", "/etc/passwd", "../x", "a/../../x", "a//b", "./a"] {
            assert!(!is_inside(bad), "{bad}");
        }
    }
}
