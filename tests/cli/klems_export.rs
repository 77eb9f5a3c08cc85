//! `brtf export --klems`: a fit of synthetic `trans` data exported as Klems
//! BSDF XML, read back by brtf's own reader (column totals equal the
//! written matrices' totals and brtf's ρ_dh / τ_dh of the fitted
//! parameters), the static-material path, and bad input.

use crate::common::{brtf, s, temp_dir, write_file};
use brtf_gonio::klems::{self, KlemsBand, KlemsDirection, Side};
use brtf_model::{Bsdf, EvalOptions, albedo};
use std::collections::HashMap;
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
        let (rho, tau) = (brtf_model::luminance(a.rho), brtf_model::luminance(a.tau));
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

// ---------------------------------------------------------------------------
// Live rtrace: the Klems file renders like the material it was made from
// ---------------------------------------------------------------------------

/// The Radiance `bin` folder holding oconv and rtrace, or `None` after a
/// loud warning (a failure under CI).
fn radiance_bin() -> Option<PathBuf> {
    let has = |d: &Path| ["oconv", "rtrace"].iter().all(|n| d.join(n).is_file());
    if let Some(dir) = std::env::var_os("RADIANCE_BIN") {
        let dir = PathBuf::from(dir);
        assert!(
            has(&dir),
            "RADIANCE_BIN={} lacks oconv/rtrace",
            dir.display()
        );
        return Some(dir);
    }
    if let Some(path) = std::env::var_os("PATH")
        && let Some(dir) = std::env::split_paths(&path).find(|d| has(d))
    {
        return Some(dir);
    }
    let lib = crate::common::repo_path(".venv/lib");
    let mut bins: Vec<PathBuf> = std::fs::read_dir(&lib)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .map(|e| e.path().join("site-packages/pyradiance/bin"))
                .filter(|p| has(p))
                .collect()
        })
        .unwrap_or_default();
    bins.sort();
    if let Some(bin) = bins.into_iter().next() {
        return Some(bin);
    }
    let message = "oconv/rtrace not found (RADIANCE_BIN, PATH, .venv pyradiance)";
    if std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false") {
        panic!("{message}: the live Klems rtrace test fails under CI");
    }
    eprintln!("\n!!! WARNING: {message}; the live Klems rtrace test did NOT run\n");
    None
}

