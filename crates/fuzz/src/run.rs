//! The runner: cases on worker threads, each under `catch_unwind`, with a
//! watchdog for hangs, and the figures of a run.
//!
//! Case `i` of seed `S` is generated from its own random stream
//! (`Rng::new(S, i)`), so a case is reproduced alone by its number
//! (`brtf-fuzz --seed S --replay i`), whatever the thread count.

use std::cell::RefCell;
use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Once};
use std::time::{Duration, Instant};

use brtf_model::Rng;

use crate::mutate::{self, Kind, below};
use crate::seeds::{Seed, Seeds, Target};
use crate::targets::{self, Outcome};

/// How to run.
#[derive(Clone, Debug)]
pub struct Config {
    /// Number of cases.
    pub cases: u64,
    /// Run seed.
    pub seed: u64,
    /// Worker threads.
    pub threads: usize,
    /// A case running longer than this is a hang (the issue says 1 s).
    pub hang_limit: Duration,
    /// A case still running after this is stuck for good: the watchdog
    /// saves the case and ends the process (a thread cannot be killed).
    pub abort_after: Duration,
    /// One case in this many uses a whole big file (0: never).
    pub whole_file_every: u64,
    /// Where inputs of panics, hangs and anomalies are saved (`None`: not saved).
    pub findings_dir: Option<PathBuf>,
    /// Print progress to stderr.
    pub progress: bool,
    /// The parsers to run (empty: all).
    pub targets: Vec<Target>,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            cases: 10_000,
            seed: 1,
            threads: std::thread::available_parallelism().map_or(2, usize::from),
            hang_limit: Duration::from_secs(1),
            abort_after: Duration::from_secs(60),
            whole_file_every: 2000,
            findings_dir: None,
            progress: false,
            targets: Vec::new(),
        }
    }
}

/// One generated input.
#[derive(Clone, Debug)]
pub struct Case {
    /// Its number in the run.
    pub index: u64,
    /// The parser.
    pub target: Target,
    /// The name given to the parser.
    pub name: String,
    /// The seed it came from.
    pub origin: String,
    /// The mutations applied, in order.
    pub mutations: Vec<Kind>,
    /// The input.
    pub bytes: Vec<u8>,
}

/// How often each target is picked: measurements 60 %, `.rad` 20 %,
/// `fit.json` 20 %, whatever the number of seed files of each.
fn target_weight(target: Target) -> usize {
    match target {
        Target::Mpc => 3,
        Target::Mountain | Target::Rad | Target::FitJson => 2,
        Target::DetectedGonio | Target::Klems | Target::TensorTree => 1,
    }
}

/// Picks one of `targets` by [`target_weight`].
fn pick_target(targets: &[Target], rng: &mut Rng) -> Target {
    let total: usize = targets.iter().map(|&t| target_weight(t)).sum();
    let mut ticket = below(rng, total.max(1));
    for &target in targets {
        if ticket < target_weight(target) {
            return target;
        }
        ticket -= target_weight(target);
    }
    targets[0]
}

/// Builds case `index` of the run `config` describes.
pub fn make_case(seeds: &Seeds, config: &Config, index: u64) -> Case {
    let mut rng = Rng::new(config.seed, index);
    let targets = if config.targets.is_empty() {
        &Target::ALL[..]
    } else {
        &config.targets[..]
    };
    let target = pick_target(targets, &mut rng);
    let whole_file_every = config.whole_file_every;
    let whole = whole_file_every > 0
        && below(&mut rng, whole_file_every as usize) == 0
        && !seeds.of(target, true).is_empty();
    let pool = seeds.of(target, whole);
    let seed_file: &Seed = pool[below(&mut rng, pool.len())];
    let small = seeds.of(seed_file.target, false);
    let other = small[below(&mut rng, small.len())];
    let mut bytes = seed_file.bytes.clone();
    let mut mutations = Vec::new();
    // One to eight mutations, fewer more often.
    let count = 1 + below(&mut rng, 4) * below(&mut rng, 3);
    for _ in 0..count {
        mutations.push(mutate::mutate(&mut bytes, target, &other.bytes, &mut rng));
    }
    // One case in 16 feeds the bytes to another parser.
    let target = if below(&mut rng, 16) == 0 {
        targets[below(&mut rng, targets.len())]
    } else {
        target
    };
    Case {
        index,
        target,
        name: seed_file.name.clone(),
        origin: seed_file.origin.clone(),
        mutations,
        bytes,
    }
}

