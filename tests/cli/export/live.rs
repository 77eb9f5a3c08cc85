//! Real Radiance for the export tests: find `oconv`/`rtrace`/`rpict`, run
//! them in a folder (so exported `.cal` files are found through `RAYPATH`),
//! and turn rtrace's direct term into a BSDF.
//!
//! Radiance is looked up in `$RADIANCE_BIN`, on `PATH`, then in the
//! repository's `.venv` (pyradiance). Missing Radiance skips the live tests
//! with a loud warning, or fails them under `CI`.

use crate::common;
use std::ffi::OsString;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Full apex angle of the test source, degrees (as in the oracle).
pub(crate) const SOURCE_APEX_DEG: f64 = 0.01;

/// rtrace options giving exactly the direct term of one unjittered source
/// sample (oracle/README.md §3).
const RTRACE_OPTIONS: &[&str] = &[
    "-h-", "-ab", "0", "-av", "0", "0", "0", "-aw", "0", "-dv-", "-st", "1", "-ss", "0", "-dj",
    "0", "-ds", "0", "-dt", "0", "-dc", "1", "-dr", "0", "-bv+", "-fdd", "-ov",
];

/// A Radiance installation.
#[derive(Debug, Clone)]
pub(crate) struct Radiance {
    bin: PathBuf,
    /// Radiance's library folder (rayinit.cal), when known.
    lib: Option<PathBuf>,
    pub origin: String,
}

/// What one program run printed.
#[derive(Debug)]
pub(crate) struct Output {
    pub stdout: Vec<u8>,
    pub stderr: String,
}

fn has(dir: &Path, name: &str) -> bool {
    dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX))
        .is_file()
}

fn lib_of(bin: &Path) -> Option<PathBuf> {
    let lib = bin.parent()?.join("lib");
    lib.join("rayinit.cal").is_file().then_some(lib)
}

fn locate() -> Result<Radiance, String> {
    let complete = |d: &Path| ["oconv", "rtrace", "rpict"].iter().all(|n| has(d, n));
    if let Some(dir) = std::env::var_os("RADIANCE_BIN") {
        let bin = PathBuf::from(dir);
        assert!(
            complete(&bin),
            "RADIANCE_BIN={} lacks oconv, rtrace or rpict",
            bin.display()
        );
        return Ok(Radiance {
            lib: lib_of(&bin),
            origin: format!("$RADIANCE_BIN={}", bin.display()),
            bin,
        });
    }
    if let Some(path) = std::env::var_os("PATH")
        && let Some(bin) = std::env::split_paths(&path).find(|d| complete(d))
    {
        return Ok(Radiance {
            lib: lib_of(&bin),
            origin: format!("PATH ({})", bin.display()),
            bin,
        });
    }
    let venv = common::repo_path(".venv/lib");
    let mut candidates: Vec<PathBuf> = std::fs::read_dir(&venv)
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
        .map(|e| e.path().join("site-packages/pyradiance/bin"))
        .filter(|p| complete(p))
        .collect();
    candidates.sort();
    if let Some(bin) = candidates.pop() {
        return Ok(Radiance {
            lib: lib_of(&bin),
            origin: format!("pyradiance in .venv ({})", bin.display()),
            bin,
        });
    }
    Err(format!(
        "looked in $RADIANCE_BIN, PATH and {}",
        venv.join("python3*/site-packages/pyradiance/bin").display()
    ))
}

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
}

/// Radiance, or `None` after a loud warning (a failure under `CI`).
pub(crate) fn radiance_or_skip(test: &str) -> Option<Radiance> {
    match locate() {
        Ok(r) => {
            eprintln!("[{test}] using Radiance from {}", r.origin);
            Some(r)
        }
        Err(searched) if in_ci() => {
            panic!("[{test}] Radiance not found and CI is set: {searched}")
        }
        Err(searched) => {
            let bar = "!".repeat(78);
            let _ = writeln!(
                std::io::stderr(),
                "\n{bar}\n!!! RADIANCE NOT FOUND: live export test `{test}` SKIPPED\n!!! {searched}\n\
                 !!! python3 -m venv .venv && .venv/bin/pip install pyradiance==1.3.1\n{bar}\n"
            );
            None
        }
    }
}

impl Radiance {
    /// RAYPATH for programs run in a folder: the folder first, then
    /// Radiance's library.
    fn raypath(&self) -> OsString {
        let mut value = OsString::from(".");
        match (std::env::var_os("RAYPATH"), &self.lib) {
            (Some(inherited), _) => {
                value.push(":");
                value.push(inherited);
            }
            (None, Some(lib)) => {
                value.push(":");
                value.push(lib.as_os_str());
            }
            (None, None) => {}
        }
        value
    }

