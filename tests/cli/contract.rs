//! The typed contract between `brtf fit` and every command that reads its
//! folder: the data are rebuilt from the stored recipe (never from the
//! text shown to people), `fit.json` carries a schema version that every
//! reader checks, and `brtf check` uses the fit's own scale.

use crate::common::{brtf, repo_path, s, temp_dir};
use brtf_fit::{FitResult, Gate};
use std::path::{Path, PathBuf};

fn real_scan(name: &str) -> PathBuf {
    let path = repo_path("../shared/data/rgl-epfl-pgII-raw").join(name);
    assert!(path.exists(), "{} is missing", path.display());
    path
}

fn shipped_files() -> Vec<String> {
    let mut files: Vec<String> = std::fs::read_dir(repo_path("data/alu-ggx"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .map(|p| s(&p).to_string())
        .collect();
    files.sort();
    files
}

/// Noise-free `brtf synth` files of the material `text` at θ_in 0, 30 and
/// 60°, with `extra` options, into `dir/set`; their paths, sorted.
fn synth_set(dir: &Path, text: &str, extra: &[&str]) -> Vec<String> {
    let rad = dir.join("truth.rad");
    std::fs::write(&rad, text).unwrap();
    let set = dir.join("set");
    let mut args = vec![
        "synth",
        "--material",
        s(&rad),
        "--theta-in",
        "0,30,60",
        "--out",
        s(&set),
        "--noise",
        "0",
        "--noise-floor",
        "0",
    ];
    args.extend_from_slice(extra);
    brtf(&args, "").ok();
    let mut files: Vec<String> = std::fs::read_dir(&set)
        .unwrap()
        .map(|e| s(&e.unwrap().path()).to_string())
        .collect();
    files.sort();
    files
}

fn fit_into(out: &Path, files: &[String], extra: &[&str]) -> FitResult {
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(files.iter().cloned());
    args.extend(["--out".into(), s(out).to_string()]);
    args.extend(extra.iter().map(|a| a.to_string()));
    brtf(&args, "").ok();
    FitResult::read(out).unwrap()
}

/// Every sentence a person reads (gates, weighting, warnings, the
/// conversion) stays out of `fit.json`, and plots and the check rebuild
/// the fitted data from the typed recipe alone: the plots find exactly
/// the fitted samples and RMS again, with every kind of gate in use.
#[test]
fn fit_json_holds_no_prose_and_plots_and_check_rebuild_the_data() {
    let dir = temp_dir();
    let out = dir.path().join("fit");
    let result = fit_into(
        &out,
        &shipped_files(),
        &["--model", "metal", "--min-value", "1e-6", "--no-export"],
    );
    let text = std::fs::read_to_string(out.join("fit.json")).unwrap();
    let gates = &result.recipe.selections;
    for kind in [
        "unavailable",
        "hemisphere",
        "theta_cap",
        "beam_mask",
        "min_value",
    ] {
        assert!(
            gates
                .iter()
                .any(|g| serde_json::to_string(g).unwrap().contains(kind)),
            "{kind} not among {gates:?}"
        );
    }
    let mut sentences: Vec<String> = gates.iter().map(Gate::to_string).collect();
    for r in result.incidences.iter().chain(&result.global) {
        sentences.push(r.weighting.to_string());
        sentences.extend(r.warnings.iter().map(|w| w.to_string()));
        sentences.extend(r.gates.iter().map(|g| g.gate.to_string()));
    }
    sentences.extend(
        result
            .provenance
            .inputs
            .iter()
            .map(|i| i.conversion.to_string()),
    );
    assert!(result.incidences.iter().any(|r| !r.warnings.is_empty()));
    for sentence in &sentences {
        assert!(
            !text.contains(sentence.as_str()),
            "fit.json holds `{sentence}`"
        );
    }
    // The plots rebuild each incidence and compare it with the fit's own
    // counts and RMS: any disagreement would be a warning.
    let plot = brtf(&["plot", s(&out)], "");
    let stderr = plot.stderr.clone();
    plot.ok();
    assert!(!stderr.contains("may not be what was fitted"), "{stderr}");
    assert!(!stderr.contains("may differ from the fit"), "{stderr}");
    let table = brtf(&["check", s(&out), "--samples", "4"], "").ok();
    assert!(table.contains("fitted"), "{table}");
}

/// `brtf check` on a raw-signal fit uses the fit's scale: with `--rho`
/// the data ÷ K, with a free scale the data ÷ the fitted scale. Before the
/// recipe, it ignored both and reported a 30× energy error.
#[test]
fn check_reports_the_fits_scale_on_raw_signal() {
    let dir = temp_dir();
    let scan = s(&real_scan("golden_paper.txt")).to_string();
    for (label, extra) in [("rho", vec!["--rho", "0.5@27"]), ("free", vec![])] {
        let out = dir.path().join(label);
        let mut args = vec!["--model", "metal", "--gray", "--no-plots", "--no-export"];
        args.extend(extra);
        let result = fit_into(&out, std::slice::from_ref(&scan), &args);
        brtf(
            &[
                "check",
                s(&out),
                "--samples",
                "2",
                "--source-omega",
                "0",
                "--detector-omega",
                "0",
            ],
            "",
        )
        .ok();
        let csv = std::fs::read_to_string(out.join("check.csv")).unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let row: Vec<&str> = lines.next().unwrap().split(',').collect();
        let get = |name: &str| -> f64 {
            row[header.iter().position(|h| *h == name).unwrap()]
                .parse()
                .unwrap()
        };
        let energy = get("render_data_energy_ratio");
        assert!(
            (energy - 1.0).abs() < 0.1,
            "{label}: render/data energy {energy}"
        );
        // A point beam and detector render the model itself, so on every
        // fitted direction the rendered-vs-data RMS is the fit's own.
        let rendered_rms = get("render_vs_data_rms_rel");
        let fit_rms = result.incidences[0].rms_rel;
        assert!(
            (rendered_rms / fit_rms - 1.0).abs() < 1e-3,
            "{label}: render-data rms {rendered_rms} vs the fit's {fit_rms}"
        );
    }
}

/// A `fit.json` of another schema version gets one clear line from every
/// command that reads it, naming the file and the version.
#[test]
fn other_schema_versions_are_refused_by_every_reader() {
    let dir = temp_dir();
    let out = dir.path().join("fit");
    fit_into(
        &out,
        &shipped_files()[..2],
        &["--model", "metal", "--no-plots", "--no-export"],
    );
    let json = out.join("fit.json");
    let text = std::fs::read_to_string(&json).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    for (found, edit) in [(1, None), (99, Some(99))] {
        match edit {
            None => value.as_object_mut().unwrap().remove("schema"),
            Some(v) => value
                .as_object_mut()
                .unwrap()
                .insert("schema".into(), v.into()),
        };
        std::fs::write(&json, serde_json::to_string(&value).unwrap()).unwrap();
        for command in [
            vec!["plot", s(&out)],
            vec!["export", s(&out)],
            vec!["check", s(&out)],
            vec!["render", "image", "--fit", s(&out), "--out", "x"],
        ] {
            let err = brtf(&command, "").err();
            let line = err.trim();
            assert_eq!(line.lines().count(), 1, "{command:?}: {err}");
            assert!(
                line.contains(s(&json)) && line.contains(&format!("schema version {found}")),
                "{command:?}: {err}"
            );
        }
    }
}

/// A parameter that ends at a bound has no standard error, and every
/// command that reads the folder still works. A metal fitted to a purely
/// diffuse sample ends with its specularity at 0; before, its standard
/// error was written as `null` and `plot`, `check`, `export` and `render`
/// failed with `invalid type: null`.
#[test]
fn a_parameter_at_a_bound_breaks_no_command() {
    let dir = temp_dir();
    let files = synth_set(
        dir.path(),
        "void plastic white 0 0 5 0.6 0.6 0.6 0 0
",
        &[],
    );
    let out = dir.path().join("fit");
    let result = fit_into(&out, &files, &["--model", "metal", "--gray"]);
    let bounded: Vec<_> = result
        .incidences
        .iter()
        .flat_map(|r| &r.params)
        .filter(|p| p.at_bound)
        .collect();
    assert!(!bounded.is_empty(), "no parameter at a bound");
    for p in &bounded {
        assert_eq!(p.stderr, None, "{p:?}");
        assert_eq!(p.missing_error_reason(), Some("at bound"));
    }
    let text = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert!(text.contains("\"stderr\": null"), "no null standard error");
    let summary_csv = std::fs::read_to_string(out.join("params.csv")).unwrap();
    assert!(!summary_csv.contains("NaN"), "{summary_csv}");
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(
        report.contains("at bound"),
        "report.html does not say `at bound`"
    );
    // fit.json is written after the report, which still links it.
    assert!(
        report.contains("href=\"fit.json\"") && report.contains("href=\"params.csv\""),
        "report.html of `brtf fit` does not link fit.json and params.csv"
    );
    brtf(&["plot", s(&out)], "").ok();
    brtf(&["export", s(&out)], "").ok();
    brtf(&["check", s(&out), "--samples", "4"], "").ok();
    let picture = dir.path().join("pic");
    brtf(
        &[
            "render",
            "image",
            "--fit",
            s(&out),
            "--out",
            s(&picture),
            "--width",
            "16",
            "--height",
            "12",
            "--samples",
            "1",
        ],
        "",
    )
    .ok();
    // A prefix given with the picture's extension is not doubled
    // (`--out pic.hdr` wrote pic.hdr.hdr and pic.hdr.png).
    let named = dir.path().join("named.hdr");
    brtf(
        &[
            "render",
            "image",
            "--fit",
            s(&out),
            "--out",
            s(&named),
            "--width",
            "8",
            "--height",
            "6",
            "--samples",
            "1",
        ],
        "",
    )
    .ok();
    assert!(named.is_file() && dir.path().join("named.png").is_file());
    assert!(!dir.path().join("named.hdr.hdr").exists());
}

/// CIE-XYZ files are fitted in Radiance RGB: a plastic of known colour,
/// written as true XYZ by `brtf synth --channels 3`, is fitted and
/// exported with its own colour (before, the XYZ values were taken as RGB
/// and (0.100, 0.401, 0.121) came out as 0.201 0.303 0.154).
#[test]
fn xyz_data_are_fitted_and_exported_in_radiance_rgb() {
    let dir = temp_dir();
    let files = synth_set(
        dir.path(),
        "void plastic green 0 0 5 0.100 0.401 0.121 0.04 0.1\n",
        &["--format", "mountain", "--channels", "3"],
    );
    // The files hold true XYZ: at normal incidence, every sample is the
    // XYZ of the material's RGB BSDF.
    let m = brtf_gonio::read_path(Path::new(&files[0])).unwrap();
    assert_eq!(m.channels, brtf_gonio::Channels::Xyz);
    let material = brtf_model::Material::new(
        brtf_model::MaterialKind::Plastic,
        &[0.100, 0.401, 0.121, 0.04, 0.1],
        None,
    )
    .unwrap();
    let bsdf = brtf_model::Bsdf::new(&material, &brtf_model::EvalOptions::default());
    let sample = m
        .samples
        .iter()
        .find(|s| s.theta_deg > 40.0 && s.theta_deg < 60.0)
        .unwrap();
    let want = brtf_model::rgb_to_xyz(bsdf.eval(m.incidence.direction(), sample.direction()));
    for (got, want) in sample.values.iter().zip(want) {
        assert!(
            (got / want - 1.0).abs() < 1e-6,
            "{:?} vs {want:?}",
            sample.values
        );
    }
    let out = dir.path().join("fit");
    let result = fit_into(&out, &files, &["--model", "plastic", "--no-plots"]);
    assert_eq!(
        result.recipe.colour,
        brtf_fit::ColourConversion::XyzToRadianceRgb
    );
    let exported = std::fs::read_to_string(out.join("green.rad"))
        .or_else(|_| std::fs::read_to_string(out.join("set.rad")))
        .unwrap();
    let words: Vec<f64> = exported
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .flat_map(|l| l.split_whitespace())
        .filter_map(|w| w.parse().ok())
        .collect();
    // `void plastic NAME 0 0 5 r g b spec rough`: the five reals come last.
    let reals = &words[words.len() - 5..];
    for (got, want) in reals[..3].iter().zip([0.100, 0.401, 0.121]) {
        assert!((got / want - 1.0).abs() < 0.01, "colour {reals:?}");
    }
}

/// A free-scale plastic's `spec` is a fraction of the unknown scale, and
/// its export says so instead of judging it as Radiance's specularity;
/// `--mask-holder` drops the pgII holder's shadow and the report says how
/// many points it masked.
#[test]
fn free_scale_plastic_export_and_the_holder_mask() {
    let dir = temp_dir();
    let out = dir.path().join("layer");
    let scan = s(&real_scan("layer_020_030.txt")).to_string();
    let result = fit_into(
        &out,
        std::slice::from_ref(&scan),
        &[
            "--model",
            "plastic",
            "--gray",
            "--mask-holder",
            "--no-adequacy",
        ],
    );
    let masked = result.incidences[0]
        .gates
        .iter()
        .find(|g| matches!(g.gate, Gate::AzimuthBand { .. }))
        .expect("the holder band gate");
    assert!(masked.removed > 1000, "{masked:?}");
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains(&format!(
        "holder band φ_out − φ_in 270±45° at θ_out &gt;= 73° (−{})",
        masked.removed
    )));
    let rad = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "rad") && !s(p).ends_with("-preview.rad"))
        .unwrap();
    let text = std::fs::read_to_string(&rad).unwrap();
    assert!(
        text.contains("spec is a fraction of that unknown scale"),
        "{text}"
    );
    assert!(
        !text.contains("specularity fractions greater than 0.1"),
        "{text}"
    );
}
