//! `brtf export`: the files it writes, its options and errors, and live
//! comparisons with real Radiance.
//!
//! * **Static export.** rtrace on `<name>.rad`, over a grid of incidence
//!   and view directions, equals brtf-model (variant radiance, the
//!   pyradiance Fresnel constant) within 1e-4 relative.
//! * **θ_in-dependent export.** rtrace on `<name>-theta.rad` (with its
//!   `.cal`) equals brtf-model evaluated with `ParamTable::at(θ_in)` (the
//!   fitted variant) within 1% relative, or 2e-5 sr⁻¹ absolute for values
//!   near 0, at every fitted incidence and between them, on both sides of
//!   the surface (transmission for `trans`/`trans2`).
//!   A pattern (colorfunc) on the θ_in-dependent material scales its colour
//!   as it does for the static types.
//! * **Validity.** oconv prints nothing for either material with the
//!   preview scene, and rpict renders the preview without a message.
//!
//! Fit results are built in code (one per material type and variant, plus
//! one from real fits of synthetic data), written as `fit.json`, and
//! exported with `brtf export`. Run with `-- --nocapture` to see the
//! comparison summaries.

pub(crate) mod live;

use crate::common::{brtf, close, s, temp_dir};
use brtf_fit::{
    FitConfig, FitReport, FitResult, FitSample, IncidenceData, InputFile, Interpolation,
    ParamEstimate, ParamTable, Provenance, Termination, fit_incidence,
};
use brtf_model::{
    Bsdf, EvalOptions, FRESNEL_K_PYRADIANCE, Material, MaterialKind, Variant, cone_solid_angle,
    direction,
};
use glam::DVec3;
use std::path::Path;

// ---------------------------------------------------------------------------
// Fit results built in code
// ---------------------------------------------------------------------------

fn report(kind: MaterialKind, theta_in: f64, args: &[f64]) -> FitReport {
    FitReport {
        source: format!("synthetic/{kind}-{theta_in}.mpc"),
        theta_in,
        phi_in: 0.0,
        params: kind
            .param_names()
            .iter()
            .zip(args)
            .map(|(name, &value)| ParamEstimate {
                name: (*name).into(),
                value,
                stderr: Some(1e-3),
                stderr_robust: Some(1e-3),
                at_bound: false,
                fixed: false,
            })
            .collect(),
        material_args: args.to_vec(),
        scale: 1.0,
        n_points: 2000,
        gates: Vec::new(),
        weighting: brtf_fit::Weighting::Caller,
        rms_rel: 0.012,
        e1: None,
        cost: 0.5,
        floor: 0.0,
        termination: Termination::Converged {
            ftol: true,
            xtol: false,
        },
        evaluations: 40,
        elapsed_ms: 1.0,
        starts: Vec::new(),
        warnings: Vec::new(),
        adequacy: None,
        robust: None,
    }
}

/// A fit result with one row per `(θ_in, args)`, the all-incidence fit
/// `global` (default: the middle row) and the θ_in table.
struct Spec {
    name: &'static str,
    kind: MaterialKind,
    variant: Variant,
    orientation: [f64; 3],
    method: Interpolation,
    rows: Vec<(f64, Vec<f64>)>,
}

impl Spec {
    fn new(name: &'static str, kind: MaterialKind, rows: Vec<(f64, Vec<f64>)>) -> Spec {
        Spec {
            name,
            kind,
            variant: Variant::Radiance,
            orientation: [1.0, 0.0, 0.0],
            method: Interpolation::Pchip,
            rows,
        }
    }

    fn variant(mut self, v: Variant) -> Spec {
        self.variant = v;
        self
    }

    fn orientation(mut self, o: [f64; 3]) -> Spec {
        self.orientation = o;
        self
    }

    fn linear(mut self) -> Spec {
        self.method = Interpolation::Linear;
        self
    }

    fn result(&self) -> FitResult {
        let reports: Vec<FitReport> = self
            .rows
            .iter()
            .map(|(t, a)| report(self.kind, *t, a))
            .collect();
        let mut config = FitConfig::new(self.kind);
        config.options = EvalOptions::with_variant(self.variant);
        config.orientation = self.orientation;
        let global = report(self.kind, 0.0, &self.rows[self.rows.len() / 2].1);
        result_of(self.name, config, reports, Some(global), self.method)
    }
}

