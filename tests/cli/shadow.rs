//! The holder's shadow: `--mask-holder` masks its band in the instrument's
//! frame (it follows φ_in), and `--mask-holder auto` finds it as regions
//! far below their mirror across the plane of incidence, on both real pgII
//! scans and on a `brtf synth --holder-shadow` scan at φ_in 210°.
//! `residuals.csv` names the gate of every masked sample.

use crate::common::{brtf, s, temp_dir, write_file};
use crate::fit::real_scan;
use brtf_fit::FitResult;
use std::path::Path;

/// `brtf fit FILE --model MODEL ARGS --no-plots --no-export` into `out`,
/// read back with its `residuals.csv` rows (θ_out, φ_out − φ_in, gate).
fn fit(
    file: &Path,
    out: &Path,
    model: &str,
    args: &[&str],
) -> (FitResult, Vec<(f64, f64, String)>) {
    let mut all = vec!["fit", s(file), "--model", model, "--gray"];
    all.extend(args);
    all.extend(["--no-plots", "--no-export", "--force", "--out", s(out)]);
    brtf(&all, "").ok();
    let result = FitResult::read(&out.join("fit.json")).unwrap();
    let phi_in = result.incidences[0].phi_in;
    let mut reader = csv::Reader::from_path(out.join("residuals.csv")).unwrap();
    let rows = reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            let theta: f64 = r[2].parse().unwrap();
            let phi: f64 = r[3].parse().unwrap();
            let gate = r[r.len() - 1].to_string();
            (theta, (phi - phi_in).rem_euclid(360.0), gate)
        })
        .collect();
    (result, rows)
}

/// In the holder's band: φ_out − φ_in within 270 ± 45°, θ_out ≥ 73° in front.
fn in_band(theta: f64, relative_phi: f64) -> bool {
    (73.0..=90.0).contains(&theta) && (relative_phi - 270.0).abs() <= 45.0
}

#[test]
fn auto_finds_the_holder_shadow_on_both_real_scans() {
    for file in ["golden_paper.txt", "layer_020_030.txt"] {
        let dir = temp_dir();
        let out = dir.path().join("fit");
        let (result, rows) = fit(
            &real_scan(file),
            &out,
            "plastic",
            &["--mask-holder", "auto"],
        );
        let input = &result.provenance.inputs[0];
        assert_eq!(input.shadows.len(), 1, "{file}: {:?}", input.shadows);
        let region = &input.shadows[0];
        eprintln!("{file}: {region}");
        assert!(region.samples > 2000, "{file}: {region}");
        assert!(region.median_ratio < 0.3, "{file}: {region}");
        let [lo, hi] = region.phi_from_incidence_deg;
        assert!(
            (220.0..235.0).contains(&lo) && (310.0..325.0).contains(&hi),
            "{file}: {region}"
        );
        assert!(region.theta_deg[0] >= 70.0, "{file}: {region}");
        // residuals.csv names every masked sample, and fit.json counts them.
        let masked: Vec<_> = rows.iter().filter(|r| r.2 == "shadow").collect();
        assert_eq!(masked.len(), region.samples);
        let gate = result.incidences[0]
            .gates
            .iter()
            .find(|g| g.gate.name() == "shadow")
            .unwrap();
        assert_eq!(gate.removed, region.samples);
        assert!(
            masked
                .iter()
                .all(|r| r.0 >= 70.0 && (220.0..325.0).contains(&r.1))
        );
    }
}

#[test]
fn a_synthetic_shadow_at_phi_in_210_is_found_and_masked() {
    let dir = temp_dir();
    let truth = write_file(
        dir.path(),
        "p.rad",
        "void plastic p\n0\n0\n5 0.5 0.5 0.5 0.06 0.1\n",
    );
    let scans = dir.path().join("scans");
    let args = [
        "synth",
        "--material",
        s(&truth),
        "--theta-in",
        "30",
        "--phi-in",
        "210",
    ];
    brtf(
        &[&args[..], &["--holder-shadow", "--out", s(&scans)]].concat(),
        "",
    )
    .ok();
    let scan = std::fs::read_dir(&scans)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();

    let (plain, plain_rows) = fit(&scan, &dir.path().join("plain"), "plastic", &[]);
    let shadowed = plain_rows
        .iter()
        .filter(|r| in_band(r.0, r.1) && r.0 <= 85.0)
        .count();
    assert!(shadowed > 100, "{shadowed}");

    let (auto, rows) = fit(
        &scan,
        &dir.path().join("auto"),
        "plastic",
        &["--mask-holder", "auto"],
    );
    let found = rows.iter().filter(|r| r.2 == "shadow").count();
    let right = rows
        .iter()
        .filter(|r| r.2 == "shadow" && in_band(r.0, r.1))
        .count();
    // Every masked sample is in the shadow, and most of the shadow is
    // masked (the synthetic holder gap at φ_in + 90° leaves some
    // shadowed samples without a mirror to compare with).
    assert_eq!(right, found);
    assert!(
        found as f64 >= 0.85 * shadowed as f64,
        "{found} of {shadowed}"
    );
    let value = |f: &FitResult, name: &str| f.incidences[0].value(name).unwrap();
    for (name, truth) in [("spec", 0.06), ("rough", 0.1)] {
        assert!(
            (value(&auto, name) / truth - 1.0).abs() < 0.02,
            "{name} {}",
            value(&auto, name)
        );
    }
    let e1 = |f: &FitResult| f.incidences[0].e1.unwrap();
    assert!(
        e1(&auto) < 0.5 * e1(&plain),
        "{} vs {}",
        e1(&auto),
        e1(&plain)
    );

    // The fixed band follows φ_in: it masks the shadow, not φ_out 270°.
    let (_, band_rows) = fit(
        &scan,
        &dir.path().join("band"),
        "plastic",
        &["--mask-holder"],
    );
    let masked: Vec<_> = band_rows.iter().filter(|r| r.2 == "azimuth_band").collect();
    assert!(masked.len() >= shadowed);
    assert!(masked.iter().all(|r| in_band(r.0, r.1)));
}
