//! Output files go through [`brtf_io::write_atomic`], so a failed run
//! leaves nothing half-written.

use anyhow::Result;
use std::path::Path;

/// Writes `bytes` to `path` atomically (same-folder temporary + rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    Ok(brtf_io::write_atomic(path, bytes)?)
}