/// Exitance / irradiance of the surface (normal +z) under a small sun at
/// `sun_theta`, on the lit side (`transmitted` false) or behind it, from
/// rtrace radiances: M/E = Σ L Λ / E over view directions in every
/// Klems patch.
fn rtrace_ratio(bin: &Path, dir: &Path, material: &str, sun_theta: f64, transmitted: bool) -> f64 {
    let apex = 0.5_f64;
    let omega = brtf_model::cone_solid_angle(apex);
    let sun = brtf_model::direction(sun_theta, 30.0);
    let scene = format!(
        "{material}\nvoid light sun_light 0 0 3 {l} {l} {l}\n\
         sun_light source sun 0 0 4 {} {} {} {apex}\n\
         shade polygon surface 0 0 12 -1 -1 0 1 -1 0 1 1 0 -1 1 0\n",
        sun.x,
        sun.y,
        sun.z,
        l = 1.0 / omega
    );
    std::fs::write(dir.join("scene.rad"), scene).unwrap();
    let lib = bin.parent().unwrap().join("lib");
    let raypath = format!(".:{}", lib.display());
    let oct = std::process::Command::new(bin.join("oconv"))
        .current_dir(dir)
        .env("RAYPATH", &raypath)
        .arg("scene.rad")
        .output()
        .unwrap();
    assert!(
        oct.status.success(),
        "oconv: {}",
        String::from_utf8_lossy(&oct.stderr)
    );
    std::fs::write(dir.join("scene.oct"), &oct.stdout).unwrap();
    // 64 points per Klems Full patch, uniform in projected solid angle
    // inside it, weighted by the patch's Λ: the quadrature a Klems file's
    // patch-constant values are exact under (a plain grid is not: its rows
    // miss the 5° polar cap).
    let basis = klems::KlemsBasis::full();
    let per_patch = 64;
    let mut rng = brtf_model::Rng::new(11, 0);
    let mut rays = String::new();
    let mut weights = Vec::new();
    for patch in basis.patches() {
        for p in patch.stratified_directions(per_patch, &mut rng) {
            let z = if transmitted { -p.z } else { p.z };
            let v = [p.x, p.y, z];
            rays += &format!(
                "{} {} {} {} {} {}\n",
                0.1 * v[0],
                0.1 * v[1],
                0.1 * v[2],
                -v[0],
                -v[1],
                -v[2]
            );
            weights.push(patch.projected_solid_angle_sr / per_patch as f64);
        }
    }
    use std::io::Write;
    let mut child = std::process::Command::new(bin.join("rtrace"))
        .current_dir(dir)
        .env("RAYPATH", &raypath)
        .args([
            "-h-",
            "-ab",
            "0",
            "-dj",
            "0",
            "-ds",
            "0",
            "-dt",
            "0",
            "-dc",
            "1",
            "-dr",
            "0",
            "-st",
            "1",
            "-ss",
            "0",
            "-lr",
            "1",
            "-fad",
            "-ov",
            "scene.oct",
        ])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(rays.as_bytes()).unwrap());
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(
        out.status.success(),
        "rtrace: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let values: Vec<f64> = out
        .stdout
        .chunks_exact(24)
        .map(|c| {
            let v = |i: usize| f64::from_ne_bytes(c[8 * i..8 * i + 8].try_into().unwrap());
            brtf_model::luminance([v(0), v(1), v(2)])
        })
        .collect();
    assert_eq!(values.len(), weights.len());
    values.iter().zip(&weights).map(|(v, w)| v * w).sum::<f64>() / sun.z
}

/// rtrace renders the Klems file (`void BSDF shade 6 0 shade.xml 0 1 0 . 0
/// 0`) with the same irradiance-weighted result as the material it was
/// made from, within 2 %: reflected and transmitted exitance per unit
/// irradiance under a small sun at 0°, 30° and 60°.
#[test]
fn klems_file_renders_like_its_material_in_rtrace() {
    let Some(bin) = radiance_bin() else {
        return;
    };
    let tmp = temp_dir();
    let rad = write_file(tmp.path(), "m.rad", TRUTH);
    brtf(
        &[
            "export",
            "--klems",
            "--material",
            s(&rad),
            "--out",
            s(tmp.path()),
        ],
        "",
    )
    .ok();
    let bsdf = "void BSDF shade 6 0 shade.xml 0 1 0 . 0 0";
    for sun_theta in [0.0, 30.0, 60.0] {
        for transmitted in [false, true] {
            let want = rtrace_ratio(&bin, tmp.path(), TRUTH, sun_theta, transmitted);
            let got = rtrace_ratio(&bin, tmp.path(), bsdf, sun_theta, transmitted);
            eprintln!(
                "sun {sun_theta}: {}: material {want:.4}, Klems {got:.4} ({:+.2} %)",
                if transmitted {
                    "transmitted"
                } else {
                    "reflected"
                },
                100.0 * (got / want - 1.0)
            );
            assert!(
                (got / want - 1.0).abs() <= 0.02,
                "sun {sun_theta} transmitted {transmitted}: {got} vs {want}"
            );
        }
    }
}

