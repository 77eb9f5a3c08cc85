//! The θ_in table: PCHIP and linear interpolation (knots, linear data,
//! monotone data, a hand-computed PCHIP value), the held end values
//! outside the range, and the errors of `validate`, `at` and the
//! constructors.

use super::report;
use crate::table::{AzimuthRing, Interpolation, ParamTable, TableError};
use brtf_model::{MaterialKind, ModelError};

/// A plastic table with these rows (θ_in, [red, green, blue, spec, rough]).
fn plastic(method: Interpolation, rows: &[(f64, [f64; 5])]) -> ParamTable {
    ParamTable {
        kind: MaterialKind::Plastic,
        lobes: 1,
        oriented: false,
        orientation: [1.0, 0.0, 0.0],
        method,
        theta_in: rows.iter().map(|r| r.0).collect(),
        args: rows.iter().map(|r| r.1.to_vec()).collect(),
        azimuth: None,
    }
}

/// Rows whose spec is `spec(θ)` and whose other arguments are fixed.
fn rows_with_spec(thetas: &[f64], spec: impl Fn(f64) -> f64) -> Vec<(f64, [f64; 5])> {
    thetas
        .iter()
        .map(|&t| (t, [0.4, 0.5, 0.6, spec(t), 0.1]))
        .collect()
}

const METHODS: [Interpolation; 2] = [Interpolation::Pchip, Interpolation::Linear];