fn result_of(
    name: &str,
    config: FitConfig,
    incidences: Vec<FitReport>,
    global: Option<FitReport>,
    method: Interpolation,
) -> FitResult {
    // Rings of azimuths share a θ_in: their rows are averaged over φ_in.
    let table = (incidences.len() > 1).then(|| {
        ParamTable::from_reports(config.shape(), config.orientation, &incidences, method)
            .or_else(|_| {
                ParamTable::from_reports_phi_averaged(
                    config.shape(),
                    config.orientation,
                    &incidences,
                    method,
                )
            })
            .unwrap()
    });
    FitResult {
        schema: brtf_fit::FIT_JSON_SCHEMA,
        name: name.into(),
        provenance: Provenance {
            brtf_version: "0.1.0".into(),
            command_line: vec!["brtf".into(), "fit".into(), "(built in the test)".into()],
            created: "2026-01-01T00:00:00Z".into(),
            inputs: incidences
                .iter()
                .map(|r| InputFile {
                    path: r.source.clone(),
                    sha256: "0".repeat(64),
                    theta_in: r.theta_in,
                    phi_in: r.phi_in,
                    conversion: brtf_fit::Conversion::Bsdf,
                    samples: 2000,
                    klems: None,
                    phi_turn_deg: 0.0,
                    peak_arc_deg: None,
                    shadows: Vec::new(),
                    channels: 0,
                })
                .collect(),
        },
        recipe: brtf_fit::Recipe::for_kind(config.kind),
        config,
        incidences,
        global,
        table,
        interpolation: method,
        warnings: Vec::new(),
        auto: None,
        outputs: Vec::new(),
    }
}

/// Rows whose arguments move smoothly between `a` (first) and `b` (last).
fn rows(thetas: &[f64], a: &[f64], b: &[f64]) -> Vec<(f64, Vec<f64>)> {
    let (lo, hi) = (thetas[0], thetas[thetas.len() - 1]);
    thetas
        .iter()
        .map(|&t| {
            let u = (t - lo) / (hi - lo);
            // A bend, so PCHIP differs from linear interpolation.
            let w = u * u * (3.0 - 2.0 * u);
            (t, a.iter().zip(b).map(|(x, y)| x + w * (y - x)).collect())
        })
        .collect()
}

/// The θ_in-dependent cases: every type, both historical variants, the
/// lobe-only function types, grey colour and roughness 0.
fn theta_specs() -> Vec<Spec> {
    use MaterialKind::*;
    let five = [0.0, 20.0, 40.0, 60.0, 75.0];
    let three = [0.0, 30.0, 60.0];
    vec![
        Spec::new(
            "plastic",
            Plastic,
            rows(
                &five,
                &[0.6, 0.4, 0.2, 0.04, 0.06],
                &[0.7, 0.45, 0.15, 0.09, 0.15],
            ),
        ),
        Spec::new(
            "metal-grey",
            Metal,
            rows(
                &[0.0, 15.0, 30.0, 45.0, 60.0],
                &[0.8, 0.8, 0.8, 0.85, 0.05],
                &[0.9, 0.9, 0.9, 0.95, 0.12],
            ),
        ),
        Spec::new(
            "trans",
            Trans,
            rows(
                &three,
                &[0.7, 0.8, 0.9, 0.03, 0.04, 0.6, 0.5],
                &[0.6, 0.8, 0.95, 0.06, 0.1, 0.4, 0.7],
            ),
        ),
        Spec::new(
            "plastic2",
            Plastic2,
            rows(
                &three,
                &[0.5, 0.5, 0.4, 0.05, 0.05, 0.15],
                &[0.55, 0.5, 0.45, 0.08, 0.1, 0.2],
            ),
        )
        .orientation([1.0, 1.0, 0.0])
        .linear(),
        Spec::new(
            "metal2",
            Metal2,
            rows(
                &[0.0, 45.0],
                &[0.9, 0.7, 0.5, 0.9, 0.04, 0.1],
                &[0.95, 0.75, 0.55, 0.92, 0.06, 0.12],
            ),
        )
        .orientation([0.0, 1.0, 0.0]),
        Spec::new(
            "trans2",
            Trans2,
            rows(
                &[0.0, 40.0, 70.0],
                &[0.8, 0.7, 0.6, 0.04, 0.05, 0.12, 0.5, 0.6],
                &[0.85, 0.75, 0.6, 0.05, 0.08, 0.15, 0.4, 0.8],
            ),
        )
        .orientation([0.3, 1.0, 0.0]),
        Spec::new(
            "plastic-ward",
            Plastic,
            rows(
                &three,
                &[0.5, 0.4, 0.3, 0.05, 0.08],
                &[0.55, 0.45, 0.3, 0.08, 0.14],
            ),
        )
        .variant(Variant::Ward1992),
        Spec::new(
            "metal-ward",
            Metal,
            rows(
                &three,
                &[0.9, 0.7, 0.5, 0.8, 0.06],
                &[0.95, 0.75, 0.55, 0.9, 0.1],
            ),
        )
        .variant(Variant::Ward1992),
        Spec::new(
            "trans-manual",
            Trans,
            rows(
                &[0.0, 45.0],
                &[0.6, 0.7, 0.8, 0.04, 0.05, 0.5, 0.5],
                &[0.65, 0.7, 0.8, 0.06, 0.08, 0.5, 0.6],
            ),
        )
        .variant(Variant::Manual2004),
        // Only the roughness changes: metfunc and transfunc suffice.
        Spec::new(
            "metal-lobe",
            Metal,
            rows(
                &three,
                &[0.9, 0.8, 0.7, 0.9, 0.05],
                &[0.9, 0.8, 0.7, 0.9, 0.11],
            ),
        ),
        Spec::new(
            "trans-lobe",
            Trans,
            rows(
                &three,
                &[0.6, 0.7, 0.8, 0.05, 0.05, 0.5, 0.6],
                &[0.6, 0.7, 0.8, 0.05, 0.12, 0.5, 0.6],
            ),
        ),
        // Roughness 0 everywhere: Fresnel-weighted diffuse only, mirror as a ray.
        Spec::new(
            "plastic-smooth",
            Plastic,
            rows(
                &three,
                &[0.4, 0.5, 0.6, 0.05, 0.0],
                &[0.45, 0.5, 0.6, 0.07, 0.0],
            ),
        ),
    ]
}

