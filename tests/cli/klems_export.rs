//! `brtf export --klems`: a fit of synthetic `trans` data exported as Klems
//! BSDF XML, read back by brtf's own reader (column totals equal the
//! written matrices' totals and brtf's ρ_dh / τ_dh of the fitted
//! parameters), the static-material path, and bad input.

use crate::common::{brtf, s, temp_dir, write_file};
use brtf_gonio::klems::{self, KlemsBand, KlemsDirection, Side};
use brtf_model::{Bsdf, EvalOptions, albedo, colour};
use std::path::{Path, PathBuf};

const TRUTH: &str = "void trans shade\n0\n0\n7 0.6 0.5 0.4 0.03 0.15 0.3 0.2\n";

/// Noise-free synthetic `trans` files at θ_in 0, 30, 60, fitted.
fn fitted(dir: &Path) -> PathBuf {
    let rad = write_file(dir, "truth.rad", TRUTH);
    let set = dir.join("set");
    brtf(
        &[
            "synth",
            "--material",
            s(&rad),
            "--theta-in",
            "0,30,60",
            "--noise",
            "0",
            "--noise-floor",
            "0",
            "--source-aperture",
            "0",
            "--detector-aperture",
            "0",
            "--out",
            s(&set),
        ],
        "",
    )
    .ok();
    let mut files: Vec<String> = std::fs::read_dir(&set)
        .unwrap()
        .map(|e| s(&e.unwrap().path()).to_string())
        .collect();
    files.sort();
    let out = dir.join("fit");
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(files);
    args.extend(["--model", "trans", "--out", s(&out), "--no-plots"].map(String::from));
    brtf(&args, "").ok();
    out
}

/// Export from a fit, read back: the front blocks only (rf, tf), the
/// file's column totals equal the library's matrices' totals (to the 6
/// written digits), each incident patch's totals are brtf's ρ_dh / τ_dh
/// of the fitted parameters at the patch's θ_in within 1 %, and fit.json
/// lists the file among the exports. (The refit of the file with
/// `brtf fit x.xml` is the Klems-reading side's test.)
#[test]
fn export_from_a_fit_reads_back_with_its_totals() {
    let tmp = temp_dir();
    let fit_dir = fitted(tmp.path());
    let out = brtf(
        &[
            "export",
            s(&fit_dir),
            "--klems",
            "quarter",
            "--name",
            "shade",
        ],
        "",
    )
    .ok();
    let path = fit_dir.join("shade.xml");
    assert!(out.contains("shade.xml"), "{out}");
    let file = klems::read_path(&path).unwrap();
    assert_eq!(file.basis.name, "LBNL/Klems Quarter");
    assert_eq!(
        file.directions(),
        vec![
            KlemsDirection::TransmissionBack,
            KlemsDirection::ReflectionBack
        ]
    );
    // The library's matrices, computed again (deterministic).
    let mut options = brtf_radiance::export::klems::KlemsOptions::new("shade");
    options.basis = file.basis.clone();
    let export = brtf_radiance::export::klems::klems_from_fit_dir(&fit_dir, &options).unwrap();
    let result = brtf_fit::FitResult::read(&fit_dir).unwrap();
    let table = result
        .table
        .as_ref()
        .expect("three incidences make a table");
    for block in &export.blocks {
        let read = file.matrix(&block.band, block.direction).unwrap();
        let n = file.basis.len();
        let lambda = file.basis.projected_solid_angles();
        let want: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|o| block.values[o * n + i] * lambda[o]).sum())
            .collect();
        let got = read.column_totals(&file.basis);
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(
                (g - w).abs() <= 1e-5 * w.abs().max(1e-3),
                "{} patch {i}: read {g} vs written {w}",
                block.direction
            );
        }
    }
    // Against brtf's albedo of the fitted parameters, ring-centre θ_in
    // (the Quarter basis's rings below 66°, where the patch average and
    // the centre value agree to well within 1 % for this material).
    let hemis = file.hemispherical(&KlemsBand::Visible, Side::Front);
    for p in hemis.iter().filter(|p| p.theta_in_deg < 60.0) {
        let material = table.at(p.theta_in_deg).unwrap().material;
        let bsdf = Bsdf::new(&material, &EvalOptions::default());
        let a = albedo(&bsdf, brtf_model::direction(p.theta_in_deg, 0.0), 1e-6);
        let (rho, tau) = (colour::luminance(a.rho), colour::luminance(a.tau));
        let (got_rho, got_tau) = (p.rho_dh.unwrap(), p.tau_dh.unwrap());
        assert!(
            (got_rho / rho - 1.0).abs() <= 0.01 && (got_tau / tau - 1.0).abs() <= 0.01,
            "patch {} at {}: rho {got_rho} vs {rho}, tau {got_tau} vs {tau}",
            p.patch,
            p.theta_in_deg
        );
    }
    let listed = brtf_fit::FitResult::read(&fit_dir).unwrap();
    assert!(
        listed.outputs.iter().any(|o| o.path == "shade.xml"),
        "{:?}",
        listed.outputs
    );
    // The earlier exports stay listed.
    assert!(listed.outputs.iter().any(|o| o.path.ends_with(".rad")));
}

/// A material gives all four components, with the provenance comment.
#[test]
fn export_of_a_material_has_four_components_and_provenance() {
    let tmp = temp_dir();
    let rad = write_file(tmp.path(), "m.rad", TRUTH);
    let out = brtf(
        &[
            "export",
            "--klems",
            "quarter",
            "--material",
            s(&rad),
            "--solar",
            "visible",
            "--out",
            s(tmp.path()),
        ],
        "",
    )
    .ok();
    assert!(out.contains("shade.xml"), "{out}");
    let text = std::fs::read_to_string(tmp.path().join("shade.xml")).unwrap();
    assert!(text.contains("sha256 "), "no provenance");
    assert!(text.contains("ASSUMPTION"), "no Solar assumption");
    let file = klems::read_str(&text, "shade.xml").unwrap();
    assert_eq!(file.directions().len(), 4);
    assert_eq!(file.bands(), vec![KlemsBand::Visible, KlemsBand::Solar]);
    // Two-sided: the back equals the front.
    let f = file
        .matrix(&KlemsBand::Visible, KlemsDirection::TransmissionBack)
        .unwrap();
    let b = file
        .matrix(&KlemsBand::Visible, KlemsDirection::TransmissionFront)
        .unwrap();
    assert_eq!(f.values, b.values);
}

#[test]
fn bad_klems_input_fails_with_a_message() {
    let tmp = temp_dir();
    let rad = write_file(tmp.path(), "m.rad", TRUTH);
    let err = brtf(&["export", "--klems", "eighth", "--material", s(&rad)], "").err();
    assert!(err.contains("eighth"), "{err}");
    let err = brtf(
        &[
            "export",
            "--klems",
            "--material",
            s(&rad),
            "--klems-samples",
            "0",
        ],
        "",
    )
    .err();
    assert!(err.contains("--klems-samples 0"), "{err}");
    let err = brtf(&["export", s(tmp.path()), "--klems"], "").err();
    assert!(err.contains("fit.json"), "{err}");
}
