//! `gnomon-fuzz`: runs the fuzz targets for a while and reports executions, outcomes
//! and crashes. Exits with 1 if any input panicked or took more memory than the cap
//! (each saved under `--crashes`).
//!
//! ```sh
//! cargo run --release -p gnomon-fuzz -- --seconds 60            # every target at once, 60 s each (CI)
//! cargo run --release -p gnomon-fuzz -- gltf --seconds 3600     # one target for an hour
//! ```
//!
//! Each target runs in a worker process under a memory cap (`--memory-cap-mb`, 1 GiB
//! by default): an allocation that would take the process past it fails, which
//! aborts the worker as a real out-of-memory would abort Gnomon. The supervisor (this
//! process without `--worker`) finds the input that was running in the file the
//! worker keeps it in, saves it as a crash, and starts a new worker for the rest of
//! the target's time. So a small file that makes Gnomon allocate gigabytes is found
//! as a crash, not lost with the process.
//!
//! Each input also has a time limit (`--input-seconds`, 10 by default): the
//! supervisor watches the file the worker writes each input to, and a worker that
//! keeps one input longer is killed and its input saved as a timeout. So a small
//! file that makes a build step slow is a finding too, not a long run.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use clap::Parser;
use gnomon_fuzz::{CurrentInput, Report, Target, files_under};

/// The system allocator, refusing what would take the live heap past `CAP` bytes (0:
/// no cap). Only a worker sets the cap.
struct Capped;

static CAP: AtomicUsize = AtomicUsize::new(0);
static LIVE: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call goes to `System` unchanged, or returns null as a failed
// allocation may; `LIVE` counts what `System` holds for us.
unsafe impl GlobalAlloc for Capped {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let cap = CAP.load(Ordering::Relaxed);
        let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        if cap != 0 && live > cap {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's layout, as `GlobalAlloc::alloc` requires.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Capped = Capped;

/// Fuzz Gnomon's inputs (no GPU needed).
#[derive(Parser)]
#[command(name = "gnomon-fuzz")]
struct Args {
    /// Targets to run: scene-file, gltf, flags [default: all three].
    targets: Vec<String>,
    /// Seconds to run each target.
    #[arg(long, default_value_t = 60)]
    seconds: u64,
    /// How many targets run at once, each in its own worker process [default: all
    /// of them]. Three targets for 60 s take 60 s of wall time, not 180; on fewer
    /// cores than jobs, each worker gets its share of them.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    jobs: Option<u64>,
    /// The mutator's seed: a run repeats from it.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// More seed files or folders, for every target [default: the examples, the
    /// broken glTF test files, the fuzzer's own seeds, and
    /// ../shared/scenes/assimp-gltf2 when present].
    #[arg(long = "seeds", value_name = "PATH")]
    seeds: Vec<PathBuf>,
    /// Where inputs that panic or exceed the memory cap are written.
    #[arg(long, default_value = "fuzz-crashes")]
    crashes: PathBuf,
    /// The memory a target's process may hold, in MiB: an allocation past it is a
    /// crash (Gnomon must refuse such an input before allocating).
    #[arg(long, default_value_t = 1024)]
    memory_cap_mb: usize,
    /// The seconds one input may take: a worker still on one input after this is
    /// killed and the input saved as a timeout.
    #[arg(long, default_value_t = 10)]
    input_seconds: u64,
    /// Run one target in this process and write its report to this file (what the
    /// supervisor starts; not for use by hand).
    #[arg(long, hide = true, value_name = "REPORT")]
    worker: Option<PathBuf>,
}

/// The seed files a target starts from, besides its built-in seeds.
fn default_seeds(target: Target) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let with_extension = |dir: PathBuf, extensions: &[&str]| -> Vec<PathBuf> {
        files_under(&dir)
            .into_iter()
            .filter(|p| p.extension().and_then(|e| e.to_str()).is_some_and(|e| extensions.contains(&e)))
            .collect()
    };
    match target {
        Target::SceneFile => [root.join("examples"), root.join("crates/fuzz/seeds/scene-file")]
            .into_iter()
            .flat_map(|dir| with_extension(dir, &["toml"]))
            .collect(),
        Target::Gltf => [
            root.join("examples/data"),
            root.join("crates/scene/tests/data/broken"),
            root.join("crates/fuzz/seeds/gltf"),
            root.join("../shared/scenes/assimp-gltf2"),
        ]
        .into_iter()
        .flat_map(|dir| with_extension(dir, &["gltf", "glb"]))
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() < 1 << 20))
        .collect(),
        Target::Flags => Vec::new(),
    }
}

