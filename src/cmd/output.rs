//! Output files go through [`brtf_io::write_atomic`], so a failed run
//! leaves nothing half-written.

use anyhow::Result;
use std::path::Path;

/// Writes `bytes` to `path` atomically (same-folder temporary + rename),
/// creating its folder when missing.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(folder) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        brtf_io::ensure_folder(folder)?;
    }
    Ok(brtf_io::write_atomic(path, bytes)?)
}
