//! Output folders committed as a whole.
//!
//! A run writes everything into a staging folder beside its target
//! (`.NAME.brtf-stage-*`) and then swaps it in with one rename, so that a
//! reader sees the old folder or the new one, never a mix. A lock file
//! beside the target (`.NAME.brtf-lock`, an advisory `flock`) keeps two
//! runs from writing the same folder. Whatever a killed run left (staging
//! folders, the old folder of an interrupted swap) is removed by the next
//! run that takes the lock.

use crate::IoError;
use std::fs::File;
use std::path::{Path, PathBuf};

/// The name pieces of brtf's hidden files beside a target folder.
const STAGE: &str = ".brtf-stage-";
const OLD: &str = ".brtf-old-";
const LOCK: &str = ".brtf-lock";

/// A rewrite of an output folder in progress. Dropping it without
/// [`FolderUpdate::commit`] removes the staging folder and leaves the
/// target untouched.
#[derive(Debug)]
pub struct FolderUpdate {
    target: PathBuf,
    staging: PathBuf,
    lock: FolderLock,
    committed: bool,
    /// Written in place: `staging` is the target itself.
    in_place: bool,
}

impl FolderUpdate {
    /// Locks `target` and starts an empty staging folder: the committed
    /// folder will hold exactly what is written into [`FolderUpdate::path`].
    pub fn fresh(target: &Path) -> Result<FolderUpdate, IoError> {
        FolderUpdate::start(target, false)
    }

    /// Locks `target` and starts a staging folder that holds the target's
    /// present files (hard links, else copies), for commands that replace
    /// only some of a folder's files. A folder that exists but is not a fit
    /// folder (no `fit.json`) may hold anything of the user's: it is not
    /// taken over but written in place, file by file (each file atomic).
    pub fn amend(target: &Path) -> Result<FolderUpdate, IoError> {
        FolderUpdate::start(target, true)
    }

    fn start(target: &Path, keep_content: bool) -> Result<FolderUpdate, IoError> {
        let (parent, name, target) = split_target(target)?;
        crate::ensure_folder(&parent)?;
        if target.exists() && !target.is_dir() {
            return Err(IoError {
                path: target,
                what: "cannot write the output folder",
                source: std::io::Error::other("a file of that name exists"),
            });
        }
        let lock = FolderLock::take(&parent.join(format!(".{name}{LOCK}")), &target)?;
        remove_leftovers(&parent, &name, &target)?;
        if keep_content && target.is_dir() && !target.join("fit.json").exists() {
            return Ok(FolderUpdate {
                staging: target.clone(),
                target,
                lock,
                committed: false,
                in_place: true,
            });
        }
        let staging = tempfile::Builder::new()
            .prefix(&format!(".{name}{STAGE}"))
            .tempdir_in(&parent)
            .map_err(fail("cannot create a staging folder in", &parent))?
            .keep();
        crate::interrupt::register(&staging);
        let update = FolderUpdate {
            target,
            staging,
            lock,
            committed: false,
            in_place: false,
        };
        if keep_content && update.target.is_dir() {
            link_tree(&update.target, &update.staging)?;
        }
        Ok(update)
    }

    /// The staging folder: write every output here.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// The folder that [`FolderUpdate::commit`] replaces.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Syncs the staging folder and swaps it in for the target, then
    /// removes the old folder and the lock.
    pub fn commit(mut self) -> Result<(), IoError> {
        if self.in_place {
            self.committed = true;
            self.lock.release();
            return Ok(());
        }
        // The files are synced by write_atomic; the folder entries too.
        sync_dir(&self.staging);
        let parent = self.target.parent().unwrap_or(Path::new("."));
        if self.target.exists() {
            swap(&self.staging, &self.target)?;
            // The staging path now holds the old folder.
            remove_tree(&self.staging);
        } else {
            std::fs::rename(&self.staging, &self.target)
                .map_err(fail("cannot move the new folder into", &self.target))?;
        }
        sync_dir(parent);
        crate::interrupt::unregister(&self.staging);
        self.committed = true;
        self.lock.release();
        Ok(())
    }
}

impl Drop for FolderUpdate {
    fn drop(&mut self) {
        if !self.committed && !self.in_place {
            remove_tree(&self.staging);
            crate::interrupt::unregister(&self.staging);
        }
        if !self.committed {
            self.lock.release();
        }
    }
}