/// Round trip: a grey rough trans exported as Klems Full and refitted from
/// the file (`brtf fit x.xml --model trans --gray --side front`) gives back
/// its parameters: colour and transmission within 2 %, specularity and
/// roughness within 5 % (the Klems-reading issue's tolerances).
#[test]
fn refit_of_the_exported_file_recovers_the_material() {
    let tmp = temp_dir();
    let truth = [0.5, 0.5, 0.5, 0.04, 0.15, 0.3, 0.2];
    let rad = write_file(
        tmp.path(),
        "grey.rad",
        "void trans grey\n0\n0\n7 0.5 0.5 0.5 0.04 0.15 0.3 0.2\n",
    );
    brtf(
        &[
            "export",
            "--klems",
            "--material",
            s(&rad),
            "--out",
            s(tmp.path()),
        ],
        "",
    )
    .ok();
    let out = tmp.path().join("refit");
    brtf(
        &[
            "fit",
            s(&tmp.path().join("grey.xml")),
            "--model",
            "trans",
            "--gray",
            "--side",
            "front",
            "--out",
            s(&out),
            "--no-plots",
            "--no-export",
        ],
        "",
    )
    .ok();
    let result = brtf_fit::FitResult::read(&out).unwrap();
    let got = &result
        .global
        .as_ref()
        .expect("an all-incidence fit")
        .material_args;
    for (k, (g, t)) in got.iter().zip(truth).enumerate() {
        let tolerance = if k == 3 || k == 4 { 0.05 } else { 0.02 };
        assert!(
            (g / t - 1.0).abs() <= tolerance,
            "argument {}: refit {g} vs {t} ({got:?})",
            k + 1
        );
    }
}

/// A two-sided fit folder (`front/` and `back/`, as `brtf fit x.xml`
/// writes for a file with both sides) exports all four components, the
/// back fit's as rb and tb: per incident patch below the horizon ring
/// their totals match the file the fit was made from within 1 %.
#[test]
fn two_sided_fit_folder_exports_four_components() {
    let tmp = temp_dir();
    let rad = write_file(
        tmp.path(),
        "grey.rad",
        "void trans grey\n0\n0\n7 0.5 0.5 0.5 0.04 0.15 0.3 0.2\n",
    );
    brtf(
        &[
            "export",
            "--klems",
            "quarter",
            "--material",
            s(&rad),
            "--out",
            s(tmp.path()),
        ],
        "",
    )
    .ok();
    let source = tmp.path().join("grey.xml");
    let two = tmp.path().join("two");
    brtf(
        &[
            "fit",
            s(&source),
            "--model",
            "trans",
            "--gray",
            "--out",
            s(&two),
            "--no-plots",
            "--no-export",
        ],
        "",
    )
    .ok();
    assert!(two.join("front/fit.json").is_file() && two.join("back/fit.json").is_file());
    brtf(&["export", s(&two), "--klems", "quarter"], "").ok();
    let original = klems::read_path(&source).unwrap();
    let exported = klems::read_path(&two.join("two.xml")).unwrap();
    assert_eq!(exported.directions().len(), 4);
    for side in Side::BOTH {
        let a = original.hemispherical(&KlemsBand::Visible, side);
        let b = exported.hemispherical(&KlemsBand::Visible, side);
        // Below the horizon ring: there the per-patch refit itself is off
        // by ~1.5 % (the fitting's accuracy, not the export's).
        for (p, q) in a.iter().zip(&b).filter(|(p, _)| {
            let t = p.theta_in_deg.min(180.0 - p.theta_in_deg);
            t < 60.0
        }) {
            for (x, y) in [(p.rho_dh, q.rho_dh), (p.tau_dh, q.tau_dh)] {
                let (x, y) = (x.unwrap(), y.unwrap());
                assert!(
                    (y / x - 1.0).abs() <= 0.01,
                    "{side} patch {}: exported {y} vs original {x}",
                    p.patch
                );
            }
        }
    }
    // One side's own folder is named by its fit, not by the folder: it
    // was written as `front/front.xml`, named "front".
    let printed = brtf(&["export", s(&two.join("front")), "--klems", "quarter"], "").ok();
    assert!(two.join("front/grey.xml").is_file(), "{printed}");
    assert!(!two.join("front/front.xml").exists(), "{printed}");
    assert_eq!(
        klems::read_path(&two.join("front/grey.xml"))
            .unwrap()
            .header
            .name
            .as_deref(),
        Some("grey")
    );
}

