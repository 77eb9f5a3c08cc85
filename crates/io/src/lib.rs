//! # brtf-io: the file helpers every brtf crate shares
//!
//! * [`write_atomic`]: a reader sees the old file or the new one, never
//!   half of one (temporary file in the same folder, fsync, rename).
//! * [`sha256_hex`]: the digest recorded for every input in `fit.json`.
//! * [`locate_input`]: finds an input file recorded in a fit folder again,
//!   from wherever the user runs a later command.
//! * [`FolderUpdate`]: an output folder written into a staging folder,
//!   under a lock, and swapped in as a whole (`folder.rs`).
//! * [`OutputFile`]: the listing of an output folder's files with their
//!   digests and the step that wrote them (`outputs.rs`).
//!
//! Errors are plain [`std::io::Error`]s with the path in [`IoError`], so
//! each crate can wrap them in its own error type.

mod folder;
mod interrupt;
mod outputs;

pub use folder::{FolderUpdate, check_overwrite, check_replaceable, fit_folder_inputs, leftovers};
pub use interrupt::clean_up_on_signals;
pub use outputs::{OutputFile, Producer, describe_outputs, folder_files, replace_outputs};
use sha2::{Digest, Sha256};
use std::io::Write;
use std::path::{Path, PathBuf};

/// An I/O failure on a named path.
#[derive(Debug)]
pub struct IoError {
    /// The file or folder concerned.
    pub path: PathBuf,
    /// What was being done (`cannot write`, `cannot create folder`...).
    pub what: &'static str,
    /// The operating system's error.
    pub source: std::io::Error,
}

impl std::fmt::Display for IoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.path.display(), self.what, self.source)
    }
}

// No `source()`: the message already ends with the system's reason, and
// anyhow's `{:#}` would print it twice.
impl std::error::Error for IoError {}

/// The largest input file read, in MiB, unless `BRTF_MAX_INPUT_MB` says
/// otherwise: far above any real scan or BSDF file, far below a machine's
/// memory.
pub const DEFAULT_MAX_INPUT_MB: u64 = 1024;

/// Opens an input file after checking that it is a regular file (not a
/// device, pipe or folder, which may never end) of at most the input
/// limit ([`DEFAULT_MAX_INPUT_MB`] or `BRTF_MAX_INPUT_MB`); returns it
/// with the limit in bytes. The errors say which limit and how to raise
/// it; the caller adds the path.
pub fn open_input(path: &Path) -> std::io::Result<(std::fs::File, u64)> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(std::io::Error::other(
            "not a regular file (a folder, device or pipe); give a measurement file",
        ));
    }
    let limit = input_limit();
    if meta.len() > limit {
        return Err(too_big());
    }
    Ok((file, limit))
}

/// Reads an input file whole ([`open_input`]'s checks); the read is
/// bounded too, in case the file grows meanwhile.
pub fn read_input(path: &Path) -> std::io::Result<Vec<u8>> {
    let (file, limit) = open_input(path)?;
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut std::io::Read::take(file, limit + 1), &mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_big());
    }
    Ok(bytes)
}

fn input_limit_mb() -> u64 {
    std::env::var("BRTF_MAX_INPUT_MB")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .unwrap_or(DEFAULT_MAX_INPUT_MB)
}

fn input_limit() -> u64 {
    input_limit_mb().saturating_mul(1 << 20)
}

fn too_big() -> std::io::Error {
    std::io::Error::other(format!(
        "larger than brtf reads ({} MiB); set BRTF_MAX_INPUT_MB to raise the limit",
        input_limit_mb()
    ))
}

/// Refuses `path` when it is a symbolic link: brtf writes its own files
/// and folders, never through a link planted in their place (a `plots`
/// link out of a fit folder, a lock file's link elsewhere).
pub fn refuse_symlink(path: &Path) -> Result<(), IoError> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => Err(IoError {
            path: path.to_path_buf(),
            what: "refusing to write through a symbolic link",
            source: std::io::Error::other(
                "brtf writes only real files and folders here; remove the link",
            ),
        }),
        _ => Ok(()),
    }
}

/// Creates `dir` and its parents when missing.
pub fn ensure_folder(dir: &Path) -> Result<(), IoError> {
    std::fs::create_dir_all(dir).map_err(|source| IoError {
        path: dir.to_path_buf(),
        what: "cannot create folder",
        source,
    })
}

/// Writes `bytes` to `path` through a temporary file beside it and a
/// rename. The folder must exist ([`ensure_folder`]). On failure the
/// temporary file is removed and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    write_atomic_parts(path, &[bytes])
}

