//! brtf's fitter against scipy's `least_squares` on the same objective:
//! both real pgII scans, a grey metal with a free scale, with absolute,
//! relative and log residuals and with a Huber loss, and a two-lobe metal
//! (scipy from six starts). brtf's cost (by
//! scipy's own cost function) must never be above scipy's, and the Huber
//! fit, iterated until its weights settle, must match scipy's
//! `loss="huber"` within 1% in cost.
//!
//! The peer is `scripts/scipy_peer.py --objective`, run with the Python of
//! the repository's `.venv` (`bash scripts/test.sh` installs numpy and
//! scipy there) or `$BRTF_PYTHON`. Without it the test warns and passes,
//! except under `CI`, where it fails.

use crate::common::{repo_path, temp_dir};
use brtf_fit::{FitConfig, Recipe, ResidualKind, RobustLoss, fit_incidence};
use brtf_model::MaterialKind;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::Command;

fn python() -> Option<PathBuf> {
    let candidate = std::env::var_os("BRTF_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo_path(".venv/bin/python"));
    let works = Command::new(&candidate)
        .args(["-c", "import numpy, scipy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if works {
        Some(candidate)
    } else if std::env::var_os("CI").is_some() {
        panic!(
            "{} with numpy and scipy is needed under CI",
            candidate.display()
        );
    } else {
        eprintln!(
            "warning: no Python with numpy and scipy ({}); peer test skipped",
            candidate.display()
        );
        None
    }
}

#[test]
fn brtf_is_never_above_scipy_on_the_same_objective() {
    let Some(python) = python() else {
        return;
    };
    let dir = temp_dir();
    let peer = repo_path("scripts/scipy_peer.py");
    for scan in ["golden_paper.txt", "layer_020_030.txt"] {
        let path = repo_path("../shared/data/rgl-epfl-pgII-raw").join(scan);
        let measurement = brtf_gonio::read_path(&path).unwrap();
        let prepared = Recipe::for_kind(MaterialKind::Metal)
            .prepare(measurement, scan)
            .unwrap();
        let data = prepared.incidence_data();
        let csv = dir.path().join(format!("{scan}.csv"));
        let mut text = String::from("vx,vy,vz,y,w\n");
        for s in &data.samples {
            let _ = writeln!(
                text,
                "{},{},{},{},{}",
                s.view.x, s.view.y, s.view.z, s.value[0], s.weight
            );
        }
        std::fs::write(&csv, text).unwrap();
        for (label, residual, loss, lobes) in [
            ("absolute", ResidualKind::Absolute, RobustLoss::None, 1),
            ("relative", ResidualKind::Relative, RobustLoss::None, 1),
            ("log", ResidualKind::Log, RobustLoss::None, 1),
            (
                "absolute",
                ResidualKind::Absolute,
                RobustLoss::Huber(1.345),
                1,
            ),
            ("absolute", ResidualKind::Absolute, RobustLoss::None, 2),
        ] {
            let mut config = FitConfig::new(MaterialKind::Metal);
            config.gray = true;
            config.free_scale = true;
            config.residual = residual;
            config.loss = loss;
            config.lobes = lobes;
            let report = fit_incidence(&data, &config).unwrap();
            let value = |name: &str| report.value(name).unwrap();
            let params: Vec<f64> = if lobes == 2 {
                ["scale", "spec", "split1", "rough1", "rough2"]
                    .iter()
                    .map(|n| value(n))
                    .collect()
            } else {
                vec![value("scale"), value("spec"), value("rough")]
            };
            let mut settings = serde_json::json!({
                "light": data.light().to_array(),
                "floor": report.floor,
                "residual": label,
                "lobes": lobes,
                "cosine_weighted": data.cosine_weighted,
                "brtf": params,
            });
            if let RobustLoss::Huber(c) = loss {
                let robust = report.robust.expect("a robust record");
                assert!(robust.settled, "{scan}: {robust:?}");
                settings["huber_f_scale"] = (c * robust.sigma).into();
            }
            let out = Command::new(&python)
                .arg(&peer)
                .args(["--objective", csv.to_str().unwrap(), &settings.to_string()])
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let answer: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            let scipy = answer["cost_scipy"].as_f64().unwrap();
            let brtf = answer["cost_at_brtf"].as_f64().unwrap();
            eprintln!(
                "{scan} {label} {loss:?} {lobes} lobe(s): brtf {brtf:.9e} (own {:.9e}), scipy {scipy:.9e} {}",
                report.cost, answer["params_scipy"]
            );
            if loss == RobustLoss::None {
                // The same objective: scipy's cost at brtf's parameters is brtf's own.
                assert!(
                    (brtf / report.cost - 1.0).abs() < 1e-6,
                    "{scan} {label}: {brtf} vs {}",
                    report.cost
                );
                assert!(
                    brtf <= scipy * (1.0 + 1e-9),
                    "{scan} {label}: brtf {brtf} > scipy {scipy}"
                );
            } else {
                assert!(
                    brtf <= scipy * 1.01,
                    "{scan} huber: brtf {brtf} vs scipy {scipy}"
                );
            }
        }
    }
}