/// Refuses to let a run replace `target` as a whole when that would lose
/// work: always when an input file lies inside it; without `force`, when
/// it is not a brtf folder (no `fit.json`) but holds files, or when its
/// `fit.json` names an input that is not among `inputs` (by content or by
/// file name): the fit of another sample.
pub fn check_replaceable(target: &Path, inputs: &[PathBuf], force: bool) -> Result<(), IoError> {
    let refuse = |why: String| IoError {
        path: target.to_path_buf(),
        what: "cannot replace the output folder",
        source: std::io::Error::other(why),
    };
    let Ok(folder) = std::fs::canonicalize(target) else {
        return Ok(());
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i.starts_with(&folder)) {
            return Err(refuse(format!(
                "it holds the input {}, and a run replaces the whole folder; choose another output folder",
                input.display()
            )));
        }
    }
    let is_empty = std::fs::read_dir(&folder).is_ok_and(|mut d| d.next().is_none());
    if force || is_empty {
        return Ok(());
    }
    let fit_json = folder.join("fit.json");
    let Ok(text) = std::fs::read_to_string(&fit_json) else {
        return Err(refuse(
            "it is not a brtf fit folder (no fit.json); --force replaces it".into(),
        ));
    };
    let recorded = recorded_inputs(&text);
    let digests: Vec<String> = inputs
        .iter()
        .filter_map(|i| std::fs::read(i).ok())
        .map(|b| crate::sha256_hex(&b))
        .collect();
    let file_name = |p: &str| Path::new(p).file_name().map(|n| n.to_os_string());
    let mut others: Vec<&str> = recorded
        .iter()
        .filter(|(path, sha)| {
            !digests.contains(sha)
                && !inputs
                    .iter()
                    .any(|i| i.file_name() == file_name(path).as_deref())
        })
        .map(|(path, _)| path.as_str())
        .collect();
    // A Klems fit records its file once per incident patch: name it once.
    others.sort_unstable();
    others.dedup();
    match (recorded.is_empty(), others.as_slice()) {
        (true, _) => Err(refuse(format!(
            "{} names no input files; --force replaces it",
            fit_json.display()
        ))),
        (false, []) => Ok(()),
        (false, others) => {
            let listed = match others {
                [a, b, c, d, rest @ ..] if !rest.is_empty() => {
                    format!("{a}, {b}, {c}, {d} and {} more", rest.len())
                }
                all => all.join(", "),
            };
            Err(refuse(format!(
                "it holds the fit of other measurements ({listed}); choose another output folder, or --force to replace it"
            )))
        }
    }
}

/// Refuses to write `output` when it is one of `inputs` (after symlinks;
/// `render gonio --like X --out X`, or a file of a fit folder the command
/// reads, [`fit_folder_inputs`]), even with `force`; and, unless `force`,
/// with a `marker`, when it exists and its first 4 KiB do not hold
/// `marker`: a file this command did not write, such as a real
/// measurement under `brtf synth`'s file name.
pub fn check_overwrite(
    output: &Path,
    inputs: &[&Path],
    marker: Option<&str>,
    force: bool,
) -> Result<(), IoError> {
    let refuse = |why: String| IoError {
        path: output.to_path_buf(),
        what: "refusing to overwrite",
        source: std::io::Error::other(why),
    };
    let Ok(existing) = std::fs::canonicalize(output) else {
        return Ok(());
    };
    if inputs
        .iter()
        .any(|i| std::fs::canonicalize(i).is_ok_and(|i| i == existing))
    {
        return Err(refuse(
            "this run reads it (an input, or a file of the fit folder it reads); --force does not change that".into(),
        ));
    }
    if force {
        return Ok(());
    }
    if let Some(marker) = marker {
        let mut head = Vec::new();
        let file = File::open(&existing).map_err(fail("cannot read", output))?;
        std::io::Read::read_to_end(&mut std::io::Read::take(file, 4096), &mut head)
            .map_err(fail("cannot read", output))?;
        if !String::from_utf8_lossy(&head).contains(marker) {
            return Err(refuse(format!(
                "it exists and this command did not write it (its header lacks `{marker}`); --force overwrites it"
            )));
        }
    }
    Ok(())
}

