//! `brtf plot`: the data set's plots and report through the CLI, the report
//! in a real browser, speed on a real 120 000-point scan, and errors.
//!
//! The browser test drives headless Chromium (see [`crate::browser`]): it
//! loads `report.html` from disk, fails on any error in the
//! browser log (console errors and resources that failed to load), checks
//! that the parameter table is shown and every image decoded, and saves a
//! screenshot. Without Chromium it warns and skips, except under `CI`,
//! where it fails.

use crate::browser::{Driver, HEAVY, base64_decode, browser_and_driver, session, severe};
use crate::common::{brtf, repo_path, s, temp_dir};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Fits the `data/alu-ggx` set into `dir/fit` (no plots) and returns the folder.
fn fit_data_set(dir: &Path) -> PathBuf {
    let out = dir.join("fit");
    let mut args: Vec<String> = vec!["fit".into()];
    for t in [0, 15, 30, 45, 60] {
        args.push(s(&repo_path(&format!("data/alu-ggx/alu-ggx:+{t}+0.mpc"))).into());
    }
    for a in [
        "--model",
        "metal",
        "--no-export",
        "--no-plots",
        "--out",
        s(&out),
    ] {
        args.push(a.into());
    }
    brtf(&args, "").ok();
    out
}

#[test]
fn brtf_plot_draws_every_chart_and_the_report() {
    let dir = temp_dir();
    let fit = fit_data_set(dir.path());
    let stdout = brtf(&["plot", s(&fit)], "").ok();
    assert!(stdout.starts_with("brtf plot: 29 files"), "{stdout}");
    for t in [0, 15, 30, 45, 60] {
        for kind in ["map", "cut"] {
            for ext in ["svg", "png"] {
                let f = fit.join(format!("plots/{kind}-t{t}.{ext}"));
                assert!(f.is_file(), "{} missing", f.display());
            }
        }
    }
    for stem in ["params", "rho", "rms", "cuts"] {
        assert!(fit.join(format!("plots/{stem}.svg")).is_file());
        assert!(fit.join(format!("plots/{stem}.png")).is_file());
    }
    let html = std::fs::read_to_string(fit.join("report.html")).unwrap();
    assert!(html.contains("id=\"param-table\""));
}

#[test]
fn brtf_plot_errors_and_warnings() {
    let dir = temp_dir();
    let err = brtf(&["plot", s(&dir.path().join("nowhere"))], "").err();
    assert!(
        err.contains("fit.json") && err.contains("cannot read"),
        "{err}"
    );
    let err = brtf(&["plot", s(dir.path()), "--ratio", "0.5"], "").err();
    assert!(err.contains("--ratio"), "{err}");

    // Relative measurement paths that cannot be found from here: the maps
    // and cuts are skipped with a warning, the rest is drawn.
    let fit = dir.path().join("moved");
    std::fs::create_dir(&fit).unwrap();
    std::fs::copy(repo_path("fits/alu-ggx/fit.json"), fit.join("fit.json")).unwrap();
    let out = Command::new(crate::common::BRTF)
        .args(["plot", s(&fit)])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(stderr.matches("warning").count(), 5, "{stderr}");
    assert!(stderr.contains("measurement file not found"), "{stderr}");
    assert!(fit.join("plots/params.svg").is_file());
    assert!(!fit.join("plots/map-t30.svg").exists());
    // With the repository as a search folder they are found again.
    let stdout = Command::new(crate::common::BRTF)
        .args(["plot", s(&fit), "--search-dir", s(&repo_path(""))])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(stdout.status.success());
    assert!(fit.join("plots/map-t30.svg").is_file());
}

fn real_scan(name: &str) -> PathBuf {
    let path = repo_path("../shared/data/rgl-epfl-pgII-raw").join(name);
    assert!(
        path.exists(),
        "{} is missing: CI always has ../shared/data",
        path.display()
    );
    path
}

#[test]
fn plotting_a_120k_point_scan_takes_under_a_second() {
    let dir = temp_dir();
    let fit = dir.path().join("golden");
    brtf(
        &[
            "fit",
            s(&real_scan("golden_paper.txt")),
            "--model",
            "metal",
            "--no-export",
            "--no-plots",
            "--out",
            s(&fit),
        ],
        "",
    )
    .ok();
    let text = std::fs::read_to_string(fit.join("fit.json")).unwrap();
    let result: brtf_fit::FitResult = serde_json::from_str(&text).unwrap();
    assert_eq!(result.incidences.len(), 1);
    assert!(result.incidences[0].n_points > 120_000);
    // The best of five runs, never while the browser test runs: other
    // tests share the machine.
    let _alone = HEAVY.lock().unwrap_or_else(|e| e.into_inner());
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let started = Instant::now();
        let out = brtf(&["plot", s(&fit)], "").ok();
        best = best.min(started.elapsed().as_secs_f64());
        // One incidence: its map and cut (SVG, PNG) and the report; no
        // chart over θ_in.
        assert!(out.contains("5 files"), "{out}");
    }
    eprintln!(
        "brtf plot of a {}-point incidence: {best:.3} s (best of 5)",
        result.incidences[0].n_points
    );
    assert!(best < 1.0, "plotting took {best:.3} s");
    assert!(fit.join("plots/map-t26.8421.png").is_file());
    assert!(!fit.join("plots/params.png").exists());
}