/// `trans2` fitted to the anisotropic Mecho fabric follows (θ_in, φ_in):
/// its table keeps each θ ring over φ_in, and the Klems file exported
/// from it (each incident patch with the parameters at its own azimuth)
/// is closer to the measured matrices than the same fit's φ_in-averaged
/// table gives, in both directions of the front side.
#[test]
fn anisotropic_fit_exports_the_parameters_of_each_azimuth() {
    let tmp = temp_dir();
    let fabric =
        crate::common::repo_path("../shared/data/lbnl-frads-klems-fabrics/klems_aniso_high.xml");
    let fit_dir = tmp.path().join("mecho");
    brtf(
        &[
            "fit",
            s(&fabric),
            "--model",
            "trans2",
            "--gray",
            "--side",
            "front",
            "--incidences",
            "theta<=40",
            "--no-plots",
            "--no-export",
            "--no-adequacy",
            "--out",
            s(&fit_dir),
        ],
        "",
    )
    .ok();
    let json = std::fs::read_to_string(fit_dir.join("fit.json")).unwrap();
    let value: serde_json::Value = serde_json::from_str(&json).unwrap();
    let rings = value["table"]["azimuth"].as_array().expect("azimuth rings");
    let counts: Vec<usize> = rings
        .iter()
        .map(|r| r["phi_in"].as_array().unwrap().len())
        .collect();
    assert_eq!(counts, [1, 8, 16, 20, 24], "the Klems rings to 40°");
    // The plots show the parameters over φ_in, a line per ring.
    brtf(&["plot", s(&fit_dir)], "").ok();
    let phi_chart = std::fs::read_to_string(fit_dir.join("plots/params-phi.svg")).unwrap();
    for ring in ["θ_in 0°", "θ_in 10°", "θ_in 40°"] {
        assert!(phi_chart.contains(ring), "{ring} missing");
    }
    let report = std::fs::read_to_string(fit_dir.join("report.html")).unwrap();
    assert!(
        report.contains("params-phi"),
        "the report shows the φ_in chart"
    );
    // At each fitted incidence the table gives that incidence's own fit.
    let result = brtf_fit::FitResult::read(&fit_dir).unwrap();
    // Patch-averaged data: no map or cut per incidence unless asked for,
    // and the report says how to get them.
    assert_eq!(report.matches("loading=\"lazy\"").count(), 0);
    assert!(report.contains("--incidence-charts"), "the report says how");
    let maps = |dir: &Path| {
        std::fs::read_dir(dir.join("plots"))
            .unwrap()
            .filter(|e| {
                let name = e.as_ref().unwrap().file_name();
                name.to_string_lossy().starts_with("map-")
            })
            .count()
    };
    assert_eq!(maps(&fit_dir), 0);
    // Asked for, so many incidences' maps and cuts load when scrolled to,
    // and the 3D view holds every incidence behind one picker.
    brtf(&["plot", s(&fit_dir), "--incidence-charts"], "").ok();
    let report = std::fs::read_to_string(fit_dir.join("report.html")).unwrap();
    assert_eq!(maps(&fit_dir), 2 * result.incidences.len());
    assert_eq!(
        report.matches("loading=\"lazy\"").count(),
        2 * result.incidences.len()
    );
    assert_eq!(report.matches("class=\"brtf-view\"").count(), 1);
    assert_eq!(
        report.matches("\"samples\":").count(),
        result.incidences.len()
    );
    for r in &result.incidences {
        let m = result
            .material_at_direction(r.theta_in, r.phi_in, None)
            .unwrap();
        for (a, b) in m.args().iter().zip(&r.material_args) {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1e-3),
                "{}: {a} vs {b}",
                r.source
            );
        }
    }
    // The same fit without the rings: φ_in-averaged rows only.
    let averaged_dir = tmp.path().join("averaged");
    std::fs::create_dir_all(&averaged_dir).unwrap();
    let mut averaged = value.clone();
    averaged["table"].as_object_mut().unwrap().remove("azimuth");
    write_file(
        &averaged_dir,
        "fit.json",
        &serde_json::to_string_pretty(&averaged).unwrap(),
    );
    let measured = klems::read_path(&fabric).unwrap();
    let band = &measured.bands()[0];
    let mut errors = Vec::new();
    for dir in [&fit_dir, &averaged_dir] {
        brtf(&["export", s(dir), "--klems", "--name", "shade"], "").ok();
        let exported = klems::read_path(&dir.join("shade.xml")).unwrap();
        let mut per_direction = Vec::new();
        for direction in [
            KlemsDirection::TransmissionBack,
            KlemsDirection::ReflectionBack,
        ] {
            let a = measured.matrix(band, direction).unwrap();
            let b = exported.matrix(&exported.bands()[0], direction).unwrap();
            let n = measured.basis.len();
            // Incident patches of the fitted rings (θ ≤ 40°: the first 69).
            let (mut diff, mut norm) = (0.0, 0.0);
            for i in 0..69 {
                for o in 0..n {
                    diff += (a.value(o, i) - b.value(o, i)).powi(2);
                    norm += a.value(o, i).powi(2);
                }
            }
            per_direction.push((diff / norm).sqrt());
        }
        errors.push(per_direction);
    }
    eprintln!(
        "relative rms error (transmission, reflection): with azimuths {:.4?}, averaged {:.4?}",
        errors[0], errors[1]
    );
    // Transmission carries the fabric's anisotropy; its reflection is
    // mostly diffuse, so it gains little, but must not lose.
    assert!(
        errors[0][0] < 0.9 * errors[1][0],
        "transmission: with azimuths {:.4}, averaged {:.4}",
        errors[0][0],
        errors[1][0]
    );
    assert!(
        errors[0][1] <= errors[1][1],
        "reflection: with azimuths {:.4}, averaged {:.4}",
        errors[0][1],
        errors[1][1]
    );
}

