//! Tensor trees in: trees that Radiance's `bsdf2ttree -f` made from the
//! function of known `trans` and `plastic` materials
//! (`brtf_radiance::export::klems_cal`), summarised by `brtf info` against
//! Radiance's `checkBSDF`, and fitted back with `brtf fit`.

use crate::common::{brtf, radiance_command, radiance_tools_or_skip, s, temp_dir};
use brtf_model::{Material, MaterialKind};
use std::path::{Path, PathBuf};

/// `bsdf2ttree -t<rank> -g <order> -f m.cal brtf_bsdf` in `dir`: the
/// front components rf and tf of `material`.
fn radiance_tree(bin: &Path, dir: &Path, material: &Material, rank: u8, order: u8) -> PathBuf {
    let cal = brtf_radiance::export::klems_cal::bsdf_function_cal(material).unwrap();
    std::fs::write(dir.join("m.cal"), cal).unwrap();
    let out = radiance_command(bin, "bsdf2ttree", dir)
        .args([&format!("-t{rank}"), "-g", &order.to_string()])
        .args(["-f", "m.cal", "brtf_bsdf"])
        .output()
        .expect("bsdf2ttree runs");
    let tail: String = String::from_utf8_lossy(&out.stderr)
        .chars()
        .rev()
        .take(300)
        .collect();
    assert!(
        out.status.success(),
        "bsdf2ttree failed: …{}",
        tail.chars().rev().collect::<String>()
    );
    let xml = dir.join(format!("m-t{rank}.xml"));
    std::fs::write(&xml, &out.stdout).unwrap();
    xml
}

/// `checkBSDF`'s component lines: label, Lambertian Y and "Max. Tot. Dir",
/// as fractions.
fn check_bsdf(bin: &Path, file: &Path) -> Vec<(String, f64, f64)> {
    let out = radiance_command(bin, "checkBSDF", file.parent().unwrap())
        .arg(file)
        .output()
        .expect("checkBSDF runs");
    assert!(out.status.success(), "checkBSDF failed: {out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Tensor_Tree"), "{text}");
    let mut lines = Vec::new();
    for line in text
        .lines()
        .filter(|l| l.contains("Refl\t") || l.contains("Trans\t"))
    {
        let fields: Vec<&str> = line.split('\t').filter(|f| !f.trim().is_empty()).collect();
        let Some(max) = fields.iter().find(|f| f.trim().ends_with('%')) else {
            continue; // the reciprocity table
        };
        let max: f64 = max.trim().trim_end_matches('%').trim().parse().unwrap();
        let y: f64 = fields[1]
            .split_whitespace()
            .nth(1)
            .unwrap()
            .parse()
            .unwrap();
        lines.push((fields[0].trim().to_string(), y / 100.0, max / 100.0));
    }
    lines
}

fn trans(args: [f64; 5]) -> Material {
    let [c, spec, rough, t, ts] = args;
    Material::new(MaterialKind::Trans, &[c, c, c, spec, rough, t, ts], None).unwrap()
}

