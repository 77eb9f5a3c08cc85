//! The `brtf eval` contract: CSV in and out, material selection, options,
//! error messages.

use crate::common::{brtf, parse_csv, s, temp_dir, write_file};
use std::f64::consts::PI;
use std::path::Path;

const HEADER: &str = "theta_out,phi_out,r,g,b";

/// `brtf eval --material file [extra...] --theta-in t --phi-in p`.
fn eval_args(file: &Path, theta_in: f64, phi_in: f64, extra: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = vec!["eval".into(), "--material".into(), s(file).into()];
    args.extend(extra.iter().map(|a| (*a).to_string()));
    args.extend([
        "--theta-in".into(),
        theta_in.to_string(),
        "--phi-in".into(),
        phi_in.to_string(),
    ]);
    args
}

/// The r,g,b of every output row.
#[track_caller]
fn eval_rgb(file: &Path, theta_in: f64, phi_in: f64, extra: &[&str], input: &str) -> Vec<[f64; 3]> {
    let csv = parse_csv(&brtf(&eval_args(file, theta_in, phi_in, extra), input).ok());
    csv.rows.iter().map(|r| [r[2], r[3], r[4]]).collect()
}

/// One value (channel 0) for one outgoing direction.
#[track_caller]
fn eval_one(file: &Path, theta_in: f64, phi_in: f64, extra: &[&str], out: (f64, f64)) -> f64 {
    eval_rgb(
        file,
        theta_in,
        phi_in,
        extra,
        &format!("{},{}\n", out.0, out.1),
    )[0][0]
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn header_columns_and_echo() {
    let dir = temp_dir();
    let file = write_file(
        dir.path(),
        "m.rad",
        "void metal alu\n0\n0\n5 .8 .8 .8 .7 .15\n",
    );
    let input = "0,0\n45.5,180\n30,-90\n120,10\n";
    let out = brtf(&eval_args(&file, 45.5, 0.0, &[]), input).ok();
    assert_eq!(out.lines().next(), Some(HEADER));
    let csv = parse_csv(&out);
    assert_eq!(csv.rows.len(), 4, "one row per direction:\n{out}");
    let echoed: Vec<(f64, f64)> = csv.rows.iter().map(|r| (r[0], r[1])).collect();
    assert_eq!(
        echoed,
        [(0.0, 0.0), (45.5, 180.0), (30.0, -90.0), (120.0, 10.0)]
    );
    for row in &csv.rows {
        assert!(
            row[2..].iter().all(|x| x.is_finite() && *x >= 0.0),
            "{row:?}"
        );
    }
    // The mirror direction is the brightest; metal is opaque (0 behind).
    assert!(csv.rows[1][2] > csv.rows[0][2] && csv.rows[1][2] > csv.rows[2][2]);
    assert_eq!(&csv.rows[3][2..], &[0.0, 0.0, 0.0]);
    // An empty input gives just the header.
    assert_eq!(
        brtf(&eval_args(&file, 10.0, 0.0, &[]), "").ok().trim_end(),
        HEADER
    );
}

#[test]
fn stdin_with_and_without_header() {
    let dir = temp_dir();
    let file = write_file(
        dir.path(),
        "m.rad",
        "void plastic p 0 0 5 .3 .4 .5 .05 .1\n",
    );
    let rows = "10,0\n30,180\n60,90\n100,0\n";
    let plain = brtf(&eval_args(&file, 30.0, 0.0, &[]), rows).ok();
    let with_header = brtf(
        &eval_args(&file, 30.0, 0.0, &[]),
        &format!("theta_out,phi_out\n{rows}"),
    )
    .ok();
    assert_eq!(plain, with_header);
    assert_eq!(parse_csv(&plain).rows.len(), 4);
}

#[test]
fn lambertian_plastic_is_rho_over_pi() {
    let dir = temp_dir();
    let file = write_file(
        dir.path(),
        "lambert.rad",
        "void plastic lambert\n0\n0\n5 0.2 0.5 0.8 0 0\n",
    );
    let input = "0,0\n30,0\n45,200\n89.5,10\n90.5,0\n135,45\n180,0\n";
    for theta_in in [0.0, 30.0, 75.0] {
        let rgb = eval_rgb(&file, theta_in, 15.0, &[], input);
        for (i, f) in rgb.iter().enumerate() {
            let expected = if i < 4 {
                [0.2 / PI, 0.5 / PI, 0.8 / PI]
            } else {
                [0.0; 3]
            };
            for c in 0..3 {
                assert!(
                    (f[c] - expected[c]).abs() <= 1e-12,
                    "θ_in {theta_in} row {i}: {f:?}"
                );
            }
        }
    }
}

#[test]
fn name_selects_the_material() {
    let dir = temp_dir();
    let text = "# two materials and some geometry\n\
                void plastic grey20\n0\n0\n5 .2 .2 .2 0 0\n\n\
                void plastic grey40\n0\n0\n5 .4 .4 .4 0 0\n\n\
                grey20 polygon floor\n0\n0\n9 0 0 0 1 0 0 0 1 0\n";
    let file = write_file(dir.path(), "two.rad", text);
    let f20 = eval_one(&file, 20.0, 0.0, &["--name", "grey20"], (10.0, 0.0));
    let f40 = eval_one(&file, 20.0, 0.0, &["--name", "grey40"], (10.0, 0.0));
    assert!(rel(f20, 0.2 / PI) < 1e-12, "{f20}");
    assert!(rel(f40, 0.4 / PI) < 1e-12, "{f40}");

    // Several materials and no --name: an error that says what to do.
    let err = brtf(&eval_args(&file, 20.0, 0.0, &[]), "10,0\n").err();
    assert!(err.contains("--name") && err.contains(s(&file)), "{err}");
    // A name that is not there.
    let err = brtf(
        &eval_args(&file, 20.0, 0.0, &["--name", "grey60"]),
        "10,0\n",
    )
    .err();
    assert!(err.contains("grey60") && err.contains(s(&file)), "{err}");

    // One Ward-type material among other primitives: no --name needed.
    let one = write_file(
        dir.path(),
        "one.rad",
        "void light lamp 0 0 3 10 10 10\n\
         lamp sphere bulb 0 0 4 0 0 5 0.5\n\
         void metal2 brushed 4 1 0 0 . 0 6 .6 .6 .6 .9 .05 .2\n",
    );
    let out = brtf(&eval_args(&one, 20.0, 0.0, &[]), "20,180\n").ok();
    assert!(parse_csv(&out).rows[0][2] > 1.0, "{out}");
}

/// Asserts that `brtf eval` fails on `text` with a `file:line:` message for
/// one of `lines`.
#[track_caller]
fn assert_material_error(text: &str, lines: &[usize], also: &str) {
    let dir = temp_dir();
    let file = write_file(dir.path(), "bad.rad", text);
    let err = brtf(&eval_args(&file, 0.0, 0.0, &[]), "10,0\n").err();
    let path = s(&file);
    assert!(
        lines.iter().any(|l| err.contains(&format!("{path}:{l}:"))),
        "expected `{path}:<one of {lines:?}>:` in: {err}"
    );
    assert!(err.contains(also), "expected `{also}` in: {err}");
}

#[test]
fn bad_material_files_report_file_and_line() {
    // Wrong argument count: the primitive starts on line 3, its reals are on line 6.
    assert_material_error(
        "# comment\n\nvoid plastic p\n0\n0\n4 .5 .5 .5 0\n",
        &[3, 6],
        "p",
    );
    // Anisotropic type without its 4 string arguments.
    assert_material_error("\nvoid metal2 m\n0\n0\n6 .5 .5 .5 .9 .1 .2\n", &[2, 3], "m");
    // Text where a number belongs (on line 6).
    assert_material_error(
        "# comment\nvoid plastic p\n0\n0\n5 .5 .5\n .5 abc 0\n",
        &[6],
        "abc",
    );
    // Unknown primitive type (line 4).
    assert_material_error(
        "# c\n\n\nvoid plastik p\n0\n0\n5 .5 .5 .5 0 0\n",
        &[4],
        "plastik",
    );
    // A file that ends in the middle of a primitive.
    assert_material_error("void plastic p\n0\n0\n5 .5 .5 .5\n", &[1, 4], "p");
    // A missing file is an error too (no line to report).
    let err = brtf(
        &eval_args(Path::new("/nonexistent/m.rad"), 0.0, 0.0, &[]),
        "",
    )
    .err();
    assert!(err.contains("/nonexistent/m.rad"), "{err}");
}

#[test]
fn bad_input_lines_report_stdin_and_line() {
    let dir = temp_dir();
    let file = write_file(dir.path(), "m.rad", "void plastic p 0 0 5 .5 .5 .5 0 0\n");
    let cases = [
        ("theta_out,phi_out\n10,20\n10,abc\n", 3),
        ("10,20\n10\n", 2),
        ("10,20,30\n", 1),
        ("10,20\n20,30\nx,y\n", 3),
        ("10,nan\n", 1),
    ];
    for (input, line) in cases {
        let err = brtf(&eval_args(&file, 0.0, 0.0, &[]), input).err();
        assert!(
            err.contains(&format!("<stdin>:{line}:")),
            "input {input:?}: {err}"
        );
    }
}

#[test]
fn fresnel_constant_for_roughness_zero() {
    // radiance-brdf.md §5: plastic 0.5 0.5 0.5 0.05 0, light and view along
    // the normal: 0.1509401 with the pyradiance constant, 0.1511972 classic.
    let dir = temp_dir();
    let file = write_file(
        dir.path(),
        "m.rad",
        "void plastic smooth 0 0 5 0.5 0.5 0.5 0.05 0\n",
    );
    let py = eval_one(&file, 0.0, 0.0, &["--fresnel-k", "pyradiance"], (0.0, 0.0));
    let classic = eval_one(&file, 0.0, 0.0, &["--fresnel-k", "classic"], (0.0, 0.0));
    let default = eval_one(&file, 0.0, 0.0, &[], (0.0, 0.0));
    let number = eval_one(
        &file,
        0.0,
        0.0,
        &["--fresnel-k", "0.00202943064"],
        (0.0, 0.0),
    );
    assert!((py - 0.1509401).abs() < 1e-7, "{py}");
    assert!((classic - 0.1511972).abs() < 1e-7, "{classic}");
    assert_eq!(default, classic, "classic is the default");
    assert!(rel(number, py) < 1e-9, "{number} vs {py}");
    let err = brtf(
        &eval_args(&file, 0.0, 0.0, &["--fresnel-k", "blue"]),
        "0,0\n",
    )
    .err();
    assert!(err.contains("blue"), "{err}");
}

#[test]
fn variants_differ_off_peak() {
    let dir = temp_dir();
    let file = write_file(
        dir.path(),
        "m.rad",
        "void plastic p 0 0 5 0.5 0.5 0.5 0.5 0.2\n",
    );
    let f =
        |variant: &str, out: (f64, f64)| eval_one(&file, 60.0, 0.0, &["--variant", variant], out);
    // radiance-brdf.md §4: W-G-M-D and the 2004 manual agree exactly at the
    // mirror peak and differ away from it.
    let peak = (60.0, 180.0);
    assert!(rel(f("manual2004", peak), f("radiance", peak)) < 1e-9);
    for off in [(40.0, 180.0), (75.0, 180.0), (60.0, 150.0)] {
        let (m, r) = (f("manual2004", off), f("radiance", off));
        assert!(
            rel(m, r) > 0.01,
            "off-peak {off:?}: manual2004 {m} vs radiance {r}"
        );
    }
    assert_eq!(
        f("radiance", peak),
        eval_one(&file, 60.0, 0.0, &[], peak),
        "radiance is the default"
    );
    let w = f("ward1992", (40.0, 180.0));
    assert!(w.is_finite() && w > 0.0 && rel(w, f("radiance", (40.0, 180.0))) > 1e-3);

    // Transmission: the manual's 1/(|c_i| c_o) against rtrace's 1/sqrt(|c_i| c_o).
    let trans = write_file(
        dir.path(),
        "t.rad",
        "void trans t 0 0 7 .8 .8 .8 .04 .1 .6 1\n",
    );
    let through = (135.0, 180.0);
    let m = eval_one(&trans, 45.0, 0.0, &["--variant", "manual2004"], through);
    let r = eval_one(&trans, 45.0, 0.0, &["--variant", "radiance"], through);
    let ratio = m / r;
    assert!(
        (ratio - 2f64.sqrt()).abs() < 1e-6,
        "manual2004/radiance at 45°/45° = {ratio}"
    );

    let run = brtf(
        &eval_args(&file, 60.0, 0.0, &["--variant", "ward2025"]),
        "0,0\n",
    );
    assert!(run.err().contains("ward2025"));
}

#[test]
fn source_omega_widens_lobes() {
    let dir = temp_dir();
    let omega = 6.8e-5; // about the sun
    // Reflection: α² → α² + ω/(4π) on flat surfaces only. At the mirror
    // peak the lobe scales by α²/α_eff² (spec 1: no diffuse part).
    let metal = write_file(dir.path(), "m.rad", "void metal m 0 0 5 .9 .9 .9 1 .01\n");
    let peak = (30.0, 180.0);
    let om = omega.to_string();
    let sharp = eval_one(&metal, 30.0, 0.0, &[], peak);
    let wide = eval_one(&metal, 30.0, 0.0, &["--source-omega", &om], peak);
    let curved = eval_one(
        &metal,
        30.0,
        0.0,
        &["--source-omega", &om, "--curved"],
        peak,
    );
    let a2 = 0.01f64.powi(2);
    let expected = a2 / (a2 + omega / (4.0 * PI));
    assert!(
        rel(wide / sharp, expected) < 1e-9,
        "{} vs {expected}",
        wide / sharp
    );
    assert!(rel(curved, sharp) < 1e-12, "curved: no reflection widening");

    // Transmission: β = α² + ω/π always, flat or not. With tspec 1 there is
    // no diffuse transmission, so at the straight-through peak f ∝ 1/β.
    let trans = write_file(
        dir.path(),
        "t.rad",
        "void trans t 0 0 7 .8 .8 .8 .04 .05 .6 1\n",
    );
    let through = (150.0, 180.0);
    let sharp = eval_one(&trans, 30.0, 0.0, &[], through);
    let wide = eval_one(&trans, 30.0, 0.0, &["--source-omega", &om], through);
    let curved = eval_one(
        &trans,
        30.0,
        0.0,
        &["--source-omega", &om, "--curved"],
        through,
    );
    let a2 = 0.05f64.powi(2);
    let expected = a2 / (a2 + omega / PI);
    assert!(
        rel(wide / sharp, expected) < 1e-9,
        "{} vs {expected}",
        wide / sharp
    );
    assert!(
        rel(curved, wide) < 1e-12,
        "transmission widening does not depend on --curved"
    );

    let err = brtf(
        &eval_args(&metal, 30.0, 0.0, &["--source-omega=-1"]),
        "0,0\n",
    )
    .err();
    assert!(err.contains("source-omega"), "{err}");
}