/// A panic, hang or anomaly.
#[derive(Clone, Debug)]
pub struct Finding {
    /// The case number.
    pub case: u64,
    /// The parser.
    pub target: Target,
    /// The seed the case came from.
    pub origin: String,
    /// The mutations applied.
    pub mutations: Vec<Kind>,
    /// The panic message and backtrace, or what went wrong.
    pub message: String,
    /// How long the case ran.
    pub elapsed: Duration,
    /// Where the input was saved.
    pub saved_to: Option<PathBuf>,
}

/// Counts for one target.
#[derive(Clone, Debug, Default)]
pub struct TargetStats {
    /// Cases run.
    pub cases: u64,
    /// Inputs the parser accepted.
    pub accepted: u64,
    /// Inputs refused with an error.
    pub rejected: u64,
    /// The longest case.
    pub slowest: Duration,
    /// The largest input, in bytes.
    pub largest_input: usize,
}

/// The figures of a run.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Cases run.
    pub cases: u64,
    /// Per target.
    pub per_target: HashMap<Target, TargetStats>,
    /// Mutations applied, per kind.
    pub per_mutation: HashMap<Kind, u64>,
    /// Cases that panicked.
    pub panics: Vec<Finding>,
    /// Cases whose CPU time passed the hang limit.
    pub hangs: Vec<Finding>,
    /// Cases whose wall time passed the hang limit while their CPU time
    /// stayed below it (the machine was busy with other work).
    pub slow_under_load: Vec<Finding>,
    /// Cases with a wrong result that is not a crash.
    pub anomalies: Vec<Finding>,
    /// The slowest case: (time, case number, origin, target).
    pub slowest: Option<(Duration, u64, String, Target)>,
    /// Peak resident memory of the process (VmHWM), in KiB.
    pub peak_memory_kib: Option<u64>,
    /// Wall time.
    pub elapsed: Duration,
    /// A few error messages per target, as a user would see them.
    pub sample_errors: HashMap<Target, Vec<String>>,
}

thread_local! {
    /// Set on fuzz worker threads: their panics are recorded, not printed.
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
    static IS_WORKER: RefCell<bool> = const { RefCell::new(false) };
}

/// Installs (once) a panic hook that records a worker's panic message,
/// location and backtrace, and leaves other threads' panics to the
/// previous hook (test failures elsewhere still print).
fn install_panic_hook() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IS_WORKER.with(|w| *w.borrow()) {
                let backtrace = std::backtrace::Backtrace::force_capture().to_string();
                let text = format!("{info}\n{}", brtf_frames(&backtrace));
                LAST_PANIC.with(|p| *p.borrow_mut() = Some(text));
            } else {
                previous(info);
            }
        }));
    });
}

/// The frames of a backtrace inside brtf's own crates (not std, not the
/// fuzzer), each with its `at file:line` line: what a bug report needs.
fn brtf_frames(backtrace: &str) -> String {
    let lines: Vec<&str> = backtrace.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let is_frame = line
            .trim_start()
            .split_once(": ")
            .is_some_and(|(n, _)| n.parse::<u32>().is_ok());
        if is_frame && line.contains("brtf_") && !line.contains("brtf_fuzz") {
            out.push(line.trim());
            if let Some(at) = lines
                .get(i + 1)
                .filter(|l| l.trim_start().starts_with("at "))
            {
                out.push(at.trim());
            }
        }
    }
    out.join("\n")
}

/// Reads VmHWM (peak resident set) from `/proc/self/status`, in KiB.
pub fn peak_memory_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Runs one case on this thread and returns its outcome or panic text.
pub fn run_case(case: &Case) -> Result<Outcome, String> {
    install_panic_hook();
    IS_WORKER.with(|w| *w.borrow_mut() = true);
    let result = catch_unwind(AssertUnwindSafe(|| {
        targets::exercise(case.target, &case.name, &case.bytes)
    }));
    IS_WORKER.with(|w| *w.borrow_mut() = false);
    result.map_err(|_| {
        LAST_PANIC
            .with(|p| p.borrow_mut().take())
            .unwrap_or_else(|| "panic without a message".into())
    })
}

/// What a worker is doing, for the watchdog: the case number + 1 (0 when
/// idle) and when it started (ns since the run began).
struct WorkerSlot {
    case_plus_one: AtomicU64,
    started_ns: AtomicU64,
}

