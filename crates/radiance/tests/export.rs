//! brtf-radiance exports: the text of every file is pinned by snapshots
//! (tests/snapshots), and the library API's behaviour (names, `at`,
//! atomic writes, errors) is checked directly. The comparison with real
//! Radiance is in the CLI tests (`tests/cli/export.rs`).

use brtf_fit::{
    FitConfig, FitReport, FitResult, InputFile, Interpolation, ParamEstimate, ParamTable,
    Provenance, Termination,
};
use brtf_model::{EvalOptions, MaterialKind, Variant};
use brtf_radiance::export::{ExportError, ExportOptions, exports, write_exports};
use brtf_radiance::{parse_primitives, select_material};

fn report(kind: MaterialKind, theta_in: f64, args: &[f64]) -> FitReport {
    FitReport {
        source: format!("data/{kind}+{theta_in}.mpc"),
        theta_in,
        phi_in: 0.0,
        params: kind
            .param_names()
            .iter()
            .zip(args)
            .map(|(name, &value)| ParamEstimate {
                name: (*name).into(),
                value,
                stderr: Some(2e-3),
                stderr_robust: Some(2e-3),
                at_bound: false,
                fixed: false,
            })
            .collect(),
        material_args: args.to_vec(),
        scale: 1.0,
        n_points: 8000,
        gates: Vec::new(),
        weighting: brtf_fit::Weighting::Caller,
        rms_rel: 0.0421,
        e1: None,
        cost: 7.5,
        floor: 0.01,
        termination: Termination::Converged {
            ftol: true,
            xtol: false,
        },
        evaluations: 57,
        elapsed_ms: 12.0,
        starts: Vec::new(),
        warnings: Vec::new(),
        adequacy: None,
        robust: None,
    }
}

fn fit(
    name: &str,
    kind: MaterialKind,
    variant: Variant,
    rows: &[(f64, &[f64])],
    global: Option<&[f64]>,
) -> FitResult {
    let incidences: Vec<FitReport> = rows.iter().map(|(t, a)| report(kind, *t, a)).collect();
    let mut config = FitConfig::new(kind);
    config.options = EvalOptions::with_variant(variant);
    let table = (rows.len() > 1).then(|| {
        ParamTable::from_reports(
            config.shape(),
            config.orientation,
            &incidences,
            Interpolation::Pchip,
        )
        .unwrap()
    });
    FitResult {
        schema: brtf_fit::FIT_JSON_SCHEMA,
        name: name.into(),
        provenance: Provenance {
            brtf_version: "0.1.0".into(),
            command_line: [
                "brtf",
                "fit",
                "data/a.mpc",
                "data/b.mpc",
                "--model",
                kind.name(),
            ]
            .map(String::from)
            .to_vec(),
            created: "2026-01-02T03:04:05Z".into(),
            inputs: incidences
                .iter()
                .map(|r| InputFile {
                    path: r.source.clone(),
                    sha256: "ab".repeat(32),
                    theta_in: r.theta_in,
                    phi_in: 0.0,
                    conversion: brtf_fit::Conversion::Bsdf,
                    samples: 8100,
                    klems: None,
                })
                .collect(),
        },
        recipe: brtf_fit::Recipe::for_kind(config.kind),
        config,
        global: global.map(|a| {
            let mut r = report(kind, 0.0, a);
            r.source = "all incidences".into();
            r
        }),
        incidences,
        table,
        interpolation: Interpolation::Pchip,
        auto: None,
        warnings: Vec::new(),
        outputs: Vec::new(),
    }
}

fn plastic() -> FitResult {
    fit(
        "painted",
        MaterialKind::Plastic,
        Variant::Radiance,
        &[
            (0.0, &[0.5, 0.4, 0.3, 0.04, 0.08]),
            (30.0, &[0.52, 0.41, 0.3, 0.05, 0.1]),
            (60.0, &[0.55, 0.43, 0.32, 0.08, 0.13]),
        ],
        Some(&[0.52, 0.41, 0.3, 0.05, 0.1]),
    )
}

fn file<'a>(export: &'a brtf_radiance::export::Export, name: &str) -> &'a str {
    &export
        .files
        .iter()
        .find(|f| f.file_name == name)
        .unwrap_or_else(|| panic!("no {name}"))
        .text
}