/// `brtf info --json` gives, per block, the largest directional total and
/// the Lambertian part as Radiance computes them: equal to `checkBSDF`'s
/// (printed to 0.1 %) within 1e-3, for isotropic and anisotropic trees.
#[test]
fn info_totals_equal_check_bsdf_on_bsdf2ttree_trees() {
    let Some(bin) = radiance_tools_or_skip(
        "ttree_check_bsdf",
        &["bsdf2ttree", "rttree_reduce", "checkBSDF"],
    ) else {
        return;
    };
    let tmp = temp_dir();
    let material = trans([0.5, 0.04, 0.15, 0.3, 0.2]);
    for (rank, order) in [(3, 6), (4, 5)] {
        let xml = radiance_tree(&bin, tmp.path(), &material, rank, order);
        let json: serde_json::Value =
            serde_json::from_str(&brtf(&["info", s(&xml), "--json"], "").ok()).unwrap();
        let entry = &json[0];
        assert_eq!(
            entry["incident_data_structure"],
            format!("TensorTree{rank}")
        );
        let blocks = entry["blocks"].as_array().unwrap();
        let theirs = check_bsdf(&bin, &xml);
        for (label, direction) in [
            ("Interior Refl", "reflection_back"),
            ("Int->Ext Trans", "transmission_back"),
        ] {
            let (_, lambertian, max) = theirs.iter().find(|l| l.0 == label).unwrap();
            let block = blocks.iter().find(|b| b["direction"] == direction).unwrap();
            let (our_lambertian, our_max) = (
                block["lambertian"].as_f64().unwrap(),
                block["max_total"].as_f64().unwrap(),
            );
            eprintln!(
                "t{rank} -g {order} {label}: max total brtf {our_max:.5} checkBSDF {max:.3}; \
                 Lambertian brtf {our_lambertian:.5} checkBSDF {lambertian:.3}"
            );
            assert!((our_max - max).abs() <= 1e-3, "t{rank} {label}");
            assert!(
                (our_lambertian - lambertian).abs() <= 1e-3,
                "t{rank} {label}"
            );
        }
        // The per-incidence totals are the material's own at those θ_in.
        let rho: Vec<f64> = entry["incidences"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i["rho_dh"].as_f64().unwrap())
            .collect();
        assert_eq!(rho.len(), 9);
        assert!((rho[0] - 0.3751).abs() < 2e-3, "{rho:?}");
    }
}

/// A fit folder's θ_in table: (θ_in, arguments).
fn table(dir: &Path) -> Vec<(f64, Vec<f64>)> {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fit.json")).unwrap()).unwrap();
    let numbers = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    numbers(&json["table"]["theta_in"])
        .into_iter()
        .zip(
            json["table"]["args"]
                .as_array()
                .unwrap()
                .iter()
                .map(numbers),
        )
        .collect()
}

/// Diffuse reflectance, diffuse transmittance, specularity and roughness
/// of `trans` (C, C, C, S, α, T, Ts) or `plastic` (C, C, C, S, α)
/// arguments.
fn quantities(args: &[f64]) -> Vec<f64> {
    let (c, spec, rough) = (args[0], args[3], args[4]);
    if args.len() == 7 {
        let t = args[5] * (1.0 - spec);
        vec![c * (1.0 - t - spec), c * (t - t * args[6]), spec, rough]
    } else {
        vec![c * (1.0 - spec), spec, rough]
    }
}

