//! No run loses or corrupts a result, and no bad option runs.
//!
//! * Output folders: `kill -9` at points spread over a whole fit (the old
//!   or the new folder, whole, each time, and no stray file once the next
//!   run has cleaned up), two fits into one folder, refits and
//!   `export`/`plot` that remove exactly their own stale files.
//! * Inputs are never overwritten, even with `--force`; a fit of another
//!   sample is not replaced without it; default names from `#sample_name`.
//! * Standard output closed early (`| head -1`) or full (`/dev/full`).
//! * Every bad number refused with one line naming option, value and
//!   range; exit codes; `.rad` validation.

use crate::common::{BRTF, repo_path, s, temp_dir, write_file};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The five shipped scans of a synthetic GGX aluminium.
fn alu_files() -> Vec<PathBuf> {
    let dir = repo_path("data/alu-ggx");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "mpc"))
        .collect();
    files.sort();
    files
}

fn command(cwd: &Path, args: &[&str]) -> Command {
    let mut c = Command::new(BRTF);
    c.args(args).current_dir(cwd).stdin(Stdio::null());
    c
}

/// Runs brtf in `cwd` and returns its output.
fn run(cwd: &Path, args: &[&str]) -> Output {
    command(cwd, args).output().expect("run brtf")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `brtf fit` of the alu set into `out` with extra options.
fn fit_args<'a>(files: &'a [PathBuf], out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["fit", "--model", "metal", "--out", out];
    args.extend(files.iter().map(|f| s(f)));
    args.extend_from_slice(extra);
    args
}

/// The folder is one run's whole output: `fit.json` lists every other file
/// with its SHA-256, and the folder holds nothing else.
#[track_caller]
fn assert_whole(dir: &Path) -> brtf_fit::FitResult {
    let fit = brtf_fit::FitResult::read(&dir.join("fit.json"))
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut listed: Vec<&str> = fit.outputs.iter().map(|o| o.path.as_str()).collect();
    listed.push("fit.json");
    listed.sort();
    let present = brtf_io::folder_files(dir).unwrap();
    assert_eq!(
        present,
        listed,
        "{}: files vs fit.json's outputs",
        dir.display()
    );
    for output in &fit.outputs {
        let bytes = std::fs::read(dir.join(&output.path)).unwrap();
        assert_eq!(
            brtf_io::sha256_hex(&bytes),
            output.sha256,
            "{}",
            output.path
        );
    }
    fit
}

fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