#[test]
fn plastic_exports_are_pinned() {
    let export = exports(&plastic(), &ExportOptions::default()).unwrap();
    let names: Vec<&str> = export.files.iter().map(|f| f.file_name.as_str()).collect();
    assert_eq!(
        names,
        [
            "painted.rad",
            "painted-theta.rad",
            "painted-theta.cal",
            "painted-preview.rad"
        ]
    );
    for f in &export.files {
        assert!(f.text.is_ascii(), "{} is not ASCII", f.file_name);
    }
    insta::assert_snapshot!("plastic_static", file(&export, "painted.rad"));
    insta::assert_snapshot!("plastic_theta_rad", file(&export, "painted-theta.rad"));
    insta::assert_snapshot!("plastic_theta_cal", file(&export, "painted-theta.cal"));
    insta::assert_snapshot!("plastic_preview", file(&export, "painted-preview.rad"));
}

#[test]
fn ward_trans_static_header_shows_the_rho_and_tau_difference() {
    let result = fit(
        "film",
        MaterialKind::Trans,
        Variant::Ward1992,
        &[
            (0.0, &[0.7, 0.8, 0.9, 0.04, 0.12, 0.6, 0.5]),
            (45.0, &[0.7, 0.8, 0.9, 0.05, 0.25, 0.6, 0.55]),
        ],
        Some(&[0.7, 0.8, 0.9, 0.045, 0.22, 0.6, 0.52]),
    );
    let export = exports(&result, &ExportOptions::default()).unwrap();
    insta::assert_snapshot!("ward_trans_static", file(&export, "film.rad"));
    assert!(
        export.notes.iter().any(|n| n.contains("ward1992")),
        "{:?}",
        export.notes
    );
}

#[test]
fn roughness_only_tables_use_the_radiance_function_types() {
    let cases = [
        (MaterialKind::Plastic, "plasfunc", vec![0.5, 0.5, 0.5, 0.05]),
        (MaterialKind::Metal, "metfunc", vec![0.9, 0.8, 0.7, 0.9]),
    ];
    for (kind, want, fixed) in cases {
        let a: Vec<f64> = fixed.iter().copied().chain([0.05]).collect();
        let b: Vec<f64> = fixed.iter().copied().chain([0.1]).collect();
        let result = fit("m", kind, Variant::Radiance, &[(0.0, &a), (50.0, &b)], None);
        let export = exports(&result, &ExportOptions::default()).unwrap();
        let rad = file(&export, "m-theta.rad");
        let prims = parse_primitives(rad, "m-theta.rad").unwrap();
        assert_eq!(prims.len(), 1);
        assert_eq!(prims[0].kind, want);
        assert_eq!(prims[0].strings, ["f_lobe", "m-theta.cal"]);
        assert_eq!(prims[0].reals, fixed);
    }
    let trans = fit(
        "t",
        MaterialKind::Trans2,
        Variant::Manual2004,
        &[
            (0.0, &[0.6, 0.7, 0.8, 0.05, 0.05, 0.1, 0.5, 0.6]),
            (50.0, &[0.6, 0.7, 0.8, 0.05, 0.08, 0.2, 0.5, 0.6]),
        ],
        None,
    );
    let export = exports(&trans, &ExportOptions::default()).unwrap();
    insta::assert_snapshot!("trans2_lobe_rad", file(&export, "t-theta.rad"));
    insta::assert_snapshot!("trans2_lobe_cal", file(&export, "t-theta.cal"));
}

#[test]
fn static_material_comes_from_the_global_fit_or_at() {
    let result = plastic();
    let read = |export: &brtf_radiance::export::Export, name: &str| {
        let text = file(export, name);
        let prims = parse_primitives(text, name).unwrap();
        select_material(&prims, None, name).unwrap()
    };
    let export = exports(&result, &ExportOptions::default()).unwrap();
    let (name, m) = read(&export, "painted.rad");
    assert_eq!(
        (name.as_str(), Some(m)),
        ("painted", result.static_material())
    );

    let at = |theta| ExportOptions {
        at: Some(theta),
        name: Some("x".into()),
        ..ExportOptions::default()
    };
    let table = result.table.as_ref().unwrap();
    let export = exports(&result, &at(45.0)).unwrap();
    assert_eq!(read(&export, "x.rad").1, table.at(45.0).unwrap().material);
    assert!(file(&export, "x.rad").contains("theta_in table (Pchip) at theta_in = 45 deg"));
    // An exact incidence uses that incidence's own report.
    let export = exports(&result, &at(30.0)).unwrap();
    assert!(file(&export, "x.rad").contains("the fit of the incidence theta_in = 30 deg"));

    for bad in [-1.0, 90.0, f64::NAN] {
        let err = exports(&result, &at(bad)).unwrap_err();
        assert!(matches!(err, ExportError::At { .. }), "{err}");
    }
}

