//! The data of the end-to-end speed comparison (`scripts/bench-fit.sh`):
//! golden_paper as brtf's default grey `metal` fit sees it, written as the
//! scipy peer's CSV (`theta_in,phi_in,vx,vy,vz,value,weight`, the format
//! of `target/fit-bench-metal.csv`). The script sets `BRTF_PEER_CSV` to
//! keep the file; otherwise it goes to a temporary folder.

use crate::common::{repo_path, temp_dir};
use brtf_fit::Recipe;
use brtf_model::MaterialKind;
use std::fmt::Write as _;

#[test]
fn peer_data_is_the_data_brtf_fits() {
    let path = repo_path("../shared/data/rgl-epfl-pgII-raw/golden_paper.txt");
    let measurement = brtf_gonio::read_path(&path).unwrap();
    let rows = measurement.samples.len();
    let data = Recipe::for_kind(MaterialKind::Metal)
        .prepare(measurement, "golden_paper.txt")
        .unwrap()
        .incidence_data();
    let mut text = String::from("theta_in,phi_in,vx,vy,vz,value,weight\n");
    for s in &data.samples {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{}",
            data.theta_in, data.phi_in, s.view.x, s.view.y, s.view.z, s.value[0], s.weight
        );
    }
    let dir = temp_dir();
    let csv = std::env::var_os("BRTF_PEER_CSV")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| dir.path().join("golden-peer.csv"));
    std::fs::write(&csv, &text).unwrap();
    // The gates (θ cap, holder band, unavailable values) keep most of the
    // 127 039 rows, and the weights are solid angles within the hemisphere.
    let kept = data.samples.len();
    assert!(kept > rows / 2 && kept < rows, "{kept} of {rows}");
    let total: f64 = data.samples.iter().map(|s| s.weight).sum();
    assert!(total > 1.0 && total < std::f64::consts::TAU, "{total}");
    let written = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(written.lines().count(), kept + 1);
}