/// The files of the fit folder `dir` that a command reading it must never
/// replace: `fit.json`, every output its manifest lists as written by a
/// step other than `step` (`check` writes `check.csv`, for one), and the
/// measurement files it was fitted to, where [`crate::locate_input`] finds
/// them from `dir` and `search`.
pub fn fit_folder_inputs(dir: &Path, step: &str, search: &[PathBuf]) -> Vec<PathBuf> {
    let fit_json = dir.join("fit.json");
    let text = std::fs::read_to_string(&fit_json).unwrap_or_default();
    let value: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
    let mut files = vec![fit_json];
    for output in value["outputs"].as_array().into_iter().flatten() {
        if let Some(path) = output["path"].as_str()
            && output["by"].as_str() != Some(step)
        {
            files.push(dir.join(path));
        }
    }
    for (recorded, _) in recorded_inputs(&text) {
        files.extend(crate::locate_input(&recorded, dir, search));
    }
    files
}

/// `provenance.inputs[]` (`path`, `sha256`) of a `fit.json` of any schema.
fn recorded_inputs(fit_json: &str) -> Vec<(String, String)> {
    let value: serde_json::Value = serde_json::from_str(fit_json).unwrap_or_default();
    let inputs = value["provenance"]["inputs"].as_array().cloned();
    inputs
        .unwrap_or_default()
        .iter()
        .filter_map(|i| {
            Some((
                i["path"].as_str()?.to_owned(),
                i["sha256"].as_str()?.to_owned(),
            ))
        })
        .collect()
}

/// The absolute parent and the file name of `target` (`fits/x` → the
/// current folder's `fits`, `x`).
/// The folder `target` as (its parent, its name as text for the hidden
/// files beside it, the folder itself).
fn split_target(target: &Path) -> Result<(PathBuf, String, PathBuf), IoError> {
    let absolute = std::path::absolute(target).map_err(fail("cannot resolve", target))?;
    // `x/.` and `x/..` have no plain last name; resolve them through the disk.
    let resolved = match absolute.file_name() {
        Some(_) => absolute,
        None => std::fs::canonicalize(&absolute).map_err(fail("cannot resolve", target))?,
    };
    match (resolved.parent(), resolved.file_name()) {
        (Some(parent), Some(name)) => Ok((
            parent.to_path_buf(),
            name.to_string_lossy().into(),
            resolved.clone(),
        )),
        _ => Err(IoError {
            path: target.to_path_buf(),
            what: "cannot use as an output folder",
            source: std::io::Error::other("it is the root folder"),
        }),
    }
}

/// An exclusive advisory lock on a file beside the target.
#[derive(Debug)]
struct FolderLock {
    path: PathBuf,
    file: Option<File>,
}

impl FolderLock {
    /// Takes the lock or fails at once, naming `target`, when another run
    /// holds it.
    fn take(path: &Path, target: &Path) -> Result<FolderLock, IoError> {
        crate::refuse_symlink(path)?;
        let mut options = File::options();
        options.create(true).truncate(false).write(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            // A link planted after the check above is not followed either.
            options.custom_flags(rustix::fs::OFlags::NOFOLLOW.bits() as i32);
        }
        loop {
            let file = options
                .open(path)
                .map_err(fail("cannot create the lock file", path))?;
            if !try_lock(&file).map_err(fail("cannot lock", path))? {
                return Err(IoError {
                    path: target.to_path_buf(),
                    what: "cannot write the output folder",
                    source: std::io::Error::other(
                        "another brtf run is writing it; wait for that run to finish \
                         or choose another output folder",
                    ),
                });
            }
            // A run that finished between our open and our lock removed the
            // file we locked; lock the file now at the path instead.
            if same_file(&file, path) {
                crate::interrupt::register(path);
                return Ok(FolderLock {
                    path: path.to_path_buf(),
                    file: Some(file),
                });
            }
        }
    }

    /// Removes the lock file, then unlocks (closing the file).
    fn release(&mut self) {
        if let Some(file) = self.file.take() {
            let _ = std::fs::remove_file(&self.path);
            crate::interrupt::unregister(&self.path);
            drop(file);
        }
    }
}

