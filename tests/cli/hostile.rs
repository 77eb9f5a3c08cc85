//! What a hostile or careless user tries: outputs aimed at the run's own
//! inputs or at a fit folder's files, links planted in a fit folder,
//! non-UTF-8 paths, absurd `--jobs`, an orientation along the normal and
//! negative option values. Every file that must not change is compared by
//! SHA-256 before and after.

use crate::common::{BRTF, repo_path, s, temp_dir};
use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn run<S: AsRef<OsStr>>(cwd: &Path, args: &[S]) -> Output {
    Command::new(BRTF)
        .args(args)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .output()
        .expect("run brtf")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The SHA-256 of every file below `dir` (or of the file `dir`).
fn digests(dir: &Path) -> Vec<(PathBuf, String)> {
    let mut all = Vec::new();
    if dir.is_file() {
        let bytes = std::fs::read(dir).unwrap();
        all.push((dir.to_path_buf(), brtf_io::sha256_hex(&bytes)));
    } else if dir.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for e in entries {
            all.extend(digests(&e));
        }
    }
    all
}

fn alu_files() -> Vec<PathBuf> {
    ["0", "15", "30", "45", "60"]
        .iter()
        .map(|t| repo_path(&format!("data/alu-ggx/alu-ggx:+{t}+0.mpc")))
        .collect()
}

/// A fit folder `F` of copies of the alu scans (in `root/scans`).
fn fit_folder(root: &Path) -> (PathBuf, Vec<PathBuf>) {
    let scans = root.join("scans");
    std::fs::create_dir(&scans).unwrap();
    let copies: Vec<PathBuf> = alu_files()
        .iter()
        .map(|f| {
            let to = scans.join(f.file_name().unwrap());
            std::fs::copy(f, &to).unwrap();
            to
        })
        .collect();
    let mut args = vec!["fit", "--model", "metal", "--out", "F", "--no-plots"];
    args.extend(copies.iter().map(|p| s(p)));
    let o = run(root, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    (root.join("F"), copies)
}

#[test]
fn no_output_replaces_an_input_or_a_fit_folders_file() {
    let root = temp_dir();
    let (folder, scans) = fit_folder(root.path());
    let name = |f: &str| s(&folder.join(f)).to_string();
    let before = (digests(&folder), digests(&root.path().join("scans")));
    let scan = s(&scans[2]).to_string();
    let refused: Vec<Vec<String>> = vec![
        vec!["check".into(), "F".into(), "--out".into(), name("fit.json")],
        vec![
            "check".into(),
            "F".into(),
            "--out".into(),
            name("alu-ggx.rad"),
        ],
        vec!["check".into(), "F".into(), "--out".into(), scan.clone()],
        [
            "render",
            "gonio",
            "--fit",
            "F",
            "--theta-in",
            "30",
            "--force",
            "--out",
        ]
        .iter()
        .map(|a| a.to_string())
        .chain([name("fit.json")])
        .collect(),
        [
            "render", "gonio", "--fit", "F", "--force", "--like", &scan, "--out", &scan,
        ]
        .iter()
        .map(|a| a.to_string())
        .collect(),
        [
            "render",
            "image",
            "--fit",
            "F",
            "--radiance",
            "--width",
            "8",
            "--height",
            "6",
            "--out",
        ]
        .iter()
        .map(|a| a.to_string())
        .chain([name("alu-ggx")])
        .collect(),
    ];
    for args in &refused {
        let o = run(root.path(), args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("refusing to overwrite"), "{args:?}: {err}");
        assert!(err.contains("this run reads it"), "{args:?}: {err}");
    }
    // A measurement that is not an input is replaced only with --force.
    let other = root.path().join("other.mpc");
    std::fs::copy(&scans[0], &other).unwrap();
    let other_before = digests(&other);
    let gonio = |force: bool| {
        let mut args = vec!["render", "gonio", "--fit", "F", "--like", &scan];
        args.extend(["--samples", "1", "--out", s(&other)]);
        if force {
            args.push("--force");
        }
        run(root.path(), &args)
    };
    let o = gonio(false);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("did not write it"), "{}", stderr(&o));
    assert_eq!(digests(&other), other_before);
    assert!(gonio(true).status.success());
    // Its own earlier output is replaced without --force.
    let o = gonio(false);
    assert!(o.status.success(), "{}", stderr(&o));
    // check's own file is rewritten as before.
    assert!(
        run(root.path(), &["check", "F", "--samples", "1"])
            .status
            .success()
    );
    std::fs::remove_file(folder.join("check.csv")).unwrap();
    assert_eq!(
        (digests(&folder), digests(&root.path().join("scans"))),
        before
    );
}