#[test]
fn both_methods_reproduce_the_rows_at_their_knots() {
    let rows = [
        (0.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
        (15.0, [0.2, 0.1, 0.3, 0.02, 0.30]),
        (40.0, [0.7, 0.2, 0.1, 0.09, 0.12]),
        (45.0, [0.3, 0.3, 0.3, 0.01, 0.05]),
        (75.0, [0.9, 0.8, 0.7, 0.04, 0.20]),
    ];
    for method in METHODS {
        let table = plastic(method, &rows);
        table.validate().unwrap();
        for (theta, args) in &rows {
            let (got, clamped) = table.args_at(*theta);
            assert!(!clamped, "{method:?} at the knot {theta}");
            for (g, w) in got.iter().zip(args) {
                assert!((g - w).abs() < 1e-12, "{method:?} at {theta}: {got:?}");
            }
        }
    }
}

#[test]
fn both_methods_are_exact_on_linear_data_with_uneven_spacing() {
    let line = |t: f64| 0.02 + 0.004 * t;
    let rows = rows_with_spec(&[0.0, 10.0, 35.0, 40.0, 70.0], line);
    for method in METHODS {
        let table = plastic(method, &rows);
        for k in 0..=140 {
            let theta = 0.5 * k as f64;
            let (args, _) = table.args_at(theta);
            assert!(
                (args[3] - line(theta)).abs() < 1e-12,
                "{method:?} at {theta}: {} vs {}",
                args[3],
                line(theta)
            );
            // Constant arguments stay constant.
            assert!((args[4] - 0.1).abs() < 1e-15);
        }
    }
}

#[test]
fn linear_interpolation_is_the_chord_between_neighbouring_rows() {
    let rows = rows_with_spec(&[10.0, 30.0, 60.0], |t| {
        if t < 20.0 { 0.1 } else { 0.5 - t / 300.0 }
    });
    // spec: 0.1 at 10°, 0.4 at 30°, 0.3 at 60°.
    let table = plastic(Interpolation::Linear, &rows);
    for (theta, want) in [
        (15.0, 0.175),
        (20.0, 0.4 * 0.5 + 0.1 * 0.5),
        (45.0, 0.35),
        (50.0, 0.4 - 0.1 * 2.0 / 3.0),
    ] {
        let (args, _) = table.args_at(theta);
        assert!(
            (args[3] - want).abs() < 1e-12,
            "at {theta}: {} vs {want}",
            args[3]
        );
    }
}

#[test]
fn pchip_matches_a_hand_computed_fritsch_carlson_value() {
    // Knots x = 10, 20, 30 with y = 0.1 + 0.1 Y, Y = 0, 1, 3 (secants
    // δ = 1, 2 per knot step). Interior slope: harmonic mean with weights
    // w1 = w2 = 3: 6 / (3/1 + 3/2) = 4/3. End slopes, three-point:
    // ((2+1)·1 − 2)/2 = 1/2 and ((2+1)·2 − 1)/2 = 5/2 (same sign as
    // their secants, no clamping). At the middle of the first interval
    // (t = ½) the Hermite basis is (½, ⅛, ½, −⅛):
    // Y = ⅛·½ + ½·1 − ⅛·4/3 = 19/48.
    let rows = rows_with_spec(&[10.0, 20.0, 30.0], |t| match t as i32 {
        10 => 0.1,
        20 => 0.2,
        _ => 0.4,
    });
    let table = plastic(Interpolation::Pchip, &rows);
    let (args, _) = table.args_at(15.0);
    let want = 0.1 + 0.1 * 19.0 / 48.0;
    assert!((args[3] - want).abs() < 1e-12, "{} vs {want}", args[3]);
    // Second interval, t = ½: ½·1 + ⅛·4/3 + ½·3 − ⅛·5/2 = 2 − 7/48.
    let (args, _) = table.args_at(25.0);
    let want = 0.1 + 0.1 * (2.0 - 7.0 / 48.0);
    assert!((args[3] - want).abs() < 1e-12, "{} vs {want}", args[3]);
}

#[test]
fn pchip_with_two_rows_is_the_straight_line() {
    let rows = rows_with_spec(&[20.0, 60.0], |t| if t < 30.0 { 0.02 } else { 0.1 });
    let pchip = plastic(Interpolation::Pchip, &rows);
    for k in 0..=40 {
        let theta = 20.0 + k as f64;
        let want = 0.02 + 0.08 * (theta - 20.0) / 40.0;
        assert!(
            (pchip.args_at(theta).0[3] - want).abs() < 1e-12,
            "at {theta}"
        );
    }
}

/// The values of argument 3 on a fine sweep of the table's range.
fn sweep(table: &ParamTable) -> Vec<(f64, f64)> {
    let (lo, hi) = table.range();
    (0..=1000)
        .map(|k| {
            let theta = lo + (hi - lo) * k as f64 / 1000.0;
            (theta, table.args_at(theta).0[3])
        })
        .collect()
}

#[test]
fn pchip_keeps_monotone_data_monotone_without_overshoot() {
    // A flat run, a steep step, and a flat run again: a natural cubic
    // spline overshoots both corners; PCHIP must not.
    let ys = [0.02, 0.02, 0.021, 0.6, 0.61, 0.61];
    let thetas = [0.0, 10.0, 20.0, 25.0, 50.0, 70.0];
    let rows: Vec<(f64, [f64; 5])> = thetas
        .iter()
        .zip(ys)
        .map(|(&t, y)| (t, [0.4, 0.5, 0.6, y, 0.1]))
        .collect();
    let table = plastic(Interpolation::Pchip, &rows);
    let values = sweep(&table);
    for w in values.windows(2) {
        assert!(w[1].1 >= w[0].1 - 1e-15, "decreases at {}°: {w:?}", w[1].0);
    }
    // Within each interval the curve stays between its two knots.
    for (theta, v) in &values {
        let i = thetas.windows(2).position(|w| *theta <= w[1]).unwrap();
        let (lo, hi) = (ys[i].min(ys[i + 1]), ys[i].max(ys[i + 1]));
        assert!(
            (lo - 1e-15..=hi + 1e-15).contains(v),
            "overshoot at {theta}°: {v} outside [{lo}, {hi}]"
        );
    }
    // And decreasing data the same way.
    let falling: Vec<(f64, [f64; 5])> = rows
        .iter()
        .map(|(t, a)| (*t, [a[0], a[1], a[2], 0.7 - a[3], a[4]]))
        .collect();
    let values = sweep(&plastic(Interpolation::Pchip, &falling));
    for w in values.windows(2) {
        assert!(w[1].1 <= w[0].1 + 1e-15, "increases at {}°", w[1].0);
    }
}

#[test]
fn pchip_does_not_overshoot_a_local_maximum() {
    // A peak at 30°: the slope there is zero and nothing exceeds it.
    let rows = rows_with_spec(&[0.0, 20.0, 30.0, 50.0, 60.0], |t| match t as i32 {
        30 => 0.5,
        20 | 50 => 0.3,
        _ => 0.1,
    });
    let values = sweep(&plastic(Interpolation::Pchip, &rows));
    let max = values.iter().map(|v| v.1).fold(f64::MIN, f64::max);
    assert!((max - 0.5).abs() < 1e-15, "max {max}");
    assert!(values.iter().all(|v| v.1 >= 0.1 - 1e-15));
}

#[test]
fn outside_the_range_the_end_rows_hold_and_the_lookup_says_clamped() {
    let rows = [
        (15.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
        (45.0, [0.2, 0.3, 0.4, 0.06, 0.10]),
        (60.0, [0.3, 0.4, 0.5, 0.09, 0.14]),
    ];
    for method in METHODS {
        let table = plastic(method, &rows);
        assert_eq!(table.range(), (15.0, 60.0));
        for (theta, row) in [(0.0, 0), (14.999, 0), (60.001, 2), (89.0, 2)] {
            let (args, clamped) = table.args_at(theta);
            assert!(clamped, "{method:?} at {theta}");
            let lookup = table.at(theta).unwrap();
            assert!(lookup.clamped);
            for (got, want) in [args.as_slice(), lookup.material.args()]
                .into_iter()
                .flat_map(|a| a.iter().zip(&rows[row].1))
            {
                assert!(
                    (got - want).abs() < 1e-15,
                    "{method:?} at {theta}: {args:?}"
                );
            }
        }
        // The ends themselves are inside.
        assert!(!table.at(15.0).unwrap().clamped);
        assert!(!table.at(60.0).unwrap().clamped);
        assert!(!table.at(30.0).unwrap().clamped);
    }
}

#[test]
fn validate_names_each_kind_of_broken_table() {
    let good = [
        (10.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
        (40.0, [0.2, 0.3, 0.4, 0.06, 0.10]),
    ];
    let table = plastic(Interpolation::Pchip, &good);
    assert_eq!(table.validate(), Ok(()));

    let mut one = table.clone();
    one.theta_in.truncate(1);
    one.args.truncate(1);
    assert_eq!(one.validate(), Err(TableError::NeedTwoIncidences(1)));

    let mut rows_missing = table.clone();
    rows_missing.args.pop();
    assert!(matches!(rows_missing.validate(), Err(TableError::Invalid(m)) if m.contains("1 rows")));

    for bad in [-1.0, 181.0, f64::NAN] {
        let mut t = table.clone();
        t.theta_in[0] = bad;
        assert!(
            matches!(t.validate(), Err(TableError::Invalid(m)) if m.contains("not an incidence")),
            "θ_in {bad}"
        );
    }
    for second in [10.0, 5.0] {
        let mut t = table.clone();
        t.theta_in[1] = second;
        assert!(
            matches!(t.validate(), Err(TableError::Invalid(m)) if m.contains("not ascending")),
            "{second}"
        );
    }

    let mut short_row = table.clone();
    short_row.args[1].pop();
    assert!(
        matches!(short_row.validate(), Err(TableError::Invalid(m)) if m.contains("4 arguments"))
    );

    let mut nan = table.clone();
    nan.args[0][4] = f64::NAN;
    assert_eq!(
        nan.validate(),
        Err(TableError::Material(ModelError::NonFinite { index: 4 }))
    );
}

#[test]
fn validate_checks_the_azimuth_rings() {
    let row = vec![0.1, 0.2, 0.3, 0.05, 0.08];
    let ring = |phis: &[f64]| AzimuthRing {
        phi_in: phis.to_vec(),
        args: phis.iter().map(|_| row.clone()).collect(),
    };
    let mut table = plastic(
        Interpolation::Linear,
        &[
            (10.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
            (40.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
        ],
    );
    table.azimuth = Some(vec![ring(&[0.0, 90.0]), ring(&[45.0])]);
    assert_eq!(table.validate(), Ok(()));
    for (rings, why) in [
        (vec![ring(&[0.0])], "azimuth rings"),
        (vec![ring(&[0.0]), ring(&[])], "0 azimuths"),
        (vec![ring(&[0.0]), ring(&[90.0, 90.0])], "not ascending"),
        (vec![ring(&[0.0]), ring(&[360.0])], "not ascending"),
        (vec![ring(&[-1.0]), ring(&[0.0])], "not ascending"),
    ] {
        table.azimuth = Some(rings);
        assert!(
            matches!(table.validate(), Err(TableError::Invalid(ref m)) if m.contains(why)),
            "{why}: {:?}",
            table.validate()
        );
    }
}

#[test]
fn a_lookup_that_is_no_valid_material_is_an_error() {
    // plastic2 with a zero u-roughness at both rows: rtrace refuses it, so
    // the interpolated material is no material.
    let table = ParamTable {
        kind: MaterialKind::Plastic2,
        lobes: 1,
        oriented: false,
        orientation: [1.0, 0.0, 0.0],
        method: Interpolation::Pchip,
        theta_in: vec![0.0, 60.0],
        args: vec![
            vec![0.5, 0.5, 0.5, 0.05, 0.0, 0.1],
            vec![0.5, 0.5, 0.5, 0.05, 0.0, 0.2],
        ],
        azimuth: None,
    };
    assert_eq!(
        table.at(30.0).unwrap_err(),
        TableError::Material(ModelError::RoughnessTooSmall)
    );
    assert!(table.validate().is_err());
    // A zero orientation is no material either.
    let mut turned = plastic(
        Interpolation::Linear,
        &[
            (0.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
            (60.0, [0.1, 0.2, 0.3, 0.05, 0.08]),
        ],
    );
    turned.orientation = [0.0; 3];
    assert_eq!(
        turned.at(30.0).unwrap_err(),
        TableError::Material(ModelError::BadOrientation)
    );
}

#[test]
fn tables_from_reports_sort_rows_and_refuse_one_or_duplicate_incidences() {
    let kind = MaterialKind::Plastic;
    let at = |theta: f64, spec: f64| report(kind, theta, &[0.5, 0.5, 0.5, spec, 0.1], 1.0);
    let reports = [at(60.0, 0.09), at(0.0, 0.03), at(30.0, 0.05)];
    let table = ParamTable::from_reports(
        brtf_model::Shape::single(kind),
        [1.0, 0.0, 0.0],
        &reports,
        Interpolation::Linear,
    )
    .unwrap();
    assert_eq!(table.theta_in, vec![0.0, 30.0, 60.0]);
    assert_eq!(
        table.args.iter().map(|a| a[3]).collect::<Vec<_>>(),
        vec![0.03, 0.05, 0.09]
    );
    assert!((table.args_at(45.0).0[3] - 0.07).abs() < 1e-12);
    assert_eq!(
        ParamTable::from_reports(
            brtf_model::Shape::single(kind),
            [1.0, 0.0, 0.0],
            &reports[..1],
            Interpolation::Pchip
        )
        .unwrap_err(),
        TableError::NeedTwoIncidences(1)
    );
    let twice = [at(30.0, 0.05), at(30.0, 0.06)];
    assert_eq!(
        ParamTable::from_reports(
            brtf_model::Shape::single(kind),
            [1.0, 0.0, 0.0],
            &twice,
            Interpolation::Pchip
        )
        .unwrap_err(),
        TableError::DuplicateTheta(30.0)
    );
    // Averaged over azimuths instead, the same two rows are one ring: the
    // mean of their arguments (and still too few for a table).
    let mut three = twice.to_vec();
    three.push(at(60.0, 0.10));
    let averaged = ParamTable::from_reports_phi_averaged(
        brtf_model::Shape::single(kind),
        [1.0, 0.0, 0.0],
        &three,
        Interpolation::Pchip,
    )
    .unwrap();
    assert_eq!(averaged.theta_in, vec![30.0, 60.0]);
    assert!((averaged.args[0][3] - 0.055).abs() < 1e-12);
    assert_eq!(
        ParamTable::from_reports_phi_averaged(
            brtf_model::Shape::single(kind),
            [1.0, 0.0, 0.0],
            &twice,
            Interpolation::Pchip
        )
        .unwrap_err(),
        TableError::NeedTwoIncidences(1)
    );
}
