//! `brtf fit DIR... --model M`: sample folders as inputs, one fit folder
//! each, the same fit as one sample's files give alone; the refusals.

use crate::common::{brtf, s, temp_dir};
use std::path::Path;

/// Writes a small synthetic sample (three incidences) into `dir/name`.
fn synth_sample(dir: &Path, name: &str, alpha: &str, seed: &str) {
    let out = dir.join(name);
    brtf(
        &[
            "synth",
            "--ggx",
            "0.9,0.9,0.9",
            "--ggx-alpha",
            alpha,
            "--ggx-diffuse",
            "0.02,0.02,0.02",
            "--theta-in",
            "0,30,60",
            "--coarse-step",
            "5",
            "--fine-step",
            "1",
            "--seed",
            seed,
            "--name",
            name,
            "--out",
            s(&out),
        ],
        "",
    )
    .ok();
}

fn params(fit_folder: &Path) -> String {
    std::fs::read_to_string(fit_folder.join("params.csv")).unwrap()
}

#[test]
fn sample_folders_fit_one_folder_each_like_single_fits() {
    let dir = temp_dir();
    let samples = dir.path().join("samples");
    synth_sample(&samples, "alpha", "0.08", "1");
    synth_sample(&samples, "beta", "0.2", "2");
    let fits = dir.path().join("fits");
    let out = brtf(
        &[
            "fit",
            s(&samples.join("alpha")),
            s(&samples.join("beta")),
            "--model",
            "metal",
            "--gray",
            "--no-plots",
            "--out",
            s(&fits),
        ],
        "",
    )
    .ok();
    assert!(out.contains("alpha") && out.contains("beta"), "{out}");
    for name in ["alpha", "beta"] {
        let folder = fits.join(name);
        assert!(folder.join("fit.json").is_file(), "{name}");
        assert!(folder.join(format!("{name}.rad")).is_file(), "{name}");
        // The same fit as the sample's files alone.
        let mut files: Vec<String> = std::fs::read_dir(samples.join(name))
            .unwrap()
            .map(|e| e.unwrap().path().display().to_string())
            .collect();
        files.sort();
        let alone = dir.path().join(format!("alone-{name}"));
        let mut args: Vec<&str> = vec!["fit"];
        args.extend(files.iter().map(String::as_str));
        args.extend([
            "--model",
            "metal",
            "--gray",
            "--no-plots",
            "--out",
            s(&alone),
        ]);
        brtf(&args, "").ok();
        assert_eq!(params(&folder), params(&alone), "{name}");
    }
    // The rougher sample fits a larger roughness.
    let rough = |name: &str| -> f64 {
        let table = params(&fits.join(name));
        let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
        let col = header.iter().position(|h| *h == "rough").unwrap();
        table
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .nth(col)
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(rough("alpha") < rough("beta"));
}

#[test]
fn folders_and_files_are_not_mixed_and_names_must_differ() {
    let dir = temp_dir();
    let samples = dir.path().join("samples");
    synth_sample(&samples, "alpha", "0.1", "1");
    let file = std::fs::read_dir(samples.join("alpha"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let err = brtf(
        &[
            "fit",
            s(&samples.join("alpha")),
            s(&file),
            "--model",
            "metal",
        ],
        "",
    )
    .err();
    assert!(err.contains("not both"), "{err}");
    // A copy of the same sample under another folder name: one output name.
    let copy = dir.path().join("copy");
    std::fs::create_dir_all(&copy).unwrap();
    for entry in std::fs::read_dir(samples.join("alpha")).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, copy.join(path.file_name().unwrap())).unwrap();
    }
    let err = brtf(
        &[
            "fit",
            s(&samples.join("alpha")),
            s(&copy),
            "--model",
            "metal",
        ],
        "",
    )
    .err();
    assert!(err.contains("are both sample"), "{err}");
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let err = brtf(&["fit", s(&empty), "--model", "metal"], "").err();
    assert!(err.contains("no measurement files"), "{err}");
}
