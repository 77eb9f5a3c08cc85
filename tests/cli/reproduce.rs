//! The README's main command reproduces the committed `fits/alu-ggx`
//! byte for byte, provenance (time and command line) aside.

use crate::common::{BRTF, repo_path, temp_dir};
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

/// Every file below `dir`, relative to it.
fn files(dir: &Path) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let relative = path.strip_prefix(dir).unwrap();
                found.insert(relative.to_string_lossy().into_owned());
            }
        }
    }
    found
}

/// `fit.json`'s provenance: its creation time and command line.
fn provenance(fit: &serde_json::Value) -> (String, String) {
    let p = &fit["provenance"];
    let command: Vec<&str> = p["command_line"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    (
        p["created"].as_str().unwrap().to_string(),
        command.join(" "),
    )
}

/// The lines of `text` that do not carry the provenance.
fn without_provenance(text: &str, stamps: &[&str]) -> Vec<String> {
    text.lines()
        .filter(|l| !stamps.iter().any(|s| l.contains(s)))
        .filter(|l| !l.contains("Command:") && !l.contains(" fit data/alu-ggx/"))
        .map(str::to_string)
        .collect()
}

#[test]
fn the_main_command_reproduces_the_committed_alu_ggx_folder() {
    let committed = repo_path("fits/alu-ggx");
    let tmp = temp_dir();
    let out = tmp.path().join("alu-ggx");
    let mut inputs: Vec<String> = std::fs::read_dir(repo_path("data/alu-ggx"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .map(|p| format!("data/alu-ggx/{}", p.file_name().unwrap().to_string_lossy()))
        .collect();
    inputs.sort();
    // From the repository, as the README says, so that the recorded input
    // paths are the committed ones.
    let run = Command::new(BRTF)
        .current_dir(repo_path(""))
        .arg("fit")
        .args(&inputs)
        .args(["--model", "metal", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );

    // The same files (check.csv is `brtf check`'s, written later).
    let mut expected = files(&committed);
    expected.remove("check.csv");
    assert_eq!(files(&out), expected);

    let read_json = |dir: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("fit.json")).unwrap()).unwrap()
    };
    let (old_fit, new_fit) = (read_json(&committed), read_json(&out));
    let (old_created, _) = provenance(&old_fit);
    let (new_created, _) = provenance(&new_fit);
    let stamps = [old_created.as_str(), new_created.as_str()];
    let mut with_provenance = BTreeSet::new();
    for name in &expected {
        let (old, new) = (
            std::fs::read(committed.join(name)).unwrap(),
            std::fs::read(out.join(name)).unwrap(),
        );
        if old == new || name == "fit.json" {
            continue;
        }
        // Only text files may differ, and only in their provenance lines.
        let (old, new) = (
            String::from_utf8(old).unwrap(),
            String::from_utf8(new).unwrap(),
        );
        assert_eq!(
            without_provenance(&old, &stamps),
            without_provenance(&new, &stamps),
            "{name} differs beyond its provenance"
        );
        with_provenance.insert(name.clone());
    }
    // The plots and params.csv are byte-identical; the exports and the
    // report differ in the time and command line they record.
    assert!(
        with_provenance
            .iter()
            .all(|n| !n.starts_with("plots/") && n != "params.csv")
    );

    // fit.json: equal but for the provenance, the fits' run times and the
    // digests of the files that record the provenance.
    let strip = |mut fit: serde_json::Value| -> Vec<String> {
        let p = fit["provenance"].as_object_mut().unwrap();
        p.remove("created");
        p.remove("command_line");
        for output in fit["outputs"].as_array_mut().unwrap() {
            if with_provenance.contains(output["path"].as_str().unwrap()) {
                output.as_object_mut().unwrap().remove("sha256");
            }
        }
        fit["global"].as_object_mut().unwrap().remove("elapsed_ms");
        for report in fit["incidences"].as_array_mut().unwrap() {
            report.as_object_mut().unwrap().remove("elapsed_ms");
        }
        let text = serde_json::to_string_pretty(&fit).unwrap();
        text.lines().map(str::to_string).collect()
    };
    let (old, new) = (strip(old_fit), strip(new_fit));
    for (line, (a, b)) in old.iter().zip(&new).enumerate() {
        assert_eq!(
            a,
            b,
            "fit.json differs at line {} of the stripped text",
            line + 1
        );
    }
    assert_eq!(old.len(), new.len(), "fit.json: lengths differ");
}