/// Writes `fit.json` for `result` into a new folder under `root`; returns
/// the folder and the result as read back, which is what `brtf export`
/// sees (serde_json may round the last bit of a float).
fn write_fit(root: &Path, folder: &str, result: &FitResult) -> (std::path::PathBuf, FitResult) {
    let dir = root.join(folder);
    std::fs::create_dir_all(&dir).unwrap();
    let json = serde_json::to_string_pretty(result).unwrap();
    std::fs::write(dir.join("fit.json"), &json).unwrap();
    (dir, serde_json::from_str(&json).unwrap())
}

/// `brtf export fit_dir args...`, which must succeed.
fn export(fit_dir: &Path, args: &[&str]) -> String {
    let mut all = vec!["export", s(fit_dir)];
    all.extend_from_slice(args);
    brtf(&all, "").ok()
}

// ---------------------------------------------------------------------------
// Comparison bookkeeping
// ---------------------------------------------------------------------------

#[derive(Default)]
struct Stats {
    values: usize,
    worst_rel: f64,
    worst_at: String,
    failures: Vec<String>,
    n_failures: usize,
}

impl Stats {
    fn compare(
        &mut self,
        model: [f64; 3],
        rtrace: [f64; 3],
        rel: f64,
        abs: f64,
        at: &dyn Fn() -> String,
    ) {
        for c in 0..3 {
            let (m, r) = (model[c], rtrace[c]);
            self.values += 1;
            if m.abs().max(r.abs()) > 1e-3 {
                let e = (m - r).abs() / m.abs().max(r.abs());
                if e > self.worst_rel {
                    self.worst_rel = e;
                    self.worst_at = at();
                }
            }
            if !(m.is_finite() && r.is_finite() && close(r, m, rel, abs)) {
                self.n_failures += 1;
                if self.failures.len() < 20 {
                    self.failures.push(format!(
                        "{} channel {c}: brtf-model {m:e}, rtrace {r:e}",
                        at()
                    ));
                }
            }
        }
    }

    #[track_caller]
    fn assert_ok(&self, test: &str, rel: f64, abs: f64) {
        eprintln!(
            "[{test}] {} values compared; worst relative difference {:.2e} (values > 1e-3 sr^-1) at {}",
            self.values, self.worst_rel, self.worst_at
        );
        assert!(self.values > 0, "{test}: nothing compared");
        assert!(
            self.n_failures == 0,
            "{test}: {} of {} values differ by more than {rel:e} relative and {abs:e} absolute:\n{}",
            self.n_failures,
            self.values,
            self.failures.join("\n")
        );
    }
}

/// The fit's formulas as rtrace applies them to the test scene's light: a
/// source of solid angle `omega` on a flat surface, no jitter.
fn as_rtrace_lights(result: &FitResult, omega: f64) -> EvalOptions {
    EvalOptions {
        source_omega: omega,
        flat: true,
        source_jitter: 0.0,
        ..result.config.options
    }
}

/// View directions (θ_out, φ_out): a grid over both hemispheres and a
/// dense patch around the mirror and straight-through directions.
fn views(theta_in: f64, phi_in: f64) -> Vec<(f64, f64)> {
    let mut v = Vec::new();
    for t in [0.0, 8.0, 20.0, 35.0, 50.0, 65.0, 78.0, 86.0, 89.5] {
        for k in 0..8 {
            let p = 45.0 * k as f64 + 10.0;
            v.push((t, p));
            v.push((180.0 - t, p));
        }
    }
    for dt in [-6.0, -3.0, -1.0, 0.0, 1.0, 3.0, 6.0] {
        for dp in [-8.0, -2.0, 0.0, 2.0, 8.0] {
            let t = theta_in + dt;
            if (0.5..89.5).contains(&t) {
                v.push((t, phi_in + 180.0 + dp));
                v.push((180.0 - t, phi_in + 180.0 + dp));
            }
        }
    }
    v
}

/// The incidences of the θ_in-dependent comparison: every node of every
/// table, the midpoints, and a few in between and beyond the ranges.
const THETA_INCIDENCES: &[f64] = &[
    0.0, 7.5, 10.0, 15.0, 20.0, 22.5, 30.0, 33.0, 37.5, 40.0, 45.0, 50.0, 52.5, 55.0, 60.0, 65.0,
    67.5, 70.0, 72.5, 75.0, 82.0,
];

