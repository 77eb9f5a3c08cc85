//! The CI version of the fuzz run (`scripts/fuzz.sh` is the long one):
//! 20 000 mutated inputs through the measurement and `.rad` parsers, and
//! 20 000 each through the `fit.json`, Klems and tensor-tree readers; no
//! panic, no hang.
//!
//! Whole big files are left to `scripts/fuzz.sh`: a 127 000-row read and
//! summary on a busy 2-core CI machine could pass 1 s without any bug; the
//! excerpts cover their rows.

use std::time::Duration;

use brtf_fuzz::{Config, SeedSources, Seeds, Target, format_report, make_case, run};

fn seeds() -> Seeds {
    Seeds::load(&SeedSources::beside_this_checkout()).unwrap_or_else(|e| panic!("{e}"))
}

fn config(targets: &[Target]) -> Config {
    Config {
        cases: 20_000,
        seed: 14,
        threads: 2,
        hang_limit: Duration::from_secs(1),
        whole_file_every: 0,
        targets: targets.to_vec(),
        ..Config::default()
    }
}

#[test]
fn measurement_and_rad_parsers_survive_20000_mutated_inputs() {
    let targets = [
        Target::Mpc,
        Target::Mountain,
        Target::DetectedGonio,
        Target::Rad,
    ];
    let config = config(&targets);
    let report = run(&seeds(), &config);
    let text = format_report(&report, &config);
    println!("{text}");
    assert_eq!(report.cases, 20_000);
    assert!(report.panics.is_empty(), "{text}");
    assert!(report.hangs.is_empty(), "{text}");
    for target in targets {
        let stats = &report.per_target[&target];
        assert!(stats.accepted > 0 && stats.rejected > 0, "{text}");
    }
    // The measurement readers' promise: every error is `file:line` with a
    // line inside the file, and what they accept writes and reads back.
    assert!(
        !report.anomalies.iter().any(|f| matches!(
            f.target,
            Target::Mpc | Target::Mountain | Target::DetectedGonio
        )),
        "{text}"
    );
}

/// The Klems XML reader: no panic, no hang, every error inside the file,
/// and what it accepts brtf's writer writes and it reads back.
#[test]
fn klems_reader_survives_20000_mutated_inputs() {
    let config = config(&[Target::Klems]);
    let report = run(&seeds(), &config);
    let text = format_report(&report, &config);
    println!("{text}");
    assert_eq!(report.cases, 20_000);
    assert!(report.panics.is_empty(), "{text}");
    assert!(report.hangs.is_empty(), "{text}");
    assert!(report.anomalies.is_empty(), "{text}");
    let stats = &report.per_target[&Target::Klems];
    assert!(stats.accepted > 0 && stats.rejected > 0, "{text}");
}

/// The tensor-tree reader: no panic, no hang, every error inside the
/// file, and the leaves of what it accepts give finite totals and
/// directions.
#[test]
fn tensor_tree_reader_survives_20000_mutated_inputs() {
    let config = config(&[Target::TensorTree]);
    let report = run(&seeds(), &config);
    let text = format_report(&report, &config);
    println!("{text}");
    assert_eq!(report.cases, 20_000);
    assert!(report.panics.is_empty(), "{text}");
    assert!(report.hangs.is_empty(), "{text}");
    assert!(report.anomalies.is_empty(), "{text}");
    let stats = &report.per_target[&Target::TensorTree];
    assert!(stats.accepted > 0 && stats.rejected > 0, "{text}");
}

#[test]
fn fit_json_reader_survives_20000_mutated_inputs() {
    let config = config(&[Target::FitJson]);
    let report = run(&seeds(), &config);
    let text = format_report(&report, &config);
    println!("{text}");
    assert!(report.panics.is_empty(), "{text}");
    assert!(report.hangs.is_empty(), "{text}");
}

#[test]
fn a_case_depends_only_on_seed_and_number() {
    let seeds = seeds();
    let config = config(&[]);
    for index in [0, 1, 777, 19_999] {
        let a = make_case(&seeds, &config, index);
        let b = make_case(&seeds, &config, index);
        assert_eq!(a.bytes, b.bytes);
        assert_eq!(a.target, b.target);
    }
}
