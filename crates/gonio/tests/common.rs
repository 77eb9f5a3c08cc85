//! Shared helpers: locating the real data and the fixtures.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use brtf_gonio::{Measurement, Sample};

/// The real pgII scan `name` from `../shared/data/rgl-epfl-pgII-raw/`.
/// Panics with a clear message when it is missing: CI always has it.
pub(crate) fn pgii_path(name: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/rgl-epfl-pgII-raw")
        .join(name);
    assert!(
        path.is_file(),
        "real measurement {} is missing: the tests need the shared data folder \
         (`shared/data/rgl-epfl-pgII-raw/`) beside the repository checkout",
        path.display()
    );
    path
}

/// A file in `tests/fixtures/`.
pub(crate) fn fixture_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// The seed's `.mpc` excerpt.
pub(crate) const MPC_FIXTURE: &str = "pab-aluA-st1:+30+0.mpc";

pub(crate) fn mpc_fixture_text() -> String {
    std::fs::read_to_string(fixture_path(MPC_FIXTURE)).expect("the .mpc fixture is committed")
}

/// golden_paper.txt, parsed once per test binary.
pub(crate) fn golden() -> &'static Measurement {
    static CELL: OnceLock<Measurement> = OnceLock::new();
    CELL.get_or_init(|| brtf_gonio::read_path(&pgii_path("golden_paper.txt")).unwrap())
}

/// layer_020_030.txt, parsed once per test binary.
pub(crate) fn layer() -> &'static Measurement {
    static CELL: OnceLock<Measurement> = OnceLock::new();
    CELL.get_or_init(|| brtf_gonio::read_path(&pgii_path("layer_020_030.txt")).unwrap())
}

/// Angle in degrees between two (θ, φ) directions.
pub(crate) fn angle_between_deg(a: (f64, f64), b: (f64, f64)) -> f64 {
    let da = brtf_gonio::direction_from_degrees(a.0, a.1);
    let db = brtf_gonio::direction_from_degrees(b.0, b.1);
    da.dot(db).clamp(-1.0, 1.0).acos().to_degrees()
}

/// Samples equal bit for bit (NaN equals NaN).
pub(crate) fn assert_samples_identical(a: &[Sample], b: &[Sample]) {
    assert_eq!(a.len(), b.len(), "sample counts differ");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let bits = |s: &Sample| {
            (
                s.theta_deg.to_bits(),
                s.phi_deg.to_bits(),
                s.values
                    .map(|v| if v.is_nan() { u64::MAX } else { v.to_bits() }),
                s.solid_angle_sr.map(f64::to_bits),
            )
        };
        assert_eq!(bits(x), bits(y), "sample {i} differs: {x:?} vs {y:?}");
    }
}

/// A regular (θ, φ) grid over the front hemisphere (and the back one when
/// `both`), with a constant value.
pub(crate) fn grid(theta_step: f64, phi_step: f64, both: bool, value: f64) -> Vec<Sample> {
    let mut samples = vec![Sample::luminance(0.0, 0.0, value)];
    let mut theta = theta_step;
    while theta <= 90.0 + 1e-9 {
        let mut phi = 0.0;
        while phi < 360.0 - 1e-9 {
            samples.push(Sample::luminance(theta, phi, value));
            if both && theta < 90.0 - 1e-9 {
                samples.push(Sample::luminance(180.0 - theta, phi, value));
            }
            phi += phi_step;
        }
        theta += theta_step;
    }
    if both {
        samples.push(Sample::luminance(180.0, 0.0, value));
    }
    samples
}