/// [`write_atomic`] of the concatenation of `parts`, without making it.
pub fn write_atomic_parts(path: &Path, parts: &[&[u8]]) -> Result<(), IoError> {
    let fail = |what: &'static str, at: &Path| {
        let at = at.to_path_buf();
        move |source| IoError {
            path: at,
            what,
            source,
        }
    };
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".brtf-write-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(fail("cannot write", path))?;
    for part in parts {
        tmp.write_all(part).map_err(fail("cannot write", path))?;
    }
    tmp.as_file()
        .sync_all()
        .map_err(fail("cannot write", path))?;
    #[cfg(unix)]
    {
        // tempfile creates 0600; keep a replaced file's mode, else 0644.
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).map_or(0o644, |m| m.permissions().mode());
        std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(mode))
            .map_err(fail("cannot write", path))?;
    }
    tmp.persist(path)
        .map_err(|e| fail("cannot write", path)(e.error))?;
    Ok(())
}

/// Lower-case hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let digest = Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest {
        s.push(HEX[usize::from(b >> 4)] as char);
        s.push(HEX[usize::from(b & 15)] as char);
    }
    s
}

/// Finds an input file recorded (as given on the command line) in a fit
/// folder: as recorded (relative to the current folder), then relative to
/// each of `search`, to the fit folder and each of its ancestors, and
/// finally by its file name inside the fit folder.
pub fn locate_input(recorded: &str, fit_dir: &Path, search: &[PathBuf]) -> Option<PathBuf> {
    let given = Path::new(recorded);
    if given.is_file() {
        return Some(given.to_path_buf());
    }
    let mut candidates = Vec::new();
    if !given.is_absolute() {
        candidates.extend(search.iter().map(|b| b.join(given)));
        if let Ok(dir) = std::fs::canonicalize(fit_dir) {
            candidates.extend(dir.ancestors().map(|a| a.join(given)));
        }
    }
    if let Some(name) = given.file_name() {
        candidates.push(fit_dir.join(name));
    }
    candidates.into_iter().find(|p| p.is_file())
}

/// The current UTC time as RFC 3339 (`2026-11-23T18:42:15Z`), from the
/// system clock, for provenance.
pub fn utc_now_rfc3339() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64);
    rfc3339_of_unix_seconds(secs)
}

/// RFC 3339 UTC text of a Unix time in seconds (civil-from-days in the
/// proleptic Gregorian calendar).
pub fn rfc3339_of_unix_seconds(secs: i64) -> String {
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn unix_times_print_as_rfc3339() {
        assert_eq!(rfc3339_of_unix_seconds(0), "1970-01-01T00:00:00Z");
        assert_eq!(rfc3339_of_unix_seconds(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(
            rfc3339_of_unix_seconds(1_795_459_335),
            "2026-11-23T18:42:15Z"
        );
    }

    use super::*;

    #[test]
    fn sha256_of_known_text() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/out.txt");
        ensure_folder(&dir.path().join("sub")).unwrap();
        write_atomic(&path, b"one").unwrap();
        write_atomic(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(dir.path().join("sub"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out.txt")]);
    }

    #[test]
    fn failed_write_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let blocker = dir.path().join("file");
        std::fs::write(&blocker, b"x").unwrap();
        let err = write_atomic(&blocker.join("inside.txt"), b"y").unwrap_err();
        assert_eq!(err.path, blocker.join("inside.txt"));
        assert_eq!(err.what, "cannot write");
        let err = ensure_folder(&blocker.join("sub")).unwrap_err();
        assert_eq!(err.what, "cannot create folder");
    }

    #[test]
    fn inputs_are_found_from_the_fit_folder() {
        let root = tempfile::tempdir().unwrap();
        let data = root.path().join("data/set");
        std::fs::create_dir_all(&data).unwrap();
        std::fs::write(data.join("a.mpc"), b"x").unwrap();
        let fit = root.path().join("fits/set");
        std::fs::create_dir_all(&fit).unwrap();
        assert_eq!(
            locate_input("data/set/a.mpc", &fit, &[]).map(|p| p.canonicalize().unwrap()),
            Some(data.join("a.mpc").canonicalize().unwrap())
        );
        assert_eq!(locate_input("nowhere/b.mpc", &fit, &[]), None);
        std::fs::write(fit.join("b.mpc"), b"x").unwrap();
        assert_eq!(
            locate_input("nowhere/b.mpc", &fit, &[]),
            Some(fit.join("b.mpc"))
        );
    }
}