#[test]
fn names_are_checked_or_sanitised() {
    let mut result = plastic();
    result.name = "fits/My fit (2)".into();
    let export = exports(&result, &ExportOptions::default()).unwrap();
    assert_eq!(export.name, "My_fit__2_");
    assert_eq!(export.files[0].file_name, "My_fit__2_.rad");
    for bad in ["", "a b", "-x", ".hidden", "a/b"] {
        let options = ExportOptions {
            name: Some(bad.into()),
            ..ExportOptions::default()
        };
        let err = exports(&result, &options).unwrap_err();
        assert!(matches!(err, ExportError::BadName(_)), "{bad}: {err}");
    }
}

#[test]
fn single_incidence_gives_a_static_material_and_a_note() {
    let result = fit(
        "one",
        MaterialKind::Metal,
        Variant::Radiance,
        &[(20.0, &[0.9, 0.9, 0.9, 0.95, 0.3])],
        None,
    );
    let export = exports(&result, &ExportOptions::default()).unwrap();
    let names: Vec<&str> = export.files.iter().map(|f| f.file_name.as_str()).collect();
    assert_eq!(names, ["one.rad", "one-preview.rad"]);
    assert!(export.notes[0].contains("no θ_in-dependent material"));
    let text = file(&export, "one.rad");
    assert!(text.contains("roughness 0.3 is above 0.2"), "{text}");
    assert!(!file(&export, "one-preview.rad").contains("-theta"));

    let mut empty = result.clone();
    empty.incidences.clear();
    assert!(matches!(
        exports(&empty, &ExportOptions::default()),
        Err(ExportError::NoParameters)
    ));
}

#[test]
fn write_exports_writes_atomically_and_reports_io_errors() {
    let dir = tempfile::tempdir().unwrap();
    let written = write_exports(dir.path(), &plastic(), &ExportOptions::default()).unwrap();
    assert_eq!(written.files.len(), 4);
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "painted-preview.rad",
            "painted-theta.cal",
            "painted-theta.rad",
            "painted.rad"
        ]
    );
    let missing = dir.path().join("no/such/folder");
    let err = write_exports(&missing, &plastic(), &ExportOptions::default()).unwrap_err();
    assert!(matches!(err, ExportError::Io { .. }), "{err}");
    assert!(err.to_string().contains("painted.rad"), "{err}");
}

#[test]
fn free_scale_and_missing_global_fit_are_reported() {
    let mut result = plastic();
    result.config.free_scale = true;
    result.global = None;
    let export = exports(&result, &ExportOptions::default()).unwrap();
    let text = file(&export, "painted.rad");
    assert!(text.contains("free overall scale"), "{text}");
    assert!(
        text.contains("the fit of the incidence theta_in = 0 deg"),
        "{text}"
    );
    assert!(file(&export, "painted-theta.rad").contains("free overall scale"));
    let notes = export.notes.join("\n");
    assert!(notes.contains("colour is relative"), "{notes}");
    assert!(notes.contains("no all-incidence fit"), "{notes}");
}

#[test]
fn hostile_strings_stay_inside_comments() {
    let mut result = plastic();
    result.name = "x\ny".into();
    result.provenance.created = "2026\nvoid light evil 0 0 3 1 1 1".into();
    result.provenance.command_line = vec!["brtf}".into(), "{fit\r\n".into()];
    result.provenance.inputs[0].path = "a\nb.mpc".into();
    result.incidences[0].warnings = vec![brtf_fit::FitWarning::AtBound {
        param: "θ ≥ 5°\n{oops}".into(),
        value: 1.0,
    }];
    let export = exports(&result, &ExportOptions::default()).unwrap();
    for f in &export.files {
        assert!(f.text.is_ascii(), "{}", f.file_name);
        if f.file_name.ends_with(".rad") {
            let prims = parse_primitives(&f.text, &f.file_name).unwrap();
            assert!(
                prims.iter().all(|p| p.name != "evil"),
                "{}:\n{}",
                f.file_name,
                f.text
            );
        } else {
            // The .cal header is one comment: braces inside it are removed.
            let header_end = f.text.find("\n}\n").unwrap();
            assert!(!f.text[1..header_end].contains(['{', '}']), "{}", f.text);
        }
    }
}