/// Traces every material (polygon k carries modifier `names[k]`) for the
/// given incidences; calls `check(k, theta_in, phi_in, v, rtrace_bsdf)`.
fn trace_all(
    radiance: &live::Radiance,
    dir: &Path,
    files: &[String],
    names: &[String],
    incidences: &[(f64, f64)],
    omega: f64,
    mut check: impl FnMut(usize, f64, f64, DVec3, [f64; 3]),
) {
    for &(theta_in, phi_in) in incidences {
        let l = direction(theta_in, phi_in);
        std::fs::write(
            dir.join("scene.rad"),
            live::scene(l.to_array(), omega, names),
        )
        .unwrap();
        let mut inputs: Vec<&str> = files.iter().map(String::as_str).collect();
        inputs.push("scene.rad");
        let warnings = radiance.oconv(dir, &inputs, "scene.oct");
        assert!(warnings.is_empty(), "oconv {inputs:?}: {warnings}");
        let dirs = views(theta_in, phi_in);
        let mut rays = Vec::new();
        for k in 0..names.len() {
            for &(t, p) in &dirs {
                rays.push(live::ray(k, direction(t, p).to_array()));
            }
        }
        let (values, stderr) = radiance.trace(dir, "scene.oct", &rays);
        assert!(stderr.is_empty(), "rtrace at θ_in {theta_in}: {stderr}");
        for (i, radiance) in values.into_iter().enumerate() {
            let (k, (t, p)) = (i / dirs.len(), dirs[i % dirs.len()]);
            let f = live::bsdf_from_radiance(radiance, omega, l.z);
            check(k, theta_in, phi_in, direction(t, p), f);
        }
    }
}

// ---------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------

#[test]
fn writes_four_files_with_headers_and_a_readable_static_material() {
    let tmp = temp_dir();
    let (dir, result) = write_fit(
        tmp.path(),
        "fits/plastic",
        &theta_specs().remove(0).result(),
    );
    let out = export(&dir, &[]);
    for name in [
        "plastic.rad",
        "plastic-theta.rad",
        "plastic-theta.cal",
        "plastic-preview.rad",
    ] {
        assert!(out.contains(name), "{out}");
        assert!(dir.join(name).is_file(), "{name} missing");
    }
    // Nothing else (no temporary files left behind).
    let mut entries: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    entries.sort();
    assert_eq!(
        entries,
        [
            "fit.json",
            "plastic-preview.rad",
            "plastic-theta.cal",
            "plastic-theta.rad",
            "plastic.rad"
        ]
    );
    let text = std::fs::read_to_string(dir.join("plastic.rad")).unwrap();
    assert!(text.is_ascii());
    for needle in [
        "all-incidence fit (5 incidences",
        "rms_rel 0.012",
        "Variant: radiance",
        "Caveats:",
        "brtf fit (built in the test)",
    ] {
        assert!(text.contains(needle), "`{needle}` not in\n{text}");
    }
    let prims = brtf_radiance::parse_primitives(&text, "plastic.rad").unwrap();
    let (name, material) = brtf_radiance::select_material(&prims, None, "plastic.rad").unwrap();
    assert_eq!(name, "plastic");
    assert_eq!(Some(material), result.static_material());
}

#[test]
fn at_takes_an_incidence_or_the_interpolated_table() {
    let tmp = temp_dir();
    let (dir, result) = write_fit(tmp.path(), "fit", &theta_specs().remove(0).result());
    let table = result.table.as_ref().unwrap();
    for (at, want) in [
        ("40", table.at(40.0).unwrap().material),
        ("33", table.at(33.0).unwrap().material),
        ("80", table.at(80.0).unwrap().material),
    ] {
        export(
            &dir,
            &["--at", at, "--name", "m", "--static-only", "--no-preview"],
        );
        let text = std::fs::read_to_string(dir.join("m.rad")).unwrap();
        let prims = brtf_radiance::parse_primitives(&text, "m.rad").unwrap();
        let (_, got) = brtf_radiance::select_material(&prims, Some("m"), "m.rad").unwrap();
        assert_eq!(got, want, "--at {at}");
        assert!(!dir.join("m-theta.rad").exists());
        if at == "80" {
            assert!(text.contains("outside the measured 0-75 deg"), "{text}");
        }
    }
}

#[test]
fn variant_fits_warn_with_the_rho_difference() {
    let tmp = temp_dir();
    for spec in theta_specs() {
        if spec.variant == Variant::Radiance {
            continue;
        }
        let (dir, _) = write_fit(tmp.path(), spec.name, &spec.result());
        let run = brtf(&["export", s(&dir)], "");
        assert!(run.success, "{run}");
        assert!(
            run.stderr.contains("which current rtrace does not compute"),
            "{run}"
        );
        let text = std::fs::read_to_string(dir.join(format!("{}.rad", spec.name))).unwrap();
        assert!(
            text.contains(&format!("WARNING: variant {}", spec.variant)),
            "{text}"
        );
        assert!(text.contains("rho rtrace"), "{text}");
        // One row per incidence, with a signed percentage.
        let rows = text
            .lines()
            .filter(|l| l.trim_end().ends_with('%') && l.starts_with("#   "))
            .count();
        assert_eq!(rows, spec.rows.len(), "{text}");
    }
}