#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use rustix::fs::{FlockOperation, flock};
    match flock(file, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(true),
        Err(e) if e == rustix::io::Errno::WOULDBLOCK => Ok(false),
        Err(e) => Err(e.into()),
    }
}

#[cfg(not(unix))]
fn try_lock(_file: &File) -> std::io::Result<bool> {
    // No advisory locks here: runs are not serialised.
    Ok(true)
}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, _path: &Path) -> bool {
    true
}

/// Swaps two folders in one step where the system can
/// (`renameat2(RENAME_EXCHANGE)`), else with two renames (a reader may then
/// briefly find no folder; [`remove_leftovers`] undoes a half-done swap).
fn swap(staging: &Path, target: &Path) -> Result<(), IoError> {
    #[cfg(any(target_os = "linux", target_os = "android"))]
    {
        use rustix::fs::{CWD, RenameFlags, renameat_with};
        if renameat_with(CWD, staging, CWD, target, RenameFlags::EXCHANGE).is_ok() {
            return Ok(());
        }
    }
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    let parent = target.parent().unwrap_or(Path::new("."));
    let old = parent.join(format!(".{name}{OLD}{}", std::process::id()));
    std::fs::rename(target, &old).map_err(fail("cannot move aside", target))?;
    if let Err(e) = std::fs::rename(staging, target) {
        let _ = std::fs::rename(&old, target);
        return Err(fail("cannot move the new folder into", target)(e));
    }
    // Keep the promise of `commit`: the staging path holds the old folder.
    std::fs::rename(&old, staging).map_err(fail("cannot move", &old))
}

/// Removes what dead runs left beside `target` (the caller holds the
/// lock, so no live run owns them). An old folder left by a swap that
/// stopped half-way is moved back when the target is missing.
fn remove_leftovers(parent: &Path, name: &str, target: &Path) -> Result<(), IoError> {
    for path in leftovers(parent, name) {
        let file_name = path.file_name().unwrap_or_default().to_string_lossy();
        let is_old = file_name.starts_with(&format!(".{name}{OLD}"));
        if is_old && !target.exists() {
            std::fs::rename(&path, target).map_err(fail("cannot restore", target))?;
        } else {
            remove_tree(&path);
        }
    }
    Ok(())
}

/// brtf's staging and old folders beside the target `parent/name`.
pub fn leftovers(parent: &Path, name: &str) -> Vec<PathBuf> {
    let prefixes = [format!(".{name}{STAGE}"), format!(".{name}{OLD}")];
    let Ok(entries) = std::fs::read_dir(parent) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .filter(|e| {
            let n = e.file_name();
            let n = n.to_string_lossy();
            prefixes.iter().any(|p| n.starts_with(p.as_str()))
        })
        .map(|e| e.path())
        .collect();
    found.sort();
    found
}

/// Mirrors the tree `from` into the empty folder `to` with hard links
/// (copies where links fail), skipping temporary files of interrupted
/// writes.
fn link_tree(from: &Path, to: &Path) -> Result<(), IoError> {
    let entries = std::fs::read_dir(from).map_err(fail("cannot read", from))?;
    for entry in entries {
        let entry = entry.map_err(fail("cannot read", from))?;
        let (source, dest) = (entry.path(), to.join(entry.file_name()));
        if is_temporary_name(&entry.file_name().to_string_lossy()) {
            continue;
        }
        let kind = entry.file_type().map_err(fail("cannot read", &source))?;
        if kind.is_symlink() {
            // A link would let this run write outside the folder.
            crate::refuse_symlink(&source)?;
        }
        if kind.is_dir() {
            std::fs::create_dir(&dest).map_err(fail("cannot create folder", &dest))?;
            link_tree(&source, &dest)?;
        } else if std::fs::hard_link(&source, &dest).is_err() {
            std::fs::copy(&source, &dest).map_err(fail("cannot copy", &source))?;
        }
    }
    Ok(())
}

/// A temporary file of [`crate::write_atomic`] (left by a killed run).
fn is_temporary_name(name: &str) -> bool {
    name.starts_with(".brtf-write-") && name.ends_with(".tmp")
}

fn remove_tree(path: &Path) {
    let _ = std::fs::remove_dir_all(path);
}