fn main() -> ExitCode {
    let args = Args::parse();
    let mut targets = Vec::new();
    for name in &args.targets {
        match Target::named(name) {
            Some(t) => targets.push(t),
            None => {
                eprintln!("gnomon-fuzz: error: no target `{name}`: choose scene-file, gltf or flags");
                return ExitCode::FAILURE;
            }
        }
    }
    if targets.is_empty() {
        targets = Target::ALL.to_vec();
    }
    if let Some(report_path) = &args.worker {
        return worker(&args, targets[0], report_path);
    }
    println!(
        "| target | seconds | executions | per second | distinct outcomes | corpus | slowest input | crashes (of them out of memory, timed out) | caught panics |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let jobs = args.jobs.map_or(targets.len(), |j| usize::try_from(j).unwrap_or(usize::MAX));
    let mut crashed = false;
    for (target, run) in supervise_all(&args, &targets, jobs) {
        println!(
            "| {} | {} | {} | {:.0} | {} | {} | {:.0} ms | {} ({}, {}) | {} |",
            target.name(),
            args.seconds,
            run.report.executions,
            run.report.executions as f64 / args.seconds.max(1) as f64,
            run.report.outcomes,
            run.report.corpus,
            run.report.slowest.as_secs_f64() * 1e3,
            run.report.crashes.len(),
            run.out_of_memory,
            run.timeouts,
            run.report.caught.len()
        );
        for crash in &run.report.crashes {
            eprintln!("gnomon-fuzz: {} crashed on {}", target.name(), crash.display());
            crashed = true;
        }
        if let Some(first) = run.report.caught.first() {
            eprintln!(
                "gnomon-fuzz: {} caught {} panic(s), e.g. on {}",
                target.name(),
                run.report.caught.len(),
                first.display()
            );
        }
    }
    if crashed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}

/// What the workers of one target found together.
#[derive(Default)]
struct Supervised {
    report: Report,
    /// Of the crashes, the inputs that took a worker past the memory cap.
    out_of_memory: usize,
    /// Of the crashes, the inputs that took longer than `--input-seconds`.
    timeouts: usize,
}

/// How a worker ended.
enum Ended {
    /// It exited, with this status.
    Exited(std::process::ExitStatus),
    /// It was killed after holding one input past the time limit.
    TimedOut,
}

/// Waits for `child`, killing it if the input it works on (the file `current`, which
/// it rewrites for each input) stays the same for longer than `limit`.
fn watch(mut child: std::process::Child, current: &Path, limit: Duration) -> Ended {
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Ended::Exited(status),
            Ok(None) => {}
            Err(_) => return Ended::TimedOut,
        }
        let idle = std::fs::metadata(current).and_then(|m| m.modified()).ok().and_then(|m| m.elapsed().ok());
        if idle.is_some_and(|idle| idle > limit) {
            let _ = child.kill();
            let _ = child.wait();
            return Ended::TimedOut;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Runs `targets`, `jobs` of them at a time (each supervisor waits on its own worker
/// process), and returns each target's run in the order given.
fn supervise_all(args: &Args, targets: &[Target], jobs: usize) -> Vec<(Target, Supervised)> {
    let mut runs = Vec::with_capacity(targets.len());
    for batch in targets.chunks(jobs.max(1)) {
        std::thread::scope(|scope| {
            let handles: Vec<_> =
                batch.iter().map(|&target| (target, scope.spawn(move || supervise(args, target)))).collect();
            for (target, handle) in handles {
                // A supervisor that panicked (no temporary folder, no worker started)
                // has already said why on stderr; its panic goes on.
                runs.push((target, handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))));
            }
        });
    }
    runs
}

/// Runs `target` in workers for `--seconds` in all, starting a new one (with the next
/// mutator seed) whenever one dies, and saving the input it died on.
fn supervise(args: &Args, target: Target) -> Supervised {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (report_path, current_path) = (dir.path().join("report"), dir.path().join("current"));
    let started = Instant::now();
    let mut total = Supervised::default();
    let mut restarts = 0u64;
    while started.elapsed().as_secs() < args.seconds {
        let left = args.seconds - started.elapsed().as_secs();
        let _ = std::fs::remove_file(&report_path);
        let mut command = std::process::Command::new(std::env::current_exe().expect("the fuzzer's own path"));
        command
            .arg(target.name())
            .args(["--seconds", &left.max(1).to_string(), "--seed", &(args.seed + restarts).to_string()])
            .args(["--memory-cap-mb", &args.memory_cap_mb.to_string()])
            .arg("--crashes")
            .arg(&args.crashes)
            .arg("--worker")
            .arg(&report_path)
            .env("GNOMON_FUZZ_CURRENT", &current_path);
        for seed in &args.seeds {
            command.arg("--seeds").arg(seed);
        }
        let child = command.spawn().expect("starting a fuzzing worker");
        let ended = watch(child, &current_path, Duration::from_secs(args.input_seconds));
        match (ended, read_report(&report_path)) {
            (Ended::Exited(status), Some(report)) if status.success() => add(&mut total.report, report),
            (Ended::TimedOut, _) => {
                let path = save_input(args, &current_path, format!("{}-timeout-{restarts}", target.name()));
                eprintln!(
                    "gnomon-fuzz: {} took over {} s on one input; it is {}",
                    target.name(),
                    args.input_seconds,
                    path.display()
                );
                total.report.crashes.push(path);
                total.timeouts += 1;
            }
            (Ended::Exited(status), _) => {
                // The worker died on its current input: past the memory cap, or any
                // other abort. Keep the input; go on with a new worker.
                let path = save_input(args, &current_path, format!("{}-died-{restarts}", target.name()));
                eprintln!(
                    "gnomon-fuzz: {} worker died ({status}); its input is {}",
                    target.name(),
                    path.display()
                );
                total.report.crashes.push(path);
                total.out_of_memory += 1;
            }
        }
        restarts += 1;
    }
    total
}

/// Keeps the input a worker died or stalled on, under `--crashes` as `name`.
fn save_input(args: &Args, current: &Path, name: String) -> PathBuf {
    let _ = std::fs::create_dir_all(&args.crashes);
    let path = args.crashes.join(name);
    let _ = std::fs::copy(current, &path);
    path
}

fn add(total: &mut Report, one: Report) {
    total.executions += one.executions;
    total.outcomes = total.outcomes.max(one.outcomes);
    total.corpus = total.corpus.max(one.corpus);
    total.slowest = total.slowest.max(one.slowest);
    total.crashes.extend(one.crashes);
    total.caught.extend(one.caught);
}

/// One target in this process, under the memory cap; its report to `report_path`.
fn worker(args: &Args, target: Target, report_path: &Path) -> ExitCode {
    let seed_dir = tempfile::tempdir().expect("a temporary directory");
    let mut seeds: Vec<PathBuf> = default_seeds(target);
    seeds.extend(args.seeds.iter().flat_map(|p| if p.is_dir() { files_under(p) } else { vec![p.clone()] }));
    for (i, seed) in target.builtin_seeds().iter().enumerate() {
        let path = seed_dir.path().join(format!("builtin-{i}"));
        if std::fs::write(&path, seed).is_ok() {
            seeds.push(path);
        }
    }
    let current =
        std::env::var_os("GNOMON_FUZZ_CURRENT").and_then(|p| CurrentInput::create(Path::new(&p)).ok());
    CAP.store(args.memory_cap_mb.saturating_mul(1 << 20), Ordering::Relaxed);
    let report = gnomon_fuzz::run(
        target,
        &seeds,
        Duration::from_secs(args.seconds),
        args.seed,
        &args.crashes,
        current.as_ref(),
    );
    CAP.store(0, Ordering::Relaxed);
    let lines = [
        report.executions.to_string(),
        report.outcomes.to_string(),
        report.corpus.to_string(),
        report.slowest.as_nanos().to_string(),
        report.crashes.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join("\t"),
        report.caught.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join("\t"),
    ];
    match std::fs::write(report_path, lines.join("\n")) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gnomon-fuzz: cannot write the worker's report {}: {e}", report_path.display());
            ExitCode::FAILURE
        }
    }
}

/// A worker's report, as `worker` writes it.
fn read_report(path: &Path) -> Option<Report> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.split('\n');
    let mut number = || lines.next().and_then(|l| l.parse::<u64>().ok());
    let (executions, outcomes, corpus, slowest) = (number()?, number()?, number()?, number()?);
    let mut paths = text
        .split('\n')
        .skip(4)
        .map(|l| l.split('\t').filter(|p| !p.is_empty()).map(PathBuf::from).collect());
    Some(Report {
        executions,
        outcomes: outcomes as usize,
        corpus: corpus as usize,
        slowest: Duration::from_nanos(slowest),
        crashes: paths.next().unwrap_or_default(),
        caught: paths.next().unwrap_or_default(),
    })
}
