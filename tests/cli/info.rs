//! `brtf info` on Klems BSDF XML: the two real fabrics of
//! `../shared/data/lbnl-frads-klems-fabrics/` (the test fails when the
//! shared data folder is missing), text and `--json`, and a clear error.

use crate::common::{self, brtf};

fn fabric(name: &str) -> String {
    let path = common::repo_path("../shared/data/lbnl-frads-klems-fabrics").join(name);
    assert!(
        path.is_file(),
        "{} is missing: the test needs the shared data folder beside the repository",
        path.display()
    );
    path.display().to_string()
}

#[test]
fn info_prints_klems_header_basis_and_totals_per_incidence() {
    let sa1 = fabric("2011-SA1.xml");
    let run = brtf(&["info", &sa1], "");
    assert!(run.success, "{run}");
    let out = &run.stdout;
    assert!(out.contains("manufacturer  Nysan"), "{run}");
    assert!(out.contains("thickness     1 Millimeter"), "{run}");
    assert!(out.contains("basis         LBNL/Klems Full (145 patches, Columns)"));
    assert!(out.contains("bands         Visible, Solar"));
    // Normal incidence from each side: ρ_dh and τ_dh (checkBSDF agrees).
    assert!(
        out.contains("  front      0      0.00  180.00   0.5600   0.0943"),
        "{run}"
    );
    assert!(
        out.contains("  back       0    180.00  180.00   0.4825   0.0959"),
        "{run}"
    );
    assert_eq!(
        out.lines().filter(|l| l.starts_with("  front ")).count(),
        145
    );
    assert_eq!(
        out.lines().filter(|l| l.starts_with("  back ")).count(),
        145
    );
}

#[test]
fn info_json_on_klems_and_errors_name_the_file() {
    let mecho = fabric("klems_aniso_high.xml");
    let run = brtf(&["info", "--json", &mecho], "");
    assert!(run.success, "{run}");
    let value: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    let entry = &value[0];
    assert_eq!(entry["name"], "Mecho_shade_fabric_6216-63__(LBL)");
    assert_eq!(entry["incidences"].as_array().unwrap().len(), 290);
    // Normal incidence from the front: the spec's known dip in τ (0.0107,
    // against 0.0172 on the 10° ring).
    let first = &entry["incidences"][0];
    assert_eq!(first["side"], "front");
    assert!(
        (first["rho_dh"].as_f64().unwrap() - 0.2178).abs() < 1e-4,
        "{first}"
    );
    assert!(
        (first["tau_dh"].as_f64().unwrap() - 0.0107).abs() < 1e-4,
        "{first}"
    );

    let dir = common::temp_dir();
    let bad = common::write_file(
        dir.path(),
        "tree.xml",
        "<WindowElement><Optical><Layer><DataDefinition>\n\
         <IncidentDataStructure>TensorTree4</IncidentDataStructure>\n\
         </DataDefinition></Layer></Optical></WindowElement>\n",
    );
    let run = brtf(&["info", common::s(&bad)], "");
    assert!(!run.success, "{run}");
    assert!(run.stderr.contains("tree.xml:1:"), "{run}");
    assert!(run.stderr.contains("no WavelengthData block"), "{run}");
}