#[test]
fn bad_input_fails_with_a_message() {
    let tmp = temp_dir();
    let err = brtf(&["export", s(tmp.path())], "").err();
    assert!(err.contains("fit.json"), "{err}");
    std::fs::write(tmp.path().join("fit.json"), "{\"name\": 3}").unwrap();
    let err = brtf(&["export", s(tmp.path())], "").err();
    assert!(err.contains("schema version 1"), "{err}");
    std::fs::write(tmp.path().join("fit.json"), "{\"schema\": 2, \"name\": 3}").unwrap();
    let err = brtf(&["export", s(tmp.path())], "").err();
    assert!(err.contains("not a brtf fit result"), "{err}");

    let (dir, result) = write_fit(tmp.path(), "fit", &theta_specs().remove(0).result());
    let err = brtf(&["export", s(&dir), "--name", "a b"], "").err();
    assert!(err.contains("cannot be used"), "{err}");
    let err = brtf(&["export", s(&dir), "--at", "95"], "").err();
    assert!(err.contains("--at 95"), "{err}");

    let mut one = result.clone();
    one.incidences.truncate(1);
    one.global = None;
    one.table = None;
    let (dir, _) = write_fit(tmp.path(), "one", &one);
    let err = brtf(&["export", s(&dir), "--at", "30"], "").err();
    assert!(err.contains("no θ_in table"), "{err}");
    let run = brtf(&["export", s(&dir)], "");
    assert!(run.success, "{run}");
    assert!(run.stderr.contains("no θ_in-dependent material"), "{run}");
    assert!(dir.join("plastic.rad").is_file());
}

#[test]
fn static_export_matches_live_rtrace() {
    let Some(radiance) = live::radiance_or_skip("static_export_matches_live_rtrace") else {
        return;
    };
    let tmp = temp_dir();
    let scene_dir = tmp.path().join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    let mut files = Vec::new();
    let mut names = Vec::new();
    let mut materials = Vec::new();
    for (k, spec) in theta_specs().into_iter().enumerate() {
        let (dir, result) = write_fit(tmp.path(), spec.name, &spec.result());
        let name = format!("m{k}");
        export(
            &dir,
            &["--out", s(&scene_dir), "--name", &name, "--no-preview"],
        );
        files.push(format!("{name}.rad"));
        materials.push(result.static_material().unwrap());
        names.push(name);
    }
    // Also one static material taken from the table with --at.
    let (dir, result) = write_fit(tmp.path(), "at", &theta_specs().remove(2).result());
    export(
        &dir,
        &[
            "--out",
            s(&scene_dir),
            "--name",
            "at37",
            "--at",
            "37.5",
            "--static-only",
            "--no-preview",
        ],
    );
    files.push("at37.rad".into());
    names.push("at37".into());
    materials.push(result.table.as_ref().unwrap().at(37.5).unwrap().material);

    let omega = cone_solid_angle(live::SOURCE_APEX_DEG);
    let options = EvalOptions {
        variant: Variant::Radiance,
        fresnel_k: FRESNEL_K_PYRADIANCE,
        source_omega: omega,
        flat: true,
        source_jitter: 0.0,
    };
    let bsdfs: Vec<Bsdf> = materials.iter().map(|m| Bsdf::new(m, &options)).collect();
    let incidences: Vec<(f64, f64)> = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0]
        .iter()
        .flat_map(|&t| [(t, 0.0), (t, 40.0)])
        .collect();
    let (rel, abs) = (1e-4, 1e-9);
    let mut stats = Stats::default();
    trace_all(
        &radiance,
        &scene_dir,
        &files,
        &names,
        &incidences,
        omega,
        |k, t, p, v, f| {
            let model = bsdfs[k].eval(direction(t, p), v);
            stats.compare(model, f, rel, abs, &|| {
                format!("{} θ_in {t} φ_in {p} v {:?}", names[k], v)
            });
        },
    );
    stats.assert_ok("static_export_matches_live_rtrace", rel, abs);
}

