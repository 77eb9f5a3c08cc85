//! Shared helpers: run `brtf`, parse its CSV, temporary files.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Path of the binary under test.
pub(crate) const BRTF: &str = env!("CARGO_BIN_EXE_brtf");

/// The outcome of one `brtf` run.
#[derive(Debug)]
pub(crate) struct Run {
    pub success: bool,
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    /// The command line, for failure messages.
    pub command: String,
}

impl Run {
    /// Panics (with the whole run in the message) unless the run succeeded.
    #[track_caller]
    pub(crate) fn ok(self) -> String {
        assert!(self.success, "expected success, got {self}");
        self.stdout
    }

    /// Panics unless the run failed with a non-zero exit code; returns stderr.
    #[track_caller]
    pub(crate) fn err(self) -> String {
        assert!(!self.success, "expected failure, got {self}");
        assert!(
            matches!(self.code, Some(c) if c != 0),
            "expected a non-zero exit code, got {self}"
        );
        assert!(
            !self.stderr.trim().is_empty(),
            "failure without a message: {self}"
        );
        self.stderr
    }
}

impl std::fmt::Display for Run {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`{}` exit {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.command, self.code, self.stdout, self.stderr
        )
    }
}

/// Runs `brtf args...` with `stdin` as its standard input.
pub(crate) fn brtf<S: AsRef<str>>(args: &[S], stdin: &str) -> Run {
    let args: Vec<&str> = args.iter().map(AsRef::as_ref).collect();
    let mut child = Command::new(BRTF)
        .args(&args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {BRTF}: {e}"));
    let mut pipe = child.stdin.take().expect("stdin is piped");
    let input = stdin.to_owned();
    // Write from a thread so that a large input cannot dead-lock against a
    // full stdout pipe. brtf may exit early (on an error) and close its end.
    let writer = std::thread::spawn(move || {
        let _ = pipe.write_all(input.as_bytes());
    });
    let output = child.wait_with_output().expect("wait for brtf");
    writer.join().expect("stdin writer");
    Run {
        success: output.status.success(),
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
        command: format!("brtf {}", args.join(" ")),
    }
}

/// A CSV table with a header and numeric rows.
#[derive(Debug, Clone)]
pub(crate) struct Csv {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Csv {
    /// Index of a column by name.
    #[track_caller]
    pub(crate) fn col(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column `{name}` in {:?}", self.header))
    }

    /// The values of one column.
    pub(crate) fn column(&self, name: &str) -> Vec<f64> {
        let i = self.col(name);
        self.rows.iter().map(|r| r[i]).collect()
    }
}

/// Parses CSV output: a header line, then rows of numbers with as many
/// fields as the header.
#[track_caller]
pub(crate) fn parse_csv(text: &str) -> Csv {
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap_or_else(|| panic!("empty CSV output"))
        .split(',')
        .map(|s| s.trim().to_owned())
        .collect();
    let rows = lines
        .enumerate()
        .map(|(i, line)| {
            let row: Vec<f64> = line
                .split(',')
                .map(|f| {
                    f.trim().parse::<f64>().unwrap_or_else(|_| {
                        panic!("line {}: `{f}` is not a number in `{line}`", i + 2)
                    })
                })
                .collect();
            assert_eq!(
                row.len(),
                header.len(),
                "line {}: `{line}` vs header {header:?}",
                i + 2
            );
            row
        })
        .collect();
    Csv { header, rows }
}

/// A fresh temporary directory (removed when dropped).
pub(crate) fn temp_dir() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("brtf-cli-test")
        .tempdir()
        .expect("create temp dir")
}

/// Writes `text` to `dir/name` and returns the path.
pub(crate) fn write_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap_or_else(|e| panic!("write {}: {e}", path.display()));
    path
}

/// A path as a `&str` (temp dirs and the repo are UTF-8 here).
pub(crate) fn s(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// Path of a file under the repository root.
pub(crate) fn repo_path(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// Path of a file in `tests/cli/data`.
pub(crate) fn data_path(name: &str) -> PathBuf {
    repo_path("tests/cli/data").join(name)
}

/// Unit vector (θ, φ in degrees), z = surface normal.
pub(crate) fn direction(theta_deg: f64, phi_deg: f64) -> [f64; 3] {
    let (st, ct) = theta_deg.to_radians().sin_cos();
    let (sp, cp) = phi_deg.to_radians().sin_cos();
    [st * cp, st * sp, ct]
}

pub(crate) use brtf_model::cone_solid_angle;

/// `|a − b| ≤ abs` or `≤ rel·|b|`.
pub(crate) fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    let d = (a - b).abs();
    d <= abs || d <= rel * b.abs()
}

/// The Radiance `bin` folder holding every tool in `names` ($RADIANCE_BIN,
/// else PATH, else pyradiance in the repo's `.venv`), or `None` after a
/// loud warning that `test` did not run. Under CI a missing tool fails.
pub(crate) fn radiance_tools_or_skip(test: &str, names: &[&str]) -> Option<PathBuf> {
    let exe = |dir: &Path, name: &str| {
        let path = dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
        path.is_file().then_some(path)
    };
    let has_all = |dir: &Path| names.iter().all(|n| exe(dir, n).is_some());
    if let Some(dir) = std::env::var_os("RADIANCE_BIN") {
        let dir = PathBuf::from(dir);
        assert!(
            has_all(&dir),
            "RADIANCE_BIN={} lacks one of {names:?}",
            dir.display()
        );
        return Some(dir);
    }
    if let Some(path) = std::env::var_os("PATH")
        && let Some(dir) = std::env::split_paths(&path).find(|d| has_all(d))
    {
        return Some(dir);
    }
    let lib = repo_path(".venv/lib");
    let mut bins: Vec<PathBuf> = std::fs::read_dir(&lib)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .filter(|e| e.file_name().to_string_lossy().starts_with("python3"))
                .map(|e| e.path().join("site-packages/pyradiance/bin"))
                .collect()
        })
        .unwrap_or_default();
    bins.sort();
    if let Some(dir) = bins.into_iter().find(|b| has_all(b)) {
        return Some(dir);
    }
    let message = format!(
        "{names:?} not found in $RADIANCE_BIN, PATH or {}",
        lib.display()
    );
    if std::env::var("CI")
        .is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
    {
        panic!("{test}: {message}; install pyradiance into .venv");
    }
    eprintln!("\n!!! WARNING: {message}; the live test {test} did NOT run\n");
    None
}

/// `name` from the Radiance `bin` folder, run in `dir`, with RAYPATH
/// holding `.` and `bin/../lib` (pyradiance keeps `WINDOW6BSDFt.xml`
/// there, which `wrapBSDF` needs).
pub(crate) fn radiance_command(bin: &Path, name: &str, dir: &Path) -> std::process::Command {
    let mut cmd = std::process::Command::new(bin.join(name));
    cmd.current_dir(dir);
    let mut raypath = std::ffi::OsString::from(".");
    if let Some(lib) = bin.parent().map(|p| p.join("lib")).filter(|l| l.is_dir()) {
        raypath.push(":");
        raypath.push(lib.as_os_str());
    }
    cmd.env("RAYPATH", raypath);
    // Radiance tools run others (bsdf2klems runs wrapBSDF) from PATH.
    let mut path = std::ffi::OsString::from(bin.as_os_str());
    if let Some(rest) = std::env::var_os("PATH") {
        path.push(":");
        path.push(rest);
    }
    cmd.env("PATH", path);
    cmd
}