#[test]
fn kill_9_at_any_moment_leaves_the_old_or_the_new_folder_whole() {
    let root = temp_dir();
    let files = alu_files();
    let fits = root.path().join("fits");
    let out = fits.join("alu");
    // Two option sets whose folders differ (the plots and the residual kind).
    let first = fit_args(&files, s(&out), &["--jobs", "1"]);
    let started = Instant::now();
    let o = run(root.path(), &first);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let full_run = started.elapsed();
    assert_whole(&out);

    let trials = 24;
    let (mut old, mut new, mut leftovers) = (0, 0, 0);
    for trial in 0..trials {
        let before = assert_whole(&out).provenance.created.clone()
            + &assert_whole(&out).outputs.len().to_string();
        let extra: &[&str] = if trial % 2 == 0 {
            &["--jobs", "1", "--residual", "log", "--no-plots"]
        } else {
            &["--jobs", "1"]
        };
        let args = fit_args(&files, s(&out), extra);
        let mut child = command(root.path(), &args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Points spread evenly over a whole run, from its start to past its end.
        let delay = full_run.mul_f64((trial as f64 + 0.5) / trials as f64 * 1.2);
        std::thread::sleep(delay);
        let _ = child.kill(); // SIGKILL
        child.wait().unwrap();
        let after = assert_whole(&out);
        if after.provenance.created.clone() + &after.outputs.len().to_string() == before {
            old += 1;
        } else {
            new += 1;
        }
        // Beside the folder: only brtf's hidden leftovers, which the next
        // run removes.
        for name in names(&fits) {
            assert!(
                name == "alu" || name.starts_with(".alu.brtf-"),
                "stray {name}"
            );
            leftovers += usize::from(name != "alu");
        }
    }
    let o = run(root.path(), &first);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_whole(&out);
    assert_eq!(names(&fits), ["alu"], "the last run cleaned every leftover");
    eprintln!(
        "kill -9: {trials} trials over {full_run:?}: old folder {old}, new folder {new}, \
         {leftovers} leftovers beside it (removed by the next run)"
    );
    assert!(old > 0, "some kills must land before the swap");
}

#[test]
fn a_second_fit_into_a_busy_folder_fails_at_once_and_the_first_completes() {
    let root = temp_dir();
    let files = alu_files();
    let fits = root.path().join("fits");
    let out = fits.join("alu");
    let args = fit_args(&files, s(&out), &["--jobs", "1"]);
    let mut first = command(root.path(), &args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the first run's staging folder: it holds the lock until it
    // swaps its folder in, a fit's whole length later.
    let deadline = Instant::now() + Duration::from_secs(20);
    while brtf_io::leftovers(&fits, "alu").is_empty() {
        assert!(Instant::now() < deadline, "the first fit never started");
        std::thread::sleep(Duration::from_millis(1));
    }
    let second = run(root.path(), &args);
    assert_eq!(second.status.code(), Some(1));
    let err = text(&second.stderr);
    assert!(err.contains("another brtf run is writing it"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(first.wait().unwrap().success());
    assert_whole(&out);
    assert_eq!(names(&fits), ["alu"]);
}

#[test]
fn a_refit_export_and_plot_remove_exactly_their_own_stale_files() {
    let root = temp_dir();
    let files = alu_files();
    let out = root.path().join("fit");
    let o = run(root.path(), &fit_args(&files, s(&out), &[]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let fit = assert_whole(&out);
    assert!(out.join("alu-ggx-theta.rad").exists() && out.join("plots/map-t60.svg").exists());
    assert!(fit.outputs.iter().any(|o| o.path == "params.csv"));

    // Export replaces its own files only: the θ_in-dependent ones go, the
    // plots stay.
    let o = run(root.path(), &["export", s(&out), "--static-only"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_whole(&out);
    assert!(!out.join("alu-ggx-theta.rad").exists() && !out.join("alu-ggx-theta.cal").exists());
    assert!(out.join("plots/map-t60.svg").exists());
    // Plot replaces the plots and the report, keeps the exports.
    let o = run(root.path(), &["plot", s(&out)]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_whole(&out);
    assert!(out.join("alu-ggx.rad").exists());

    // A refit of one incidence: no table, so no -theta.rad, no .cal, and
    // no map of the other incidences. It fits fewer files: --force.
    let one = [files[2].clone()];
    let args = fit_args(&one, s(&out), &[]);
    let err = text(&run(root.path(), &args).stderr);
    assert!(err.contains("holds the fit of other measurements"), "{err}");
    let mut forced = args.clone();
    forced.push("--force");
    let o = run(root.path(), &forced);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let fit = assert_whole(&out);
    assert_eq!(fit.incidences.len(), 1);
    let present = brtf_io::folder_files(&out).unwrap();
    assert!(
        !present
            .iter()
            .any(|f| f.contains("theta") || f.contains("-t60")),
        "{present:?}"
    );
    assert_eq!(names(root.path()), ["fit"]);
}

#[test]
fn inputs_are_never_overwritten() {
    let root = temp_dir();
    let scan = root.path().join("pab-aluA-st1:+30+0.mpc");
    std::fs::copy(
        repo_path("crates/gonio/tests/fixtures/pab-aluA-st1:+30+0.mpc"),
        &scan,
    )
    .unwrap();
    let original = std::fs::read(&scan).unwrap();
    let material = repo_path("data/materials/examples.rad");
    let gonio = [
        "render",
        "gonio",
        "--material",
        s(&material),
        "--name",
        "white_paint",
        "--like",
        s(&scan),
        "--out",
        s(&scan),
        "--samples",
        "1",
    ];
    let o = run(root.path(), &gonio);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o.stderr).contains("this run reads it")
            && text(&o.stderr).contains("--force does not"),
        "{}",
        text(&o.stderr)
    );
    // synth's default prefix is the folder's name: a real scan of that
    // name is not replaced.
    let folder = root.path().join("pab-aluA-st1");
    std::fs::create_dir(&folder).unwrap();
    let real = folder.join("pab-aluA-st1:+30+0.mpc");
    std::fs::copy(&scan, &real).unwrap();
    let synth = [
        "synth",
        "--ggx",
        "0.9,0.9,0.9",
        "--theta-in",
        "30",
        "--out",
        s(&folder),
    ];
    let o = run(root.path(), &synth);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o.stderr).contains("did not write it"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(std::fs::read(&real).unwrap(), original);
    // A fit folder that holds its inputs would lose them in the swap.
    let fit = [
        "fit",
        "--model",
        "metal",
        "--out",
        s(root.path()),
        s(&scan),
        "--force",
    ];
    let o = run(root.path(), &fit);
    assert!(
        text(&o.stderr).contains("holds the input"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(std::fs::read(&scan).unwrap(), original);
    // Not even with --force: that replaces only files of the same command.
    let mut forced = gonio.to_vec();
    forced.push("--force");
    assert_eq!(run(root.path(), &forced).status.code(), Some(1));
    assert_eq!(std::fs::read(&scan).unwrap(), original);
}

#[test]
fn default_names_come_from_the_sample_name_and_another_sample_is_not_replaced() {
    let root = temp_dir();
    let data = root.path().join("scans");
    for (prefix, f0) in [("Alu sample", "0.9,0.9,0.9"), ("Brass", "0.9,0.6,0.3")] {
        let synth = [
            "synth",
            "--ggx",
            f0,
            "--theta-in",
            "20,40",
            "--format",
            "mountain",
            "--channels",
            "3",
            "--prefix",
            prefix,
            "--out",
            s(&data),
            "--coarse-step",
            "5",
            "--fine-step",
            "1",
        ];
        let o = run(root.path(), &synth);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let scans = |stem: &str| -> Vec<String> {
        names(&data)
            .into_iter()
            .filter(|n| n.starts_with(stem))
            .map(|n| s(&data.join(n)).to_owned())
            .collect()
    };
    for stem in ["Alu sample", "Brass"] {
        let mut args = vec!["fit", "--model", "metal", "--no-plots"];
        let files = scans(stem);
        args.extend(files.iter().map(String::as_str));
        let o = run(root.path(), &args);
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    assert_eq!(names(&root.path().join("fits")), ["Alu_sample", "Brass"]);
    // Brass under Alu's folder: refused, the Alu fit intact.
    let mut args = vec![
        "fit",
        "--model",
        "metal",
        "--no-plots",
        "--out",
        "fits/Alu_sample",
    ];
    let brass = scans("Brass");
    args.extend(brass.iter().map(String::as_str));
    let o = run(root.path(), &args);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o.stderr).contains("other measurements"),
        "{}",
        text(&o.stderr)
    );
    let alu = assert_whole(&root.path().join("fits/Alu_sample"));
    assert!(alu.provenance.inputs[0].path.contains("Alu sample"));
}

#[test]
fn a_closed_pipe_exits_quietly_and_a_full_disk_says_so_in_one_line() {
    let root = temp_dir();
    let material = repo_path("data/materials/examples.rad");
    let eval = [
        "eval",
        "--material",
        s(&material),
        "--name",
        "white_paint",
        "--theta-in",
        "30",
        "--phi-in",
        "0",
    ];
    let directions: String = (0..200_000)
        .map(|i| format!("{},{}\n", i % 90, i % 360))
        .collect();
    // `brtf eval … | head -1`
    let mut child = command(root.path(), &eval)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        let _ = stdin.write_all(directions.as_bytes());
    });
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert_eq!(first, "theta_out,phi_out,r,g,b\n");
    let o = child.wait_with_output().unwrap();
    feeder.join().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(text(&o.stderr), "");

    // A fit whose reader has gone before anything is printed: quiet, exit
    // 0, and the folder whole.
    let files = alu_files();
    let out = root.path().join("fit");
    let args = fit_args(&files, s(&out), &["--no-plots"]);
    let mut child = command(root.path(), &args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(!text(&o.stderr).contains("panicked"), "{}", text(&o.stderr));
    assert_whole(&out);

    // /dev/full: one line, exit 1, the folder whole.
    if Path::new("/dev/full").exists() {
        for args in [fit_args(&files, s(&out), &["--no-plots"]), eval.to_vec()] {
            let full = std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap();
            let o = command(root.path(), &args)
                .stdin(Stdio::null())
                .stdout(full)
                .output()
                .unwrap();
            let err = text(&o.stderr);
            assert_eq!(o.status.code(), Some(1), "{err}");
            assert!(err.contains("cannot write to standard output"), "{err}");
            assert_eq!(err.lines().count(), 1, "{err}");
        }
        assert_whole(&out);
        // A full standard error loses the messages, not the run: a fit
        // with warnings and progress still writes its folder.
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = command(root.path(), &fit_args(&files, s(&out), &["--no-plots"]))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(full)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "a full stderr ended the fit");
        assert_whole(&out);
        // brtf synth reports every file on stderr (it panicked there).
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let synth = [
            "synth",
            "--ggx",
            "0.9,0.9,0.9",
            "--theta-in",
            "30",
            "--out",
            "quiet",
        ];
        let o = command(root.path(), &synth)
            .stdin(Stdio::null())
            .stderr(full)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "a full stderr ended brtf synth");
        assert!(root.path().join("quiet/quiet:+30+0.mpc").is_file());
    }
}

#[test]
fn every_bad_number_is_refused_in_one_line_before_any_work() {
    let root = temp_dir();
    let material = repo_path("data/materials/examples.rad");
    let m = s(&material);
    let scan = s(&alu_files()[0]).to_owned();
    let fit = |extra: &[&'static str]| -> Vec<String> {
        let mut a = vec!["fit", "--model", "metal", "--out", "never", &scan];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect()
    };
    let eval = |theta: &str| -> Vec<String> {
        [
            "eval",
            "--material",
            m,
            "--name",
            "white_paint",
            "--theta-in",
            theta,
            "--phi-in",
            "0",
        ]
        .map(String::from)
        .to_vec()
    };
    let synth = |extra: &[&str]| -> Vec<String> {
        let mut a = vec![
            "synth",
            "--ggx",
            "0.9,0.9,0.9",
            "--theta-in",
            "30",
            "--out",
            "never",
        ];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect()
    };
    let gonio = |extra: &[&str]| -> Vec<String> {
        let mut a = vec!["render", "gonio", "--material", m, "--name", "white_paint"];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect()
    };
    let check = |extra: &[&str]| -> Vec<String> {
        let mut a = vec!["check", "nowhere"];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect()
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            check(&["--intermediate", "1000000000"]),
            "--intermediate 1000000000: out of range",
        ),
        (check(&["--samples", "0"]), "--samples 0: out of range"),
        (
            [
                "render",
                "image",
                "--material",
                m,
                "--out",
                "never",
                "--exposure=-1",
            ]
            .map(String::from)
            .to_vec(),
            "--exposure -1: out of range",
        ),
        (
            [
                "render",
                "image",
                "--material",
                m,
                "--out",
                "never",
                "--samples",
                "100000000",
            ]
            .map(String::from)
            .to_vec(),
            "--samples 100000000: out of range",
        ),
        (
            check(&["--detector-omega", "7"]),
            "--detector-omega 7: out of range",
        ),
        (
            fit(&["--source-omega", "100"]),
            "--source-omega 100: out of range; allowed: 0 ≤ ω ≤ 2π",
        ),
        (
            fit(&["--loss", "cauchy:0"]),
            "--loss 0: out of range; allowed: C > 0",
        ),
        (
            fit(&["--theta-cap", "200"]),
            "--theta-cap 200: out of range; allowed: 0 < θ ≤ 90",
        ),
        (
            fit(&["--floor=-1"]),
            "--floor -1: out of range; allowed: > 0",
        ),
        (fit(&["--beam-mask", "95"]), "--beam-mask 95: out of range"),
        (fit(&["--fresnel-k", "2"]), "--fresnel-k 2: out of range"),
        (
            fit(&["--beam-integral", "0"]),
            "--beam-integral 0: out of range",
        ),
        (
            eval("nan"),
            "--theta-in NaN: out of range; allowed: 0 ≤ θ_in ≤ 180 degrees, not 90",
        ),
        (eval("90"), "--theta-in 90: out of range"),
        (synth(&["--theta-in", "90"]), "--theta-in 90: out of range"),
        (
            synth(&["--fine-step", "1e-6"]),
            "at most 2,000,000 samples per file",
        ),
        (
            synth(&["--coarse-step", "0"]),
            "--coarse-step 0: out of range",
        ),
        (synth(&["--noise=-1"]), "--noise -1: out of range"),
        (
            synth(&["--prefix", "a\n#injected: 1"]),
            "--prefix \"a\\n#injected: 1\": out of range; allowed: one line",
        ),
        (gonio(&["--theta-in", "90"]), "--theta-in 90: out of range"),
        (
            gonio(&["--theta-in", "30", "--theta-step", "1e-6"]),
            "grid steps too small",
        ),
        (
            gonio(&["--theta-in", "30", "--theta-step", "0"]),
            "grid steps must be positive",
        ),
        (
            [
                "albedo",
                "--material",
                m,
                "--name",
                "white_paint",
                "--theta-in",
                "30",
                "--tolerance",
                "0",
            ]
            .map(String::from)
            .to_vec(),
            "--tolerance 0: out of range",
        ),
    ];
    for (args, expected) in cases {
        let started = Instant::now();
        let o = run(
            root.path(),
            &args.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            !err.contains("Some(") && o.stdout.is_empty(),
            "{args:?}: {err}"
        );
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "{args:?} did work first"
        );
    }
    assert_eq!(names(root.path()), Vec::<String>::new(), "nothing written");
}

#[test]
fn usage_errors_exit_1_and_help_exits_0_listing_the_models() {
    let root = temp_dir();
    let o = run(root.path(), &["fit", "--bogus"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("unexpected argument '--bogus'"));
    let o = run(root.path(), &["fit", "--help"]);
    assert_eq!(o.status.code(), Some(0));
    let help = text(&o.stdout);
    assert!(
        help.contains("[possible values: plastic, metal, trans, plastic2, metal2, trans2, auto]"),
        "{help}"
    );
    assert!(help.contains("--force"), "{help}");
}

#[test]
fn rad_files_with_impossible_or_misparsed_materials_are_refused_or_read_right() {
    let root = temp_dir();
    let eval = |file: &Path, name: Option<&str>| {
        let mut args = vec![
            "eval",
            "--material",
            s(file),
            "--theta-in",
            "30",
            "--phi-in",
            "0",
        ];
        if let Some(n) = name {
            args.extend(["--name", n]);
        }
        let mut child = command(root.path(), &args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // brtf refuses a bad file before it reads stdin, and may be gone.
        let _ = child.stdin.take().unwrap().write_all(b"10,180\n");
        child.wait_with_output().unwrap()
    };
    for (body, expected) in [
        (
            "void plastic p 0 0 5 .5 .5 .5 .05 -.1",
            "bad.rad:2: plastic `p`: rough is -0.1; it must not be negative",
        ),
        (
            "void metal p 0 0 5 .5 .5 .5 1.5 .1",
            "spec is 1.5; it is a fraction, at most 1",
        ),
        (
            "void trans p 0 0 7 .5 .5 .5 0 .1 1.2 0",
            "trans is 1.2; it is a fraction, at most 1",
        ),
    ] {
        let file = write_file(root.path(), "bad.rad", &format!("# test\n{body}\n"));
        let o = eval(&file, None);
        assert_eq!(o.status.code(), Some(1));
        assert!(text(&o.stderr).contains(expected), "{}", text(&o.stderr));
    }
    // `void alias new old` has no argument lists: the material after it
    // is read, and the alias gives old's material.
    let file = write_file(
        root.path(),
        "alias.rad",
        "void plastic p 0 0 5 .5 .5 .5 .05 .1\nvoid alias q p\nvoid metal m 0 0 5 .5 .5 .5 .9 .05\n",
    );
    let by_alias = eval(&file, Some("q"));
    let direct = eval(&file, Some("p"));
    assert!(by_alias.status.success(), "{}", text(&by_alias.stderr));
    assert_eq!(text(&by_alias.stdout), text(&direct.stdout));
    assert!(eval(&file, Some("m")).status.success());
    // brtf's own θ_in-dependent export: refused, naming the file to use.
    let o = eval(&repo_path("fits/alu-ggx/alu-ggx-theta.rad"), None);
    let err = text(&o.stderr);
    assert!(
        err.contains("θ_in-dependent export") && err.contains("(alu-ggx.rad)"),
        "{err}"
    );
}