#[test]
fn theta_export_matches_live_rtrace() {
    let Some(radiance) = live::radiance_or_skip("theta_export_matches_live_rtrace") else {
        return;
    };
    let tmp = temp_dir();
    let scene_dir = tmp.path().join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    let mut cases: Vec<(String, FitResult)> = theta_specs()
        .into_iter()
        .map(|spec| (spec.name.to_string(), spec.result()))
        .collect();
    cases.push(("fitted-trans".into(), fitted_trans()));
    let mut files = Vec::new();
    let mut names = Vec::new();
    for (name, result) in &mut cases {
        let (dir, reread) = write_fit(tmp.path(), name, result);
        *result = reread;
        export(&dir, &["--out", s(&scene_dir), "--name", name]);
        files.push(format!("{name}-theta.rad"));
        names.push(name.clone());
        let text = std::fs::read_to_string(scene_dir.join(format!("{name}-theta.rad"))).unwrap();
        let expected_type = match name.as_str() {
            "metal-lobe" => "metfunc",
            "trans-lobe" => "transfunc",
            _ => "BRTDfunc",
        };
        assert!(
            text.contains(&format!("void {expected_type} {name}\n")),
            "{name}: expected a {expected_type}:\n{text}"
        );
    }
    // A pattern on the material modifies its colour, as it does for the
    // static types: the same material under a constant colorfunc.
    const TINT: [f64; 3] = [0.5, 0.8, 1.0];
    for name in ["plastic", "metal-grey", "trans", "metal-lobe", "trans2"] {
        let k = names.iter().position(|n| n == name).unwrap();
        let text = std::fs::read_to_string(scene_dir.join(&files[k])).unwrap();
        let line = text
            .lines()
            .find(|l| l.starts_with("void ") && l.ends_with(&format!(" {name}")))
            .unwrap();
        let kind = line.split_whitespace().nth(1).unwrap();
        let tinted = text.replace(line, &format!("{name}-tint {kind} {name}-tinted"));
        let pattern = format!(
            "void colorfunc {name}-tint\n4 {} {} {} .\n0\n0\n\n",
            TINT[0], TINT[1], TINT[2]
        );
        std::fs::write(
            scene_dir.join(format!("{name}-tinted.rad")),
            pattern + &tinted,
        )
        .unwrap();
        let mut result = cases[k].1.clone();
        for row in &mut result.table.as_mut().unwrap().args {
            for c in 0..3 {
                row[c] *= TINT[c];
            }
        }
        files.push(format!("{name}-tinted.rad"));
        names.push(format!("{name}-tinted"));
        cases.push((format!("{name}-tinted"), result));
    }
    let omega = cone_solid_angle(live::SOURCE_APEX_DEG);
    let mut incidences: Vec<(f64, f64)> = THETA_INCIDENCES.iter().map(|&t| (t, 0.0)).collect();
    incidences.extend([(12.0, 35.0), (47.0, 35.0), (63.0, 120.0)]);
    let (rel, abs) = (1e-2, 2e-5);
    let mut stats = Stats::default();
    let mut per_material = vec![(0usize, 0.0f64); cases.len()];
    trace_all(
        &radiance,
        &scene_dir,
        &files,
        &names,
        &incidences,
        omega,
        |k, t, p, v, f| {
            let result = &cases[k].1;
            let table = result.table.as_ref().unwrap();
            let options = as_rtrace_lights(result, omega);
            let material = table.at(t).unwrap().material;
            let model = Bsdf::new(&material, &options).eval(direction(t, p), v);
            for c in 0..3 {
                if model[c].abs() > 1e-3 {
                    let e = (model[c] - f[c]).abs() / model[c].abs();
                    per_material[k].1 = per_material[k].1.max(e);
                }
            }
            per_material[k].0 += 3;
            stats.compare(model, f, rel, abs, &|| {
                format!(
                    "{} θ_in {t} φ_in {p} v ({:.4} {:.4} {:.4})",
                    names[k], v.x, v.y, v.z
                )
            });
        },
    );
    for ((name, _), (n, worst)) in cases.iter().zip(&per_material) {
        eprintln!("  {name:>16}: {n} values, worst relative {worst:.2e}");
    }
    stats.assert_ok("theta_export_matches_live_rtrace", rel, abs);
}

