//! Writers: exact round trips in both formats, header regeneration, atomic
//! writes and refusals.

use brtf_gonio::{
    Channels, Incidence, Measurement, Quantity, Sample, SourceFormat, WriteError, read_path,
    read_str, to_mountain_string, to_mpc_string, write_mountain, write_mpc, write_path,
};

use crate::common::{MPC_FIXTURE, assert_samples_identical, fixture_path, golden, layer};

fn assert_mpc_columns_identical(a: &Measurement, b: &Measurement) {
    assert_eq!(a.mpc_columns.len(), b.mpc_columns.len());
    for (x, y) in a.mpc_columns.iter().zip(&b.mpc_columns) {
        let bits = |c: &brtf_gonio::MpcColumns| {
            [
                c.beam_reference,
                c.raw_signal,
                c.minus_background_per_beam_reference,
                c.cosine_corrected,
            ]
            .map(|v| if v.is_nan() { u64::MAX } else { v.to_bits() })
        };
        assert_eq!(bits(x), bits(y));
    }
}

#[test]
fn golden_paper_round_trips_through_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("golden_copy.txt");
    write_mountain(golden(), &path).unwrap();
    let back = read_path(&path).unwrap();
    assert_samples_identical(&back.samples, &golden().samples);
    assert_eq!(
        back.header,
        golden().header,
        "unchanged header lines are kept verbatim"
    );
    assert_eq!(back.incidence, golden().incidence);
    assert_eq!(back.quantity, golden().quantity);
    assert_eq!(back.sample_name, golden().sample_name);
    // Only the target is left: the temporary file was renamed.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn layer_round_trips_in_memory() {
    let text = to_mountain_string(layer());
    let back = read_str(&text, "layer_copy.txt").unwrap();
    assert_samples_identical(&back.samples, &layer().samples);
    // Writing the re-read data gives the same text again.
    assert_eq!(to_mountain_string(&back), text);
}

#[test]
fn xyz_mountain_round_trip_with_sentinels_and_negatives() {
    let samples = vec![
        Sample::new(0.0, 0.0, [0.1, 0.2, 0.3]),
        Sample::new(45.5, 359.999, [-1e-7, f64::NAN, 1e-300]),
        Sample::new(135.25, 12.0, [1.0 / 3.0, 2.0f64.sqrt(), 1e20]),
        Sample::new(180.0, 0.0, [0.0, -0.0, 123.456]),
    ];
    let mut m = Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(12.5, 33.0),
        Quantity::Raw {
            unit: "nA".into(),
            beam_integral: Some(0.25),
        },
        Channels::Xyz,
        samples,
    );
    m.sample_name = Some("xyz test".into());
    m.up_phi_deg = 90.0;
    let text = to_mountain_string(&m);
    assert!(text.contains("#colorimetry: CIE-XYZ"), "{text}");
    assert!(text.contains("9.9e+37"), "NaN written as the sentinel");
    let back = read_str(&text, "xyz.txt").unwrap();
    assert_samples_identical(&back.samples, &m.samples);
    assert_eq!(back.channels, Channels::Xyz);
    assert_eq!(
        back.quantity, m.quantity,
        "beam integral carried by #beam_integral"
    );
    assert_eq!(back.incidence, m.incidence);
    assert_eq!(back.up_phi_deg, 90.0);
    assert_eq!(back.sample_name, m.sample_name);
}

#[test]
fn mpc_fixture_round_trips() {
    let original = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(MPC_FIXTURE);
    write_mpc(&original, &path).unwrap();
    let back = read_path(&path).unwrap();
    assert_samples_identical(&back.samples, &original.samples);
    assert_mpc_columns_identical(&back, &original);
    assert_eq!(back.header, original.header);
    assert_eq!(back.beam, original.beam);
    assert_eq!(back.incidence, original.incidence);
    // The header text is reproduced line for line.
    let written = std::fs::read_to_string(&path).unwrap();
    let fixture = std::fs::read_to_string(fixture_path(MPC_FIXTURE)).unwrap();
    let head = |t: &str| t.lines().take(14).map(str::to_owned).collect::<Vec<_>>();
    assert_eq!(head(&written), head(&fixture));
}