/// Maximum sample error messages kept per target.
const SAMPLE_ERRORS: usize = 12;

/// Runs the cases and returns the figures.
pub fn run(seeds: &Seeds, config: &Config) -> Report {
    install_panic_hook();
    let start = Instant::now();
    let next_case = AtomicU64::new(0);
    let report = Mutex::new(Report::default());
    let threads = config.threads.max(1);
    let slots: Arc<Vec<WorkerSlot>> = Arc::new(
        (0..threads)
            .map(|_| WorkerSlot {
                case_plus_one: AtomicU64::new(0),
                started_ns: AtomicU64::new(0),
            })
            .collect(),
    );
    let done = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|scope| {
        scope.spawn(|| watchdog(seeds, config, &slots, start, &done));
        let workers: Vec<_> = (0..threads)
            .map(|w| {
                let slots = Arc::clone(&slots);
                let (next_case, report) = (&next_case, &report);
                scope.spawn(move || {
                    let mut local = Report::default();
                    loop {
                        let index = next_case.fetch_add(1, Ordering::Relaxed);
                        if index >= config.cases {
                            break;
                        }
                        let case = make_case(seeds, config, index);
                        let slot = &slots[w];
                        slot.started_ns
                            .store(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
                        slot.case_plus_one.store(index + 1, Ordering::Release);
                        let began = Instant::now();
                        let cpu_before = thread_cpu_time();
                        let outcome = run_case(&case);
                        let elapsed = began.elapsed();
                        let cpu = thread_cpu_time()
                            .zip(cpu_before)
                            .map(|(after, before)| after.saturating_sub(before));
                        slot.case_plus_one.store(0, Ordering::Release);
                        record(&mut local, &case, outcome, (elapsed, cpu), config);
                        if config.progress && (index + 1) % (config.cases / 20).max(1) == 0 {
                            eprintln!(
                                "brtf-fuzz: {} / {} cases, {:.0} s",
                                index + 1,
                                config.cases,
                                start.elapsed().as_secs_f64()
                            );
                        }
                    }
                    merge(&mut report.lock().unwrap(), local);
                })
            })
            .collect();
        for worker in workers {
            let _ = worker.join();
        }
        done.store(true, Ordering::Release);
    });
    let mut report = report.into_inner().unwrap();
    for list in [
        &mut report.panics,
        &mut report.hangs,
        &mut report.slow_under_load,
        &mut report.anomalies,
    ] {
        list.sort_by_key(|f| f.case);
    }
    report.elapsed = start.elapsed();
    report.peak_memory_kib = peak_memory_kib();
    report
}

/// Ends the process when a case runs past `abort_after` (after saving it),
/// since a stuck thread cannot be stopped from outside.
fn watchdog(
    seeds: &Seeds,
    config: &Config,
    slots: &[WorkerSlot],
    start: Instant,
    done: &std::sync::atomic::AtomicBool,
) {
    while !done.load(Ordering::Acquire) {
        std::thread::sleep(Duration::from_millis(100));
        let now_ns = start.elapsed().as_nanos() as u64;
        for slot in slots {
            let case_plus_one = slot.case_plus_one.load(Ordering::Acquire);
            let started = slot.started_ns.load(Ordering::Relaxed);
            if case_plus_one == 0
                || now_ns.saturating_sub(started) < config.abort_after.as_nanos() as u64
            {
                continue;
            }
            let case = make_case(seeds, config, case_plus_one - 1);
            let saved = save(config, "stuck", &case);
            eprintln!(
                "brtf-fuzz: HANG: case {} ({}, {}, mutations {:?}) still runs after {} s; input {}; \
                 replay with --seed {} --replay {}",
                case.index,
                case.target.label(),
                case.origin,
                case.mutations,
                config.abort_after.as_secs(),
                saved.map_or_else(|| "not saved".into(), |p| p.display().to_string()),
                config.seed,
                case.index
            );
            std::process::exit(3);
        }
    }
}