    /// Runs `program args...` in `dir` with `stdin`; panics on failure.
    pub(crate) fn run(&self, program: &str, dir: &Path, args: &[&str], stdin: &[u8]) -> Output {
        let exe = self
            .bin
            .join(format!("{program}{}", std::env::consts::EXE_SUFFIX));
        let mut child = Command::new(&exe)
            .args(args)
            .current_dir(dir)
            .env("RAYPATH", self.raypath())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot run {}: {e}", exe.display()));
        let mut pipe = child.stdin.take().expect("piped");
        let input = stdin.to_vec();
        let writer = std::thread::spawn(move || {
            let _ = pipe.write_all(&input);
        });
        let mut stdout = Vec::new();
        child
            .stdout
            .take()
            .expect("piped")
            .read_to_end(&mut stdout)
            .expect("read stdout");
        let out = child.wait_with_output().expect("wait");
        writer.join().expect("stdin writer");
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(
            out.status.success(),
            "{program} {args:?} in {} failed: {stderr}",
            dir.display()
        );
        Output { stdout, stderr }
    }

    /// `oconv files... > scene.oct` in `dir`; returns oconv's stderr.
    pub(crate) fn oconv(&self, dir: &Path, files: &[&str], octree: &str) -> String {
        let out = self.run("oconv", dir, files, b"");
        std::fs::write(dir.join(octree), &out.stdout).expect("write octree");
        out.stderr
    }

    /// rtrace on `octree` in `dir` for `rays` (origin, direction): the
    /// radiance of each, and rtrace's stderr.
    pub(crate) fn trace(
        &self,
        dir: &Path,
        octree: &str,
        rays: &[[f64; 6]],
    ) -> (Vec<[f64; 3]>, String) {
        let mut args: Vec<&str> = RTRACE_OPTIONS.to_vec();
        args.push(octree);
        let input: Vec<u8> = rays
            .iter()
            .flat_map(|r| r.iter().flat_map(|x| x.to_ne_bytes()))
            .collect();
        let out = self.run("rtrace", dir, &args, &input);
        assert_eq!(
            out.stdout.len(),
            rays.len() * 24,
            "rtrace returned {} bytes for {} rays: {}",
            out.stdout.len(),
            rays.len(),
            out.stderr
        );
        let values = out
            .stdout
            .chunks_exact(24)
            .map(|c| {
                let v = |i: usize| f64::from_ne_bytes(c[8 * i..8 * i + 8].try_into().expect("8"));
                [v(0), v(1), v(2)]
            })
            .collect();
        (values, out.stderr)
    }
}

/// A distant source in direction `l` (unit) of radiance 1/ω, and one 2 × 2
/// polygon (normal +z) per modifier, the k-th centred at (10k, 0, 0).
pub(crate) fn scene(l: [f64; 3], omega: f64, modifiers: &[String]) -> String {
    let radiance = 1.0 / omega;
    let mut s = format!(
        "void light test_source_light\n0\n0\n3 {radiance} {radiance} {radiance}\n\n\
         test_source_light source test_source\n0\n0\n4 {} {} {} {SOURCE_APEX_DEG}\n\n",
        l[0], l[1], l[2]
    );
    for (k, m) in modifiers.iter().enumerate() {
        let x = 10.0 * k as f64;
        s += &format!(
            "{m} polygon test_surface_{k}\n0\n0\n12 {} -1 0 {} -1 0 {} 1 0 {} 1 0\n\n",
            x - 1.0,
            x + 1.0,
            x + 1.0,
            x - 1.0
        );
    }
    s
}

/// The ray that sees polygon `k` from direction `v` (unit, away from it).
pub(crate) fn ray(k: usize, v: [f64; 3]) -> [f64; 6] {
    [10.0 * k as f64 + v[0], v[1], v[2], -v[0], -v[1], -v[2]]
}

/// The BSDF rtrace implies: radiance / (L_f32 · ω · |cos θ_in|).
pub(crate) fn bsdf_from_radiance(radiance: [f64; 3], omega: f64, light_cosine: f64) -> [f64; 3] {
    let l32 = f64::from((1.0 / omega) as f32);
    let scale = l32 * omega * light_cosine.abs();
    radiance.map(|x| x / scale)
}
