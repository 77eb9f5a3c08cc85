//! The `brtf albedo` contract: columns, exact Lambertian values, delta
//! spikes, and the rtrace reference integrals of the oracle.

use crate::common::{Csv, brtf, parse_csv, repo_path, s, temp_dir, write_file};
use std::collections::BTreeMap;
use std::path::Path;

const HEADER: &str = "theta_in,phi_in,rho_r,rho_g,rho_b,tau_r,tau_g,tau_b,rho_spike,tau_spike";
/// Solid angle of the 0.01° source the oracle tables were made with.
const ORACLE_OMEGA: &str = "2.3924596e-08";

#[track_caller]
fn albedo(file: &Path, theta_in: &str, extra: &[&str]) -> Csv {
    let mut args = vec!["albedo", "--material", s(file), "--theta-in", theta_in];
    args.extend_from_slice(extra);
    let out = brtf(&args, "").ok();
    assert_eq!(out.lines().next(), Some(HEADER), "{out}");
    parse_csv(&out)
}

#[test]
fn header_rows_and_echo() {
    let dir = temp_dir();
    let file = write_file(dir.path(), "m.rad", "void metal m 0 0 5 .8 .8 .8 .7 .15\n");
    let csv = albedo(&file, "0,30,60", &[]);
    assert_eq!(csv.rows.len(), 3);
    assert_eq!(csv.column("theta_in"), [0.0, 30.0, 60.0]);
    assert_eq!(csv.column("phi_in"), [0.0; 3], "φ_in defaults to 0");
    let csv = albedo(&file, "15", &["--phi-in", "45"]);
    assert_eq!((csv.rows[0][0], csv.rows[0][1]), (15.0, 45.0));
    // Opaque: no transmission, no spikes; rough metal reflects < 1.
    let row = &csv.rows[0];
    assert!(row[2..5].iter().all(|&x| x > 0.3 && x < 1.0), "{row:?}");
    assert_eq!(&row[5..], &[0.0; 5]);
}

#[test]
fn lambertian_plastic_albedo_is_its_colour() {
    let dir = temp_dir();
    let file = write_file(
        dir.path(),
        "lambert.rad",
        "void plastic lambert\n0\n0\n5 0.2 0.5 0.8 0 0\n",
    );
    let csv = albedo(&file, "0,15,30,45,60,75,85", &[]);
    assert_eq!(csv.rows.len(), 7);
    for row in &csv.rows {
        let expected = [0.2, 0.5, 0.8, 0.0, 0.0, 0.0, 0.0, 0.0];
        for (x, e) in row[2..].iter().zip(expected) {
            assert!((x - e).abs() <= 1e-6, "θ_in {}: {row:?}", row[0]);
        }
    }
}

#[test]
fn roughness_zero_reports_spikes() {
    let dir = temp_dir();
    let text = "void trans smooth 0 0 7 0.8 0.8 0.8 0.05 0 0.5 0.5\n\
                void trans rough 0 0 7 0.8 0.8 0.8 0.05 0.1 0.5 0.5\n\
                void plastic glossy 0 0 5 0.5 0.5 0.5 0.05 0\n";
    let file = write_file(dir.path(), "m.rad", text);
    let fk = ["--fresnel-k", "pyradiance"];
    let smooth = albedo(&file, "0,45,80", &[&["--name", "smooth"], &fk[..]].concat());
    let (rs, ts) = (smooth.col("rho_spike"), smooth.col("tau_spike"));
    for row in &smooth.rows {
        assert!(row[rs] >= 0.05 && row[rs] < 1.0, "rho_spike: {row:?}");
        assert!(row[ts] > 0.05 && row[ts] < 0.5, "tau_spike: {row:?}");
        let total: f64 = [row[2], row[5], row[rs], row[ts]].iter().sum();
        assert!(total <= 1.0 + 1e-3, "energy {total}: {row:?}");
    }
    // Fresnel: the mirror spike grows towards grazing.
    assert!(smooth.rows[2][rs] > smooth.rows[0][rs], "{:?}", smooth.rows);

    let rough = albedo(&file, "0,45", &["--name", "rough"]);
    for row in &rough.rows {
        assert_eq!(
            (row[rough.col("rho_spike")], row[rough.col("tau_spike")]),
            (0.0, 0.0)
        );
        assert!(row[2] > 0.05 && row[5] > 0.1, "{row:?}");
    }
    let glossy = albedo(&file, "30", &["--name", "glossy"]);
    let row = &glossy.rows[0];
    assert!(row[glossy.col("rho_spike")] >= 0.05, "{row:?}");
    assert_eq!(row[glossy.col("tau_spike")], 0.0, "{row:?}");
}

