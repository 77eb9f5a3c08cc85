//! Where results go. Files are written through [`brtf_io::write_atomic`]
//! (a failed run leaves nothing half-written), fit folders through
//! brtf-workflow, and text through [`Stdout`], whose errors say that
//! standard output failed; `main` exits quietly on a closed pipe.

use anyhow::Result;
use std::io::Write;

/// Standard output whose errors name it and keep their kind (so that
/// [`is_broken_pipe`] can tell a reader that left from a failure).
pub(crate) struct Stdout(std::io::StdoutLock<'static>);

/// The locked standard output.
pub(crate) fn stdout() -> Stdout {
    Stdout(std::io::stdout().lock())
}

fn named(e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("cannot write to standard output: {e}"))
}

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf).map_err(named)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush().map_err(named)
    }
}

/// Prints `text` to standard output and flushes it.
pub(crate) fn print(text: &str) -> Result<()> {
    let mut out = stdout();
    out.write_all(text.as_bytes())?;
    Ok(out.flush()?)
}

/// Whether `err` comes from writing into a pipe whose reader has gone
/// (`brtf … | head -1`).
pub(crate) fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
            || cause
                .downcast_ref::<csv::Error>()
                .is_some_and(|e| matches!(e.kind(), csv::ErrorKind::Io(io) if io.kind() == std::io::ErrorKind::BrokenPipe))
    })
}
