//! Worker threads of a run (`--jobs`).

use crate::WorkflowError;

/// Runs `f` on a pool of `jobs` worker threads, or on rayon's global pool
/// (one thread per core) when `jobs` is `None`. `jobs` is 1 to 4 × the
/// machine's cores: more threads only take turns on the same cores.
pub fn with_jobs<T: Send>(
    jobs: Option<usize>,
    f: impl FnOnce() -> T + Send,
) -> Result<T, WorkflowError> {
    let Some(n) = jobs else {
        return Ok(f());
    };
    let most = 4 * std::thread::available_parallelism().map_or(1, |c| c.get());
    if !(1..=most).contains(&n) {
        return Err(WorkflowError::Usage(format!(
            "--jobs {n}: out of range; allowed: 1 to {most} (4 × the machine's cores)"
        )));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| WorkflowError::Usage(format!("cannot start {n} worker threads: {e}")))?;
    Ok(pool.install(f))
}
