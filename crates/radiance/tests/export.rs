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
use brtf_radiance::{parse_primitives, select_composite, select_material};

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
                    phi_turn_deg: 0.0,
                    peak_arc_deg: None,
                    shadows: Vec::new(),
                    channels: 0,
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
    // Not renderable as is: said first, and no preview scene.
    assert!(text.starts_with("# NOT RENDERABLE AS IS: "), "{text}");
    assert!(
        export
            .files
            .iter()
            .all(|f| !f.file_name.ends_with("-preview.rad"))
    );
    let notes = export.notes.join("\n");
    assert!(notes.contains("not renderable as is"), "{notes}");
    assert!(
        notes.contains("no preview scene for a free-scale fit"),
        "{notes}"
    );
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

// ---------------------------------------------------------------------------
// Lobe sums
// ---------------------------------------------------------------------------

/// [`fit`] of a lobe sum: `shape`'s flat arguments in every row, the
/// anisotropic types' orientation `orientation`.
fn lobe_fit(
    name: &str,
    shape: brtf_model::Shape,
    orientation: [f64; 3],
    rows: &[(f64, &[f64])],
) -> FitResult {
    let mut result = fit(name, shape.kind, Variant::Radiance, rows, Some(rows[0].1));
    let names = shape.param_names();
    for report in result.incidences.iter_mut().chain(result.global.as_mut()) {
        for (p, name) in report.params.iter_mut().zip(&names) {
            p.name = name.clone();
        }
    }
    result.config.lobes = shape.lobes;
    result.config.oriented = shape.oriented;
    result.config.orientation = orientation;
    result.table = Some(
        ParamTable::from_reports(shape, orientation, &result.incidences, Interpolation::Pchip)
            .unwrap(),
    );
    result
}

/// Every function the `.cal` text calls is defined in it or by Radiance
/// (rayinit.cal and the built-ins), and none is defined twice.
#[track_caller]
fn assert_cal_is_closed(cal: &str) {
    const RADIANCE: &[&str] = &[
        "if", "select", "exp", "sqrt", "acos", "abs", "min", "max", "cos", "sin", "atan2", "floor",
        "and", "or", "sq",
    ];
    let mut code = String::new();
    let mut depth = 0;
    for c in cal.chars() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ if depth == 0 => code.push(c),
            _ => {}
        }
    }
    let mut defined = Vec::new();
    for statement in code.split(';') {
        let s = statement.trim_start();
        let head: String = s
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let rest = &s[head.len()..];
        let rest = match rest.find(')') {
            Some(close) if rest.starts_with('(') => &rest[close + 1..],
            _ => rest,
        };
        if !head.is_empty() && rest.trim_start().starts_with(['=', ':']) {
            assert!(!defined.contains(&head), "`{head}` defined twice");
            defined.push(head);
        }
    }
    let mut word = String::new();
    let mut number = false;
    for c in code.chars() {
        if c.is_ascii_alphanumeric() || c == '_' || (number && c == '.') {
            if word.is_empty() {
                number = c.is_ascii_digit();
            }
            word.push(c);
            continue;
        }
        if c == '(' && !number && !word.is_empty() {
            assert!(
                defined.contains(&word) || RADIANCE.contains(&word.as_str()),
                "`{word}` is called but not defined"
            );
        }
        word.clear();
        number = false;
    }
}

#[test]
fn lobe_sum_exports_hold_the_lobes() {
    use brtf_model::Shape;
    let shape = Shape::new(MaterialKind::Metal, 2, false).unwrap();
    // red green blue spec split1 rough1 rough2
    let result = lobe_fit(
        "alu",
        shape,
        [1.0, 0.0, 0.0],
        &[
            (0.0, &[0.93, 0.93, 0.93, 0.86, 0.42, 0.085, 0.18]),
            (30.0, &[0.95, 0.95, 0.95, 0.88, 0.45, 0.087, 0.2]),
            (60.0, &[0.98, 0.98, 0.98, 0.92, 0.37, 0.085, 0.2]),
        ],
    );
    let export = exports(&result, &ExportOptions::default()).unwrap();
    let stat = file(&export, "alu.rad");
    assert!(stat.contains("static Radiance lobe sum (2 metal primitives in a mixfunc)"));
    assert!(stat.contains("Fitted arguments (red green blue spec split1 rough1 rough2)"));
    assert!(
        stat.ends_with("void mixfunc alu\n4 alu.1 alu.2 0.42 .\n0\n0\n"),
        "{stat}"
    );
    let prims = parse_primitives(stat, "alu.rad").unwrap();
    let (name, material) = select_composite(&prims, None, "alu.rad").unwrap();
    assert_eq!(name, "alu");
    let fitted = result.static_composite().unwrap();
    assert_eq!(material.shape(), Some(shape));
    for (a, b) in material.args().unwrap().iter().zip(fitted.args().unwrap()) {
        assert!((a - b).abs() < 1e-15);
    }
    // One BRTDfunc whose functions add the lobes with their weights.
    let theta = file(&export, "alu-theta.rad");
    assert!(theta.contains("void BRTDfunc alu\n"), "{theta}");
    assert!(theta.contains("A lobe sum: the functions add the 2 metal lobes"));
    let cal = file(&export, "alu-theta.cal");
    for needle in [
        "w_lobe1(t) = p_split1(t);",
        "w_lobe2(t) = (1 - p_split1(t));",
        "lobe_2(c, hx, hy, hz, om, t) = lobe_h_2(",
        "sq(p_rough2(t)) + om/(4*PI)",
        "refl(k, c, hx, hy, hz, om, t) = w_lobe1(t)*refl_1(k, c, hx, hy, hz, om, t)\n\t+ w_lobe2(t)*refl_2(",
        "  theta_in        red     green      blue      spec    split1    rough1    rough2",
    ] {
        assert!(cal.contains(needle), "`{needle}` not in\n{cal}");
    }
    assert_cal_is_closed(cal);
    // The preview uses the material's name.
    assert!(file(&export, "alu-preview.rad").contains("alu sphere alu-preview_ball"));
    // --at: the interpolated lobe sum.
    let options = ExportOptions {
        at: Some(45.0),
        name: Some("x".into()),
        ..ExportOptions::default()
    };
    let export = exports(&result, &options).unwrap();
    let prims = parse_primitives(file(&export, "x.rad"), "x.rad").unwrap();
    let (_, at) = select_composite(&prims, None, "x.rad").unwrap();
    let (want, _) = result.table.as_ref().unwrap().composite_at(45.0).unwrap();
    for (a, b) in at.args().unwrap().iter().zip(want.args().unwrap()) {
        assert!((a - b).abs() < 1e-15);
    }
}