/// Makes a folder's entries durable (best effort: not every system can
/// sync a folder).
fn sync_dir(dir: &Path) {
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

fn fail(what: &'static str, at: &Path) -> impl FnOnce(std::io::Error) -> IoError {
    let path = at.to_path_buf();
    move |source| IoError { path, what, source }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    }

    #[test]
    fn fresh_update_replaces_the_whole_folder() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("fit");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("stale.rad"), b"old").unwrap();
        let update = FolderUpdate::fresh(&target).unwrap();
        crate::write_atomic(&update.path().join("new.rad"), b"new").unwrap();
        assert_eq!(names(&target), ["stale.rad"], "untouched until commit");
        update.commit().unwrap();
        assert_eq!(names(&target), ["new.rad"]);
        assert_eq!(names(root.path()), ["fit"], "no staging, old or lock left");
    }

    #[test]
    fn amend_keeps_other_files_and_dropping_changes_nothing() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("fit");
        std::fs::create_dir_all(target.join("plots")).unwrap();
        std::fs::write(target.join("fit.json"), b"{}").unwrap();
        std::fs::write(target.join("plots/a.svg"), b"a").unwrap();
        std::fs::write(target.join(".brtf-write-x.tmp"), b"").unwrap();
        let update = FolderUpdate::amend(&target).unwrap();
        crate::write_atomic(&update.path().join("plots/a.svg"), b"b").unwrap();
        drop(update);
        assert_eq!(std::fs::read(target.join("plots/a.svg")).unwrap(), b"a");
        assert_eq!(names(root.path()), ["fit"]);
        let update = FolderUpdate::amend(&target).unwrap();
        crate::write_atomic(&update.path().join("plots/a.svg"), b"b").unwrap();
        update.commit().unwrap();
        assert_eq!(names(&target), ["fit.json", "plots"]);
        assert_eq!(std::fs::read(target.join("plots/a.svg")).unwrap(), b"b");
    }

    #[test]
    fn a_second_run_is_refused_while_the_first_holds_the_lock() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("fit");
        let first = FolderUpdate::fresh(&target).unwrap();
        let err = FolderUpdate::fresh(&target).unwrap_err();
        assert!(err.to_string().contains("another brtf run"), "{err}");
        drop(first);
        FolderUpdate::fresh(&target).unwrap().commit().unwrap();
        assert_eq!(names(root.path()), ["fit"]);
    }

    #[test]
    fn leftovers_of_dead_runs_are_removed_and_a_half_swap_undone() {
        let root = tempfile::tempdir().unwrap();
        std::fs::create_dir(root.path().join(".fit.brtf-stage-dead")).unwrap();
        std::fs::create_dir(root.path().join(".fit.brtf-old-1")).unwrap();
        std::fs::write(root.path().join(".fit.brtf-old-1/fit.json"), b"{}").unwrap();
        std::fs::write(root.path().join(".fit.brtf-lock"), b"").unwrap();
        let update = FolderUpdate::amend(&root.path().join("fit")).unwrap();
        assert_eq!(
            names(update.path()),
            ["fit.json"],
            "the old folder restored"
        );
        update.commit().unwrap();
        assert_eq!(names(root.path()), ["fit"]);
    }

    #[test]
    fn a_folder_that_is_not_a_fit_folder_is_written_in_place() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("scene");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("mine.txt"), b"x").unwrap();
        let update = FolderUpdate::amend(&target).unwrap();
        assert_eq!(update.path(), target);
        crate::write_atomic(&update.path().join("a.rad"), b"a").unwrap();
        update.commit().unwrap();
        assert_eq!(names(&target), ["a.rad", "mine.txt"]);
        assert_eq!(names(root.path()), ["scene"]);
    }

    #[test]
    fn only_a_fit_of_the_same_inputs_is_replaced_without_force() {
        let root = tempfile::tempdir().unwrap();
        let (a, b) = (
            root.path().join("a:+0+0.mpc"),
            root.path().join("b:+0+0.mpc"),
        );
        std::fs::write(&a, b"a").unwrap();
        std::fs::write(&b, b"b").unwrap();
        let target = root.path().join("fit");
        check_replaceable(&target, std::slice::from_ref(&a), false).unwrap();
        std::fs::create_dir(&target).unwrap();
        check_replaceable(&target, std::slice::from_ref(&a), false).unwrap();
        std::fs::write(target.join("notes.txt"), b"mine").unwrap();
        let err = check_replaceable(&target, std::slice::from_ref(&a), false).unwrap_err();
        assert!(err.to_string().contains("not a brtf fit folder"), "{err}");
        check_replaceable(&target, std::slice::from_ref(&a), true).unwrap();
        let fit = format!(
            r#"{{"provenance": {{"inputs": [{{"path": "x/a:+0+0.mpc", "sha256": "{}"}}]}}}}"#,
            crate::sha256_hex(b"old a")
        );
        std::fs::write(target.join("fit.json"), fit).unwrap();
        check_replaceable(&target, &[a.clone(), b.clone()], false).unwrap();
        let err = check_replaceable(&target, std::slice::from_ref(&b), false).unwrap_err();
        assert!(
            err.to_string()
                .contains("other measurements (x/a:+0+0.mpc)"),
            "{err}"
        );
        check_replaceable(&target, &[b], true).unwrap();
        let inside = target.join("c.mpc");
        std::fs::write(&inside, b"c").unwrap();
        let err = check_replaceable(&target, &[inside], true).unwrap_err();
        assert!(err.to_string().contains("holds the input"), "{err}");
    }

    /// A Klems fit records its one file once per incident patch; the
    /// refusal names each file once, and at most four of many.
    #[test]
    fn other_measurements_are_named_once_and_few() {
        let root = tempfile::tempdir().unwrap();
        let mine = root.path().join("mine.xml");
        std::fs::write(&mine, b"mine").unwrap();
        let target = root.path().join("fit");
        std::fs::create_dir(&target).unwrap();
        let patches: Vec<String> = (0..145)
            .map(|_| format!(r#"{{"path": "shade.xml", "sha256": "{}"}}"#, "0".repeat(64)))
            .collect();
        let fit = format!(
            r#"{{"provenance": {{"inputs": [{}]}}}}"#,
            patches.join(", ")
        );
        std::fs::write(target.join("fit.json"), fit).unwrap();
        let err = check_replaceable(&target, std::slice::from_ref(&mine), false).unwrap_err();
        let text = err.to_string();
        assert_eq!(text.matches("shade.xml").count(), 1, "{text}");
        let many: Vec<String> = (0..7)
            .map(|k| format!(r#"{{"path": "s{k}.mpc", "sha256": "{}"}}"#, "0".repeat(64)))
            .collect();
        let fit = format!(r#"{{"provenance": {{"inputs": [{}]}}}}"#, many.join(", "));
        std::fs::write(target.join("fit.json"), fit).unwrap();
        let err = check_replaceable(&target, std::slice::from_ref(&mine), false).unwrap_err();
        assert!(err.to_string().contains("s3.mpc and 3 more"), "{err}");
    }

    #[test]
    fn inputs_are_never_overwritten_and_foreign_files_only_with_force() {
        let root = tempfile::tempdir().unwrap();
        let scan = root.path().join("scan.mpc");
        std::fs::write(&scan, b"#real measurement").unwrap();
        for force in [false, true] {
            let err = check_overwrite(&scan, &[&scan], None, force).unwrap_err();
            assert!(err.to_string().contains("this run reads it"), "{err}");
        }
        let err = check_overwrite(&scan, &[], Some("brtf synth"), false).unwrap_err();
        assert!(err.to_string().contains("did not write it"), "{err}");
        check_overwrite(&scan, &[], Some("brtf synth"), true).unwrap();
        std::fs::write(&scan, b"#generated by brtf 0.1.0 synth").unwrap();
        check_overwrite(&scan, &[], Some("brtf 0.1.0 synth"), false).unwrap();
        check_overwrite(&root.path().join("new.mpc"), &[&scan], None, false).unwrap();
    }

    #[test]
    fn a_file_in_the_way_is_an_error() {
        let root = tempfile::tempdir().unwrap();
        std::fs::write(root.path().join("fit"), b"x").unwrap();
        let err = FolderUpdate::fresh(&root.path().join("fit")).unwrap_err();
        assert!(
            err.to_string().contains("a file of that name exists"),
            "{err}"
        );
    }
}