/// A `trans2` fitted to rings of azimuths (as to a Klems basis) follows
/// (θ_in, φ_in): rtrace on its `-theta.rad` equals brtf-model with
/// `ParamTable::at_direction(θ_in, φ_in)`, at the fitted incidences and
/// between them in θ_in and φ_in, for both interpolation methods. The
/// orientation is turned, so φ_in counts from u, not from x.
#[test]
fn azimuth_export_matches_live_rtrace() {
    let Some(radiance) = live::radiance_or_skip("azimuth_export_matches_live_rtrace") else {
        return;
    };
    let tmp = temp_dir();
    let scene_dir = tmp.path().join("scene");
    std::fs::create_dir_all(&scene_dir).unwrap();
    // u at 30° from x: φ_in from u is the light's azimuth minus 30°.
    let orientation = [30f64.to_radians().cos(), 30f64.to_radians().sin(), 0.0];
    let rings: [(f64, usize); 5] = [(0.0, 1), (15.0, 8), (30.0, 12), (45.0, 12), (60.0, 8)];
    let args_at = |theta: f64, phi_from_u: f64| -> Vec<f64> {
        let (c, s2) = (
            phi_from_u.to_radians().cos(),
            (2.0 * phi_from_u).to_radians().sin(),
        );
        let x = theta / 60.0;
        let g = 0.30 + 0.05 * x;
        vec![
            g,
            g,
            g,
            0.02 + 0.01 * x * (1.0 + c),
            0.06 + 0.03 * x * (1.0 + 0.5 * s2),
            0.10 + 0.04 * x * (1.0 - c),
            0.15 + 0.05 * x * c,
            0.5 + 0.2 * x * s2,
        ]
    };
    let mut reports = Vec::new();
    for (theta, count) in rings {
        for k in 0..count {
            // Azimuths of the light in the data's frame (from x).
            let phi = 360.0 * k as f64 / count as f64 + 5.0;
            let mut r = report(MaterialKind::Trans2, theta, &args_at(theta, phi - 30.0));
            r.phi_in = phi;
            reports.push(r);
        }
    }
    let mut cases = Vec::new();
    for (name, method) in [
        ("aniso-pchip", Interpolation::Pchip),
        ("aniso-linear", Interpolation::Linear),
    ] {
        let mut config = FitConfig::new(MaterialKind::Trans2);
        config.orientation = orientation;
        let mut result = result_of(name, config, reports.clone(), None, method);
        result.table = Some(
            ParamTable::from_reports_over_azimuth(
                brtf_model::Shape::single(MaterialKind::Trans2),
                orientation,
                &reports,
                method,
                false,
            )
            .unwrap(),
        );
        let (dir, reread) = write_fit(tmp.path(), name, &result);
        assert!(reread.table.as_ref().unwrap().depends_on_azimuth());
        export(&dir, &["--out", s(&scene_dir), "--name", name]);
        cases.push((name.to_string(), reread));
    }
    let files: Vec<String> = cases
        .iter()
        .map(|(n, _)| format!("{n}-theta.rad"))
        .collect();
    let names: Vec<String> = cases.iter().map(|(n, _)| n.clone()).collect();
    let omega = cone_solid_angle(live::SOURCE_APEX_DEG);
    // Light azimuths from x: on a ring's incidences, between them, across
    // 0°/360°; θ_in on rows and between them.
    let incidences = [
        (15.0, 50.0),
        (15.0, 72.5),
        (22.0, 3.0),
        (30.0, 350.0),
        (37.5, 200.0),
        (45.0, 125.0),
        (52.0, 275.0),
        (60.0, 95.0),
        (7.0, 140.0),
    ];
    let (rel, abs) = (1e-2, 2e-5);
    let mut stats = Stats::default();
    let mut differs_from_mean = 0;
    trace_all(
        &radiance,
        &scene_dir,
        &files,
        &names,
        &incidences,
        omega,
        |k, t, p, v, f| {
            let table = cases[k].1.table.as_ref().unwrap();
            let options = as_rtrace_lights(&cases[k].1, omega);
            let l = direction(t, p);
            let material = table.at_direction(t, p - 30.0).unwrap().material;
            let model = Bsdf::new(&material, &options).eval(l, v);
            let mean = Bsdf::new(&table.at(t).unwrap().material, &options).eval(l, v);
            if (mean[0] - model[0]).abs() > 0.05 * model[0].abs() {
                differs_from_mean += 1;
            }
            stats.compare(model, f, rel, abs, &|| {
                format!(
                    "{} θ_in {t} φ_in {p} v ({:.4} {:.4} {:.4})",
                    names[k], v.x, v.y, v.z
                )
            });
        },
    );
    stats.assert_ok("azimuth_export_matches_live_rtrace", rel, abs);
    // The azimuth matters: many values differ from the φ_in-averaged table's.
    assert!(
        differs_from_mean > 50,
        "{differs_from_mean} values depend on φ_in"
    );
}

#[test]
fn exports_pass_oconv_and_the_preview_renders() {
    let Some(radiance) = live::radiance_or_skip("exports_pass_oconv_and_the_preview_renders")
    else {
        return;
    };
    let tmp = temp_dir();
    for spec in theta_specs() {
        let (dir, _) = write_fit(tmp.path(), spec.name, &spec.result());
        export(&dir, &[]);
        let n = spec.name;
        for material in [format!("{n}.rad"), format!("{n}-theta.rad")] {
            let preview = format!("{n}-preview.rad");
            let warnings = radiance.oconv(&dir, &[&material, &preview], "preview.oct");
            assert!(
                warnings.is_empty(),
                "oconv {material} {preview}: {warnings}"
            );
        }
        // The preview's own render command, tiny: the .cal loads and
        // evaluates without a message, direct and indirect.
        let out = radiance.run(
            "rpict",
            &dir,
            &[
                "-vtv",
                "-vp",
                "6",
                "-6",
                "3",
                "-vd",
                "-6",
                "6",
                "-2.6",
                "-vu",
                "0",
                "0",
                "1",
                "-vh",
                "30",
                "-vv",
                "30",
                "-x",
                "12",
                "-y",
                "12",
                "-ab",
                "1",
                "-ad",
                "64",
                "-as",
                "0",
                "-aa",
                "0",
                "-ps",
                "1",
                "preview.oct",
            ],
            b"",
        );
        assert!(out.stderr.is_empty(), "rpict {n}: {}", out.stderr);
        assert!(out.stdout.len() > 100, "rpict {n}: no picture");
    }
}

// ---------------------------------------------------------------------------
// A real fit of synthetic data
// ---------------------------------------------------------------------------