#[test]
fn bad_arguments_fail() {
    let dir = temp_dir();
    let file = write_file(dir.path(), "m.rad", "void plastic p 0 0 5 .5 .5 .5 0 0\n");
    let err = brtf(
        &["albedo", "--material", s(&file), "--theta-in", "0,200"],
        "",
    )
    .err();
    assert!(err.contains("200"), "{err}");
    let bad = write_file(dir.path(), "bad.rad", "\nvoid plastic p 0 0 4 .5 .5 .5 0\n");
    let err = brtf(&["albedo", "--material", s(&bad), "--theta-in", "0"], "").err();
    assert!(err.contains(&format!("{}:2:", s(&bad))), "{err}");
}

/// One row of the oracle's `rho_dh.csv`.
struct RefRow {
    theta_in: f64,
    values: [f64; 6],
}

/// `brtf albedo` against rtrace's own BRDF integrated numerically
/// (crates/model/tests/data/oracle/rho_dh.csv), all rows, within 2e-4.
#[test]
fn albedo_matches_rtrace_reference_integrals() {
    let path = repo_path("crates/model/tests/data/oracle/rho_dh.csv");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (c_type, c_args, c_orient) = (col("type"), col("args"), col("orient"));
    let (c_theta, c_phi) = (col("theta_in"), col("phi_in"));
    let value_cols = ["rho_r", "rho_g", "rho_b", "tau_r", "tau_g", "tau_b"].map(col);

    // Group by material and φ_in: one brtf run per group.
    let mut groups: BTreeMap<(String, String, String, String), Vec<RefRow>> = BTreeMap::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split(',').collect();
        let num = |i: usize| f[i].parse::<f64>().unwrap_or_else(|_| panic!("{line}"));
        let key = (
            f[c_type].into(),
            f[c_args].into(),
            f[c_orient].into(),
            f[c_phi].into(),
        );
        groups.entry(key).or_default().push(RefRow {
            theta_in: num(c_theta),
            values: value_cols.map(num),
        });
    }
    assert!(groups.len() >= 36, "{} groups", groups.len());

    let dir = temp_dir();
    let (mut compared, mut worst) = (0usize, (0.0f64, String::new()));
    for (i, ((kind, args, orient, phi), rows)) in groups.iter().enumerate() {
        let strings = if orient.is_empty() {
            "0".to_string()
        } else {
            format!("4 {orient} .")
        };
        let n = args.split_whitespace().count();
        let text = format!("void {kind} ref{i}\n{strings}\n0\n{n} {args}\n");
        let file = write_file(dir.path(), &format!("ref{i}.rad"), &text);
        let thetas: Vec<String> = rows.iter().map(|r| r.theta_in.to_string()).collect();
        let extra = [
            "--phi-in",
            phi,
            "--fresnel-k",
            "pyradiance",
            "--source-omega",
            ORACLE_OMEGA,
        ];
        let csv = albedo(&file, &thetas.join(","), &extra);
        assert_eq!(csv.rows.len(), rows.len());
        for (row, reference) in csv.rows.iter().zip(rows) {
            assert_eq!(row[0], reference.theta_in);
            for (c, (&x, &r)) in row[2..8].iter().zip(&reference.values).enumerate() {
                let d = (x - r).abs();
                let at = format!(
                    "{kind} `{args}` orient `{orient}` θ_in {} φ_in {phi} column {c}",
                    row[0]
                );
                assert!(d <= 2e-4, "{at}: brtf {x} vs rtrace integral {r}");
                if d > worst.0 {
                    worst = (d, at);
                }
                compared += 1;
            }
        }
    }
    println!(
        "albedo vs rho_dh.csv: {compared} values in {} runs; worst absolute difference {:.1e} at {}",
        groups.len(),
        worst.0,
        worst.1
    );
}
