//! Lobe sums and fitted orientations through brtf's tracer, end to end:
//! `brtf fit --lobes 2` (and `--model metal2`, orientation fitted) on the
//! synthetic scans of `data/alu-ggx`, then `brtf check`, `brtf render
//! gonio --fit` and `brtf render image --fit`.
//!
//! * `check`: with a point beam and detector the renderer reproduces the
//!   model (render/model energy ratio 1 within the reported Monte Carlo
//!   error), and over every fitted direction its misfit to the data is
//!   the fit's own RMS, as for the one-lobe fit.
//! * `render gonio --fit DIR --static`: the rendered lobe sum equals the
//!   weighted sum of `brtf eval` of each lobe written as its own primitive.
//! * `render image --fit DIR`: pictures of lobe sums; with `--radiance`
//!   the scene holds the lobe sum as a `mixfunc` tree, and real `rpict`
//!   renders the same picture (`render::rpict_difference`).

use crate::common::{brtf, parse_csv, repo_path, s, temp_dir, write_file};
use crate::render::{radiance_or_skip, rpict_difference};
use brtf_fit::FitResult;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// `brtf fit data/alu-ggx/*.mpc --model MODEL EXTRA… --out DIR` (no plots, no exports).
fn fit_alu(dir: &Path, model: &str, extra: &[&str]) -> PathBuf {
    let data = repo_path("data/alu-ggx");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&data)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 5, "the alu-ggx scans");
    let out = dir.join(format!("{model}{}", extra.join("")));
    let mut args: Vec<String> = vec!["fit".into()];
    args.extend(files.iter().map(|f| s(f).to_string()));
    args.extend(["--model", model].map(String::from));
    args.extend(extra.iter().map(|a| a.to_string()));
    args.extend(["--out", s(&out), "--no-plots", "--no-export"].map(String::from));
    brtf(&args, "").ok();
    out
}