#[test]
fn lobe_sums_whose_roughness_alone_changes_use_plasfunc() {
    use brtf_model::Shape;
    let shape = Shape::new(MaterialKind::Plastic, 3, false).unwrap();
    let result = lobe_fit(
        "p3",
        shape,
        [1.0, 0.0, 0.0],
        &[
            (0.0, &[0.5, 0.5, 0.5, 0.06, 0.3, 0.5, 0.02, 0.1, 0.3]),
            (45.0, &[0.5, 0.5, 0.5, 0.06, 0.3, 0.5, 0.03, 0.12, 0.35]),
        ],
    );
    let export = exports(&result, &ExportOptions::default()).unwrap();
    assert!(file(&export, "p3-theta.rad").contains("void plasfunc p3\n2 f_lobe p3-theta.cal\n"));
    let cal = file(&export, "p3-theta.cal");
    assert!(cal.contains(
        "lobe(c, hx, hy, hz, om, t) = w_lobe1(t)*lobe_1(c, hx, hy, hz, om, t)\n\
         \t+ w_lobe2(t)*lobe_2(c, hx, hy, hz, om, t)\n\t+ w_lobe3(t)*lobe_3("
    ));
    assert!(cal.contains("w_lobe3(t) = (1 - p_split1(t))*(1 - p_split2(t));"));
    assert_cal_is_closed(cal);
    let stat = file(&export, "p3.rad");
    assert!(stat.contains("void mixfunc p3.mix2\n4 p3.2 p3.3 0.5 .\n"));
}

#[test]
fn a_fitted_orientation_turns_the_frame_with_theta_in() {
    use brtf_model::Shape;
    let shape = Shape::new(MaterialKind::Plastic2, 2, true).unwrap();
    // ... split1 rough_u1 rough_v1 rough_u2 rough_v2 orient
    let result = lobe_fit(
        "brushed",
        shape,
        [1.0, 0.0, 0.0],
        &[
            (
                20.0,
                &[0.5, 0.45, 0.4, 0.06, 0.55, 0.05, 0.15, 0.2, 0.08, 28.0],
            ),
            (
                50.0,
                &[0.5, 0.45, 0.4, 0.06, 0.55, 0.05, 0.15, 0.2, 0.08, 33.0],
            ),
        ],
    );
    let export = exports(&result, &ExportOptions::default()).unwrap();
    let cal = file(&export, "brushed-theta.cal");
    for needle in [
        "u0x(t) = cos(p_orient(t)*DEGREE); u0y(t) = sin(p_orient(t)*DEGREE); u0z(t) = 0;",
        "hx*uhx(t) + hy*uhy(t) + hz*uhz(t)",
        "w2u_1(t) = if(crl(t), sq(p_rough_u1(t)),",
        "w2v_2(t) = if(crl(t), sq(p_rough_v2(t)),",
    ] {
        assert!(cal.contains(needle), "`{needle}` not in\n{cal}");
    }
    assert_cal_is_closed(cal);
    // The static material: the orientation of the all-incidence angle.
    let stat = file(&export, "brushed.rad");
    assert!(stat.contains("the fitted angle orient = 28 deg"), "{stat}");
    let prims = parse_primitives(stat, "b.rad").unwrap();
    let (_, m) = select_composite(&prims, None, "b.rad").unwrap();
    let o = m.components()[1].1.orientation();
    assert!((o.y.atan2(o.x).to_degrees() - 28.0).abs() < 1e-12);

    // A table that also follows φ_in, counted from a fitted orientation: no
    // θ_in-dependent material, and a note says why.
    let mut azimuth = result.clone();
    let table = azimuth.table.as_mut().unwrap();
    table.azimuth = Some(
        table
            .args
            .iter()
            .map(|a| brtf_fit::AzimuthRing {
                phi_in: vec![0.0],
                args: vec![a.clone()],
            })
            .collect(),
    );
    let export = exports(&azimuth, &ExportOptions::default()).unwrap();
    assert_eq!(export.files.len(), 2);
    assert!(
        export
            .notes
            .iter()
            .any(|n| n.contains("orientation is fitted too"))
    );
}
