//! Known parameters back from `brtf synth` files (2 % noise, the default
//! apertures, blind spot and holder gap) at θ_in 0–60°, through `brtf fit`
//! from the command line: both lobes of a lobe sum within 2 %, and the
//! orientation of an anisotropic lobe within 1°.

use crate::common::{brtf, s, temp_dir, write_file};
use brtf_fit::FitResult;
use std::path::Path;

const THETA_IN: &str = "0,15,30,45,60";

/// Synthesises `truth` into `dir/scans`, fits it with `fit_args` and
/// returns the fit.
fn synth_and_fit(dir: &Path, truth: &str, fit_args: &[&str]) -> FitResult {
    let material = write_file(dir, "truth.rad", truth);
    let scans = dir.join("scans");
    brtf(
        &[
            "synth",
            "--material",
            s(&material),
            "--theta-in",
            THETA_IN,
            "--out",
            s(&scans),
        ],
        "",
    )
    .ok();
    let mut files: Vec<String> = std::fs::read_dir(&scans)
        .unwrap()
        .map(|e| e.unwrap().path().to_string_lossy().into_owned())
        .filter(|p| p.ends_with(".mpc"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 5, "{files:?}");
    let out = dir.join("fit");
    let mut args = vec!["fit".to_string()];
    args.extend(files);
    args.extend(fit_args.iter().map(|a| a.to_string()));
    args.extend(["--no-plots", "--out", s(&out)].map(String::from));
    brtf(&args, "").ok();
    FitResult::read(&out.join("fit.json")).unwrap()
}

fn within(found: f64, truth: f64, rel: f64) -> bool {
    (found - truth).abs() <= rel * truth
}

#[test]
fn two_plastic_lobes_come_back_within_two_percent() {
    let dir = temp_dir();
    let result = synth_and_fit(
        dir.path(),
        "void plastic two.1\n0\n0\n5 0.5 0.5 0.5 0.08 0.05\n\n\
         void plastic two.2\n0\n0\n5 0.5 0.5 0.5 0.08 0.2\n\n\
         void mixfunc two\n4 two.1 two.2 0.4 .\n0\n0\n",
        &["--model", "plastic", "--lobes", "2"],
    );
    let material = result.static_composite().expect("a lobe sum");
    let [(w1, m1), (w2, m2)] = material.components() else {
        panic!("two lobes expected: {material:?}")
    };
    println!(
        "weights {w1:.5} {w2:.5}, lobes {:?} {:?}",
        m1.args(),
        m2.args()
    );
    // Lobes come ordered by roughness, the sharper first as in the truth.
    assert!(
        within(*w1, 0.4, 0.02) && within(*w2, 0.6, 0.02),
        "{w1} {w2}"
    );
    for (lobe, roughness) in [(m1, 0.05), (m2, 0.2)] {
        let a = lobe.args();
        for (k, truth) in [(0, 0.5), (3, 0.08), (4, roughness)] {
            assert!(within(a[k], truth, 0.02), "argument {k}: {a:?}");
        }
    }
}

#[test]
fn two_metal_lobes_come_back_within_two_percent() {
    let dir = temp_dir();
    let result = synth_and_fit(
        dir.path(),
        "void metal m.1\n0\n0\n5 0.9 0.9 0.9 0.92 0.07\n\n\
         void metal m.2\n0\n0\n5 0.9 0.9 0.9 0.92 0.25\n\n\
         void mixfunc m\n4 m.1 m.2 0.7 .\n0\n0\n",
        &["--model", "metal", "--lobes", "2"],
    );
    let material = result.static_composite().expect("a lobe sum");
    let [(w1, m1), (w2, m2)] = material.components() else {
        panic!("two lobes expected: {material:?}")
    };
    println!(
        "weights {w1:.5} {w2:.5}, lobes {:?} {:?}",
        m1.args(),
        m2.args()
    );
    assert!(
        within(*w1, 0.7, 0.02) && within(*w2, 0.3, 0.02),
        "{w1} {w2}"
    );
    for (lobe, roughness) in [(m1, 0.07), (m2, 0.25)] {
        let a = lobe.args();
        for (k, truth) in [(0, 0.9), (3, 0.92), (4, roughness)] {
            assert!(within(a[k], truth, 0.02), "argument {k}: {a:?}");
        }
    }
}

/// The angle of `orientation` from u, in degrees, with the roughnesses it
/// belongs to: a quarter turn swaps u and v, so the truth's (30°, 0.05 along
/// u) may come back as (120°, 0.05 along v).
fn orientation_matches(found_deg: f64, u: f64, v: f64, truth_deg: f64, truth_uv: [f64; 2]) -> bool {
    let turn = (found_deg - truth_deg).rem_euclid(180.0);
    let (off, uv) = if (turn - 90.0).abs() < 45.0 {
        ((turn - 90.0).abs(), [v, u])
    } else {
        (turn.min(180.0 - turn), [u, v])
    };
    off <= 1.0 && within(uv[0], truth_uv[0], 0.02) && within(uv[1], truth_uv[1], 0.02)
}

#[test]
fn an_anisotropic_lobe_s_orientation_comes_back_within_one_degree() {
    for kind in ["plastic2", "metal2"] {
        let dir = temp_dir();
        let args = if kind == "plastic2" {
            "0.5 0.5 0.5 0.08 0.05 0.15"
        } else {
            "0.9 0.9 0.9 0.92 0.05 0.15"
        };
        // Orientation vector at 30° from u in the surface plane.
        let truth = format!("void {kind} brushed\n4 0.8660254037844387 0.5 0 .\n0\n6 {args}\n");
        let result = synth_and_fit(dir.path(), &truth, &["--model", kind]);
        assert!(
            result.config.oriented,
            "{kind}: the orientation is fitted by default"
        );
        let material = result.static_composite().expect("a material");
        let [(_, m)] = material.components() else {
            panic!("one lobe expected")
        };
        let o = m.orientation();
        let angle = o.y.atan2(o.x).to_degrees();
        let a = m.args();
        println!("{kind}: orientation {angle:.3}°, arguments {a:?}");
        assert!(
            orientation_matches(angle, a[4], a[5], 30.0, [0.05, 0.15]),
            "{kind}: orientation {angle}° with roughnesses {} {}",
            a[4],
            a[5]
        );
    }
}
