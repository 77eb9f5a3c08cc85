//! Ctrl-C and `kill`: a command-line run removes what it was writing.
//!
//! Each [`crate::FolderUpdate`] registers its staging folder and lock file
//! while it runs. [`clean_up_on_signals`] (called by the `brtf` binary,
//! not by the Python package, whose interpreter owns SIGINT) removes them
//! on SIGINT or SIGTERM and exits with 130 or 143, as a shell reports a
//! process killed by those signals.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The paths a signal removes: staging folders and lock files in use.
static IN_PROGRESS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Registers `path` for removal on a signal.
pub(crate) fn register(path: &Path) {
    if let Ok(mut paths) = IN_PROGRESS.lock() {
        paths.push(path.to_path_buf());
    }
}

/// Forgets `path` (done with, or removed).
pub(crate) fn unregister(path: &Path) {
    if let Ok(mut paths) = IN_PROGRESS.lock() {
        paths.retain(|p| p != path);
    }
}

/// Starts a thread that, on SIGINT or SIGTERM, removes the registered
/// staging folders and lock files and exits with 128 + the signal.
pub fn clean_up_on_signals() -> std::io::Result<()> {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    // Held until the exit: no folder update starts or ends meanwhile.
                    let paths = IN_PROGRESS.lock();
                    for path in paths.iter().flat_map(|p| p.iter()) {
                        if path.is_dir() {
                            let _ = std::fs::remove_dir_all(path);
                        } else {
                            let _ = std::fs::remove_file(path);
                        }
                    }
                    std::process::exit(128 + signal);
                }
            })?;
    }
    Ok(())
}