/// Fits `trans` to noise-free synthetic data at θ_in = 0, 30 and 60 whose
/// parameters change with θ_in, and returns the fit result.
fn fitted_trans() -> FitResult {
    let truth = |t: f64| {
        let u = t / 60.0;
        vec![
            0.6 + 0.1 * u,
            0.7,
            0.8 - 0.1 * u,
            0.04 + 0.03 * u,
            0.05 + 0.05 * u * u,
            0.5 - 0.1 * u,
            0.6 + 0.2 * u,
        ]
    };
    let config = FitConfig::new(MaterialKind::Trans);
    let reports: Vec<FitReport> = [0.0, 30.0, 60.0]
        .iter()
        .map(|&t| {
            let m = Material::new(MaterialKind::Trans, &truth(t), None).unwrap();
            fit_incidence(&synthetic(&m, t), &config).unwrap()
        })
        .collect();
    result_of("fitted-trans", config, reports, None, Interpolation::Pchip)
}

/// Noise-free BSDF samples of `material` on a 2° × 10° grid over both
/// hemispheres plus a dense patch at the mirror and through directions.
fn synthetic(material: &Material, theta_in: f64) -> IncidenceData {
    let bsdf = Bsdf::new(material, &EvalOptions::default());
    let l = direction(theta_in, 0.0);
    let mut samples = Vec::new();
    let mut push = |v: DVec3, weight: f64| {
        samples.push(FitSample {
            view: v,
            value: bsdf.eval(l, v),
            weight,
        });
    };
    for i in 0..43 {
        let t = 1.0 + 2.0 * i as f64;
        for j in 0..36 {
            let p = 10.0 * j as f64;
            let w = t.to_radians().sin() * 2f64.to_radians() * 10f64.to_radians();
            push(direction(t, p), w);
            push(direction(180.0 - t, p), w);
        }
    }
    for i in 1..=15 {
        for j in 0..12 {
            let (dt, dp) = (
                0.8 * i as f64 * (j as f64).cos(),
                0.8 * i as f64 * (j as f64).sin(),
            );
            let t = theta_in + dt;
            if t > 0.5 && t < 85.0 {
                let w = 1e-4;
                push(direction(t, 180.0 + dp), w);
                push(direction(180.0 - t, 180.0 + dp), w);
            }
        }
    }
    IncidenceData {
        source: format!("synthetic trans θ_in={theta_in}"),
        theta_in,
        phi_in: 0.0,
        channels: 3,
        samples,
        gates: Vec::new(),
        weighting: brtf_fit::Weighting::Caller,
        patch_pairs: None,
        cosine_weighted: false,
    }
}

/// A fit of one incidence says so in its `.rad` header, not "the
/// all-incidence fit (1 incidences, …)".
#[test]
fn a_one_incidence_export_names_its_incidence() {
    let dir = temp_dir();
    let out = dir.path().join("one");
    let scan = crate::fit::real_scan("golden_paper.txt");
    let args = ["fit", s(&scan), "--model", "metal", "--gray", "--no-plots"];
    brtf(&[&args[..], &["--out", s(&out)]].concat(), "").ok();
    let rad = std::fs::read_to_string(out.join("Golden_glossy_paper.rad")).unwrap();
    assert!(
        rad.contains("# Parameters: the fit of the one incidence, theta_in = 26.8421 deg ("),
        "{rad}"
    );
    assert!(!rad.contains("1 incidences"), "{rad}");
}

/// A free-scale fit's material is not renderable as is: its first line
/// says so and no preview scene is written.
#[test]
fn a_free_scale_export_says_it_is_not_renderable_and_has_no_preview() {
    let dir = temp_dir();
    let out = dir.path().join("free");
    let scan = crate::fit::real_scan("golden_paper.txt");
    let args = ["fit", s(&scan), "--model", "metal", "--gray", "--no-plots"];
    let run = brtf(&[&args[..], &["--out", s(&out)]].concat(), "");
    let printed = format!("{}{}", run.stdout, run.stderr);
    assert!(run.success, "{printed}");
    let rad = std::fs::read_to_string(out.join("Golden_glossy_paper.rad")).unwrap();
    assert!(rad.starts_with("# NOT RENDERABLE AS IS: "), "{rad}");
    assert!(!out.join("Golden_glossy_paper-preview.rad").exists());
    assert!(
        printed.contains("no preview scene for a free-scale fit"),
        "{printed}"
    );
    // With a known reflectance it is absolute: renderable, with its scene.
    let absolute = dir.path().join("absolute");
    let args = ["fit", s(&scan), "--model", "metal", "--gray", "--no-plots"];
    let known = ["--rho", "0.85@26.8421", "--out", s(&absolute)];
    brtf(&[&args[..], &known[..]].concat(), "").ok();
    let rad = std::fs::read_to_string(absolute.join("Golden_glossy_paper.rad")).unwrap();
    assert!(!rad.contains("NOT RENDERABLE"), "{rad}");
    assert!(absolute.join("Golden_glossy_paper-preview.rad").exists());
}