#[test]
fn links_planted_in_a_fit_folder_or_at_its_lock_are_not_followed() {
    let root = temp_dir();
    let (folder, _) = fit_folder(root.path());
    let outside = root.path().join("outside");
    std::fs::create_dir(&outside).unwrap();
    std::fs::write(outside.join("map-t30.svg"), "keep").unwrap();
    std::os::unix::fs::symlink(&outside, folder.join("plots")).unwrap();
    let before = (digests(&folder), digests(&outside));
    let o = run(root.path(), &["plot", "F"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("plots: refusing to write through a symbolic link"),
        "{err}"
    );
    assert_eq!((digests(&folder), digests(&outside)), before);

    let planted = root.path().join("planted");
    std::os::unix::fs::symlink(&planted, root.path().join(".G.brtf-lock")).unwrap();
    let mut args = vec!["fit", "--model", "metal", "--out", "G", "--no-plots"];
    let files = alu_files();
    args.extend(files.iter().map(|p| s(p)));
    let o = run(root.path(), &args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(".G.brtf-lock: refusing to write through a symbolic link"),
        "{err}"
    );
    assert!(!planted.exists() && !root.path().join("G").exists());
}

#[test]
fn non_utf8_paths_are_read_and_written() {
    let root = temp_dir();
    let name = |stem: &[u8], ext: &str| {
        let mut bytes = stem.to_vec();
        bytes.extend_from_slice(ext.as_bytes());
        PathBuf::from(OsStr::from_bytes(&bytes))
    };
    let scan = root.path().join(name(b"b\xff", ".mpc"));
    std::fs::copy(&alu_files()[2], &scan).unwrap();
    let out = root.path().join(name(b"f\xff", ""));
    let o = run(
        root.path(),
        &[
            OsStr::new("fit"),
            scan.as_os_str(),
            OsStr::new("--model"),
            OsStr::new("plastic"),
            OsStr::new("--no-plots"),
            OsStr::new("--out"),
            out.as_os_str(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("fit.json").is_file());
    let klems = root.path().join(name(b"k\xff", ""));
    let o = run(
        root.path(),
        &[
            OsStr::new("export"),
            out.as_os_str(),
            OsStr::new("--klems"),
            OsStr::new("quarter"),
            OsStr::new("--klems-samples"),
            OsStr::new("4"),
            OsStr::new("--out"),
            klems.as_os_str(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let synth = root.path().join(name(b"s\xff", ""));
    let o = run(
        root.path(),
        &[
            OsStr::new("synth"),
            OsStr::new("--material"),
            repo_path("data/materials/examples.rad").as_os_str(),
            OsStr::new("--name"),
            OsStr::new("white_paint"),
            OsStr::new("--theta-in"),
            OsStr::new("30"),
            OsStr::new("--out"),
            synth.as_os_str(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&synth).unwrap().count(), 1);
}

#[test]
fn absurd_options_are_refused_before_any_work() {
    let root = temp_dir();
    let files = alu_files();
    let fit = |extra: &[&str]| {
        let mut args = vec!["fit", "--out", "X", "--no-plots"];
        args.extend(files.iter().map(|p| s(p)));
        args.extend_from_slice(extra);
        run(root.path(), &args)
    };
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let cases: [(&[&str], String); 4] = [
        (
            &["--model", "metal", "--jobs", "5000"],
            format!("--jobs 5000: out of range; allowed: 1 to {}", 4 * cores),
        ),
        (
            &["--model", "plastic2", "--orientation", "0,0,1"],
            "--orientation 0,0,1: needs a direction with a part in the surface".into(),
        ),
        (
            &["--model", "metal", "--theta-cap", "-5"],
            "--theta-cap -5: out of range".into(),
        ),
        (
            &["--model", "metal", "--jobs", "0"],
            "--jobs 0: out of range".into(),
        ),
    ];
    for (extra, expected) in cases {
        let o = fit(extra);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {err}");
        assert!(err.contains(&expected), "{extra:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{extra:?}: {err}");
    }
    assert!(!root.path().join("X").exists());
    // Negative values as their own word, in a nested subcommand too.
    let o = run(
        root.path(),
        &[
            "render",
            "image",
            "--material",
            s(&repo_path("data/materials/examples.rad")),
            "--name",
            "white_paint",
            "--out",
            "img",
            "--exposure",
            "-1",
        ],
    );
    assert!(
        stderr(&o).contains("--exposure -1: out of range"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn endless_or_huge_inputs_are_refused_before_reading() {
    let root = temp_dir();
    let examples = repo_path("data/materials/examples.rad");
    let endless: [&[&str]; 4] = [
        &["info", "/dev/zero"],
        &["fit", "/dev/zero", "--model", "metal", "--out", "Z"],
        &[
            "eval",
            "--material",
            "/dev/zero",
            "--theta-in",
            "30",
            "--phi-in",
            "0",
        ],
        &["info", "."],
    ];
    for args in endless {
        let o = run(root.path(), args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("not a regular file"), "{args:?}: {err}");
    }
    // Over the limit (lowered to 1 MiB here): refused from its size.
    let big = root.path().join("big.txt");
    let file = std::fs::File::create(&big).unwrap();
    file.set_len(2 << 20).unwrap();
    for args in [
        vec!["info", "big.txt"],
        vec!["fit", "big.txt", "--model", "metal", "--out", "Z"],
        vec![
            "eval",
            "--material",
            "big.txt",
            "--theta-in",
            "30",
            "--phi-in",
            "0",
        ],
    ] {
        let o = Command::new(BRTF)
            .args(&args)
            .current_dir(root.path())
            .env("BRTF_MAX_INPUT_MB", "1")
            .stdin(Stdio::null())
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("larger than brtf reads (1 MiB); set BRTF_MAX_INPUT_MB"),
            "{args:?}: {err}"
        );
    }
    assert!(!root.path().join("Z").exists());
    // Within the default limit the same file is read (and refused for its
    // NUL bytes, with the offset).
    let o = run(root.path(), &["info", "big.txt"]);
    assert!(
        stderr(&o).contains("NUL byte at byte offset 0"),
        "{}",
        stderr(&o)
    );
    let o = run(
        root.path(),
        &[
            "eval",
            "--material",
            s(&examples),
            "--name",
            "white_paint",
            "--theta-in",
            "30",
            "--phi-in",
            "0",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn an_xml_element_with_absurd_attribute_counts_is_refused() {
    let root = temp_dir();
    let attributes: Vec<String> = (0..200_000).map(|i| format!("a{i}=\"1\"")).collect();
    let text = format!(
        "<?xml version=\"1.0\"?>\n<!-- x=1 y=2 -->\n<WindowElement {}></WindowElement>\n",
        attributes.join(" ")
    );
    std::fs::write(root.path().join("crowded.xml"), text).unwrap();
    let o = run(root.path(), &["info", "crowded.xml"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("crowded.xml:3:") && err.contains("an element with 200000 attributes"),
        "{err}"
    );
    // The real fabrics still read.
    let fabric = repo_path("../shared/data/lbnl-frads-klems-fabrics/klems_aniso_high.xml");
    let o = run(root.path(), &["info", s(&fabric)]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn ctrl_c_and_kill_remove_the_staging_folder_and_the_lock() {
    let root = temp_dir();
    let golden = repo_path("../shared/data/rgl-epfl-pgII-raw/golden_paper.txt");
    assert!(golden.is_file(), "{} is missing", golden.display());
    let leftovers = |dir: &Path| -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".brtf-"))
            .collect()
    };
    for (signal, code) in [("-INT", 130), ("-TERM", 143)] {
        let mut child = Command::new(BRTF)
            .args(["fit", s(&golden), "--model", "auto", "--out", "S"])
            .current_dir(root.path())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Signal once the run is writing (its staging folder exists).
        let started = std::time::Instant::now();
        while !leftovers(root.path()).iter().any(|n| n.contains("stage")) {
            assert!(child.try_wait().unwrap().is_none(), "the fit ended first");
            assert!(started.elapsed().as_secs() < 60, "no staging folder");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let killed = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "{signal}: {status:?}");
        assert_eq!(leftovers(root.path()), Vec::<String>::new(), "{signal}");
        assert!(!root.path().join("S").exists());
    }
}
