//! `residuals.csv`: every sample of every incidence, with the model the fit
//! compared it with and the gate that removed it. Its rows give back
//! `fit.json`'s sample counts, gate counts and E1.

use crate::common::{brtf, repo_path, s, temp_dir};
use crate::fit::real_scan;
use brtf_fit::FitResult;
use std::collections::BTreeMap;
use std::path::Path;

/// `residuals.csv` of the fit folder `dir` as rows of named fields.
fn rows(dir: &Path) -> Vec<BTreeMap<String, String>> {
    let mut reader = csv::Reader::from_path(dir.join("residuals.csv")).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            header
                .iter()
                .cloned()
                .zip(r.iter().map(String::from))
                .collect()
        })
        .collect()
}

fn number(row: &BTreeMap<String, String>, key: &str) -> f64 {
    row[key].parse().unwrap_or(f64::NAN)
}

/// Checks `dir`'s rows against its `fit.json`: per incidence the fitted
/// count, every gate's removals and E1 (`cosine`: the file's values carry
/// |cos θ_out|).
fn check_against_fit_json(dir: &Path, samples: usize, cosine: bool) {
    let result = FitResult::read(&dir.join("fit.json")).unwrap();
    let rows = rows(dir);
    assert_eq!(rows.len(), samples);
    for report in &result.incidences {
        let mine: Vec<_> = rows
            .iter()
            .filter(|r| (number(r, "theta_in") - report.theta_in).abs() < 1e-9)
            .collect();
        let fitted: Vec<_> = mine.iter().filter(|r| r["gate"].is_empty()).collect();
        assert_eq!(fitted.len(), report.n_points, "θ_in {}", report.theta_in);
        for gate in &report.gates {
            let removed = mine
                .iter()
                .filter(|r| r["gate"] == gate.gate.name())
                .count();
            assert_eq!(removed, gate.removed, "{}", gate.gate.name());
        }
        let (mut misfit, mut total) = (0.0, 0.0);
        for r in &fitted {
            let c = if cosine {
                number(r, "theta_out").to_radians().cos().abs()
            } else {
                1.0
            };
            let w = number(r, "weight") * c;
            misfit += w * (number(r, "model") - number(r, "data")).abs();
            total += w * number(r, "data").abs();
        }
        let e1 = report.e1.unwrap();
        assert!(
            (misfit / total / e1 - 1.0).abs() < 1e-6,
            "θ_in {}: E1 from the rows {} against {e1}",
            report.theta_in,
            misfit / total
        );
    }
}

#[test]
fn residuals_of_a_real_scan_give_back_its_counts_gates_and_e1() {
    let dir = temp_dir();
    let out = dir.path().join("fit");
    let scan = real_scan("golden_paper.txt");
    let args = [
        "fit",
        s(&scan),
        "--model",
        "plastic",
        "--lobes",
        "2",
        "--mask-holder",
    ];
    brtf(
        &[&args[..], &["--no-plots", "--no-export", "--out", s(&out)]].concat(),
        "",
    )
    .ok();
    check_against_fit_json(&out, 127_039, true);
    // The holder band's samples are named, and lie in its band.
    let rows = rows(&out);
    let band: Vec<_> = rows
        .iter()
        .filter(|r| r["gate"] == "azimuth_band")
        .collect();
    assert!(band.len() > 500, "{}", band.len());
    assert!(band.iter().all(|r| number(r, "theta_out") >= 70.0));
}

#[test]
fn residuals_of_the_shipped_set_give_back_its_counts_gates_and_e1() {
    let dir = temp_dir();
    let out = dir.path().join("fit");
    let files: Vec<String> = ["0", "30", "60"]
        .iter()
        .map(|t| {
            repo_path(&format!("data/alu-ggx/alu-ggx:+{t}+0.mpc"))
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    let mut args = vec!["fit".to_string()];
    args.extend(files);
    args.extend(["--model", "metal", "--no-plots", "--out", s(&out)].map(String::from));
    brtf(&args, "").ok();
    check_against_fit_json(&out, 8990 + 2 * 9087, false);
}
