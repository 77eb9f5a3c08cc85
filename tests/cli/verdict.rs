//! What a fit can be trusted for, said the same way everywhere: the
//! verdict in the summary, the `.rad` header and report.html; a free
//! scale's energy in the file's own unit; Klems peaks judged on patch
//! averages; a colour measured elsewhere given at export.

use crate::common::{brtf, repo_path, s, temp_dir};
use crate::fit::real_scan;
use std::path::Path;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// golden_paper: one plastic lobe carries the energy (with `--rho`) and
/// puts the highlight in the right place but makes it too wide; the two
/// lobes `--model auto` chooses get the width right, and with a free scale
/// the energy is not trusted. The terminal, the `.rad` header and the
/// report say the same.
#[test]
fn the_verdict_is_the_same_in_the_summary_the_rad_header_and_the_report() {
    let dir = temp_dir();
    let scan = real_scan("golden_paper.txt");
    let cases = [
        (
            vec!["--model", "plastic", "--rho", "0.85@26.8421"],
            "trust for energy, highlight direction; not for gloss width",
        ),
        (
            vec!["--model", "auto"],
            "trust for highlight direction, gloss width; not for energy",
        ),
    ];
    for (k, (args, headline)) in cases.iter().enumerate() {
        let out = dir.path().join(format!("fit{k}"));
        let mut all = vec!["fit", s(&scan), "--out", s(&out)];
        all.extend(args);
        let summary = brtf(&all, "").ok();
        assert!(
            summary.contains(&format!("verdict: {headline}")),
            "{summary}"
        );
        assert!(
            summary.contains("valid at θ_in 26.84° only (one incidence fitted"),
            "{summary}"
        );
        let rad = std::fs::read_to_string(out.join("Golden_glossy_paper.rad")).unwrap();
        assert!(rad.contains(&format!("# Verdict: {headline}.")), "{rad}");
        assert!(rad.contains("valid at theta_in 26.84 deg only"), "{rad}");
        let report = std::fs::read_to_string(out.join("report.html")).unwrap();
        assert!(
            report.contains(&format!(
                "<section id=\"verdict\" class=\"verdict\"><strong>Verdict: {headline}</strong>"
            )),
            "no verdict box in report.html"
        );
    }
}

/// A free scale's "data ρ" would be the data ÷ a scale that moves with the
/// residual kind (it read 0.998 to 1.511). Its energy is now the data's
/// own integral in the file's unit: the same for every residual kind, and
/// on golden_paper the instrument's own `#front_integral 0.0263`.
#[test]
fn a_free_scales_energy_is_in_the_files_unit_whatever_the_residual() {
    let dir = temp_dir();
    let scan = real_scan("golden_paper.txt");
    let mut data = Vec::new();
    for residual in ["absolute", "relative", "log"] {
        let out = dir.path().join(residual);
        let summary = brtf(
            &[
                "fit",
                s(&scan),
                "--model",
                "plastic",
                "--residual",
                residual,
                "--no-plots",
                "--no-export",
                "--out",
                s(&out),
            ],
            "",
        )
        .ok();
        assert!(summary.contains("in uA·sr"), "{summary}");
        let fit = json(&out.join("fit.json"));
        let adequacy = &fit["incidences"][0]["adequacy"];
        assert!(adequacy["rho_data"].is_null(), "{adequacy}");
        let raw = &adequacy["raw_energy"];
        assert_eq!(raw["unit"], "uA", "{raw}");
        data.push(raw["data"].as_f64().unwrap());
    }
    assert!(
        data.iter().all(|d| (d / data[0] - 1.0).abs() < 1e-12),
        "{data:?}"
    );
    assert!((data[0] / 0.0263 - 1.0).abs() < 0.01, "{data:?}");
}

/// A Klems file made from a `trans` material is fitted by that material:
/// its peak must not be reported elsewhere. The brightest three of 145
/// patches jumped between neighbours (12° apart) on small differences;
/// both peaks are now taken over the same patches.
#[test]
fn a_klems_file_of_the_model_itself_raises_no_peak_warning() {
    let dir = temp_dir();
    let material = dir.path().join("tr.rad");
    std::fs::write(
        &material,
        "void trans tr\n0\n0\n7 0.6 0.6 0.6 0.06 0.05 0.4 0.5\n",
    )
    .unwrap();
    let klems = dir.path().join("klems");
    brtf(
        &[
            "export",
            "--klems",
            "--material",
            s(&material),
            "--out",
            s(&klems),
        ],
        "",
    )
    .ok();
    let out = dir.path().join("fit");
    let run = brtf(
        &[
            "fit",
            s(&klems.join("tr.xml")),
            "--model",
            "trans",
            "--gray",
            "--side",
            "front",
            "--incidences",
            "theta<=40",
            "--no-plots",
            "--no-export",
            "--out",
            s(&out),
        ],
        "",
    );
    let stderr = run.stderr.clone();
    let summary = run.ok();
    assert!(!summary.contains("peak away"), "{summary}");
    assert!(!stderr.contains("peak"), "{stderr}");
    let fit = json(&out.join("fit.json"));
    let incidences = fit["incidences"].as_array().unwrap();
    assert!(incidences.len() > 20, "{}", incidences.len());
    for r in incidences {
        let offset = r["adequacy"]["peak_offset_deg"].as_f64().unwrap();
        assert!(offset < 2.0, "θ_in {}: peak {offset}°", r["theta_in"]);
    }
}

/// `brtf export --colour R,G,B`: a one-channel fit's materials take the
/// colour's chromaticity at their fitted luminance, and the header says
/// where the colour came from; without it the header says how to give one.
#[test]
fn a_colour_measured_elsewhere_is_given_at_export() {
    let dir = temp_dir();
    let fit = repo_path("fits/alu-ggx");
    let grey = dir.path().join("grey");
    let coloured = dir.path().join("coloured");
    brtf(&["export", s(&fit), "--out", s(&grey)], "").ok();
    brtf(
        &[
            "export",
            s(&fit),
            "--colour",
            "0.8,0.6,0.4",
            "--out",
            s(&coloured),
        ],
        "",
    )
    .ok();
    let args = |folder: &Path| -> (String, Vec<f64>) {
        let text = std::fs::read_to_string(folder.join("alu-ggx.rad")).unwrap();
        let line = text.lines().find(|l| l.starts_with("5 ")).unwrap();
        let values = line
            .split_whitespace()
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        (text, values)
    };
    let (grey_text, g) = args(&grey);
    let (text, c) = args(&coloured);
    assert!(grey_text.contains("give --colour R,G,B"), "{grey_text}");
    assert!(
        text.contains("# Colour: given with --colour 0.8,0.6,0.4"),
        "{text}"
    );
    let luminance = |v: &[f64]| brtf_model::luminance([v[0], v[1], v[2]]);
    assert!(
        (luminance(&c) / luminance(&g) - 1.0).abs() < 1e-9,
        "{g:?} {c:?}"
    );
    assert!((c[0] / c[1] - 0.8 / 0.6).abs() < 1e-9 && (c[2] / c[1] - 0.4 / 0.6).abs() < 1e-9);
    assert_eq!(&c[3..], &g[3..], "specularity and roughness unchanged");
    for bad in ["1,2", "0,0,0", "-1,0.5,0.5"] {
        let colour = format!("--colour={bad}");
        let err = brtf(&["export", s(&fit), &colour, "--out", s(&grey)], "").err();
        assert!(err.contains("--colour"), "{bad}: {err}");
    }
}