/// The repo's `.venv` Python when it imports pyWinCalc, or `None` after a
/// loud warning (a failure under CI, whose test command installs it).
fn pywincalc_python() -> Option<PathBuf> {
    let python = crate::common::repo_path(".venv/bin/python");
    let works = std::process::Command::new(&python)
        .args(["-c", "import pywincalc"])
        .output()
        .is_ok_and(|o| o.status.success());
    if works {
        return Some(python);
    }
    let message = "pyWinCalc not found in .venv (bash scripts/test.sh installs it)";
    if std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false") {
        panic!("{message}: the pyWinCalc test fails under CI");
    }
    eprintln!("\n!!! WARNING: {message}; the pyWinCalc test did NOT run\n");
    None
}

/// What pyWinCalc (LBNL's WINDOW calculation engine) makes of a Klems
/// file: a one-layer `GlazingSystem`'s direct-hemispherical T and R at
/// normal incidence, front and back, photopic and solar.
const PYWINCALC_TOTALS: &str = r#"
import json, sys, pywincalc
layer = pywincalc.parse_bsdf_xml_file(sys.argv[1])
hemisphere = pywincalc.BSDFHemisphere.create(pywincalc.BSDFBasisType.FULL)
system = pywincalc.GlazingSystem(solid_layers=[layer], bsdf_hemisphere=hemisphere)
out = {}
for method in ("PHOTOPIC", "SOLAR"):
    results = system.optical_method_results(method).system_results
    for side in ("front", "back"):
        s = getattr(results, side)
        out[f"{method} {side}"] = [s.transmittance.direct_hemispherical,
                                   s.reflectance.direct_hemispherical]
print(json.dumps(out))
"#;

/// The thermal fields of a Klems file as pyWinCalc reads them.
const PYWINCALC_FIELDS: &str = r#"
import sys, pywincalc
l = pywincalc.parse_bsdf_xml_file(sys.argv[1])
print(l.permeability_factor, l.emissivity_front, l.emissivity_back, l.ir_transmittance, l.conductivity)
"#;