#[test]
fn the_report_opens_in_headless_chromium_without_errors() {
    let Some((browser, driver)) = browser_and_driver() else {
        return;
    };
    let dir = temp_dir();
    let fit = fit_data_set(dir.path());
    brtf(&["plot", s(&fit)], "").ok();
    let report = std::fs::canonicalize(fit.join("report.html")).unwrap();

    let _alone = HEAVY.lock().unwrap_or_else(|e| e.into_inner());
    let driver = Driver::start(&driver);
    let id = session(&driver, &browser, &dir.path().join("chromium-profile"), &[]);
    let at = |p: &str| format!("/session/{id}{p}");
    driver.must(
        "POST",
        &at("/url"),
        Some(json!({"url": format!("file://{}", s(&report))})),
    );
    let state = driver.must(
        "POST",
        &at("/execute/sync"),
        Some(json!({"args": [], "script": "
            const t = document.getElementById('param-table');
            return {
                ready: document.readyState,
                title: document.title,
                rows: t ? t.querySelectorAll('tbody tr').length : -1,
                tableHeight: t ? t.getBoundingClientRect().height : 0,
                tableOverflow: t ? t.getBoundingClientRect().right - document.documentElement.clientWidth : 1e9,
                images: document.images.length,
                note: document.getElementById('theta-note') !== null,
                broken: Array.from(document.images)
                    .filter(i => !i.complete || i.naturalWidth === 0)
                    .map(i => i.getAttribute('src')),
            };"})),
    );
    let log = driver.must("POST", &at("/se/log"), Some(json!({"type": "browser"})));
    let shot = driver.must("GET", &at("/screenshot"), None);

    // A wide parameter table, two anisotropic lobes with a fitted
    // orientation (14 columns), also fits the page at 1280 px. It is a fit
    // of one incidence: no chart over θ_in, one line in their place.
    let wide = dir.path().join("wide");
    let alu = repo_path("data/alu-ggx/alu-ggx:+30+0.mpc");
    let args = [
        "fit",
        s(&alu),
        "--model",
        "plastic2",
        "--lobes",
        "2",
        "--no-export",
    ];
    brtf(&[&args[..], &["--out", s(&wide)]].concat(), "").ok();
    let wide_report = std::fs::canonicalize(wide.join("report.html")).unwrap();
    driver.must(
        "POST",
        &at("/url"),
        Some(json!({"url": format!("file://{}", s(&wide_report))})),
    );
    let wide_state = driver.must(
        "POST",
        &at("/execute/sync"),
        Some(json!({"args": [], "script": "
            const t = document.getElementById('param-table');
            const note = document.getElementById('theta-note');
            const theta = document.getElementById('theta');
            return {
                columns: t ? t.querySelectorAll('thead th').length : -1,
                overflow: t ? t.getBoundingClientRect().right - document.documentElement.clientWidth : 1e9,
                images: Array.from(document.images).map(i => i.getAttribute('src')),
                broken: Array.from(document.images)
                    .filter(i => !i.complete || i.naturalWidth === 0)
                    .map(i => i.getAttribute('src')),
                thetaImages: theta ? theta.querySelectorAll('img').length : -1,
                note: note ? note.innerText : null,
                noteShown: note ? note.getBoundingClientRect().height > 0 : false,
            };"})),
    );
    let mut wide_images: Vec<&str> = wide_state["images"]
        .as_array()
        .expect("the images")
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    wide_images.sort();
    assert_eq!(
        wide_images,
        ["plots/cut-t30.svg", "plots/map-t30.svg"],
        "{wide_state}"
    );
    assert_eq!(wide_state["broken"], json!([]), "{wide_state}");
    assert_eq!(wide_state["thetaImages"], json!(0), "{wide_state}");
    assert_eq!(
        wide_state["note"],
        json!("One incidence fitted: the charts over θ_in need two or more."),
        "{wide_state}"
    );
    assert_eq!(wide_state["noteShown"], json!(true), "{wide_state}");
    assert!(
        wide_state["columns"].as_i64().unwrap() >= 14,
        "{wide_state}"
    );
    assert!(
        wide_state["overflow"].as_f64().unwrap() <= 0.0,
        "{wide_state}"
    );

    // The check itself: a page with a missing image and a console error
    // must show up in the log as errors.
    let bad = fit.join("bad.html");
    std::fs::write(
        &bad,
        "<!DOCTYPE html><title>bad</title><img src=\"plots/nope.svg\">\
         <script>console.error('on purpose')</script>",
    )
    .unwrap();
    let bad = std::fs::canonicalize(bad).unwrap();
    driver.must(
        "POST",
        &at("/url"),
        Some(json!({"url": format!("file://{}", s(&bad))})),
    );
    let bad_log = driver.must("POST", &at("/se/log"), Some(json!({"type": "browser"})));
    let _ = driver.call("DELETE", &at(""), None);
    let bad_errors = severe(&bad_log).len();
    assert_eq!(bad_errors, 2, "the log must catch errors: {bad_log:#}");

    let errors = severe(&log);
    assert!(errors.is_empty(), "browser errors: {errors:#?}");
    assert_eq!(state["ready"], json!("complete"), "{state}");
    assert_eq!(state["title"], json!("alu-ggx: brtf fit report"), "{state}");
    assert_eq!(state["rows"], json!(6), "5 incidences + all: {state}");
    assert!(state["tableHeight"].as_f64().unwrap() > 50.0, "{state}");
    // At 1280 px the parameter table fits the page: nothing cut off.
    assert!(state["tableOverflow"].as_f64().unwrap() <= 0.0, "{state}");
    assert_eq!(state["images"], json!(14), "{state}");
    assert_eq!(state["note"], json!(false), "five incidences: {state}");
    assert_eq!(state["broken"], json!([]), "{state}");
    let png = base64_decode(shot.as_str().expect("a base64 screenshot"));
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 10_000);
    let saved = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-screenshot.png");
    std::fs::write(&saved, &png).unwrap();
    eprintln!(
        "report.html loaded in Chromium without errors; screenshot: {}",
        saved.display()
    );
}