/// `brtf check DIR ARGS…`: the printed table and `check.csv` as name → value maps.
fn check(dir: &Path, args: &[&str]) -> (String, Vec<HashMap<String, String>>) {
    let mut all = vec!["check", s(dir)];
    all.extend_from_slice(args);
    let table = brtf(&all, "").ok();
    let text = std::fs::read_to_string(dir.join("check.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows = lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect();
    (table, rows)
}

fn get(row: &HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|e| panic!("{key} = {:?}: {e}", row[key]))
}

/// Every row's render/model energy ratio is 1 within its reported Monte
/// Carlo error (never looser than `floor`).
#[track_caller]
fn ratio_within_error(rows: &[HashMap<String, String>], floor: f64, what: &str) {
    for row in rows {
        let ratio = get(row, "render_model_energy_ratio");
        let error = get(row, "mc_rms_rel").max(floor);
        assert!(
            (ratio - 1.0).abs() <= error,
            "{what} θ_in {}: render/model {ratio} beyond its error {error}",
            row["theta_in"]
        );
    }
}

/// The fitted rows' render-vs-data RMS against the fit's own RMS: the
/// largest relative difference.
fn misfit_gap(rows: &[HashMap<String, String>]) -> f64 {
    let fitted: Vec<_> = rows.iter().filter(|r| r["kind"] == "fitted").collect();
    assert_eq!(fitted.len(), 5, "one row per scan");
    fitted
        .iter()
        .map(|r| {
            let fit = get(r, "fit_rms_rel");
            (get(r, "render_vs_data_rms_rel") - fit).abs() / fit
        })
        .fold(0.0, f64::max)
}

#[test]
fn check_of_a_two_lobe_fit_renders_the_model_and_the_fit_s_misfit() {
    let dir = temp_dir();
    let one = fit_alu(dir.path(), "metal", &[]);
    let two = fit_alu(dir.path(), "metal", &["--lobes", "2"]);
    // Every fitted direction, a point beam and detector (the fit's ω = 0).
    let every = ["--source-omega", "0", "--detector-omega", "0"];
    let (_, one_rows) = check(&one, &every);
    let (table, two_rows) = check(&two, &every);
    assert!(table.contains("metal ×2 lobes (θ_in table)"), "{table}");
    assert_eq!(two_rows.len(), 9, "5 fitted + 4 intermediate incidences");
    ratio_within_error(&one_rows, 1e-9, "one lobe");
    ratio_within_error(&two_rows, 1e-9, "two lobes");
    for row in &two_rows {
        assert!(get(row, "render_vs_model_rms_rel") < 1e-4, "{row:?}");
    }
    // The render's misfit to the data is the fit's, for two lobes as for one.
    let (gap_one, gap_two) = (misfit_gap(&one_rows), misfit_gap(&two_rows));
    eprintln!("render-vs-data vs the fit's RMS: one lobe {gap_one:.1e}, two lobes {gap_two:.1e}");
    assert!(gap_one < 1e-4 && gap_two < 1e-4, "{gap_one} {gap_two}");
    // So is its E1, the share of the measured light in the wrong place.
    for row in one_rows.iter().chain(&two_rows) {
        if row["kind"] == "fitted" {
            let (fit, render) = (get(row, "fit_e1"), get(row, "render_vs_data_e1"));
            assert!(fit > 0.01 && (render - fit).abs() <= 1e-4 * fit, "{row:?}");
        }
    }
    // And the second lobe fits these scans better than one.
    for (a, b) in one_rows.iter().zip(&two_rows) {
        if a["kind"] == "fitted" {
            assert!(get(b, "fit_rms_rel") < get(a, "fit_rms_rel"), "{a:?} {b:?}");
        }
    }
    // A 1° beam and detector: Monte Carlo noise, the ratio still within it.
    let (_, rows) = check(
        &two,
        &[
            "--source-apex",
            "1",
            "--detector-apex",
            "1",
            "--samples",
            "64",
        ],
    );
    for row in &rows {
        assert!(
            get(row, "mc_rms_rel") > 1e-4,
            "finite apertures are noisy: {row:?}"
        );
    }
    ratio_within_error(&rows, 0.0, "two lobes, 1° apertures");
}

#[test]
fn check_of_a_fitted_orientation_fit_renders_the_model() {
    let dir = temp_dir();
    let oriented = fit_alu(dir.path(), "metal2", &[]);
    let fit = FitResult::read(&oriented).unwrap();
    assert!(
        fit.config.oriented,
        "metal2 fits its orientation on gonio scans"
    );
    let point = ["--source-omega", "0", "--detector-omega", "0"];
    let (table, rows) = check(&oriented, &point);
    assert!(
        table.contains("metal2 (orientation fitted) (θ_in table)"),
        "{table}"
    );
    ratio_within_error(&rows, 1e-9, "fitted orientation");
    for row in &rows {
        // The rendered frame turns with θ_in exactly as the model's.
        assert!(get(row, "render_vs_model_rms_rel") < 1e-4, "{row:?}");
    }
}

#[test]
fn render_gonio_of_a_lobe_sum_fit_is_the_weighted_sum_of_its_lobes() {
    let dir = temp_dir();
    let two = fit_alu(dir.path(), "metal", &["--lobes", "2"]);
    let rendered = parse_csv(
        &brtf(
            &[
                "render",
                "gonio",
                "--fit",
                s(&two),
                "--static",
                "--theta-in",
                "30",
                "--phi-in",
                "0",
                "--theta-step",
                "10",
                "--phi-step",
                "30",
                "--source-apex",
                "0.01",
                "--detector-apex",
                "0.01",
                "--samples",
                "16",
            ],
            "",
        )
        .ok(),
    );
    let directions: String = rendered
        .rows
        .iter()
        .map(|r| format!("{},{}\n", r[0], r[1]))
        .collect();
    // Each lobe of the static material as its own primitive, through `brtf eval`.
    let material = FitResult::read(&two).unwrap().static_composite().unwrap();
    assert_eq!(material.components().len(), 2);
    let mut want = vec![[0.0; 3]; rendered.rows.len()];
    for (k, (w, lobe)) in material.components().iter().enumerate() {
        let primitive = brtf_radiance::primitive_from_material(lobe, "lobe");
        let file = write_file(
            dir.path(),
            &format!("lobe{k}.rad"),
            &brtf_radiance::format_primitive(&primitive),
        );
        let args = [
            "eval",
            "--material",
            s(&file),
            "--theta-in",
            "30",
            "--phi-in",
            "0",
        ];
        let eval = parse_csv(&brtf(&args, &directions).ok());
        assert_eq!(eval.rows.len(), want.len());
        for (sum, row) in want.iter_mut().zip(&eval.rows) {
            for c in 0..3 {
                sum[c] += w * row[2 + c];
            }
        }
    }
    for (row, want) in rendered.rows.iter().zip(&want) {
        for c in 0..3 {
            let (got, err) = (row[2 + c], row[5 + c]);
            assert!(
                (got - want[c]).abs() <= 3.0 * err + 1e-4 * want[c],
                "({}, {}): rendered {got} ± {err} vs Σ w_k eval_k {}",
                row[0],
                row[1],
                want[c]
            );
        }
    }
    // The peak towards the mirror direction is the lobes', far above the base.
    let mirror = rendered
        .rows
        .iter()
        .position(|r| r[0] == 30.0 && r[1] == 180.0)
        .unwrap();
    assert!(rendered.rows[mirror][2] > 10.0 * rendered.rows[0][2]);
}

#[test]
fn render_image_of_a_lobe_sum_fit() {
    let dir = temp_dir();
    let two = fit_alu(dir.path(), "metal", &["--lobes", "2"]);
    let prefix = dir.path().join("pic");
    let args = [
        "render",
        "image",
        "--fit",
        s(&two),
        "--out",
        s(&prefix),
        "--width",
        "48",
        "--height",
        "36",
        "--samples",
        "2",
        "--specular-samples",
        "2",
    ];
    brtf(&args, "").ok();
    let hdr = std::fs::read(dir.path().join("pic.hdr")).unwrap();
    let pic = brtf_trace::hdr::read(&mut &hdr[..]).unwrap();
    assert_eq!((pic.width, pic.height), (48, 36));
    let lit = pic
        .pixels
        .iter()
        .filter(|p| p.iter().all(|c| c.is_finite()) && p[0] > 0.0)
        .count();
    assert!(lit > pic.pixels.len() / 2, "{lit} lit pixels");
    // `--radiance` writes the lobe sum as its primitives and mixfunc
    // tree, named as the scene uses it, and real rpict renders the same
    // picture (direct light only).
    let Some(radiance) = radiance_or_skip("render_image_of_a_lobe_sum_fit") else {
        return;
    };
    let (w, h) = (160, 120);
    let (ws, hs) = (w.to_string(), h.to_string());
    let stem = "fit2";
    let out = dir.path().join(stem);
    let args = [
        "render",
        "image",
        "--fit",
        s(&two),
        "--static",
        "--out",
        s(&out),
        "--width",
        &ws,
        "--height",
        &hs,
        "--samples",
        "4",
        "--no-jitter",
        "--direct-only",
        "--radiance",
        "--fresnel-k",
        "pyradiance",
        "--light-apex",
        "0.2",
        "--view-phi",
        "300",
        "--source-samples",
        "4",
    ];
    brtf(&args, "").ok();
    let rad = std::fs::read_to_string(dir.path().join("fit2.rad")).unwrap();
    for primitive in [
        "void metal sample.1",
        "void metal sample.2",
        "void mixfunc sample",
    ] {
        assert!(rad.contains(primitive), "no `{primitive}` in\n{rad}");
    }
    assert!(rad.find("void mixfunc sample") < rad.find("sample ring floor"));
    let mean = rpict_difference(&radiance, dir.path(), stem, (w, h));
    eprintln!("rpict vs brtf-trace, a two-lobe fit: {:.3}%", 100.0 * mean);
}