fn record(
    report: &mut Report,
    case: &Case,
    outcome: Result<Outcome, String>,
    (elapsed, cpu): (Duration, Option<Duration>),
    config: &Config,
) {
    report.cases += 1;
    for kind in &case.mutations {
        *report.per_mutation.entry(*kind).or_default() += 1;
    }
    let stats = report.per_target.entry(case.target).or_default();
    stats.cases += 1;
    stats.slowest = stats.slowest.max(elapsed);
    stats.largest_input = stats.largest_input.max(case.bytes.len());
    if report.slowest.as_ref().is_none_or(|s| elapsed > s.0) {
        report.slowest = Some((elapsed, case.index, case.origin.clone(), case.target));
    }
    let finding = |kind: &str, message: String| Finding {
        case: case.index,
        target: case.target,
        origin: case.origin.clone(),
        mutations: case.mutations.clone(),
        message,
        elapsed,
        saved_to: save(config, kind, case),
    };
    match outcome {
        Ok(Outcome::Accepted) => stats.accepted += 1,
        Ok(Outcome::Rejected(message)) => {
            stats.rejected += 1;
            let samples = report.sample_errors.entry(case.target).or_default();
            if samples.len() < SAMPLE_ERRORS && case.bytes.len() < 1 << 16 {
                samples.push(message);
            }
        }
        Ok(Outcome::Anomaly { class, detail }) => {
            stats.rejected += 1;
            report
                .anomalies
                .push(finding("anomaly", format!("{class}\n{detail}")));
        }
        Err(panic) => report.panics.push(finding("panic", panic)),
    }
    // A hang is judged on the case's own CPU time: on a 2-core machine
    // shared with compilers, wall time alone would blame the parser for
    // waiting its turn. Wall-time overruns are counted apart.
    if elapsed > config.hang_limit {
        let cpu_text =
            cpu.map_or_else(|| "unknown".into(), |c| format!("{:.2} s", c.as_secs_f64()));
        let detail = format!("ran {:.2} s (CPU time {cpu_text})", elapsed.as_secs_f64());
        if cpu.is_none_or(|c| c > config.hang_limit) {
            let message = format!("CPU time over the limit\n{detail}");
            report.hangs.push(finding("hang", message));
        } else {
            let message = format!("wall time over the limit, CPU time under it\n{detail}");
            report.slow_under_load.push(finding("slow", message));
        }
    }
}

/// CPU time this thread has used so far (`/proc/thread-self/schedstat`,
/// nanoseconds on the CPU), or `None` where that file does not exist.
pub fn thread_cpu_time() -> Option<Duration> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = text.split_ascii_whitespace().next()?.parse().ok()?;
    Some(Duration::from_nanos(ns))
}

fn merge(into: &mut Report, from: Report) {
    into.cases += from.cases;
    for (target, s) in from.per_target {
        let t = into.per_target.entry(target).or_default();
        t.cases += s.cases;
        t.accepted += s.accepted;
        t.rejected += s.rejected;
        t.slowest = t.slowest.max(s.slowest);
        t.largest_input = t.largest_input.max(s.largest_input);
    }
    for (kind, n) in from.per_mutation {
        *into.per_mutation.entry(kind).or_default() += n;
    }
    into.panics.extend(from.panics);
    into.hangs.extend(from.hangs);
    into.slow_under_load.extend(from.slow_under_load);
    into.anomalies.extend(from.anomalies);
    if let Some(s) = from.slowest
        && into.slowest.as_ref().is_none_or(|i| s.0 > i.0)
    {
        into.slowest = Some(s);
    }
    for (target, messages) in from.sample_errors {
        let list = into.sample_errors.entry(target).or_default();
        for m in messages {
            if list.len() < SAMPLE_ERRORS {
                list.push(m);
            }
        }
    }
}

/// Saves a case's input as `DIR/KIND-CASE-NAME`; only the first few of
/// each kind, so a systematic bug does not fill the disk.
fn save(config: &Config, kind: &str, case: &Case) -> Option<PathBuf> {
    const MAX_SAVED_PER_KIND: usize = 50;
    if kind == "slow" {
        return None; // not a bug; big inputs, many of them
    }
    let dir = config.findings_dir.as_ref()?;
    std::fs::create_dir_all(dir).ok()?;
    let prefix = format!("{kind}-");
    let saved = std::fs::read_dir(dir)
        .ok()?
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
        .count();
    if saved >= MAX_SAVED_PER_KIND {
        return None;
    }
    let safe_name: String = case
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let path = dir.join(format!("{kind}-{}-{safe_name}", case.index));
    std::fs::write(&path, &case.bytes).ok()?;
    Some(path)
}