#[test]
fn changed_values_regenerate_their_header_lines() {
    let mut m = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    m.incidence = Incidence::new(40.0, 90.0);
    m.beam.as_mut().unwrap().integral = 0.5;
    let text = to_mpc_string(&m).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "#using beam file: pab-aluA-st1:beam.mpc.refint 0.5"
    );
    assert_eq!(lines[8], "40", "bare style kept");
    assert_eq!(lines[10], "#90", "commented style kept");
    let back = read_str(&text, "x:+40+90.mpc").unwrap();
    assert_eq!(back.incidence, m.incidence);
    assert_eq!(back.beam.unwrap().integral, 0.5);

    let mut g = golden().clone();
    g.incidence = Incidence::new(10.0, 20.0);
    g.samples.truncate(100);
    let text = to_mountain_string(&g);
    assert!(text.contains("#incident_angle\t10\t20\n"));
    assert!(text.contains("#intheta\t10\n") && text.contains("#inphi\t20\n"));
    assert!(text.contains("#datapoints_in_file\t100\n"));
    let back = read_str(&text, "g.txt").unwrap();
    assert_eq!(back.incidence, g.incidence);
    assert_eq!(back.len(), 100);
}

#[test]
fn programmatic_measurements_get_a_complete_header() {
    let m = Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(30.0, 0.0),
        Quantity::Bsdf,
        Channels::Y,
        vec![
            Sample::luminance(30.0, 180.0, 5.0),
            Sample::luminance(60.0, 90.0, 0.3),
        ],
    );
    let text = to_mountain_string(&m);
    assert_eq!(
        text,
        "#intheta\t30\n#inphi\t0\n#datapoints_in_file\t2\n#format: theta\tphi\tBSDF\n\
         30\t180\t5\n60\t90\t0.3\n"
    );
    let mpc = to_mpc_string(&m).unwrap();
    let back = read_str(&mpc, "prog.mpc").unwrap();
    assert_eq!(back.incidence, m.incidence);
    assert_eq!(back.samples, m.samples, "missing solid angles stay missing");
    assert!(back.mpc_columns.iter().all(|c| c.raw_signal.is_nan()));
}

#[test]
fn cross_format_writes() {
    // .mpc → Mountain keeps the old header as comments and the samples.
    let mpc = read_path(&fixture_path(MPC_FIXTURE)).unwrap();
    let text = to_mountain_string(&mpc);
    assert!(
        text.contains("\n#>30\n"),
        "bare value kept as an inert comment"
    );
    assert!(text.starts_with("#>using beam file: pab-aluA-st1:beam.mpc.refint 0.063626\n"));
    let back = read_str(&text, "from-mpc.txt").unwrap();
    assert_eq!(back.format, SourceFormat::Mountain);
    assert_eq!(back.quantity, Quantity::Bsdf);
    assert_eq!(back.incidence, mpc.incidence);
    let plain: Vec<_> = mpc
        .samples
        .iter()
        .map(|s| Sample {
            solid_angle_sr: None,
            ..*s
        })
        .collect();
    assert_samples_identical(&back.samples, &plain);

    // Raw Mountain → BSDF → .mpc.
    let mut small = golden().clone();
    small.samples.truncate(500);
    let bsdf = small.raw_to_bsdf(0.05).unwrap().measurement;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("converted.mpc");
    write_path(&bsdf, &path, SourceFormat::Mpc).unwrap();
    let back = read_path(&path).unwrap();
    assert_samples_identical(&back.samples, &bsdf.samples);
    assert_eq!(back.incidence, bsdf.incidence);
}

#[test]
fn mpc_refuses_what_it_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("raw.mpc");
    let err = write_mpc(golden(), &path).unwrap_err();
    assert!(matches!(err, WriteError::Unsupported { .. }));
    assert!(err.to_string().contains("raw.mpc") && err.to_string().contains("BSDF"));
    assert!(!path.exists());
    let xyz = Measurement::new(
        SourceFormat::Mpc,
        Incidence::new(0.0, 0.0),
        Quantity::Bsdf,
        Channels::Xyz,
        vec![],
    );
    assert!(to_mpc_string(&xyz).is_err());
}

#[test]
fn write_errors_name_the_path() {
    let err =
        write_mountain(golden(), std::path::Path::new("/nonexistent/dir/out.txt")).unwrap_err();
    assert!(matches!(err, WriteError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/dir/out.txt"));
}

#[test]
fn overwriting_replaces_the_whole_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.txt");
    std::fs::write(&path, "x".repeat(10_000_000)).unwrap();
    let m = Measurement::new(
        SourceFormat::Mountain,
        Incidence::new(0.0, 0.0),
        Quantity::Dsf,
        Channels::Y,
        vec![Sample::luminance(10.0, 0.0, 1.0)],
    );
    write_mountain(&m, &path).unwrap();
    assert!(std::fs::metadata(&path).unwrap().len() < 200);
    assert_eq!(read_path(&path).unwrap().samples, m.samples);
}