/// pyWinCalc reads brtf's Klems files (comma-separated rows and a Solar
/// band, as WINDOW writes them) and computes brtf's own totals to 0.5 %:
/// WINDOW's front is Radiance's back (`docs/klems.md`). WINDOW's thermal
/// fields come through; `--solar none` leaves the band out, and pyWinCalc
/// then cannot build the system.
#[test]
fn pywincalc_reads_the_files_and_computes_brtfs_totals() {
    let Some(python) = pywincalc_python() else {
        return;
    };
    let dir = temp_dir();
    let material = write_file(
        dir.path(),
        "shade.rad",
        "void trans shade\n0\n0\n7 0.6 0.5 0.4 0.06 0.05 0.4 0.5\n",
    );
    let export = |extra: &[&str], out: &str| -> PathBuf {
        let out = dir.path().join(out);
        let mut args = vec![
            "export",
            "--klems",
            "--material",
            s(&material),
            "--out",
            s(&out),
        ];
        args.extend(extra);
        brtf(&args, "").ok();
        out.join("shade.xml")
    };
    let totals = |xml: &Path| -> std::process::Output {
        std::process::Command::new(&python)
            .args(["-c", PYWINCALC_TOTALS, s(xml)])
            .output()
            .expect("python runs")
    };
    let xml = export(&[], "default");
    let text = std::fs::read_to_string(&xml).unwrap();
    assert!(
        text.contains(">Solar</Wavelength>"),
        "a Solar band by default"
    );
    let run = totals(&xml);
    assert!(
        run.status.success(),
        "pyWinCalc: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let window: HashMap<String, [f64; 2]> = serde_json::from_slice(&run.stdout).unwrap();
    let info: serde_json::Value =
        serde_json::from_str(&brtf(&["info", s(&xml), "--json"], "").ok()).unwrap();
    let at_normal = |side: &str| -> [f64; 2] {
        let row = info[0]["incidences"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["side"] == side && r["patch"] == 0)
            .unwrap();
        [
            row["tau_dh"].as_f64().unwrap(),
            row["rho_dh"].as_f64().unwrap(),
        ]
    };
    for method in ["PHOTOPIC", "SOLAR"] {
        for (window_side, radiance_side) in [("front", "back"), ("back", "front")] {
            let got = window[&format!("{method} {window_side}")];
            let want = at_normal(radiance_side);
            eprintln!(
                "pyWinCalc {method} {window_side}: T {got:?}, brtf {radiance_side}: {want:?}"
            );
            for k in 0..2 {
                assert!(
                    (got[k] / want[k] - 1.0).abs() < 0.005,
                    "{method} {window_side}: pyWinCalc {got:?}, brtf {want:?}"
                );
            }
        }
    }
    // WINDOW's thermal fields, as pyWinCalc reads them.
    let fields = export(
        &[
            "--permeability",
            "0.05",
            "--emissivity",
            "0.84,0.8",
            "--ir-transmittance",
            "0.1",
            "--conductivity",
            "0.15",
        ],
        "fields",
    );
    let read = std::process::Command::new(&python)
        .args(["-c", PYWINCALC_FIELDS, s(&fields)])
        .output()
        .expect("python runs");
    let text = String::from_utf8_lossy(&read.stdout);
    assert_eq!(text.trim(), "0.05 0.84 0.8 0.1 0.15", "{read:?}");
    let info = brtf(&["info", s(&fields)], "").ok();
    assert!(info.contains("  PermeabilityFactor 0.05"), "{info}");
    let err = brtf(
        &[
            "export",
            "--klems",
            "--material",
            s(&material),
            "--emissivity",
            "0.95,0.9",
            "--ir-transmittance",
            "0.1",
            "--out",
            s(&dir.path().join("bad")),
        ],
        "",
    )
    .err();
    assert!(err.contains("their sum exceeds 1"), "{err}");
    let bare = export(&["--solar", "none"], "bare");
    assert!(!std::fs::read_to_string(&bare).unwrap().contains(">Solar<"));
    assert!(
        !totals(&bare).status.success(),
        "pyWinCalc needs a Solar band"
    );
}