/// Trees made by Radiance from known materials are fitted back with the
/// Klems round trip's tolerances: diffuse parts within 2 %, specularity
/// and roughness within 5 %, at every fitted θ_in (0°, 20°, 40°, 60°,
/// each moved to its input cell's centre).
#[test]
fn fits_recover_materials_from_bsdf2ttree_trees() {
    let Some(bin) = radiance_tools_or_skip("ttree_round_trip", &["bsdf2ttree", "rttree_reduce"])
    else {
        return;
    };
    let plastic = Material::new(MaterialKind::Plastic, &[0.6, 0.6, 0.6, 0.05, 0.1], None).unwrap();
    let cases = [
        ("trans", trans([0.7, 0.05, 0.10, 0.5, 0.4]), 3, 6),
        ("plastic", plastic, 3, 6),
        ("trans", trans([0.8, 0.08, 0.20, 0.3, 0.6]), 4, 5),
    ];
    let mut failures = Vec::new();
    for (model, material, rank, order) in cases {
        let tmp = temp_dir();
        let xml = radiance_tree(&bin, tmp.path(), &material, rank, order);
        let out = tmp.path().join("fit");
        let started = std::time::Instant::now();
        brtf(
            &[
                "fit",
                s(&xml),
                "--model",
                model,
                "--gray",
                "--out",
                s(&out),
                "--no-plots",
                "--no-export",
                "--no-adequacy",
                "--theta-in-grid",
                "0,20,40,60",
            ],
            "",
        )
        .ok();
        let seconds = started.elapsed().as_secs_f64();
        let truth = quantities(material.args());
        let rows = table(&out);
        assert_eq!(rows.len(), 4, "{rows:?}");
        for (theta, args) in rows {
            let got = quantities(&args);
            for (k, (g, t)) in got.iter().zip(&truth).enumerate() {
                let tolerance = if k + 2 < truth.len() { 0.02 } else { 0.05 };
                let error = (g / t - 1.0).abs();
                let line = format!(
                    "{model} t{rank} -g {order} θ_in {theta:.2}: quantity {k} fitted {g:.4}, truth {t:.4} ({:.1}% off)",
                    100.0 * error
                );
                eprintln!("{line}");
                if error > tolerance {
                    failures.push(line);
                }
            }
        }
        eprintln!("{model} t{rank} -g {order}: fit took {seconds:.1} s");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Without Radiance: the committed `bsdf2ttree` fixture is summarised and
/// fitted, and `--theta-in-grid` is refused where it means nothing.
#[test]
fn fixture_tree_is_summarised_and_fitted_and_the_grid_option_is_checked() {
    let tree = crate::common::repo_path("crates/gonio/tests/fixtures/ttree/asym-t3-g4.xml");
    let info = brtf(&["info", s(&tree)], "").ok();
    assert!(
        info.contains("format        TensorTree3 (isotropic tensor tree)"),
        "{info}"
    );
    assert!(
        info.contains("Reflection Back     Radiance rf, light from +z"),
        "{info}"
    );
    let tmp = temp_dir();
    let out = tmp.path().join("fit");
    let run = brtf(
        &[
            "fit",
            s(&tree),
            "--model",
            "plastic",
            "--gray",
            "--out",
            s(&out),
            "--no-plots",
            "--no-export",
            "--no-adequacy",
            "--theta-in-grid",
            "20,21,40",
        ],
        "",
    )
    .ok();
    // 20° and 21° share one input cell of the -g 4 tree: two incidences.
    assert_eq!(table(&out).len(), 2, "{run}");

    let mpc = crate::common::repo_path("crates/gonio/tests/fixtures/pab-aluA-st1:+30+0.mpc");
    let klems = crate::common::repo_path("../shared/data/lbnl-frads-klems-fabrics/2011-SA1.xml");
    for (file, expected) in [
        (
            &mpc,
            "--theta-in-grid sets the incidences of tensor-tree BSDF XML files",
        ),
        (
            &klems,
            "--theta-in-grid sets the incidences of tensor trees",
        ),
    ] {
        let out = tmp.path().join("refused");
        let run = brtf(
            &[
                "fit",
                s(file),
                "--model",
                "plastic",
                "--out",
                s(&out),
                "--theta-in-grid",
                "10",
            ],
            "",
        );
        assert!(!run.success && run.stderr.contains(expected), "{run}");
    }
    let run = brtf(
        &[
            "fit",
            s(&tree),
            "--model",
            "plastic",
            "--theta-in-grid",
            "10,95",
        ],
        "",
    );
    assert!(!run.success && run.stderr.contains("`95`"), "{run}");
}

/// A two-sided tree (the fixture's blocks copied to the `Front`
/// directions, light from −z) fits each side into its own folder, with
/// the same result on both, and the side-by-side report.
#[test]
fn a_two_sided_tree_fits_both_sides() {
    let fixture = crate::common::repo_path("crates/gonio/tests/fixtures/ttree/asym-t3-g4.xml");
    let text = std::fs::read_to_string(fixture).unwrap();
    let start = text.find("<WavelengthData>").unwrap();
    let end = text.rfind("</WavelengthData>").unwrap() + "</WavelengthData>".len();
    let back = text[start..end]
        .replace("Reflection Back", "Reflection Front")
        .replace("Transmission Back", "Transmission Front");
    let tmp = temp_dir();
    let both = tmp.path().join("both.xml");
    std::fs::write(&both, format!("{}\n{back}{}", &text[..end], &text[end..])).unwrap();
    let out = tmp.path().join("fit");
    brtf(
        &[
            "fit",
            s(&both),
            "--model",
            "plastic",
            "--gray",
            "--out",
            s(&out),
            "--no-plots",
            "--no-export",
            "--no-adequacy",
            "--theta-in-grid",
            "20,50",
        ],
        "",
    )
    .ok();
    let front = table(&out.join("front"));
    let back = table(&out.join("back"));
    assert_eq!(front.len(), 2);
    assert_eq!(front, back);
    assert!(out.join("report.html").is_file());
}
